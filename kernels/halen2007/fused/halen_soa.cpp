// The halen_soa kernel variants for this CPU (kernels/simd/isa.h).
#include "kernels/halen2007/fused/halen_soa.h"

#include "kernels/simd/isa.h"

namespace hairbench::kernels::halen_soa {

namespace baseline {
FrameFn frame_fn();
ForestFrameFn forest_frame_fn();
}  // namespace baseline
namespace x86_64_v4 {
FrameFn frame_fn();
ForestFrameFn forest_frame_fn();
}  // namespace x86_64_v4

FrameFn frame_kernel_baseline() { return baseline::frame_fn(); }
ForestFrameFn forest_kernel_baseline() { return baseline::forest_frame_fn(); }

FrameFn frame_kernel() {
  static const FrameFn fn = simd::select(&baseline::frame_fn, HAIRBENCH_V4_ENTRY(frame_fn));
  return fn;
}

ForestFrameFn forest_kernel() {
  static const ForestFrameFn fn = simd::select(&baseline::forest_frame_fn, HAIRBENCH_V4_ENTRY(forest_frame_fn));
  return fn;
}

}  // namespace hairbench::kernels::halen_soa
