#include "kernels/halen2007/reference/halen_kernels.h"

#include "kernels/common/strand_kernels.h"

#include <algorithm>
#include <cmath>
#include <vector>

namespace hairbench::kernels {

namespace {
Vec3f xyz(const Vec4f& v) { return v.head<3>(); }
}  // namespace

float falloff_stiffness(float k, float distance, float c, int exponent) {
  const float lc = std::max(distance * c, 1.0f);
  float d = 1.0f;
  for (int i = 0; i < exponent; ++i) d *= lc;
  return k / d;
}

void arc_lengths(std::span<const Vec4f> rest, std::span<float> out) {
  out[0] = 0.0f;
  for (std::size_t i = 1; i < rest.size(); ++i) out[i] = out[i - 1] + (xyz(rest[i]) - xyz(rest[i - 1])).norm();
}

float tilt_factor(const Vec3f& up, const Vec3f& head_up, float min_fraction) {
  const float s = 0.5f * (up.dot(head_up) + 1.0f);
  return s * (1.0f - min_fraction) + min_fraction;
}

void head_references(std::span<const Vec3f> local, std::span<const float> lift, const Affine3f& head,
                     const Vec3f& gravity, std::span<Vec3f> ref) {
  for (std::size_t i = 0; i < local.size(); ++i) ref[i] = head * local[i] - gravity * lift[i];
}

void add_spring_acceleration(std::span<Vec4f> pos, std::span<const Vec4f> prev, std::span<const Vec3f> ref,
                             std::span<const float> k, float scale, float dt) {
  const float dt2 = dt * dt;
  for (std::size_t i = 0; i < pos.size(); ++i) {
    if (pos[i].w() == 0.0f) continue;
    pos[i].head<3>() += (scale * k[i] * dt2) * (ref[i] - xyz(prev[i]));
  }
}

void spring_setup(std::span<const Vec4f> rest, float stiffness, float c, int exponent, std::span<float> k,
                  std::span<float> lift) {
  std::vector<float> arc(rest.size());
  arc_lengths(rest, arc);
  for (std::size_t i = 0; i < rest.size(); ++i) {
    k[i] = falloff_stiffness(stiffness, arc[i], c, exponent);
    // §4.4: the reference node is the rest node, fixed relative to the head, "displaced
    // vertically ... to compensate for gravity" by L = mg/k (g/k_L per unit mass). The
    // displacement is along world up, so the head-transformed rest shape is in
    // equilibrium in any head pose while k_m = k, which is what the tilt weakening relaxes.
    lift[i] = k[i] > 0.0f ? 1.0f / k[i] : 0.0f;
  }
}

void cascade_setup(std::span<const Vec4f> rest, float stiffness, float c, int exponent, float down_fraction,
                   CascadeFrames frames, std::span<float> inv_mass, std::span<float> k_up,
                   std::span<float> k_down, std::span<float> lift, std::span<int> base, std::span<float> lever,
                   std::span<Mat3f> rest_space, std::span<Vec3f> up_local, std::span<Vec3f> down_local) {
  const std::size_t n = rest.size();
  std::vector<float> arc(n), edge(n, 0.0f);
  arc_lengths(rest, arc);
  for (std::size_t i = 1; i < n; ++i) edge[i] = arc[i] - arc[i - 1];
  const float tiny = rounding_sized_length(edge);
  for (std::size_t i = 0; i < n; ++i) {
    inv_mass[i] = rest[i].w();
    k_up[i] = k_down[i] = lift[i] = lever[i] = 0.0f;
    base[i] = -1;
    up_local[i] = down_local[i] = Vec3f::Zero();
  }
  for (std::size_t j = 1; j < n; ++j) {
    const int b = edge[j] < tiny ? base[j - 1] : static_cast<int>(j) - 1;
    base[j] = b;
    if (b >= 0) lever[j] = (xyz(rest[j]) - xyz(rest[static_cast<std::size_t>(b)])).norm();
  }
  for (std::size_t i = 1; i < n; ++i) {
    k_up[i] = falloff_stiffness(stiffness, arc[i], c, exponent);
    // Only nodes with a segment two below them have a downward reference node.
    if (i + 2 < n) k_down[i] = down_fraction * k_up[i];
    const float ksum = k_up[i] + k_down[i];
    lift[i] = ksum > 0.0f ? 1.0f / ksum : 0.0f;
  }
  const Vec3f root_dir = (xyz(rest[1]) - xyz(rest[0])).normalized();
  tangent_spaces(rest, root_tangent_space(root_dir), frames, base, rest_space);
  // §4.3: the reference nodes are the rest positions of the nodes in the tangent spaces
  // of the rest shape.
  auto p = [&](std::size_t i) -> Vec3f { return xyz(rest[i]); };
  for (std::size_t i = 1; i < n; ++i) {
    up_local[i] = rest_space[i - 1].transpose() * (p(i) - p(i - 1));
    if (i + 2 < n) down_local[i] = rest_space[i + 2].transpose() * (p(i) - p(i + 2));
  }
}

Mat3f root_tangent_space(const Vec3f& n) {
  // Any T across the root segment will do; the cascade carries it to every segment.
  Vec3f b = n.cross(Vec3f::UnitZ());
  if (b.squaredNorm() < 1e-8f) b = n.cross(Vec3f::UnitX());
  b.normalize();
  Mat3f m;
  m.col(0) = b;
  m.col(1) = n;
  m.col(2) = n.cross(b);
  return m;
}

void tangent_spaces(std::span<const Vec4f> pos, const Mat3f& root, CascadeFrames frames,
                    std::span<const int> base, std::span<Mat3f> space) {
  space[0] = root;
  for (std::size_t j = 1; j < pos.size(); ++j) {
    const Mat3f& parent = space[j - 1];
    const Vec3f d = xyz(pos[j]) - xyz(pos[j - 1]);
    const float len = d.norm();
    if (base[j] != static_cast<int>(j) - 1 || !(len > 0.0f)) {
      space[j] = parent;
      continue;
    }
    const Vec3f n = d / len;
    Vec3f b;
    bool ok;
    if (frames == CascadeFrames::Cross) {
      b = n.cross(parent.col(2));
      const float bl = b.norm();
      ok = bl > 1e-6f;
      if (ok) b /= bl;
    } else {
      // Rodrigues' formula for the rotation about a = N_{j-1} × N_j by the angle between
      // them: v -> c v + a × v + (a·v) a / (1 + c), c = N_{j-1}·N_j.
      const Vec3f n0 = parent.col(1);
      const float c = n0.dot(n);
      ok = c > -0.999f;
      if (ok) {
        const Vec3f a = n0.cross(n);
        const Vec3f b0 = parent.col(0);
        b = c * b0 + a.cross(b0) + (a.dot(b0) / (1.0f + c)) * a;
        b = (b - b.dot(n) * n).normalized();
      }
    }
    if (!ok) b = (parent.col(0) - parent.col(0).dot(n) * n).normalized();
    space[j].col(0) = b;
    space[j].col(1) = n;
    space[j].col(2) = n.cross(b);
  }
}

namespace {
// One reference spring of cascade_accelerations: vertex i towards the node `local` of
// space j. Adds the spring's load on the twist of space j about its N to twist[j].
void reference_spring(std::span<const Vec4f> pos, std::span<const Mat3f> space, const CascadeStrand& s,
                      bool reactions, const Vec3f& head_gravity, std::size_t i, std::size_t j,
                      const Vec3f& local, float k, std::span<float> twist, std::span<Vec3f> acc) {
  const Mat3f& m = space[j];
  const Vec3f d = m * local;
  // The stretch from the offsets (d and P_i - P_j, a segment or two long), not from the
  // positions themselves: its rounding is that of the strand's scale, not the head's.
  const Vec3f elastic = k * (d - (xyz(pos[i]) - xyz(pos[j])));
  if (s.inv_mass[i] != 0.0f) acc[i] += elastic - (k * s.lift[i]) * head_gravity;
  const int a = s.base[j];
  if (!reactions || a < 0) return;
  const Vec3f r = -elastic;
  const Vec3f fa = (m.col(1).dot(r) * d - local.y() * r) / s.lever[j];
  if (s.inv_mass[j] != 0.0f) acc[j] += r - fa;
  if (s.inv_mass[static_cast<std::size_t>(a)] != 0.0f) acc[static_cast<std::size_t>(a)] += fa;
  twist[j] += m.col(1).dot(d.cross(elastic));
}

// The springs' reaction through the twist of the spaces (CascadeFrames::Transport): space
// j is its parent's carried by the smallest rotation from N_{j-1} to N_j, so every bend
// between the root and segment j turns it about N_j (the frames' holonomy). A bend
// between directions N_p and N (segments p and j, p the last one before j with a space of
// its own; for j = 1 the root's given N), κ = N_p × N / (1 + N_p · N) half its curvature
// binormal, turns the spaces from j on by -κ · dx / |e_j| for a move dx of P_j, κ · dx /
// |e_j| for one of P_{j-1}, and likewise through e_p, κ · dx / |e_p| for P_{p-1} and
// -κ · dx / |e_p| for P_p (the holonomy gradient of discrete elastic rods, Bergou et al.
// 2008). twist[j] holds dE/dψ_j of the springs space j carries, summed tip
// to root into each bend's load.
void twist_reactions(std::span<const Vec4f> pos, std::span<const Mat3f> space, const CascadeStrand& s,
                     std::span<const float> twist, std::span<Vec3f> acc) {
  const std::size_t n = pos.size();
  auto own = [&](std::size_t j) {
    return s.base[j] == static_cast<int>(j) - 1 && (xyz(pos[j]) - xyz(pos[j - 1])).norm() > 0.0f;
  };
  auto push = [&](std::size_t to, std::size_t from, const Vec3f& f) {
    if (s.inv_mass[to] != 0.0f) acc[to] += f;
    if (s.inv_mass[from] != 0.0f) acc[from] -= f;
  };
  float load = 0.0f;
  for (std::size_t j = n - 1; j >= 1; --j) {
    load += twist[j];
    if (!own(j)) continue;
    const Vec3f& nj = space[j].col(1);
    const Vec3f& np = space[j - 1].col(1);
    const float c = np.dot(nj);
    if (!(c > -0.999f)) continue;  // folded back: the transport is undefined there
    const Vec3f kappa = np.cross(nj) / (1.0f + c);
    push(j, j - 1, (load / (xyz(pos[j]) - xyz(pos[j - 1])).norm()) * kappa);
    std::size_t p = j - 1;
    while (p >= 1 && !own(p)) --p;
    if (p >= 1) push(p, p - 1, (load / (xyz(pos[p]) - xyz(pos[p - 1])).norm()) * kappa);
  }
}
}  // namespace

void cascade_accelerations(std::span<const Vec4f> pos, std::span<const Mat3f> space, const CascadeStrand& s,
                           bool reactions, CascadeFrames frames, const Vec3f& gravity, const Vec3f& head_gravity,
                           std::span<float> twist, std::span<Vec3f> acc) {
  const std::size_t n = pos.size();
  for (std::size_t i = 0; i < n; ++i) {
    acc[i] = gravity;
    twist[i] = 0.0f;
  }
  for (std::size_t j = 0; j < n; ++j) {
    if (j + 1 < n)
      reference_spring(pos, space, s, reactions, head_gravity, j + 1, j, s.up_local[j + 1], s.k_up[j + 1], twist,
                       acc);
    if (j >= 3)
      reference_spring(pos, space, s, reactions, head_gravity, j - 2, j, s.down_local[j - 2], s.k_down[j - 2], twist,
                       acc);
  }
  if (reactions && frames == CascadeFrames::Transport) twist_reactions(pos, space, s, twist, acc);
}

void add_acceleration(std::span<Vec4f> pos, std::span<Vec4f> step, std::span<const Vec3f> acc, float dt) {
  const float dt2 = dt * dt;
  for (std::size_t i = 0; i < pos.size(); ++i) {
    if (pos[i].w() == 0.0f) continue;
    const Vec3f a = dt2 * acc[i];
    pos[i].head<3>() += a;
    step[i].head<3>() += a;
  }
}

namespace {
Mat3f rotation_about(int axis, float angle) {
  return Eigen::AngleAxisf(angle, Vec3f::Unit(axis)).toRotationMatrix();
}
int primary_axis(ForestAxes axes) { return axes == ForestAxes::ParentX ? 0 : 2; }
}  // namespace

Mat3f forest_joint_rotation(ForestAxes axes, float theta, float phi) {
  return rotation_about(primary_axis(axes), theta) * rotation_about(1, phi);
}

void forest_angles(ForestAxes axes, const Vec3f& d, float& theta, float& phi) {
  if (axes == ForestAxes::ParentZ) {
    // R_z(θ) R_y(φ) z = (cos θ sin φ, sin θ sin φ, cos φ); straight (d = z) is the
    // gimbal configuration where θ has no effect, taken as θ = 0.
    phi = std::atan2(std::sqrt(d.x() * d.x() + d.y() * d.y()), d.z());
    theta = (d.x() == 0.0f && d.y() == 0.0f) ? 0.0f : std::atan2(d.y(), d.x());
  } else {
    // R_x(θ) R_y(φ) z = (sin φ, -sin θ cos φ, cos θ cos φ).
    phi = std::atan2(d.x(), std::sqrt(d.y() * d.y() + d.z() * d.z()));
    theta = std::atan2(-d.y(), d.z());
  }
}

Mat3f forest_root_frame(const Vec3f& z) {
  Vec3f y = z.cross(Vec3f::UnitX());
  if (y.squaredNorm() < 1e-8f) y = z.cross(Vec3f::UnitZ());
  y.normalize();
  Mat3f m;
  m.col(0) = y.cross(z);
  m.col(1) = y;
  m.col(2) = z;
  return m;
}

void forest_rest(std::span<const Vec4f> rest, ForestAxes axes, std::span<Mat3f> rest_frame,
                 std::span<float> theta0, std::span<float> phi0, std::span<float> length) {
  const std::size_t n = rest.size();
  rest_frame[0] = forest_root_frame((xyz(rest[1]) - xyz(rest[0])).normalized());
  theta0[0] = phi0[0] = 0.0f;
  length[0] = 0.0f;
  for (std::size_t i = 1; i < n; ++i) {
    const Vec3f d = xyz(rest[i]) - xyz(rest[i - 1]);
    length[i] = d.norm();
    if (rest[i].w() == 0.0f) {
      // Rigid with the head: its own direction, whatever the parent's.
      rest_frame[i] = forest_root_frame(d / length[i]);
      theta0[i] = phi0[i] = 0.0f;
      continue;
    }
    const Mat3f& parent = rest_frame[i - 1];
    forest_angles(axes, parent.transpose() * (d / length[i]), theta0[i], phi0[i]);
    rest_frame[i] = parent * forest_joint_rotation(axes, theta0[i], phi0[i]);
  }
}

float forest_setup(std::span<const Vec4f> rest, ForestAxes axes, float stiffness, float c, int exponent,
                   std::span<Mat3f> rest_frame, std::span<float> theta0, std::span<float> phi0,
                   std::span<float> length, std::span<float> k) {
  const std::size_t n = rest.size();
  forest_rest(rest, axes, rest_frame, theta0, phi0, length);
  std::vector<float> arc(n);
  arc_lengths(rest, arc);
  k[0] = 0.0f;
  // The joint of segment i sits at vertex i-1.
  for (std::size_t i = 1; i < n; ++i) k[i] = falloff_stiffness(stiffness, arc[i - 1], c, exponent);
  return 1.0f / arc[n - 1];
}

namespace {
// Whether s K − C is positive definite for one chain's tridiagonal K (stiffness kk, see
// forest_rest_stiffness_scale) and diagonal C: every pivot of its LDLᵀ factorisation > 0.
bool chain_definite(std::span<const double> kk, std::span<const double> c, double s) {
  double pivot = 0.0;
  for (std::size_t j = 0; j < kk.size(); ++j) {
    const double next = j + 1 < kk.size() ? kk[j + 1] : 0.0;
    const double diagonal = s * (kk[j] + next) - c[j];
    const double coupling = j > 0 ? s * kk[j] : 0.0;
    pivot = j > 0 ? diagonal - coupling * coupling / pivot : diagonal;
    if (!(pivot > 0.0)) return false;
  }
  return true;
}

// The smallest s with s K − C semi-definite, by bisection on definiteness (monotone in s,
// K being definite); 0 where C has no positive entry.
double chain_buckling_scale(std::span<const double> kk, std::span<const double> c) {
  if (std::none_of(c.begin(), c.end(), [](double v) { return v > 0.0; })) return 0.0;
  double lo = 0.0, hi = 1.0;
  for (int i = 0; i < 128 && !chain_definite(kk, c, hi); ++i) {
    lo = hi;
    hi *= 2.0;
  }
  for (int i = 0; i < 60; ++i) {
    const double mid = 0.5 * (lo + hi);
    (chain_definite(kk, c, mid) ? hi : lo) = mid;
  }
  return hi;
}
}  // namespace

float forest_rest_inertia_scale(std::span<const Vec4f> rest, std::span<const float> length,
                                std::span<const float> k, float inv_strand_length, const Vec3f& gravity,
                                double margin) {
  const double g = gravity.cast<double>().norm();
  if (!(g > 0.0)) return 1.0f;
  const Eigen::Vector3d up = -gravity.cast<double>() / g;
  double scale = 0.0;
  std::vector<double> kk, c;
  // Each run of free segments is a chain whose parent is rigid with the head.
  for (std::size_t i = 1; i <= rest.size(); ++i) {
    if (i < rest.size() && rest[i].w() != 0.0f) {
      // A zero-length segment has no direction for gravity to turn.
      const double l = length[i];
      const double rise = l > 0.0 ? (xyz(rest[i]) - xyz(rest[i - 1])).cast<double>().dot(up) / l : 0.0;
      kk.push_back(k[i]);
      c.push_back(g * rise * double(inv_strand_length));
      continue;
    }
    if (!kk.empty() && std::all_of(kk.begin(), kk.end(), [](double v) { return v > 0.0; }))
      scale = std::max(scale, chain_buckling_scale(kk, c));
    kk.clear();
    c.clear();
  }
  return static_cast<float>(std::max(1.0, margin * scale));
}

Mat34f root_inertia(const Affine3f& head, const Affine3f& h1, const Affine3f& h0, float dt) {
  const Eigen::Matrix4f second = head.matrix() - 2.0f * h1.matrix() + h0.matrix();
  return (second * head.inverse(Eigen::Isometry).matrix()).topRows<3>() / (dt * dt);
}

Vec3f head_angular_acceleration(const Affine3f& head, const Affine3f& h1, const Affine3f& h0, float dt) {
  const Mat3f m = (head.linear() - 2.0f * h1.linear() + h0.linear()) * h1.linear().transpose() / (dt * dt);
  return 0.5f * Vec3f(m(2, 1) - m(1, 2), m(0, 2) - m(2, 0), m(1, 0) - m(0, 1));
}

void forest_pose(const ForestStrand& s, ForestAxes axes, const Affine3f& head) {
  const Mat3f head_rotation = head.linear();
  const std::size_t n = s.pos.size();
  for (std::size_t i = 0; i < n; ++i) {
    if (s.rest[i].w() == 0.0f) {
      s.frame[i] = head_rotation * s.rest_frame[i];
      s.pos[i].head<3>() = head * xyz(s.rest[i]);
      continue;
    }
    s.frame[i] = s.frame[i - 1] * forest_joint_rotation(axes, s.theta[i], s.phi[i]);
    s.pos[i].head<3>() = xyz(s.pos[i - 1]) + s.length[i] * s.frame[i].col(2);
  }
}

namespace {
// External acceleration at a free segment end: gravity, the part of the wind that meets
// the segment face-on (as verlet_integrate), the inertial force of the moving root, and
// a penalty pushing the end out of any sphere it is inside, damped along the sphere's
// normal: v is the end's velocity relative to the head.
Vec3f external_acceleration(const ForestForces& f, const Vec3f& p, const Vec3f& z, const Vec3f& v) {
  const Vec3f root = f.inertia.leftCols<3>() * p + f.inertia.col(3);
  Vec3f a = f.gravity - root;
  if (f.wind.active()) {
    const Vec3f w = f.wind.acceleration();
    a += w - w.dot(z) * z;
  }
  const float push = f.collision_stiffness / (f.dt * f.dt);
  const float damp = 2.0f * f.collision_damping * std::sqrt(f.collision_stiffness) / f.dt;
  for (const Vec4f& sphere : f.spheres) {
    const Vec3f d = p - xyz(sphere);
    const float r = sphere.w();
    const float dist2 = d.squaredNorm();
    if (dist2 >= r * r) continue;
    const float dist = std::sqrt(dist2);
    const Vec3f normal = dist > 0.0f ? Vec3f(d / dist) : Vec3f::UnitY();
    // The damping is held within damp · depth / dt, so the force still starts from 0 as the
    // end enters the sphere: a jump there would let a rounding-sized difference of where
    // the end is decide a finite difference of force.
    const float depth = r - dist, limit = damp * depth / f.dt, along = damp * v.dot(normal);
    a += (push * depth - (along < -limit ? -limit : limit < along ? limit : along)) * normal;
  }
  return a;
}
}  // namespace

void forest_integrate(const ForestStrand& s, ForestAxes axes, const ForestForces& f) {
  const std::size_t n = s.pos.size();
  const int primary = primary_axis(axes);
  // Eq. 4.2.2: each joint's spring torque (kθ + vθ')a_p + (kφ + vφ')y, a_p the parent's
  // primary axis (z originally, x with §5.9's fix) and y the joint's y axis.
  for (std::size_t i = 1; i < n; ++i) {
    if (s.rest[i].w() == 0.0f) {
      s.joint_torque[i] = Vec3f::Zero();
      continue;
    }
    const Vec3f a = s.frame[i - 1].col(primary);
    const Vec3f y = s.frame[i].col(1);
    s.joint_torque[i] = (s.k[i] * (s.theta[i] - s.theta0[i]) + f.joint_damping * s.dtheta[i]) * a +
                        (s.k[i] * (s.phi[i] - s.phi0[i]) + f.joint_damping * s.dphi[i]) * y;
  }
  Vec3f parent_acc = f.root_angular_acceleration;
  // The segment's angular velocity and its end's velocity relative to the head, summed
  // from the root over the joint rates (θ' about a_p, φ' about y: Eq. 4.2.6's state).
  Vec3f spin = Vec3f::Zero(), velocity = Vec3f::Zero();
  for (std::size_t i = 1; i < n; ++i) {
    if (s.rest[i].w() == 0.0f) {
      spin = velocity = Vec3f::Zero();
      continue;
    }
    const Vec3f z = s.frame[i].col(2);
    const Vec3f p = xyz(s.pos[i]);
    spin += s.dtheta[i] * s.frame[i - 1].col(primary) + s.dphi[i] * s.frame[i].col(1);
    velocity += spin.cross(s.length[i] * z);
    // Eq. 4.2.1, 4.2.4 and 4.2.3: the external torque (less gravity's on the rest
    // segment) as an angular acceleration, minus the joint's own spring, plus its child's.
    Vec3f torque = z.cross(external_acceleration(f, p, z, velocity));
    if (f.gravity_compensation) {
      // The part of gravity normal to the head-transformed rest segment z0, as a constant
      // force: z × g_n with g_n = g − (g · z0) z0 cancels gravity's torque in the rest pose
      // and, being a force, does no net work round a closed path of the segment (a
      // constant torque would: in 3D it pumps a segment that circles).
      const Vec3f z0 = f.head_rotation * s.rest_frame[i].col(2);
      torque -= z.cross(f.gravity - f.gravity.dot(z0) * z0);
    }
    const float gain = f.inertia_model == ForestInertia::Mass ? s.length[i] : f.inv_inertia_length;
    Vec3f acc = gain * torque - s.joint_torque[i];
    if (i + 1 < n) acc += s.joint_torque[i + 1];
    // Eq. 4.2.5: relative to the parent, projected on the joint axes.
    const Vec3f rel = acc - parent_acc;
    parent_acc = acc;
    const float ddtheta = s.frame[i - 1].col(primary).dot(rel);
    const float ddphi = s.frame[i].col(1).dot(rel);
    // Eq. 4.2.6: explicit Euler, the angle advanced with the velocity of the step's start.
    s.theta[i] += s.dtheta[i] * f.dt;
    s.phi[i] += s.dphi[i] * f.dt;
    s.dtheta[i] = (s.dtheta[i] + ddtheta * f.dt) * f.keep;
    s.dphi[i] = (s.dphi[i] + ddphi * f.dt) * f.keep;
  }
}

}  // namespace hairbench::kernels
