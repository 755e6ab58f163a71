// A short `hairbench stress` set: every CPU model escalated along the time step and a
// teleport until it fails, stable at the base scenario's own step. Long under the
// sanitizers, and physics, not input handling: labelled slow.
#include "stress_support.h"

#include "core/parallel.h"
#include "harness/stress.h"

#include <gtest/gtest.h>

namespace hairbench {
namespace {

TEST(Stress, ShortSetEscalatesUntilFailureAndKeepsTheBaseStable) {
  ThreadPool pool(2);
  StressOptions opt;
  opt.models = test::stress_models();
  opt.keep_every = 100;  // 20 strands
  opt.axes = "time_step|teleport";
  opt.degenerate = false;
  const StressResult r = run_stress(opt, pool);
  ASSERT_EQ(r.axes.size(), 2 * opt.models.size());
  for (const StressAxisResult& a : r.axes) {
    SCOPED_TRACE(a.model + " / " + a.axis);
    ASSERT_FALSE(a.cells.empty());
    for (const StressCell& c : a.cells) {
      // A failure always says why; a stable cell never carries a reason.
      EXPECT_EQ(c.stable, c.reason.empty());
      // The base scenario's own time step (1/60 s) is where every model is stable, but
      // for those known to be unstable on some grooms (known_unstable).
      if (a.axis == "time_step" && c.value == 1.0 / 60) {
        if (test::known_unstable(a.model)) {
          EXPECT_TRUE(c.stable || c.reason.rfind("unstable:", 0) == 0) << c.reason;
        } else {
          EXPECT_TRUE(c.stable) << c.reason;
        }
      }
    }
    // last stable < first failing, both from the tried values, when both exist.
    if (a.first_failing && a.last_stable) {
      EXPECT_LT(*a.last_stable, *a.first_failing);
    }
    if (a.first_failing) {
      EXPECT_FALSE(a.reason.empty());
    }
  }
  const nlohmann::json j = stress_json(r);
  EXPECT_EQ(j["axes"].size(), r.axes.size());
}

}  // namespace
}  // namespace hairbench
