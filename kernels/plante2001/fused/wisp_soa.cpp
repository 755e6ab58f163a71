// The wisp block kernel variant for this CPU (kernels/simd/isa.h), and the lanes' set-up.
#include "kernels/plante2001/fused/wisp_soa.h"

#include "kernels/simd/isa.h"

namespace hairbench::kernels::wisp_soa {

namespace baseline {
Kernels kernels();
}
namespace x86_64_v4 {
Kernels kernels();
}

bool block_eligible(const WispSystem& s, std::size_t w) {
  const std::uint32_t b = s.node_begin[w], e = s.node_begin[w + 1];
  return e - b >= 3 && e - b <= static_cast<std::uint32_t>(kMaxNodes);
}

BodyLanes::BodyLanes(const BodyStep& body)
    : spheres(body.spheres.empty() ? nullptr : body.spheres.data()->data()),
      count(body.spheres.size()),
      moves(body.moves.data()),
      h(body.h) {
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 4; ++c) motion[r][c] = body.motion.matrix()(r, c);
}

void contact_nodes(const WispSystem& s, std::span<const WispParams> params, std::size_t begin, std::size_t end,
                   ContactNode* out) {
  for (std::size_t k = begin; k < end; ++k) {
    ContactNode& c = out[k];
    for (int i = 0; i < 3; ++i) {
      c.a[ContactNode::kX + i] = s.x[k][i];
      c.a[ContactNode::kV + i] = s.v[k][i];
      c.a[ContactNode::kN + i] = s.n[k][i];
      c.b[ContactNode::kE1 + i] = s.e1[k][i];
      c.b[ContactNode::kE2 + i] = s.e2[k][i];
    }
    for (int q = 0; q < kEnvelopePerSection; ++q) {
      c.a[ContactNode::kR + q] = s.r[kEnvelopePerSection * k + q];
      c.b[ContactNode::kRdot + q] = s.rdot[kEnvelopePerSection * k + q];
    }
    c.a[ContactNode::kRRest] = s.r_rest[k];
    c.a[ContactNode::kEnvelopeMass] = params[s.wisp_params[s.node_wisp[k]]].envelope_mass;
    c.a[15] = 0.0f;
    for (int i = ContactNode::kRdot + kEnvelopePerSection; i < 16; ++i) c.b[i] = 0.0f;
  }
}

Kernels kernels() {
  static const Kernels k = simd::select(&baseline::kernels, HAIRBENCH_V4_ENTRY(kernels));
  return k;
}

Kernels kernels_baseline() { return baseline::kernels(); }

}  // namespace hairbench::kernels::wisp_soa
