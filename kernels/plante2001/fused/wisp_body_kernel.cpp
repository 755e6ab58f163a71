// plante_wisp's wisp-body passes between detections (§4.2; wisp_soa.h, body_slide and
// body_hold) over the contacts the last detection listed (wisp_body_list), 16 masses at
// a time, one a lane, each lane performing wisp_body_slide's or wisp_body_hold's
// operations on its mass (wisp_kernels.cpp) in Eigen's order for 3-vectors
// (wisp_lanes.h). Compiled once per ISA variant like the other wisp block kernels.
#include "kernels/plante2001/fused/wisp_lanes.h"
#include "kernels/plante2001/fused/wisp_soa.h"

#include <cmath>
#include <cstdint>

#ifndef HAIRBENCH_ISA_VARIANT
#error "HAIRBENCH_ISA_VARIANT must name the ISA variant"
#endif

namespace hairbench::kernels::wisp_soa::HAIRBENCH_ISA_VARIANT {

namespace {

constexpr int W = kLanes;
constexpr int Q = kEnvelopePerSection;
// The helpers below are forced inline: a call inside a lane loop keeps it scalar.

// f(nodes, m) for the masses of wisps [first, first + count) listed in slot `slot`
// (wisp_body_list), W at a time (the nodes of m of them in nodes[0, m)). One slot at a
// time, so that a lane loop reads one array for all its lanes (GCC turns a choice
// between arrays into a load from a chosen address, which is not a vector gather).
template <class F>
void listed(const WispSystem& s, std::uint32_t first, std::uint32_t count, std::uint32_t slot, F&& f) {
  // Signed: AVX-512 gathers take 32-bit signed indices.
  std::int32_t nodes[W];
  int m = 0;
  for (std::uint32_t w = first; w < first + count; ++w) {
    if (!s.wisp_touches[w]) continue;  // its lists are empty
    const std::uint32_t* size = &s.body_list_size[kBodyListSlots * w];
    const std::uint32_t* list = &s.body_list[kBodyListSlots * s.node_begin[w]];
    for (std::uint32_t before = 0; before < slot; ++before) list += size[before];
    for (std::uint32_t c = 0; c < size[slot]; ++c) {
      nodes[m++] = static_cast<std::int32_t>(list[c]);
      if (m == W) {
        f(nodes, m);
        m = 0;
      }
    }
  }
  if (m == 0) return;
  // The lanes past the last mass repeat the first; their results are dropped.
  for (int l = m; l < W; ++l) nodes[l] = nodes[0];
  f(nodes, m);
}

// Whether a wisp of [first, first + count) touches a body (most runs do not).
bool any_touches(const WispSystem& s, std::uint32_t first, std::uint32_t count) {
  std::uint8_t any = 0;
  for (std::uint32_t w = first; w < first + count; ++w) any |= s.wisp_touches[w];
  return any != 0;
}

// The arrays the lanes read, as plain pointers taken before the lane loops (GCC makes
// vector gathers only of loads at a loop-invariant base).
struct Arrays {
  const float *x, *e1, *e2, *r_rest, *spheres;
  const std::int32_t *node_body, *env_body, *moves;
  float *v, *r, *rdot;
  Arrays(WispSystem& s, const BodyLanes& body)
      : x(s.x.data()->data()), e1(s.e1.data()->data()), e2(s.e2.data()->data()), r_rest(s.r_rest.data()),
        spheres(body.spheres), node_body(s.node_body.data()), env_body(s.env_body.data()), moves(body.moves),
        v(s.v.data()->data()), r(s.r.data()), rdot(s.rdot.data()) {}
};

// A listed mass of node k: its envelope index and half-line direction (envelope_dir;
// for a skeleton mass, unused) and its sphere.
struct Contact {
  int k, ei, sphere;
  F3 x, dir, centre;
  float radius;
};
[[gnu::always_inline]] inline Contact contact(const Arrays& a, int k, int ei, int sphere, F3 dir) {
  return {k,
          ei,
          sphere,
          load3(a.x, k),
          dir,
          {a.spheres[4 * sphere], a.spheres[4 * sphere + 1], a.spheres[4 * sphere + 2]},
          a.spheres[4 * sphere + 3]};
}
[[gnu::always_inline]] inline Contact skeleton_contact(const Arrays& a, int k) {
  return contact(a, k, Q * k, a.node_body[k], {0.0f, 0.0f, 0.0f});
}
// Envelope mass q of node k; `axis` is e1 or e2 (by q) and `sign` +1 or -1.
[[gnu::always_inline]] inline Contact envelope_contact(const Arrays& a, int k, int q, const float* axis, float sign) {
  const F3 e = load3(axis, k);
  return contact(a, k, Q * k + q, a.env_body[Q * k + q], {sign * e.x, sign * e.y, sign * e.z});
}

// half_line_entry (wisp_kernels.cpp).
[[gnu::always_inline]] inline float half_line_entry(F3 x, F3 dir, F3 centre, float radius) {
  const F3 xc = sub(x, centre);
  const float bb = dot(dir, xc), cc = dot(xc, xc) - radius * radius;
  const float disc = bb * bb - cc;
  const bool miss = !(disc >= 0.0f) | (cc < 0.0f) | (bb > 0.0f);
  // Every operation runs on every lane and the result is picked after: an operation
  // that may trap (a square root of a negative, a division by zero, a comparison after
  // || or &&) is not vector code when written on one branch only. The root of a taken
  // lane is that of disc.
  const float root = std::sqrt(disc >= 0.0f ? disc : 0.0f);
  return miss ? -1.0f : -bb - root;
}

// wisp_body_slide's `slide` (wisp_kernels.cpp): the velocity change of a point moving
// at v at p against the contact's sphere.
[[gnu::always_inline]] inline F3 slide_change(const BodyLanes& body, const Arrays& a, const Contact& c, F3 p, F3 v,
                                              float drag) {
  // unit_or with its fallback +y (p at the sphere's centre).
  const F3 off = sub(p, c.centre);
  const float n2 = dot(off, off);
  const F3 unit_off = quot(off, std::sqrt(n2));
  const F3 nrm = pick(n2 > 1e-24f, unit_off, F3{0.0f, 1.0f, 0.0f});
  // BodyStep::surface_velocity; motion * p is Eigen's 4 x 4 product with (p, 1), column
  // by column, as its SSE2 code in the baseline build of wisp_kernels.cpp adds them
  // (no fused multiply-add; the bit-for-bit tests check it).
  const auto& m = body.motion;
  const F3 moved{((m[0][0] * p.x + m[0][1] * p.y) + m[0][2] * p.z) + m[0][3],
                 ((m[1][0] * p.x + m[1][1] * p.y) + m[1][2] * p.z) + m[1][3],
                 ((m[2][0] * p.x + m[2][1] * p.y) + m[2][2] * p.z) + m[2][3]};
  const F3 surface = pick(a.moves[c.sphere] != 0, quot(sub(moved, p), body.h), F3{0.0f, 0.0f, 0.0f});
  const F3 rel = sub(v, surface);
  const float vn = dot(rel, nrm);
  const F3 dragged = mul(-drag, sub(rel, mul(vn, nrm)));
  return pick(vn < 0.0f, sub(dragged, mul(vn, nrm)), dragged);
}

}  // namespace

void body_slide(WispSystem& s, std::uint32_t first, std::uint32_t count, const BodyLanes& body, float drag) {
  if (!any_touches(s, first, count)) return;
  const Arrays a(s, body);
  // The skeleton masses first: a node's slide changes its velocity, which its envelope
  // masses' slides then read (in wisp_body_slide the node comes before its envelope);
  // an envelope mass's slide changes only its own radial rate.
  listed(s, first, count, 0, [&](const std::int32_t* nodes, int m) {
    float vx[W], vy[W], vz[W];
#pragma GCC ivdep
    for (int l = 0; l < W; ++l) {
      const Contact c = skeleton_contact(a, nodes[l]);
      const F3 v = load3(a.v, c.k);
      const F3 slid = add(v, slide_change(body, a, c, c.x, v, drag));
      vx[l] = slid.x;
      vy[l] = slid.y;
      vz[l] = slid.z;
    }
    for (int l = 0; l < m; ++l) {
      float* out = a.v + 3 * nodes[l];
      out[0] = vx[l];
      out[1] = vy[l];
      out[2] = vz[l];
    }
  });
  for (int q = 0; q < Q; ++q) {
    const float* axis = q % 2 == 0 ? a.e1 : a.e2;
    const float sign = q < 2 ? 1.0f : -1.0f;
    listed(s, first, count, static_cast<std::uint32_t>(q + 1), [&](const std::int32_t* nodes, int m) {
      float rdot_new[W];
      int at[W];
#pragma GCC ivdep
      for (int l = 0; l < W; ++l) {
        const Contact c = envelope_contact(a, nodes[l], q, axis, sign);
        const float r = a.r[c.ei], rdot = a.rdot[c.ei];
        const F3 p = add(c.x, mul(r, c.dir));
        const F3 dv = slide_change(body, a, c, p, add(load3(a.v, c.k), mul(rdot, c.dir)), drag);
        const float slid = rdot + dot(dv, c.dir);
        // The stop at the entry point: std::min(slid, std::max(0, (t - r) / h)) where t >= 0.
        const float t = half_line_entry(c.x, c.dir, c.centre, c.radius);
        const float gap_rate = (t - r) / body.h;
        const float cap = 0.0f < gap_rate ? gap_rate : 0.0f;
        const float stopped = cap < slid ? cap : slid;
        rdot_new[l] = t >= 0.0f ? stopped : slid;
        at[l] = c.ei;
      }
      for (int l = 0; l < m; ++l) a.rdot[at[l]] = rdot_new[l];
    });
  }
}

void body_hold(WispSystem& s, std::uint32_t first, std::uint32_t count, const BodyLanes& body) {
  if (!any_touches(s, first, count)) return;
  const Arrays a(s, body);
  for (int q = 0; q < Q; ++q) {
    const float* axis = q % 2 == 0 ? a.e1 : a.e2;
    const float sign = q < 2 ? 1.0f : -1.0f;
    listed(s, first, count, static_cast<std::uint32_t>(q + 1), [&](const std::int32_t* nodes, int m) {
      float r_new[W], rdot_new[W], floor[W];
      int at[W];
      // Read on every lane before the loop below, which would read it only where the
      // mass is held (a masked gather GCC does not make).
#pragma GCC ivdep
      for (int l = 0; l < W; ++l) floor[l] = kMinRadiusFraction * a.r_rest[nodes[l]];
#pragma GCC ivdep
      for (int l = 0; l < W; ++l) {
        const Contact c = envelope_contact(a, nodes[l], q, axis, sign);
        const float r = a.r[c.ei], rdot = a.rdot[c.ei];
        const float t = half_line_entry(c.x, c.dir, c.centre, c.radius);
        const bool keep = (t < 0.0f) | (r <= t);
        r_new[l] = keep ? r : (t < floor[l] ? floor[l] : t);  // std::max(t, floor)
        rdot_new[l] = keep | !(0.0f < rdot) ? rdot : 0.0f;  // std::min(rdot, 0)
        at[l] = c.ei;
      }
      for (int l = 0; l < m; ++l) {
        a.r[at[l]] = r_new[l];
        a.rdot[at[l]] = rdot_new[l];
      }
    });
  }
}

}  // namespace hairbench::kernels::wisp_soa::HAIRBENCH_ISA_VARIANT
