// Side-by-side runs of a fast model and its per-stage reference, shared by the han_fused
// and halen_fused agreement tests.
#pragma once

#include "test_support.h"

#include "core/parallel.h"
#include "models/registry.h"
#include "reports/metrics.h"

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

namespace hairbench::test {

// The Table 1 model-1 groom (three regions, ragged vertex counts, three colliders),
// every keep_every-th strand.
inline Scenario paper_model1(std::size_t keep_every) {
  Scenario sc = load_scenario(std::filesystem::path(HAIRBENCH_PAPER_SCENARIO_DIR) / "han2012_model1.json");
  sc.groom = every_nth_strand(sc.groom, keep_every);
  return sc;
}

inline std::unique_ptr<HairModel> make_named(const std::string& name, const Scenario& sc,
                                             const std::vector<ParamOverride>& ov, ThreadPool& pool,
                                             bool skip_inert = true) {
  const ModelInfo* info = find_model(name);
  if (!info) throw std::runtime_error("no model " + name);
  return make_model(*info, sc, resolve_params(*info, sc, ov), pool, "", skip_inert);
}

// Steps two models in lockstep; the first frame whose positions differ in any bit, or
// -1. `max_diff` gets the largest coordinate difference over all frames.
inline int first_difference(const Scenario& sc, const std::string& a, const std::string& b, int frames,
                            const std::vector<ParamOverride>& ov, double* max_diff = nullptr,
                            bool skip_inert = true) {
  ThreadPool pool(2);
  auto ma = make_named(a, sc, ov, pool, skip_inert);
  auto mb = make_named(b, sc, ov, pool, skip_inert);
  int first = -1;
  double worst = 0.0;
  for (int f = 0; f < frames; ++f) {
    const FrameInput in = frame_input(sc, f);
    StageTimes t;
    ma->step(in, t);
    mb->step(in, t);
    const auto pa = ma->positions(), pb = mb->positions();
    if (first < 0 && std::memcmp(pa.data(), pb.data(), pa.size_bytes()) != 0) first = f;
    for (std::size_t i = 0; i < pa.size(); ++i) worst = std::max(worst, double((pa[i] - pb[i]).cwiseAbs().maxCoeff()));
  }
  if (max_diff) *max_diff = worst;
  return first;
}

inline std::uint64_t state_hash_after(const Scenario& sc, const std::string& model, int threads, int frames) {
  ThreadPool pool(threads);
  auto m = make_named(model, sc, {}, pool);
  for (int f = 0; f < frames; ++f) {
    StageTimes t;
    m->step(frame_input(sc, f), t);
  }
  return metrics::state_hash(m->positions());
}

// Sleeping strands and their wake-up: `idle` (every 16th strand) for 200
// frames, the head still until it turns at 2 s.
inline Scenario idle_then_turn() {
  Scenario sc = builtin("idle", 16);
  sc.frames = 200;
  Oscillator turn;
  turn.kind = Oscillator::Kind::Rotate;
  turn.amplitude = 0.5;
  turn.start = 2.0;
  turn.end = 10.0;
  sc.head.oscillators = {turn};
  return sc;
}

}  // namespace hairbench::test
