// BM_metric/METRIC/SCENARIO: one per-frame metric of reports/metrics.h on one frame's
// positions, on one thread (as `compare` runs it: one task per model and metric). In
// `compare` the metrics run every frame for every model, and cost about as much as the
// fast models' steps.
//
// The positions are han_m3's after a quarter of the scenario's frames: a moving, bent
// groom, the same every run. Scenarios: `shake` (built in) and Table 1's model 1 groom
// (scenarios/paper/han2012_model1.json: 19,776 strands, 221,078 vertices, of several sizes).
#include "core/parallel.h"
#include "harness/runner.h"
#include "reports/metrics.h"
#include "scenarios/scenario.h"

#include <benchmark/benchmark.h>

#include <chrono>
#include <filesystem>
#include <memory>
#include <string>
#include <utility>
#include <vector>

namespace hairbench {
namespace {

struct MetricInput {
  std::string key;
  Scenario sc;
  std::unique_ptr<metrics::RestInfo> rest;
  std::vector<Vec4f> p, ref;  // han_m3's positions; the rest groom's under the same head
  std::vector<Vec4f> spheres;
  FrameInput in;
};

const MetricInput& input(const std::string& scenario) {
  static std::vector<std::unique_ptr<MetricInput>> loaded;
  for (const auto& m : loaded)
    if (m->key == scenario) return *m;
  auto m = std::make_unique<MetricInput>();
  m->key = scenario;
  const std::filesystem::path paper = std::filesystem::path(HAIRBENCH_SCENARIO_ROOT) / "paper" / (scenario + ".json");
  m->sc = load_scenario(std::filesystem::exists(paper) ? paper : find_scenario(scenario));
  m->rest = std::make_unique<metrics::RestInfo>(m->sc.groom);
  ThreadPool pool(0);
  const ModelInfo* info = find_model("han_m3");
  std::unique_ptr<HairModel> model = make_model(*info, m->sc, resolve_params(*info, m->sc, {}), pool);
  StageTimes times;
  for (int f = 0; f <= m->sc.frames / 4; ++f) {
    m->in = frame_input(m->sc, f);
    model->step(m->in, times);
  }
  const auto p = model->positions();
  m->p.assign(p.begin(), p.end());
  m->ref = m->sc.groom.positions;
  for (Vec4f& v : m->ref) v.head<3>() = m->in.head * Vec3f(v.head<3>());
  for (const Sphere& c : m->sc.colliders) {
    const Vec3f centre = collider_center(c, m->in.head);
    m->spheres.emplace_back(centre.x(), centre.y(), centre.z(), c.radius);
  }
  loaded.push_back(std::move(m));
  return *loaded.back();
}

enum Metric { kDeviation, kJaggedness, kLengthError, kRestShapeError, kPenetration, kBlowup };

void bm_metric(benchmark::State& state, Metric metric, const std::string& scenario) {
  const MetricInput& m = input(scenario);
  const metrics::RestInfo& rest = *m.rest;
  const auto start = std::chrono::steady_clock::now();
  for (auto _ : state) {
    switch (metric) {
      case kDeviation: benchmark::DoNotOptimize(metrics::deviation(m.p, m.ref, rest.mean_strand_length)); break;
      case kJaggedness: benchmark::DoNotOptimize(metrics::jaggedness(rest, m.p)); break;
      case kLengthError: benchmark::DoNotOptimize(metrics::length_error(rest, m.p)); break;
      case kRestShapeError: benchmark::DoNotOptimize(metrics::rest_shape_error(rest, m.p, m.in.head)); break;
      case kPenetration: benchmark::DoNotOptimize(metrics::penetration(m.p, m.spheres)); break;
      case kBlowup: benchmark::DoNotOptimize(metrics::blowup_reason(rest, m.p, m.in.head.translation())); break;
    }
  }
  const double ns = std::chrono::duration<double, std::nano>(std::chrono::steady_clock::now() - start).count();
  state.counters["ns_per_vertex"] = ns / (static_cast<double>(state.iterations()) * static_cast<double>(m.p.size()));
}

const bool registered = [] {
  const std::pair<Metric, const char*> all[] = {
      {kDeviation, "deviation"},           {kJaggedness, "jaggedness"},   {kLengthError, "length_error"},
      {kRestShapeError, "rest_shape_error"}, {kPenetration, "penetration"}, {kBlowup, "blowup_reason"}};
  for (const char* scenario : {"shake", "han2012_model1"})
    for (const auto& [metric, name] : all)
      benchmark::RegisterBenchmark((std::string("BM_metric/") + name + "/" + scenario).c_str(), bm_metric, metric,
                                   std::string(scenario))
          ->Unit(benchmark::kMicrosecond);
  return true;
}();

}  // namespace
}  // namespace hairbench
