#include "kernels/simd/isa.h"

namespace hairbench::kernels::simd {

namespace {
bool cpu_has_x86_64_v4() {
#if defined(__x86_64__)
  __builtin_cpu_init();
  return __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512bw") &&
         __builtin_cpu_supports("avx512dq") && __builtin_cpu_supports("avx512vl");
#else
  return false;
#endif
}
}  // namespace

Isa runtime_isa() {
#ifdef HAIRBENCH_SOA_V4
  static const Isa isa = cpu_has_x86_64_v4() ? Isa::X86_64_V4 : Isa::Baseline;
  return isa;
#else
  return Isa::Baseline;
#endif
}

const char* isa_name(Isa isa) { return isa == Isa::X86_64_V4 ? "x86-64-v4" : "baseline"; }

}  // namespace hairbench::kernels::simd
