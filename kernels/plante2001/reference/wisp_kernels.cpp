#include "kernels/plante2001/reference/wisp_kernels.h"

#include "kernels/simd/vec_math.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace hairbench::kernels {

namespace {

Vec3f unit_or(const Vec3f& v, const Vec3f& fallback) {
  const float n2 = v.squaredNorm();
  return n2 > 1e-24f ? Vec3f(v / std::sqrt(n2)) : fallback;
}

float lerp(float a, float b, float u) { return a + u * (b - a); }

}  // namespace

void WispSystem::resize_state() {
  const std::size_t n = rest_x.size();
  x = rest_x;
  v.assign(n, Vec3f::Zero());
  acc.assign(n, Vec3f::Zero());
  rest_len.assign(n, 0.0f);
  seg_mass.resize(n, 0.0f);
  mass.assign(n, 0.0f);
  inv_mass.assign(n, 0.0f);
  bend_scale.assign(n, 0.0f);
  bend_local.assign(n, Vec3f::Zero());
  rest_bend.assign(n, 0.0f);
  e1.assign(n, Vec3f::UnitX());
  e2.assign(n, Vec3f::UnitY());
  this->n.assign(n, Vec3f::UnitZ());
  rest_e1.assign(wisp_count(), Vec3f::UnitX());
  root_t.assign(wisp_count(), Vec3f::UnitY());
  bishop_u.assign(n, Vec3f::UnitX());
  bishop_kappa.assign(n, Vec3f::Zero());
  twist_load.assign(n, 0.0f);
  rest_fe1.assign(n, Vec3f::UnitX());
  rest_fe2.assign(n, Vec3f::UnitY());
  frame_weight.assign(n, 1.0f);
  node_wisp.assign(n, 0);
  for (std::size_t w = 0; w < wisp_count(); ++w)
    for (std::uint32_t k = node_begin[w]; k < node_begin[w + 1]; ++k) node_wisp[k] = static_cast<std::uint32_t>(w);
  r_rest.resize(n, 0.0f);
  r.assign(kEnvelopePerSection * n, 0.0f);
  for (std::size_t k = 0; k < n; ++k)
    for (int q = 0; q < kEnvelopePerSection; ++q) r[kEnvelopePerSection * k + q] = r_rest[k];
  rdot.assign(kEnvelopePerSection * n, 0.0f);
  racc.assign(kEnvelopePerSection * n, 0.0f);
  node_body.assign(n, -1);
  env_body.assign(kEnvelopePerSection * n, -1);
  wisp_touches.assign(wisp_count(), 0);
  body_list.assign((kEnvelopePerSection + 1) * n, 0);
  body_list_size.assign((kEnvelopePerSection + 1) * wisp_count(), 0);
  seg_len.assign(n, 0.0f);
  seg_inv_len.assign(n, 0.0f);
  seg_t.assign(n, Vec3f::Zero());
  node_dv.assign(n, Vec3f::Zero());
  node_dv_weight.assign(n, 0.0f);
  env_dr.assign(kEnvelopePerSection * n, 0.0f);
  env_dr_weight.assign(kEnvelopePerSection * n, 0.0f);
}

Vec3f minimal_rotate(const Vec3f& a, const Vec3f& b, const Vec3f& v) {
  const float c = a.dot(b);
  if (1.0f + c < 1e-6f) {
    // a and b opposite: every half turn about an axis normal to a is minimal; pick one.
    const Vec3f axis = a.unitOrthogonal();
    return 2.0f * axis.dot(v) * axis - v;
  }
  // Rodrigues' formula with k = a x b (|k| = sin, c = cos) without trigonometry.
  const Vec3f k = a.cross(b);
  return v * c + k.cross(v) + k * (k.dot(v) / (1.0f + c));
}

NodeSection node_section(const WispSystem& s, std::uint32_t k, const Eigen::Matrix3f& head_rot) {
  NodeSection ns;
  const float wgt = s.frame_weight[k];
  auto axis = [&](const std::vector<Vec3f>& cur, const std::vector<Vec3f>& rest) -> Vec3f {
    if (wgt == 1.0f) return cur[k];
    return wgt * cur[k] + (1.0f - wgt) * (head_rot * rest[k]);
  };
  ns.e1 = axis(s.e1, s.rest_fe1);
  ns.e2 = axis(s.e2, s.rest_fe2);
  // Near the root the envelope's scale is blended towards 1 like the axes: a strand
  // next to its own root is not squeezed towards the wisp's centre.
  const float* r = &s.r[kEnvelopePerSection * k];
  const float inv_rest = 1.0f / s.r_rest[k];
  for (int q = 0; q < kEnvelopePerSection; ++q) ns.scale[q] = wgt * r[q] * inv_rest + (1.0f - wgt);
  return ns;
}

namespace {

// section_frame between node k and its neighbour j (k itself at sfrac 0), a fraction u of
// the way, from their NodeSections.
SectionFrame section_between(const WispSystem& s, std::uint32_t k, std::uint32_t j, float u, const NodeSection& at_k,
                             const NodeSection& at_j) {
  SectionFrame f;
  f.origin = s.x[k] + u * (s.x[j] - s.x[k]);
  f.e1 = unit_or(at_k.e1 + u * (at_j.e1 - at_k.e1), s.e1[k]);
  const Vec3f e2 = at_k.e2 + u * (at_j.e2 - at_k.e2);
  f.e2 = unit_or(e2 - e2.dot(f.e1) * f.e1, s.e2[k]);
  f.n = f.e1.cross(f.e2);
  f.scale_a[0] = lerp(at_k.scale[0], at_j.scale[0], u);
  f.scale_b[0] = lerp(at_k.scale[1], at_j.scale[1], u);
  f.scale_a[1] = lerp(at_k.scale[2], at_j.scale[2], u);
  f.scale_b[1] = lerp(at_k.scale[3], at_j.scale[3], u);
  f.rest_radius = lerp(s.r_rest[k], s.r_rest[j], u);
  return f;
}

std::uint32_t section_neighbour(std::uint32_t k, float sfrac) {
  return sfrac > 0.0f ? k + 1 : sfrac < 0.0f ? k - 1 : k;
}

// The strand point at coordinates c in section frame f (strand_point).
Vec3f point_in(const SectionFrame& f, const Vec4f& c) {
  const float a = c.y() * (c.y() >= 0.0f ? f.scale_a[0] : f.scale_a[1]);
  const float b = c.z() * (c.z() >= 0.0f ? f.scale_b[0] : f.scale_b[1]);
  return f.origin + a * f.e1 + b * f.e2 + c.w() * f.n;
}

}  // namespace

SectionFrame section_frame(const WispSystem& s, std::uint32_t k, float sfrac, const Eigen::Matrix3f& head_rot) {
  const std::uint32_t j = section_neighbour(k, sfrac);
  return section_between(s, k, j, std::abs(sfrac), node_section(s, k, head_rot), node_section(s, j, head_rot));
}

float section_weight(const WispSystem& s, std::uint32_t k, float sfrac) {
  return lerp(s.frame_weight[k], s.frame_weight[section_neighbour(k, sfrac)], std::abs(sfrac));
}

Vec3f strand_point(const WispSystem& s, std::uint32_t k, const Vec4f& c, const Eigen::Matrix3f& head_rot) {
  return point_in(section_frame(s, k, c.x(), head_rot), c);
}

Vec3f strand_point(const WispSystem& s, std::uint32_t k, const Vec4f& c, const NodeSection* sections) {
  const std::uint32_t j = section_neighbour(k, c.x());
  return point_in(section_between(s, k, j, std::abs(c.x()), sections[k], sections[j]), c);
}

Vec4f strand_coord(const WispSystem& s, std::uint32_t k, float sfrac, const Vec3f& p, const Eigen::Matrix3f& head_rot) {
  const SectionFrame f = section_frame(s, k, sfrac, head_rot);
  const Vec3f d = p - f.origin;
  return Vec4f(sfrac, d.dot(f.e1), d.dot(f.e2), d.dot(f.n));
}

void wisp_frames(WispSystem& s, std::size_t w, const Vec3f& root_e1) {
  const std::uint32_t b = s.node_begin[w], e = s.node_begin[w + 1];
  if (e - b < 2) {
    s.n[b] = Vec3f::UnitY();
    s.e1[b] = unit_or(root_e1 - root_e1.dot(s.n[b]) * s.n[b], s.n[b].unitOrthogonal());
    s.e2[b] = s.n[b].cross(s.e1[b]);
    return;
  }
  // Section normals: the first and last follow their segment, the others bisect the two
  // adjacent segments (§3.3, after Shen & Thalmann).
  Vec3f prev_t = unit_or(s.x[b + 1] - s.x[b], Vec3f::UnitY());
  s.n[b] = prev_t;
  for (std::uint32_t k = b + 1; k + 1 < e; ++k) {
    const Vec3f t = unit_or(s.x[k + 1] - s.x[k], prev_t);
    s.n[k] = unit_or(prev_t + t, t);
    prev_t = t;
  }
  s.n[e - 1] = prev_t;
  s.e1[b] = unit_or(root_e1 - root_e1.dot(s.n[b]) * s.n[b], s.n[b].unitOrthogonal());
  s.e2[b] = s.n[b].cross(s.e1[b]);
  for (std::uint32_t k = b + 1; k < e; ++k) {
    Vec3f e1 = minimal_rotate(s.n[k - 1], s.n[k], s.e1[k - 1]);
    // Re-orthogonalise so that rounding does not accumulate along the wisp.
    e1 = unit_or(e1 - e1.dot(s.n[k]) * s.n[k], s.n[k].unitOrthogonal());
    s.e1[k] = e1;
    s.e2[k] = s.n[k].cross(e1);
  }
}

void bishop_frames(WispSystem& s, std::size_t w, const Vec3f& root_t, const Vec3f& root_u) {
  const std::uint32_t b = s.node_begin[w], e = s.node_begin[w + 1];
  Vec3f prev_t = root_t, u = root_u;
  for (std::uint32_t k = b + 1; k < e; ++k) {
    const Vec3f& t = s.seg_t[k];
    // minimal_rotate, keeping the curvature binormal's half, (prev_t x t) / (1 + cos),
    // for the twist loads; none where the segments fold back onto each other.
    const float c = prev_t.dot(t);
    Vec3f turned;
    if (1.0f + c < 1e-6f) {
      turned = minimal_rotate(prev_t, t, u);
      s.bishop_kappa[k] = Vec3f::Zero();
    } else {
      const Vec3f k_axis = prev_t.cross(t);
      const Vec3f kappa = (1.0f / (1.0f + c)) * k_axis;
      turned = c * u + k_axis.cross(u) + k_axis.dot(u) * kappa;
      s.bishop_kappa[k] = kappa;
    }
    const Vec3f normal = turned - turned.dot(t) * t;
    const float n2 = normal.squaredNorm();
    u = n2 > 1e-24f ? Vec3f((1.0f / std::sqrt(n2)) * normal) : t.unitOrthogonal();
    s.bishop_u[k] = u;
    prev_t = t;
  }
}

void wisp_init_rest(WispSystem& s, std::size_t w, int root_blend) {
  const std::uint32_t b = s.node_begin[w], e = s.node_begin[w + 1];
  for (std::uint32_t k = b; k < e; ++k) {
    s.x[k] = s.rest_x[k];
    s.v[k] = Vec3f::Zero();
    s.rest_len[k] = k == b ? 0.0f : (s.rest_x[k] - s.rest_x[k - 1]).norm();
    // Lumped masses: each node carries half of each adjacent segment's hair, so that on
    // any segment lengths a node's springs (each scaled by its segment's hair) accelerate
    // it by at most twice their stiffness per metre (settings.h: the stable step).
    s.mass[k] = 0.5f * ((k > b ? s.seg_mass[k] : 0.0f) + (k + 1 < e ? s.seg_mass[k + 1] : 0.0f));
    s.inv_mass[k] = 1.0f / s.mass[k];
  }
  // The bending spring at node k-1 scales with the shorter and lighter of its two
  // segments, so that the lateral stiffness it puts on nodes k and k-2 stays within the
  // stable step whatever their ratio; where segment (k-2, k-1) is pinned (the head's,
  // §3.2) only segment (k-1, k) counts: a pinned node takes any stiffness, and the root
  // must hold the whole wisp's weight.
  for (std::uint32_t k = b + 2; k < e; ++k) {
    const bool head_segment = s.pinned[k - 2] && s.pinned[k - 1];
    const float l0 = head_segment ? s.rest_len[k] : std::min(s.rest_len[k], s.rest_len[k - 1]);
    const float m = head_segment ? s.seg_mass[k] : std::min(s.seg_mass[k], s.seg_mass[k - 1]);
    s.bend_scale[k] = l0 * l0 * m;
  }
  const Vec3f n0 = e - b >= 2 ? unit_or(s.rest_x[b + 1] - s.rest_x[b], Vec3f::UnitY()) : Vec3f::UnitY();
  Vec3f ref = n0.cross(Vec3f::UnitZ());
  if (ref.squaredNorm() < 1e-8f) ref = n0.cross(Vec3f::UnitY());
  s.rest_e1[w] = ref.normalized();
  wisp_frames(s, w, s.rest_e1[w]);
  // The weight ramps with the distance, in nodes, to the nearest pinned node: strands
  // pinned at both ends (TressFX) blend towards the head at the tip as at the root.
  for (std::uint32_t k = b; k < e; ++k) {
    s.rest_fe1[k] = s.e1[k];
    s.rest_fe2[k] = s.e2[k];
    std::uint32_t nearest = e - b;
    for (std::uint32_t j = b; j < e; ++j)
      if (s.pinned[j]) nearest = std::min(nearest, k > j ? k - j : j - k);
    s.frame_weight[k] = std::min(1.0f, static_cast<float>(nearest) / static_cast<float>(root_blend + 1));
  }
  // The rest directions in the Bishop frames of the rest skeleton (bishop_frames): the
  // frame of the first segment is rest_e1 about its own direction root_t.
  s.root_t[w] = n0;
  if (e - b < 3) return;
  // The rest angles of the paper's springs, from the segments' directions as the axial
  // springs' pass computes them (wisp_forces_and_velocities), so that the rest skeleton
  // gives paper_bending its rest angles to the bit.
  Vec3f prev_t = Vec3f::Zero();
  for (std::uint32_t k = b + 1; k < e; ++k) {
    const Vec3f d = s.rest_x[k] - s.rest_x[k - 1];
    const float len = d.norm();
    const Vec3f t = (1.0f / len) * d;
    if (k >= b + 2 && len > 0.0f && s.rest_len[k - 1] > 0.0f)
      s.rest_bend[k] = atan2_upper(prev_t.cross(t).norm(), prev_t.dot(t));
    prev_t = t;
  }
  for (std::uint32_t k = b + 1; k < e; ++k) s.seg_t[k] = unit_or(s.rest_x[k] - s.rest_x[k - 1], n0);
  bishop_frames(s, w, s.root_t[w], s.rest_e1[w]);
  for (std::uint32_t k = b + 2; k < e; ++k) {
    const Vec3f& u = s.bishop_u[k - 1];
    const Vec3f& tp = s.seg_t[k - 1];
    const Vec3f& t = s.seg_t[k];
    s.bend_local[k] = Vec3f(t.dot(u), t.dot(tp.cross(u)), t.dot(tp));
  }
}

void wisp_pin(WispSystem& s, std::size_t w, const Affine3f& head, float h) {
  for (std::uint32_t k = s.node_begin[w]; k < s.node_begin[w + 1]; ++k) {
    if (!s.pinned[k]) continue;
    const Vec3f p = head * s.rest_x[k];
    s.v[k] = (p - s.x[k]) / h;
    s.x[k] = p;
  }
}

// Damped bending springs whose force grows linearly with the bending angle (§3.2),
// towards the rest style: segment (k-1, k) is turned towards its rest direction in the
// Bishop frame of segment (k-2, k-1) (bishop_frames: the head-carried frame of the
// first segment, carried segment to segment by minimal rotation, §3.3's "quaternion
// that minimally rotates"), with the energy k bend_scale angle^2 / 2 (bend_scale = L0^2
// m, L0 and m the shorter rest length and lighter hair of the two segments: the lateral
// acceleration on nodes k and k-2, torque / length^2 / mass, stays at most about k
// whatever their ratio; wisp_init_rest). The forces are that energy's exact negative
// gradient, so the springs neither pump energy nor push the wisp as a whole:
//  - through segment (k-1, k), on nodes k and k-1;
//  - through segment (k-2, k-1), which carries the frame, on nodes k-1 and k-2;
//  - through the frame's twist about segment (k-2, k-1), which every bend between the
//    head and that segment sets (the frames' holonomy). A bend between segments e_prev
//    and e, kappa_b = 2 t_prev x t / (1 + t_prev . t) its curvature binormal, adds to
//    the twist of the frames after it kappa_b . dx / (2 |e_prev|) for a move dx of
//    e_prev's first node, -kappa_b . dx / (2 |e|) for one of e's last node, and minus
//    their sum for the node between: the holonomy gradient of discrete elastic rods
//    (Bergou et al. 2008). The springs' loads on the twist (twist_load) are summed tip
//    to root and applied per node in one pass.
// Without the twist's part (a target that turns only with segment (k-2, k-1)) the
// springs are a follower load, which a fold of the style turns into flutter with the
// head still: a ponytail guide folded 110 degrees over a 2 mm segment, resampled to 32
// vertices (tests/plante_test.cpp).
void bishop_bending(WispSystem& s, std::size_t w, const WispParams& p, const Eigen::Matrix3f& head_rot) {
  const std::uint32_t b = s.node_begin[w], e = s.node_begin[w + 1];
  bishop_frames(s, w, head_rot * s.root_t[w], head_rot * s.rest_e1[w]);
  for (std::uint32_t k = b + 1; k < e; ++k) s.twist_load[k] = 0.0f;
  for (std::uint32_t k = b + 2; k < e; ++k) {
    const float len = s.seg_len[k], len_prev = s.seg_len[k - 1];
    if (!(len > 0.0f) || !(len_prev > 0.0f)) continue;
    const Vec3f& t = s.seg_t[k];
    const Vec3f& t_prev = s.seg_t[k - 1];
    const Vec3f& u = s.bishop_u[k - 1];
    const Vec3f& bl = s.bend_local[k];
    const Vec3f target = bl.x() * u + bl.y() * t_prev.cross(u) + bl.z() * t_prev;
    const Vec3f axis = target.cross(t);
    const float sin_angle = axis.norm();
    Vec3f fk = Vec3f::Zero(), fk2 = Vec3f::Zero();
    if (sin_angle > 1e-7f) {
      // q = dE/d(angle) / sin(angle): the gradient of cos(angle) = t . target, times q.
      const float q = p.bending_stiffness * atan2_upper(sin_angle, target.dot(t)) * s.bend_scale[k] / sin_angle;
      fk = (q * s.seg_inv_len[k]) * (target - target.dot(t) * t);
      fk2 = (q * s.seg_inv_len[k - 1]) * (t_prev.cross(axis));
      s.twist_load[k - 1] = -q * t_prev.dot(axis);
    }
    const Vec3f dv = s.v[k] - s.v[k - 1];
    const Vec3f damp = (p.bending_damping * s.seg_mass[k]) * (dv - dv.dot(t) * t);
    s.acc[k] += (fk - damp) * s.inv_mass[k];
    s.acc[k - 2] += fk2 * s.inv_mass[k - 2];
    s.acc[k - 1] -= (fk + fk2 - damp) * s.inv_mass[k - 1];
  }
  float load = 0.0f;
  for (std::uint32_t k = e - 1; k > b; --k) {
    load += s.twist_load[k];
    if (!(s.seg_len[k] > 0.0f)) continue;
    // kappa_b / 2 of the bend between segments k - 1 (the head's direction for the first)
    // and k.
    const Vec3f& kappa = s.bishop_kappa[k];
    const Vec3f fn = (load * s.seg_inv_len[k]) * kappa;
    s.acc[k] += fn * s.inv_mass[k];
    s.acc[k - 1] -= fn * s.inv_mass[k - 1];
    if (k > b + 1 && s.seg_len[k - 1] > 0.0f) {
      const Vec3f fp = (load * s.seg_inv_len[k - 1]) * kappa;
      s.acc[k - 1] += fp * s.inv_mass[k - 1];
      s.acc[k - 2] -= fp * s.inv_mass[k - 2];
    }
  }
}

void paper_bending(std::uint32_t n, const Vec3f* t, const float* len, const float* inv_len, const float* rest_bend,
                   const float* bend_scale, const float* seg_mass, const float* inv_mass, const Vec3f* v,
                   float stiffness, float damping, Vec3f* acc) {
  for (std::uint32_t k = 2; k < n; ++k) {
    if (!(len[k] > 0.0f) || !(len[k - 1] > 0.0f)) continue;
    const Vec3f& tk = t[k];
    const Vec3f& t_prev = t[k - 1];
    // theta_k from |t_prev x t| and t_prev . t (atan2_upper, as bishop_bending reads its
    // angle). With q = dE_k/d(theta) / sin(theta) (E_k: wisp_kernels.h) the forces are q
    // times the gradient of cos(theta) = t_prev . t: (t_prev - cos t) / len[k] on node k,
    // (cos t_prev - t) / len[k-1] on node k-2.
    const Vec3f axis = t_prev.cross(tk);
    const float sin_angle = axis.norm();
    Vec3f fk = Vec3f::Zero(), fk2 = Vec3f::Zero();
    if (sin_angle > 1e-7f) {
      const float cos_angle = t_prev.dot(tk);
      const float q = stiffness * (atan2_upper(sin_angle, cos_angle) - rest_bend[k]) * bend_scale[k] / sin_angle;
      fk = (q * inv_len[k]) * (t_prev - cos_angle * tk);
      fk2 = (q * inv_len[k - 1]) * (cos_angle * t_prev - tk);
    }
    const Vec3f dv = v[k] - v[k - 1];
    const Vec3f damp = (damping * seg_mass[k]) * (dv - dv.dot(tk) * tk);
    acc[k] += (fk - damp) * inv_mass[k];
    acc[k - 2] += fk2 * inv_mass[k - 2];
    acc[k - 1] -= (fk + fk2 - damp) * inv_mass[k - 1];
  }
}

void wisp_forces_and_velocities(WispSystem& s, std::size_t w, const WispParams& p, const Eigen::Matrix3f& head_rot,
                                const Vec3f& gravity, const Wind& wind, float h) {
  const std::uint32_t b = s.node_begin[w], e = s.node_begin[w + 1];
  const Vec3f wind_acc = wind.acceleration();
  const bool windy = wind.active();
  // Gravity, air resistance and wind (the part of it that meets the segment face-on).
  for (std::uint32_t k = b; k < e; ++k) {
    Vec3f a = gravity - p.air_drag * s.v[k];
    if (windy && k > b) {
      const Vec3f t = unit_or(s.x[k] - s.x[k - 1], Vec3f::Zero());
      a += wind_acc - wind_acc.dot(t) * t;
    }
    s.acc[k] = a;
  }
  // Linear damped axial springs (§3.2): the force of segment (k-1, k) is its hair times
  // the stiffness times the stretch, each end accelerated by that over its mass.
  // Each segment's length and direction are kept for the bending springs.
  for (std::uint32_t k = b + 1; k < e; ++k) {
    const Vec3f d = s.x[k] - s.x[k - 1];
    const float len = d.norm();
    s.seg_len[k] = len;
    if (!(len > 0.0f)) continue;
    const float inv_len = 1.0f / len;
    s.seg_inv_len[k] = inv_len;
    const Vec3f t = inv_len * d;
    s.seg_t[k] = t;
    const float f =
        s.seg_mass[k] * (p.axial_stiffness * (len - s.rest_len[k]) + p.axial_damping * (s.v[k] - s.v[k - 1]).dot(t));
    s.acc[k - 1] += (f * s.inv_mass[k - 1]) * t;
    s.acc[k] -= (f * s.inv_mass[k]) * t;
  }
  // Damped bending springs (§3.2): the paper's law on the bend angles, or towards the rest
  // directions in Bishop frames (settings.h `bending`).
  if (p.bending == BendingLaw::kPaper) {
    paper_bending(e - b, &s.seg_t[b], &s.seg_len[b], &s.seg_inv_len[b], &s.rest_bend[b], &s.bend_scale[b],
                  &s.seg_mass[b], &s.inv_mass[b], &s.v[b], p.bending_stiffness, p.bending_damping, &s.acc[b]);
  } else {
    bishop_bending(s, w, p, head_rot);
  }
  // A wisp pinned at its tip as well (TressFX strands pinned at both ends) ends in a
  // single pinned node, not in a pinned segment as at the root (§3.2): nothing else holds
  // the direction of its last free segment, which would swing about the pinned node like
  // a ball joint - on tressfx_ponytail_shake the tips of the folded curls would turn over
  // by 100 degrees within 5 frames, and the strands rebuilt on them stretch past 50%. The
  // last segment gets the bending spring the first free one gets from the pinned root
  // segment: towards its head-carried rest direction, the head taking the reaction.
  if (e - b >= 3 && s.pinned[e - 1] && !s.pinned[e - 2]) {
    const std::uint32_t k = e - 2;
    const float len = s.seg_len[e - 1];
    if (len > 0.0f) {
      const Vec3f& t = s.seg_t[e - 1];
      const Vec3f target = head_rot * (s.rest_x[e - 1] - s.rest_x[k]).normalized();
      const Vec3f axis = t.cross(target);
      const float sin_angle = axis.norm();
      if (sin_angle > 1e-7f) {
        const float l0 = s.rest_len[e - 1];
        const float torque = p.bending_stiffness * atan2_upper(sin_angle, target.dot(t)) * l0 * l0 * s.seg_mass[e - 1];
        // Node k moves against the rotation of t about the pinned node.
        s.acc[k] -= ((torque / len) * s.inv_mass[k]) * (axis / sin_angle).cross(t);
      }
      const Vec3f dv = s.v[k] - s.v[e - 1];
      s.acc[k] -= ((p.bending_damping * s.seg_mass[e - 1]) * s.inv_mass[k]) * (dv - dv.dot(t) * t);
    }
  }
  // Envelope (§3.3): non-linear damped radial springs to the skeleton mass, soft damped
  // springs between neighbouring envelope masses of a section; only the components
  // along each half-line act (§5.1). The half-line moves with the skeleton mass, whose
  // acceleration appears as an inertial force: a swinging wisp squashes and stretches.
  for (std::uint32_t k = b; k < e; ++k) {
    const std::size_t e0 = kEnvelopePerSection * k;
    if (s.pinned[k]) {
      for (int q = 0; q < kEnvelopePerSection; ++q) s.racc[e0 + q] = 0.0f;
      continue;
    }
    const float r0 = s.r_rest[k];
    const Vec3f frame_acc = gravity - s.acc[k];
    Vec3f reaction = Vec3f::Zero();
    for (int q = 0; q < kEnvelopePerSection; ++q) {
      const Vec3f dir = envelope_dir(s, k, q);
      const float r = s.r[e0 + q], rd = s.rdot[e0 + q];
      const float spring = r < r0 ? -p.radial_stiffness * (r - r0) * (r0 / r)
                                  : -p.radial_stiffness * p.radial_stretch * (r - r0);
      const float radial = spring - p.radial_damping * rd;
      reaction -= p.envelope_mass * radial * dir;
      s.racc[e0 + q] = radial + frame_acc.dot(dir) - p.air_drag * (s.v[k].dot(dir) + rd);
    }
    const float d0 = r0 * std::sqrt(2.0f);
    for (int q = 0; q < kEnvelopePerSection; ++q) {
      const int q2 = (q + 1) % kEnvelopePerSection;
      const float ra = s.r[e0 + q], rb = s.r[e0 + q2];
      const float d = std::sqrt(ra * ra + rb * rb);
      if (!(d > 0.0f)) continue;
      const float ddot = (ra * s.rdot[e0 + q] + rb * s.rdot[e0 + q2]) / d;
      const float tension = p.ring_stiffness * (d - d0) + p.ring_damping * ddot;
      s.racc[e0 + q] -= tension * ra / d;
      s.racc[e0 + q2] -= tension * rb / d;
    }
    s.acc[k] += reaction;
  }
  for (std::uint32_t k = b; k < e; ++k) {
    if (s.pinned[k]) continue;
    s.v[k] += h * s.acc[k];
    for (int q = 0; q < kEnvelopePerSection; ++q)
      s.rdot[kEnvelopePerSection * k + q] += h * s.racc[kEnvelopePerSection * k + q];
  }
}

void wisp_positions(WispSystem& s, std::size_t w, const Vec3f& root_e1, float h) {
  const std::uint32_t b = s.node_begin[w], e = s.node_begin[w + 1];
  for (std::uint32_t k = b; k < e; ++k)
    if (!s.pinned[k]) s.x[k] += h * s.v[k];
  wisp_frames(s, w, root_e1);
  for (std::uint32_t k = b; k < e; ++k) {
    if (s.pinned[k]) continue;
    const float r_min = kMinRadiusFraction * s.r_rest[k], r_max = kMaxRadiusFraction * s.r_rest[k];
    for (int q = 0; q < kEnvelopePerSection; ++q) {
      const std::size_t i = kEnvelopePerSection * k + q;
      s.r[i] += h * s.rdot[i];
      if (s.r[i] < r_min) {
        s.r[i] = r_min;
        s.rdot[i] = std::max(s.rdot[i], 0.0f);
      } else if (s.r[i] > r_max) {
        s.r[i] = r_max;
        s.rdot[i] = std::min(s.rdot[i], 0.0f);
      }
    }
  }
}

namespace {

// Where the half-line x + t dir (x outside the sphere) enters the sphere: t >= 0, or -1
// when it misses it or x is inside (the detection's case).
float half_line_entry(const Vec3f& x, const Vec3f& dir, const Vec4f& sphere) {
  const Vec3f xc = x - sphere.head<3>();
  const float bb = dir.dot(xc), cc = xc.squaredNorm() - sphere.w() * sphere.w();
  const float disc = bb * bb - cc;
  if (!(disc >= 0.0f) || cc < 0.0f || bb > 0.0f) return -1.0f;
  return -bb - std::sqrt(disc);
}

// The sphere whose surface is nearest to p, and the signed gap to it.
int nearest_sphere(std::span<const Vec4f> spheres, const Vec3f& p, float& gap) {
  int best = -1;
  gap = INFINITY;
  for (std::size_t i = 0; i < spheres.size(); ++i) {
    const float g = (p - spheres[i].head<3>()).norm() - spheres[i].w();
    if (g < gap) {
      gap = g;
      best = static_cast<int>(i);
    }
  }
  return best;
}

// Where a skeleton mass at x inside a sphere (centre c) is moved to, on the sphere of
// radius R around c, by the penetration reaction (§4.2). The wisp is processed root to
// tip and the mass entered the body along its axial spring from `prev`, which is
// outside: of the points of that sphere it is moved to the one nearest x at the
// spring's rest length `len` from prev, so that a mass found deep inside (a body that moved fast, a
// groom that starts inside) comes out without stretching its segment - moved straight
// out, a mass 2 cm inside would stretch a 1.7 cm segment by half and the strands rebuilt
// on it past the 50% edge bound. prev may lie on that sphere itself (pushed there at this
// detection). When no such point exists (prev deep inside, or too far) the mass is
// moved straight out.
Vec3f push_out(const Vec3f& c, float R, const Vec3f& prev, const Vec3f& x, float len) {
  const Vec3f radial = c + R * unit_or(x - c, Vec3f::UnitY());
  const Vec3f pc = prev - c;
  const float d = pc.norm();
  if (!(d > 0.0f) || !(len > 0.0f)) return radial;
  // The circle where the sphere |q - c| = R meets |q - prev| = len: centre c + a u,
  // radius rho, in the plane normal to u.
  const Vec3f u = pc / d;
  const float a = (R * R - len * len + d * d) / (2.0f * d);
  const float rho2 = R * R - a * a;
  if (!(rho2 >= 0.0f)) return radial;
  const Vec3f xc = x - c;
  const Vec3f lateral = unit_or(xc - xc.dot(u) * u, u.unitOrthogonal());
  return c + a * u + std::sqrt(rho2) * lateral;
}

}  // namespace

void wisp_body_detect(WispSystem& s, std::size_t w, const BodyStep& body, const Vec3f& root_e1, float threshold) {
  const std::uint32_t b = s.node_begin[w], e = s.node_begin[w + 1];
  // Skeleton first, root to tip: the root is outside the body, so a mass found inside
  // entered it during the last steps (§4.2).
  // A mass after one that was moved is drawn back along its axial spring to no more
  // than its rest length, so that the reaction carries the rest of the wisp along
  // instead of tearing the spring (it may then be found inside, and moved in turn).
  bool prev_moved = false, any_moved = false;
  std::uint8_t touches = 0;
  for (std::uint32_t k = b; k < e; ++k) {
    s.node_body[k] = -1;
    if (s.pinned[k]) {
      prev_moved = false;
      continue;
    }
    bool moved = false;
    if (prev_moved) {
      const Vec3f d = s.x[k] - s.x[k - 1];
      const float len = d.norm();
      if (len > s.rest_len[k]) {
        s.x[k] = s.x[k - 1] + d * (s.rest_len[k] / len);
        moved = true;
      }
    }
    float gap;
    const int i = nearest_sphere(body.spheres, s.x[k], gap);
    if (i >= 0 && gap < threshold) {
      s.node_body[k] = i;
      touches = 1;
      if (gap < 0.0f) {
        const Vec3f c = body.spheres[i].head<3>();
        s.x[k] = push_out(c, body.spheres[i].w() + 0.9f * threshold, s.x[k > b ? k - 1 : k], s.x[k], s.rest_len[k]);
        const Vec3f nrm = unit_or(s.x[k] - c, Vec3f::UnitY());
        const float vn = (s.v[k] - body.surface_velocity(i, s.x[k])).dot(nrm);
        if (vn < 0.0f) s.v[k] -= vn * nrm;
        moved = true;
      }
    }
    prev_moved = moved;
    any_moved = any_moved || moved;
  }
  // The frames follow the skeleton (wisp_positions built them from this state unless a
  // mass was moved).
  if (any_moved) wisp_frames(s, w, root_e1);
  // Then the envelope masses, each along its half-line.
  for (std::uint32_t k = b; k < e; ++k) {
    for (int q = 0; q < kEnvelopePerSection; ++q) {
      const std::size_t ei = kEnvelopePerSection * k + q;
      s.env_body[ei] = -1;
      if (s.pinned[k]) continue;
      const Vec3f dir = envelope_dir(s, k, q);
      float gap;
      const int i = nearest_sphere(body.spheres, s.x[k] + s.r[ei] * dir, gap);
      if (i < 0 || gap >= threshold) continue;
      s.env_body[ei] = i;
      touches = 1;
      if (gap >= 0.0f) continue;
      // Entry point of the half-line x + t dir into the sphere: |x + t dir - c| = R.
      const Vec3f c = body.spheres[i].head<3>();
      const float R = body.spheres[i].w();
      const Vec3f xc = s.x[k] - c;
      const float bb = dir.dot(xc);
      const float cc = xc.squaredNorm() - R * R;
      const float t = -bb - std::sqrt(std::max(bb * bb - cc, 0.0f));
      s.r[ei] = std::clamp(t, kMinRadiusFraction * s.r_rest[k], s.r[ei]);
      Vec3f p = s.x[k] + s.r[ei] * dir;
      const Vec3f nrm = unit_or(p - c, Vec3f::UnitY());
      // Compressed to its floor and still inside (the skeleton mass lies closer to the
      // surface than that): the skeleton mass moves out so that the section fits.
      const float depth = R - (p - c).norm();
      if (depth > 0.0f) {
        s.x[k] += depth * nrm;
        p += depth * nrm;
      }
      const float vn = (s.v[k] + s.rdot[ei] * dir - body.surface_velocity(i, p)).dot(nrm);
      if (vn < 0.0f) s.rdot[ei] -= vn * nrm.dot(dir);
    }
  }
  s.wisp_touches[w] = touches;
}

void wisp_body_hold(WispSystem& s, std::size_t w, const BodyStep& body) {
  if (!s.wisp_touches[w]) return;
  for (std::uint32_t k = s.node_begin[w]; k < s.node_begin[w + 1]; ++k) {
    if (s.pinned[k]) continue;
    for (int q = 0; q < kEnvelopePerSection; ++q) {
      const std::size_t ei = kEnvelopePerSection * k + q;
      const int i = s.env_body[ei];
      if (i < 0) continue;
      const float t = half_line_entry(s.x[k], envelope_dir(s, k, q), body.spheres[i]);
      if (t < 0.0f || s.r[ei] <= t) continue;
      s.r[ei] = std::max(t, kMinRadiusFraction * s.r_rest[k]);
      s.rdot[ei] = std::min(s.rdot[ei], 0.0f);
    }
  }
}

void wisp_body_slide(WispSystem& s, std::size_t w, const BodyStep& body, float drag) {
  if (!s.wisp_touches[w]) return;
  const std::uint32_t b = s.node_begin[w], e = s.node_begin[w + 1];
  // The velocity change that removes the approach and damps the tangential slip of a
  // point moving at v at p against sphere i.
  auto slide = [&](int i, const Vec3f& p, const Vec3f& v) -> Vec3f {
    const Vec3f nrm = unit_or(p - body.spheres[i].head<3>(), Vec3f::UnitY());
    const Vec3f rel = v - body.surface_velocity(i, p);
    const float vn = rel.dot(nrm);
    Vec3f dv = -drag * (rel - vn * nrm);
    if (vn < 0.0f) dv -= vn * nrm;
    return dv;
  };
  for (std::uint32_t k = b; k < e; ++k) {
    if (s.pinned[k]) continue;
    if (s.node_body[k] >= 0) s.v[k] += slide(s.node_body[k], s.x[k], s.v[k]);
    for (int q = 0; q < kEnvelopePerSection; ++q) {
      const std::size_t ei = kEnvelopePerSection * k + q;
      if (s.env_body[ei] < 0) continue;
      const Vec3f dir = envelope_dir(s, k, q);
      s.rdot[ei] += slide(s.env_body[ei], s.x[k] + s.r[ei] * dir, s.v[k] + s.rdot[ei] * dir).dot(dir);
      // The surface stops the mass on its half-line: its radial rate takes it no further
      // than the entry point in this step (the velocity form of wisp_body_hold).
      const float t = half_line_entry(s.x[k], dir, body.spheres[s.env_body[ei]]);
      if (t >= 0.0f) s.rdot[ei] = std::min(s.rdot[ei], std::max(0.0f, (t - s.r[ei]) / body.h));
    }
  }
}

void wisp_body_list(WispSystem& s, std::size_t w) {
  const std::uint32_t b = s.node_begin[w], e = s.node_begin[w + 1];
  std::uint32_t* out = &s.body_list[kBodyListSlots * b];
  std::uint32_t* size = &s.body_list_size[kBodyListSlots * w];
  // Slot by slot, each root to tip. The detection records no contact on a pinned node.
  for (std::uint32_t slot = 0; slot < kBodyListSlots; ++slot) {
    size[slot] = 0;
    if (!s.wisp_touches[w]) continue;
    for (std::uint32_t k = b; k < e; ++k) {
      const int sphere = slot == 0 ? s.node_body[k] : s.env_body[kEnvelopePerSection * k + slot - 1];
      if (sphere >= 0) out[size[slot]++] = k;
    }
    out += size[slot];
  }
}

namespace {

// Widest envelope radius of node k: its envelope masses lie within it of x[k].
float widest_radius(const WispSystem& s, std::uint32_t k) {
  const float* r = &s.r[kEnvelopePerSection * k];
  return std::max(std::max(r[0], r[1]), std::max(r[2], r[3]));
}

}  // namespace

SegmentVolume::SegmentVolume(const WispSystem& s, std::uint32_t seg) : a(seg), xa(s.x[seg]), d(s.x[seg + 1] - xa) {
  len2 = d.squaredNorm();
  inv_len2 = 1.0f / len2;
  if (len2 > 0.0f) {
    t = d / std::sqrt(len2);
    t_orth = t.unitOrthogonal();
  }
  const float reach = 1.01f * std::max(widest_radius(s, seg), widest_radius(s, seg + 1));
  reach2 = reach * reach;
}

float SegmentVolume::contains(const WispSystem& s, const Vec3f& p) const {
  if (!(len2 > 0.0f)) return -1.0f;
  const float u = (p - xa).dot(d) / len2;
  if (!(u >= 0.0f && u <= 1.0f)) return -1.0f;
  const Vec3f lateral = p - (xa + u * d);
  Vec3f e1 = (1.0f - u) * s.e1[a] + u * s.e1[a + 1];
  e1 = unit_or(e1 - e1.dot(t) * t, t_orth);
  const Vec3f e2 = t.cross(e1);
  const float alpha = lateral.dot(e1), beta = lateral.dot(e2);
  const std::size_t ea = kEnvelopePerSection * a, eb = ea + kEnvelopePerSection;
  const int qa = alpha >= 0.0f ? 0 : 2, qb = beta >= 0.0f ? 1 : 3;
  const float ra = lerp(s.r[ea + qa], s.r[eb + qa], u), rb = lerp(s.r[ea + qb], s.r[eb + qb], u);
  const float f = (alpha / ra) * (alpha / ra) + (beta / rb) * (beta / rb);
  return f < 1.0f ? u : -1.0f;
}

ContactImpulse contact_impulse(const WispSystem& s, const WispContact& c, const InteractionParams& ip,
                              std::span<const WispParams> params, float h) {
  const std::uint32_t k = c.envelope ? c.point / kEnvelopePerSection : c.point;
  if (s.pinned[k]) return {Vec3f::Zero(), 0.0f, 0.0f, false};
  const int q = static_cast<int>(c.point % kEnvelopePerSection);
  const Vec3f dir = c.envelope ? envelope_dir(s, k, q) : Vec3f::Zero();
  const Vec3f p = c.envelope ? Vec3f(s.x[k] + s.r[c.point] * dir) : s.x[k];
  const Vec3f vp = c.envelope ? Vec3f(s.v[k] + s.rdot[c.point] * dir) : s.v[k];
  const float mp = c.envelope ? params[s.wisp_params[s.node_wisp[k]]].envelope_mass : 1.0f;
  const std::uint32_t a = c.seg;
  const Vec3f axis = s.x[a + 1] - s.x[a];
  const Vec3f sigma_s = unit_or(axis, s.n[a]);
  const Vec3f& sigma_p = s.n[k];
  const Vec3f vs = (1.0f - c.u) * s.v[a] + c.u * s.v[a + 1];
  const Vec3f rel = vp - vs;

  // §4.1: quasi-parallel wisps lie in one plane and move roughly within it. Its normal
  // is sigma_p x sigma_s; for wisps within a few degrees of parallel that product
  // vanishes, and the plane through the segment's axis and the point (which holds both
  // wisps) is used instead.
  Vec3f dv = -rel;  // very dissipative collision by default: contact velocities averaged
  bool parallel = std::abs(sigma_p.dot(sigma_s)) >= ip.parallel_cos;
  if (parallel) {
    constexpr float kMinSin = 0.087f;  // sin 5°
    Vec3f nrm = sigma_p.cross(sigma_s);
    if (nrm.squaredNorm() < kMinSin * kMinSin) nrm = sigma_s.cross(p - (s.x[a] + c.u * axis));
    nrm = unit_or(nrm, sigma_s.unitOrthogonal());
    const float out_of_plane = rel.dot(nrm);
    parallel = std::abs(out_of_plane) <= ip.in_plane_sin * rel.norm();
    if (parallel) {
      // Viscous drag proportional to the strand density of the penetrated segment
      // (its rest cross-section over the current one) and to the time step.
      const std::size_t ea = kEnvelopePerSection * a, eb = ea + kEnvelopePerSection;
      auto radius = [&](int qq) { return lerp(s.r[ea + qq], s.r[eb + qq], c.u); };
      const float r0 = lerp(s.r_rest[a], s.r_rest[a + 1], c.u);
      const float area = 0.25f * (radius(0) + radius(2)) * (radius(1) + radius(3));
      const float density = area > 0.0f ? r0 * r0 / area : 1.0f;
      const float drag = std::min(1.0f, ip.hair_friction * density * h);
      dv = -out_of_plane * nrm - drag * (rel - out_of_plane * nrm);
    }
  }

  // Split between the point (mass mp relative to a skeleton mass) and the segment's
  // skeleton, both wisps' skeleton masses taken as equal: the paper's Delta v_p =
  // -(...)/2 (§4.1), whatever hair each wisp carries.
  const Vec3f dvp = dv * (1.0f / (1.0f + mp));
  // The segment's nodes take the opposite impulse, shared linearly. In the average over a
  // node's contacts, a contact counts by the share of the relative velocity it asks the
  // node to absorb (1 for an equal mass, less for a light envelope mass), so that many
  // light contacts do not dilute a heavy one.
  const float share = 2.0f * mp / (1.0f + mp);
  if (!c.envelope) return {dvp, 0.0f, share, true};
  const float dr = dvp.dot(dir);
  return {mp * dr * dir, dr, share, true};
}

void contact_accumulate(WispSystem& s, const WispContact& c, const ContactImpulse& r, std::uint32_t lo,
                        std::uint32_t hi) {
  auto mine = [&](std::uint32_t node) { return node >= lo && node < hi; };
  // Nothing of this range first: a thread's range has only some of the list's contacts,
  // and then it reads nothing of their impulses.
  const std::uint32_t k = c.envelope ? c.point / kEnvelopePerSection : c.point;
  if (!mine(k) && !mine(c.seg) && !mine(c.seg + 1)) return;
  if (!r.respond) return;
  if (c.envelope) {
    if (mine(k)) {
      s.env_dr[c.point] += r.dr;
      s.env_dr_weight[c.point] += 1.0f;
    }
  } else if (mine(c.point)) {
    s.node_dv[c.point] += r.impulse;
    s.node_dv_weight[c.point] += 1.0f;
  }
  for (const auto& [node, weight] : {std::pair{c.seg, 1.0f - c.u}, std::pair{c.seg + 1, c.u}}) {
    if (!mine(node) || s.pinned[node]) continue;
    s.node_dv[node] -= weight * r.impulse;
    s.node_dv_weight[node] += weight * r.share;
  }
}

namespace {

// Several contacts on one mass: their modifications are averaged (once all of them are
// accumulated, in list order).
void apply_node(WispSystem& s, std::uint32_t node) {
  const float wgt = s.node_dv_weight[node];
  if (wgt == 0.0f) return;
  s.v[node] += s.node_dv[node] / std::max(wgt, 1.0f);
  s.node_dv[node] = Vec3f::Zero();
  s.node_dv_weight[node] = 0.0f;
}

void apply_envelope(WispSystem& s, std::uint32_t point) {
  const float wgt = s.env_dr_weight[point];
  if (wgt == 0.0f) return;
  s.rdot[point] += s.env_dr[point] / std::max(wgt, 1.0f);
  s.env_dr[point] = 0.0f;
  s.env_dr_weight[point] = 0.0f;
}

}  // namespace

void wisp_contacts_respond(WispSystem& s, std::span<const WispContact> contacts, const InteractionParams& ip,
                           std::span<const WispParams> params, float h) {
  constexpr std::uint32_t kAll = std::numeric_limits<std::uint32_t>::max();
  for (const WispContact& c : contacts) contact_accumulate(s, c, contact_impulse(s, c, ip, params, h), 0, kAll);
  for (const WispContact& c : contacts) {
    if (c.envelope)
      apply_envelope(s, c.point);
    else
      apply_node(s, c.point);
    apply_node(s, c.seg);
    apply_node(s, c.seg + 1);
  }
}

void wisp_contacts_apply(WispSystem& s, std::span<const WispContact> contacts, std::span<const ContactImpulse> impulses,
                         std::uint32_t lo, std::uint32_t hi) {
  for (std::size_t i = 0; i < contacts.size(); ++i) contact_accumulate(s, contacts[i], impulses[i], lo, hi);
  for (std::uint32_t node = lo; node < hi; ++node) {
    apply_node(s, node);
    for (int q = 0; q < kEnvelopePerSection; ++q) apply_envelope(s, kEnvelopePerSection * node + q);
  }
}

}  // namespace hairbench::kernels
