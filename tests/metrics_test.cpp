// The metric definitions of DESIGN.md and the properties each must have.
#include "core/parallel.h"
#include "models/registry.h"
#include "reports/metrics.h"
#include "reports/report.h"

#include <gtest/gtest.h>

#include <cmath>
#include <tuple>

namespace hairbench {
namespace {

// Strand s of n vertices: a gently bent strand in the xy plane, a quarter circle arc of
// radius 0.2, moved along x and z by s.
std::vector<Vec3f> bent_strand(int s, int n) {
  std::vector<Vec3f> pts;
  for (int i = 0; i < n; ++i) {
    const float a = 0.5f * float(M_PI) * float(i) / float(n - 1);
    pts.emplace_back(0.2f * std::sin(a) + 0.05f * float(s), 0.2f * std::cos(a), 0.01f * float(s));
  }
  return pts;
}

Groom bent_groom(int strands = 3, int n = 12) {
  Groom g;
  for (int s = 0; s < strands; ++s) g.add_strand(bent_strand(s, n), 0);
  return g;
}

std::vector<Vec4f> transformed(const std::vector<Vec4f>& p, const Affine3f& t) {
  std::vector<Vec4f> out = p;
  for (Vec4f& v : out) v.head<3>() = t * Vec3f(v.head<3>());
  return out;
}

TEST(Jaggedness, ZeroOnRestShape) {
  const Groom g = bent_groom();
  const metrics::RestInfo rest(g);
  EXPECT_EQ(metrics::jaggedness(rest, g.positions), 0.0);
}

// 30 strands of interleaved sizes, as in a ragged groom: 12 of 12 vertices, 9 of 13, 6 of
// 5 and 3 of 3 (303 vertices: not a whole number of vector lanes).
Groom ragged_groom() {
  Groom g;
  for (int s = 0; s < 30; ++s) g.add_strand(bent_strand(s, s % 10 == 9 ? 3 : s % 5 == 1 ? 5 : s % 2 == 0 ? 12 : 13), 0);
  return g;
}

// The groom's positions bent out of their planes, unevenly.
std::vector<Vec4f> perturbed(const Groom& g) {
  std::vector<Vec4f> p = g.positions;
  for (std::size_t k = 0; k < p.size(); ++k) {
    p[k].x() += 0.0013f * static_cast<float>((k * 3) % 7);
    p[k].y() += 0.0021f * static_cast<float>((k * 7) % 5);
    p[k].z() += 0.0017f * static_cast<float>((k * 5) % 11);
  }
  return p;
}

Eigen::Vector3d xyz(const Vec4f& v) { return v.head<3>().cast<double>(); }

// Strands of one size go through the lane code eight at a time, the rest one at a time:
// the groom value is the serial sum of strand_jaggedness_raw, bit for bit.
TEST(Jaggedness, LanesGiveTheSerialBits) {
  const Groom g = ragged_groom();
  const metrics::RestInfo rest(g);
  EXPECT_EQ(rest.jagged_grouped.size(), 16u);  // 8 of the 12-vertex strands, 8 of the 13
  EXPECT_EQ(rest.jagged_alone.size(), 14u);
  const std::vector<Vec4f> p = perturbed(g);
  double serial = 0.0;
  for (std::size_t s = 0; s < g.strand_count(); ++s)
    serial += metrics::strand_jaggedness_raw(std::span<const Vec4f>(p).subspan(g.strand_begin(s), g.strand_size(s))) -
              rest.rest_jaggedness[s];
  serial /= static_cast<double>(g.strand_count());
  EXPECT_GT(serial, 0.0);
  EXPECT_EQ(metrics::jaggedness(rest, p), serial);
}

// The other metrics run as vector loops over the whole groom; each gives the bits of its
// definition computed vertex by vertex and strand by strand, with Eigen, in order.
TEST(Metrics, VectorLoopsGiveTheSerialBits) {
  const Groom g = ragged_groom();
  const metrics::RestInfo rest(g);
  const std::vector<Vec4f> p = perturbed(g);
  double sum = 0.0, max = 0.0;
  std::size_t edges = 0;
  for (std::size_t s = 0; s < g.strand_count(); ++s)
    for (std::size_t i = g.strand_begin(s) + 1; i < g.strand_begin(s) + g.strand_size(s); ++i) {
      const double e = std::abs((xyz(p[i]) - xyz(p[i - 1])).norm() - rest.rest_length[i]) / rest.rest_length[i];
      sum += e * e;
      max = std::max(max, e);
      ++edges;
    }
  const metrics::LengthError le = metrics::length_error(rest, p);
  EXPECT_GT(max, 0.0);
  EXPECT_EQ(le.max, max);
  EXPECT_EQ(le.rms, std::sqrt(sum / static_cast<double>(edges)));

  // rest_shape_error: a sum over 303 vertices rounds away most one-ulp differences in its
  // terms, so it is checked on many head poses and on a two-vertex strand as well.
  const Groom pair = bent_groom(1, 2);
  const metrics::RestInfo pair_rest(pair);
  for (int k = 0; k < 400; ++k) {
    const float a = 0.37f * static_cast<float>(k);
    const Affine3f head = Eigen::Translation3f(0.01f * std::sin(a), -0.02f, 0.03f * std::cos(3.0f * a)) *
                          Eigen::AngleAxisf(a, Vec3f(std::sin(2.0f * a), 1.0f, -0.2f).normalized());
    for (const auto& [groom, info, q] :
         {std::tuple{&g, &rest, p}, std::tuple{&pair, &pair_rest, perturbed(pair)}}) {
      double sum2 = 0.0;
      for (std::size_t i = 0; i < q.size(); ++i)
        sum2 += (xyz(q[i]) - (head * Vec3f(groom->positions[i].head<3>())).cast<double>()).squaredNorm();
      ASSERT_EQ(metrics::rest_shape_error(*info, q, head),
                std::sqrt(sum2 / static_cast<double>(q.size())) / info->mean_strand_length)
          << "head pose " << k;
    }
  }

  // Five spheres (four share a pass, then one): the last reaches deepest into the hair.
  const std::vector<Vec4f> spheres = {Vec4f(0.1f, 0.1f, 0.1f, 0.05f), Vec4f(0.5f, 0.2f, 0.1f, 0.03f),
                                      Vec4f(5.0f, 0.0f, 0.0f, 0.1f), Vec4f(0.3f, 0.14f, 0.2f, 0.08f),
                                      Vec4f(0.8f, 0.1f, 0.16f, 0.15f)};
  double deepest = 0.0;
  for (const Vec4f& c : spheres)
    for (const Vec4f& v : p) deepest = std::max(deepest, double(c.w()) - (xyz(v) - xyz(c)).norm());
  EXPECT_GT(deepest, 0.0);
  EXPECT_EQ(metrics::penetration(p, spheres), deepest);
}

TEST(Jaggedness, UnchangedByRigidMotion) {
  const Groom g = bent_groom();
  const metrics::RestInfo rest(g);
  // Deform, then move the deformed groom rigidly: the metric must not change.
  std::vector<Vec4f> p = g.positions;
  p[5].x() += 0.01f;
  p[17].z() -= 0.007f;
  Affine3f t = Affine3f::Identity();
  t.rotate(Eigen::AngleAxisf(1.1f, Vec3f(0.3f, 1.0f, -0.2f).normalized()));
  t.pretranslate(Vec3f(0.4f, -1.0f, 2.0f));
  const double before = metrics::jaggedness(rest, p);
  const double after = metrics::jaggedness(rest, transformed(p, t));
  EXPECT_GT(before, 0.0);
  EXPECT_NEAR(before, after, 1e-4 * before);
}

// A one-vertex zig-zag is jaggier than a smooth bend with the same largest
// displacement: the metric reads changes of curvature, not curvature.
TEST(Jaggedness, ZigZagBeatsSmoothBend) {
  const int n = 16;
  Groom g;
  std::vector<Vec3f> straight;
  for (int i = 0; i < n; ++i) straight.emplace_back(0.0f, -0.02f * float(i), 0.0f);
  g.add_strand(straight, 0);
  const metrics::RestInfo rest(g);
  const float amp = 0.01f;
  std::vector<Vec4f> zig = g.positions, smooth = g.positions;
  zig[8].x() += amp;
  for (int i = 2; i < n; ++i) smooth[i].x() += amp * std::sin(float(M_PI) * float(i - 2) / float(2 * (n - 3))) ;
  // Same maximum displacement for both shapes.
  float smooth_max = 0.0f;
  for (int i = 0; i < n; ++i) smooth_max = std::max(smooth_max, smooth[i].x());
  for (int i = 0; i < n; ++i) smooth[i].x() *= amp / smooth_max;
  EXPECT_GT(metrics::jaggedness(rest, zig), 3.0 * metrics::jaggedness(rest, smooth));
}

// The same model stepped twice from the same input is the same: deviation exactly 0.
TEST(Deviation, MethodOneAgainstItselfIsExactlyZero) {
  const Groom g = bent_groom(20, 16);
  ThreadPool pool(2);
  const ModelInfo* m1 = find_model("han_m1");
  ASSERT_NE(m1, nullptr);
  auto a = m1->make({&pool});
  auto b = m1->make({&pool});
  ParamSet params(m1->params, g.region_names.size());
  a->reset(g, params);
  b->reset(g, params);
  StageTimes times;
  for (int f = 0; f < 30; ++f) {
    FrameInput in;
    in.dt = 1.0 / 60.0;
    in.t = (f + 1) * in.dt;
    in.gravity = Vec3f(0.0f, -9.81f, 0.0f);
    in.head.rotate(Eigen::AngleAxisf(0.3f * std::sin(float(in.t) * 6.0f), Vec3f::UnitY()));
    a->step(in, times);
    b->step(in, times);
  }
  const metrics::RestInfo rest(g);
  EXPECT_EQ(metrics::deviation(a->positions(), b->positions(), rest.mean_strand_length), 0.0);
  EXPECT_GT(metrics::rest_shape_error(rest, a->positions(), Affine3f::Identity()), 0.0);
}

TEST(LengthError, MeasuresRelativeStretch) {
  const Groom g = bent_groom(1, 4);
  const metrics::RestInfo rest(g);
  std::vector<Vec4f> p = g.positions;
  // Stretch the last edge by 10% along itself.
  const Vec4f e = p[3] - p[2];
  p[3] = p[2] + 1.1f * e;
  const auto le = metrics::length_error(rest, p);
  EXPECT_NEAR(le.max, 0.1, 1e-5);
  EXPECT_NEAR(le.rms, 0.1 / std::sqrt(3.0), 1e-5);
}

TEST(Stability, DetectsNanStretchAndEscape) {
  const Groom g = bent_groom(2, 6);
  const metrics::RestInfo rest(g);
  EXPECT_EQ(metrics::blowup_reason(rest, g.positions, Vec3f::Zero()), "");
  std::vector<Vec4f> nan = g.positions;
  nan[7].y() = std::nanf("");
  EXPECT_NE(metrics::blowup_reason(rest, nan, Vec3f::Zero()).find("non-finite"), std::string::npos);
  std::vector<Vec4f> far = g.positions;
  for (Vec4f& v : far) v.x() += 100.0f;
  EXPECT_NE(metrics::blowup_reason(rest, far, Vec3f::Zero()).find("farther"), std::string::npos);
  std::vector<Vec4f> stretched = g.positions;
  stretched[5].head<3>() += 2.0f * (stretched[5] - stretched[4]).head<3>();
  EXPECT_NE(metrics::blowup_reason(rest, stretched, Vec3f::Zero()).find("edge length"), std::string::npos);
}

// The edge test's bound is 50% of the rest length either way, just inside and outside
// it (blowup_reason screens squared lengths before taking the exact test).
TEST(Stability, EdgeBoundIsFiftyPercentEitherWay) {
  const Groom g = bent_groom(1, 4);
  const metrics::RestInfo rest(g);
  for (const float scale : {0.48f, 0.52f, 1.48f, 1.52f}) {
    std::vector<Vec4f> p = g.positions;
    p[3] = p[2] + scale * (p[3] - p[2]);
    const bool flagged = metrics::blowup_reason(rest, p, Vec3f::Zero()).find("edge length") != std::string::npos;
    EXPECT_EQ(flagged, scale < 0.5f || scale > 1.5f) << scale;
  }
}

// "Farther than 10 L-bar from the head" is measured from the head body, which holds the
// roots: a groom whose roots span many strand lengths (TestHair1: 11 cm strands up to
// 1.06 m from its centre) is sane at rest, and a vertex is caught once it is 10 L-bar
// beyond the farthest root's distance from the head centre.
TEST(Stability, DistanceIsFromTheHeadNotItsCentre) {
  Groom g;
  const std::vector<Vec3f> near{{0.1f, 0, 0}, {0.2f, 0, 0}, {0.3f, 0, 0}};
  const std::vector<Vec3f> far{{5.0f, 0, 0}, {5.0f, 0.1f, 0}, {5.0f, 0.2f, 0}};
  g.add_strand(near, 0);
  g.add_strand(far, 0);
  const metrics::RestInfo rest(g);
  ASSERT_NEAR(rest.mean_strand_length, 0.2, 1e-6);
  ASSERT_NEAR(rest.head_extent, 5.0, 1e-6);
  EXPECT_EQ(metrics::blowup_reason(rest, g.positions, Vec3f::Zero()), "");
  // The head centre moved 1 m: everything moved with it, still sane.
  std::vector<Vec4f> moved = g.positions;
  for (Vec4f& v : moved) v.z() += 1.0f;
  EXPECT_EQ(metrics::blowup_reason(rest, moved, Vec3f(0, 0, 1)), "");
  // A strand pulled along, edges intact, 10 L-bar + 5 m out: escaped.
  std::vector<Vec4f> escaped = g.positions;
  for (std::size_t i = 3; i < 6; ++i) escaped[i].x() += 2.01f;
  EXPECT_NE(metrics::blowup_reason(rest, escaped, Vec3f::Zero()).find("farther"), std::string::npos);
  for (std::size_t i = 3; i < 6; ++i) escaped[i].x() -= 0.02f;
  EXPECT_EQ(metrics::blowup_reason(rest, escaped, Vec3f::Zero()), "");
}

// Follow strands rebuilt from guides (those after simulated_strands) are not held to the
// edge bound, which is the simulation's; NaN and escape still count everywhere.
TEST(Stability, EdgeBoundCoversSimulatedStrandsOnly) {
  const Groom g = bent_groom(3, 6);
  const metrics::RestInfo rest(g, 2);
  std::vector<Vec4f> stretched = g.positions;
  stretched[17].head<3>() += 2.0f * (stretched[17] - stretched[16]).head<3>();
  EXPECT_EQ(metrics::blowup_reason(rest, stretched, Vec3f::Zero()), "");
  EXPECT_NE(metrics::blowup_reason(metrics::RestInfo(g), stretched, Vec3f::Zero()).find("edge length"),
            std::string::npos);
  stretched[5].head<3>() += 2.0f * (stretched[5] - stretched[4]).head<3>();
  EXPECT_NE(metrics::blowup_reason(rest, stretched, Vec3f::Zero()).find("strand 0"), std::string::npos);
  std::vector<Vec4f> nan = g.positions;
  nan[15].x() = std::nanf("");
  EXPECT_NE(metrics::blowup_reason(rest, nan, Vec3f::Zero()).find("non-finite"), std::string::npos);
}

TEST(StateHash, ChangesWithOneBit) {
  const Groom g = bent_groom();
  std::vector<Vec4f> p = g.positions;
  const auto h = metrics::state_hash(p);
  p[10].x() = std::nextafter(p[10].x(), 1.0f);
  EXPECT_NE(h, metrics::state_hash(p));
  EXPECT_EQ(metrics::hash_hex(0x0123456789abcdefull), "0123456789abcdef");
}

TEST(Penetration, DeepestVertexInsideAnySphere) {
  std::vector<Vec4f> p = {Vec4f(0.0f, 0.05f, 0.0f, 1.0f), Vec4f(0.0f, 0.3f, 0.0f, 1.0f)};
  const std::vector<Vec4f> spheres = {Vec4f(0.0f, 0.0f, 0.0f, 0.1f)};
  EXPECT_NEAR(metrics::penetration(p, spheres), 0.05, 1e-7);
  p[0].y() = 0.2f;
  EXPECT_EQ(metrics::penetration(p, spheres), 0.0);
}

TEST(ReportStats, MedianAndPercentile) {
  EXPECT_DOUBLE_EQ(median({3.0, 1.0, 2.0}), 2.0);
  EXPECT_DOUBLE_EQ(median({4.0, 1.0, 2.0, 3.0}), 2.5);
  EXPECT_DOUBLE_EQ(percentile({0.0, 10.0}, 0.95), 9.5);
}

// NaN must never reach the JSON as a bare token.
TEST(Report, NonFiniteValuesBecomeNull) {
  RunRecord r;
  r.model = "han_m1";
  r.vertices = 10;
  r.step_ms = {1.0};
  r.t = {0.1};
  r.deviation = {std::nan("")};
  r.jaggedness = {INFINITY};
  r.length_rms = r.length_max = r.rest_shape_error = r.penetration = {0.0};
  const std::string text = run_json(r).dump();
  EXPECT_EQ(text.find("NaN"), std::string::npos);
  EXPECT_EQ(text.find("nan"), std::string::npos);
  EXPECT_EQ(text.find("inf"), std::string::npos);
  EXPECT_TRUE(run_json(r)["metrics"]["jaggedness"]["max"].is_null());
}

}  // namespace
}  // namespace hairbench
