// Properties Halén & Wester 2007 claim for (or that define) the spring (§4.4), cascading
// spaces (§4.3) and interactive forest (§4.2, §5.9) models.
#include "test_support.h"

#include "harness/probe.h"
#include "kernels/halen2007/nodes.h"
#include "kernels/halen2007/reference/halen_kernels.h"
#include "models/halen2007/step_bounds.h"
#include "models/registry.h"
#include "reports/metrics.h"
#include "scenarios/groom_gen.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <map>

namespace hairbench {
namespace {

using test::builtin;

const std::vector<std::string> kHalen = {"halen_spring", "halen_cascade", "halen_forest"};

// A head that turns 90° about the vertical and moves 10 cm within 0.15 s, then holds
// still for 3.85 s, gravity on. No tilt, so the spring model's k_m stays k and the
// head-transformed rest shape is every model's equilibrium (gravity compensation).
Scenario turn_and_hold(std::size_t keep_every) {
  Scenario sc = builtin("idle", keep_every);
  sc.head.oscillators.clear();
  HeadKey a, b;
  b.t = 0.15;
  b.translate = Vec3f(0.1f, 0.0f, 0.0f);
  b.axis = Vec3f::UnitY();
  b.angle = M_PI / 2;
  sc.head.keys = {a, b};
  sc.frames = 240;
  return sc;
}

// The `idle` groom with `vertices` per strand, every `keep_every`-th strand (the same
// roots in every vertex count).
Groom idle_groom(int vertices, std::size_t keep_every) {
  const Scenario sc = builtin("idle", 1);
  GroomSpec spec;
  spec.vertices_per_strand = vertices;
  return every_nth_strand(generate_groom(spec, sc.head_radius, "test").groom, keep_every);
}

// §4 criterion 1, "the ability to return to a predefined position at rest": after the
// head stops, each model comes back to the head-transformed rest shape. Bounds, in L-bar:
// spring 1e-3, forest 2e-2 and cascade 5e-3 are settled states (about ten times what each
// shows, to leave room for compiler differences). The cascade, at the thesis's 8 nodes
// with its springs' reactions as the gradient of their energy, comes back as the others
// do, on a 16-vertex groom (0.29 -> 4e-4) and an 8-vertex one (0.52 -> 3e-3).
TEST(HalenModels, ReturnToRestShapeAfterHeadStops) {
  const auto runs = test::run(turn_and_hold(16), kHalen);
  const std::map<std::string, double> bound = {{"halen_spring", 1e-3}, {"halen_forest", 2e-2}, {"halen_cascade", 5e-3}};
  const std::map<std::string, double> back = {{"halen_spring", 0.5}, {"halen_forest", 0.5}, {"halen_cascade", 0.5}};
  for (const RunRecord& r : runs) {
    ASSERT_FALSE(r.failure) << r.model;
    const double peak = test::max_of(r.series("rest_shape_error"));
    RecordProperty(r.model + "_peak", std::to_string(peak));
    RecordProperty(r.model + "_final", std::to_string(r.series("rest_shape_error").back()));
    EXPECT_GT(peak, 0.05) << r.model << ": the turn should disturb the hair";
    EXPECT_LT(r.series("rest_shape_error").back(), bound.at(r.model)) << r.model;
    EXPECT_LT(r.series("rest_shape_error").back(), back.at(r.model) * peak) << r.model;
  }
  Scenario eight = turn_and_hold(16);
  eight.groom = idle_groom(8, 16);
  const RunRecord c = test::run(eight, {"halen_cascade"}).front();
  ASSERT_FALSE(c.failure);
  const double peak = test::max_of(c.series("rest_shape_error"));
  RecordProperty("halen_cascade_8_peak", std::to_string(peak));
  RecordProperty("halen_cascade_8_final", std::to_string(c.series("rest_shape_error").back()));
  EXPECT_GT(peak, 0.05);
  EXPECT_LT(c.series("rest_shape_error").back(), 0.1 * peak);
}

// §4 criterion 2, fixed length, of the simulated nodes (the stretched verdict's edges).
// The forest rebuilds positions from angles (§4.2: "the length of every segment is always
// kept constant"): exact to float rounding. The position models correct lengths with
// Eq. 4.2 and stay within 1% RMS on `shake`. The groom's vertices drawn between the nodes
// (§5.5) follow their segments and stay within 1% RMS too.
TEST(HalenModels, SegmentLengthsOnShake) {
  const auto runs = test::run(builtin("shake", 8), kHalen);
  for (const RunRecord& r : runs) {
    ASSERT_FALSE(r.failure) << r.model;
    RecordProperty(r.model + "_node_edge_peak", std::to_string(r.verdict.stretch.peak));
    if (r.model == "halen_forest")
      EXPECT_LT(r.verdict.stretch.peak, 1e-5) << r.model;
    else
      EXPECT_LT(r.verdict.stretch.peak, 0.5) << r.model;
    EXPECT_LT(test::rms_of(r.series("length_error_rms")), 0.01) << r.model;
  }
}

// §4.4: "As the head is tilted the spring strength is reduced", so that hair held up by
// its springs falls under gravity when the head is upside down. With α = k (tilt_min 1)
// the springs hold the head-transformed rest shape exactly (their displacement cancels
// gravity in any pose); with k_m the hair hangs away from it.
TEST(HalenSpring, TiltWeakeningLetsHairFallUpsideDown) {
  const Scenario sc = builtin("tilt_upside_down", 8);
  const auto weak = test::run(sc, {"halen_spring"});
  const auto stiff = test::run(sc, {"halen_spring"}, {{"halen_spring", "tilt_min", 1.0}});
  const RunRecord& w = test::find(weak, "halen_spring");
  const RunRecord& s = test::find(stiff, "halen_spring");
  ASSERT_FALSE(w.failure);
  ASSERT_FALSE(s.failure);
  const double hang_weak = w.series("rest_shape_error").back(), hang_stiff = s.series("rest_shape_error").back();
  RecordProperty("hang_weakened", std::to_string(hang_weak));
  RecordProperty("hang_alpha_equals_k", std::to_string(hang_stiff));
  EXPECT_LT(hang_stiff, 1e-3);
  EXPECT_GT(hang_weak, 0.03);
  EXPECT_GT(hang_weak, 10.0 * hang_stiff);
}

// A straight strand hanging from a still head, gravity off, wind (a force normal to the
// strand) along `wind_dir` for 0.5 s; returns the largest deviation from rest, / L-bar.
double straight_strand_response(int axis_convention, const Vec3f& wind_dir) {
  Scenario sc = builtin("idle", 1000);
  Groom g;
  g.head_radius = sc.groom.head_radius;
  g.positions.clear();
  std::vector<Vec3f> pts;
  for (int i = 0; i < 16; ++i) pts.emplace_back(0.0f, 0.1f - 0.25f * static_cast<float>(i) / 15.0f, 0.0f);
  g.add_strand(pts, 0);
  sc.groom = g;
  sc.gravity = Vec3f::Zero();
  sc.colliders.clear();
  sc.wind.direction = wind_dir;
  sc.wind.keys = {{0.0, 5.0}, {0.5, 5.0}, {0.5001, 0.0}};
  const auto runs = test::run(sc, {"halen_forest"}, {{"halen_forest", "axis_convention", double(axis_convention)}}, 1, 60);
  const RunRecord& r = test::find(runs, "halen_forest");
  EXPECT_FALSE(r.failure);
  return test::max_of(r.series("rest_shape_error"));
}

// §5.9: with Di Giacomo et al.'s axes a straight strand lies along the primary (z)
// axis; a force along the joint's y axis gives a torque along x, orthogonal to both joint
// axes, so "it's completely stiff to such forces". With the parent's x axis as primary
// axis the same force bends it. A force along x bends it in both conventions.
TEST(HalenForest, GimbalStiffnessAndTheXAxisFix) {
  const Vec3f z(0.0f, -1.0f, 0.0f);  // the strand's direction
  const kernels::Mat3f frame = kernels::forest_root_frame(z);
  const Vec3f y = frame.col(1), x = frame.col(0);
  const double fixed_y = straight_strand_response(1, y);
  const double original_y = straight_strand_response(0, y);
  const double original_x = straight_strand_response(0, x);
  RecordProperty("fix_force_along_y", std::to_string(fixed_y));
  RecordProperty("original_force_along_y", std::to_string(original_y));
  RecordProperty("original_force_along_x", std::to_string(original_x));
  EXPECT_GT(fixed_y, 0.05);
  EXPECT_LT(original_y, 1e-4);
  EXPECT_GT(original_x, 0.05);
}

// One strand of the interactive forest at its rest angles, with the model's defaults
// (settings.h) for the joint stiffness and its falloff, stepped by the kernels directly.
struct ForestFixture {
  std::vector<Vec4f> rest, pos;
  std::vector<kernels::Mat3f> rest_frame, frame;
  std::vector<float> length, theta0, phi0, k, theta, phi, dtheta, dphi;
  std::vector<Vec3f> joint_torque;
  float inv_length = 0.0f;

  ForestFixture(std::vector<Vec4f> points, float stiffness)
      : rest(std::move(points)), pos(rest), rest_frame(rest.size()), frame(rest.size()), length(rest.size()),
        theta0(rest.size()), phi0(rest.size()), k(rest.size()), dtheta(rest.size(), 0.0f), dphi(rest.size(), 0.0f),
        joint_torque(rest.size()) {
    inv_length = kernels::forest_setup(rest, kernels::ForestAxes::ParentX, stiffness, 5.0f, 2, rest_frame, theta0,
                                       phi0, length, k);
    theta = theta0;
    phi = phi0;
  }
  kernels::ForestStrand view() {
    return {rest, rest_frame, length, theta0, phi0, k, theta, phi, dtheta, dphi, frame, joint_torque, pos};
  }
  // Poses the strand under `head` and takes one integration step.
  void step(const Affine3f& head, kernels::ForestForces f) {
    kernels::forest_pose(view(), kernels::ForestAxes::ParentX, head);
    f.head_rotation = head.linear();
    f.inv_inertia_length = inv_length;
    kernels::forest_integrate(view(), kernels::ForestAxes::ParentX, f);
  }
  // Largest distance of a vertex from the head-transformed rest pose, / strand length.
  double rest_error(const Affine3f& head) const {
    double worst = 0.0;
    for (std::size_t i = 0; i < rest.size(); ++i)
      worst = std::max(worst, double((pos[i].head<3>() - head * rest[i].head<3>()).norm()));
    return worst * inv_length;
  }
};

// A straight strand of n vertices (two pinned) along +x from the origin, 25 cm long.
std::vector<Vec4f> straight_strand(int n) {
  std::vector<Vec4f> v;
  for (int i = 0; i < n; ++i) v.emplace_back(0.25f * static_cast<float>(i) / static_cast<float>(n - 1), 0.0f, 0.0f,
                                             i < 2 ? 0.0f : 1.0f);
  return v;
}

// gravity_compensation: gravity's torque on the head-transformed rest segment is taken
// away, so a wavy strand under a tilted head stays where the head carries its rest pose
// (within 1e-6 of its length, rounding) through a second of substeps under gravity;
// without it (§4.2 as written) gravity bends the strand (by 5e-3 of its length) until the
// joint springs hold it.
TEST(HalenForest, GravityCompensationHoldsTheHeadTransformedRestPose) {
  GroomSpec spec;
  spec.style = "wavy";
  spec.strands = 1;
  const Groom g = generate_groom(spec, 0.1f, "halen_test").groom;
  Affine3f head = Affine3f::Identity();
  head.translate(Vec3f(0.02f, -0.05f, 0.01f));
  head.rotate(Eigen::AngleAxisf(1.2f, Vec3f(1.0f, 0.0f, 1.0f).normalized()));
  std::map<bool, double> error;
  for (bool compensate : {true, false}) {
    ForestFixture strand(g.positions, 5000.0f);
    kernels::ForestForces f;
    f.gravity = Vec3f(0.0f, -9.81f, 0.0f);
    f.joint_damping = 120.0f;
    f.dt = 1.0f / 720.0f;
    f.gravity_compensation = compensate;
    for (int i = 0; i < 720; ++i) strand.step(head, f);
    error[compensate] = strand.rest_error(head);
  }
  RecordProperty("compensated", std::to_string(error[true]));
  RecordProperty("uncompensated", std::to_string(error[false]));
  EXPECT_LT(error[true], 1e-6);
  EXPECT_GT(error[false], 1e-3);
}

// Eq. 4.2.4's J for the external torques, on a straight horizontal strand without joint
// springs, at rest under gravity: the first free joint takes the whole angular
// acceleration and the others none (the strand starts to turn rigidly about its root).
// With J = m L ℓ it is g / ℓ, a pendulum of the strand's length whatever the segment
// count; with §4.2's J ≈ mI it is L g, the torque per unit mass, proportional to the
// segment length L.
TEST(HalenForest, InertiaChoiceSetsTheSwingOfAStraightStrand) {
  const float g = 9.81f, dt = 1.0f / 720.0f;
  for (const auto inertia : {kernels::ForestInertia::StrandPendulum, kernels::ForestInertia::Mass})
    for (int n : {9, 17}) {
      ForestFixture strand(straight_strand(n), 0.0f);
      kernels::ForestForces f;
      f.gravity = Vec3f(0.0f, -g, 0.0f);
      f.dt = dt;
      f.gravity_compensation = false;
      f.inertia_model = inertia;
      strand.step(Affine3f::Identity(), f);
      const float segment = 0.25f / static_cast<float>(n - 1);
      const float expected = inertia == kernels::ForestInertia::Mass ? segment * g : g / 0.25f;
      const float speed = std::hypot(strand.dtheta[2], strand.dphi[2]);
      EXPECT_NEAR(speed, expected * dt, 1e-4f * expected * dt) << int(inertia) << " n " << n;
      for (int i = 3; i < n; ++i) EXPECT_LT(std::hypot(strand.dtheta[i], strand.dphi[i]), 1e-6f * speed) << i;
    }
}

// head_angular_acceleration recovers a head turning at a constant 30 rad/s² about a tilted
// axis (already at 9.8 rad/s, and moving) from three substeps.
TEST(HalenForest, HeadAngularAccelerationFromTheRootInertia) {
  const Vec3f axis = Vec3f(0.3f, 1.0f, -0.4f).normalized();
  const float alpha = 30.0f, dt = 1.0f / 720.0f;
  auto head_at = [&](float t) {
    Affine3f h = Affine3f::Identity();
    h.translate(Vec3f(0.5f * t * t, 0.1f * t, 0.0f));
    h.rotate(Eigen::AngleAxisf(0.5f * alpha * t * t + 0.8f * t, axis));
    return h;
  };
  const float t = 0.3f;
  const Vec3f a = kernels::head_angular_acceleration(head_at(t), head_at(t - dt), head_at(t - 2 * dt), dt);
  EXPECT_LT((a - alpha * axis).norm(), 0.02f * alpha) << a.transpose();
}

// root_angular_acceleration: Eq. 4.2.5 subtracts the parent's angular acceleration, and
// the first free joint's parent is rigid with the head. Without springs, forces or the
// root's inertial force, that joint then turns against the head at its angular
// acceleration, so the strand keeps its direction in the world while the head turns.
TEST(HalenForest, FirstJointSubtractsTheHeadsAngularAcceleration) {
  const float dt = 1.0f / 720.0f;
  ForestFixture strand(straight_strand(9), 0.0f);
  kernels::ForestForces f;
  f.dt = dt;
  // About the strand's primary joint axis at the root (forest_root_frame: z × Z for a
  // strand along x, then x = y × z = Z).
  f.root_angular_acceleration = Vec3f(0.0f, 0.0f, 40.0f);
  strand.step(Affine3f::Identity(), f);
  EXPECT_NEAR(strand.dtheta[2], -40.0f * dt, 1e-5f);
  EXPECT_NEAR(strand.dphi[2], 0.0f, 1e-6f);
  for (int i = 3; i < 9; ++i) EXPECT_LT(std::hypot(strand.dtheta[i], strand.dphi[i]), 1e-6f) << i;
}

// The thesis as written (settings.h): no gravity compensation, J ≈ mI, the head's
// angular acceleration subtracted at the first joint, no drag, an undamped penalty. It runs stably on the scenarios
// docs/limitations.md reports, and J ≈ mI leaves gravity a small fraction of the joint
// springs: at rest the hair sags, by less than 1e-3 L-bar. Known difference: the sphere
// penalty forces, scaled down with gravity, let `shake` push the hair deeper into the head
// than the defaults do.
TEST(HalenForest, ThesisAsWrittenIsStiffAndStable) {
  const std::vector<ParamOverride> thesis = {{"halen_forest", "gravity_compensation", 0},
                                             {"halen_forest", "inertia", 0},
                                             {"halen_forest", "root_angular_acceleration", 1},
                                             {"halen_forest", "drag", 0},
                                             {"halen_forest", "collision_damping", 0}};
  for (const char* name : {"idle", "shake", "tilt_upside_down", "spin_fast"}) {
    const auto runs = test::run(builtin(name, 16), {"halen_forest"}, thesis);
    const RunRecord& r = test::find(runs, "halen_forest");
    EXPECT_FALSE(r.failure) << name;
    EXPECT_EQ(r.verdict.status, verdict::Status::ok) << name << ": " << r.verdict.reason;
    if (std::string(name) == "idle") {
      EXPECT_GT(r.series("rest_shape_error").back(), 0.0) << "gravity is not compensated";
      EXPECT_LT(r.series("rest_shape_error").back(), 1e-3);
    }
    if (std::string(name) == "shake") {
      const auto defaults = test::run(builtin(name, 16), {"halen_forest"});
      EXPECT_GT(test::max_of(r.series("penetration")), test::max_of(test::find(defaults, "halen_forest").series("penetration")));
    }
  }
}

// Straight strands of `vertices` vertices and `length` metres standing up from the crown
// of the `idle` head (roots within 35° of the top, radial), as a mohawk's do.
Scenario upright_scenario(int vertices, double length) {
  Scenario sc = builtin("idle", 1);
  Groom g;
  const float r = sc.head_radius;
  for (int a = 0; a < 8; ++a)
    for (int b = 1; b <= 4; ++b) {
      const float tilt = 0.6f * static_cast<float>(b) / 4.0f, turn = 0.785f * static_cast<float>(a);
      const Vec3f dir(std::sin(tilt) * std::cos(turn), std::cos(tilt), std::sin(tilt) * std::sin(turn));
      std::vector<Vec3f> pts;
      for (int i = 0; i < vertices; ++i)
        pts.push_back(dir * (r + static_cast<float>(length) * static_cast<float>(i) / static_cast<float>(vertices - 1)));
      g.add_strand(pts, 0);
    }
  sc.groom = g;
  return sc;
}

// kernels::forest_rest_inertia_scale on one straight strand of m free segments with equal
// joints k (no falloff): K is the fixed-free chain, whose smallest eigenvalue is
// 4k sin²(π / (2(2m + 1))), and gravity turns each upright segment at g/ℓ per radian, so
// J must rise by margin · (g/ℓ) / that eigenvalue; a hanging or level strand, or no
// gravity, needs nothing.
TEST(HalenKernels, RestInertiaScaleIsTheChainsBucklingBound) {
  const int n = 32;  // 2 pinned + 30 free segments after the root edge
  const double length = 0.08, k = 5000.0, g = 9.81, margin = kernels::kForestRestMargin;
  auto scale = [&](const Vec3f& dir, const Vec3f& gravity) {
    std::vector<Vec4f> rest;
    for (int i = 0; i < n; ++i) {
      const Vec3f p = dir * static_cast<float>(length * i / (n - 1));
      rest.emplace_back(p.x(), p.y(), p.z(), i < 2 ? 0.0f : 1.0f);
    }
    std::vector<kernels::Mat3f> frame(n);
    std::vector<float> theta0(n), phi0(n), len(n), stiffness(n);
    const float inv_length = kernels::forest_setup(rest, kernels::ForestAxes::ParentX, static_cast<float>(k), 0.0f, 2,
                                                   frame, theta0, phi0, len, stiffness);
    return kernels::forest_rest_inertia_scale(rest, len, stiffness, inv_length, gravity, margin);
  };
  const int m = n - 2;
  const double lambda = 4.0 * k * std::pow(std::sin(M_PI / (2.0 * (2 * m + 1))), 2);
  const double expected = margin * (g / length) / lambda;
  const Vec3f down(0.0f, -static_cast<float>(g), 0.0f);
  EXPECT_NEAR(scale(Vec3f::UnitY(), down), expected, 1e-4 * expected);
  EXPECT_GT(expected, 10.0) << "a 30-segment 8 cm strand at the default k must need it";
  EXPECT_EQ(scale(-Vec3f::UnitY(), down), 1.0f);
  EXPECT_EQ(scale(Vec3f::UnitX(), down), 1.0f);
  EXPECT_EQ(scale(Vec3f::UnitY(), Vec3f::Zero()), 1.0f);
}

// With J = m L ℓ gravity's pull on an upright segment does not fall with the segment
// count while the joints' slowest mode does: the rest state of 8 cm, 32-vertex strands
// standing on the crown grows under the probe's kick when every strand keeps J
// (rest_hold 0), and is stable with J raised where it topples (the default).
TEST(HalenForest, RestHoldKeepsUprightStrandsStanding) {
  const Scenario sc = upright_scenario(32, 0.08);
  ThreadPool pool(2);
  const ModelInfo* info = find_model("halen_forest");
  auto probe = [&](double hold) {
    const verdict::Probe p = perturbation_probe(*info, sc, resolve_params(*info, sc, {{"halen_forest", "rest_hold", hold}}), pool);
    RecordProperty("rate_rest_hold" + std::to_string(int(hold)), std::to_string(p.rate));
    EXPECT_TRUE(p.run);
    return p;
  };
  EXPECT_TRUE(probe(0).grows);
  EXPECT_FALSE(probe(1).grows);
}

// A strand of many segments keeps swinging after the head stops unless something damps
// its slowest mode: Eq. 4.2.2's joint damping v reaches it as v (π / 2n)² (0.3/s at 32
// vertices), and a toppled upright strand circles, pumped by any torque that is not the
// gradient of an energy. With drag, the damped penalty and gravity compensation as a force,
// the upright groom of RestHoldKeepsUprightStrandsStanding at 64 vertices comes to rest
// after `nod` (the settle check's energy falls), and faster with the drag than without.
TEST(HalenForest, FineUprightStrandsSettleAfterTheHeadStops) {
  Scenario sc = upright_scenario(64, 0.08);
  const Scenario nod = builtin("nod", 1);
  sc.head = nod.head;
  sc.frames = nod.frames;
  sc.settle_from = nod.settle_from;
  auto settle = [&](double drag) {
    const auto runs = test::run(sc, {"halen_forest"}, {{"halen_forest", "drag", drag}});
    const RunRecord& r = test::find(runs, "halen_forest");
    RecordProperty("settle_rate_drag" + std::to_string(int(drag)), std::to_string(r.verdict.settle.rate));
    EXPECT_FALSE(r.failure);
    return r;
  };
  const RunRecord with_drag = settle(2.0), without = settle(0.0);
  EXPECT_EQ(with_drag.verdict.status, verdict::Status::ok) << with_drag.verdict.reason;
  EXPECT_TRUE(with_drag.verdict.settle.decays);
  EXPECT_LT(with_drag.verdict.settle.rate, without.verdict.settle.rate);
}

// The perturbation probe (harness/probe.h) of the cascade on the `idle` groom with
// `vertices` per strand (every 40th strand).
verdict::Probe cascade_probe(int vertices, const std::vector<ParamOverride>& ov) {
  Scenario sc = builtin("idle", 1);
  sc.groom = idle_groom(vertices, 40);
  ThreadPool pool(2);
  const ModelInfo* info = find_model("halen_cascade");
  return perturbation_probe(*info, sc, resolve_params(*info, sc, ov), pool);
}

// §5.9: "instability problems occurring in the cascading coordinate systems model are
// mostly caused by high stiffness in the springs connecting the downward reference
// nodes ... With longer strands ... this causes a struggle between the upward and
// downward reference nodes. A solution ... is to reduce the stiffness of the downward
// reference nodes to a fraction". That is the thesis's reference nodes, fixed during the
// step (reactions 0), with k = 6000 s^-2 at every node whatever their count (the thesis
// scales nothing with it). With the groom's root edge pinned, a 4-node strand has two free
// nodes and no downward spring, and the probe's kick dies away; from 5 nodes on it grows
// whatever the downward fraction (0, 1/4 and 1 all grow, at 5.5-6.9/s), so the thesis's
// cure does not cure it here (docs/limitations.md, "The cascade"). As the halves of
// torsion springs (reactions 1, the default, with the stiffness scaled to the node count)
// the springs store and return energy but make none: no node count up to 16 or downward
// stiffness makes the kick grow (32 nodes: docs/limitations.md, "The cascade").
TEST(HalenCascade, FixedReferenceNodesAreUnstableOnLongerStrandsWhateverTheDownwardFraction) {
  const std::string m = "halen_cascade";
  auto probe = [&](int nodes, double reactions, double down) {
    std::vector<ParamOverride> ov{{m, "reactions", reactions}, {m, "down_fraction", down}, {m, "nodes", double(nodes)}};
    if (reactions == 0) ov.push_back({m, "stiffness", 6000.0 * std::pow(7.0 / (nodes - 1.0), 4.0)});
    const verdict::Probe p = cascade_probe(nodes, ov);
    RecordProperty("rate_" + std::to_string(nodes) + "_reactions" + std::to_string(int(reactions)) + "_down" +
                       std::to_string(int(100 * down)),
                   std::to_string(p.rate));
    EXPECT_TRUE(p.run);
    return p.grows;
  };
  EXPECT_FALSE(probe(4, 0, 1.0));
  for (double down : {0.0, 0.25, 1.0}) EXPECT_TRUE(probe(5, 0, down)) << down;
  EXPECT_TRUE(probe(16, 0, 0.0));
  for (int nodes : {4, 8, 16})
    for (double down : {0.25, 1.0}) EXPECT_FALSE(probe(nodes, 1, down)) << nodes << " " << down;
}

// The perturbation probe finds the cascade's rest state stable at 4, 8 and 16 nodes on
// straight, wavy and curly grooms, and the kick dies down to float rounding: the
// difference it leaves after 2 s is within 20 kicks (1e-6 L-bar each). The curly groom
// takes 40 substeps a frame at 8 nodes; with Verlet's velocity taken as the difference of
// two positions rounded at the head's scale the rounding alone kept its strands moving,
// the difference ending at 1.4e-4 L-bar, not decaying; in step form
// (kernels/common/strand_kernels.h) it ends near 1e-6 L-bar.
TEST(HalenCascade, ProbeFindsTheRestStateStable) {
  for (const std::string style : {"straight", "wavy", "curly"})
    for (int nodes : {4, 8, 16}) {
      Scenario sc = builtin("idle", 1);
      GroomSpec spec;
      spec.style = style;
      sc.groom = every_nth_strand(generate_groom(spec, sc.head_radius, "test").groom, 40);
      ThreadPool pool(2);
      const ModelInfo* info = find_model("halen_cascade");
      const verdict::Probe p =
          perturbation_probe(*info, sc, resolve_params(*info, sc, {{"halen_cascade", "nodes", double(nodes)}}), pool);
      RecordProperty("rate_" + style + "_" + std::to_string(nodes), std::to_string(p.rate));
      RecordProperty("last_" + style + "_" + std::to_string(nodes), test::sci(p.last));
      ASSERT_TRUE(p.run);
      EXPECT_FALSE(p.grows) << style << " " << nodes;
      EXPECT_LT(p.last, 20 * ProbeSettings::kAmplitude) << style << " " << nodes;
    }
}

// §4 criterion 1 at rest: on `idle` with nothing skipped and no strand asleep, the hair
// holds its rest shape for 10 s (600 frames) at 8 and 16 nodes, within 1e-4 L-bar: the
// displaced reference nodes carry the weight (§4.3, L = mg/k).
TEST(HalenCascade, RestsForTenSecondsAtEightAndSixteenNodes) {
  for (int nodes : {8, 16}) {
    Scenario sc = builtin("idle", 1);
    sc.groom = idle_groom(16, 40);
    ThreadPool pool(2);
    RunOptions opt;
    opt.models = {"halen_cascade"};
    opt.frames = 600;
    opt.skip_inert = false;
    opt.overrides = {{"halen_cascade", "nodes", double(nodes)}};
    const RunRecord r = run_scenario(sc, opt, pool).front();
    RecordProperty("max_rest_error_" + std::to_string(nodes), std::to_string(test::max_of(r.series("rest_shape_error"))));
    EXPECT_EQ(r.verdict.status, verdict::Status::ok) << nodes << " " << r.verdict.reason;
    EXPECT_LT(test::max_of(r.series("rest_shape_error")), 1e-4) << nodes;
  }
}

// §4 criterion 1 after motion, at the defaults: on `walk`, `spin_fast` and `wind_gust`
// over straight, wavy and curly grooms (every 40th strand), the cascade's verdict is ok and
// with the head held still to 8 s the hair is back within 0.05 L-bar of its style.
TEST(HalenCascade, ReturnsToItsStyleAfterWalkSpinAndWind) {
  ThreadPool pool(2);
  for (const std::string motion : {"walk", "spin_fast", "wind_gust"})
    for (const std::string style : {"straight", "wavy", "curly"}) {
      Scenario sc = builtin(motion, 1);
      GroomSpec spec;
      spec.style = style;
      sc.groom = every_nth_strand(generate_groom(spec, sc.head_radius, "test").groom, 40);
      RunOptions opt;
      opt.models = {"halen_cascade"};
      opt.frames = 480;
      const std::vector<RunRecord> runs = run_scenario(sc, opt, pool);
      const RunRecord& r = test::find(runs, "halen_cascade");
      RecordProperty(motion + "_" + style + "_settled", std::to_string(r.series("rest_shape_error").back()));
      EXPECT_EQ(r.verdict.status, verdict::Status::ok) << motion << " " << style << ": " << r.verdict.reason;
      EXPECT_LT(r.series("rest_shape_error").back(), 0.05) << motion << " " << style;
    }
}

// One model stepped directly through a scenario; `at` sees every frame's positions and
// head pose.
void step_through(const Scenario& sc, const std::string& model, const std::vector<ParamOverride>& ov,
                  const std::function<void(int, std::span<const Vec4f>, const Affine3f&)>& at) {
  const ModelInfo* info = find_model(model);
  ThreadPool pool(2);
  auto m = make_model(*info, sc, resolve_params(*info, sc, ov), pool, "", true);
  StageTimes times;
  for (int f = 0; f < sc.frames; ++f) {
    const FrameInput in = frame_input(sc, f);
    m->step(in, times);
    at(f, m->positions(), in.head);
  }
}

// How far, along world up, the tips hang below their roots, averaged over the strands,
// in mean strand lengths.
double tip_drop(const Groom& g, std::span<const Vec4f> p, const Vec3f& up) {
  double drop = 0.0;
  for (std::size_t s = 0; s < g.strand_count(); ++s)
    drop += up.dot(p[g.strand_begin(s)].head<3>() - p[g.strand_begin(s + 1) - 1].head<3>());
  return drop / (static_cast<double>(g.strand_count()) * mean_strand_length(g));
}

// §4 ("If the hair is at rest but tilted ... it would be unnatural for it to return to a
// predefined shape") with §4.4's reference nodes displaced upward and "kept static in
// relation to the base": upright, the displacement carries the weight and gravity
// changes nothing; upside down it no longer does, and the hair falls over the scalp:
// with gravity the tips end below their roots (at rest, head turned, they are 0.84
// L-bar above them), without it the hair keeps them above.
TEST(HalenCascade, GravityBendsTheHairOnlyWhenTheHeadTilts) {
  const Vec3f up = Vec3f::UnitY();
  for (const char* name : {"idle", "tilt_upside_down"}) {
    Scenario sc = builtin(name, 8);
    std::vector<Vec4f> with, without;
    double drop_with = 0.0, drop_without = 0.0;
    step_through(sc, "halen_cascade", {}, [&](int f, std::span<const Vec4f> p, const Affine3f&) {
      if (f + 1 == sc.frames) with.assign(p.begin(), p.end()), drop_with = tip_drop(sc.groom, p, up);
    });
    sc.gravity = Vec3f::Zero();
    step_through(sc, "halen_cascade", {}, [&](int f, std::span<const Vec4f> p, const Affine3f&) {
      if (f + 1 == sc.frames) without.assign(p.begin(), p.end()), drop_without = tip_drop(sc.groom, p, up);
    });
    const double apart = metrics::deviation(with, without, mean_strand_length(sc.groom));
    RecordProperty(std::string(name) + "_gravity_vs_none", std::to_string(apart));
    RecordProperty(std::string(name) + "_tip_drop_gravity", std::to_string(drop_with));
    RecordProperty(std::string(name) + "_tip_drop_none", std::to_string(drop_without));
    if (std::string(name) == "idle") {
      EXPECT_LT(apart, 1e-4);
    } else {
      EXPECT_GT(apart, 0.3);
      EXPECT_GT(drop_with, 0.5);
      EXPECT_LT(drop_without, drop_with - 0.5);
    }
  }
}

// §4.3 fixes the strand's root node and gives node 1's upward reference node in the
// root's space; the groom's pinned root edge is that space: while the head shakes,
// vertices 0 and 1 stay rigid with the head and vertices 2, the first the springs move,
// leave their head-transformed rest positions.
TEST(HalenCascade, TheRootEdgeIsFixedAndTheNextVertexMoves) {
  Scenario sc = builtin("shake", 8);
  sc.frames = 30;
  double root = 0.0, next = 0.0;
  step_through(sc, "halen_cascade", {}, [&](int f, std::span<const Vec4f> p, const Affine3f& head) {
    if (f + 1 != sc.frames) return;
    for (std::size_t s = 0; s < sc.groom.strand_count(); ++s) {
      const std::size_t b = sc.groom.strand_begin(s);
      for (std::size_t i : {b, b + 1})
        root = std::max(root, double((p[i].head<3>() - head * sc.groom.positions[i].head<3>()).norm()));
      next += (p[b + 2].head<3>() - head * sc.groom.positions[b + 2].head<3>()).norm();
    }
  });
  next /= static_cast<double>(sc.groom.strand_count()) * mean_strand_length(sc.groom);
  RecordProperty("vertex2_mean_offset", std::to_string(next));
  EXPECT_LT(root, 1e-6);
  EXPECT_GT(next, 1e-3);
}

// `shake`: while the head shakes ±60° at 2 Hz the strands swing out but keep hanging (the
// tips stay below the roots, where a flat disc would have them level with them), and once
// it holds still they come back to their style.
TEST(HalenCascade, ShakenStrandsSwingAndComeBackToTheirStyle) {
  const Scenario sc = builtin("shake", 8);
  const Vec3f up = -sc.gravity.normalized();
  double rest_drop = 0.0, least = 1e9, last = 0.0, error = 0.0;
  step_through(sc, "halen_cascade", {}, [&](int f, std::span<const Vec4f> p, const Affine3f& head) {
    if (f == 0) {
      std::vector<Vec4f> rest = sc.groom.positions;
      for (Vec4f& v : rest) v.head<3>() = head * v.head<3>();
      rest_drop = tip_drop(sc.groom, rest, up);
    }
    const double drop = tip_drop(sc.groom, p, up);
    least = std::min(least, drop);
    if (f + 1 == sc.frames) {
      last = drop;
      std::vector<Vec4f> rest = sc.groom.positions;
      for (Vec4f& v : rest) v.head<3>() = head * v.head<3>();
      error = metrics::deviation(p, rest, mean_strand_length(sc.groom));
    }
  });
  RecordProperty("rest_tip_drop", std::to_string(rest_drop));
  RecordProperty("least_tip_drop", std::to_string(least));
  RecordProperty("final_tip_drop", std::to_string(last));
  RecordProperty("final_rest_error", std::to_string(error));
  EXPECT_LT(least, 0.9 * rest_drop);
  EXPECT_GT(least, 0.2 * rest_drop);
  EXPECT_GT(last, 0.95 * rest_drop);
  EXPECT_LT(error, 0.06);
}

// Same input -> bit-identical state, whatever the thread count.
TEST(HalenModels, DeterministicAcrossRunsAndThreads) {
  const Scenario sc = builtin("shake", 16);
  const auto a = test::run(sc, kHalen, {}, 2, 60);
  const auto b = test::run(sc, kHalen, {}, 2, 60);
  const auto c = test::run(sc, kHalen, {}, 1, 60);
  ASSERT_EQ(a.size(), kHalen.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].state_hash, b[i].state_hash) << a[i].model;
    EXPECT_EQ(a[i].state_hash, c[i].state_hash) << a[i].model;
  }
}

// Every shipped scenario runs every model without NaN or blow-up (thinned grooms, the
// first second of each).
TEST(HalenModels, StableOnEveryBuiltinScenario) {
  for (const auto& file : test::procedural_builtin_scenarios()) {
    const auto runs = test::run(builtin(file.stem().string(), 25), kHalen, {}, 2, 60);
    for (const RunRecord& r : runs)
      EXPECT_FALSE(r.failure) << file << " " << r.model << ": " << (r.failure ? r.failure->reason : "");
  }
}

// The joint rotation of both conventions points the child's z axis where forest_angles
// says, so rest shapes are rebuilt exactly from their angles.
TEST(HalenKernels, ForestAnglesRoundTrip) {
  for (int convention : {0, 1})
    for (const Vec3f& d : {Vec3f(0.3f, -0.2f, 0.9f), Vec3f(-0.5f, 0.7f, 0.1f), Vec3f(0.0f, 0.0f, 1.0f),
                           Vec3f(0.1f, 0.9f, -0.6f)}) {
      const Vec3f u = d.normalized();
      float theta = 0.0f, phi = 0.0f;
      const auto axes = static_cast<kernels::ForestAxes>(convention);
      kernels::forest_angles(axes, u, theta, phi);
      const Vec3f back = kernels::forest_joint_rotation(axes, theta, phi).col(2);
      EXPECT_LT((back - u).norm(), 1e-5f) << convention;
    }
}

// §4.3's spaces are orthonormal and follow the strand: N along each segment, with either
// way of taking B and T from the parent.
TEST(HalenKernels, TangentSpacesAreOrthonormalAlongTheStrand) {
  const Scenario sc = builtin("idle", 400);
  const auto strand = std::span(sc.groom.positions).subspan(0, sc.groom.strand_size(0));
  std::vector<kernels::Mat3f> space(strand.size());
  std::vector<int> base(strand.size());
  for (std::size_t j = 0; j < strand.size(); ++j) base[j] = static_cast<int>(j) - 1;
  const Vec3f n0 = (strand[1] - strand[0]).head<3>().normalized();
  for (auto frames : {kernels::CascadeFrames::Cross, kernels::CascadeFrames::Transport}) {
    kernels::tangent_spaces(strand, kernels::root_tangent_space(n0), frames, base, space);
    for (std::size_t i = 1; i < strand.size(); ++i) {
      EXPECT_LT((space[i].transpose() * space[i] - kernels::Mat3f::Identity()).norm(), 1e-5f) << i;
      const Vec3f n = (strand[i] - strand[i - 1]).head<3>().normalized();
      EXPECT_LT((space[i].col(1) - n).norm(), 1e-5f) << i;
    }
  }
}

// The thesis's B_j = N_j × T_{j-1} is undefined where a segment bends 90° towards T_{j-1}
// (the ponytail groom's tie bends 96°): near it, a small turn of the segment spins its
// space about N. The transported space turns about as much as the segment does.
TEST(HalenKernels, TransportedSpacesDoNotSpinNearARightAngleBend) {
  const float l = 0.02f;
  const kernels::Mat3f root = kernels::root_tangent_space(Vec3f(0.0f, -1.0f, 0.0f));
  const std::vector<int> base = {-1, 0, 1};
  auto turn = [&](kernels::CascadeFrames frames, float sideways) {
    // Segment 1 along the root's N, segment 2 bent 89.5° towards T, its end moved by
    // `sideways` along B; returns the angle B_2 turns through.
    const float a = 89.5f * static_cast<float>(M_PI) / 180.0f;
    const Vec3f p1 = l * root.col(1), p2 = p1 + l * (std::cos(a) * root.col(1) + std::sin(a) * root.col(2));
    std::vector<Vec4f> pos = {Vec4f::Zero(), Vec4f(p1.x(), p1.y(), p1.z(), 1.0f), Vec4f(p2.x(), p2.y(), p2.z(), 1.0f)};
    std::vector<kernels::Mat3f> before(3), after(3);
    kernels::tangent_spaces(pos, root, frames, base, before);
    pos[2].head<3>() += sideways * root.col(0);
    kernels::tangent_spaces(pos, root, frames, base, after);
    return std::asin(std::min(before[2].col(0).cross(after[2].col(0)).norm(), 1.0f));
  };
  const float moved = 1e-4f * l;  // the segment turns by 1e-4 rad
  const float cross = turn(kernels::CascadeFrames::Cross, moved);
  const float transport = turn(kernels::CascadeFrames::Transport, moved);
  RecordProperty("cross_turn_rad", std::to_string(cross));
  RecordProperty("transport_turn_rad", std::to_string(transport));
  EXPECT_GT(cross, 5e-3f);
  EXPECT_GT(transport, 5e-5f);
  EXPECT_LT(transport, 3e-4f);
}

// cascade_setup: the groom's pins are kept (its pinned root edge is §4.3's given space at
// the root), and node 1 has springs (an upward reference node in the root's space, a
// downward one). A rounding-sized segment takes its parent's space and joins its rigid
// segment.
TEST(HalenKernels, CascadeSetupKeepsThePinsAndJoinsRoundingSizedSegments) {
  Groom g;
  std::vector<Vec3f> pts;
  for (int i = 0; i < 6; ++i) pts.emplace_back(0.0f, -0.02f * static_cast<float>(i), 0.0f);
  pts[4] = pts[3] + Vec3f(0.0f, -2.4e-7f, 0.0f);
  g.add_strand(pts, 0);
  g.add_strand(pts, 0, 3);
  const std::size_t n = pts.size();
  std::vector<float> inv(n), ku(n), kd(n), lift(n), lever(n);
  std::vector<int> base(n);
  std::vector<kernels::Mat3f> space(n);
  std::vector<Vec3f> up(n), down(n);
  for (std::size_t s = 0; s < 2; ++s) {
    kernels::cascade_setup(std::span(g.positions).subspan(g.strand_begin(s), n), 1000.0f, 5.0f, 2, 0.25f,
                           kernels::CascadeFrames::Transport, inv, ku, kd, lift, base, lever, space, up, down);
    EXPECT_EQ(inv[0], 0.0f);
    EXPECT_EQ(inv[1], 0.0f);  // the groom's pinned root edge
    EXPECT_GT(ku[1], 0.0f);
    EXPECT_GT(kd[1], 0.0f);  // node 1 has a downward reference node in segment 3's space
  }
  EXPECT_EQ(base, (std::vector<int>{-1, 0, 1, 2, 2, 4}));
  EXPECT_NEAR(lever[4], 0.02f, 1e-6f);
  EXPECT_LT((space[4] - space[3]).norm(), 1e-6f);
}

// With reactions, each reference spring is half of a torsion spring: the accelerations
// are minus the gradient of the springs' energy Σ k/2 |P - M w - O_T|², the spaces' twist
// included, so the springs neither make nor take energy. Checked by central differences
// of the energy through the production tangent_spaces, on straight, wavy and curly rest
// strands bent and perturbed away from rest. Without the twist's part the error is of the
// forces' own size on curved strands; the thesis's fixed reference nodes are no gradient
// even on a straight one.
TEST(HalenKernels, ReferenceSpringForcesAreTheNegativeGradientOfTheirEnergy) {
  const std::size_t n = 10;
  enum class Force { Exact, NoTwist, FixedReferences };
  auto relative_error = [&](const std::vector<Vec3f>& rest_pts, Force force) {
    Groom g;
    g.add_strand(rest_pts, 0, 1);
    std::vector<float> inv(n), ku(n), kd(n), lift(n), lever(n), twist(n);
    std::vector<int> base(n);
    std::vector<kernels::Mat3f> rest_space(n), space(n);
    std::vector<Vec3f> up(n), down(n), acc(n);
    kernels::cascade_setup(g.positions, 1000.0f, 5.0f, 2, 0.25f, kernels::CascadeFrames::Transport, inv, ku, kd,
                           lift, base, lever, rest_space, up, down);
    const kernels::CascadeStrand cs{inv, ku, kd, lift, base, lever, up, down};
    // Bent and perturbed at the rest lengths (the edge corrections keep them): each
    // segment turned by a few degrees about an axis of its own, the strand re-chained.
    std::vector<Vec4f> bent = g.positions;
    for (std::size_t i = 2; i < n; ++i) {
      const float fi = static_cast<float>(i);
      const Vec3f axis = Vec3f(std::sin(1.7f * fi), std::cos(2.3f * fi), std::sin(3.1f * fi) + 0.5f).normalized();
      const Vec3f e = g.positions[i].head<3>() - g.positions[i - 1].head<3>();
      bent[i].head<3>() = bent[i - 1].head<3>() + Eigen::AngleAxisf(0.05f * fi, axis) * e;
    }
    auto energy = [&](const std::vector<Vec4f>& p) {
      kernels::tangent_spaces(p, rest_space[0], kernels::CascadeFrames::Transport, base, space);
      double e = 0.0;
      for (std::size_t i = 1; i < n; ++i) {
        e += 0.5 * ku[i] * (p[i].head<3>() - p[i - 1].head<3>() - space[i - 1] * up[i]).cast<double>().squaredNorm();
        if (i + 2 < n)
          e += 0.5 * kd[i] * (p[i].head<3>() - p[i + 2].head<3>() - space[i + 2] * down[i]).cast<double>().squaredNorm();
      }
      return e;
    };
    // At rest, under gravity, the displaced reference nodes hold every node still.
    const Vec3f gravity(0.0f, -9.81f, 0.0f);
    kernels::tangent_spaces(g.positions, rest_space[0], kernels::CascadeFrames::Transport, base, space);
    kernels::cascade_accelerations(g.positions, space, cs, true, kernels::CascadeFrames::Transport, gravity, gravity,
                                   twist, acc);
    for (std::size_t i = 1; i < n; ++i) EXPECT_LT(acc[i].norm(), 1e-4f) << "vertex " << i;
    kernels::tangent_spaces(bent, rest_space[0], kernels::CascadeFrames::Transport, base, space);
    kernels::cascade_accelerations(bent, space, cs, force != Force::FixedReferences,
                                   force == Force::Exact ? kernels::CascadeFrames::Transport
                                                         : kernels::CascadeFrames::Cross,
                                   Vec3f::Zero(), Vec3f::Zero(), twist, acc);
    double err = 0.0, size = 0.0;
    for (std::size_t i = 1; i < n; ++i)
      for (int c = 0; c < 3; ++c) {
        const float h = 1e-4f;
        std::vector<Vec4f> a = bent, b = bent;
        a[i][c] += h;
        b[i][c] -= h;
        const double grad = (energy(a) - energy(b)) / (double(a[i][c]) - double(b[i][c]));
        err += (acc[i][c] + grad) * (acc[i][c] + grad);
        size += grad * grad;
      }
    return std::sqrt(err / size);
  };
  std::vector<Vec3f> straight, wavy, curly;
  for (std::size_t i = 0; i < n; ++i) {
    const float fi = static_cast<float>(i);
    straight.emplace_back(0.0f, -0.03f * fi, 0.0f);
    wavy.emplace_back(0.01f * std::sin(1.2f * fi), -0.028f * fi, 0.0f);
    curly.emplace_back(0.02f * std::cos(1.3f * fi), -0.015f * fi, 0.02f * std::sin(1.3f * fi));
  }
  for (const auto& [name, pts] : {std::pair{"straight", straight}, {"wavy", wavy}, {"curly", curly}}) {
    SCOPED_TRACE(name);
    const double exact = relative_error(pts, Force::Exact);
    const double no_twist = relative_error(pts, Force::NoTwist), fixed = relative_error(pts, Force::FixedReferences);
    RecordProperty(std::string(name) + "_relative_error", std::to_string(exact));
    RecordProperty(std::string(name) + "_relative_error_without_twist", std::to_string(no_twist));
    EXPECT_LT(exact, 1e-3);
    EXPECT_GT(fixed, 0.3);
    if (std::string(name) != "straight") {
      EXPECT_GT(no_twist, 0.02);
    }
  }
}

// ---- simulated nodes (§5.5, kernels/halen2007/nodes.h) --------------------------------

// The 32-vertex TressFX mohawk (every 40th strand) and the procedural curly groom at 32
// vertices: curls finer than 8 nodes.
std::vector<std::pair<std::string, Groom>> fine_grooms() {
  const Scenario mohawk = load_scenario(find_scenario("tressfx_mohawk"));
  GroomSpec curly;
  curly.style = "curly";
  curly.vertices_per_strand = 32;
  const Scenario idle = builtin("idle", 1);
  return {{"mohawk", every_nth_strand(mohawk.groom, 40)},
          {"curly", every_nth_strand(generate_groom(curly, idle.head_radius, "test").groom, 40)}};
}

// Nodes lie on the rest polyline: the first, the last and every pinned vertex are nodes,
// the others spaced equally in arc length between them (on straight strands, equal
// chords); the requested count on every strand.
TEST(HalenNodes, NodesSitOnAnchorsAndSpaceTheRestEqually) {
  const Groom g = upright_scenario(16, 0.25).groom;
  const kernels::NodeLayout layout = kernels::layout_nodes(g, 8, false);
  ASSERT_EQ(layout.nodes.strand_count(), g.strand_count());
  for (std::size_t s = 0; s < g.strand_count(); ++s) {
    ASSERT_EQ(layout.nodes.strand_size(s), 8u);
    const Vec4f* d = g.positions.data() + g.strand_begin(s);
    const Vec4f* n = layout.nodes.positions.data() + layout.nodes.strand_begin(s);
    EXPECT_EQ(n[0], d[0]);
    EXPECT_EQ(n[7], d[15]);
    EXPECT_EQ(n[1], d[1]) << "a pinned vertex is a node";
    std::vector<float> seg;
    for (int j = 2; j < 8; ++j) seg.push_back((n[j] - n[j - 1]).head<3>().norm());
    for (float l : seg) EXPECT_NEAR(l, seg.front(), 1e-5f * seg.front()) << "strand " << s;
  }
}

// §6.3's static strands: with tied_static a strand pinned at both ends with free vertices
// between is held static, every node pinned and every drawn vertex rigid with the head or
// on a pinned node; a strand the groom pins whole is not counted, and a free one is laid
// out as usual. Without tied_static the tied strand's tip is an anchor between free nodes.
TEST(HalenNodes, StrandsTiedAtBothEndsAreHeldStaticWhenAsked) {
  Groom g = upright_scenario(16, 0.25).groom;
  g = select_strands(g, std::vector<std::uint32_t>{0, 1, 2});
  g.positions[g.strand_begin(1) + 15].w() = 0.0f;  // tied at the tip
  for (std::uint32_t i = g.strand_begin(2); i < g.strand_begin(3); ++i) g.positions[i].w() = 0.0f;  // rigid
  const kernels::NodeLayout held = kernels::layout_nodes(g, 8, true);
  EXPECT_EQ(held.static_strands, 1u);
  for (std::uint32_t i = held.nodes.strand_begin(1); i < held.nodes.strand_begin(2); ++i)
    EXPECT_EQ(held.nodes.positions[i].w(), 0.0f);
  for (std::uint32_t i = g.strand_begin(1); i < g.strand_begin(2); ++i)
    EXPECT_NE(held.span[i].kind, kernels::NodeSpan::Kind::Segment) << i;
  EXPECT_NE(held.nodes.positions[held.nodes.strand_begin(0) + 4].w(), 0.0f);
  const kernels::NodeLayout tied = kernels::layout_nodes(g, 8, false);
  EXPECT_EQ(tied.static_strands, 0u);
  EXPECT_NE(tied.nodes.positions[tied.nodes.strand_begin(1) + 4].w(), 0.0f);
  EXPECT_EQ(tied.nodes.positions[tied.nodes.strand_begin(2) - 1], g.positions[g.strand_begin(2) - 1]);
}

// A drawn vertex keeps its rest offset in its segment's frame: with the nodes at rest under
// any rigid head pose, the drawn groom is the rest groom under that pose (within float
// rounding), curls finer than the nodes included; a pinned vertex is head · rest, bit for
// bit.
TEST(HalenNodes, TheDrawnGroomAtRestIsTheRestGroomUnderTheHead) {
  Affine3f head = Affine3f::Identity();
  head.translate(Vec3f(0.3f, -0.1f, 0.2f));
  head.rotate(Eigen::AngleAxisf(1.1f, Vec3f(0.3f, 1.0f, -0.5f).normalized()));
  for (const auto& [name, g] : fine_grooms())
    for (int count : {4, 8, 16, 32}) {
      const kernels::NodeLayout layout = kernels::layout_nodes(g, count);
      std::vector<Vec4f> nodes = layout.nodes.positions, drawn(g.vertex_count());
      for (Vec4f& v : nodes) v.head<3>() = head * v.head<3>();
      std::vector<Quatf> frame(nodes.size());
      double worst = 0.0;
      for (std::size_t s = 0; s < g.strand_count(); ++s) {
        const std::size_t nb = layout.nodes.strand_begin(s), nn = layout.nodes.strand_size(s);
        const std::size_t db = g.strand_begin(s), dn = g.strand_size(s);
        kernels::draw_from_nodes(std::span(nodes).subspan(nb, nn), std::span(layout.nodes.positions).subspan(nb, nn),
                                 std::span(layout.span).subspan(db, dn), std::span(g.positions).subspan(db, dn), head,
                                 std::span(frame).subspan(nb, nn), std::span(drawn).subspan(db, dn));
        for (std::size_t i = db; i < db + dn; ++i) {
          const Vec3f want = head * g.positions[i].head<3>();
          worst = std::max(worst, double((drawn[i].head<3>() - want).norm()));
          if (g.positions[i].w() == 0.0f) {
            EXPECT_EQ(drawn[i].head<3>(), want);
          }
        }
      }
      RecordProperty(name + "_" + std::to_string(count) + "_worst_m", std::to_string(worst));
      EXPECT_LT(worst, 2e-6 * mean_strand_length(g)) << name << " at " << count << " nodes";
    }
}

// The models start from the rest groom: every Halén model, reset at every node count, draws
// the rest groom, and after one frame with the head still the drawn groom has moved only
// as much as the nodes have (no jump from the drawing).
TEST(HalenNodes, EveryModelStartsFromTheRestGroom) {
  ThreadPool pool(2);
  Scenario sc = builtin("idle", 1);
  for (const auto& [name, g] : fine_grooms()) {
    sc.groom = g;
    for (const std::string model : {"halen_spring", "halen_cascade", "halen_forest"})
      for (int count : {4, 8, 16}) {
        const ModelInfo* info = find_model(model);
        auto m = make_model(*info, sc, resolve_params(*info, sc, {{model, "nodes", double(count)}}), pool, "", true);
        double worst = 0.0;
        for (std::size_t i = 0; i < g.vertex_count(); ++i)
          worst = std::max(worst, double((m->positions()[i] - g.positions[i]).head<3>().norm()));
        EXPECT_LT(worst, 2e-6 * mean_strand_length(g)) << name << " " << model << " " << count;
      }
  }
}

// A model never simulates a strand at more nodes than the groom's strands have vertices
// (nodes_for_groom): TressFX TestHair1's strands have 4, and at the default 8 nodes the
// spring model laid 6 nodes on its 2 free edges, whose 1.2 cm segments an upright strand
// left stretched by 79% in the first frame (`stretched`).
TEST(HalenNodes, NodesNeverOutnumberTheGroomsVertices) {
  ThreadPool pool(2);
  // Every 37th guide (guide 8103 among them), simulated as the groom (follow hairs do not
  // change what is tested).
  Scenario sc = load_scenario(find_scenario("tressfx_testhair1"));
  if (sc.follow) {
    sc.groom = sc.guides;
    sc.follow.reset();
  }
  sc.groom = every_nth_strand(sc.groom, 37);
  const Groom& g = sc.groom;
  std::size_t most = 0;
  for (std::size_t s = 0; s < g.strand_count(); ++s) most = std::max<std::size_t>(most, g.strand_size(s));
  ASSERT_EQ(most, 4u);
  for (const std::string model : {"halen_spring", "halen_cascade", "halen_forest"}) {
    const ModelInfo* info = find_model(model);
    const ParamSet p = resolve_params(*info, sc, {});
    ASSERT_EQ(p.get_int("nodes"), 8);
    auto m = make_model(*info, sc, p, pool, "", true);
    ASSERT_NE(m->simulated_groom(), nullptr);
    for (std::size_t s = 0; s < m->simulated_groom()->strand_count(); ++s)
      ASSERT_EQ(m->simulated_groom()->strand_size(s), 4u) << model << " strand " << s;
    EXPECT_NE(info->step_bound(g, p, sc.gravity).why.find("(at 4 nodes)"), std::string::npos) << model;
    RunOptions opt;
    opt.models = {model};
    const RunRecord r = run_scenario(sc, opt, pool).front();
    EXPECT_EQ(r.verdict.stretch.frames_above, 0) << model << ": " << r.verdict.reason;
    EXPECT_EQ(verdict::status_name(r.verdict.status), "ok") << model << ": " << r.verdict.reason;
    EXPECT_EQ(r.params["nodes"], 4.0) << model << ": the report shows the count the model ran at";
  }
}

// §5.9: k_L = k / (L c)^a, k at the root, decreasing faster for larger a.
TEST(HalenKernels, StiffnessFalloff) {
  EXPECT_FLOAT_EQ(kernels::falloff_stiffness(100.0f, 0.0f, 10.0f, 2), 100.0f);
  EXPECT_FLOAT_EQ(kernels::falloff_stiffness(100.0f, 0.2f, 10.0f, 1), 50.0f);
  EXPECT_FLOAT_EQ(kernels::falloff_stiffness(100.0f, 0.2f, 10.0f, 2), 25.0f);
  EXPECT_FLOAT_EQ(kernels::falloff_stiffness(100.0f, 0.2f, 10.0f, 3), 12.5f);
}

// cascade_rest_stiffness keeps its last answers: a kept one is the one the measurement
// gives. The same inputs again give the same bits; the stiffness doubled doubles the
// springs' modes (the Jacobian is linear in it); a vertex of each strand moved by a
// millimetre, or a falloff changed, is a new measurement, and the first inputs after them
// still give the first answer.
TEST(HalenCascade, RestStiffnessKeptAnswersAreMeasurements) {
  const ModelInfo* info = find_model("halen_cascade");
  ASSERT_NE(info, nullptr);
  Scenario sc = builtin("idle", 1);
  sc.groom = idle_groom(8, 50);
  const ParamSet p = resolve_params(*info, sc, {});
  const ParamSet stiff = resolve_params(*info, sc, {{"halen_cascade", "stiffness", 2.0 * p.get("stiffness", 0)}});
  const ParamSet falloff =
      resolve_params(*info, sc, {{"halen_cascade", "falloff_scale", 0.5 * p.get("falloff_scale", 0)}});
  const double first = halen::cascade_rest_stiffness(sc.groom, p);
  ASSERT_GT(first, 0.0);
  EXPECT_EQ(halen::cascade_rest_stiffness(sc.groom, p), first);
  EXPECT_NEAR(halen::cascade_rest_stiffness(sc.groom, stiff), 2.0 * first, 1e-3 * first);
  EXPECT_NE(halen::cascade_rest_stiffness(sc.groom, falloff), first);
  Groom moved = sc.groom;
  for (std::size_t k = 0; k < moved.strand_count(); ++k) moved.positions[moved.strand_begin(k) + 4].x() += 1e-3f;
  EXPECT_NE(halen::cascade_rest_stiffness(moved, p), first);
  EXPECT_EQ(halen::cascade_rest_stiffness(sc.groom, p), first);
}

}  // namespace
}  // namespace hairbench
