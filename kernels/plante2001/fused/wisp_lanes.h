// Helpers of the lane loops of the wisp kernels (wisp_soa_kernel.cpp,
// wisp_contact_kernel.cpp): 3-vector arithmetic in Eigen's evaluation order for
// 3-vectors, so that a lane gets the bits of the per-wisp kernels (wisp_kernels.cpp): a
// dot product or squared norm is x + (y + z) (Eigen's unrolled reduction halves the
// terms), a vector over a scalar divides each component, sums of vector terms go left to
// right; and the transpose that fills their lanes. The kernel files are compiled once per
// ISA variant, so these have internal linkage: each variant keeps its own code.
#pragma once

#include <cmath>

#if defined(__AVX512F__)
#include <immintrin.h>
#endif

namespace hairbench::kernels::wisp_soa {
namespace {

struct F3 {
  float x, y, z;
};
inline F3 sub(F3 a, F3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
inline F3 add(F3 a, F3 b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
inline F3 mul(float s, F3 a) { return {s * a.x, s * a.y, s * a.z}; }
inline F3 quot(F3 a, float s) { return {a.x / s, a.y / s, a.z / s}; }
inline float dot(F3 a, F3 b) { return a.x * b.x + (a.y * b.y + a.z * b.z); }
inline F3 cross(F3 a, F3 b) { return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x}; }
inline F3 pick(bool c, F3 a, F3 b) { return {c ? a.x : b.x, c ? a.y : b.y, c ? a.z : b.z}; }
inline float lerp(float a, float b, float u) { return a + u * (b - a); }
// Vector i of an array of 3-vectors (Vec3f) read as floats; forced inline, since a call
// inside a lane loop keeps it scalar.
[[gnu::always_inline]] inline F3 load3(const float* p, int i) { return {p[3 * i], p[3 * i + 1], p[3 * i + 2]}; }

// unit_or of wisp_kernels.cpp; `bad` is set where the fallback would be taken (set
// without a branch, so that the lane loops stay vector code).
inline F3 unit(F3 v, int& bad) {
  const float n2 = dot(v, v);
  bad |= !(n2 > 1e-24f);
  return quot(v, std::sqrt(n2));
}

#if defined(__AVX512F__)
// A 16 x 16 transpose: element j of r[l] becomes element l of r[j]. With it, 16 runs of
// 16 floats (one a lane) become 16 rows of one float a lane, instead of 16 scalar moves a
// row. (GCC 12 warns that the unpack intrinsics' internal undefined operand may be
// uninitialised; it is a false positive, as in soa_rows.h.)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
inline void transpose16(__m512* r) {
  __m512 t[16], u[16];
  for (int a = 0; a < 16; a += 2) {
    t[a] = _mm512_unpacklo_ps(r[a], r[a + 1]);
    t[a + 1] = _mm512_unpackhi_ps(r[a], r[a + 1]);
  }
  // u[4g + c]: element c of each 128-bit part, of rows 4g..4g+3.
  for (int g = 0; g < 16; g += 4) {
    u[g] = _mm512_shuffle_ps(t[g], t[g + 2], 0x44);
    u[g + 1] = _mm512_shuffle_ps(t[g], t[g + 2], 0xEE);
    u[g + 2] = _mm512_shuffle_ps(t[g + 1], t[g + 3], 0x44);
    u[g + 3] = _mm512_shuffle_ps(t[g + 1], t[g + 3], 0xEE);
  }
  for (int c = 0; c < 4; ++c) {
    const __m512 p = _mm512_shuffle_f32x4(u[c], u[4 + c], 0x88), q = _mm512_shuffle_f32x4(u[c], u[4 + c], 0xDD);
    const __m512 p2 = _mm512_shuffle_f32x4(u[8 + c], u[12 + c], 0x88);
    const __m512 q2 = _mm512_shuffle_f32x4(u[8 + c], u[12 + c], 0xDD);
    r[c] = _mm512_shuffle_f32x4(p, p2, 0x88);
    r[8 + c] = _mm512_shuffle_f32x4(p, p2, 0xDD);
    r[4 + c] = _mm512_shuffle_f32x4(q, q2, 0x88);
    r[12 + c] = _mm512_shuffle_f32x4(q, q2, 0xDD);
  }
}
#pragma GCC diagnostic pop
#endif

}  // namespace
}  // namespace hairbench::kernels::wisp_soa
