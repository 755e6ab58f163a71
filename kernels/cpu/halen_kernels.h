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

// §4.4 with §5.9's falloff, one strand: the spring strength k_L of every vertex and its
// reference node's lift 1/k_L (L = mg/k per unit mass; 0 where k_L is 0).
void spring_setup(std::span<const Vec4f> rest, float stiffness, float c, int exponent, std::span<float> k,
                  std::span<float> lift);

// §4.3 with §5.9's falloff and downward fraction, one strand: the upward (vertices 2..n)
// and downward (vertices with a segment two below them) spring strengths, the rest
// tangent spaces, the reference nodes in them and the lift 1/(k_up + k_down) they share.
// Entries a vertex has no use for are 0.
void cascade_setup(std::span<const Vec4f> rest, float stiffness, float c, int exponent, float down_fraction,
                   std::span<float> k_up, std::span<float> k_down, std::span<Mat3f> rest_space,
                   std::span<Vec3f> up_local, std::span<Vec3f> down_local, std::span<float> lift);

// ---- cascading spaces (§4.3) ----------------------------------------------------------

// A tangent space as the matrix M = [B N T] (columns): N along the segment, B and T
// across it.
// The given first space at the scalp (§4.3: "The first tangent space for the connection
// point on the scalp is given") for a root segment along the unit vector n.
Mat3f root_tangent_space(const Vec3f& n);

// §4.3: the tangent spaces from the root up. space[1] (segment 0-1, rigid with the head)
// is `root`; for n >= 2, N_n = (P_n - P_{n-1}) / |.|, B_n = N_n × T_{n-1} (normalised),
// T_n = N_n × B_n. space[0] is not used. Where N_n is parallel to T_{n-1} the cross
// product vanishes and B_{n-1}, then perpendicular to N_n, is kept.
void tangent_spaces(std::span<const Vec4f> pos, const Mat3f& root, std::span<Mat3f> space);

// §4.3: P_world = M P + O_T with O_T the segment's second node, then displaced upward
// against gravity by lift_i (L = mg/k per unit mass, shared by both reference nodes of a
// vertex). The upward reference node of vertex i lives in the space of segment i-1
// (origin P_{i-1}), i >= 2; the downward one in the space of segment i+2 (origin
// P_{i+2}), i + 2 < n. Writes up_ref[2..n) and down_ref[0..n-2).
void cascade_references(std::span<const Vec4f> pos, std::span<const Mat3f> space,
                        std::span<const Vec3f> up_local, std::span<const Vec3f> down_local,
                        std::span<const float> lift, const Vec3f& gravity, std::span<Vec3f> up_ref,
                        std::span<Vec3f> down_ref);

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

// Rest angles and frames of one strand (head at identity), from its rest polyline.
void forest_rest(std::span<const Vec4f> rest, ForestAxes axes, std::span<Mat3f> rest_frame,
                 std::span<float> theta0, std::span<float> phi0, std::span<float> length);

// §4.2: positions rebuilt from the angles, P_i = P_{i-1} + L_i z_i, so segment lengths
// are exact; pinned vertices and their segments follow the head rigidly.
void forest_pose(const ForestStrand& s, ForestAxes axes, const Affine3f& head);

struct ForestForces {
  Vec3f gravity = Vec3f::Zero();
  Wind wind;
  // Acceleration of a point rigid with the head, a(p) = inertia · (p, 1): its negative is
  // the inertial force of the moving root on a segment end.
  Mat34f inertia = Mat34f::Zero();
  Mat3f head_rotation = Mat3f::Identity();
  std::span<const Vec4f> spheres;  // world xyz + radius
  float collision_stiffness = 0.0f;  // fraction of the penetration depth removed per dt²
  float joint_damping = 0.0f;        // v of Eq. 4.2.2, s^-1
  float inv_inertia_length = 0.0f;   // 1 / ℓ, see forest_integrate
  float dt = 0.0f;
};

// One explicit Euler step of the joint angles (Eq. 4.2.1-4.2.6) from the pose in s.frame
// and s.pos. External forces per unit mass at each segment end (gravity, wind normal to
// the segment, the root's inertia, sphere penalty forces) become torques τ = L z × F
// (4.2.1); with J = m L ℓ I (J ≈ mI of Eq. 4.2.4, with the scalar of a segment whose
// torque swings a straight strand like a pendulum of its length ℓ) the angular
// acceleration of the torque is z × a / ℓ. The joint springs (4.2.2) of a segment and of
// its child are added (4.2.3), the parent's absolute acceleration subtracted (4.2.5) and
// the result projected on the joint axes. Gravity compensation, the forest's counterpart
// of the spring models' L = mg/k: the torque gravity exerts on the head-transformed rest
// segment is subtracted, so the head-transformed rest pose is in equilibrium.
void forest_integrate(const ForestStrand& s, ForestAxes axes, const ForestForces& f);

}  // namespace hairbench::kernels
