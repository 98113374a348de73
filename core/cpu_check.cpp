// Every femto program (and the Python module) checks, before any of its code runs, that the CPU
// has the instruction set the build was compiled for (FEMTO_ARCH in CMakeLists.txt): one clear
// message instead of "Illegal instruction". Compiled for the baseline x86-64 (CMakeLists.txt), so
// that the check itself runs on any CPU; with FEMTO_CPU_PROBE it is the configure-time probe.
#include <cpuid.h>

#include <cstdio>
#include <cstdlib>

namespace {

bool bit(unsigned reg, int b) {
  return ((reg >> b) & 1u) != 0;
}

// What -march=x86-64-v3 lets the compiler use (AVX, AVX2, BMI1, BMI2, F16C, FMA, LZCNT, MOVBE),
// and the operating system saving the AVX registers (XCR0 bits 1 and 2).
bool has_x86_64_v3() {
  unsigned a = 0, b = 0, c = 0, d = 0;
  if (!__get_cpuid(1, &a, &b, &c, &d)) return false;
  if (!(bit(c, 12) && bit(c, 22) && bit(c, 27) && bit(c, 28) && bit(c, 29)))
    return false;  // FMA, MOVBE, OSXSAVE, AVX, F16C
  unsigned xcr0 = 0, xcr0_high = 0;
  __asm__ volatile("xgetbv" : "=a"(xcr0), "=d"(xcr0_high) : "c"(0));
  if ((xcr0 & 6u) != 6u) return false;
  if (!__get_cpuid_count(7, 0, &a, &b, &c, &d)) return false;
  if (!(bit(b, 3) && bit(b, 5) && bit(b, 8))) return false;  // BMI1, AVX2, BMI2
  if (!__get_cpuid(0x80000001u, &a, &b, &c, &d)) return false;
  return bit(c, 5);  // LZCNT
}

[[maybe_unused]] void check_cpu(int, char**, char**) {
  if (has_x86_64_v3()) return;
  std::fputs(
      "femto: this build is compiled for x86-64-v3 (AVX2, FMA, BMI2), which this CPU lacks; "
      "rebuild femto on this machine, or with cmake -DFEMTO_ARCH=default\n",
      stderr);
  std::_Exit(1);
}

}  // namespace

#if defined(FEMTO_CPU_PROBE)
int main() {
  return has_x86_64_v3() ? 0 : 1;
}
#elif defined(FEMTO_NEEDS_X86_64_V3) && defined(FEMTO_CPU_CHECK_PREINIT)
// Programs: in .preinit_array, which runs before the initializers of every shared library (they
// may call the program's own copies of library templates, compiled for x86-64-v3).
[[gnu::used, gnu::section(".preinit_array")]] void (*femto_preinit_cpu_check)(int, char**,
                                                                              char**) = check_cpu;
#elif defined(FEMTO_NEEDS_X86_64_V3)
// The Python module (a shared object has no .preinit_array): before its own initializers.
[[gnu::constructor(101)]] void femto_module_cpu_check() {
  check_cpu(0, nullptr, nullptr);
}
#endif
