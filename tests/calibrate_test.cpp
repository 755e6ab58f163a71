// --calibrate (harness/calibrate.h): each model's stiffness fitted so that its material
// card's sag matches the reference's.
#include "core/parallel.h"
#include "harness/calibrate.h"
#include "harness/runner.h"
#include "test_support.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

namespace hairbench {
namespace {

// --calibrate on `shake` (thinned): every model's static sag ends within max(10%, 0.005 L̄)
// of the reference's but the wisp model's, whose calibration says how far it stays; each fit names its parameter and
// what it was fitted on, and the card the run carries is the fitted material's. The same
// command twice fits the same values (deterministic).
TEST(MaterialCard, CalibrateBringsEverySagWithinTheToleranceOfTheReferences) {
  const Scenario sc = test::builtin("shake", 16);
  ThreadPool pool(2);
  RunOptions opt;
  opt.models = test::kCpuModels;
  opt.frames = 2;
  opt.calibrate = true;
  const std::vector<RunRecord> runs = run_scenario(sc, opt, pool);
  const std::vector<RunRecord> again = run_scenario(sc, opt, pool);
  for (std::size_t i = 0; i < runs.size(); ++i) {
    const RunRecord& r = runs[i];
    SCOPED_TRACE(r.model);
    ASSERT_TRUE(r.card.measured);
    const double tolerance = std::max(kSagTolerance * std::abs(r.reference_card.sag), kSagFloor);
    // The one known exception: the wisp model's sag stays above the reference's at every
    // bending stiffness in its range (docs/metrics.md, Calibration), and says so.
    if (r.model == "plante_wisp" && r.calibration && !r.calibration->fits.at(0).within) {
      EXPECT_NE(r.calibration->fits[0].note.find("cannot reach the reference's sag"), std::string::npos);
      EXPECT_GT(r.card.sag, r.reference_card.sag);
    } else {
      EXPECT_LE(std::abs(r.card.sag - r.reference_card.sag), tolerance);
    }
    EXPECT_EQ(r.params.dump(), again[i].params.dump());
    if (r.model == "han_m1") {
      EXPECT_FALSE(r.calibration.has_value());
      continue;
    }
    ASSERT_TRUE(r.calibration.has_value());
    ASSERT_EQ(r.calibration->fits.size(), 2u);
    for (const material::Calibration::Fit& f : r.calibration->fits) {
      EXPECT_FALSE(f.param.empty()) << f.role;
      // Fitted (on the sag or the decay rate), within or saying how far it stays; or left
      // as it is, saying why.
      EXPECT_TRUE(f.on.empty() ? !f.note.empty() : (f.on == "sag" || f.on == "sigma")) << f.role << " " << f.on;
      EXPECT_TRUE(f.within || !f.note.empty()) << f.role;
    }
  }
}

}  // namespace
}  // namespace hairbench
