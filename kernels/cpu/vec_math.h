// Elementary functions written so that a loop over lanes vectorises (libm's are calls).
#pragma once

namespace hairbench::kernels {

// sin x and cos x: x = k π/2 + r with |r| <= π/4 (Cody-Waite: π/2 in three parts, the
// first two with few significant bits so that k times them is exact for |k| < 64, i.e.
// |x| < 100), Taylor series of sin r to r^9 and cos r to r^10 (truncation below 3e-9 on
// |r| <= π/4, under float's half ulp), then the quadrant k mod 4 picks ±sin r or ±cos r.
// k is rounded with the 1.5·2^23 trick (round to nearest even for |v| < 2^22), which
// vectorises on every ISA. Within a few 1e-7 of std::sin / std::cos on |x| <= 100
// (tests/halen_fused_test.cpp).
inline void sincos_poly(float x, float& s, float& c) {
  constexpr float kTwoOverPi = 0.636619772367581343f;
  // π/2 = kP1 + kP2 + kP3; kP1 and kP2 have few significant bits, so k·kP1 and k·kP2 are exact.
  constexpr float kP1 = 1.5703125f, kP2 = 4.837512969970703125e-4f, kP3 = 7.54978995489188216e-8f;
  constexpr float kRound = 12582912.0f;  // 1.5 · 2^23
  const float kf = (x * kTwoOverPi + kRound) - kRound;
  // Past |x| ~ 1e5 the reduction is inexact (and float x has no fractional digits left);
  // the clamp keeps the results bounded there, |sin|, |cos| <= 1.0000001.
  const float r0 = ((x - kf * kP1) - kf * kP2) - kf * kP3;
  const float r = r0 < -0.8f ? -0.8f : r0 > 0.8f ? 0.8f : r0;
  const float r2 = r * r;
  const float sr = r + r * r2 * (-1.0f / 6 + r2 * (1.0f / 120 + r2 * (-1.0f / 5040 + r2 * (1.0f / 362880))));
  const float cr =
      1.0f + r2 * (-0.5f + r2 * (1.0f / 24 + r2 * (-1.0f / 720 + r2 * (1.0f / 40320 + r2 * (-1.0f / 3628800)))));
  const int q = static_cast<int>(kf) & 3;
  const bool swap = (q & 1) != 0;
  const float s0 = swap ? cr : sr, c0 = swap ? sr : cr;
  s = (q == 2 || q == 3) ? -s0 : s0;
  c = (q == 1 || q == 2) ? -c0 : c0;
}

}  // namespace hairbench::kernels
