// The narrow phase of the wisp-wisp interactions (wisp_soa.h, ContactsFn), compiled
// once per ISA variant like the block kernels (kernels/CMakeLists.txt): the box tests
// of a cell's candidates and the volume tests of a segment's masses run as vector code.
#include "kernels/cpu/wisp_grid.h"
#include "kernels/cpu/wisp_soa.h"

#include <algorithm>
#include <bit>
#include <cmath>

#if defined(__x86_64__)
#include <immintrin.h>
#endif

namespace hairbench::kernels::wisp_soa::PLANTE_SOA_VARIANT {

// GCC 12 warns that the AVX-512 intrinsics' internal undefined operands may be
// uninitialised, wherever they are inlined; it is a false positive (as in soa_rows.h).
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wuninitialized"
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"

namespace {

#if defined(__AVX512F__) && defined(__AVX512DQ__)
// A vector of 16 from two of 8: lo in lanes 0-7, hi in lanes 8-15 (the pairs of tests
// below run two of SegmentMasses' 8-lane tests in one vector).
__m512 halves(float lo, float hi) { return _mm512_insertf32x8(_mm512_set1_ps(lo), _mm256_set1_ps(hi), 1); }
__m512 halves(const float* lo, const float* hi) {
  return _mm512_insertf32x8(_mm512_zextps256_ps512(_mm256_load_ps(lo)), _mm256_load_ps(hi), 1);
}
#endif

// Cheap bounds of the masses of segment i (node seg[i] + 1 and its envelope) against
// the volume of segment j, 8 lanes for its 5 masses (issue 10): the axial one of the
// full test (masses_in), widened by far more than rounding (these sums may round
// otherwise, and the quotient by len2 is a product with its reciprocal), and the
// distance to the axis within vol.reach2. Most masses are outside one of them, and
// every mass the full test finds is inside both. Bit q for mass q; none where the
// masses are pinned or the volume is degenerate (it holds nothing), all where it is so
// thin that 1 / len2 overflows (the full test decides).
std::uint32_t near_half(const SegmentVolume& vol, const SegmentMasses& m, bool free) {
  if (!free || !(vol.len2 > 0.0f)) return 0;
  if (!(vol.inv_len2 < INFINITY)) return (1u << kMassesPerSegment) - 1;
  alignas(32) std::int32_t near[SegmentMasses::kWidth];
  for (int q = 0; q < SegmentMasses::kWidth; ++q) {
    const float px = m.x[q] - vol.xa.x(), py = m.y[q] - vol.xa.y(), pz = m.z[q] - vol.xa.z();
    const float u = (px * vol.d.x() + py * vol.d.y() + pz * vol.d.z()) * vol.inv_len2;
    const float lx = px - u * vol.d.x(), ly = py - u * vol.d.y(), lz = pz - u * vol.d.z();
    near[q] = (u >= -1e-3f) & (u <= 1.001f) & (lx * lx + ly * ly + lz * lz <= vol.reach2);
  }
  std::uint32_t bits = 0;
  for (int q = 0; q < kMassesPerSegment; ++q) bits |= static_cast<std::uint32_t>(near[q]) << q;
  return bits;
}

// near_half both ways for a pair: bits 0-4 for the masses of i near the volume of j,
// bits 8-12 for those of j near the volume of i. With AVX-512 both directions run as one
// vector of 16, at the cost of one of 8, with the same bounds.
std::uint32_t near_pair(const SegmentGrid& g, std::size_t i, std::size_t j) {
  const SegmentVolume &vi = g.vol[i], &vj = g.vol[j];
  const SegmentMasses &mi = g.mass[i], &mj = g.mass[j];
#if defined(__AVX512F__) && defined(__AVX512DQ__)
  static_assert(SegmentMasses::kWidth == 8);
  const __m512 dx = halves(vj.d.x(), vi.d.x()), dy = halves(vj.d.y(), vi.d.y()), dz = halves(vj.d.z(), vi.d.z());
  const __m512 px = _mm512_sub_ps(halves(mi.x, mj.x), halves(vj.xa.x(), vi.xa.x()));
  const __m512 py = _mm512_sub_ps(halves(mi.y, mj.y), halves(vj.xa.y(), vi.xa.y()));
  const __m512 pz = _mm512_sub_ps(halves(mi.z, mj.z), halves(vj.xa.z(), vi.xa.z()));
  const __m512 u = _mm512_mul_ps(
      _mm512_add_ps(_mm512_add_ps(_mm512_mul_ps(px, dx), _mm512_mul_ps(py, dy)), _mm512_mul_ps(pz, dz)),
      halves(vj.inv_len2, vi.inv_len2));
  const __m512 lx = _mm512_sub_ps(px, _mm512_mul_ps(u, dx)), ly = _mm512_sub_ps(py, _mm512_mul_ps(u, dy));
  const __m512 lz = _mm512_sub_ps(pz, _mm512_mul_ps(u, dz));
  const __m512 l2 = _mm512_add_ps(_mm512_add_ps(_mm512_mul_ps(lx, lx), _mm512_mul_ps(ly, ly)), _mm512_mul_ps(lz, lz));
  std::uint32_t bits = _mm512_cmp_ps_mask(u, _mm512_set1_ps(-1e-3f), _CMP_GE_OQ) &
                       _mm512_cmp_ps_mask(u, _mm512_set1_ps(1.001f), _CMP_LE_OQ) &
                       _mm512_cmp_ps_mask(l2, halves(vj.reach2, vi.reach2), _CMP_LE_OQ);
  constexpr std::uint32_t kHalf = (1u << kMassesPerSegment) - 1;
  bits &= kHalf | kHalf << 8;
  // The rare volumes near_half treats apart, as it does.
  auto special = [](const SegmentVolume& v, bool free) { return !free || !(v.len2 > 0.0f) || !(v.inv_len2 < INFINITY); };
  if (special(vj, g.mass_free[i] != 0)) bits = (bits & ~kHalf) | near_half(vj, mi, g.mass_free[i] != 0);
  if (special(vi, g.mass_free[j] != 0)) bits = (bits & kHalf) | near_half(vi, mj, g.mass_free[j] != 0) << 8;
  return bits;
#else
  return near_half(vj, mi, g.mass_free[i] != 0) | near_half(vi, mj, g.mass_free[j] != 0) << 8;
#endif
}

// Contacts of the masses of segment i (bit q: mass q, the node then its envelope) in
// the volume of segment (a, a + 1), at axial parameters axial[q].
void emit(const SegmentGrid& g, std::size_t i, std::uint32_t a, std::uint32_t bits, const float* axial,
          std::vector<WispContact>& out) {
  const std::uint32_t k = g.seg[i] + 1;
  for (; bits != 0; bits &= bits - 1) {
    const int q = std::countr_zero(bits);
    if (q == 0)
      out.push_back({k, a, axial[q], 0});
    else
      out.push_back({static_cast<std::uint32_t>(kEnvelopePerSection * k + q - 1), a, axial[q], 1});
  }
}

// The masses of segment i in the volume of segment j, where near_pair found some near
// it (the full test, with the frame's square root and divisions); appends contacts to out.
void masses_in(const SegmentGrid& g, const WispSystem& s, std::size_t i, std::size_t j, std::vector<WispContact>& out) {
  const SegmentVolume& vol = g.vol[j];
  const SegmentMasses& m = g.mass[i];
  alignas(32) std::int32_t near[SegmentMasses::kWidth];
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
  std::uint32_t bits = 0;
  for (int q = 0; q < kMassesPerSegment; ++q) bits |= static_cast<std::uint32_t>(near[q]) << q;
  emit(g, i, vol.a, bits, axial, out);
}

#if defined(__AVX512F__) && defined(__AVX512DQ__)
// Two full tests at once: the masses of i1 against the volume of j1 in lanes 0-7, those
// of i2 against j2 in lanes 8-15 (issue 10: a test's chain of divisions and a square
// root is long, and a vector of 16 costs what one of 8 does). Each lane performs
// masses_in's operations in its order (unfused: -ffp-contract=off), so the same contacts
// with the same axial parameters; they are appended as the two masses_in would.
void masses_in_2(const SegmentGrid& g, const WispSystem& s, std::size_t i1, std::size_t j1, std::size_t i2,
                 std::size_t j2, std::vector<WispContact>& out) {
  const SegmentVolume &v1 = g.vol[j1], &v2 = g.vol[j2];
  const SegmentMasses &m1 = g.mass[i1], &m2 = g.mass[i2];
  auto add = [](__m512 a, __m512 b) { return _mm512_add_ps(a, b); };
  auto sub = [](__m512 a, __m512 b) { return _mm512_sub_ps(a, b); };
  auto mul = [](__m512 a, __m512 b) { return _mm512_mul_ps(a, b); };
  auto dot = [&](__m512 ax, __m512 ay, __m512 az, __m512 bx, __m512 by, __m512 bz) {
    return add(mul(ax, bx), add(mul(ay, by), mul(az, bz)));  // x + (y + z), as Eigen's
  };
  const __m512 mx = halves(m1.x, m2.x), my = halves(m1.y, m2.y), mz = halves(m1.z, m2.z);
  const __m512 xa0 = halves(v1.xa.x(), v2.xa.x()), xa1 = halves(v1.xa.y(), v2.xa.y()), xa2 = halves(v1.xa.z(), v2.xa.z());
  const __m512 d0 = halves(v1.d.x(), v2.d.x()), d1 = halves(v1.d.y(), v2.d.y()), d2 = halves(v1.d.z(), v2.d.z());
  const __m512 t0 = halves(v1.t.x(), v2.t.x()), t1 = halves(v1.t.y(), v2.t.y()), t2 = halves(v1.t.z(), v2.t.z());
  const Vec3f &ea1 = s.e1[v1.a], &eb1 = s.e1[v1.a + 1], &ea2 = s.e1[v2.a], &eb2 = s.e1[v2.a + 1];
  const float* r1 = &s.r[kEnvelopePerSection * v1.a];
  const float* r2 = &s.r[kEnvelopePerSection * v2.a];
  __m512 ra[kEnvelopePerSection], dr[kEnvelopePerSection];
  for (int q = 0; q < kEnvelopePerSection; ++q) {
    ra[q] = halves(r1[q], r2[q]);
    dr[q] = halves(r1[q + kEnvelopePerSection] - r1[q], r2[q + kEnvelopePerSection] - r2[q]);
  }
  const __m512 px = sub(mx, xa0), py = sub(my, xa1), pz = sub(mz, xa2);
  const __m512 u = _mm512_div_ps(dot(px, py, pz, d0, d1, d2), halves(v1.len2, v2.len2));
  const __m512 lx = sub(mx, add(xa0, mul(u, d0))), ly = sub(my, add(xa1, mul(u, d1)));
  const __m512 lz = sub(mz, add(xa2, mul(u, d2)));
  // The section axes interpolated along the segment, made orthonormal about its axis.
  const __m512 w = sub(_mm512_set1_ps(1.0f), u);
  __m512 ex = add(mul(w, halves(ea1.x(), ea2.x())), mul(u, halves(eb1.x(), eb2.x())));
  __m512 ey = add(mul(w, halves(ea1.y(), ea2.y())), mul(u, halves(eb1.y(), eb2.y())));
  __m512 ez = add(mul(w, halves(ea1.z(), ea2.z())), mul(u, halves(eb1.z(), eb2.z())));
  const __m512 et = dot(ex, ey, ez, t0, t1, t2);
  ex = sub(ex, mul(et, t0));
  ey = sub(ey, mul(et, t1));
  ez = sub(ez, mul(et, t2));
  const __m512 n2 = dot(ex, ey, ez, ex, ey, ez);
  const __mmask16 unit = _mm512_cmp_ps_mask(n2, _mm512_set1_ps(1e-24f), _CMP_GT_OQ);
  const __m512 len = _mm512_sqrt_ps(n2);
  ex = _mm512_mask_div_ps(halves(v1.t_orth.x(), v2.t_orth.x()), unit, ex, len);
  ey = _mm512_mask_div_ps(halves(v1.t_orth.y(), v2.t_orth.y()), unit, ey, len);
  ez = _mm512_mask_div_ps(halves(v1.t_orth.z(), v2.t_orth.z()), unit, ez, len);
  const __m512 fx = sub(mul(t1, ez), mul(t2, ey)), fy = sub(mul(t2, ex), mul(t0, ez));
  const __m512 fz = sub(mul(t0, ey), mul(t1, ex));
  const __m512 alpha = dot(lx, ly, lz, ex, ey, ez), beta = dot(lx, ly, lz, fx, fy, fz);
  const __m512 zero = _mm512_setzero_ps();
  const __m512 r_alpha = _mm512_mask_blend_ps(_mm512_cmp_ps_mask(alpha, zero, _CMP_GE_OQ), add(ra[2], mul(u, dr[2])),
                                              add(ra[0], mul(u, dr[0])));
  const __m512 r_beta = _mm512_mask_blend_ps(_mm512_cmp_ps_mask(beta, zero, _CMP_GE_OQ), add(ra[3], mul(u, dr[3])),
                                             add(ra[1], mul(u, dr[1])));
  const __m512 qa = _mm512_div_ps(alpha, r_alpha), qb = _mm512_div_ps(beta, r_beta);
  const __m512 f = add(mul(qa, qa), mul(qb, qb));
  const std::uint32_t bits = _mm512_cmp_ps_mask(u, zero, _CMP_GE_OQ) &
                             _mm512_cmp_ps_mask(u, _mm512_set1_ps(1.0f), _CMP_LE_OQ) &
                             _mm512_cmp_ps_mask(f, _mm512_set1_ps(1.0f), _CMP_LT_OQ);
  alignas(64) float axial[2 * SegmentMasses::kWidth];
  _mm512_store_ps(axial, u);
  constexpr std::uint32_t kHalf = (1u << kMassesPerSegment) - 1;
  emit(g, i1, v1.a, bits & kHalf, axial, out);
  emit(g, i2, v2.a, (bits >> SegmentMasses::kWidth) & kHalf, axial + SegmentMasses::kWidth, out);
}
#else
void masses_in_2(const SegmentGrid& g, const WispSystem& s, std::size_t i1, std::size_t j1, std::size_t i2,
                 std::size_t j2, std::vector<WispContact>& out) {
  masses_in(g, s, i1, j1, out);
  masses_in(g, s, i2, j2, out);
}
#endif

// The full tests near_pair leaves, two at a time (masses_in_2), appended in the order
// they were asked for.
class FullTests {
 public:
  FullTests(const SegmentGrid& g, const WispSystem& s, std::vector<WispContact>& out) : g_(g), s_(s), out_(out) {}
  ~FullTests() {
    if (pending_) masses_in(g_, s_, i_, j_, out_);
  }
  void add(std::size_t i, std::size_t j) {
    if (pending_) {
      masses_in_2(g_, s_, i_, j_, i, j, out_);
    } else {
      i_ = i;
      j_ = j;
    }
    pending_ = !pending_;
  }

 private:
  const SegmentGrid& g_;
  const WispSystem& s_;
  std::vector<WispContact>& out_;
  std::size_t i_ = 0, j_ = 0;
  bool pending_ = false;
};

// Items [b, e) of a cell whose boxes meet [lo, hi] (compared as the original
// (lo > hi).any() rejection, so NaN boxes are kept alike) and which are first met in
// this cell: each axis of `past` (bit a where the cell lies past the tested segment's
// cell_lo[a]) is set in their item_first (SegmentGrid::item_first). As bits from b on;
// e - b <= 32.
std::uint32_t overlapping(const SegmentGrid& g, std::uint32_t b, std::uint32_t e, const Vec3f& lo, const Vec3f& hi,
                          std::uint8_t past) {
  // Box tests into an array first (vector code), then gathered into bits.
  const float *lx = g.item_lo[0].data() + b, *ly = g.item_lo[1].data() + b, *lz = g.item_lo[2].data() + b;
  const float *hx = g.item_hi[0].data() + b, *hy = g.item_hi[1].data() + b, *hz = g.item_hi[2].data() + b;
  const std::uint8_t* first = g.item_first.data() + b;
  const std::uint32_t count = e - b;
  alignas(32) std::int32_t meet[32];
  for (std::uint32_t t = 0; t < count; ++t)
    meet[t] = !(lo.x() > hx[t]) & !(lx[t] > hi.x()) & !(lo.y() > hy[t]) & !(ly[t] > hi.y()) & !(lo.z() > hz[t]) &
              !(lz[t] > hi.z()) & ((first[t] & past) == past);
  std::uint32_t bits = 0;
  for (std::uint32_t t = 0; t < count; ++t) bits |= static_cast<std::uint32_t>(meet[t]) << t;
  return bits;
}

// The pairs the box tests leave, tested kDepth pairs after their loads were started:
// a pair's partner segment lies anywhere in memory, and near_pair's first use of its
// volume waited on the load (issue 10: the hottest instruction of the narrow phase).
// First in, first out: the pairs keep their order.
class PairQueue {
 public:
  PairQueue(const SegmentGrid& g, FullTests& full) : g_(g), full_(full) {}
  ~PairQueue() {
    while (head_ != tail_) test(ring_[head_++ % kDepth]);
  }
  void add(std::uint32_t i, std::uint32_t j) {
    __builtin_prefetch(&g_.vol[j]);
    __builtin_prefetch(&g_.mass[j]);
    __builtin_prefetch(reinterpret_cast<const char*>(&g_.mass[j]) + 64);
    if (tail_ - head_ == kDepth) test(ring_[head_++ % kDepth]);
    ring_[tail_++ % kDepth] = {i, j};
  }

 private:
  static constexpr std::uint32_t kDepth = 16;
  struct Pair {
    std::uint32_t i, j;
  };
  void test(Pair p) {
    const std::uint32_t near = near_pair(g_, p.i, p.j);
    if ((near & 0xff) != 0) full_.add(p.i, p.j);
    if ((near >> 8) != 0) full_.add(p.j, p.i);
  }
  const SegmentGrid& g_;
  FullTests& full_;
  Pair ring_[kDepth];
  std::uint32_t head_ = 0, tail_ = 0;
};

}  // namespace

void contacts(const SegmentGrid& g, const WispSystem& s, std::size_t begin, std::size_t end,
              std::vector<WispContact>& out) {
  auto index = [&](int x, int y, int z) { return (static_cast<std::size_t>(z) * g.dims.y() + y) * g.dims.x() + x; };
  FullTests full(g, s, out);
  PairQueue pairs(g, full);  // flushed before `full`
  for (std::size_t i = begin; i < end; ++i) {
    const auto i32 = static_cast<std::uint32_t>(i);
    const Eigen::Vector3i& lo = g.cell_lo[i];
    const std::uint32_t* self = g.self_items.data() + g.self_begin[i];
    for (int z = lo.z(); z <= g.cell_hi[i].z(); ++z)
      for (int y = lo.y(); y <= g.cell_hi[i].y(); ++y)
        for (int x = lo.x(); x <= g.cell_hi[i].x(); ++x) {
          const std::uint32_t stop = g.cell_start[index(x, y, z) + 1];
          const auto past = static_cast<std::uint8_t>((x != lo.x()) | (y != lo.y()) << 1 | (z != lo.z()) << 2);
          // A cell's items ascend: the later segments follow i's own entry. The box and
          // first-cell tests over a run of items at once; the wisp and narrow-phase tests
          // then for the pairs left, in item order: the same pairs in the same order as
          // testing each item in turn with a mailbox (grid_contacts_ref).
          for (std::uint32_t it = *self++ + 1; it < stop; it += 32) {
            for (std::uint32_t bits = overlapping(g, it, std::min(stop, it + 32), g.lo[i], g.hi[i], past); bits != 0;
                 bits &= bits - 1) {
              const std::uint32_t j = g.cell_items[it + static_cast<std::uint32_t>(std::countr_zero(bits))];
              // Later within a wisp: a wisp's segments are consecutive in seg, so j - i
              // is seg[j] - seg[i] there, and only the nearest need the wisp looked up.
              if (j - i32 < 3 && g.wisp[j] == g.wisp[i]) continue;
              pairs.add(i32, j);
            }
          }
        }
  }
}

#pragma GCC diagnostic pop

}  // namespace hairbench::kernels::wisp_soa::PLANTE_SOA_VARIANT
