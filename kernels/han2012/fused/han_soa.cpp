// The han_soa kernel variant for this CPU (kernels/simd/isa.h).
#include "kernels/han2012/fused/han_soa.h"

#include "kernels/simd/isa.h"

namespace hairbench::kernels::han_soa {

namespace baseline {
FrameFn frame_fn();
}
namespace x86_64_v4 {
FrameFn frame_fn();
}

FrameFn frame_kernel_baseline() { return baseline::frame_fn(); }

FrameFn frame_kernel() {
  static const FrameFn fn = simd::select(&baseline::frame_fn, HAIRBENCH_V4_ENTRY(frame_fn));
  return fn;
}

}  // namespace hairbench::kernels::han_soa
