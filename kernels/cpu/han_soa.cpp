// Run-time choice of the han_soa kernel variant (see kernels/CMakeLists.txt).
#include "kernels/cpu/han_soa.h"
#include "kernels/cpu/soa_common.h"

namespace hairbench::kernels::han_soa {

namespace baseline {
FrameFn frame_fn();
}
#ifdef HAIRBENCH_HAN_SOA_V4
namespace x86_64_v4 {
FrameFn frame_fn();
}
#endif

namespace {
bool has_v4() {
#ifdef HAIRBENCH_HAN_SOA_V4
  return soa::cpu_has_x86_64_v4();
#else
  return false;
#endif
}
}  // namespace

FrameFn frame_kernel_baseline() { return baseline::frame_fn(); }

FrameFn frame_kernel() {
#ifdef HAIRBENCH_HAN_SOA_V4
  static const FrameFn fn = has_v4() ? x86_64_v4::frame_fn() : baseline::frame_fn();
  return fn;
#else
  return baseline::frame_fn();
#endif
}

const char* frame_kernel_isa() { return has_v4() ? "x86-64-v4" : "baseline"; }

}  // namespace hairbench::kernels::han_soa
