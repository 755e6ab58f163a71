// The layered wisp model of Plante, Cani & Poulin 2001 (§3-§5) as plain arrays and pure
// per-wisp functions: skeleton point masses (§3.2), envelope masses on half-lines of the
// cross-sections (§3.3), and the velocity/position modifications of the interactions
// (§4). The model adapter (models/plante2001/) owns the loop of §5.1 and the rates.
//
// Units: a skeleton mass is the hair its node carries, in strand-metres (the length of
// the wisp's strands that the node stands for: half of each adjacent segment's hair), an
// envelope mass `envelope_mass` times its node's. Stiffnesses are in 1/s^2 and dampings
// in 1/s per unit of the hair a spring holds (WispSystem::seg_mass): a segment's axial
// spring pulls with (stiffness x stretch x its hair), so that on skeletons of equal
// segments a node accelerates by stiffness x stretch, as the explicit integration's
// stable step (§5.3, settings.h) asks, whatever the wisp's strand count.
#pragma once

#include "core/types.h"

#include <cstdint>
#include <span>
#include <vector>

namespace hairbench::kernels {

// Which bending springs hold the skeleton (settings.h `bending`).
enum class BendingLaw : std::uint8_t {
  // §3.2 as written: a spring on the angle between consecutive segments, towards its rest
  // angle (paper_bending).
  kPaper = 0,
  // Towards each segment's rest direction in the Bishop frame of the segment before it,
  // the angle and the bend's azimuth (bishop_bending).
  kBishop = 1,
};

// Physical parameters of one wisp (one per groom region).
struct WispParams {
  float air_drag = 5.0f;            // 1/s, on every mass's absolute velocity (§5.1 "air resistance")
  float axial_stiffness = 4e5f;     // 1/s^2 per metre of stretch, times the segment's hair (§3.2)
  float axial_damping = 40.0f;      // 1/s on the relative axial velocity, times the segment's hair
  float bending_stiffness = 1e5f;   // 1/s^2: torque = k * angle * bend_scale (§3.2)
  float bending_damping = 60.0f;    // 1/s on the relative lateral velocity, times the segment's hair
  float envelope_mass = 0.1f;       // envelope mass / skeleton mass (§3.3 "much lighter")
  float radial_stiffness = 5e4f;    // 1/s^2, compression branch at small strain (§3.3)
  float radial_stretch = 0.3f;      // stretch stiffness as a fraction of the compression one
  float radial_damping = 300.0f;    // 1/s ("highly viscous" radial springs, §1 abstract)
  float ring_stiffness = 1e4f;      // 1/s^2, soft springs between a section's envelope masses
  float ring_damping = 200.0f;      // 1/s, "highly damped"
  BendingLaw bending = BendingLaw::kBishop;
};

// Interaction parameters (§4), shared by all wisps.
struct InteractionParams {
  float contact_threshold = 0.002f;  // m, sliding contact distance to a body (§4.2)
  float body_friction = 20.0f;       // 1/s, viscous tangential drag against a body (§4.2)
  float hair_friction = 5.0f;        // 1/s at rest density, viscous drag between quasi-parallel wisps (§4.1)
  float parallel_cos = 0.866f;       // cos of the widest angle between "quasi-parallel" wisps
  float in_plane_sin = 0.5f;         // sin of the widest angle between v_rel and the wisps' plane
};

// The envelope masses of a section, in this order along the section's axes e1, e2.
inline constexpr int kEnvelopePerSection = 4;  // §5.2: "we use only four envelope mass-points"

// The compression branch stiffens as r0/r (§3.3: "a wisp becomes progressively stiffer
// during a compression"); below this fraction of the rest radius the envelope mass is
// stopped, which bounds the spring's slope at 16 times its rest value and keeps the
// explicit integration (§5.3) stable at the default 1000 Hz.
inline constexpr float kMinRadiusFraction = 0.25f;
// The stretch branch is soft (radial_stretch) and a skeleton mass jerked by a contact
// flings its envelope masses outwards (inertial force, wisp_forces_and_velocities): on
// a groom starting inside a collider they reached 4 times the rest radius within a
// frame, and the strands, whose section offsets scale with the envelope (§5.2), moved
// by 3 rest radii between neighbouring sections. Beyond twice the rest radius the
// envelope mass is stopped: a strand's offset (at most wisp_width_max edges) then moves
// by at most as much again.
inline constexpr float kMaxRadiusFraction = 2.0f;


// All wisps. Nodes of wisp w are [node_begin[w], node_begin[w+1]); node k's envelope
// masses are 4k..4k+3 along +e1, +e2, -e1, -e2 of its section frame.
struct WispSystem {
  std::vector<std::uint32_t> node_begin{0};
  std::vector<std::uint16_t> wisp_params;  // index into the params table, per wisp

  // Skeleton (§3.2). Pinned nodes (the first segment, inside the head) follow the head.
  std::vector<Vec3f> x, v, acc;   // acc: scratch of wisp_forces_and_velocities (the block kernel keeps its own)
  std::vector<Vec3f> rest_x;      // head rest frame
  std::vector<std::uint8_t> pinned;
  // The hair of segment (k-1, k), strand-metres, stored at k (0 at a wisp's first node):
  // the length of the wisp's strands whose sections lie along that segment.
  std::vector<float> seg_mass;
  // Per node: its mass, half the hair of each adjacent segment (so a wisp's masses sum to
  // the length of its strands), and 1 / mass.
  std::vector<float> mass, inv_mass;
  // The bending spring at node k-1 (segments (k-2, k-1) and (k-1, k)), stored at k: its
  // torque is bending_stiffness x angle x bend_scale[k], bend_scale = L0^2 x m with L0
  // the shorter rest length and m the lighter hair of the two segments, of (k-1, k) alone
  // where (k-2, k-1) is the head's (wisp_init_rest).
  std::vector<float> bend_scale;
  std::vector<float> rest_len;    // segment (k-1, k), stored at k (0 at a wisp's first node)
  // Rest direction of segment (k-1, k), stored at k, in the Bishop frame (u, t x u, t) of
  // segment (k-2, k-1) (bishop_frames).
  std::vector<Vec3f> bend_local;
  // The rest angle of the bending spring at node k-1, between segments (k-2, k-1) and
  // (k-1, k), stored at k, radians in [0, pi] (paper_bending).
  std::vector<float> rest_bend;
  std::vector<Vec3f> root_t;      // per wisp: rest direction of its first segment, head rest frame
  // Scratch of wisp_forces_and_velocities: the Bishop frames' u of segment (k-1, k) at k,
  // half the curvature binormal of the bend between segments k-1 and k, (t_{k-1} x t_k) /
  // (1 + t_{k-1} . t_k), and the bending springs' loads on the twist of those frames.
  std::vector<Vec3f> bishop_u, bishop_kappa;
  std::vector<float> twist_load;
  // Section frames (§3.3): e1, e2 span the plane bisecting the adjacent segments, n its
  // normal; propagated root to tip by minimal rotation from the head-attached root frame.
  std::vector<Vec3f> e1, e2, n;
  std::vector<Vec3f> rest_e1;     // per wisp: e1 of its first section, head rest frame
  // Rest section frames (head rest frame), and per node the weight of the current
  // section frame against the head-carried rest one in the strand rebuild (see
  // strand_point): 0 on pinned nodes, ramping to 1 over the first free ones.
  std::vector<Vec3f> rest_fe1, rest_fe2;
  std::vector<float> frame_weight;
  std::vector<std::uint32_t> node_wisp;

  // Envelope (§3.3): radial coordinate along each half-line and its rate.
  std::vector<float> r, rdot, racc;  // per envelope mass; racc: radial acceleration scratch
  std::vector<float> r_rest;         // per node: sections are circles at rest

  // Body contacts found at the last body-collision detection (sphere index, -1 none).
  std::vector<std::int32_t> node_body, env_body;
  // Per wisp, whether that detection recorded any: the others' sliding contacts and
  // holds have nothing to do.
  std::vector<std::uint8_t> wisp_touches;
  // The same contacts as lists of nodes (wisp_body_list), for plante_wisp's passes
  // between detections: wisp w's from body_list[5 node_begin[w]], in 5 slots (the
  // skeleton masses, then the envelope masses q = 0..3) of body_list_size[5 w + slot].
  std::vector<std::uint32_t> body_list, body_list_size;
  // Scratch of wisp_forces_and_velocities: length, its inverse and direction of segment
  // (k-1, k) at k.
  std::vector<float> seg_len, seg_inv_len;
  std::vector<Vec3f> seg_t;
  // Per-mass velocity modification accumulators for the wisp-wisp response.
  std::vector<Vec3f> node_dv;
  std::vector<float> node_dv_weight, env_dr, env_dr_weight;

  std::size_t wisp_count() const { return node_begin.size() - 1; }
  std::size_t node_count() const { return x.size(); }
  // Sizes every state array after node_begin, wisp_params, rest_x, pinned and seg_mass
  // are filled; the state is the rest state (x = rest_x, still, envelope at rest radius
  // r_rest).
  void resize_state();
};

// Unit direction of envelope mass q of node k.
inline Vec3f envelope_dir(const WispSystem& s, std::size_t k, int q) {
  switch (q) {
    case 0: return s.e1[k];
    case 1: return s.e2[k];
    case 2: return -s.e1[k];
    default: return -s.e2[k];
  }
}
inline Vec3f envelope_point(const WispSystem& s, std::size_t k, int q) {
  return s.x[k] + s.r[4 * k + q] * envelope_dir(s, k, q);
}

// A strand vertex in its wisp (§3.4, §5.2), as coordinates (s, a, b, c) relative to
// node k: the section it lies in is interpolated a fraction |s| of the way to node
// k + sign(s) (origin, axes and envelope scale), (a, b) are its coordinates in that
// section's plane, scaled on each half-axis by its envelope mass's radius over the rest
// radius, and c an offset along the section normal. The skeleton has its own resolution
// (a few segments about as long as the wisp is wide, §4.1 footnote 1, §5.3), so a
// strand's vertices lie in sections interpolated between the nodes and bend with the
// wisp along each segment.
//
// Near the root the section axes (and the envelope's scale, towards 1) are blended
// towards the head-carried rest axes (frame_weight): every strand is rooted at its own point of the scalp and bends there,
// whereas a wide wisp's section swinging about the wisp's centre would carry the strand
// offsets (up to the wisp's radius) through the same angle and stretch the first free
// strand edges by up to radius x angle - more than the edge itself for a centimetre-wide
// wisp swinging by a radian.
Vec3f strand_point(const WispSystem& s, std::uint32_t k, const Vec4f& coord, const Eigen::Matrix3f& head_rot);
// The parts of a section frame that depend on one node k: its axes, blended towards the
// head-carried rest axes by frame_weight, and its envelope's scale per half-axis
// (current over rest radius), blended towards 1 alike.
struct NodeSection {
  Vec3f e1, e2;
  float scale[kEnvelopePerSection];
};
NodeSection node_section(const WispSystem& s, std::uint32_t k, const Eigen::Matrix3f& head_rot);
// strand_point from every node's NodeSection (`sections`, by node index), with the same
// bits: plante_wisp's rebuild sets each node's up once per step instead of twice per
// strand vertex that lies near it.
Vec3f strand_point(const WispSystem& s, std::uint32_t k, const Vec4f& coord, const NodeSection* sections);
// frame_weight interpolated like the section of strand_point at coordinate sfrac.
float section_weight(const WispSystem& s, std::uint32_t k, float sfrac);
// The coordinates of p in the section a fraction sfrac of the way from node k towards
// k + sign(sfrac), in the current state: exact for strand_point when the envelope is at
// its rest radii.
Vec4f strand_coord(const WispSystem& s, std::uint32_t k, float sfrac, const Vec3f& p, const Eigen::Matrix3f& head_rot);
// Scale factors (current / rest radius) of the section interpolated like strand_point,
// for the half-axes on the sides of a and b: the envelope's extent there is
// r_rest-interpolated times this scale.
struct SectionFrame {
  Vec3f origin, e1, e2, n;
  float scale_a[2], scale_b[2];  // [0]: +axis, [1]: -axis
  float rest_radius;
};
SectionFrame section_frame(const WispSystem& s, std::uint32_t k, float sfrac, const Eigen::Matrix3f& head_rot);

// Rotates v by the minimal rotation taking unit a to unit b (no twist about the axis).
Vec3f minimal_rotate(const Vec3f& a, const Vec3f& b, const Vec3f& v);

// Bishop frames of wisp w's segments from the unit directions seg_t (at k for segment
// (k-1, k)): a unit vector u normal to each, carried from `root_u` (normal to `root_t`,
// the head-carried rest direction of the first segment) segment to segment by the minimal
// rotation between their directions (no twist about them), into bishop_u, and half of each
// bend's curvature binormal into bishop_kappa. The bending springs read their rest
// directions in these frames.
void bishop_frames(WispSystem& s, std::size_t w, const Vec3f& root_t, const Vec3f& root_u);

// Section frames of wisp w from its skeleton: n_k bisects the adjacent segments, e1 of
// the first section is `root_e1` (head-attached), every other frame is the previous one
// minimally rotated from n_{k-1} to n_k (§3.3).
void wisp_frames(WispSystem& s, std::size_t w, const Vec3f& root_e1);

// Rest data of wisp w from its rest skeleton (rest_x) and its segments' hair (seg_mass):
// rest lengths, masses, bending scales, frames, the rest bending directions, and frame
// weights ramping from 0 to 1 over the `root_blend` free nodes after the pinned ones.
void wisp_init_rest(WispSystem& s, std::size_t w, int root_blend);

// Pinned nodes follow the head transform `head`; their velocities are the displacement
// over the step h.
void wisp_pin(WispSystem& s, std::size_t w, const Affine3f& head, float h);

// The bending springs of §3.2 as written: "a damped spring for which the force increases
// linearly with the bending angle", on one wisp of n nodes whose arrays start at its
// first node (segment (k-1, k) at k: unit direction t, length len and its inverse
// inv_len, as the axial springs' pass leaves them; rest_bend, bend_scale, seg_mass,
// inv_mass and v as in WispSystem). The spring at node k-1 acts on the angle
//   theta_k = atan2(|t_{k-1} x t_k|, t_{k-1} . t_k)  in [0, pi]
// between the segments that meet there, towards its rest angle theta0_k = rest_bend[k];
// the paper gives no rest angle, and a spring's rest is the rest skeleton's. Its energy is
//   E_k = stiffness bend_scale[k] (theta_k - theta0_k)^2 / 2,
// and the forces are E_k's negative gradient on the angle's three nodes, of size
// stiffness bend_scale (theta - theta0) / len on the nodes k and k-2 at the ends (linear in
// the angle, as §3.2 says), the node between taking minus their sum: conservative, and
// neither the wisp's momentum nor its angular momentum changes. The angle alone has no
// azimuth: a bent segment turned about the segment before it keeps its angle and costs
// nothing (the paper leaves style memory to oriented particles, §6). Where theta0 > 0 the
// energy has a cone at theta = 0 (the straight segment pair is its local maximum, its
// direction undefined): there, and at theta = pi, no force. The damping is bishop_bending's
// (the lateral velocity of node k relative to node k-1), as both laws' springs are damped
// alike. Adds to acc (accelerations, force over mass).
void paper_bending(std::uint32_t n, const Vec3f* t, const float* len, const float* inv_len, const float* rest_bend,
                   const float* bend_scale, const float* seg_mass, const float* inv_mass, const Vec3f* v,
                   float stiffness, float damping, Vec3f* acc);

// The bending springs towards the rest style (WispParams::bending kBishop, the default):
// wisp w's segment (k-1, k) turned towards its rest direction bend_local[k] read in the
// Bishop frame of segment (k-2, k-1), with the energy stiffness bend_scale angle^2 / 2 and
// its exact gradient, the frames' twist included (see the definition). Expects seg_t,
// seg_len and seg_inv_len of the current skeleton; adds to acc.
void bishop_bending(WispSystem& s, std::size_t w, const WispParams& p, const Eigen::Matrix3f& head_rot);

// §5.1 steps 1 and 3 (before modifications): forces, then v += a h for the skeleton
// masses and rdot += a_r h for the envelope masses (their accelerations projected on
// their half-lines). head_rot: the head's rotation (rest directions of pinned parts).
void wisp_forces_and_velocities(WispSystem& s, std::size_t w, const WispParams& p, const Eigen::Matrix3f& head_rot,
                                const Vec3f& gravity, const Wind& wind, float h);

// §5.1 step 4: x += v h for the skeleton, root to tip, then the new section frames, then
// r += rdot h for the envelope (kept within 0.25 and 2 times its rest radius).
void wisp_positions(WispSystem& s, std::size_t w, const Vec3f& root_e1, float h);

// ---- Wisp-body interactions (§4.2) -------------------------------------------------

// Where the bodies are during one integration step: spheres (xyz centre, w radius,
// world space), which of them move with the head, and the head's rigid motion over the
// step (it carries a point on a head-attached sphere from where it was to where it is).
struct BodyStep {
  std::span<const Vec4f> spheres;
  std::span<const std::int32_t> moves;  // 1 where the sphere moves with the head (int: the lane kernels gather it)
  Affine3f motion = Affine3f::Identity();
  float h = 0.0f;
  Vec3f surface_velocity(std::size_t i, const Vec3f& p) const {
    return moves[i] ? Vec3f((motion * p - p) / h) : Vec3f::Zero();
  }
};

// Detection on wisp w (§4.2): records which sphere each free mass is within `threshold`
// of, and applies the penetration reaction root to tip: a skeleton mass inside is moved
// out to 0.9 threshold above the surface ("slightly under the sliding contact
// threshold"); then, with the frames rebuilt, an envelope mass inside is moved along its
// half-line onto the surface. A moved mass loses its velocity into the body. Expects
// the section frames of the current skeleton (wisp_positions builds them), and rebuilds
// them only if a skeleton mass moved.
void wisp_body_detect(WispSystem& s, std::size_t w, const BodyStep& body, const Vec3f& root_e1, float threshold);

// Between detections, an envelope mass the last detection found in contact with a body
// stays out of it: where its half-line now enters the sphere nearer than the mass, the
// mass is held at the entry point (no nearer than the radius floor) and its outward
// radial rate, which would carry it in, is removed. Run after every position update, so
// each correction is one step's worth of motion: an inelastic wall. Corrected only at the
// detections, the radial spring would drive the mass a period's worth into the head, and
// the reaction's jump back would re-compress the spring 120 times a second (see
// wisp_body_slide).
void wisp_body_hold(WispSystem& s, std::size_t w, const BodyStep& body);

// Sliding contact (§4.2, a velocity modification) for the masses recorded by the last
// detection, on every integration step until the next one: the relative velocity
// approaching the surface is removed and the tangential one reduced by the fraction
// `drag` (viscous friction over the step); envelope masses only along their half-lines
// (§5.1).
void wisp_body_slide(WispSystem& s, std::size_t w, const BodyStep& body, float drag);

// The contacts of wisp w's last detection as lists (body_list): plante_wisp's passes
// between two detections visit only these (on `shake` 2% of the masses are in contact),
// 16 at a time (wisp_soa.h, body_slide and body_hold).
void wisp_body_list(WispSystem& s, std::size_t w);
// The lists' slots: skeleton masses, then envelope masses q = 0..3.
inline constexpr std::uint32_t kBodyListSlots = kEnvelopePerSection + 1;

// ---- Wisp-wisp interactions (§4.1) --------------------------------------------------

// A point mass (skeleton node, or envelope mass 4k+q) found inside the volume of a wisp
// segment (seg, seg+1) at axial parameter u.
struct WispContact {
  std::uint32_t point;   // node index, or envelope index when envelope != 0
  std::uint32_t seg;     // first node of the segment
  float u;
  std::uint8_t envelope;
};

// The volume of segment (a, a+1), bounded by its two sections (§4.1): swept by the
// sections' quarter-ellipses (semi-axes: the envelope radii) interpolated linearly along
// the axis. A point p is inside at axial parameter u = (p - xa).d / |d|^2 in [0,1] when,
// with lateral = p - (xa + u d), e1 the section axes (1-u) e1[a] + u e1[a+1] made unit
// and normal to t (t_orth where that vanishes), e2 = t x e1, alpha = lateral.e1, beta =
// lateral.e2, and ra, rb the radii of the envelope masses on the sides of alpha and beta
// interpolated at u: (alpha/ra)^2 + (beta/rb)^2 < 1. The axis is set up once per
// detection for the tests of many points (the test: wisp_grid_kernel.cpp).
// One cache line each: the narrow phase reads the volumes of a segment's partners in no
// order the prefetcher follows.
struct alignas(64) SegmentVolume {
  std::uint32_t a = 0;
  Vec3f xa, d, t, t_orth;  // first node, axis, unit axis and a unit normal to it (len2 > 0)
  float len2 = 0.0f;
  // 1 / len2, for the narrow phase's cheap axial bound only (its margin is far above the
  // rounding of a multiplication instead of the division); the test itself divides.
  float inv_len2 = 0.0f;
  // (1.01 widest)^2, widest the widest envelope radius at either end. alpha^2 + beta^2
  // is the squared distance to the axis (e1, e2 an orthonormal basis of the plane normal
  // to it) and the interpolated radii are at most `widest`: a point farther than that
  // from the axis is outside. The 1% margin is far above rounding, so a test on this
  // bound rejects no inside point.
  float reach2 = 0.0f;

  SegmentVolume() = default;
  SegmentVolume(const WispSystem& s, std::uint32_t seg);
  // The test of one point p, as written above: its axial parameter u where p is inside,
  // else -1 (plante_wisp_ref's narrow phase, grid_contacts_ref).
  float contains(const WispSystem& s, const Vec3f& p) const;
};

// The response of every contact from the current state (§4.1), accumulated then applied
// as averages per mass: quasi-parallel wisps (orientations within acos(parallel_cos),
// relative velocity within asin(in_plane_sin) of their common plane) lose the relative
// velocity normal to that plane and get a viscous in-plane drag min(1, hair_friction *
// density * h), h the period the response stands for; other contacts are inelastic
// collisions (relative velocity removed). The split takes the two wisps' skeleton
// masses as equal, whatever hair they carry: the paper sets both wisps' velocities to
// "the average of their initial values" (§4.1); an envelope point weighs envelope_mass
// of that.
void wisp_contacts_respond(WispSystem& s, std::span<const WispContact> contacts, const InteractionParams& ip,
                           std::span<const WispParams> params, float h);

// The same response in two parts, for threads: each contact's impulse depends
// only on the state before the response, so the impulses of any ranges of contacts can be
// found at once; the sums per mass then run in list order, each thread over the masses of
// its own nodes, so every mass gets the same bits as from wisp_contacts_respond.
struct ContactImpulse {
  Vec3f impulse;  // on the point (a node's Delta v, or an envelope mass's along its half-line)
  float dr;       // an envelope point's Delta rdot
  float share;    // the contact's weight in the averages of the segment's nodes
  bool respond;   // false where the point's node is pinned: no response at all
};
ContactImpulse contact_impulse(const WispSystem& s, const WispContact& c, const InteractionParams& ip,
                              std::span<const WispParams> params, float h);
// Adds contact c's response to the masses of nodes [lo, hi) (envelope masses by their node).
void contact_accumulate(WispSystem& s, const WispContact& c, const ContactImpulse& r, std::uint32_t lo,
                        std::uint32_t hi);
// Every contact's response on the masses of nodes [lo, hi), in list order, then applied
// as averages (impulses[i]: contact_impulse of contacts[i]).
void wisp_contacts_apply(WispSystem& s, std::span<const WispContact> contacts, std::span<const ContactImpulse> impulses,
                         std::uint32_t lo, std::uint32_t hi);

}  // namespace hairbench::kernels
