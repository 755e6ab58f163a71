// Row operations shared by the block kernels (han_soa, halen_soa): rows of 16 lanes, one
// strand per lane. The kernel files are compiled once per ISA variant, so these have
// internal linkage: each variant keeps its own code (an inline function with external
// linkage would be merged across the variants by the linker).
#pragma once

#include "kernels/simd/soa_common.h"

#include <bit>
#include <cstddef>
#include <cstdint>

#if defined(__AVX512F__)
#include <immintrin.h>
#endif

namespace hairbench::kernels::soa {
namespace {

inline constexpr int kRowLanes = 16;

// A pinned row follows the head (follow_head of the per-strand kernels): prev = pos,
// pos = head · rest, in Eigen's order (AffinePose). The pose is taken by value: through a
// reference the compiler must assume the row stores may change it, and leaves the lane
// loop scalar.
inline void follow_head_row(const AffinePose h, float* __restrict px, float* __restrict py, float* __restrict pz,
                            float* __restrict qx, float* __restrict qy, float* __restrict qz, const float* rx,
                            const float* ry, const float* rz) {
  _Pragma("GCC ivdep") for (int l = 0; l < kRowLanes; ++l) {
    const float x = px[l], y = py[l], z = pz[l];
    px[l] = h.x(rx[l], ry[l], rz[l]);
    py[l] = h.y(rx[l], ry[l], rz[l]);
    pz[l] = h.z(rx[l], ry[l], rz[l]);
    qx[l] = x;
    qy[l] = y;
    qz[l] = z;
  }
}

// Whether two rows hold the same bits in every lane (a sphere collision pass that leaves
// a row so would leave it so again: the collide functions stop there).
inline bool same_bits(const float* a, const float* b) {
  std::uint32_t diff = 0;
  _Pragma("GCC ivdep") for (int l = 0; l < kRowLanes; ++l) diff |=
      std::bit_cast<std::uint32_t>(a[l]) ^ std::bit_cast<std::uint32_t>(b[l]);
  return diff == 0;
}

// Rows 0..n-1 of x, y, z and w (16 lanes each, consecutive rows 16 floats apart) to
// lane_out[l] + 4 i, float4 per vertex, for every lane whose lane_out[l] is not null. With
// AVX-512, a transpose of each row's four vectors into one float4 per lane: sixteen 16-byte
// stores a row instead of 64 scalar ones. (GCC 12 warns that the unpack intrinsics'
// internal undefined operand may be uninitialised; it is a false positive.)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
inline void write_rows_float4(const float* x, const float* y, const float* z, const float* w, int n,
                              float* const* lane_out) {
#if defined(__AVX512F__)
  for (int i = 0; i < n; ++i) {
    const __m512 vx = _mm512_loadu_ps(x + i * kRowLanes), vy = _mm512_loadu_ps(y + i * kRowLanes),
                 vz = _mm512_loadu_ps(z + i * kRowLanes), vw = _mm512_loadu_ps(w + i * kRowLanes);
    const __m512 t0 = _mm512_unpacklo_ps(vx, vy), t1 = _mm512_unpackhi_ps(vx, vy);
    const __m512 t2 = _mm512_unpacklo_ps(vz, vw), t3 = _mm512_unpackhi_ps(vz, vw);
    // v[m] holds lane 4k + m's float4 in its 128-bit part k.
    const __m512 v[4] = {_mm512_shuffle_ps(t0, t2, _MM_SHUFFLE(1, 0, 1, 0)),
                         _mm512_shuffle_ps(t0, t2, _MM_SHUFFLE(3, 2, 3, 2)),
                         _mm512_shuffle_ps(t1, t3, _MM_SHUFFLE(1, 0, 1, 0)),
                         _mm512_shuffle_ps(t1, t3, _MM_SHUFFLE(3, 2, 3, 2))};
    const std::size_t o = 4 * static_cast<std::size_t>(i);
    for (int m = 0; m < 4; ++m) {
      if (lane_out[m]) _mm_storeu_ps(lane_out[m] + o, _mm512_extractf32x4_ps(v[m], 0));
      if (lane_out[4 + m]) _mm_storeu_ps(lane_out[4 + m] + o, _mm512_extractf32x4_ps(v[m], 1));
      if (lane_out[8 + m]) _mm_storeu_ps(lane_out[8 + m] + o, _mm512_extractf32x4_ps(v[m], 2));
      if (lane_out[12 + m]) _mm_storeu_ps(lane_out[12 + m] + o, _mm512_extractf32x4_ps(v[m], 3));
    }
  }
#else
  for (int l = 0; l < kRowLanes; ++l) {
    float* o = lane_out[l];
    if (!o) continue;
    for (int i = 0; i < n; ++i) {
      o[4 * i] = x[i * kRowLanes + l];
      o[4 * i + 1] = y[i * kRowLanes + l];
      o[4 * i + 2] = z[i * kRowLanes + l];
      o[4 * i + 3] = w[i * kRowLanes + l];
    }
  }
#endif
}

// The inverse of write_rows_float4: lane_in[l] + 4 i (float4 per vertex, every lane
// non-null) to rows 0..n-1 of x, y, z and w. With AVX-512, each row's sixteen float4
// loads go into four vectors (lane 4k + m in v[m]'s 128-bit part k) and a 4x4 transpose
// within each 128-bit part gives the rows.
inline void read_rows_float4(const float* const* lane_in, int n, float* x, float* y, float* z, float* w) {
#if defined(__AVX512F__)
  for (int i = 0; i < n; ++i) {
    const std::size_t o = 4 * static_cast<std::size_t>(i);
    __m512 v[4];
    for (int m = 0; m < 4; ++m) {
      const __m512 k0 = _mm512_castps128_ps512(_mm_loadu_ps(lane_in[m] + o));
      const __m512 k1 = _mm512_insertf32x4(k0, _mm_loadu_ps(lane_in[4 + m] + o), 1);
      const __m512 k2 = _mm512_insertf32x4(k1, _mm_loadu_ps(lane_in[8 + m] + o), 2);
      v[m] = _mm512_insertf32x4(k2, _mm_loadu_ps(lane_in[12 + m] + o), 3);
    }
    const __m512 a0 = _mm512_unpacklo_ps(v[0], v[1]), a1 = _mm512_unpacklo_ps(v[2], v[3]);
    const __m512 a2 = _mm512_unpackhi_ps(v[0], v[1]), a3 = _mm512_unpackhi_ps(v[2], v[3]);
    _mm512_storeu_ps(x + i * kRowLanes, _mm512_shuffle_ps(a0, a1, _MM_SHUFFLE(1, 0, 1, 0)));
    _mm512_storeu_ps(y + i * kRowLanes, _mm512_shuffle_ps(a0, a1, _MM_SHUFFLE(3, 2, 3, 2)));
    _mm512_storeu_ps(z + i * kRowLanes, _mm512_shuffle_ps(a2, a3, _MM_SHUFFLE(1, 0, 1, 0)));
    _mm512_storeu_ps(w + i * kRowLanes, _mm512_shuffle_ps(a2, a3, _MM_SHUFFLE(3, 2, 3, 2)));
  }
#else
  for (int l = 0; l < kRowLanes; ++l) {
    const float* in = lane_in[l];
    for (int i = 0; i < n; ++i) {
      x[i * kRowLanes + l] = in[4 * i];
      y[i * kRowLanes + l] = in[4 * i + 1];
      z[i * kRowLanes + l] = in[4 * i + 2];
      w[i * kRowLanes + l] = in[4 * i + 3];
    }
  }
#endif
}
#pragma GCC diagnostic pop

}  // namespace
}  // namespace hairbench::kernels::soa
