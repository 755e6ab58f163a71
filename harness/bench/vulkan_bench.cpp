// The Vulkan models' device time per frame (timestamp queries), Google Benchmark style:
// BM_HanVk/<method>/<scenario>, manual time = the GPU time of one step. Scenarios: the
// built-in shake, Han & Harada's Table 1 groom sizes with Table 2's iteration counts
// (scenarios/paper), and two TressFX grooms whose follow hairs are built on the device.
// Without a Vulkan device every benchmark is skipped with the reason.
#include "core/parallel.h"
#include "harness/gpu_clock.h"
#include "harness/runner.h"
#include "models/han2012/vulkan/han_vulkan.h"
#include "reports/report.h"
#include "scenarios/scenario.h"

#include <benchmark/benchmark.h>

#include <chrono>
#include <map>
#include <memory>
#include <string>
#include <vector>

namespace hairbench {
namespace {

const char* const kScenarios[] = {"builtin/shake.json",
                                  "paper/han2012_model1.json",
                                  "paper/han2012_model2.json",
                                  "paper/han2012_model3.json",
                                  "builtin/tressfx_ponytail_shake.json",
                                  "builtin/tressfx_testhair1.json"};

const Scenario& scenario(int index) {
  static std::map<int, Scenario> cache;
  auto it = cache.find(index);
  if (it == cache.end())
    it = cache.emplace(index, load_scenario(std::string(HAIRBENCH_SCENARIO_ROOT) + "/" + kScenarios[index])).first;
  return it->second;
}

// Steps the model frame after frame of the scenario's head script (wrapping around), and
// reports the device time of each step, after the warm-up compare also takes
// (HairModel::warm_up; the same steps as back_to_back_gpu_ms, harness/runner.h), so that
// both measure the same thing. Counters: wall_ms, the mean wall time of step() (upload,
// submit, wait); readback_ms, the mean time of positions() after it (the copy back that
// compare pays every frame for its metrics, and which the device time does not see);
// gpu_median_ms, the median device time (compare's timing.gpu_ms.median); follow_gpu_ms,
// the mean device time of the follow hairs dispatch (TressFX grooms); clock_mhz, the GPU
// clock after the last step, where nvidia-smi can read it.
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
  std::unique_ptr<HairModel> model = make_model(*info, sc, resolve_params(*info, sc, {}), pool);
  const auto& vk = dynamic_cast<const han_vk::HanVkModel&>(*model);
  StageTimes times;
  int frame = 0;
  model->warm_up(frame_input(sc, 0), kGpuWarmUpSeconds);
  using clock = std::chrono::steady_clock;
  double wall_s = 0.0, readback_s = 0.0, follow_ms = 0.0;
  std::vector<double> gpu_ms;
  for (auto _ : state) {
    const FrameInput in = frame_input(sc, frame++ % sc.frames);
    const auto t0 = clock::now();
    model->step(in, times);
    const auto t1 = clock::now();
    benchmark::DoNotOptimize(model->positions().data());
    const auto t2 = clock::now();
    wall_s += std::chrono::duration<double>(t1 - t0).count();
    readback_s += std::chrono::duration<double>(t2 - t1).count();
    gpu_ms.push_back(model->last_gpu_ms().value_or(0.0));
    follow_ms += vk.last_follow_gpu_ms().value_or(0.0);
    state.SetIterationTime(gpu_ms.back() * 1e-3);
  }
  const GpuClock gpu_clock = read_gpu_clock(model->backend().device);
  state.SetLabel(sc.name + " " + std::to_string(sc.groom.strand_count()) + " strands " +
                 std::to_string(sc.groom.vertex_count()) + " vertices on " + model->backend().device);
  state.counters["vertices"] = static_cast<double>(sc.groom.vertex_count());
  const double frames = static_cast<double>(state.iterations());
  state.counters["wall_ms"] = wall_s * 1e3 / frames;
  state.counters["readback_ms"] = readback_s * 1e3 / frames;
  state.counters["gpu_median_ms"] = median(gpu_ms);
  if (sc.follow) state.counters["follow_gpu_ms"] = follow_ms / frames;
  if (gpu_clock.mhz) state.counters["clock_mhz"] = *gpu_clock.mhz;
}

// Methods 1-3 x scenarios, each for 0.1 s of device time: on a GPU thousands of frames,
// the whole head script several times over; on a CPU device (lavapipe), where one frame
// of the Table 1 grooms takes seconds, a single frame.
BENCHMARK(BM_HanVk)
    ->ArgsProduct({{1, 2, 3}, {0, 1, 2, 3, 4, 5}})
    ->ArgNames({"method", "scenario"})
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond)
    ->MinTime(0.1);

}  // namespace
}  // namespace hairbench
