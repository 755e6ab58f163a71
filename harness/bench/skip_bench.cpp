// What skipping inert stages saves, per CPU model (filter: --benchmark_filter=BM_skip):
//
//   BM_skip/MODEL/FEATURE:on|off  `shake` with the feature present (on) and absent (off):
//       colliders (the head sphere / none), wind (a steady 6 m/s^2 wind / none),
//       global (S_G 0.2 / 0), local (S_L 0.9 / 0). Counters stage_<name>: mean ms per
//       step in that stage; the skipped stage reads 0 in the off run, and the step time
//       drops by about the on run's stage time.
//   BM_settled/MODEL/idle|shake  step time once `idle` has settled (its strands asleep),
//       against `shake` while it shakes: settled, idle should cost < 10% of shake.
//
// One iteration is one frame; manual time covers step() only.
#include "core/parallel.h"
#include "harness/runner.h"
#include "scenarios/scenario.h"

#include <benchmark/benchmark.h>

#include <chrono>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

namespace hairbench {
namespace {

struct Feature {
  const char* name;
  // Makes the "off" variant of the scenario and parameters (the "on" one is `shake`, with
  // a steady wind for the wind pair).
  std::function<void(Scenario&, std::vector<ParamOverride>&)> on, off;
};

const std::vector<Feature>& features() {
  static const std::vector<Feature> f = {
      {"colliders", [](Scenario&, auto&) {}, [](Scenario& sc, auto&) { sc.colliders.clear(); }},
      {"wind", [](Scenario& sc, auto&) { sc.wind.strength = 6.0; sc.wind.keys.clear(); },
       [](Scenario& sc, auto&) { sc.wind.strength = 0.0; sc.wind.keys.clear(); }},
      {"global", [](Scenario&, auto&) {}, [](Scenario&, auto& o) { o.push_back({"*", "global_stiffness", 0.0}); }},
      {"local", [](Scenario&, auto&) {}, [](Scenario&, auto& o) { o.push_back({"*", "local_stiffness", 0.0}); }},
  };
  return f;
}

// Steps `model` for `frames` frames from `first`, timing each step; counters get the
// mean ms per step of every stage.
void time_frames(benchmark::State& state, HairModel& model, const Scenario& sc, int first) {
  StageTimes times;
  std::map<std::string, double> stage_ms;
  int f = first, n = 0;
  for (auto _ : state) {
    times.clear();
    const FrameInput in = frame_input(sc, f++);
    const auto start = std::chrono::steady_clock::now();
    model.step(in, times);
    state.SetIterationTime(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
    for (const auto& e : times.entries()) stage_ms[std::string(e.name)] += e.ms;
    ++n;
  }
  for (const auto& [name, ms] : stage_ms) state.counters["stage_" + name] = n ? ms / n : 0.0;
}

void bm_skip(benchmark::State& state, const ModelInfo* info, const Feature* feature, bool on) {
  Scenario sc = load_scenario(find_scenario("shake"));
  std::vector<ParamOverride> overrides;
  (on ? feature->on : feature->off)(sc, overrides);
  ThreadPool pool(0);
  auto model = make_model(*info, sc, resolve_params(*info, sc, overrides), pool);
  time_frames(state, *model, sc, 0);
}

void bm_settled(benchmark::State& state, const ModelInfo* info, const char* scenario) {
  const Scenario sc = load_scenario(find_scenario(scenario));
  ThreadPool pool(0);
  auto model = make_model(*info, sc, resolve_params(*info, sc, {}), pool);
  int first = 0;
  if (std::string(scenario) == "idle") {
    // Settle untimed over the scenario's own frames; the timed frames follow, the head
    // still as before.
    StageTimes times;
    for (; first < sc.frames; ++first) model->step(frame_input(sc, first), times);
  }
  time_frames(state, *model, sc, first);
}

const bool registered = [] {
  for (const ModelInfo& m : model_registry()) {
    if (m.platform != Platform::Cpu) continue;
    const std::string model(m.name);
    for (const Feature& f : features())
      for (bool on : {true, false})
        benchmark::RegisterBenchmark(("BM_skip/" + model + "/" + f.name + (on ? ":on" : ":off")).c_str(), bm_skip, &m,
                                     &f, on)
            ->UseManualTime()
            ->Iterations(120)
            ->Unit(benchmark::kMillisecond);
    for (const char* sc : {"idle", "shake"})
      benchmark::RegisterBenchmark(("BM_settled/" + model + "/" + sc).c_str(), bm_settled, &m, sc)
          ->UseManualTime()
          ->Iterations(60)
          ->Unit(benchmark::kMillisecond);
  }
  return true;
}();

}  // namespace
}  // namespace hairbench
