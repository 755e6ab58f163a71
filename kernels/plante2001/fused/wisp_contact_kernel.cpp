// The impulses of the wisp-wisp contacts (wisp_soa.h, ImpulsesFn) for kLanes contacts at
// once, one contact per lane. Each lane performs the operations of contact_impulse
// (wisp_kernels.cpp, §4.1) in their order (wisp_lanes.h), so it gets the same bits; a
// lane whose plane normal falls back to an arbitrary orthogonal (wisps parallel and the
// point on the segment's axis) is redone by contact_impulse. Compiled once per ISA
// variant, like the block kernels (kernels/CMakeLists.txt).
#include "kernels/plante2001/fused/wisp_lanes.h"
#include "kernels/plante2001/fused/wisp_soa.h"

#include <algorithm>
#include <cmath>
#include <cstdint>

#ifndef HAIRBENCH_ISA_VARIANT
#error "HAIRBENCH_ISA_VARIANT must name the ISA variant"
#endif

namespace hairbench::kernels::wisp_soa::HAIRBENCH_ISA_VARIANT {

namespace {

constexpr int W = kLanes;

// A lane's inputs, read from the contact and the rows of its nodes (the contact's point
// and the segment it is in), coordinate by coordinate: [i][l] is coordinate i of lane l.
struct Lanes {
  alignas(64) float p[3][W];  // the point
  alignas(64) float vp[3][W];  // its velocity
  alignas(64) float d[3][W];   // an envelope point's direction (0 for a node)
  alignas(64) float sp[3][W];  // sigma_p: the point's node's section normal
  alignas(64) float xa[3][W], xb[3][W];  // the segment's first and second node
  alignas(64) float va[3][W], vb[3][W];
  alignas(64) float na[3][W];  // the first node's section normal (unit_or's fallback)
  alignas(64) float ra[kEnvelopePerSection][W], rb[kEnvelopePerSection][W];  // envelope radii at a, a + 1
  alignas(64) float r0a[W], r0b[W];  // rest radii
  alignas(64) float u[W], mp[W];
  alignas(64) std::int32_t envelope[W];
};

using N = ContactNode;

#if defined(__AVX512F__) && defined(__AVX512DQ__)
// Contacts [b, b + W) into the lanes (lanes past count repeat the first contact): each
// contact's three node rows, 16 contacts at a time, turned into lanes by transposes.
// p and vp as contact_impulse forms them: x + r dir, componentwise, on envelope points.
void load(const ContactNode* nodes, std::span<const WispContact> contacts, std::size_t b, int count, Lanes& in) {
  __m512 point_a[W], point_b[W], seg_a[W], seg_b[W];
  alignas(64) std::int32_t q[W];
  for (int l = 0; l < W; ++l) {
    const WispContact& c = contacts[b + (l < count ? l : 0)];
    const std::uint32_t k = c.envelope ? c.point / kEnvelopePerSection : c.point;
    point_a[l] = _mm512_load_ps(nodes[k].a);
    point_b[l] = _mm512_load_ps(nodes[k].b);
    seg_a[l] = _mm512_load_ps(nodes[c.seg].a);
    seg_b[l] = _mm512_load_ps(nodes[c.seg + 1].a);
    in.u[l] = c.u;
    in.envelope[l] = c.envelope;
    q[l] = static_cast<std::int32_t>(c.point % kEnvelopePerSection);
  }
  transpose16(point_a);
  transpose16(point_b);
  transpose16(seg_a);
  transpose16(seg_b);
  const __m512i qv = _mm512_load_si512(q);
  const __mmask16 env = _mm512_test_epi32_mask(_mm512_load_si512(in.envelope), _mm512_set1_epi32(0xff));
  const __mmask16 q1 = _mm512_cmpeq_epi32_mask(qv, _mm512_set1_epi32(1));
  const __mmask16 q2 = _mm512_cmpeq_epi32_mask(qv, _mm512_set1_epi32(2));
  const __mmask16 q3 = _mm512_cmpeq_epi32_mask(qv, _mm512_set1_epi32(3));
  auto of_q = [&](const __m512* rows) {  // rows[q] per lane
    __m512 v = _mm512_mask_mov_ps(rows[0], q1, rows[1]);
    v = _mm512_mask_mov_ps(v, q2, rows[2]);
    return _mm512_mask_mov_ps(v, q3, rows[3]);
  };
  const __m512 r = of_q(point_a + N::kR), rd = of_q(point_b + N::kRdot);
  for (int i = 0; i < 3; ++i) {
    // envelope_dir: e1, e2, -e1, -e2 for q = 0..3 (negated by the sign bit, as Eigen).
    __m512 dir = _mm512_mask_mov_ps(point_b[N::kE1 + i], q1 | q3, point_b[N::kE2 + i]);
    dir = _mm512_mask_xor_ps(dir, q2 | q3, dir, _mm512_set1_ps(-0.0f));
    dir = _mm512_maskz_mov_ps(env, dir);
    const __m512 x = point_a[N::kX + i], v = point_a[N::kV + i];
    _mm512_store_ps(in.p[i], _mm512_mask_add_ps(x, env, x, _mm512_mul_ps(r, dir)));
    _mm512_store_ps(in.vp[i], _mm512_mask_add_ps(v, env, v, _mm512_mul_ps(rd, dir)));
    _mm512_store_ps(in.d[i], dir);
    _mm512_store_ps(in.sp[i], point_a[N::kN + i]);
    _mm512_store_ps(in.xa[i], seg_a[N::kX + i]);
    _mm512_store_ps(in.xb[i], seg_b[N::kX + i]);
    _mm512_store_ps(in.va[i], seg_a[N::kV + i]);
    _mm512_store_ps(in.vb[i], seg_b[N::kV + i]);
    _mm512_store_ps(in.na[i], seg_a[N::kN + i]);
  }
  for (int e = 0; e < kEnvelopePerSection; ++e) {
    _mm512_store_ps(in.ra[e], seg_a[N::kR + e]);
    _mm512_store_ps(in.rb[e], seg_b[N::kR + e]);
  }
  _mm512_store_ps(in.r0a, seg_a[N::kRRest]);
  _mm512_store_ps(in.r0b, seg_b[N::kRRest]);
  _mm512_store_ps(in.mp, _mm512_mask_mov_ps(_mm512_set1_ps(1.0f), env, point_a[N::kEnvelopeMass]));
}
#else
// The same, lane by lane.
void load(const ContactNode* nodes, std::span<const WispContact> contacts, std::size_t b, int count, Lanes& in) {
  for (int l = 0; l < W; ++l) {
    const WispContact& c = contacts[b + (l < count ? l : 0)];
    const std::uint32_t k = c.envelope ? c.point / kEnvelopePerSection : c.point;
    const ContactNode &point = nodes[k], &na = nodes[c.seg], &nb = nodes[c.seg + 1];
    const int q = static_cast<int>(c.point % kEnvelopePerSection);
    const float r = c.envelope ? point.a[N::kR + q] : 0.0f, rd = c.envelope ? point.b[N::kRdot + q] : 0.0f;
    for (int i = 0; i < 3; ++i) {
      const float e = point.b[(q & 1 ? N::kE2 : N::kE1) + i];
      const float dir = c.envelope ? (q >= 2 ? -e : e) : 0.0f;  // envelope_dir
      in.p[i][l] = c.envelope ? point.a[N::kX + i] + r * dir : point.a[N::kX + i];
      in.vp[i][l] = c.envelope ? point.a[N::kV + i] + rd * dir : point.a[N::kV + i];
      in.d[i][l] = dir;
      in.sp[i][l] = point.a[N::kN + i];
      in.xa[i][l] = na.a[N::kX + i];
      in.xb[i][l] = nb.a[N::kX + i];
      in.va[i][l] = na.a[N::kV + i];
      in.vb[i][l] = nb.a[N::kV + i];
      in.na[i][l] = na.a[N::kN + i];
    }
    for (int e = 0; e < kEnvelopePerSection; ++e) {
      in.ra[e][l] = na.a[N::kR + e];
      in.rb[e][l] = nb.a[N::kR + e];
    }
    in.r0a[l] = na.a[N::kRRest];
    in.r0b[l] = nb.a[N::kRRest];
    in.u[l] = c.u;
    in.mp[l] = c.envelope ? point.a[N::kEnvelopeMass] : 1.0f;
    in.envelope[l] = c.envelope;
  }
}
#endif

}  // namespace

// contact_impulse, lane by lane; see there for the physics.
void impulses(const WispSystem& s, const ContactNode* nodes, std::span<const WispContact> contacts, std::size_t begin,
              std::size_t end, const InteractionParams& ip, std::span<const WispParams> params, float h,
              ContactImpulse* out) {
  Lanes in;
  float ix[W], iy[W], iz[W], dr[W], share[W];
  int bad[W];
  constexpr float kMinSin = 0.087f;  // as contact_impulse
  for (std::size_t b = begin; b < end; b += W) {
    const int count = static_cast<int>(std::min<std::size_t>(W, end - b));
    load(nodes, contacts, b, count, in);
    _Pragma("GCC ivdep") for (int l = 0; l < W; ++l) {
      bad[l] = 0;
      const F3 p{in.p[0][l], in.p[1][l], in.p[2][l]}, vp{in.vp[0][l], in.vp[1][l], in.vp[2][l]};
      const F3 xa{in.xa[0][l], in.xa[1][l], in.xa[2][l]}, xb{in.xb[0][l], in.xb[1][l], in.xb[2][l]};
      const float u = in.u[l];
      const F3 axis = sub(xb, xa);
      // unit_or(axis, n[a]) as a select: its fallback is at hand.
      const float axis2 = dot(axis, axis);
      const F3 sigma_s = pick(axis2 > 1e-24f, quot(axis, std::sqrt(axis2)), F3{in.na[0][l], in.na[1][l], in.na[2][l]});
      const F3 sigma_p{in.sp[0][l], in.sp[1][l], in.sp[2][l]};
      const F3 vs = add(mul(1.0f - u, F3{in.va[0][l], in.va[1][l], in.va[2][l]}), mul(u, F3{in.vb[0][l], in.vb[1][l], in.vb[2][l]}));
      const F3 rel = sub(vp, vs);
      F3 dv{-rel.x, -rel.y, -rel.z};
      const bool near_parallel = std::abs(dot(sigma_p, sigma_s)) >= ip.parallel_cos;
      F3 nrm = cross(sigma_p, sigma_s);
      const F3 in_plane = cross(sigma_s, sub(p, add(xa, mul(u, axis))));
      nrm = pick(dot(nrm, nrm) < kMinSin * kMinSin, in_plane, nrm);
      int no_normal = 0;
      nrm = unit(nrm, no_normal);
      bad[l] = near_parallel & no_normal;
      const float out_of_plane = dot(rel, nrm);
      const bool in_plane_motion = std::abs(out_of_plane) <= ip.in_plane_sin * std::sqrt(dot(rel, rel));
      const float radius0 = lerp(in.ra[0][l], in.rb[0][l], u), radius1 = lerp(in.ra[1][l], in.rb[1][l], u);
      const float radius2 = lerp(in.ra[2][l], in.rb[2][l], u), radius3 = lerp(in.ra[3][l], in.rb[3][l], u);
      const float r0 = lerp(in.r0a[l], in.r0b[l], u);
      const float area = 0.25f * (radius0 + radius2) * (radius1 + radius3);
      const float density = area > 0.0f ? r0 * r0 / area : 1.0f;
      const float drag = std::min(1.0f, ip.hair_friction * density * h);
      const F3 normal_part = mul(out_of_plane, nrm);
      const F3 sliding = sub(mul(-out_of_plane, nrm), mul(drag, sub(rel, normal_part)));
      dv = pick(near_parallel && in_plane_motion, sliding, dv);
      const float mp = in.mp[l];
      const F3 dvp = mul(1.0f / (1.0f + mp), dv);
      share[l] = 2.0f * mp / (1.0f + mp);
      const F3 dir{in.d[0][l], in.d[1][l], in.d[2][l]};
      const float d = dot(dvp, dir);
      const F3 impulse = pick(in.envelope[l] != 0, mul(mp * d, dir), dvp);
      ix[l] = impulse.x;
      iy[l] = impulse.y;
      iz[l] = impulse.z;
      dr[l] = in.envelope[l] ? d : 0.0f;
    }
    for (int l = 0; l < count; ++l) {
      const WispContact& c = contacts[b + l];
      const std::uint32_t k = c.envelope ? c.point / kEnvelopePerSection : c.point;
      if (bad[l] || s.pinned[k])
        out[b + l] = contact_impulse(s, c, ip, params, h);
      else
        out[b + l] = {Vec3f(ix[l], iy[l], iz[l]), dr[l], share[l], true};
    }
  }
}

}  // namespace hairbench::kernels::wisp_soa::HAIRBENCH_ISA_VARIANT
