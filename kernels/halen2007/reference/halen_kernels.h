// The new building blocks of Halén & Wester 2007's three strand models (chapter 4, §5.9),
// as pure functions over one strand's plain arrays. Verlet (Eq. 4.1), the edge
// correction (Eq. 4.2), head following and sphere collisions are the shared kernels of
// strand_kernels.h; only what those models add is here: reference-node springs (§4.3,
// §4.4), the cascading tangent spaces (§4.3) and the joint-angle forest (§4.2, §5.9).
#pragma once

#include "core/types.h"

#include <span>

namespace hairbench::kernels {

using Mat3f = Eigen::Matrix3f;
using Mat34f = Eigen::Matrix<float, 3, 4>;

// ---- shared by the three models -------------------------------------------------------

// §5.9: spring strength falling with the distance L from the root, k_L = k / (L c)^a
// (a = 1 linear, 2 quadratic, 3 cubic). The formula exceeds k for L c < 1 and is
// unbounded at the root, where the thesis says the strength is k; it is held at k there.
float falloff_stiffness(float k, float distance, float c, int exponent);

// Arc length of every vertex of one strand from its root (vertex 0).
void arc_lengths(std::span<const Vec4f> rest, std::span<float> out);

// §4.4's tilt weakening as a factor of k: k_m / k = s + (1 - s) α/k with
// s = (z · z_h + 1) / 2, z the world up vector and z_h the head's up vector. 1 upright,
// α/k upside down.
float tilt_factor(const Vec3f& up, const Vec3f& head_up, float min_fraction);

// Reference nodes rigid with the head (§4.4), displaced upward against gravity by
// L = mg/k (per unit mass: lift_i = 1/k_i): ref_i = head · local_i - gravity · lift_i.
void head_references(std::span<const Vec3f> local, std::span<const float> lift, const Affine3f& head,
                     const Vec3f& gravity, std::span<Vec3f> ref);

// Zero-rest-length springs to fixed reference nodes, F = k L (§4.3), as the force term of
// Verlet (Eq. 4.1). Runs after verlet_integrate, whose `prev` then holds the positions the
// step started from: free vertices get p += scale · k_i (ref_i - p_start) dt². k is per
// unit node mass (s^-2).
void add_spring_acceleration(std::span<Vec4f> pos, std::span<const Vec4f> prev, std::span<const Vec3f> ref,
                             std::span<const float> k, float scale, float dt);

// ---- set-up of the spring models, shared by the reference and the fused models --------

// How a segment's tangent space takes B and T from its parent's (§4.3; "there is no one
// way of defining the binormal and the tangent").
enum class CascadeFrames : int {
  // The thesis's: B_j = N_j × T_{j-1} (normalised), T_j = N_j × B_j. Undefined where
  // N_j is parallel to T_{j-1}, a bend of 90° towards T: near it a small turn of the
  // segment spins the space about N (there the parent's B, made perpendicular to N_j,
  // is kept).
  Cross = 0,
  // The parent's space turned by the smallest rotation that takes N_{j-1} to N_j
  // (parallel transport): B and T turn with the segment, undefined only where the
  // strand folds back on itself (there, too, the parent's B is kept).
  Transport = 1,
};

// §4.4 with §5.9's falloff, one strand: the spring strength k_L of every vertex and its
// reference node's lift 1/k_L (L = mg/k per unit mass; 0 where k_L is 0).
void spring_setup(std::span<const Vec4f> rest, float stiffness, float c, int exponent, std::span<float> k,
                  std::span<float> lift);

// §4.3 with §5.9's falloff and downward fraction, one strand. The thesis fixes node 0 to
// the scalp, node 1's upward reference node in the given tangent space at the root; here
// the groom's pins are kept, so its pinned root edge (vertices 0 and 1, the root frame
// every groom gives) is that given space, held rigid with the head, as in every other
// model. Writes:
//  - inv_mass: the groom's inverse masses, which the springs read;
//  - k_up (vertices 1..n) and k_down (vertices 1.. with a segment two below them), the
//    lift 1/(k_up + k_down) per unit gravity (L = mg/k with both reference nodes
//    displaced alike, "half the distance" when they are equally strong);
//  - base and lever: the rigid segment that carries space j is (base[j], j), lever[j] long
//    at rest; base[j] = j-1 but where segment j is rounding-sized (under 1/1000 of the
//    strand's median rest edge: its direction is rounding noise), which takes its
//    parent's space and joins its rigid segment; -1 where the space is the head's;
//  - the rest tangent spaces (space[0] the root's) and the reference nodes in them.
// Entries a vertex has no use for are 0.
void cascade_setup(std::span<const Vec4f> rest, float stiffness, float c, int exponent, float down_fraction,
                   CascadeFrames frames, std::span<float> inv_mass, std::span<float> k_up,
                   std::span<float> k_down, std::span<float> lift, std::span<int> base, std::span<float> lever,
                   std::span<Mat3f> rest_space, std::span<Vec3f> up_local, std::span<Vec3f> down_local);

// ---- cascading spaces (§4.3) ----------------------------------------------------------

// A tangent space as the matrix M = [B N T] (columns): N along the segment, B and T
// across it.
// The given first space at the scalp (§4.3: "The first tangent space for the connection
// point on the scalp is given") for a root segment along the unit vector n.
Mat3f root_tangent_space(const Vec3f& n);

// §4.3: the tangent spaces from the root up. space[0] is the given space at the scalp,
// `root`; the segment ending at vertex j >= 1 has N_j = (P_j - P_{j-1}) / |.| and B, T
// from its parent's space, by `frames` (CascadeFrames). A segment with base[j] != j-1
// (cascade_setup) or of zero length keeps its parent's space.
void tangent_spaces(std::span<const Vec4f> pos, const Mat3f& root, CascadeFrames frames,
                    std::span<const int> base, std::span<Mat3f> space);

// One strand's constant set-up (cascade_setup), as cascade_accelerations reads it.
struct CascadeStrand {
  std::span<const float> inv_mass;      // the groom's
  std::span<const float> k_up, k_down;  // per unit node mass, s^-2
  std::span<const float> lift;          // per unit gravity
  std::span<const int> base;
  std::span<const float> lever;
  std::span<const Vec3f> up_local, down_local;
};

// §4.3's reference springs as accelerations (per unit node mass), from the positions and
// spaces at the start of the step. Space j (origin P_j, P_0 for the root's) carries the
// upward reference node of vertex j+1 and the downward one of vertex j-2 (j >= 3). A
// zero-rest-length spring F = kL pulls its vertex P towards the reference node M w + O_T
// (w its rest offset in the space), displaced against gravity, in two parts:
//  - elastic, k (M w + O_T - P): the half of the torsion spring that §4.3 says the
//    reference nodes simulate. With `reactions` it pushes back on what places the node,
//    so that the springs are the negative gradient of E = Σ k/2 |M w + O_T - P|² (they
//    neither make nor take energy): on the segment that carries the space, as a force
//    R = -F at the reference node on a rigid segment (A = base[j], O = j): f_A =
//    ((N·R) d - (N·d) R) / ℓ on A and R - f_A on O, d the node's offset from O, N the
//    segment's direction and ℓ = lever[j], the split that gives the segment R's force and
//    its torque across N; and, with CascadeFrames::Transport, through the twist of the
//    spaces about their N that every bend between the root and the space sets (the
//    transported frames' holonomy). Without reactions the reference node is fixed during
//    the step, as the thesis has it, and the springs are no gradient; with the thesis's
//    Cross frames the twist's part is left out (their twist has no such gradient);
//  - the displacement's share, k·lift·(-g_h) with g_h = `head_gravity`, gravity turned by
//    the head (§4.4: the displaced position is "kept static in relation to the base"): at
//    rest it carries the node's weight, mg, from the head; a constant force, the gradient
//    of a linear potential.
// Gravity is added here too, so that at rest it meets the displacement's share in one sum
// (added to a position apart, the two would each round the position, and the roundings
// of a moving strand do not cancel). Pinned vertices take nothing. Accumulated from
// gravity, space by space, upward then downward, then the twist's part tip to root.
// `twist` is scratch of one float per vertex.
void cascade_accelerations(std::span<const Vec4f> pos, std::span<const Mat3f> space, const CascadeStrand& s,
                           bool reactions, CascadeFrames frames, const Vec3f& gravity, const Vec3f& head_gravity,
                           std::span<float> twist, std::span<Vec3f> acc);

// p += dt² acc and the same to the vertex's step, for the free vertices: gravity and the
// reference springs as the force term of Verlet (Eq. 4.1), after verlet_integrate_steps
// (run without gravity; the step form of kernels/common/strand_kernels.h).
void add_acceleration(std::span<Vec4f> pos, std::span<Vec4f> step, std::span<const Vec3f> acc, float dt);

// ---- the interactive forest (§4.2, after Di Giacomo et al. 2001, and §5.9) ------------

// Which axis of the parent frame the first joint angle θ turns about: the parent's z
// (the segment itself; Di Giacomo et al.'s original) or its x (Halén's fix, §5.9).
// φ then turns about the joint's y axis.
enum class ForestAxes : int { ParentZ = 0, ParentX = 1 };

// Joint rotation from the parent frame to the child frame: R_primary(θ) · R_y(φ).
Mat3f forest_joint_rotation(ForestAxes axes, float theta, float phi);
// The angles (θ, φ) that point the child's z axis along the unit vector d, given in
// the parent frame. A straight child (d = z) has θ = φ = 0 in both conventions.
void forest_angles(ForestAxes axes, const Vec3f& d, float& theta, float& phi);
// Frame (columns x y z) of a rigid root segment along the unit vector z: y = z × X
// normalised (z × Z where z is along X), x = y × z.
Mat3f forest_root_frame(const Vec3f& z);

// One strand's joint state, indexed by the vertex that ends the segment; segments ending
// at a pinned vertex are rigid with the head.
struct ForestStrand {
  std::span<const Vec4f> rest;
  std::span<const Mat3f> rest_frame;  // frames of the rest pose (head at identity)
  std::span<const float> length;      // segment lengths L_i
  std::span<const float> theta0, phi0;
  std::span<const float> k;           // joint stiffness per unit inertia, s^-2
  std::span<float> theta, phi, dtheta, dphi;
  std::span<Mat3f> frame;             // current frames (columns x y z)
  std::span<Vec3f> joint_torque;      // scratch: each joint's spring torque (Eq. 4.2.2)
  std::span<Vec4f> pos;
};

// The set-up of one strand (§4.2, §5.9): forest_rest, and the joint stiffness falling with
// the distance of the joint (vertex i-1 for segment i) from the root. Returns 1/ℓ, ℓ the
// strand's length (see forest_integrate).
float forest_setup(std::span<const Vec4f> rest, ForestAxes axes, float stiffness, float c, int exponent,
                   std::span<Mat3f> rest_frame, std::span<float> theta0, std::span<float> phi0,
                   std::span<float> length, std::span<float> k);

// The acceleration of a point rigid with the head, a(p) = inertia · (p, 1), by central
// differences of the head transform over three substeps dt apart (h0, h1, head):
// (H - 2H_1 + H_0) H^-1 p / dt².
Mat34f root_inertia(const Affine3f& head, const Affine3f& h1, const Affine3f& h0, float dt);
// The head's angular acceleration Ω̇_H at the middle substep, by the same central
// differences: R''R^T = [Ω̇_H]× + [Ω_H]×², whose antisymmetric part is [Ω̇_H]×, with R
// the rotation of h1.
Vec3f head_angular_acceleration(const Affine3f& head, const Affine3f& h1, const Affine3f& h0, float dt);

// Rest angles and frames of one strand (head at identity), from its rest polyline.
void forest_rest(std::span<const Vec4f> rest, ForestAxes axes, std::span<Mat3f> rest_frame,
                 std::span<float> theta0, std::span<float> phi0, std::span<float> length);

// §4.2: positions rebuilt from the angles, P_i = P_{i-1} + L_i z_i, so segment lengths
// are exact; pinned vertices and their segments follow the head rigidly.
void forest_pose(const ForestStrand& s, ForestAxes axes, const Affine3f& head);

// The inertia J of Eq. 4.2.4 that turns an external torque τ = L z × F (Eq. 4.2.1, F = m a)
// into an angular acceleration. Mass: Di Giacomo et al.'s J ≈ mI, so Ω̇ = τ / m = L z × a
// (lengths in metres). StrandPendulum: J = m L ℓ I with ℓ the strand's length, so
// Ω̇ = z × a / ℓ and a straight strand swings under gravity like a pendulum of length ℓ,
// whatever its segment count.
enum class ForestInertia : int { Mass = 0, StrandPendulum = 1 };

struct ForestForces {
  Vec3f gravity = Vec3f::Zero();
  Wind wind;
  // Acceleration of a point rigid with the head, a(p) = inertia · (p, 1): its negative is
  // the inertial force of the moving root on a segment end (§4.2: "to approximate inertia
  // when the root has changed direction and speed, forces are added").
  Mat34f inertia = Mat34f::Zero();
  Mat3f head_rotation = Mat3f::Identity();
  std::span<const Vec4f> spheres;  // world xyz + radius
  float collision_stiffness = 0.0f;  // fraction of the penetration depth removed per dt²
  // ζ: the penalty is damped along the sphere's normal at 2ζ √(collision_stiffness) / dt,
  // ζ times critical for the penalty spring alone, by at most that rate times depth / dt.
  float collision_damping = 0.0f;
  float joint_damping = 0.0f;        // v of Eq. 4.2.2, s^-1
  // The fraction of every joint's rate kept after a step, exp(-drag dt): damping of each
  // segment's rotation relative to the head (see forest_integrate).
  float keep = 1.0f;
  float inv_inertia_length = 0.0f;   // 1 / ℓ, see ForestInertia
  float dt = 0.0f;
  ForestInertia inertia_model = ForestInertia::StrandPendulum;
  // Take the part of gravity normal to the head-transformed rest segment off as a force,
  // so that pose is in equilibrium (the forest's counterpart of the spring models'
  // L = mg/k; not in §4.2, where gravity bends the strand until the joint springs hold it).
  bool gravity_compensation = true;
  // Ω̇_p of Eq. 4.2.5 for the first free segment, whose parent is rigid with the head:
  // head_angular_acceleration, or zero to leave the head's motion to the inertial force.
  Vec3f root_angular_acceleration = Vec3f::Zero();
};

// How much one strand's inertia J = m L ℓ (ForestInertia::StrandPendulum) must be raised
// so that its rest pose, held in equilibrium by gravity compensation, is a stable one: a
// factor s >= 1 that divides the strand's external torques (1 where the pose already
// stands). Linearised about the rest pose with the head at identity, a segment i turned
// by a small angle about any axis normal to it meets gravity's torque |g| (z_i · up) / ℓ
// per radian (Eq. 4.2.1 with τ = L z × m g, through Eq. 4.2.4's J), which pushes it
// further over where the segment points up. The joint springs (Eq. 4.2.2-4.2.3) act on
// the absolute angles α of a chain of free segments through the tridiagonal K of
// (Kα)_i = k_i (α_i − α_{i−1}) − k_{i+1} (α_{i+1} − α_i), α fixed at the rigid root and
// free at the tip, so the chain stands when K − C / s is positive definite,
// C = diag(|g| (z_i · up) / ℓ). K's slowest mode falls as k / n² with the segment count n
// while gravity's term does not, so an upright strand of many short segments (a mohawk, a
// groom resampled finely) topples out of a pose that 16 vertices hold. s is `margin`
// times the smallest factor that makes s K − C semi-definite: the strand would stand
// under `margin` times its weight. Raising J rather than k leaves the explicit step's
// bound (the fastest joint mode, about 4k) where it was. Zero gravity, or a joint without
// stiffness (no factor helps), gives 1.
float forest_rest_inertia_scale(std::span<const Vec4f> rest, std::span<const float> length,
                                std::span<const float> k, float inv_strand_length, const Vec3f& gravity,
                                double margin);
// The margin the models use.
inline constexpr double kForestRestMargin = 2.0;

// One explicit Euler step of the joint angles (Eq. 4.2.1-4.2.6) from the pose in s.frame
// and s.pos. External forces per unit mass at each segment end (gravity, wind normal to
// the segment, the root's inertia, sphere penalty forces) become torques τ = L z × F
// (4.2.1) and, through f.inertia_model's J (4.2.4), angular accelerations, less z × g_n
// where f.gravity_compensation is set, g_n the part of gravity normal to the
// head-transformed rest segment (zero torque in that pose). The sphere penalty is damped
// along the sphere's normal (f.collision_damping), with the end's velocity relative to
// the head summed from the root over the joint rates. The joint
// springs (4.2.2) of a segment and of its child are added (4.2.3), the parent's absolute
// acceleration subtracted (4.2.5; f.root_angular_acceleration for the first free
// segment) and the result projected on the joint axes. Last, the joint rates are scaled
// by f.keep: taking d ω_i off every segment's absolute acceleration, ω_i its angular
// velocity relative to the head, leaves −d (θ' a_p + φ' y) relative to the parent
// (Eq. 4.2.5), each joint's own rates, so a drag on the segments' rotation is a per-joint
// decay that, unlike Eq. 4.2.2's v (which joints pass to their parents), damps a
// strand's slowest swing as fast as its fastest whatever its segment count.
void forest_integrate(const ForestStrand& s, ForestAxes axes, const ForestForces& f);

}  // namespace hairbench::kernels
