// `hairbench stress`: the energy-growth failure criterion and the degenerate grooms (each
// runs or is refused at load, never diverges); stress_set_test.cpp runs a short stress set.
#include "stress_support.h"

#include "core/parallel.h"
#include "harness/stress.h"
#include "models/registry.h"
#include "reports/metrics.h"

#include <gtest/gtest.h>

#include <string>
#include <vector>

namespace hairbench {
namespace {

using metrics::EnergyGrowthCheck;
constexpr int kFramesToFail = EnergyGrowthCheck::kWindow * (EnergyGrowthCheck::kWindows + 1);

TEST(EnergyGrowthCheck, SustainedGrowthWithTheHeadStillFails) {
  // L-bar 0.25 m, g 9.81: the threshold is 0.05 * 9.81 * 0.25 = 0.123 J/kg per window.
  EnergyGrowthCheck check(0.25, 9.81);
  int failed_at = -1;
  for (int f = 0; f < 200 && failed_at < 0; ++f)
    if (!check.add(0.02 * f, false).empty()) failed_at = f;  // +0.2 J/kg per 10 frames
  EXPECT_EQ(failed_at, kFramesToFail - 1);
}

TEST(EnergyGrowthCheck, DecayOrSlowGrowthOrDrivenGrowthPasses) {
  EnergyGrowthCheck decaying(0.25, 9.81), slow(0.25, 9.81), driven(0.25, 9.81);
  for (int f = 0; f < 500; ++f) {
    EXPECT_EQ(decaying.add(5.0 * std::exp(-0.01 * f), false), "");
    EXPECT_EQ(slow.add(0.01 * f, false), "");  // 0.1 J/kg per window: below 0.123
    // The head moves every 50th frame: growth never lasts 60 undriven frames.
    EXPECT_EQ(driven.add(0.05 * f, f % 50 == 0), "");
  }
}

TEST(Stress, DegenerateGroomsRunStablyOrAreRefusedForEveryModel) {
  ThreadPool pool(2);
  StressOptions opt;
  opt.models = test::stress_models();
  opt.axes = "none";  // degenerate grooms only
  const StressResult r = run_stress(opt, pool);
  ASSERT_EQ(r.degenerate.size(), 5 * opt.models.size());
  for (const DegenerateResult& d : r.degenerate) {
    SCOPED_TRACE(d.model + " on " + d.name + ": " + d.reason);
    EXPECT_NE(d.status, "diverged");
    if (d.name == "zero_length_edge") {
      // Refused at load with the groom and the field named.
      EXPECT_EQ(d.status, "refused");
      EXPECT_NE(d.reason.find("zero_length_edge"), std::string::npos);
      EXPECT_NE(d.reason.find("zero-length edge"), std::string::npos);
    } else if (test::known_unstable(d.model)) {
      // Reported as unstable where they are (known_unstable), never as a blow-up.
      EXPECT_TRUE(d.status == "ok" || d.status == "unstable") << d.status;
    } else if (d.model.rfind("plante_wisp", 0) == 0 && d.name == "inside_collider") {
      // The layered wisps' first body detection moves the skeleton masses that start
      // inside the collider out onto its surface (§4.2), wrapping the skeleton round it;
      // its bending springs then throw it off within a frame, and the strands rebuilt on
      // the skeleton folded over pass the 50% bound for a few frames
      // (docs/limitations.md). It settles, never blows up, but not where its rest twin
      // does: pushed off the collider the other way, it rests there (deformed).
      EXPECT_TRUE(d.status == "ok" || d.status == "stretched" || d.status == "deformed") << d.status;
    } else if (d.model.rfind("halen_cascade", 0) == 0 && (d.name == "two_vertex_strands" || d.name == "inside_collider")) {
      // The cascade comes back, but slower than the short base scenario's half-second
      // window (e-folding times of 2.4 s and 18 s, docs/limitations.md): deformed.
      EXPECT_TRUE(d.status == "ok" || d.status == "deformed") << d.status;
    } else {
      EXPECT_EQ(d.status, "ok");  // these are valid grooms: every model must cope
    }
  }
}

}  // namespace
}  // namespace hairbench
