// The narrow phase of the wisp-wisp interactions (wisp_soa.h, ContactsFn), compiled
// once per ISA variant like the block kernels (kernels/CMakeLists.txt): the box tests
// of a cell's candidates and the volume tests of a segment's masses run as vector code.
#include "kernels/cpu/wisp_grid.h"
#include "kernels/cpu/wisp_soa.h"

#include <algorithm>
#include <bit>
#include <cmath>

namespace hairbench::kernels::wisp_soa::PLANTE_SOA_VARIANT {

namespace {

// The masses of segment i (node seg[i] + 1 and its envelope) tested against the volume
// of segment j; appends contacts to out.
void masses_in(const SegmentGrid& g, const WispSystem& s, std::size_t i, std::size_t j, std::vector<WispContact>& out) {
  const SegmentVolume& vol = g.vol[j];
  if (!g.mass_free[i] || !(vol.len2 > 0.0f)) return;  // a degenerate volume holds nothing
  // Cheap bounds first, for all the masses at once (issue 10): the axial one of the
  // test below, widened by far more than rounding (these sums may round otherwise), and
  // the distance to the axis within vol.reach2. Most masses are outside one of them, and
  // every mass the full test finds is inside both; the full test, with the frame's
  // square root and divisions, runs only where some mass is.
  const SegmentMasses& m = g.mass[i];
  alignas(32) std::int32_t near[SegmentMasses::kWidth];
  for (int q = 0; q < SegmentMasses::kWidth; ++q) {
    const float px = m.x[q] - vol.xa.x(), py = m.y[q] - vol.xa.y(), pz = m.z[q] - vol.xa.z();
    const float u = (px * vol.d.x() + py * vol.d.y() + pz * vol.d.z()) / vol.len2;
    const float lx = px - u * vol.d.x(), ly = py - u * vol.d.y(), lz = pz - u * vol.d.z();
    near[q] = (u >= -1e-3f) & (u <= 1.001f) & (lx * lx + ly * ly + lz * lz <= vol.reach2);
  }
  std::uint32_t bits = 0;
  for (int q = 0; q < kMassesPerSegment; ++q) bits |= static_cast<std::uint32_t>(near[q]) << q;
  if (bits == 0) return;
  // The full test (SegmentVolume), for all the masses at once: each lane performs the
  // operations of the per-point test of plante_wisp before issue 10 in its order (Eigen's
  // 3-vector dot products and norms sum x + (y + z); its quotients by a scalar are
  // divisions), so the same contacts are found with the same axial parameters.
  // The segment's values, as scalars read once: the lanes then run as vector code.
  const float xa[3] = {vol.xa.x(), vol.xa.y(), vol.xa.z()}, d[3] = {vol.d.x(), vol.d.y(), vol.d.z()};
  const float t[3] = {vol.t.x(), vol.t.y(), vol.t.z()}, o[3] = {vol.t_orth.x(), vol.t_orth.y(), vol.t_orth.z()};
  const Vec3f &e1a = s.e1[vol.a], &e1b = s.e1[vol.a + 1];
  const float ea[3] = {e1a.x(), e1a.y(), e1a.z()}, eb[3] = {e1b.x(), e1b.y(), e1b.z()};
  const float* r_at_a = &s.r[kEnvelopePerSection * vol.a];
  float ra[kEnvelopePerSection], dr[kEnvelopePerSection];
  for (int q = 0; q < kEnvelopePerSection; ++q) {
    ra[q] = r_at_a[q];
    dr[q] = r_at_a[q + kEnvelopePerSection] - r_at_a[q];
  }
  const float len2 = vol.len2;
  alignas(32) float axial[SegmentMasses::kWidth];
  for (int q = 0; q < SegmentMasses::kWidth; ++q) {
    const float px = m.x[q] - xa[0], py = m.y[q] - xa[1], pz = m.z[q] - xa[2];
    const float u = (px * d[0] + (py * d[1] + pz * d[2])) / len2;
    const float lx = m.x[q] - (xa[0] + u * d[0]), ly = m.y[q] - (xa[1] + u * d[1]), lz = m.z[q] - (xa[2] + u * d[2]);
    // The section axes interpolated along the segment, made orthonormal about its axis.
    const float w = 1.0f - u;
    float ex = w * ea[0] + u * eb[0], ey = w * ea[1] + u * eb[1], ez = w * ea[2] + u * eb[2];
    const float et = ex * t[0] + (ey * t[1] + ez * t[2]);
    ex = ex - et * t[0];
    ey = ey - et * t[1];
    ez = ez - et * t[2];
    const float n2 = ex * ex + (ey * ey + ez * ez);
    const bool unit = n2 > 1e-24f;
    const float len = std::sqrt(n2);
    ex = unit ? ex / len : o[0];
    ey = unit ? ey / len : o[1];
    ez = unit ? ez / len : o[2];
    const float fx = t[1] * ez - t[2] * ey, fy = t[2] * ex - t[0] * ez, fz = t[0] * ey - t[1] * ex;
    const float alpha = lx * ex + (ly * ey + lz * ez), beta = lx * fx + (ly * fy + lz * fz);
    const float r_alpha = alpha >= 0.0f ? ra[0] + u * dr[0] : ra[2] + u * dr[2];
    const float r_beta = beta >= 0.0f ? ra[1] + u * dr[1] : ra[3] + u * dr[3];
    const float f = (alpha / r_alpha) * (alpha / r_alpha) + (beta / r_beta) * (beta / r_beta);
    near[q] = (u >= 0.0f) & (u <= 1.0f) & (f < 1.0f);
    axial[q] = u;
  }
  bits = 0;
  for (int q = 0; q < kMassesPerSegment; ++q) bits |= static_cast<std::uint32_t>(near[q]) << q;
  const std::uint32_t k = g.seg[i] + 1;
  for (; bits != 0; bits &= bits - 1) {
    const int q = std::countr_zero(bits);
    const float u = axial[q];
    if (q == 0)
      out.push_back({k, vol.a, u, 0});
    else
      out.push_back({static_cast<std::uint32_t>(kEnvelopePerSection * k + q - 1), vol.a, u, 1});
  }
}

// Items [b, e) of cells whose boxes meet [lo, hi] (compared as the original
// (lo > hi).any() rejection, so NaN boxes are kept alike), as bits from b on; e - b <= 32.
std::uint32_t overlapping(const SegmentGrid& g, std::uint32_t b, std::uint32_t e, const Vec3f& lo, const Vec3f& hi) {
  // Box tests into an array first (vector code), then gathered into bits.
  const float *lx = g.item_lo[0].data() + b, *ly = g.item_lo[1].data() + b, *lz = g.item_lo[2].data() + b;
  const float *hx = g.item_hi[0].data() + b, *hy = g.item_hi[1].data() + b, *hz = g.item_hi[2].data() + b;
  const std::uint32_t count = e - b;
  alignas(32) std::int32_t meet[32];
  for (std::uint32_t t = 0; t < count; ++t)
    meet[t] = !(lo.x() > hx[t]) & !(lx[t] > hi.x()) & !(lo.y() > hy[t]) & !(ly[t] > hi.y()) & !(lo.z() > hz[t]) &
              !(lz[t] > hi.z());
  std::uint32_t bits = 0;
  for (std::uint32_t t = 0; t < count; ++t) bits |= static_cast<std::uint32_t>(meet[t]) << t;
  return bits;
}

}  // namespace

void contacts(const SegmentGrid& g, const WispSystem& s, std::size_t begin, std::size_t end,
                   std::vector<std::uint32_t>& mailbox, std::vector<WispContact>& out) {
  auto index = [&](int x, int y, int z) { return (static_cast<std::size_t>(z) * g.dims.y() + y) * g.dims.x() + x; };
  for (std::size_t i = begin; i < end; ++i) {
    const std::uint32_t a = g.seg[i];
    const auto i32 = static_cast<std::uint32_t>(i);
    for (int z = g.cell_lo[i].z(); z <= g.cell_hi[i].z(); ++z)
      for (int y = g.cell_lo[i].y(); y <= g.cell_hi[i].y(); ++y)
        for (int x = g.cell_lo[i].x(); x <= g.cell_hi[i].x(); ++x) {
          const std::size_t c = index(x, y, z);
          // A cell's items ascend: the later segments start after i.
          const std::uint32_t stop = g.cell_start[c + 1];
          std::uint32_t it = static_cast<std::uint32_t>(
              std::upper_bound(g.cell_items.begin() + g.cell_start[c], g.cell_items.begin() + stop, i32) -
              g.cell_items.begin());
          // The box test first, over a run of items at once; the mailbox, wisp and
          // narrow-phase tests then for the boxes that meet, in item order: the same
          // pairs in the same order as testing each item in turn, since the box test
          // does not depend on the cell.
          for (; it < stop; it += 32) {
            std::uint32_t bits = overlapping(g, it, std::min(stop, it + 32), g.lo[i], g.hi[i]);
            // The later segments' data lie far apart in memory: their loads are started
            // together rather than one narrow phase after the other.
            for (std::uint32_t rest = bits; rest != 0; rest &= rest - 1) {
              const std::uint32_t j = g.cell_items[it + static_cast<std::uint32_t>(std::countr_zero(rest))];
              __builtin_prefetch(&g.vol[j]);
              __builtin_prefetch(&g.mass[j]);
              __builtin_prefetch(reinterpret_cast<const char*>(&g.mass[j]) + 64);
            }
            for (; bits != 0; bits &= bits - 1) {
              const std::uint32_t j = g.cell_items[it + static_cast<std::uint32_t>(std::countr_zero(bits))];
              if (mailbox[j] == i32) continue;
              mailbox[j] = i32;
              const std::uint32_t b = g.seg[j];
              if (g.wisp[j] == g.wisp[i] && b - a < 3) continue;  // b > a within a wisp
              masses_in(g, s, i, j, out);
              masses_in(g, s, j, i, out);
            }
          }
        }
  }
}

}  // namespace hairbench::kernels::wisp_soa::PLANTE_SOA_VARIANT
