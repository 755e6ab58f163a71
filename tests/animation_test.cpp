// The motion player's frames (reports/animation.h): the encoding round-trips and refuses
// what it did not write, the recorder keeps positions in the head's frame to within half
// its unit and stops at a blown-up strand, the verdicts' strands are drawn, and a
// lockstep run's recorded frames are its models' positions (the last one against the
// final snapshot, taken independently).
#include "core/parallel.h"
#include "harness/runner.h"
#include "reports/animation.h"
#include "test_support.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

using namespace hairbench;

namespace {

// Strands of 3 and 8 vertices, over frames that swing, stand still and jump.
std::vector<std::int32_t> frames_of(std::size_t frames, std::size_t per_frame) {
  std::vector<std::int32_t> q;
  for (std::size_t f = 0; f < frames; ++f)
    for (std::size_t i = 0; i < per_frame; ++i)
      q.push_back(static_cast<std::int32_t>(f == 3 ? 40000 - 7 * long(i) : std::lround(300 * std::sin(0.3 * f + 0.1 * i)) - 20));
  return q;
}

}  // namespace

TEST(Animation, EncodingRoundTripsAndRefusesWhatItDidNotWrite) {
  const std::vector<std::uint32_t> sizes = {3, 8};
  const std::vector<std::int32_t> q = frames_of(12, 33);
  const std::string code = animation::encode(q, sizes);
  EXPECT_EQ(animation::decode(code, sizes), q);
  // Still frames cost next to nothing: each is a frame's worth of zero residuals, deflated.
  std::vector<std::int32_t> still(q.begin(), q.begin() + 33);
  for (int f = 1; f < 40; ++f) still.insert(still.end(), q.begin(), q.begin() + 33);
  EXPECT_LT(animation::encode(still, sizes).size(), animation::encode(q, sizes).size());
  EXPECT_EQ(animation::decode(animation::encode(still, sizes), sizes), still);

  EXPECT_THROW(animation::decode(code.substr(0, code.size() - 1), sizes), std::runtime_error);  // base64 length
  EXPECT_THROW(animation::decode("!!!!" + code.substr(4), sizes), std::runtime_error);          // not base64
  EXPECT_THROW(animation::decode("AAAA", sizes), std::runtime_error);                           // not zlib
  EXPECT_THROW(animation::decode(code, std::vector<std::uint32_t>{3, 7}), std::runtime_error);  // other strands
  EXPECT_THROW(animation::encode(q, std::vector<std::uint32_t>{5, 8}), std::invalid_argument);
}

TEST(Animation, PicksRootTipAndEvenVerticesAndSpreadsStrands) {
  EXPECT_EQ(animation::picked_vertices(5), (std::vector<std::uint32_t>{0, 1, 2, 3, 4}));
  const std::vector<std::uint32_t> v = animation::picked_vertices(32);
  ASSERT_EQ(v.size(), animation::kVertices);
  EXPECT_EQ(v.front(), 0u);
  EXPECT_EQ(v.back(), 31u);
  for (std::size_t i = 1; i < v.size(); ++i) {
    EXPECT_GT(v[i], v[i - 1]);
    EXPECT_NEAR(double(v[i] - v[i - 1]), 31.0 / 7.0, 1.0);
  }
  EXPECT_EQ(animation::spread_strands(10).size(), 10u);
  const std::vector<std::uint32_t> s = animation::spread_strands(2000);
  EXPECT_LE(s.size(), animation::kSpreadStrands);
  EXPECT_GE(s.size(), animation::kSpreadStrands - 1);
  EXPECT_EQ(animation::stride(240), 5);
  EXPECT_EQ(animation::stride(48), 1);
  EXPECT_LE((300 + animation::stride(300) - 1) / animation::stride(300), animation::kMaxFrames);
}

TEST(Animation, VerdictsNameTheirStrandsAndEveryPanelDrawsThem) {
  verdict::Verdict v;
  v.stretch.frames_above = 2;
  v.stretch.worst_strand = 1001;
  v.settle.decays = false;
  v.settle.spread.strands = 40;
  v.settle.spread.strand = 7;
  v.back.deformed = true;
  v.back.worst_strand = 5000;  // beyond the candidates (a follow hair): not drawn
  const std::vector<animation::Named> named = animation::named_strands(v, "m", 2000);
  ASSERT_EQ(named.size(), 2u);
  EXPECT_EQ(named[0].strand, 1001u);
  EXPECT_EQ(named[1].strand, 7u);
  const std::vector<std::uint32_t> drawn = animation::drawn_strands(2000, named);
  EXPECT_TRUE(std::is_sorted(drawn.begin(), drawn.end()));
  EXPECT_EQ(std::count(drawn.begin(), drawn.end(), 1001u), 1);
  EXPECT_EQ(std::count(drawn.begin(), drawn.end(), 7u), 1);
  EXPECT_EQ(std::count(drawn.begin(), drawn.end(), 0u), 1);  // a spread strand, named by nobody
  EXPECT_TRUE(animation::named_strands(verdict::Verdict{}, "m", 2000).empty());
}

TEST(Animation, RecorderKeepsTheHeadFrameToHalfAUnitAndStopsAtABlowUp) {
  Groom g;
  g.strand_offsets = {0, 3, 13};
  for (int v = 0; v < 13; ++v) g.positions.emplace_back(0.01f * v, 0.1f - 0.02f * v, 0.003f * v * v, 1.0f);
  Affine3f head = Affine3f::Identity();
  head.rotate(Eigen::AngleAxisf(0.7f, Vec3f(0.3f, 1.0f, 0.2f).normalized()));
  head.translation() = Vec3f(0.4f, -1.2f, 2.0f);
  std::vector<Vec4f> p = g.positions;
  for (Vec4f& x : p) x.head<3>() = head * Vec3f(x.head<3>());
  animation::Recorder rec(g, 2);
  rec.add(p, head);
  rec.add(p, head);
  EXPECT_EQ(rec.frames(), 2);
  const std::vector<std::uint32_t> sizes = {3, animation::kVertices};
  const std::vector<std::int32_t> q = animation::decode(rec.encode(std::vector<std::uint32_t>{0, 1}), sizes);
  ASSERT_EQ(q.size(), 2 * 3 * (3 + animation::kVertices));
  const std::vector<std::uint32_t> picked = animation::picked_vertices(10);
  for (std::size_t i = 0; i < 3 + animation::kVertices; ++i) {
    const std::uint32_t vertex = i < 3 ? std::uint32_t(i) : 3 + picked[i - 3];
    for (int a = 0; a < 3; ++a)
      EXPECT_NEAR(q[3 * i + a] * animation::kUnitMetres, g.positions[vertex][a], 0.5 * animation::kUnitMetres + 1e-6)
          << "vertex " << vertex << " axis " << a;
  }
  p[12].x() = std::numeric_limits<float>::quiet_NaN();  // the tip, drawn
  rec.add(p, head);
  p[12].x() = 0.0f;
  rec.add(p, head);  // a run drawn up to its blow-up, not past it
  EXPECT_EQ(rec.frames(), 2);
  EXPECT_TRUE(rec.ended());
}

TEST(Animation, ALockstepRunRecordsItsModelsAtTheStride) {
  const Scenario sc = test::builtin("shake", 100);  // 20 strands
  ThreadPool pool(2);
  RunOptions opt;
  opt.models = {"han_m1", "halen_spring"};
  opt.frames = 49;  // stride 2: frames 0, 2, ..., 48, the last the final snapshot's
  ScenarioRecord rec;
  opt.scenario_record = &rec;
  opt.animation = true;
  const std::vector<RunRecord> runs = run_scenario(sc, opt, pool);
  ASSERT_TRUE(rec.animation);
  const ScenarioRecord::Animation& a = *rec.animation;
  EXPECT_EQ(a.stride, 2);
  EXPECT_EQ(a.heads.size(), 25u);
  EXPECT_EQ(a.strands, animation::spread_strands(sc.groom.strand_count()));
  ASSERT_TRUE(runs[0].animation && runs[1].animation);
  EXPECT_TRUE(runs[0].animation->same_as_reference);
  EXPECT_TRUE(runs[0].animation->data.empty());
  EXPECT_EQ(a.reference.frames, 25);
  EXPECT_EQ(runs[1].animation->frames, 25);
  std::vector<std::uint32_t> sizes;
  for (const auto& v : a.vertices) sizes.push_back(static_cast<std::uint32_t>(v.size()));
  // The final snapshot's strands hold every strand here (20 < kMaxSnapshotStrands).
  ASSERT_EQ(rec.snapshot_strands.size(), sc.groom.strand_count());
  for (const auto& [run, code] :
       {std::pair{&runs[0], a.reference.data}, std::pair{&runs[1], runs[1].animation->data}}) {
    const std::vector<std::int32_t> q = animation::decode(code, sizes);
    const std::size_t per = q.size() / 25;
    const Affine3f& head = a.heads.back();
    const auto& snap = run->snapshots[1];
    ASSERT_EQ(snap.frame, 48);
    std::size_t at = 24 * per;
    double worst = 0.0;
    for (std::size_t k = 0; k < a.strands.size(); ++k)
      for (std::uint32_t v : a.vertices[k]) {
        const Vec3f local(float(q[at] * animation::kUnitMetres), float(q[at + 1] * animation::kUnitMetres),
                          float(q[at + 2] * animation::kUnitMetres));
        const Vec3f world = head * local;
        const std::vector<float>& xyz = snap.strands[a.strands[k]];
        worst = std::max<double>(worst, (world - Vec3f(xyz[3 * v], xyz[3 * v + 1], xyz[3 * v + 2])).norm());
        at += 3;
      }
    // Half a unit on each of three axes, rotated back to the world.
    EXPECT_LE(worst, 0.5 * std::sqrt(3.0) * animation::kUnitMetres + 1e-5) << run->model;
  }
}
