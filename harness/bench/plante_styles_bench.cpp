// Plante, Cani & Poulin 2001 §5.3: the three hair styles of the paper (short: 199 wisps
// of 4.0 segments, medium: 73 of 9.9, long: 56 of 7.7) simulated at the paper's rates
// (integration 1000 Hz, body collisions 120 Hz, wisp self-interactions 24 Hz), one
// thread like the paper's single R12000, under the head motion of the `shake` scenario
// in frames of 1/24 s. Reports the time per simulated second, the projection to the
// paper's 264 frames (11 s at 24 frames/s) and each stage's share of the step time.
// The paper: 3.2 h (short) and 2.9 h (medium, long) for 264 frames on a 270 MHz R12000;
// 92-95% of it in interactions, 64-70% of that wisp-wisp.
#include "harness/paper_setups.h"

#include <benchmark/benchmark.h>

#include <map>
#include <string>

namespace hairbench {
namespace {

constexpr int kFrames = 24;  // one simulated second per iteration

void BM_PlanteStyle(benchmark::State& state) {
  const PlanteStyle& style = plante_styles()[static_cast<std::size_t>(state.range(0))];
  PlanteStyleTiming total;
  for (auto _ : state) {
    const PlanteStyleTiming t = time_plante_style(style, kFrames);
    state.SetIterationTime(t.step_ms / 1000.0);  // the steps only, not the set-up
    total.wisps = t.wisps;
    total.segments_per_wisp = t.segments_per_wisp;
    total.step_ms += t.step_ms;
    total.sim_s += t.sim_s;
    for (const auto& [stage, ms] : t.stage_ms) total.stage_ms[stage] += ms;
  }
  std::map<std::string, double>& stage_ms = total.stage_ms;
  const double interactions = stage_ms["body_collision"] + stage_ms["self_interaction"];
  state.counters["wisps"] = total.wisps;
  state.counters["segments_per_wisp"] = total.segments_per_wisp;
  state.counters["ms_per_sim_s"] = total.step_ms / total.sim_s;
  state.counters["s_for_264_frames"] = total.step_ms / total.sim_s * 264.0 / 24.0 / 1000.0;
  for (const char* stage : {"integrate", "body_collision", "self_interaction", "rebuild"})
    state.counters[std::string(stage) + "_share"] = stage_ms[stage] / total.step_ms;
  state.counters["interaction_share"] = interactions / total.step_ms;
  state.counters["self_of_interactions"] = interactions > 0.0 ? stage_ms["self_interaction"] / interactions : 0.0;
  state.SetLabel(style.name);
}
BENCHMARK(BM_PlanteStyle)->DenseRange(0, 2)->UseManualTime()->Unit(benchmark::kMillisecond)->Iterations(2);

}  // namespace
}  // namespace hairbench
