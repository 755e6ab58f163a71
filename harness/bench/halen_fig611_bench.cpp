// Halén & Wester 2007 Figure 6.1.1: CPU time per frame of the spring ("Static"), forest
// and cascade models for 9, 25, 49 and 121 strands of 4 and 8 nodes. One thread, as the
// thesis's Pentium 4; the `shake` scenario's head motion, repeated every 2 s; each
// model's default parameters (the counter `passes` is its substeps per frame).
//
//   build/release/hairbench_bench --benchmark_filter=HalenFig611
#include "core/parallel.h"
#include "harness/paper_setups.h"
#include "harness/runner.h"
#include "models/registry.h"

#include <benchmark/benchmark.h>

namespace hairbench {
namespace {

void run_fig611(benchmark::State& state, const char* model_name) {
  const Scenario sc = fig611_scenario(static_cast<int>(state.range(0)), static_cast<int>(state.range(1)));
  const ModelInfo* info = find_model(model_name);
  ThreadPool pool(1);
  auto model = info->make(ModelContext{&pool});
  const ParamSet params = resolve_params(*info, sc, {});
  model->reset(sc.groom, params);
  StageTimes times;
  int frame = 0;
  for (auto _ : state) {
    const FrameInput in = fig611_frame_input(sc, frame);
    times.clear();
    model->step(in, times);
    benchmark::DoNotOptimize(model->positions().data());
    ++frame;
  }
  state.counters["passes"] = params.get("substeps");
  state.counters["strands"] = static_cast<double>(state.range(0));
  state.counters["nodes"] = static_cast<double>(state.range(1));
}

void fig611_args(benchmark::internal::Benchmark* b) {
  for (int nodes : {4, 8})
    for (int strands : {9, 25, 49, 121}) b->Args({strands, nodes});
  b->ArgNames({"strands", "nodes"})->Unit(benchmark::kMicrosecond);
}

BENCHMARK_CAPTURE(run_fig611, spring, "halen_spring")->Name("HalenFig611/spring")->Apply(fig611_args);
BENCHMARK_CAPTURE(run_fig611, forest, "halen_forest")->Name("HalenFig611/forest")->Apply(fig611_args);
BENCHMARK_CAPTURE(run_fig611, cascade, "halen_cascade")->Name("HalenFig611/cascade")->Apply(fig611_args);

}  // namespace
}  // namespace hairbench
