// The narrow phase of the wisp-wisp interactions (wisp_soa.h, ContactsFn), compiled
// once per ISA variant like the block kernels (kernels/CMakeLists.txt): the box tests
// of a cell's candidates and the volume tests of a segment's masses run as vector code.
#include "kernels/plante2001/wisp_grid.h"
#include "kernels/plante2001/fused/wisp_soa.h"

#include <algorithm>
#include <bit>
#include <cmath>

#if defined(__x86_64__)
#include <immintrin.h>
#endif

namespace hairbench::kernels::wisp_soa::HAIRBENCH_ISA_VARIANT {

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

// Cheap bounds of the masses of segment i (node seg[i] + 1 and its envelope) against the
// volume of segment j, 8 lanes for its 5 masses: the axial one of the full test
// (masses_in), widened by far more than rounding (these sums may round otherwise, and the
// quotient by len2 is a product with its reciprocal), and the distance to the axis within
// vol.reach2. Most masses are outside one of them, and every mass the full test finds is
// inside both. Bit q for mass q; none where the masses are pinned or the volume is
// degenerate (it holds nothing), all where it is so thin that 1 / len2 overflows (the
// full test decides).
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
[[gnu::always_inline]] inline std::uint32_t near_pair(const SegmentGrid& g, std::size_t i, std::size_t j) {
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
// it (the full test, with the frame's square root and divisions): bit q where mass q is
// inside, at axial parameter axial[q] (8 of them).
std::uint32_t masses_in(const SegmentGrid& g, const WispSystem& s, std::size_t i, std::size_t j, float* axial) {
  const SegmentVolume& vol = g.vol[j];
  const SegmentMasses& m = g.mass[i];
  alignas(32) std::int32_t near[SegmentMasses::kWidth];
  // The full test (SegmentVolume), for all the masses at once: each lane performs the
  // operations of the per-point test (SegmentVolume::contains) in its order (Eigen's
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
  return bits;
}

#if defined(__AVX512F__) && defined(__AVX512DQ__)
// Two full tests at once: the masses of i1 against the volume of j1 in lanes 0-7, those
// of i2 against j2 in lanes 8-15 (a test's chain of divisions and a square root is long,
// and a vector of 16 costs what one of 8 does). Each lane performs masses_in's operations
// in its order (unfused: -ffp-contract=off), so the same contacts with the same axial
// parameters: the bits and axial parameters of the first test in bits 0-7 and
// axial[0, 8), those of the second in bits 8-15 and axial[8, 16).
std::uint32_t masses_in_2(const SegmentGrid& g, const WispSystem& s, std::size_t i1, std::size_t j1, std::size_t i2,
                          std::size_t j2, float* axial) {
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
  _mm512_store_ps(axial, u);
  constexpr std::uint32_t kHalf = (1u << kMassesPerSegment) - 1;
  return bits & (kHalf | kHalf << SegmentMasses::kWidth);
}
#else
std::uint32_t masses_in_2(const SegmentGrid& g, const WispSystem& s, std::size_t i1, std::size_t j1, std::size_t i2,
                          std::size_t j2, float* axial) {
  constexpr int L = SegmentMasses::kWidth;
  return masses_in(g, s, i1, j1, axial) | masses_in(g, s, i2, j2, axial + L) << L;
}
#endif

// Items [b, e) of a cell whose boxes meet [lo, hi] (compared as the original
// (lo > hi).any() rejection, so NaN boxes are kept alike), which are first met in this
// cell (each axis of `past`, bit a where the cell lies past the tested segment's
// cell_lo[a], is set in their item_first: SegmentGrid::item_first) and whose segment is
// `first_pair` or later. As bits from b on; e - b <= 32.
#if defined(__AVX512F__) && defined(__AVX512DQ__)
// 16 items per vector, the last ones by masked loads (a scalar remainder, as GCC makes
// for an 8-lane loop, would be a large share of the box tests' time: a cell's later
// items number 26 on average on shake).
std::uint32_t overlapping(const SegmentGrid& g, std::uint32_t b, std::uint32_t e, const Vec3f& lo, const Vec3f& hi,
                          std::uint8_t past, std::uint32_t first_pair) {
  const __m512 lx = _mm512_set1_ps(lo.x()), ly = _mm512_set1_ps(lo.y()), lz = _mm512_set1_ps(lo.z());
  const __m512 hx = _mm512_set1_ps(hi.x()), hy = _mm512_set1_ps(hi.y()), hz = _mm512_set1_ps(hi.z());
  const __m512i want = _mm512_set1_epi32(past), from = _mm512_set1_epi32(static_cast<int>(first_pair));
  std::uint32_t bits = 0;
  for (std::uint32_t t = b; t < e; t += 16) {
    const __mmask16 live = e - t >= 16 ? 0xffff : static_cast<__mmask16>((1u << (e - t)) - 1);
    auto load = [&](const std::vector<float>& v) { return _mm512_maskz_loadu_ps(live, v.data() + t); };
    // !(x > y) is true on NaN, as the scalar form: the quiet "not greater" predicate.
    __mmask16 m = _mm512_mask_cmp_ps_mask(live, lx, load(g.item_hi[0]), _CMP_NGT_UQ);
    m = _mm512_mask_cmp_ps_mask(m, load(g.item_lo[0]), hx, _CMP_NGT_UQ);
    m = _mm512_mask_cmp_ps_mask(m, ly, load(g.item_hi[1]), _CMP_NGT_UQ);
    m = _mm512_mask_cmp_ps_mask(m, load(g.item_lo[1]), hy, _CMP_NGT_UQ);
    m = _mm512_mask_cmp_ps_mask(m, lz, load(g.item_hi[2]), _CMP_NGT_UQ);
    m = _mm512_mask_cmp_ps_mask(m, load(g.item_lo[2]), hz, _CMP_NGT_UQ);
    m = _mm512_mask_cmpge_epu32_mask(m, _mm512_maskz_loadu_epi32(live, g.cell_items.data() + t), from);
    if (past != 0) {
      const __m512i first = _mm512_cvtepu8_epi32(_mm_maskz_loadu_epi8(live, g.item_first.data() + t));
      m = _mm512_mask_cmpeq_epi32_mask(m, _mm512_and_si512(first, want), want);
    }
    bits |= static_cast<std::uint32_t>(m) << (t - b);
  }
  return bits;
}
#else
std::uint32_t overlapping(const SegmentGrid& g, std::uint32_t b, std::uint32_t e, const Vec3f& lo, const Vec3f& hi,
                          std::uint8_t past, std::uint32_t first_pair) {
  // Box tests into an array first (vector code), then gathered into bits.
  const float *lx = g.item_lo[0].data() + b, *ly = g.item_lo[1].data() + b, *lz = g.item_lo[2].data() + b;
  const float *hx = g.item_hi[0].data() + b, *hy = g.item_hi[1].data() + b, *hz = g.item_hi[2].data() + b;
  const std::uint8_t* first = g.item_first.data() + b;
  const std::uint32_t* item = g.cell_items.data() + b;
  const std::uint32_t count = e - b;
  alignas(32) std::int32_t meet[32];
  for (std::uint32_t t = 0; t < count; ++t)
    meet[t] = !(lo.x() > hx[t]) & !(lx[t] > hi.x()) & !(lo.y() > hy[t]) & !(ly[t] > hi.y()) & !(lo.z() > hz[t]) &
              !(lz[t] > hi.z()) & ((first[t] & past) == past) & (item[t] >= first_pair);
  std::uint32_t bits = 0;
  for (std::uint32_t t = 0; t < count; ++t) bits |= static_cast<std::uint32_t>(meet[t]) << t;
  return bits;
}
#endif

// The pairs the box tests leave, tested in batches, in order. Their loads are started as
// they are added: a pair's partner segment lies anywhere in memory. Then, per batch:
// near_pair of every pair (independent, so their chains of vector operations overlap;
// tested one at a time, each would wait on the last one's branches), the full tests they
// leave as a list (written without a branch: about a third of the directions go either
// way), and those tests two at a time (masses_in_2). The contacts come out as testing
// each pair in turn appends them: masses of i in j, then of j in i.
class PairBatch {
 public:
  PairBatch(const SegmentGrid& g, const WispSystem& s, std::vector<WispContact>& out) : g_(g), s_(s), out_(out) {}
  ~PairBatch() { flush(); }
  PairBatch(const PairBatch&) = delete;
  PairBatch& operator=(const PairBatch&) = delete;
  void add(std::uint32_t i, std::uint32_t j) {
    __builtin_prefetch(&g_.vol[j]);
    __builtin_prefetch(&g_.mass[j]);
    __builtin_prefetch(reinterpret_cast<const char*>(&g_.mass[j]) + 64);
    pairs_[count_++] = {i, j};
    if (count_ == kBatch) flush();
  }

 private:
  static constexpr std::uint32_t kBatch = 128;
  struct Pair {
    std::uint32_t i, j;
  };
  void flush() {
    for (std::uint32_t k = 0; k < count_; ++k) near_[k] = near_pair(g_, pairs_[k].i, pairs_[k].j);
    std::uint32_t n = 0;
    for (std::uint32_t k = 0; k < count_; ++k) {
      full_[n] = pairs_[k];
      n += (near_[k] & 0xff) != 0;
      full_[n] = {pairs_[k].j, pairs_[k].i};
      n += (near_[k] >> 8) != 0;
    }
    constexpr int L = SegmentMasses::kWidth;
    for (std::uint32_t t = 0; t + 1 < n; t += 2) {
      const Pair a = full_[t], b = full_[t + 1];
      const std::uint32_t bits = masses_in_2(g_, s_, a.i, a.j, b.i, b.j, &axial_[t][0]);
      inside_[t] = bits & ((1u << L) - 1);
      inside_[t + 1] = bits >> L;
    }
    if (n % 2 != 0) inside_[n - 1] = masses_in(g_, s_, full_[n - 1].i, full_[n - 1].j, &axial_[n - 1][0]);
    for (std::uint32_t t = 0; t < n; ++t) emit(g_, full_[t].i, g_.seg[full_[t].j], inside_[t], &axial_[t][0], out_);
    count_ = 0;
  }
  const SegmentGrid& g_;
  const WispSystem& s_;
  std::vector<WispContact>& out_;
  std::uint32_t count_ = 0;
  Pair pairs_[kBatch];
  std::uint32_t near_[kBatch];
  Pair full_[2 * kBatch + 1];
  // Per full test: its masses inside, and their axial parameters (masses_in_2 writes two
  // tests' lanes at once).
  std::uint32_t inside_[2 * kBatch];
  alignas(64) float axial_[2 * kBatch][SegmentMasses::kWidth];
};

}  // namespace

void contacts(const SegmentGrid& g, const WispSystem& s, std::size_t begin, std::size_t end,
              std::vector<WispContact>& out) {
  PairBatch pairs(g, s, out);
  for (std::size_t i = begin; i < end; ++i) {
    const auto i32 = static_cast<std::uint32_t>(i);
    // Segments less than three apart along a wisp are no pair. A wisp's segments are
    // consecutive in seg, so these are the ones after i up to its wisp's end: the later
    // segments j of i's cells pair with it from first_pair on, which the box tests check
    // (checking wisp[j] per pair left would put the load of j on the path of the next
    // pair's).
    std::uint32_t first_pair = i32 + 1;
    while (first_pair < i32 + 3 && first_pair < g.size() && g.wisp[first_pair] == g.wisp[i]) ++first_pair;
    const Eigen::Vector3i& lo = g.cell_lo[i];
    const std::uint32_t* self = g.self_items.data() + g.self_begin[i];
    for (int z = lo.z(); z <= g.cell_hi[i].z(); ++z)
      for (int y = lo.y(); y <= g.cell_hi[i].y(); ++y)
        for (int x = lo.x(); x <= g.cell_hi[i].x(); ++x) {
          const std::uint32_t stop = g.cell_start[g.cell_at(x, y, z) + 1];
          const auto past = static_cast<std::uint8_t>((x != lo.x()) | (y != lo.y()) << 1 | (z != lo.z()) << 2);
          // A cell's items ascend: the later segments follow i's own entry. The box,
          // first-cell and wisp tests over a run of items at once; the narrow-phase tests
          // then for the pairs left, in item order: the same pairs in the same order as
          // testing each item in turn with a mailbox (grid_contacts_ref).
          for (std::uint32_t it = *self++ + 1; it < stop; it += 32) {
            std::uint32_t bits = overlapping(g, it, std::min(stop, it + 32), g.lo[i], g.hi[i], past, first_pair);
            for (; bits != 0; bits &= bits - 1)
              pairs.add(i32, g.cell_items[it + static_cast<std::uint32_t>(std::countr_zero(bits))]);
          }
        }
  }
}

#pragma GCC diagnostic pop

}  // namespace hairbench::kernels::wisp_soa::HAIRBENCH_ISA_VARIANT
