// Configure-time probe (CMakeLists.txt, FEMTO_ARCH=auto): exits 0 when the build machine has the
// x86-64-v3 features femto's code generation relies on (AVX2, FMA, BMI2).
int main() {
  __builtin_cpu_init();
  const bool v3 = __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma") &&
                  __builtin_cpu_supports("bmi2");
  return v3 ? 0 : 1;
}
