// Skip what a scene does not need: a stage the scene makes inert is not run,
// and not running it never changes the physics; settled strands sleep and wake
// bit-exactly; a scenario may give each region its own Han method (§6).
#include "test_support.h"

#include "core/parallel.h"
#include "harness/runner.h"
#include "reports/metrics.h"

#include <gtest/gtest.h>

#include <cstring>
#include <functional>
#include <map>
#include <numbers>
#include <string>
#include <vector>

namespace hairbench {
namespace {

// Every CPU model. The position-based ones skip passes; the forest and the wisps only
// skip their body pass, and must come out identical all the same. All of them sleep
// (plante_wisp as a whole: its wisps touch each other).
using test::kCpuModels;
const std::vector<std::string> kSleepers = kCpuModels;

// Seconds of `idle` by which a model's hair has settled below StrandSleep::kRestSpeed for
// kQuietFrames. plante_wisp is slower: its slowest mode is damped by air resistance
// alone (5/s), and its wisps slide down the head against viscous friction (§4.2) until
// their bending springs hold them; measured on the thinned `idle`, its fastest mass falls
// below 1e-4 m/s after about 7.5 s (2.7e-4 at 5 s, 1.6e-4 at 6 s, 9e-5 at 8 s, 6e-5 at 12 s).
double settle_seconds(const std::string& model) { return model == "plante_wisp" ? 9.0 : 2.0; }

struct Simulation {
  std::vector<Vec4f> positions;
  std::map<std::string, int> skipped_steps;  // stage -> steps in which it was skipped
  std::vector<std::vector<Vec4f>> history;   // positions after every frame, when kept
};

using Tweak = std::function<void(ParamSet&, const Groom&)>;

Simulation simulate(const std::string& model, const Scenario& sc, bool skip_inert, int frames,
                    const Tweak& tweak = {}, bool keep_history = false, int threads = 2) {
  const ModelInfo* info = find_model(model);
  EXPECT_NE(info, nullptr) << model;
  ThreadPool pool(threads);
  ParamSet params = resolve_params(*info, sc, {});
  if (tweak) tweak(params, sc.groom);
  auto m = make_model(*info, sc, params, pool, "", skip_inert);
  Simulation out;
  StageTimes times;
  for (int f = 0; f < frames; ++f) {
    times.clear();
    m->step(frame_input(sc, f), times);
    for (const auto& e : times.entries())
      if (e.skipped) ++out.skipped_steps[std::string(e.name)];
    if (keep_history) out.history.emplace_back(m->positions().begin(), m->positions().end());
  }
  out.positions.assign(m->positions().begin(), m->positions().end());
  return out;
}

bool bit_identical(const std::vector<Vec4f>& a, const std::vector<Vec4f>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(Vec4f)) == 0;
}

Tweak set_everywhere(const std::string& name, double value) {
  return [=](ParamSet& p, const Groom&) {
    if (p.has(name)) p.set_everywhere(name, value, {"test", ""});
  };
}

// The head moves through all of these frames (shake turns for 2 s), so no strand may
// sleep and the skipped and unskipped runs must agree bit for bit.
constexpr int kMovingFrames = 90;

struct InertCase {
  const char* name;
  std::function<void(Scenario&)> scene;
  Tweak params;
  const char* han_stage;  // the Han stage this case makes inert ("" if none)
};

std::vector<InertCase> inert_cases() {
  return {
      {"no_wind", [](Scenario&) {}, {}, ""},
      {"no_colliders", [](Scenario& sc) { sc.colliders.clear(); }, {}, "collision"},
      {"global_stiffness_0", [](Scenario&) {}, set_everywhere("global_stiffness", 0.0), "global_shape"},
      {"global_range_0", [](Scenario&) {}, set_everywhere("global_range", 0.0), "global_shape"},
      {"local_stiffness_0", [](Scenario&) {}, set_everywhere("local_stiffness", 0.0), "local_shape"},
  };
}

TEST(SkipInert, SkippingAnInertStageNeverChangesThePhysics) {
  for (const InertCase& c : inert_cases()) {
    Scenario sc = test::builtin("shake", 16);
    c.scene(sc);
    for (const std::string& model : kCpuModels) {
      const Simulation skipped = simulate(model, sc, true, kMovingFrames, c.params);
      const Simulation full = simulate(model, sc, false, kMovingFrames, c.params);
      EXPECT_TRUE(bit_identical(skipped.positions, full.positions)) << c.name << " " << model;
      EXPECT_TRUE(full.skipped_steps.empty()) << c.name << " " << model << ": --no-skip must run every stage";
      if (std::string(c.han_stage).empty() || model.rfind("han_", 0) != 0) continue;
      // The stage is reported every step, as skipped, not left out.
      EXPECT_EQ(skipped.skipped_steps.count(c.han_stage) ? skipped.skipped_steps.at(c.han_stage) : 0, kMovingFrames)
          << c.name << " " << model;
    }
  }
}

TEST(SkipInert, InertRegionSkipsOnlyItsOwnStrands) {
  // Ponytail: the global pass is off in one region only, so the stage still runs for the
  // other regions and must leave the inert region's strands as the full run does.
  Scenario sc = test::builtin("ponytail", 8);
  ASSERT_GE(sc.groom.region_names.size(), 2u);
  const Tweak one_region = [](ParamSet& p, const Groom&) { p.set_region(0, "global_stiffness", 0.0, {"test", ""}); };
  for (const std::string& model : test::kHan) {
    const Simulation skipped = simulate(model, sc, true, kMovingFrames, one_region);
    const Simulation full = simulate(model, sc, false, kMovingFrames, one_region);
    EXPECT_TRUE(bit_identical(skipped.positions, full.positions)) << model;
    EXPECT_EQ(skipped.skipped_steps.count("global_shape"), 0u) << model;
  }
}

TEST(SkipInert, ColliderThatIsNeverTouchedEqualsNoCollider) {
  // A present but inert stage (a sphere 100 m away) against an absent one: the collision
  // pass must not move a vertex it does not push out.
  Scenario with = test::builtin("shake", 16);
  ASSERT_FALSE(with.colliders.empty());
  Scenario without = with;
  without.colliders.clear();
  with.colliders = {Sphere{Vec3f(100.0f, 0.0f, 0.0f), 0.1f, false}};
  for (const std::string& model : kCpuModels) {
    EXPECT_TRUE(bit_identical(simulate(model, with, true, kMovingFrames).positions,
                              simulate(model, without, true, kMovingFrames).positions))
        << model;
  }
}

TEST(SkipInert, ZeroWindEqualsNoWind) {
  Scenario calm = test::builtin("shake", 16);
  Scenario zero = calm;
  zero.wind.direction = Vec3f(0.0f, 0.0f, 1.0f);
  zero.wind.keys = {{0.0, 0.0}, {10.0, 0.0}};
  for (const std::string& model : kCpuModels) {
    // The zero-strength wind term computed (--no-skip) against no wind at all.
    EXPECT_TRUE(bit_identical(simulate(model, zero, false, kMovingFrames).positions,
                              simulate(model, calm, true, kMovingFrames).positions))
        << model;
  }
}

// idle: the head never moves; strands settle under gravity and their shape constraints.
TEST(Sleep, SettledStrandsSleepHoldStillAndStayCloseToTheFullRun) {
  Scenario sc = test::builtin("idle", 16);
  for (const std::string& model : kSleepers) {
    const int frames = std::max(sc.frames, static_cast<int>((settle_seconds(model) + 1.0) / sc.dt + 0.5));
    const Simulation asleep = simulate(model, sc, true, frames, {}, true);
    const Simulation full = simulate(model, sc, false, frames);
    // By the end every strand sleeps: the last frames are bit-identical to each other.
    const auto& h = asleep.history;
    EXPECT_TRUE(bit_identical(h[h.size() - 1], h[h.size() - 10])) << model;
    // Sleeping only stopped motion below StrandSleep::kRestSpeed: the frozen hair is
    // within 1e-4 of a strand length (25 um on 25 cm strands) of the hair that kept
    // being simulated.
    const double dev = metrics::deviation(asleep.positions, full.positions, mean_strand_length(sc.groom));
    EXPECT_LT(dev, 1e-4) << model;
  }
}

TEST(Sleep, WakeUpResumesBitExactlyWhereTheStrandFellAsleep) {
  // Still for 2 s, then a turn: the strands fall asleep, hold bit-exactly still, and the
  // first moving frame starts from exactly those positions.
  for (const std::string& model : kSleepers) {
    Scenario sc = test::builtin("idle", 16);
    const double wake_t = settle_seconds(model);
    Oscillator turn;
    turn.kind = Oscillator::Kind::Rotate;
    turn.amplitude = 30.0 * std::numbers::pi / 180.0;
    turn.start = wake_t;
    turn.end = wake_t + 8.0;
    sc.head.oscillators = {turn};
    const int wake_frame = static_cast<int>(wake_t / sc.dt + 0.5);  // first step whose head moves
    sc.frames = wake_frame + 80;
    const Simulation run = simulate(model, sc, true, sc.frames, {}, true);
    const auto& h = run.history;
    // Asleep well before the head moves: unchanged over the last 20 still frames.
    EXPECT_TRUE(bit_identical(h[wake_frame - 1], h[wake_frame - 21])) << model;
    // Awake once it moves, and stable through the turn.
    EXPECT_FALSE(bit_identical(h[wake_frame], h[wake_frame - 1])) << model;
    const metrics::RestInfo rest(sc.groom);
    for (int f = wake_frame; f < sc.frames; ++f)
      ASSERT_TRUE(metrics::blowup_reason(rest, h[f], sc.head.at((f + 1) * sc.dt).translation()).empty())
          << model << " frame " << f;
    // Against the run that never slept: the frozen state differed by less than 1e-4 L
    // (previous test); through the turn the two stay that close.
    const Simulation full = simulate(model, sc, false, sc.frames);
    EXPECT_LT(metrics::deviation(run.positions, full.positions, mean_strand_length(sc.groom)), 1e-3) << model;
  }
}

TEST(RegionMethod, EachRegionRunsItsOwnMethod) {
  // Han strands do not interact, so a han_m1 run whose region r uses method 3 must give
  // region r's strands exactly as han_m3 does and the others exactly as han_m1 does.
  Scenario sc = test::builtin("ponytail", 8);
  const std::size_t regions = sc.groom.region_names.size();
  ASSERT_GE(regions, 2u);
  const std::size_t lod = regions - 1;
  const Tweak m3_on_lod = [&](ParamSet& p, const Groom&) { p.set_region(lod, "method", 3, {"test", ""}); };
  const Simulation mixed = simulate("han_m1", sc, true, kMovingFrames, m3_on_lod);
  const Simulation m1 = simulate("han_m1", sc, true, kMovingFrames);
  const Simulation m3 = simulate("han_m3", sc, true, kMovingFrames);
  std::size_t lod_strands = 0;
  for (std::size_t s = 0; s < sc.groom.strand_count(); ++s) {
    const std::size_t b = sc.groom.strand_begin(s), n = sc.groom.strand_size(s);
    const auto& expect = sc.groom.strand_region[s] == lod ? m3.positions : m1.positions;
    lod_strands += sc.groom.strand_region[s] == lod;
    EXPECT_EQ(std::memcmp(mixed.positions.data() + b, expect.data() + b, n * sizeof(Vec4f)), 0) << "strand " << s;
  }
  EXPECT_GT(lod_strands, 0u);
  EXPECT_FALSE(bit_identical(m1.positions, m3.positions));  // the methods do differ here
}

}  // namespace
}  // namespace hairbench
