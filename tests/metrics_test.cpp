// The metric definitions of docs/metrics.md and the properties each must have.
#include "core/parallel.h"
#include "harness/runner.h"
#include "models/registry.h"
#include "reports/material.h"
#include "reports/metrics.h"
#include "reports/verdict.h"
#include "reports/report.h"
#include "scenarios/groom_gen.h"
#include "scenarios/tfx/tfx.h"

#include <gtest/gtest.h>

#include <cfloat>
#include <cmath>
#include <filesystem>
#include <set>
#include <stdexcept>
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
// the groom value is the serial mean of strand_jaggedness, bit for bit.
TEST(Jaggedness, LanesGiveTheSerialBits) {
  const Groom g = ragged_groom();
  const metrics::RestInfo rest(g);
  EXPECT_EQ(rest.jagged_grouped.size(), 16u);  // 8 of the 12-vertex strands, 8 of the 13
  EXPECT_EQ(rest.jagged_alone.size(), 14u);
  const std::vector<Vec4f> p = perturbed(g);
  double serial = 0.0;
  for (std::size_t s = 0; s < g.strand_count(); ++s) serial += metrics::strand_jaggedness(rest, p, s);
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
  std::size_t edges = 0, worst_strand = 0, worst_edge = 0;
  for (std::size_t s = 0; s < g.strand_count(); ++s)
    for (std::size_t i = g.strand_begin(s) + 1; i < g.strand_begin(s) + g.strand_size(s); ++i) {
      const double e = std::abs((xyz(p[i]) - xyz(p[i - 1])).norm() - double(rest.rest_length[i])) / rest.edge_scale[s];
      sum += e * e;
      if (e > max) {
        max = e;
        worst_strand = s;
        worst_edge = i - g.strand_begin(s);
      }
      ++edges;
    }
  const metrics::LengthError le = metrics::length_error(rest, p);
  EXPECT_GT(max, 0.0);
  EXPECT_EQ(le.max, max);
  EXPECT_EQ(le.rms, std::sqrt(sum / static_cast<double>(edges)));
  EXPECT_EQ(le.worst_strand, worst_strand);
  EXPECT_EQ(le.worst_edge, worst_edge);

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

  // The divergence check's mechanical energy and the settle check's kinetic energy
  // relative to the head, on the same poses and the two-vertex strand, with the previous
  // frame's positions moved by a few millimetres in every direction and the head moving
  // from one pose to the next.
  for (int k = 0; k < 400; ++k) {
    auto pose = [](float a) -> Affine3f {
      return Eigen::Translation3f(0.01f * std::sin(a), -0.02f, 0.03f * std::cos(3.0f * a)) *
             Eigen::AngleAxisf(a, Vec3f(std::sin(2.0f * a), 1.0f, -0.2f).normalized());
    };
    const float a = 0.37f * static_cast<float>(k);
    const Affine3f head = pose(a), head_prev = pose(a - 0.05f);
    const double dt = 1.0 / (60.0 * (1 + k % 3));
    const Vec3f gravity(0.01f * static_cast<float>(k % 5), -9.81f, 0.3f);
    const Eigen::Vector3d g = gravity.cast<double>();
    for (const std::vector<Vec4f>& q : {p, perturbed(pair)}) {
      std::vector<Vec4f> before = q;
      for (std::size_t i = 0; i < q.size(); ++i) {
        const float u = static_cast<float>(i);
        before[i].head<3>() += 0.003f * Vec3f(std::sin(0.7f * a + u), std::cos(1.3f * a + 2.0f * u), std::sin(2.1f * a - u));
      }
      double energy = 0.0, kinetic = 0.0;
      const Affine3f carry = head * head_prev.inverse();
      for (std::size_t i = 0; i < q.size(); ++i) {
        const Eigen::Vector3d v = (xyz(q[i]) - xyz(before[i])) / dt;
        energy += 0.5 * v.squaredNorm() - g.dot(xyz(q[i]));
        const Vec3f d = q[i].head<3>() - carry * Vec3f(before[i].head<3>());
        kinetic += static_cast<double>(d.squaredNorm());
      }
      ASSERT_EQ(metrics::mechanical_energy(q, before, dt, gravity), energy / static_cast<double>(q.size()))
          << "pose " << k << ", " << q.size() << " vertices";
      ASSERT_EQ(verdict::relative_kinetic_energy(q, before, head, head_prev, dt),
                kinetic / (2.0 * dt * dt * static_cast<double>(q.size())))
          << "pose " << k << ", " << q.size() << " vertices";
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

// A rigid motion moves float positions, which are rounded again: each coordinate by up to
// half an ulp of the largest coordinate X, after the float rotation's own few roundings.
// An edge of length l then turns by up to about c FLT_EPSILON X / l, and kb and d with it:
// a rigidly moved strand scores up to kRigid FLT_EPSILON X / l_min (l_min its shortest
// edge of nonzero length; a zero-length edge stays exactly 0, its kb 0), not 0, and the
// groom up to the mean of that over its strands. kRigid holds with room to spare on every
// shape below; a real deformation scores orders of magnitude above it.
constexpr double kRigid = 16.0;
double rigid_bound(std::span<const Vec4f> moved, const metrics::RestInfo& rest) {
  double extent = 0.0;
  for (const Vec4f& v : moved) extent = std::max(extent, double(v.head<3>().cwiseAbs().maxCoeff()));
  const Groom& g = *rest.groom;
  double sum = 0.0;
  for (std::size_t s = 0; s < g.strand_count(); ++s) {
    double shortest = INFINITY;
    for (std::size_t i = g.strand_begin(s) + 1; i < g.strand_begin(s) + g.strand_size(s); ++i)
      if (rest.rest_length[i] > 0.0f) shortest = std::min(shortest, double(rest.rest_length[i]));
    if (g.strand_size(s) >= 4) sum += kRigid * FLT_EPSILON * extent / shortest;
  }
  return sum / static_cast<double>(g.strand_count());
}

Affine3f some_rigid_motion() {
  Affine3f t = Affine3f::Identity();
  t.rotate(Eigen::AngleAxisf(1.1f, Vec3f(0.3f, 1.0f, -0.2f).normalized()));
  t.pretranslate(Vec3f(0.4f, -1.0f, 2.0f));
  return t;
}

TEST(Jaggedness, RigidMotionScoresZeroWithinFloatRounding) {
  const Groom g = ragged_groom();
  const metrics::RestInfo rest(g);
  const std::vector<Vec4f> moved = transformed(g.positions, some_rigid_motion());
  const double bound = rigid_bound(moved, rest);
  EXPECT_LT(bound, 1e-3);
  EXPECT_LE(metrics::jaggedness(rest, moved), bound);
  // A deformed shape moved rigidly keeps its value, within the same bound.
  const std::vector<Vec4f> p = perturbed(g);
  const double before = metrics::jaggedness(rest, p);
  EXPECT_GT(before, 1e3 * bound);
  EXPECT_NEAR(metrics::jaggedness(rest, transformed(p, some_rigid_motion())), before, bound);
}

// Exporters write rest edges of 2.4e-7 m: a rigid motion turns such an edge by order 1
// radian (its ends round by about 1e-7 m), so the pairs that read it are weighted out
// (RestInfo::kb_weight) and the groom still scores about 0; a kink elsewhere on the same
// strand still counts.
TEST(Jaggedness, RoundingSizedRestEdgesCarryNoKink) {
  Groom g;
  std::vector<Vec3f> pts;
  for (int i = 0; i < 16; ++i) pts.emplace_back(0.01f * std::sin(0.7f * i), -0.02f * float(i), 0.0f);
  pts[8] = pts[7] + 2.4e-7f * (pts[9] - pts[7]).normalized();
  g.add_strand(pts, 0);
  const metrics::RestInfo rest(g);
  EXPECT_EQ(rest.kb_weight[7] + rest.kb_weight[8] + rest.kb_weight[9], 0.0);
  EXPECT_EQ(rest.kb_weight[4], 1.0);
  const std::vector<Vec4f> moved = transformed(g.positions, some_rigid_motion());
  EXPECT_LT(metrics::jaggedness(rest, moved), 1e-4);
  std::vector<Vec4f> kinked = moved;
  kinked[3].x() += 0.005f;
  EXPECT_GT(metrics::jaggedness(rest, kinked), 0.05);
}

// A straight strand of 16 vertices along -y, 2 cm edges.
Groom straight_strand(int n = 16) {
  Groom g;
  std::vector<Vec3f> straight;
  for (int i = 0; i < n; ++i) straight.emplace_back(0.0f, -0.02f * float(i), 0.0f);
  g.add_strand(straight, 0);
  return g;
}

// Bent into a circular arc of the same edge lengths, kb is the same at every vertex: d
// stays 0 up to the rounding of the float positions (as for a rigid motion), however
// strong the bend.
TEST(Jaggedness, UniformBendScoresAboutZero) {
  const Groom g = straight_strand();
  const metrics::RestInfo rest(g);
  const double radius = 0.1, turn = 0.02 / radius;  // each edge turns by 0.2 rad: |kb| = 2 tan 0.1
  std::vector<Vec4f> arc = g.positions;
  for (std::size_t i = 0; i < arc.size(); ++i) {
    const double a = turn * double(i);
    arc[i].x() = float(radius * (1.0 - std::cos(a)));
    arc[i].y() = float(-radius * std::sin(a));
  }
  EXPECT_LE(metrics::jaggedness(rest, arc), rigid_bound(arc, rest));
  EXPECT_LT(rigid_bound(arc, rest), 1e-4 * 2.0 * std::tan(0.1));
}

// Changes of curvature, not curvature: a smooth bend of amplitude A (half a sine wave over
// the strand) scores far below a zig-zag of the same amplitude, alone or added to it.
TEST(Jaggedness, ZigZagFarAboveSmoothBend) {
  const Groom g = straight_strand();
  const int n = 16;
  const metrics::RestInfo rest(g);
  const float amp = 0.01f;
  std::vector<Vec4f> smooth = g.positions, zig = g.positions;
  for (int i = 0; i < n; ++i) {
    smooth[i].x() += amp * std::sin(float(M_PI) * float(i) / float(n - 1));
    zig[i].x() += i % 2 ? amp : -amp;
  }
  std::vector<Vec4f> both = smooth;
  for (int i = 0; i < n; ++i) both[i].x() += zig[i].x();
  const double bend = metrics::jaggedness(rest, smooth);
  EXPECT_GT(bend, 0.0);
  EXPECT_LT(bend, 0.1 * metrics::jaggedness(rest, zig));
  EXPECT_LT(bend, 0.1 * metrics::jaggedness(rest, both));
}

// The styled grooms: a wave or curl flattened out, a smooth bend and noise all score above
// 0 (the flattened ones are where a rest-subtracted roughness went negative), and the rest
// shape exactly 0.
TEST(Jaggedness, PositiveOnEveryDeformationOfTheStyles) {
  for (const char* style : {"straight", "wavy", "curly"}) {
    GroomSpec spec;
    spec.style = style;
    spec.strands = 40;
    spec.vertices_per_strand = 24;
    const Groom g = generate_groom(spec, 0.1f, "metrics_test").groom;
    const metrics::RestInfo rest(g);
    EXPECT_EQ(metrics::jaggedness(rest, g.positions), 0.0) << style;
    std::vector<Vec4f> bent = g.positions, noisy = g.positions, flat = g.positions;
    for (std::size_t s = 0; s < g.strand_count(); ++s) {
      const std::size_t b = g.strand_begin(s), n = g.strand_size(s);
      const Vec3f root = g.positions[b].head<3>(), tip = g.positions[b + n - 1].head<3>();
      for (std::size_t i = 2; i < n; ++i) {
        const float u = float(i) / float(n - 1);
        bent[b + i].z() += 0.02f * u * u;
        noisy[b + i].head<3>() += 0.002f * Vec3f(std::sin(12.9898f * float(b + i)), std::sin(78.233f * float(b + i)),
                                                std::sin(37.719f * float(b + i)));
        flat[b + i].head<3>() = root + u * (tip - root);  // the style's shape straightened
      }
    }
    for (const auto& [name, p] :
         {std::pair{"bend", &bent}, std::pair{"noise", &noisy}, std::pair{"flattened", &flat}}) {
      EXPECT_GT(metrics::jaggedness(rest, *p), 0.0) << style << " " << name;
    }
  }
}

// The shipped TressFX assets (centimetre files, read in metres; Ratboy's strands have edges
// down to 3.3e-6 m): 0 at rest, about 0 under a rigid motion (within the float bound
// above), far above it once perturbed.
TEST(Jaggedness, TressFxAssetsRigidAboutZeroPerturbedAbove) {
  const std::filesystem::path assets = HAIRBENCH_ASSET_DIR;
  for (const char* file : {"testhair1/TestHair1.tfx", "ratboy_mohawk_v4.0/Ratboy_mohawk.tfx", "ponytail/front_top.tfx",
                           "ponytail/side.tfx", "ponytail/back.tfx", "ponytail/tail.tfx"}) {
    const Groom g = tfx::load_tfx_asset(assets / file, {0.01f}).groom;
    const metrics::RestInfo rest(g);
    EXPECT_EQ(metrics::jaggedness(rest, g.positions), 0.0) << file;
    const std::vector<Vec4f> moved = transformed(g.positions, some_rigid_motion());
    const double bound = rigid_bound(moved, rest);
    EXPECT_LE(metrics::jaggedness(rest, moved), bound) << file;
    EXPECT_GT(metrics::jaggedness(rest, perturbed(g)), 100.0 * bound) << file;
  }
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
  // Stretch the last edge by 10% along itself (all edges have one length: the scale).
  const Vec4f e = p[3] - p[2];
  p[3] = p[2] + 1.1f * e;
  const auto le = metrics::length_error(rest, p);
  EXPECT_NEAR(le.max, 0.1, 1e-5);
  EXPECT_NEAR(le.rms, 0.1 / std::sqrt(3.0), 1e-5);
  EXPECT_EQ(le.worst_strand, 0u);
  EXPECT_EQ(le.worst_edge, 3u);
}

// Strands along -y with the edge lengths given (axis-aligned, so float and double edge
// lengths agree exactly), side by side along x.
Groom strands_of_edges(const std::vector<std::vector<float>>& edges) {
  Groom g;
  for (std::size_t s = 0; s < edges.size(); ++s) {
    std::vector<Vec3f> pts{Vec3f(0.01f * float(s), 0.0f, 0.0f)};
    for (const float l : edges[s]) pts.emplace_back(pts.back() - Vec3f(0.0f, l, 0.0f));
    g.add_strand(pts, 0);
  }
  return g;
}

// Exporters write rest edges of 0 m and about 1e-7 m: their errors are measured against the
// strand's median edge, so rounding-sized motion stays rounding-sized.
TEST(LengthError, DegenerateRestEdgesAreMeasuredAgainstTheStrandScale) {
  const Groom g = strands_of_edges({{0.02f, 0.02f, 0.02f, 0.02f},
                                    {0.02f, 0.0f, 0.02f, 1e-7f, 0.02f, 0.02f},
                                    {0.0f, 0.0f, 0.0f, 0.02f}});
  const metrics::RestInfo rest(g);
  EXPECT_NEAR(rest.edge_scale[0], 0.02, 1e-9);
  EXPECT_NEAR(rest.edge_scale[1], 0.02, 1e-9);  // the median of 0, 1e-7 and four 0.02
  // The third strand's median edge is 0: the scale is the mean rest edge of the groom.
  EXPECT_NEAR(rest.edge_scale[2], (9 * 0.02 + 1e-7) / 14.0, 1e-9);
  EXPECT_EQ(metrics::length_error(rest, g.positions).max, 0.0);
  EXPECT_EQ(metrics::blowup_reason(rest, g.positions, Vec3f::Zero()), "");

  // The tiny edge (strand 1, edge 4) lengthened by 1e-7 m: an error of 1e-7 / 0.02, not 100%.
  std::vector<Vec4f> p = g.positions;
  const std::size_t tip = g.strand_begin(1) + 4;
  for (std::size_t i = tip; i < g.strand_begin(1) + g.strand_size(1); ++i) p[i].y() -= 1e-7f;
  const double moved = double(p[tip - 1].y()) - double(p[tip].y()) - double(rest.rest_length[tip]);
  ASSERT_NEAR(moved, 1e-7, 1e-8);  // float rounding of the shifted positions
  const metrics::LengthError le = metrics::length_error(rest, p);
  EXPECT_NEAR(le.max, moved / 0.02, 1e-6);
  EXPECT_LT(le.max, 1e-4);
  EXPECT_EQ(le.worst_strand, 1u);
  EXPECT_EQ(le.worst_edge, 4u);
  EXPECT_EQ(metrics::blowup_reason(rest, p, Vec3f::Zero()), "");
  // The zero-length edge opened up by as much: the same.
  std::vector<Vec4f> q = g.positions;
  for (std::size_t i = g.strand_begin(1) + 2; i < g.strand_begin(1) + g.strand_size(1); ++i) q[i].y() -= 1e-7f;
  EXPECT_LT(metrics::length_error(rest, q).max, 1e-4);
  EXPECT_EQ(metrics::blowup_reason(rest, q, Vec3f::Zero()), "");

  // An ordinary edge (strand 1, edge 5) stretched by 60%: still an error of 0.6, and flagged.
  std::vector<Vec4f> r = g.positions;
  for (std::size_t i = g.strand_begin(1) + 5; i < g.strand_begin(1) + g.strand_size(1); ++i) r[i].y() -= 0.012f;
  const metrics::LengthError stretched = metrics::length_error(rest, r);
  EXPECT_NEAR(stretched.max, 0.6, 1e-5);
  EXPECT_EQ(stretched.worst_strand, 1u);
  EXPECT_EQ(stretched.worst_edge, 5u);
  EXPECT_GT(stretched.max, verdict::kStretchLimit);
  // A stretched edge is the stretched verdict's, not a blow-up: the run goes on.
  EXPECT_EQ(metrics::blowup_reason(rest, r, Vec3f::Zero()), "");
}

TEST(Stability, DetectsNanAndEscapeButNotStretch) {
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
  EXPECT_EQ(metrics::blowup_reason(rest, stretched, Vec3f::Zero()), "");
  EXPECT_GT(metrics::length_error(rest, stretched).max, verdict::kStretchLimit);
}

// The stretch limit is 50% of the strand's edge scale either way, just inside and
// outside it.
TEST(Stability, StretchLimitIsFiftyPercentEitherWay) {
  const Groom g = bent_groom(1, 4);
  const metrics::RestInfo rest(g);
  for (const float scale : {0.48f, 0.52f, 1.48f, 1.52f}) {
    std::vector<Vec4f> p = g.positions;
    p[3] = p[2] + scale * (p[3] - p[2]);
    verdict::StretchTracker tracker;
    tracker.add(0, metrics::length_error(rest, p));
    EXPECT_EQ(tracker.result().frames_above == 1, scale < 0.5f || scale > 1.5f) << scale;
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

// NaN and escape count in every strand, follow strands rebuilt from guides (those after
// simulated_strands) included.
TEST(Stability, NanCountsInFollowStrandsToo) {
  const Groom g = bent_groom(3, 6);
  const metrics::RestInfo rest(g, 2);
  std::vector<Vec4f> nan = g.positions;
  nan[15].x() = std::nanf("");
  EXPECT_NE(metrics::blowup_reason(rest, nan, Vec3f::Zero()).find("strand 2"), std::string::npos);
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
  r.series("deviation_vs_reference") = {std::nan("")};
  r.series("jaggedness") = {INFINITY};
  r.series("length_error_rms") = r.series("length_error_max") = r.series("rest_shape_error") = r.series("penetration") = {0.0};
  const std::string text = run_json(r).dump();
  EXPECT_EQ(text.find("NaN"), std::string::npos);
  EXPECT_EQ(text.find("nan"), std::string::npos);
  EXPECT_EQ(text.find("inf"), std::string::npos);
  EXPECT_TRUE(run_json(r)["metrics"]["jaggedness"]["max"].is_null());
}

// The metric table (reports/frame_metrics.h) is well formed: unique column names found
// by name, every summary on one of its metric's columns with a printf format, a headline
// summary per metric, and every gated summary a number the report writes.
TEST(MetricTable, WellFormed) {
  const auto table = metrics::frame_metrics();
  ASSERT_FALSE(table.empty());
  std::set<std::string_view> names, columns;
  std::size_t c = 0;
  for (std::size_t m = 0; m < table.size(); ++m) {
    const metrics::FrameMetric& fm = table[m];
    SCOPED_TRACE(std::string(fm.name));
    EXPECT_TRUE(names.insert(fm.name).second);
    EXPECT_TRUE(fm.host != nullptr);
    EXPECT_FALSE(fm.unit.empty());
    EXPECT_FALSE(fm.meaning.empty());
    ASSERT_FALSE(fm.columns.empty());
    ASSERT_FALSE(fm.summaries.empty());
    EXPECT_EQ(metrics::first_column(m), c);
    for (const metrics::Column& col : fm.columns) {
      EXPECT_TRUE(columns.insert(col.name).second) << col.name;
      EXPECT_EQ(metrics::column_index(col.name), c);
      EXPECT_EQ(metrics::column(c).name, col.name);
      ++c;
    }
    for (const metrics::Summary& s : fm.summaries) {
      EXPECT_LT(s.column, fm.columns.size());
      EXPECT_EQ(s.format.substr(0, 1), "%");
      EXPECT_GE(s.gate_rel, 0.0);
    }
  }
  EXPECT_EQ(metrics::column_count(), c);
  EXPECT_THROW(metrics::column_index("no_such_metric"), std::out_of_range);
  EXPECT_EQ(metrics::definitions_json().size(), table.size());
}

// The runner records, and the report writes, what the table holds: each metric under its
// name with each summary's key, each reported column as a series of a value per frame,
// and the table itself as metric_definitions.
TEST(MetricTable, TheReportWritesWhatTheTableHolds) {
  Scenario sc = load_scenario(find_scenario("shake"));
  sc.groom = every_nth_strand(sc.groom, 64);
  sc.frames = 12;
  sc.settle_from = 0.0;  // every frame is a settled one: rest_shape_error has frames to average
  ThreadPool pool(2);
  RunOptions opt;
  opt.models = {"han_m1", "han_m3"};
  opt.probe = opt.twin = opt.material_card = false;
  const std::vector<RunRecord> runs = run_scenario(sc, opt, pool);
  const nlohmann::json report = make_report(ReportContext{}, runs);
  EXPECT_EQ(report["metric_definitions"], metrics::definitions_json());
  for (const nlohmann::json& run : report["runs"]) {
    for (const metrics::FrameMetric& fm : metrics::frame_metrics()) {
      const nlohmann::json& m = run["metrics"][std::string(fm.name)];
      for (const metrics::Summary& s : fm.summaries) {
        if (fm.columns[s.column].follow_only) continue;  // no follow hairs on `shake`
        EXPECT_TRUE(s.key.empty() ? m.is_number() : m[std::string(s.key)].is_number()) << fm.name << " " << s.key;
      }
      for (const metrics::Column& col : fm.columns) {
        if (col.reported && !col.follow_only) {
          EXPECT_EQ(run["series"][std::string(col.name)].size(), 12u) << col.name;
        }
      }
    }
  }
  // The reference's deviation from itself is 0; the other's is not.
  EXPECT_EQ(report["runs"][0]["metrics"]["deviation_vs_reference"]["max"], 0.0);
  EXPECT_GT(report["runs"][1]["metrics"]["deviation_vs_reference"]["max"].get<double>(), 0.0);
}

// The card's mode fit (two-pole linear prediction) on sampled decays it must read: a slow
// damped swing under a fast one that dies out, and an overdamped pair of exponentials,
// whose slower it must give.
TEST(MaterialCard, SlowestModeRecoversTheSlowOneOfTwo) {
  constexpr double dt = 1.0 / 60.0;
  std::vector<double> swing, creep;
  for (int n = 0; n < 120; ++n) {
    const double t = n * dt;
    swing.push_back(std::exp(-2.0 * t) * std::cos(9.0 * t) + 0.5 * std::exp(-40.0 * t) * std::cos(50.0 * t));
    creep.push_back(std::exp(-1.5 * t) + std::exp(-25.0 * t));
  }
  const material::Mode m = material::slowest_mode(swing, dt, 10);
  EXPECT_NEAR(m.sigma, 2.0, 0.02);
  EXPECT_NEAR(m.omega, 9.0, 0.05);
  const material::Mode c = material::slowest_mode(creep, dt, 10);
  EXPECT_NEAR(c.sigma, 1.5, 0.02);
  EXPECT_EQ(c.omega, 0.0);
  EXPECT_TRUE(std::isnan(material::slowest_mode(std::vector<double>(50, 0.0), dt).sigma));
}

// The card reads the material: method 1 with less local shape stiffness (S_L 0.2 against 0.9) sags
// more on the hanging `ponytail`; the cascade with a quarter of its reference springs'
// stiffness responds more slowly (its hair carries its weight on the springs' offsets, so
// its sag is 0 at any stiffness and the mode is where its stiffness shows). Every run has
// a card, and its ratios are to the reference's.
TEST(MaterialCard, ASofterMaterialSagsMoreOrRespondsMoreSlowly) {
  Scenario sc = load_scenario(find_scenario("ponytail"));
  sc.groom = every_nth_strand(sc.groom, 16);
  ThreadPool pool(2);
  auto card = [&](const std::string& model, const std::string& name, double value) {
    RunOptions opt;
    opt.models = {model};
    opt.frames = 2;
    opt.model_overrides = {{model, name, value}};
    const std::vector<RunRecord> runs = run_scenario(sc, opt, pool);
    EXPECT_TRUE(runs.at(0).card.measured) << runs.at(0).card.skipped_why;
    EXPECT_TRUE(runs.at(0).reference_card.measured);
    return runs.at(0).card;
  };
  const material::Card stiff = card("han_m1", "local_stiffness", 0.9), soft = card("han_m1", "local_stiffness", 0.2);
  EXPECT_GT(stiff.sag, 0.0);
  EXPECT_GT(soft.sag, 1.5 * stiff.sag);
  const material::Card k = card("halen_cascade", "stiffness", 6000), quarter = card("halen_cascade", "stiffness", 1500);
  EXPECT_LT(std::abs(k.sag), 1e-6);
  EXPECT_LT(std::hypot(quarter.sigma, quarter.omega), 0.5 * std::hypot(k.sigma, k.omega));
}

}  // namespace
}  // namespace hairbench
