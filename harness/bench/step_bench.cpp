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
// frames, / L-bar), jaggedness (mean over frames), roofline_ratio (mean step time over
// the time to stream the model's state_bytes() once, read and write, on all threads:
// measured in the same process just before the model runs, so the ratio survives a
// noisy machine), state_mib, and min_ms / roofline_ratio_min (the fastest frame: a
// thread descheduled by another process inflates the mean, never the minimum).
//
// Besides the built-in scenarios, the paper's grooms (scenarios/paper, e.g.
// han2012_model1: Table 1 model 1, 19,776 strands) are registered too.
// BM_step_1thread/... is the same benchmark on one thread (thread scaling).
//
// The roofline probes: BM_roofline_stream/bytes:N streams a buffer (read + write) on all
// threads, in GB/s; BM_roofline_fma runs independent fused multiply-add chains on all
// threads at the widest vector width the CPU has, in GFLOP/s.
//
// Test-only knob: HAIRBENCH_BENCH_PLANTED_SLOWDOWN=F (e.g. 0.3) steps a second instance of
// the model, inside the timed region, on a fraction F of the frames: F times the step's
// work, real and deterministic (the same instruction count every run), so that
// tests/perf_gate_e2e.sh can check that ci/perf-gate catches a known slowdown.
// Unset or 0: no extra work.
#include "core/error.h"
#include "core/parallel.h"
#include "harness/plugin_loading.h"
#include "harness/roofline.h"
#include "harness/runner.h"
#include "reports/metrics.h"
#include "scenarios/scenario.h"

#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#if defined(__x86_64__)
#include <immintrin.h>
#endif

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

void bm_step(benchmark::State& state, const ModelInfo* info, const Scenario* sc, int threads) {
  ThreadPool pool(threads);
  std::unique_ptr<HairModel> model = make_model(*info, *sc, resolve_params(*info, *sc, {}), pool);
  const ModelInfo* ref_info = find_model(sc->reference);
  // The reference itself needs no second lane: its deviation is 0 by definition.
  std::unique_ptr<HairModel> ref = ref_info && ref_info != info ? make_model(*ref_info, *sc, resolve_params(*ref_info, *sc, {}), pool) : nullptr;
  const metrics::RestInfo rest(sc->groom);
  StageTimes times;
  double step_s = 0.0, min_s = 1e30, dev2 = 0.0, jag = 0.0;
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
    min_s = std::min(min_s, s);
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
  const std::size_t bytes = model->state_bytes();
  state.counters["state_mib"] = static_cast<double>(bytes) / (1024.0 * 1024.0);
  const double stream = stream_seconds(bytes, pool);
  state.counters["roofline_ratio"] = step_s / n / stream;
  // The fastest frame, and its ratio: on a shared machine a step whose thread was
  // descheduled inflates the mean, never the minimum.
  state.counters["min_ms"] = min_s * 1e3;
  state.counters["roofline_ratio_min"] = min_s / stream;
  if (!stable) state.SetLabel("diverged");
}

void bm_roofline_stream(benchmark::State& state) {
  ThreadPool pool(0);
  const auto bytes = static_cast<std::size_t>(state.range(0));
  double s = 0.0;
  for (auto _ : state) {
    s = stream_seconds(bytes, pool);
    state.SetIterationTime(s);
  }
  state.counters["GB_per_s"] = 2.0 * static_cast<double>(bytes) / s * 1e-9;  // read + write
}

// Independent multiply-add chains, enough of them to cover the FMA latency.
#if defined(__x86_64__)
__attribute__((target("avx512f,fma"))) double fma_avx512(long iterations) {
  __m512 acc[12];
  for (int k = 0; k < 12; ++k) acc[k] = _mm512_set1_ps(static_cast<float>(k));
  const __m512 a = _mm512_set1_ps(0.9999f), b = _mm512_set1_ps(1e-4f);
  for (long i = 0; i < iterations; ++i)
    for (int k = 0; k < 12; ++k) acc[k] = _mm512_fmadd_ps(acc[k], a, b);
  __m512 sum = acc[0];
  for (int k = 1; k < 12; ++k) sum = _mm512_add_ps(sum, acc[k]);
  benchmark::DoNotOptimize(sum);
  return 2.0 * 16 * 12 * static_cast<double>(iterations);
}
#endif
double fma_portable(long iterations) {
  float acc[12][4];
  for (int k = 0; k < 12; ++k)
    for (int l = 0; l < 4; ++l) acc[k][l] = static_cast<float>(k + l);
  for (long i = 0; i < iterations; ++i)
    for (int k = 0; k < 12; ++k)
      for (int l = 0; l < 4; ++l) acc[k][l] = acc[k][l] * 0.9999f + 1e-4f;
  benchmark::DoNotOptimize(acc);
  return 2.0 * 4 * 12 * static_cast<double>(iterations);
}

void bm_roofline_fma(benchmark::State& state) {
  ThreadPool pool(0);
#if defined(__x86_64__)
  const bool wide = __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("fma");
#else
  const bool wide = false;
#endif
  constexpr long kIterations = 2'000'000;
  double flops = 0.0;
  for (auto _ : state) {
    std::vector<double> per(static_cast<std::size_t>(pool.threads()), 0.0);
    double* out = per.data();
    const auto start = std::chrono::steady_clock::now();
    pool.parallel_for(per.size(), [out, wide](std::size_t b, std::size_t e) {
      for (std::size_t t = b; t < e; ++t) {
#if defined(__x86_64__)
        out[t] = wide ? fma_avx512(kIterations) : fma_portable(kIterations);
#else
        out[t] = fma_portable(kIterations);
#endif
      }
    });
    state.SetIterationTime(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
    flops = 0.0;
    for (double f : per) flops += f;
  }
  state.counters["GFLOP_per_s"] = benchmark::Counter(flops * 1e-9, benchmark::Counter::kIsIterationInvariantRate);
  state.SetLabel(wide ? "avx512 fma" : "portable mul+add");
}

// The paper's scenarios (scenarios/paper/*.json), which the built-in list leaves out.
std::vector<Scenario> paper_scenarios() {
  std::vector<Scenario> out;
  const std::filesystem::path dir = std::filesystem::path(HAIRBENCH_SCENARIO_ROOT) / "paper";
  std::error_code ec;
  if (!std::filesystem::is_directory(dir, ec)) return out;
  std::vector<std::filesystem::path> files;
  for (const auto& e : std::filesystem::directory_iterator(dir))
    if (e.path().extension() == ".json") files.push_back(e.path());
  std::sort(files.begin(), files.end());
  for (const auto& f : files) out.push_back(load_scenario(f));
  return out;
}

// Registered before main() runs: every model x every loadable built-in and paper
// scenario x groom size, on all threads and on one.
const bool registered = [] {
  benchmark::RegisterBenchmark("BM_roofline_fma", bm_roofline_fma)->UseManualTime()->Iterations(3)->Unit(benchmark::kMillisecond);
  for (long mib : {1, 4, 16, 64})
    benchmark::RegisterBenchmark("BM_roofline_stream", bm_roofline_stream)
        ->Arg(mib << 20)
        ->ArgName("bytes")
        ->UseManualTime()
        ->Iterations(1)
        ->Unit(benchmark::kMillisecond);
  // The plugins a comparison loads (the default ones beside the binary, HAIRBENCH_PLUGIN_PATH):
  // their models are timed like the built-in ones.
  try {
    load_plugins({});
  } catch (const InputError& e) {
    std::fprintf(stderr, "hairbench_bench: %s\n", e.what());
  }
  static std::vector<std::unique_ptr<Scenario>> scenarios;
  std::vector<Scenario> all = load_builtin_scenarios();
  for (Scenario& sc : paper_scenarios()) all.push_back(std::move(sc));
  for (const Scenario& sc : all) {
    for (std::size_t keep : kThinning) {
      if (keep > 1 && sc.follow) continue;
      scenarios.push_back(std::make_unique<Scenario>(thinned(sc, keep)));
      const Scenario* s = scenarios.back().get();
      for (const ModelInfo& m : model_registry()) {
        std::string tail = "/";
        tail.append(m.name).append("/").append(s->name).append("/strands:").append(
            std::to_string(s->groom.strand_count()));
        for (const auto& [family, threads] : {std::pair{"BM_step", 0}, std::pair{"BM_step_1thread", 1}})
          benchmark::RegisterBenchmark((std::string(family) + tail).c_str(), bm_step, &m, s, threads)
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
