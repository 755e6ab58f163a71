// Run-time choice of the halen_soa kernel variant (see kernels/CMakeLists.txt).
#include "kernels/cpu/halen_soa.h"

namespace hairbench::kernels::halen_soa {

namespace baseline {
FrameFn frame_fn();
}
#ifdef HAIRBENCH_HALEN_SOA_V4
namespace x86_64_v4 {
FrameFn frame_fn();
}
#endif

FrameFn frame_kernel_baseline() { return baseline::frame_fn(); }

FrameFn frame_kernel() {
#ifdef HAIRBENCH_HALEN_SOA_V4
  __builtin_cpu_init();
  static const FrameFn fn = __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512bw") &&
                                    __builtin_cpu_supports("avx512dq") && __builtin_cpu_supports("avx512vl")
                                ? x86_64_v4::frame_fn()
                                : baseline::frame_fn();
  return fn;
#else
  return baseline::frame_fn();
#endif
}

}  // namespace hairbench::kernels::halen_soa
