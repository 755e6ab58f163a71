// The impulses of the wisp-wisp contacts (wisp_soa.h, ImpulsesFn) for kLanes contacts
// at once, one contact per lane (issue 10). Each lane performs the operations of
// contact_impulse (wisp_kernels.cpp, §4.1) in their order (wisp_lanes.h), so it gets the
// same bits; a lane whose plane normal falls back to an arbitrary orthogonal (wisps
// parallel and the point on the segment's axis) is redone by contact_impulse. Compiled
// once per ISA variant, like the block kernels (kernels/CMakeLists.txt).
#include "kernels/cpu/wisp_lanes.h"
#include "kernels/cpu/wisp_soa.h"

#include <algorithm>
#include <cmath>

#ifndef PLANTE_SOA_VARIANT
#error "PLANTE_SOA_VARIANT must name the ISA variant"
#endif

namespace hairbench::kernels::wisp_soa::PLANTE_SOA_VARIANT {

namespace {

constexpr int W = kLanes;

// A lane's inputs, read from the contact and the state (the contact's point and the
// segment it is in), coordinate by coordinate.
struct Lanes {
  float px[W], py[W], pz[W];     // the point
  float vpx[W], vpy[W], vpz[W];  // its velocity
  float dx[W], dy[W], dz[W];     // an envelope point's direction (0 for a node)
  float spx[W], spy[W], spz[W];  // sigma_p: the point's node's section normal
  float ax[W], ay[W], az[W];     // the segment's first node
  float bx[W], by[W], bz[W];     // and second
  float vax[W], vay[W], vaz[W], vbx[W], vby[W], vbz[W];
  float nax[W], nay[W], naz[W];  // the first node's section normal (unit_or's fallback)
  float ra[W][kEnvelopePerSection], rb[W][kEnvelopePerSection];  // envelope radii at a, a + 1
  float r0a[W], r0b[W];          // rest radii
  float u[W], mp[W];
  int envelope[W];
};

void load(const WispSystem& s, const WispContact& c, std::span<const WispParams> params, Lanes& in, int l) {
  const std::uint32_t k = c.envelope ? c.point / kEnvelopePerSection : c.point;
  const Vec3f dir = c.envelope ? envelope_dir(s, k, static_cast<int>(c.point % kEnvelopePerSection)) : Vec3f::Zero();
  const Vec3f& x = s.x[k];
  const Vec3f& v = s.v[k];
  // p and vp as contact_impulse forms them: x + r dir, componentwise.
  const float r = c.envelope ? s.r[c.point] : 0.0f, rd = c.envelope ? s.rdot[c.point] : 0.0f;
  in.px[l] = c.envelope ? x.x() + r * dir.x() : x.x();
  in.py[l] = c.envelope ? x.y() + r * dir.y() : x.y();
  in.pz[l] = c.envelope ? x.z() + r * dir.z() : x.z();
  in.vpx[l] = c.envelope ? v.x() + rd * dir.x() : v.x();
  in.vpy[l] = c.envelope ? v.y() + rd * dir.y() : v.y();
  in.vpz[l] = c.envelope ? v.z() + rd * dir.z() : v.z();
  in.dx[l] = dir.x();
  in.dy[l] = dir.y();
  in.dz[l] = dir.z();
  in.spx[l] = s.n[k].x();
  in.spy[l] = s.n[k].y();
  in.spz[l] = s.n[k].z();
  const std::uint32_t a = c.seg;
  in.ax[l] = s.x[a].x();
  in.ay[l] = s.x[a].y();
  in.az[l] = s.x[a].z();
  in.bx[l] = s.x[a + 1].x();
  in.by[l] = s.x[a + 1].y();
  in.bz[l] = s.x[a + 1].z();
  in.vax[l] = s.v[a].x();
  in.vay[l] = s.v[a].y();
  in.vaz[l] = s.v[a].z();
  in.vbx[l] = s.v[a + 1].x();
  in.vby[l] = s.v[a + 1].y();
  in.vbz[l] = s.v[a + 1].z();
  in.nax[l] = s.n[a].x();
  in.nay[l] = s.n[a].y();
  in.naz[l] = s.n[a].z();
  for (int q = 0; q < kEnvelopePerSection; ++q) {
    in.ra[l][q] = s.r[kEnvelopePerSection * a + q];
    in.rb[l][q] = s.r[kEnvelopePerSection * (a + 1) + q];
  }
  in.r0a[l] = s.r_rest[a];
  in.r0b[l] = s.r_rest[a + 1];
  in.u[l] = c.u;
  in.mp[l] = c.envelope ? params[s.wisp_params[s.node_wisp[k]]].envelope_mass : 1.0f;
  in.envelope[l] = c.envelope;
}

inline float lerp(float a, float b, float u) { return a + u * (b - a); }

}  // namespace

// contact_impulse, lane by lane; see there for the physics.
void impulses(const WispSystem& s, std::span<const WispContact> contacts, std::size_t begin, std::size_t end,
              const InteractionParams& ip, std::span<const WispParams> params, float h, ContactImpulse* out) {
  Lanes in;
  float ix[W], iy[W], iz[W], dr[W], share[W];
  int bad[W];
  constexpr float kMinSin = 0.087f;  // as contact_impulse
  for (std::size_t b = begin; b < end; b += W) {
    const int count = static_cast<int>(std::min<std::size_t>(W, end - b));
    // Lanes past `count` repeat the first contact (real data) and are dropped.
    for (int l = 0; l < W; ++l) load(s, contacts[b + (l < count ? l : 0)], params, in, l);
    _Pragma("GCC ivdep") for (int l = 0; l < W; ++l) {
      bad[l] = 0;
      const F3 p{in.px[l], in.py[l], in.pz[l]}, vp{in.vpx[l], in.vpy[l], in.vpz[l]};
      const F3 xa{in.ax[l], in.ay[l], in.az[l]}, xb{in.bx[l], in.by[l], in.bz[l]};
      const float u = in.u[l];
      const F3 axis = sub(xb, xa);
      // unit_or(axis, n[a]) as a select: its fallback is at hand.
      const float axis2 = dot(axis, axis);
      const F3 sigma_s = pick(axis2 > 1e-24f, quot(axis, std::sqrt(axis2)), F3{in.nax[l], in.nay[l], in.naz[l]});
      const F3 sigma_p{in.spx[l], in.spy[l], in.spz[l]};
      const F3 vs = add(mul(1.0f - u, F3{in.vax[l], in.vay[l], in.vaz[l]}), mul(u, F3{in.vbx[l], in.vby[l], in.vbz[l]}));
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
      const float radius0 = lerp(in.ra[l][0], in.rb[l][0], u), radius1 = lerp(in.ra[l][1], in.rb[l][1], u);
      const float radius2 = lerp(in.ra[l][2], in.rb[l][2], u), radius3 = lerp(in.ra[l][3], in.rb[l][3], u);
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
      const F3 dir{in.dx[l], in.dy[l], in.dz[l]};
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

}  // namespace hairbench::kernels::wisp_soa::PLANTE_SOA_VARIANT
