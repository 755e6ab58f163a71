// Properties of Müller, Kim & Chentanez 2012's Dynamic Follow-The-Leader kernels
// (kernels/muller2012/ftl_kernels.h): §3's one-pass inextensibility, §4's velocity
// correction (Algorithm 1), pins, our collision scheme, determinism.
#include "kernels/muller2012/ftl_kernels.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <vector>

namespace hairbench {
namespace {

namespace muller = kernels::muller;

constexpr float kDt = 1.0f / 60.0f;
const Vec3f kGravity(0.0f, -9.81f, 0.0f);

// One strand and its scratch, stepped with the kernels.
struct Strand {
  std::vector<Vec4f> rest, x, v, p, d;
  std::vector<float> rest_length;

  explicit Strand(std::vector<Vec4f> r) : rest(std::move(r)), x(rest), v(rest.size(), Vec4f::Zero()),
                                          p(rest.size()), d(rest.size()), rest_length(rest.size()) {
    muller::rest_lengths(rest, rest_length);
  }
  void step(const muller::StepInput& in) { muller::dftl_step(x, v, p, d, rest, rest_length, in); }
  float edge(std::size_t i) const { return (x[i].head<3>() - x[i - 1].head<3>()).norm(); }
};

// `n` vertices from `root` along `dir`, `length` long in all, the first `pinned` pinned.
std::vector<Vec4f> line(int n, const Vec3f& root, const Vec3f& dir, float length, int pinned) {
  std::vector<Vec4f> out;
  for (int i = 0; i < n; ++i) {
    const Vec3f p = root + dir.normalized() * (length * static_cast<float>(i) / static_cast<float>(n - 1));
    out.emplace_back(p.x(), p.y(), p.z(), i < pinned ? 0.0f : 1.0f);
  }
  return out;
}

// A curled rest strand: a helix leaving the scalp at (0, 0.1, 0), root pinned.
std::vector<Vec4f> curl(int n) {
  std::vector<Vec4f> out;
  for (int i = 0; i < n; ++i) {
    const float t = static_cast<float>(i) * 0.4f;
    out.emplace_back(0.02f * std::sin(t), 0.1f + 0.015f * static_cast<float>(i), 0.02f * (1.0f - std::cos(t)),
                     i == 0 ? 0.0f : 1.0f);
  }
  return out;
}

Affine3f pose(float angle, const Vec3f& axis, const Vec3f& translation) {
  Affine3f h = Affine3f::Identity();
  h.linear() = Eigen::AngleAxisf(angle, axis.normalized()).toRotationMatrix();
  h.translation() = translation;
  return h;
}

muller::StepInput input(float s_damping) {
  muller::StepInput in;
  in.gravity = kGravity;
  in.dt = kDt;
  in.s_damping = s_damping;
  return in;
}

// Largest |edge - rest| / rest over the edges into free vertices.
float worst_edge_error(const Strand& s) {
  float worst = 0.0f;
  for (std::size_t i = 1; i < s.x.size(); ++i)
    if (s.x[i].w() != 0.0f && s.rest_length[i] > 0.0f)
      worst = std::max(worst, std::abs(s.edge(i) - s.rest_length[i]) / s.rest_length[i]);
  return worst;
}

// §3: one pass leaves every edge at its rest length, however far the prediction was
// thrown: the head jumps 0.5 m and turns 120° in one step, the strand moving fast.
TEST(MullerFtl, OneStepKeepsEveryEdgeAtRestLengthUnderAViolentHeadJump) {
  Strand s(curl(16));
  for (Vec4f& v : s.v) v.head<3>() = Vec3f(3.0f, -2.0f, 5.0f);
  muller::StepInput in = input(0.9f);
  in.head = pose(2.1f, Vec3f(1.0f, 1.0f, 0.3f), Vec3f(0.5f, -0.2f, 0.3f));
  s.step(in);
  EXPECT_LT(worst_edge_error(s), 1e-5f);
  in.head = pose(-0.4f, Vec3f(0.0f, 0.0f, 1.0f), Vec3f(-0.3f, 0.0f, 0.0f));
  s.step(in);
  EXPECT_LT(worst_edge_error(s), 1e-5f);
}

// Pinned vertices anywhere (root, middle, tip) are exactly head · rest, and the FTL pass
// goes on from a pinned middle vertex: the edge out of it holds its length.
TEST(MullerFtl, PinnedVerticesAreExactlyHeadTimesRest) {
  std::vector<Vec4f> rest = line(16, Vec3f(0.0f, 0.1f, 0.0f), Vec3f(1.0f, 0.3f, 0.0f), 0.25f, 2);
  rest[7].w() = 0.0f;
  rest[15].w() = 0.0f;
  Strand s(rest);
  muller::StepInput in = input(0.9f);
  for (int k = 1; k <= 20; ++k) {
    in.head = pose(0.1f * static_cast<float>(k), Vec3f(0.2f, 1.0f, 0.1f), Vec3f(0.01f * static_cast<float>(k), 0, 0));
    s.step(in);
    for (std::size_t i : {0u, 1u, 7u, 15u}) {
      const Vec3f expected = in.head * rest[i].head<3>();
      EXPECT_EQ(s.x[i].x(), expected.x());
      EXPECT_EQ(s.x[i].y(), expected.y());
      EXPECT_EQ(s.x[i].z(), expected.z());
      EXPECT_EQ(s.x[i].w(), 0.0f);
    }
    EXPECT_NEAR(s.edge(8), s.rest_length[8], 1e-5f * s.rest_length[8]);
  }
}

// Algorithm 1 with s_damping = 0 is plain FTL: the velocity is the position change over
// the step, exactly.
TEST(MullerFtl, WithoutTheCorrectionVelocityIsPositionChangeOverDt) {
  Strand s(curl(12));
  muller::StepInput in = input(0.0f);
  for (int k = 1; k <= 30; ++k) {
    in.head = pose(0.05f * static_cast<float>(k), Vec3f::UnitY(), Vec3f::Zero());
    const std::vector<Vec4f> before = s.x;
    s.step(in);
    for (std::size_t i = 0; i < s.x.size(); ++i) {
      const Vec3f expected = (s.x[i].head<3>() - before[i].head<3>()) / kDt;
      EXPECT_EQ(s.v[i].head<3>(), expected) << "vertex " << i << " step " << k;
    }
  }
}

// §4: v_i = (p_i - x_i)/Δt - s_damping d_{i+1}/Δt. The tip has no child, and a free
// vertex before a pinned one has a child FTL never moved: neither gets a correction term.
TEST(MullerFtl, VelocityCorrectionTakesTheChildsMoveAndSkipsTheTip) {
  std::vector<Vec4f> rest = line(10, Vec3f(0.0f, 0.1f, 0.0f), Vec3f::UnitX(), 0.2f, 1);
  rest[6].w() = 0.0f;
  Strand s(rest);
  for (Vec4f& v : s.v) v.head<3>() = Vec3f(0.0f, -2.0f, 0.0f);  // a fall FTL must hold back
  muller::StepInput in = input(0.9f);
  muller::predict(s.x, s.v, s.rest, in, s.p);
  muller::follow_the_leader(s.p, s.d, s.rest, s.rest_length, in);
  const std::vector<Vec4f> x0 = s.x;
  muller::update_velocity(s.x, s.v, s.p, s.d, in);
  const auto plain = [&](std::size_t i) { return Vec3f((s.p[i].head<3>() - x0[i].head<3>()) / kDt); };
  EXPECT_EQ(s.v[9].head<3>(), plain(9));  // the tip
  EXPECT_EQ(s.v[5].head<3>(), plain(5));  // before the pinned vertex 6
  const Vec3f corrected = ((s.p[3].head<3>() - x0[3].head<3>()) - 0.9f * s.d[4].head<3>()) / kDt;
  EXPECT_EQ(s.v[3].head<3>(), corrected);
  EXPECT_GT((s.v[3].head<3>() - plain(3)).norm(), 0.1f * plain(3).norm());
}

// A strand hanging straight down is FTL's fixed point under gravity: it stays put.
TEST(MullerFtl, StrandHangingStraightDownStaysStill) {
  Strand s(line(16, Vec3f(0.03f, 0.0f, 0.02f), -Vec3f::UnitY(), 0.25f, 2));
  muller::StepInput in = input(0.9f);
  for (int k = 0; k < 600; ++k) s.step(in);
  for (std::size_t i = 0; i < s.x.size(); ++i) EXPECT_LT((s.x[i] - s.rest[i]).norm(), 1e-6f) << "vertex " << i;
}

// Only the part of the wind normal to an edge acts (ours, as every hairbench model): wind
// along a straight strand, without gravity, moves nothing.
TEST(MullerFtl, WindAlongTheStrandDoesNotMoveIt) {
  Strand s(line(8, Vec3f::Zero(), Vec3f::UnitX(), 0.2f, 2));
  muller::StepInput in = input(0.9f);
  in.gravity = Vec3f::Zero();
  in.wind = Vec3f(4.0f, 0.0f, 0.0f);
  for (int k = 0; k < 100; ++k) s.step(in);
  for (std::size_t i = 0; i < s.x.size(); ++i) EXPECT_EQ(s.x[i], s.rest[i]) << "vertex " << i;
  in.wind = Vec3f(0.0f, 0.0f, 4.0f);
  s.step(in);
  EXPECT_GT(s.x[7].z(), 0.0f);
}

// Mechanical energy per unit mass of the free vertices: ½|Δx/Δt|² - g · x.
float energy(const std::vector<Vec4f>& x, const std::vector<Vec4f>& before) {
  float e = 0.0f;
  for (std::size_t i = 0; i < x.size(); ++i) {
    if (x[i].w() == 0.0f) continue;
    const Vec3f vel = (x[i].head<3>() - before[i].head<3>()) / kDt;
    e += 0.5f * vel.squaredNorm() - kGravity.dot(x[i].head<3>());
  }
  return e;
}

// The energy a strand released horizontally keeps after `steps` steps, above its lowest
// (hanging) state.
float energy_left(float s_damping, int steps) {
  Strand s(line(16, Vec3f::Zero(), Vec3f::UnitX(), 0.25f, 1));
  const muller::StepInput in = input(s_damping);
  std::vector<Vec4f> before = s.x;
  for (int k = 0; k < steps; ++k) {
    before = s.x;
    s.step(in);
  }
  const Strand hanging(line(16, Vec3f::Zero(), -Vec3f::UnitY(), 0.25f, 1));
  return energy(s.x, before) - energy(hanging.x, hanging.x);
}

// §4: the velocity correction damps (the paper's s_damping = 0.9 loses energy faster than
// plain FTL's velocities).
TEST(MullerFtl, TheCorrectionDampsASwingingStrand) {
  const float initial = energy_left(0.0f, 0);
  const float plain = energy_left(0.0f, 120);
  const float corrected = energy_left(0.9f, 120);
  EXPECT_GT(initial, 0.0f);
  EXPECT_LT(plain, initial);
  EXPECT_LT(corrected, 0.5f * plain);
}

// Our collision scheme: a strand falls onto a sphere that shakes and turns under it. No
// free vertex ends inside the sphere by more than rounding, and every edge keeps its length.
TEST(MullerFtl, CollisionsKeepVerticesOutsideAndEdgesExact) {
  Strand s(line(16, Vec3f(0.0f, 0.1f, 0.0f), Vec3f(1.0f, 0.05f, 0.3f), 0.25f, 2));
  muller::StepInput in = input(0.9f);
  for (int k = 1; k <= 300; ++k) {
    const float t = static_cast<float>(k) * kDt;
    in.head = pose(0.5f * std::sin(8.0f * t), Vec3f::UnitZ(), Vec3f(0.05f * std::sin(12.0f * t), 0.0f, 0.0f));
    const std::vector<Vec4f> spheres = {Vec4f(in.head.translation().x(), 0.0f, 0.0f, 0.1f)};
    in.spheres = spheres;
    s.step(in);
    for (std::size_t i = 0; i < s.x.size(); ++i)
      if (s.x[i].w() != 0.0f) {
        EXPECT_GT((s.x[i].head<3>() - spheres[0].head<3>()).norm(), 0.1f - 1e-6f);
      }
    ASSERT_LT(worst_edge_error(s), 1e-5f) << "step " << k;
  }
}

// The same inputs give the same bits.
TEST(MullerFtl, Deterministic) {
  const auto run = [] {
    Strand s(curl(16));
    muller::StepInput in = input(0.9f);
    in.wind = Vec3f(2.0f, 0.0f, 1.0f);
    in.damping = 0.01f;
    const std::vector<Vec4f> spheres = {Vec4f(0.0f, 0.0f, 0.0f, 0.1f), Vec4f(0.05f, 0.2f, 0.0f, 0.04f)};
    in.spheres = spheres;
    for (int k = 1; k <= 200; ++k) {
      in.head = pose(0.01f * static_cast<float>(k), Vec3f(0.3f, 1.0f, 0.0f), Vec3f::Zero());
      s.step(in);
    }
    return s;
  };
  const Strand a = run();
  const Strand b = run();
  EXPECT_EQ(std::memcmp(a.x.data(), b.x.data(), a.x.size() * sizeof(Vec4f)), 0);
  EXPECT_EQ(std::memcmp(a.v.data(), b.v.data(), a.v.size() * sizeof(Vec4f)), 0);
}

// follow_the_leader over strands side by side gives each strand the bits of its pass
// alone: strands of different lengths (one longer than the rest, so the others stop
// early), a pin mid-strand, a free root, two inputs (regions) and spheres the strands
// fall through, over steps of a moving head.
TEST(MullerFtl, StrandsSideBySideGiveTheBitsOfEachAlone) {
  std::vector<Strand> alone, together;
  for (int k = 0; k < 5; ++k) {
    std::vector<Vec4f> rest = k == 3 ? curl(23) : line(6 + 3 * k, Vec3f(0.01f * k, 0.1f, 0.0f),
                                                       Vec3f(1.0f, 0.2f * k, 0.3f), 0.25f, k == 4 ? 0 : 1);
    if (k == 2) rest[5].w() = 0.0f;
    alone.emplace_back(rest);
    together.emplace_back(rest);
  }
  muller::StepInput in[2] = {input(0.9f), input(0.5f)};
  const std::vector<Vec4f> spheres = {Vec4f(0.05f, 0.02f, 0.0f, 0.08f), Vec4f(0.15f, 0.05f, 0.05f, 0.05f)};
  for (muller::StepInput& i : in) i.spheres = spheres;
  int collided = 0;
  for (int step = 1; step <= 60; ++step) {
    for (muller::StepInput& i : in) i.head = pose(0.02f * static_cast<float>(step), Vec3f::UnitZ(), Vec3f::Zero());
    std::vector<muller::FtlStrand> group;
    for (std::size_t k = 0; k < alone.size(); ++k) {
      const muller::StepInput& ik = in[k % 2];
      for (Strand* s : {&alone[k], &together[k]}) muller::predict(s->x, s->v, s->rest, ik, s->p);
      muller::follow_the_leader(alone[k].p, alone[k].d, alone[k].rest, alone[k].rest_length, ik);
      Strand& t = together[k];
      group.push_back({t.p, t.d, t.rest, t.rest_length, &ik});
    }
    muller::follow_the_leader(group);
    for (std::size_t k = 0; k < alone.size(); ++k) {
      const muller::StepInput& ik = in[k % 2];
      ASSERT_EQ(std::memcmp(alone[k].p.data(), together[k].p.data(), alone[k].p.size() * sizeof(Vec4f)), 0)
          << "strand " << k << " step " << step;
      ASSERT_EQ(std::memcmp(alone[k].d.data(), together[k].d.data(), alone[k].d.size() * sizeof(Vec4f)), 0)
          << "strand " << k << " step " << step;
      for (const Vec4f& p : alone[k].p)
        collided += (p.head<3>() - spheres[0].head<3>()).norm() < spheres[0].w() + 1e-4f;
      for (Strand* s : {&alone[k], &together[k]}) muller::update_velocity(s->x, s->v, s->p, s->d, ik);
    }
  }
  EXPECT_GT(collided, 0) << "no vertex met a sphere: the test would not reach the collisions";
}

// The plugin ABI's head is 4x4 column-major (translation in elements 12-14).
TEST(MullerFtl, HeadTransformReadsTheAbisColumnMajorMatrix) {
  const Affine3f a = pose(0.3f, Vec3f::UnitY(), Vec3f(1.0f, 2.0f, 3.0f));
  const Affine3f read = muller::head_transform(a.matrix().data());
  EXPECT_EQ(read.matrix(), a.matrix());
  EXPECT_EQ(a.matrix().data()[12], 1.0f);
}

}  // namespace
}  // namespace hairbench
