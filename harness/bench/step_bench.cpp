// BM_step/MODEL/SCENARIO/strands:N: one model's step() on one built-in scenario at one
// groom size, for every registered model (the registry is read at start-up, so models
// other branches register appear without edits here). Manual time: only step() is timed;
// the reference (the scenario's, han_m1) steps in lockstep outside the timed region so
// that the counters match the report's metrics.
//
// One benchmark iteration is one frame, and a benchmark runs the scenario's frames once
// through (Iterations = frames): the counters then cover the whole head script, the
// same frames as a `hairbench compare` run. Use --benchmark_repetitions for spread.
//
// Counters: ns_per_vertex (mean step time / vertices), deviation_vs_reference (RMS over
// frames, / L-bar), jaggedness (mean over frames).
//
// Test-only knob: HAIRBENCH_BENCH_PLANTED_SLOWDOWN=F (e.g. 0.3) steps a second instance of
// the model, inside the timed region, on a fraction F of the frames: F times the step's
// work, real and deterministic (the same instruction count every run), so that
// tests/perf_gate_e2e.sh can check that ci/perf-gate catches a known slowdown (issue 9).
// Unset or 0: no extra work.
#include "core/parallel.h"
#include "harness/runner.h"
#include "reports/metrics.h"
#include "scenarios/scenario.h"

#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <memory>
#include <string>
#include <vector>

namespace hairbench {
namespace {

// Groom sizes: the scenario's own groom and every 4th strand of it (a procedural groom
// is the same hair at a lower density). Asset grooms with follow hairs keep their own.
constexpr std::size_t kThinning[] = {1, 4};

double planted_slowdown() {
  const char* v = std::getenv("HAIRBENCH_BENCH_PLANTED_SLOWDOWN");
  return v ? std::max(0.0, std::atof(v)) : 0.0;
}

Scenario thinned(const Scenario& sc, std::size_t keep_every) {
  if (keep_every == 1) return sc;
  Scenario out = sc;
  Groom thin;
  thin.region_names = sc.groom.region_names;
  thin.head_radius = sc.groom.head_radius;
  thin.positions.clear();
  thin.strand_offsets = {0};
  for (std::size_t s = 0; s < sc.groom.strand_count(); s += keep_every) {
    const auto b = sc.groom.positions.begin() + sc.groom.strand_begin(s);
    thin.positions.insert(thin.positions.end(), b, b + sc.groom.strand_size(s));
    thin.strand_offsets.push_back(static_cast<std::uint32_t>(thin.positions.size()));
    thin.strand_region.push_back(sc.groom.strand_region[s]);
  }
  out.groom = std::move(thin);
  return out;
}

void bm_step(benchmark::State& state, const ModelInfo* info, const Scenario* sc) {
  ThreadPool pool(0);
  std::unique_ptr<HairModel> model = make_model(*info, *sc, resolve_params(*info, *sc, {}), pool);
  const ModelInfo* ref_info = find_model(sc->reference);
  // The reference itself needs no second lane: its deviation is 0 by definition.
  std::unique_ptr<HairModel> ref = ref_info && ref_info != info ? make_model(*ref_info, *sc, resolve_params(*ref_info, *sc, {}), pool) : nullptr;
  const metrics::RestInfo rest(sc->groom);
  StageTimes times;
  double step_s = 0.0, dev2 = 0.0, jag = 0.0;
  int f = 0;
  bool stable = true;
  const double slowdown = planted_slowdown();
  std::unique_ptr<HairModel> planted = slowdown > 0.0 ? make_model(*info, *sc, resolve_params(*info, *sc, {}), pool) : nullptr;
  double planted_owed = 0.0;
  for (auto _ : state) {
    const FrameInput in = frame_input(*sc, f);
    if (ref) ref->step(in, times);
    times.clear();
    const auto start = std::chrono::steady_clock::now();
    model->step(in, times);
    for (planted_owed += slowdown; planted && planted_owed >= 1.0; planted_owed -= 1.0) planted->step(in, times);
    const auto end = std::chrono::steady_clock::now();
    const double s = std::chrono::duration<double>(end - start).count();
    state.SetIterationTime(s);
    step_s += s;
    const auto p = model->positions();
    if (stable && !metrics::blowup_reason(rest, p, in.head.translation()).empty()) stable = false;
    const double d = ref ? metrics::deviation(p, ref->positions(), rest.mean_strand_length) : 0.0;
    dev2 += d * d;
    jag += metrics::jaggedness(rest, p);
    ++f;
  }
  if (f == 0) return;
  const double n = static_cast<double>(f);
  state.counters["ns_per_vertex"] = step_s * 1e9 / (n * static_cast<double>(sc->groom.vertex_count()));
  state.counters["deviation_vs_reference"] = std::sqrt(dev2 / n);
  state.counters["jaggedness"] = jag / n;
  if (!stable) state.SetLabel("unstable");
}

// Registered before main() runs: every model x every loadable built-in scenario x groom size.
const bool registered = [] {
  static std::vector<std::unique_ptr<Scenario>> scenarios;
  for (const Scenario& sc : load_builtin_scenarios(nullptr)) {
    for (std::size_t keep : kThinning) {
      if (keep > 1 && sc.follow) continue;
      scenarios.push_back(std::make_unique<Scenario>(thinned(sc, keep)));
      const Scenario* s = scenarios.back().get();
      for (const ModelInfo& m : model_registry()) {
        const std::string name = "BM_step/" + std::string(m.name) + "/" + s->name +
                                 "/strands:" + std::to_string(s->groom.strand_count());
        benchmark::RegisterBenchmark(name.c_str(), bm_step, &m, s)
            ->UseManualTime()
            ->Iterations(s->frames)
            ->Unit(benchmark::kMillisecond);
      }
    }
  }
  return true;
}();

}  // namespace
}  // namespace hairbench
