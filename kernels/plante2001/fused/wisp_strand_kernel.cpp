// The strand rebuild's section frames (§5.2) for 16 vertices at a time (wisp_soa.h,
// strand_points). Compiled once per ISA variant like the other wisp block kernels; each
// lane performs strand_point's operations (from the nodes' NodeSections) in Eigen's order
// for 3-vectors (wisp_lanes.h), so a vertex gets the per-vertex kernel's bits.
#include "kernels/plante2001/fused/wisp_lanes.h"
#include "kernels/plante2001/fused/wisp_soa.h"

#include <cmath>

#ifndef HAIRBENCH_ISA_VARIANT
#error "HAIRBENCH_ISA_VARIANT must name the ISA variant"
#endif

namespace hairbench::kernels::wisp_soa::HAIRBENCH_ISA_VARIANT {

namespace {

constexpr int W = kLanes;
// A NodeSection as floats: e1 (0-2), e2 (3-5), the four scales (6-9).
constexpr int kSectionFloats = 10;
static_assert(sizeof(NodeSection) == kSectionFloats * sizeof(float), "NodeSection is read as floats");

F3 section3(const float* p, int i, int at) {
  return {p[kSectionFloats * i + at], p[kSectionFloats * i + at + 1], p[kSectionFloats * i + at + 2]};
}

}  // namespace

void strand_points(const WispSystem& s, const NodeSection* sections, const std::uint32_t* node, const Vec4f* coord,
                   std::uint32_t n, Vec3f* point, float* weight) {
  const float* x = s.x.data()->data();
  const float* sec = reinterpret_cast<const float*>(sections);
  const float* cf = coord->data();
  for (std::uint32_t i0 = 0; i0 < n; i0 += W) {
    float px[W], py[W], pz[W], wt[W];
    int bad[W];
    // Lanes past the strand's end repeat its last vertex; their results are dropped.
#pragma GCC ivdep
    for (int l = 0; l < W; ++l) {
      const int i = static_cast<int>(i0 + l < n ? i0 + l : n - 1);
      const int k = static_cast<int>(node[i]);
      const float sfrac = cf[4 * i], ca = cf[4 * i + 1], cb = cf[4 * i + 2], cn = cf[4 * i + 3];
      const int j = sfrac > 0.0f ? k + 1 : sfrac < 0.0f ? k - 1 : k;
      const float u = std::abs(sfrac);
      // section_between (wisp_kernels.cpp) from the NodeSections of k and j.
      const F3 xk = load3(x, k), xj = load3(x, j);
      const F3 origin = add(xk, mul(u, sub(xj, xk)));
      const F3 e1k = section3(sec, k, 0), e1j = section3(sec, j, 0);
      const F3 e2k = section3(sec, k, 3), e2j = section3(sec, j, 3);
      int fallback = 0;
      const F3 e1 = unit(add(e1k, mul(u, sub(e1j, e1k))), fallback);
      const F3 e2_lerp = add(e2k, mul(u, sub(e2j, e2k)));
      const F3 e2 = unit(sub(e2_lerp, mul(dot(e2_lerp, e1), e1)), fallback);
      const F3 nrm = cross(e1, e2);
      const float* sk = sec + kSectionFloats * k + 6;
      const float* sj = sec + kSectionFloats * j + 6;
      // point_in: the scale of the half-axis on the coordinate's side.
      float scale[4];
      for (int q = 0; q < 4; ++q) scale[q] = lerp(sk[q], sj[q], u);
      const float a = ca * (ca >= 0.0f ? scale[0] : scale[2]);
      const float b = cb * (cb >= 0.0f ? scale[1] : scale[3]);
      const F3 p = add(add(add(origin, mul(a, e1)), mul(b, e2)), mul(cn, nrm));
      px[l] = p.x;
      py[l] = p.y;
      pz[l] = p.z;
      wt[l] = lerp(s.frame_weight[k], s.frame_weight[j], u);
      bad[l] = fallback;
    }
    const std::uint32_t m = n - i0 < W ? n - i0 : W;
    for (std::uint32_t l = 0; l < m; ++l) {
      // A unit_or fallback axis: the per-vertex kernel takes it.
      point[i0 + l] = bad[l] ? strand_point(s, node[i0 + l], coord[i0 + l], sections)
                             : Vec3f(px[l], py[l], pz[l]);
      weight[i0 + l] = wt[l];
    }
  }
}

}  // namespace hairbench::kernels::wisp_soa::HAIRBENCH_ISA_VARIANT
