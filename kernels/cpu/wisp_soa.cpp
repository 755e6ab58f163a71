// Run-time choice of the wisp block kernel variant (see kernels/CMakeLists.txt).
#include "kernels/cpu/wisp_soa.h"

#include "kernels/cpu/soa_common.h"

namespace hairbench::kernels::wisp_soa {

namespace baseline {
Kernels kernels();
}
#ifdef HAIRBENCH_PLANTE_SOA_V4
namespace x86_64_v4 {
Kernels kernels();
}
#endif

namespace {
bool has_v4() {
#ifdef HAIRBENCH_PLANTE_SOA_V4
  return soa::cpu_has_x86_64_v4();
#else
  return false;
#endif
}
}  // namespace

bool block_eligible(const WispSystem& s, std::size_t w) {
  const std::uint32_t b = s.node_begin[w], e = s.node_begin[w + 1];
  return e - b >= 3 && e - b <= static_cast<std::uint32_t>(kMaxNodes);
}

Kernels kernels() {
#ifdef HAIRBENCH_PLANTE_SOA_V4
  static const Kernels k = has_v4() ? x86_64_v4::kernels() : baseline::kernels();
  return k;
#else
  return baseline::kernels();
#endif
}

Kernels kernels_baseline() { return baseline::kernels(); }

const char* kernels_isa() { return has_v4() ? "x86-64-v4" : "baseline"; }

}  // namespace hairbench::kernels::wisp_soa
