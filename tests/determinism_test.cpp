// Pinned state hashes: each readable reference model, stepped through the built-in `shake`
// scenario, ends in the same bits on every build and at any thread count (the
// determinism contract: no FMA contraction, no reassociated sums, per-strand work
// independent of how strands are spread over threads).
//
// A hash here changing means the reference's bits changed. The references are the
// paper-faithful readable implementations the fused kernels are checked against, so that
// must never happen by accident: a deliberate change of a reference (a paper-fidelity fix)
// updates its constant in the same commit and says why there. A hash that differs between
// 1 and 2 threads is a determinism bug, never a reason to update a constant.
#include "test_support.h"

#include "reports/metrics.h"

#include <gtest/gtest.h>

#include <memory>
#include <string>
#include <utility>

namespace hairbench {
namespace {

// `shake` with every 10th strand (200 strands of 16 vertices), all 240 frames (the 2 s of
// shaking, then the hold): well under a second per model and thread count.
constexpr std::size_t kKeepEvery = 10;

// metrics::state_hash of the final positions (hash_hex), per reference model.
const std::pair<const char*, const char*> kExpectedHash[] = {
    {"han_m1_ref", "503d58a976aca2ce"},        {"han_m2_ref", "b51af50c942088ce"},
    {"han_m3_ref", "55bd3c29c969089b"},        {"halen_spring_ref", "3ef9a60168ce0c50"},
    {"halen_cascade_ref", "3f9b6997419fe8fa"}, {"halen_forest_ref", "8074c90fe3db4758"},
    {"plante_wisp_ref", "1f29d7fc5af2b294"},
};

std::string final_hash(const Scenario& sc, const std::string& model, int threads) {
  ThreadPool pool(threads);
  const ModelInfo* info = find_model(model);
  EXPECT_NE(info, nullptr) << model;
  if (!info) return {};
  std::unique_ptr<HairModel> m = make_model(*info, sc, resolve_params(*info, sc, {}), pool);
  StageTimes times;
  for (int f = 0; f < sc.frames; ++f) m->step(frame_input(sc, f), times);
  return metrics::hash_hex(metrics::state_hash(m->positions()));
}

TEST(Determinism, ReferenceModelsMatchTheirPinnedHashOnShake) {
  const Scenario sc = test::builtin("shake", kKeepEvery);
  ASSERT_EQ(sc.groom.strand_count(), 200u);
  ASSERT_EQ(sc.frames, 240);
  for (const auto& [model, expected] : kExpectedHash) {
    const std::string one = final_hash(sc, model, 1);
    EXPECT_EQ(final_hash(sc, model, 2), one) << model << ": the thread count changed the bits";
    EXPECT_EQ(one, expected) << model << ": the reference's bits changed (see the comment at the top)";
  }
}

}  // namespace
}  // namespace hairbench
