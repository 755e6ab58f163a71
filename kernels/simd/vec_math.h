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

// atan2(y, x) for y > 0: the angle in (0, π) between two directions, from |a × b| and
// a · b. libm's atan2f is a call, which keeps the lane loops around it scalar.
// Reduction: q = min(y, |x|) / max(y, |x|) in [0, 1], and atan q = π/4 +
// atan((q - 1) / (q + 1)) above tan(π/8), so that the polynomial's argument t has
// |t| <= tan(π/8); atan t = t + t^3 P(t^2), P of degree 4 with coefficients fitted to
// atan's relative error on that interval (0.66 ulp there in float arithmetic as
// written). Then π/2 - a where y > |x|, and π - a where x < 0. One division:
// (q - 1) / (q + 1) = (lo - hi) / (lo + hi). Its rounding just above tan(π/8) is the
// worst case: within 3 ulp of atan2 on the upper half plane (tests/plante_test.cpp).
// NaN in, NaN out.
inline float atan2_upper(float y, float x) {
  constexpr float kTanPi8 = 0.414213562373095f;
  constexpr float kPi4 = 0.785398163397448f, kPi2 = 1.57079632679490f, kPi = 3.14159265358979f;
  constexpr float kC0 = -0.33333316445350647f, kC1 = 0.19998471438884735f, kC2 = -0.14243534207344055f,
                  kC3 = 0.1059381440281868f, kC4 = -0.060782235115766525f;
  const float ax = x < 0.0f ? -x : x;
  const bool steep = y > ax;
  const float hi = steep ? y : ax, lo = steep ? ax : y;
  const bool big = lo > kTanPi8 * hi;
  const float t = big ? (lo - hi) / (lo + hi) : lo / hi;
  const float t2 = t * t;
  const float p = t + t * t2 * (kC0 + t2 * (kC1 + t2 * (kC2 + t2 * (kC3 + t2 * kC4))));
  const float a = big ? kPi4 + p : p;    // atan(lo / hi), in [0, π/4]
  const float b = steep ? kPi2 - a : a;  // atan(y / |x|), in [0, π/2]
  return x < 0.0f ? kPi - b : b;
}

}  // namespace hairbench::kernels
