// BM_wisp_grid and BM_wisp_narrow_phase/{ref,fast}: the parts of plante_wisp's wisp-wisp
// detection (Plante et al. 2001 §4.1) on one frozen state, one thread, so that a change
// to one of them is measured without the rest of the step and its noise.
// The state: plante_wisp stepped through the first kFrames frames of `shake` (the head
// turning, the hair spread and in contact). BM_wisp_grid rebuilds the broad phase's
// grid (grid_build); BM_wisp_narrow_phase tests every pair of it, `ref` by
// grid_contacts_ref (plante_wisp_ref's), `fast` by the ISA variant's ContactsFn
// (plante_wisp's). Both find the same contacts in the same order; the counter
// `contacts` says how many.
#include "core/parallel.h"
#include "harness/runner.h"
#include "kernels/simd/isa.h"
#include "kernels/plante2001/wisp_grid.h"
#include "kernels/plante2001/fused/wisp_soa.h"
#include "models/plante2001/fused/wisp_fused.h"
#include "models/registry.h"
#include "scenarios/scenario.h"

#include <benchmark/benchmark.h>

#include <limits>
#include <memory>
#include <stdexcept>
#include <vector>

namespace hairbench {
namespace {

constexpr int kFrames = 60;

// The wisps of plante_wisp after kFrames frames of shake, made once.
const kernels::WispSystem& shaken_wisps() {
  static const kernels::WispSystem wisps = [] {
    const Scenario sc = load_scenario(find_scenario("shake"));
    const ModelInfo* info = find_model("plante_wisp");
    if (!info) throw std::runtime_error("BM_wisp_*: plante_wisp is not registered");
    ThreadPool pool(1);
    std::unique_ptr<HairModel> model = make_model(*info, sc, resolve_params(*info, sc, {}), pool);
    StageTimes times;
    for (int f = 0; f < kFrames && f < sc.frames; ++f) model->step(frame_input(sc, f), times);
    return dynamic_cast<const plante::WispModel&>(*model).wisps();
  }();
  return wisps;
}

void bm_wisp_grid(benchmark::State& state) {
  const kernels::WispSystem& s = shaken_wisps();
  kernels::SegmentGrid g;
  for (auto _ : state) kernels::grid_build(g, s);
  state.counters["segments"] = static_cast<double>(g.size());
  state.counters["cell_entries"] = static_cast<double>(g.cell_items.size());
}

void bm_wisp_narrow_phase(benchmark::State& state, bool fast) {
  const kernels::WispSystem& s = shaken_wisps();
  kernels::SegmentGrid g;
  kernels::grid_build(g, s);
  const kernels::wisp_soa::Kernels k = kernels::wisp_soa::kernels();
  std::vector<std::uint32_t> mailbox;
  std::vector<kernels::WispContact> out;
  for (auto _ : state) {
    out.clear();
    if (fast) {
      k.contacts(g, s, 0, g.size(), out);
    } else {
      mailbox.assign(g.size(), std::numeric_limits<std::uint32_t>::max());
      kernels::grid_contacts_ref(g, s, 0, g.size(), mailbox, out);
    }
    benchmark::DoNotOptimize(out.data());
  }
  state.counters["contacts"] = static_cast<double>(out.size());
  if (fast) state.SetLabel(kernels::simd::isa_name(kernels::simd::runtime_isa()));
}

BENCHMARK(bm_wisp_grid)->Name("BM_wisp_grid")->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(bm_wisp_narrow_phase, ref, false)->Name("BM_wisp_narrow_phase/ref")->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(bm_wisp_narrow_phase, fast, true)->Name("BM_wisp_narrow_phase/fast")->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace hairbench
