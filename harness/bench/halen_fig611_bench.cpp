// Halén & Wester 2007 Figure 6.1.1: CPU time per frame of the spring ("Static"), forest
// and cascade models for 9, 25, 49 and 121 strands of 4 and 8 nodes. One thread, as the
// thesis's Pentium 4; the `shake` scenario's head motion, repeated every 2 s; each
// model's default parameters (the counter `passes` is its substeps per frame).
//
//   build/release/hairbench_bench --benchmark_filter=HalenFig611
#include "core/parallel.h"
#include "harness/runner.h"
#include "models/registry.h"
#include "scenarios/groom_gen.h"
#include "scenarios/scenario.h"

#include <benchmark/benchmark.h>

#include <cmath>

namespace hairbench {
namespace {

void run_fig611(benchmark::State& state, const char* model_name) {
  Scenario sc = load_scenario(find_scenario("shake"));
  GroomSpec spec;
  spec.strands = static_cast<int>(state.range(0));
  spec.vertices_per_strand = static_cast<int>(state.range(1));
  sc.groom = generate_groom(spec, sc.head_radius, "fig611").groom;
  const ModelInfo* info = find_model(model_name);
  ThreadPool pool(1);
  auto model = info->make(ModelContext{&pool});
  const ParamSet params = resolve_params(*info, sc, {});
  model->reset(sc.groom, params);
  StageTimes times;
  constexpr double kPeriod = 2.0;  // the shake's oscillation; the head is back at rest then
  int frame = 0;
  for (auto _ : state) {
    const double t0 = std::fmod(frame * sc.dt, kPeriod);
    FrameInput in;
    in.frame = frame;
    in.dt = sc.dt;
    in.t = t0 + sc.dt;
    in.head_prev = sc.head.at(t0);
    in.head = sc.head.at(in.t);
    in.gravity = sc.gravity;
    in.wind = sc.wind.at(in.t);
    in.colliders = sc.colliders;
    times.clear();
    model->step(in, times);
    benchmark::DoNotOptimize(model->positions().data());
    ++frame;
  }
  state.counters["passes"] = params.get("substeps");
  state.counters["strands"] = static_cast<double>(spec.strands);
  state.counters["nodes"] = static_cast<double>(spec.vertices_per_strand);
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
