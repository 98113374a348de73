// Every femto program (and the Python module) checks, before any of its code runs, that the CPU
// has the instruction set the build was compiled for (FEMTO_ARCH in CMakeLists.txt): one clear
// message instead of "Illegal instruction". Compiled for the baseline x86-64, so that the check
// itself runs on any CPU.
#include <cstdio>
#include <cstdlib>

#if defined(FEMTO_NEEDS_X86_64_V3)
namespace {
// Priority 101: before the constructors of the program's own (x86-64-v3) code.
[[gnu::constructor(101)]] void check_cpu_instruction_set() {
  __builtin_cpu_init();
  if (__builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma") &&
      __builtin_cpu_supports("bmi2"))
    return;
  std::fputs(
      "femto: this build is compiled for x86-64-v3 (AVX2, FMA, BMI2), which this CPU lacks; "
      "rebuild femto on this machine, or with cmake -DFEMTO_ARCH=default\n",
      stderr);
  std::_Exit(1);
}
}  // namespace
#endif
