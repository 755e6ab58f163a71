// Properties Halén & Wester 2007 claim for (or that define) the spring (§4.4), cascading
// spaces (§4.3) and interactive forest (§4.2, §5.9) models.
#include "test_support.h"

#include "kernels/cpu/halen_kernels.h"
#include "models/registry.h"
#include "reports/metrics.h"
#include "scenarios/groom_gen.h"

#include <gtest/gtest.h>

#include <cmath>
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

// §4 criterion 1, "the ability to return to a predefined position at rest": after the
// head stops, each model comes back to the head-transformed rest shape. Bounds, in L-bar:
// spring 1e-3 and forest 2e-2 are settled states (about ten times what each shows, to
// leave room for compiler differences). Known difference: the cascade returns slowly,
// 0.57 L-bar just after the turn and still 0.22 four seconds later, because each upward
// reference extrapolates the segment above it (a disturbance is handed down the strand
// with a gain of up to 3 per node) and its downward springs pull against that; it must
// have come at least halfway back and below 0.3.
TEST(HalenModels, ReturnToRestShapeAfterHeadStops) {
  const auto runs = test::run(turn_and_hold(16), kHalen);
  const std::map<std::string, double> bound = {{"halen_spring", 1e-3}, {"halen_forest", 2e-2}, {"halen_cascade", 0.3}};
  for (const RunRecord& r : runs) {
    ASSERT_FALSE(r.failure) << r.model;
    const double peak = test::max_of(r.rest_shape_error);
    RecordProperty(r.model + "_peak", std::to_string(peak));
    RecordProperty(r.model + "_final", std::to_string(r.rest_shape_error.back()));
    EXPECT_GT(peak, 0.05) << r.model << ": the turn should disturb the hair";
    EXPECT_LT(r.rest_shape_error.back(), bound.at(r.model)) << r.model;
    EXPECT_LT(r.rest_shape_error.back(), 0.5 * peak) << r.model;
  }
}

// §4 criterion 2, fixed length. The forest rebuilds positions from angles (§4.2: "the
// length of every segment is always kept constant"): exact to float rounding. The
// position models correct lengths with Eq. 4.2 and stay within 1% RMS on `shake`.
TEST(HalenModels, SegmentLengthsOnShake) {
  const auto runs = test::run(builtin("shake", 8), kHalen);
  for (const RunRecord& r : runs) {
    ASSERT_FALSE(r.failure) << r.model;
    if (r.model == "halen_forest")
      EXPECT_LT(test::max_of(r.length_max), 1e-5) << r.model;
    else
      EXPECT_LT(test::rms_of(r.length_rms), 0.01) << r.model;
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
  const double hang_weak = w.rest_shape_error.back(), hang_stiff = s.rest_shape_error.back();
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
  return test::max_of(r.rest_shape_error);
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

// Kinetic energy per vertex, (1/2)|v|² averaged over vertices and over the frames with
// t >= from, of one model stepped directly through a scenario.
double oscillation_energy(const Scenario& sc, const std::string& model, double down_fraction, double from) {
  const ModelInfo* info = find_model(model);
  ThreadPool pool(2);
  // The instability grows from rounding noise at rest, which sleeping strands (below
  // 0.1 mm/s) would freeze: this measures the model's own dynamics.
  ModelContext ctx{&pool};
  ctx.skip_inert = false;
  auto m = info->make(ctx);
  m->reset(sc.groom, resolve_params(*info, sc, {{model, "down_fraction", down_fraction}}));
  std::vector<Vec4f> last(m->positions().begin(), m->positions().end());
  StageTimes times;
  double energy = 0.0;
  int count = 0;
  for (int f = 0; f < sc.frames; ++f) {
    FrameInput in;
    in.frame = f;
    in.dt = sc.dt;
    in.t = (f + 1) * sc.dt;
    in.head_prev = sc.head.at(f * sc.dt);
    in.head = sc.head.at(in.t);
    in.gravity = sc.gravity;
    in.wind = sc.wind.at(in.t);
    in.colliders = sc.colliders;
    m->step(in, times);
    const auto p = m->positions();
    if (in.t >= from) {
      double sum = 0.0;
      for (std::size_t i = 0; i < p.size(); ++i) sum += 0.5 * ((p[i] - last[i]).head<3>() / sc.dt).squaredNorm();
      energy += sum / static_cast<double>(p.size());
      ++count;
    }
    std::copy(p.begin(), p.end(), last.begin());
  }
  return energy / count;
}

// §5.9: "instability problems occurring in the cascading coordinate systems model are
// mostly caused by high stiffness in the springs connecting the downward reference
// nodes ... With longer strands ... this causes a struggle between the upward and
// downward reference nodes. A solution ... is to reduce the stiffness of the downward
// reference nodes to a fraction". Long (40 cm) strands under gravity, head still: with
// equal up/down stiffness the rest pose is unstable and rounding alone sets the hair
// moving; with downward springs at a quarter it stays nearly still.
// Known difference: the energy left after the head stops moving (2 s of `nod`, then 1 s
// still) does not show it: equal stiffness leaves 0.013 m²/s² per vertex, a quarter
// 0.022. More springs make the strand stiffer, which damps the swing after a motion
// faster than the struggle excites it on that time scale.
TEST(HalenCascade, EqualDownwardStiffnessIsUnstableAtRest) {
  Scenario sc = builtin("idle", 16);
  GroomSpec spec;
  spec.strands = 125;
  spec.length = 0.4;
  sc.groom = generate_groom(spec, sc.head_radius, "test").groom;
  sc.frames = 180;
  const double equal = oscillation_energy(sc, "halen_cascade", 1.0, 1.0);
  const double quarter = oscillation_energy(sc, "halen_cascade", 0.25, 1.0);
  RecordProperty("energy_equal", std::to_string(equal));
  RecordProperty("energy_quarter", std::to_string(quarter));
  EXPECT_GT(equal, 10.0 * quarter) << "equal " << equal << " quarter " << quarter;
  EXPECT_GT(equal, 1e-4) << "equal " << equal << " quarter " << quarter;
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

// §4.3's spaces are orthonormal and follow the strand: N along each segment.
TEST(HalenKernels, TangentSpacesAreOrthonormalAlongTheStrand) {
  const Scenario sc = builtin("idle", 400);
  const auto strand = std::span(sc.groom.positions).subspan(0, sc.groom.strand_size(0));
  std::vector<kernels::Mat3f> space(strand.size());
  const Vec3f n0 = (strand[1] - strand[0]).head<3>().normalized();
  kernels::tangent_spaces(strand, kernels::root_tangent_space(n0), space);
  for (std::size_t i = 1; i < strand.size(); ++i) {
    EXPECT_LT((space[i].transpose() * space[i] - kernels::Mat3f::Identity()).norm(), 1e-5f) << i;
    const Vec3f n = (strand[i] - strand[i - 1]).head<3>().normalized();
    EXPECT_LT((space[i].col(1) - n).norm(), 1e-5f) << i;
  }
}

// §5.9: k_L = k / (L c)^a, k at the root, decreasing faster for larger a.
TEST(HalenKernels, StiffnessFalloff) {
  EXPECT_FLOAT_EQ(kernels::falloff_stiffness(100.0f, 0.0f, 10.0f, 2), 100.0f);
  EXPECT_FLOAT_EQ(kernels::falloff_stiffness(100.0f, 0.2f, 10.0f, 1), 50.0f);
  EXPECT_FLOAT_EQ(kernels::falloff_stiffness(100.0f, 0.2f, 10.0f, 2), 25.0f);
  EXPECT_FLOAT_EQ(kernels::falloff_stiffness(100.0f, 0.2f, 10.0f, 3), 12.5f);
}

}  // namespace
}  // namespace hairbench
