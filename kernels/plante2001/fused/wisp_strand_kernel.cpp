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

}  // namespace

void strand_points(const WispSystem& s, const NodeSection* sections, const std::uint32_t* node, const Vec4f* coord,
                   std::uint32_t n, Vec3f* point, float* weight) {
  const float* x = s.x.data()->data();
  const float* sec = reinterpret_cast<const float*>(sections);
  const float* cf = coord->data();
  for (std::uint32_t i0 = 0; i0 < n; i0 += W) {
    // Each lane's inputs first, copied into rows of one float a lane (the vertex's node k
    // and its neighbour j are indirect, and GCC does not vectorise such loads), then the
    // arithmetic on the rows as vector code.
    alignas(64) float sfrac[W], ca[W], cb[W], cn[W], wk[W], wj[W];
    alignas(64) float xk[3][W], xj[3][W], sk[kSectionFloats][W], sj[kSectionFloats][W];
    // Lanes past the strand's end repeat its last vertex; their results are dropped.
    for (int l = 0; l < W; ++l) {
      const int i = static_cast<int>(i0 + l < n ? i0 + l : n - 1);
      const int k = static_cast<int>(node[i]);
      sfrac[l] = cf[4 * i];
      ca[l] = cf[4 * i + 1];
      cb[l] = cf[4 * i + 2];
      cn[l] = cf[4 * i + 3];
      const int j = sfrac[l] > 0.0f ? k + 1 : sfrac[l] < 0.0f ? k - 1 : k;
      for (int c = 0; c < 3; ++c) {
        xk[c][l] = x[3 * k + c];
        xj[c][l] = x[3 * j + c];
      }
      for (int c = 0; c < kSectionFloats; ++c) {
        sk[c][l] = sec[kSectionFloats * k + c];
        sj[c][l] = sec[kSectionFloats * j + c];
      }
      wk[l] = s.frame_weight[k];
      wj[l] = s.frame_weight[j];
    }
    float px[W], py[W], pz[W], wt[W];
    int bad[W];
#pragma GCC ivdep
    for (int l = 0; l < W; ++l) {
      const float u = std::abs(sfrac[l]);
      // section_between (wisp_kernels.cpp) from the NodeSections of k and j.
      const F3 xkl{xk[0][l], xk[1][l], xk[2][l]}, xjl{xj[0][l], xj[1][l], xj[2][l]};
      const F3 origin = add(xkl, mul(u, sub(xjl, xkl)));
      const F3 e1k{sk[0][l], sk[1][l], sk[2][l]}, e1j{sj[0][l], sj[1][l], sj[2][l]};
      const F3 e2k{sk[3][l], sk[4][l], sk[5][l]}, e2j{sj[3][l], sj[4][l], sj[5][l]};
      int fallback = 0;
      const F3 e1 = unit(add(e1k, mul(u, sub(e1j, e1k))), fallback);
      const F3 e2_lerp = add(e2k, mul(u, sub(e2j, e2k)));
      const F3 e2 = unit(sub(e2_lerp, mul(dot(e2_lerp, e1), e1)), fallback);
      const F3 nrm = cross(e1, e2);
      // point_in: the scale of the half-axis on the coordinate's side.
      float scale[4];
      for (int q = 0; q < 4; ++q) scale[q] = lerp(sk[6 + q][l], sj[6 + q][l], u);
      const float a = ca[l] * (ca[l] >= 0.0f ? scale[0] : scale[2]);
      const float b = cb[l] * (cb[l] >= 0.0f ? scale[1] : scale[3]);
      const F3 p = add(add(add(origin, mul(a, e1)), mul(b, e2)), mul(cn[l], nrm));
      px[l] = p.x;
      py[l] = p.y;
      pz[l] = p.z;
      wt[l] = lerp(wk[l], wj[l], u);
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
