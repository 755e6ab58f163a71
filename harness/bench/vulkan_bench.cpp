// The Vulkan models' device time per frame (timestamp queries), Google Benchmark style:
// BM_HanVk/<method>/<scenario>, manual time = the GPU time of one step. Scenarios: the
// built-in shake and Han & Harada's Table 1 groom sizes with Table 2's iteration counts
// (scenarios/paper). Without a Vulkan device every benchmark is skipped with the reason.
#include "core/parallel.h"
#include "harness/runner.h"
#include "models/han2012/vulkan/model.h"
#include "scenarios/scenario.h"

#include <benchmark/benchmark.h>

#include <chrono>
#include <map>
#include <memory>
#include <string>

namespace hairbench {
namespace {

const char* const kScenarios[] = {"builtin/shake.json", "paper/han2012_model1.json", "paper/han2012_model2.json",
                                  "paper/han2012_model3.json"};

const Scenario& scenario(int index) {
  static std::map<int, Scenario> cache;
  auto it = cache.find(index);
  if (it == cache.end())
    it = cache.emplace(index, load_scenario(std::string(HAIRBENCH_SCENARIO_ROOT) + "/" + kScenarios[index])).first;
  return it->second;
}

// Steps the model frame after frame of the scenario's head script (wrapping around), and
// reports the device time of each step. The first frame (pipeline compilation on some
// drivers) is stepped before timing starts. Counters: wall_ms, the mean wall time of
// step() (upload, submit, wait); readback_ms, the mean time of positions() after it (the
// copy back that compare and the follow hairs pay every frame, and which the device time
// does not see).
void BM_HanVk(benchmark::State& state) {
  const std::string why = han_vk::unavailable(ModelContext{});
  if (!why.empty()) {
    state.SkipWithError(why.c_str());
    return;
  }
  const int method = static_cast<int>(state.range(0));
  const Scenario& sc = scenario(static_cast<int>(state.range(1)));
  const std::string name = "han_m" + std::to_string(method) + "_vk";
  const ModelInfo* info = find_model(name);
  ThreadPool pool(1);
  std::unique_ptr<HairModel> model = info->make(ModelContext{&pool});
  model->reset(sc.groom, resolve_params(*info, sc, {}));
  StageTimes times;
  int frame = 0;
  auto input = [&] {
    FrameInput in;
    const int f = frame++ % sc.frames;
    in.frame = f;
    in.dt = sc.dt;
    in.t = (f + 1) * sc.dt;
    in.head_prev = sc.head.at(f * sc.dt);
    in.head = sc.head.at(in.t);
    in.gravity = sc.gravity;
    in.wind = sc.wind.at(in.t);
    in.colliders = sc.colliders;
    return in;
  };
  model->step(input(), times);
  using clock = std::chrono::steady_clock;
  double wall_s = 0.0, readback_s = 0.0;
  for (auto _ : state) {
    const FrameInput in = input();
    const auto t0 = clock::now();
    model->step(in, times);
    const auto t1 = clock::now();
    benchmark::DoNotOptimize(model->positions().data());
    const auto t2 = clock::now();
    wall_s += std::chrono::duration<double>(t1 - t0).count();
    readback_s += std::chrono::duration<double>(t2 - t1).count();
    state.SetIterationTime(model->last_gpu_ms().value_or(0.0) * 1e-3);
  }
  state.SetLabel(sc.name + " " + std::to_string(sc.groom.strand_count()) + " strands " +
                 std::to_string(sc.groom.vertex_count()) + " vertices on " + model->backend().device);
  state.counters["vertices"] = static_cast<double>(sc.groom.vertex_count());
  const double frames = static_cast<double>(state.iterations());
  state.counters["wall_ms"] = wall_s * 1e3 / frames;
  state.counters["readback_ms"] = readback_s * 1e3 / frames;
}

// Methods 1-3 x scenarios; few iterations: on a CPU device (lavapipe) one frame of the
// Table 1 grooms takes seconds.
BENCHMARK(BM_HanVk)
    ->ArgsProduct({{1, 2, 3}, {0, 1, 2, 3}})
    ->ArgNames({"method", "scenario"})
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond)
    ->Iterations(5);

}  // namespace
}  // namespace hairbench
