// Run-time choice of the halen_soa kernel variant (see kernels/CMakeLists.txt).
#include "kernels/cpu/halen_soa.h"
#include "kernels/cpu/soa_common.h"

namespace hairbench::kernels::halen_soa {

namespace baseline {
FrameFn frame_fn();
ForestFrameFn forest_frame_fn();
}  // namespace baseline
#ifdef HAIRBENCH_HALEN_SOA_V4
namespace x86_64_v4 {
FrameFn frame_fn();
ForestFrameFn forest_frame_fn();
}  // namespace x86_64_v4
#endif

namespace {
bool has_v4() {
#ifdef HAIRBENCH_HALEN_SOA_V4
  return soa::cpu_has_x86_64_v4();
#else
  return false;
#endif
}
}  // namespace

FrameFn frame_kernel_baseline() { return baseline::frame_fn(); }
ForestFrameFn forest_kernel_baseline() { return baseline::forest_frame_fn(); }

FrameFn frame_kernel() {
#ifdef HAIRBENCH_HALEN_SOA_V4
  static const FrameFn fn = has_v4() ? x86_64_v4::frame_fn() : baseline::frame_fn();
  return fn;
#else
  return baseline::frame_fn();
#endif
}

ForestFrameFn forest_kernel() {
#ifdef HAIRBENCH_HALEN_SOA_V4
  static const ForestFrameFn fn = has_v4() ? x86_64_v4::forest_frame_fn() : baseline::forest_frame_fn();
  return fn;
#else
  return baseline::forest_frame_fn();
#endif
}

}  // namespace hairbench::kernels::halen_soa
