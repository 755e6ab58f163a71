// The block kernels' (han_soa, halen_soa) last step of a frame: a block's rows back to the
// groom-ordered float4 array. The kernel files are compiled once per ISA variant, so this
// has internal linkage: each variant keeps its own code (an inline function with external
// linkage would be merged across the variants by the linker).
#pragma once

#include <cstddef>

#if defined(__AVX512F__)
#include <immintrin.h>
#endif

namespace hairbench::kernels::soa {
namespace {

// Rows 0..n-1 of x, y, z and w (16 lanes each, consecutive rows 16 floats apart) to
// lane_out[l] + 4 i, float4 per vertex, for every lane whose lane_out[l] is not null. With
// AVX-512, a transpose of each row's four vectors into one float4 per lane: sixteen 16-byte
// stores a row instead of 64 scalar ones. (GCC 12 warns that the unpack intrinsics'
// internal undefined operand may be uninitialised; it is a false positive.)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
inline void write_rows_float4(const float* x, const float* y, const float* z, const float* w, int n,
                              float* const* lane_out) {
  constexpr int kW = 16;
#if defined(__AVX512F__)
  for (int i = 0; i < n; ++i) {
    const __m512 vx = _mm512_loadu_ps(x + i * kW), vy = _mm512_loadu_ps(y + i * kW),
                 vz = _mm512_loadu_ps(z + i * kW), vw = _mm512_loadu_ps(w + i * kW);
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
  for (int l = 0; l < kW; ++l) {
    float* o = lane_out[l];
    if (!o) continue;
    for (int i = 0; i < n; ++i) {
      o[4 * i] = x[i * kW + l];
      o[4 * i + 1] = y[i * kW + l];
      o[4 * i + 2] = z[i * kW + l];
      o[4 * i + 3] = w[i * kW + l];
    }
  }
#endif
}
#pragma GCC diagnostic pop

}  // namespace
}  // namespace hairbench::kernels::soa
