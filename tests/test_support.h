// Shared helpers for the model tests: load a built-in scenario, run it, read metrics.
#pragma once

#include <cstdio>

#include "core/groom_fit.h"
#include "core/parallel.h"
#include "harness/runner.h"
#include "scenarios/scenario.h"
#include "scenarios/tfx/tfx.h"

#include <algorithm>
#include <stdexcept>
#include <string>
#include <vector>

namespace hairbench::test {

// A built-in scenario with every `keep_every`-th strand of its groom: the properties
// under test are per strand, and a thinner groom keeps the suite fast.
inline Scenario builtin(const std::string& name, std::size_t keep_every = 8) {
  Scenario sc = load_scenario(find_scenario(name));
  sc.groom = every_nth_strand(sc.groom, keep_every);
  return sc;
}

// The built-in scenarios on procedural grooms: every one but the TressFX scenarios, which
// are large and rebuild follow hairs, and have their own thinned runs in
// tressfx_scenario_test (the Halén models are not checked on them there).
inline std::vector<std::filesystem::path> procedural_builtin_scenarios() {
  std::vector<std::filesystem::path> out;
  for (const auto& file : builtin_scenarios())
    if (file.stem().string().rfind("tressfx_", 0) != 0) out.push_back(file);
  return out;
}

// Han & Harada's own setting for the claims of §6: Table 2's counts for model 1 (3 local,
// 2 length iterations) and TressFX's sample stiffness (S_G 0.2 on the first 30% of the
// strand, S_L 0.5), kept stable under metric gravity by substepping.
inline std::vector<ParamOverride> paper_setting() {
  return {{"*", "local_iterations", 3},  {"*", "length_iterations", 2}, {"*", "global_stiffness", 0.2},
          {"*", "global_range", 0.3},    {"*", "global_ramp", 0},       {"*", "local_stiffness", 0.5},
          {"*", "damping", 0.1}};
}

inline std::vector<RunRecord> run(const Scenario& sc, std::vector<std::string> models,
                                  std::vector<ParamOverride> overrides = {}, int threads = 2, int frames = 0) {
  ThreadPool pool(threads);
  RunOptions opt;
  opt.models = std::move(models);
  opt.overrides = std::move(overrides);
  opt.frames = frames;
  return run_scenario(sc, opt, pool);
}

// Guide `s` of an imported scenario's asset as the file authors it, before import hygiene
// (repair_groom), written over strand `index` of `g` (a groom in the scenario's frame): read
// from the file, in metres, moved by the import's translation (the root, which no repair
// moves).
inline void restore_authored_guide(const Scenario& sc, Groom& g, std::uint32_t s, std::uint32_t index) {
  const Groom file = tfx::read_tfx_strands(sc.import->file);
  const float scale = metres_per_unit(sc.import->unit);
  const std::uint32_t fb = file.strand_begin(s), b = g.strand_begin(index);
  if (file.strand_size(s) != g.strand_size(index)) throw std::runtime_error("restore_authored_guide: sizes differ");
  const Vec3f shift = g.positions[b].head<3>() - scale * file.positions[fb].head<3>();
  for (std::uint32_t i = 0; i < file.strand_size(s); ++i)
    g.positions[b + i].head<3>() = scale * file.positions[fb + i].head<3>() + shift;
}

inline const RunRecord& find(const std::vector<RunRecord>& runs, const std::string& model) {
  for (const RunRecord& r : runs)
    if (r.model == model) return r;
  throw std::runtime_error("no run for " + model);
}

// A value for RecordProperty in 3 significant digits (std::to_string's six decimals show
// 1e-7 as 0).
inline std::string sci(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3g", v);
  return buf;
}
inline double max_of(const std::vector<double>& v) { return *std::max_element(v.begin(), v.end()); }
inline double mean_of(const std::vector<double>& v) {
  double s = 0.0;
  for (double x : v) s += x;
  return s / static_cast<double>(v.size());
}
inline double rms_of(const std::vector<double>& v) {
  double s = 0.0;
  for (double x : v) s += x * x;
  return std::sqrt(s / static_cast<double>(v.size()));
}

inline const std::vector<std::string> kHan = {"han_m1", "han_m2", "han_m3"};
// Every CPU model (the fast ones; their _ref twins give the same bits).
inline const std::vector<std::string> kCpuModels = {"han_m1",        "han_m2",       "han_m3",     "halen_spring",
                                                    "halen_cascade", "halen_forest", "plante_wisp"};

}  // namespace hairbench::test
