// hairbench command line: one CLI11 application with a subcommand per task. Every bad
// argument is one line on stderr, "hairbench: arguments: WHAT: what is wrong", and exit
// code 2, like every other bad input.
#include "core/error.h"
#include "core/parallel.h"
#include "git_sha.h"
#include "harness/at_rest_cache.h"
#include "harness/charts.h"
#include "harness/gpu_clock.h"
#include "harness/merge.h"
#include "harness/plugin_loading.h"
#include "harness/precision.h"
#include "harness/progress.h"
#include "harness/reproduce.h"
#include "harness/runner.h"
#include "harness/shard.h"
#include "harness/stress.h"
#include "models/registry.h"
#include "reports/report.h"
#include "scenarios/groom_scenario.h"
#include "scenarios/scenario.h"
#ifdef HAIRBENCH_HAS_VULKAN
#include "kernels/vulkan/runtime.h"
#endif

#include <CLI/CLI.hpp>

#include <algorithm>
#include <charconv>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <regex>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include <unistd.h>

namespace hairbench {
namespace {

// Help texts: lines of at most 62 characters, so that the subcommand list of
// `hairbench --help`, which indents them by 30, stays within 92 columns.
constexpr const char* kDescription =
    "hairbench runs hair-simulation models side by side on\n"
    "scenarios and reports their speed and accuracy.\n"
    "`hairbench SUBCOMMAND --help` describes each subcommand.";

constexpr const char* kExitCodes =
    "exit codes: 0 done (unstable models are results, not errors),\n"
    "1 internal error or chart script failure, 2 bad arguments or files";

constexpr const char* kListHelp = "list prints the models, the built-in scenarios or the\nVulkan devices.";

constexpr const char* kCompareHelp =
    "compare runs every selected model in lockstep on each\n"
    "scenario (default: every built-in scenario) and writes\n"
    "DIR/report.json, then its charts, DIR/report_summary.md and\n"
    "DIR/report.html.";

constexpr const char* kSweepHelp =
    "sweep runs every selected model that has the --knob\n"
    "parameter at each of its values, and writes one report whose\n"
    "runs carry the value as \"knob\"; a note names the selected\n"
    "models that lack the parameter, which are left out.";

constexpr const char* kStressHelp =
    "stress escalates one axis at a time (time step, head angular\n"
    "velocity and acceleration, teleports, strand vertices and\n"
    "length, every stiffness, iteration count and damping) from\n"
    "the stable base scenario until each CPU model's verdict is\n"
    "no longer ok (stretched, deformed, unstable or diverged), runs\n"
    "degenerate grooms, prints the table, writes DIR/stress.json\n"
    "and draws its heatmap DIR/stress_heatmap.png.";

constexpr const char* kMergeHelp =
    "merge writes one report, OUT_DIR/report.json (or stress.json,\n"
    "or reproduce.json) with its charts, from the reports of the\n"
    "shards of one command (--shard I/N); it refuses shards of\n"
    "different builds, scenarios or plans, reference runs that\n"
    "differ, duplicate runs and missing ones.";

constexpr const char* kReproduceHelp =
    "reproduce runs the papers' claims and tables\n"
    "(reports/published/) at the papers' settings and writes\n"
    "DIR/reproduce.json, .md, .html and the claims' charts: setup\n"
    "rows (matches / mismatch), claims (holds / differs / not\n"
    "testable, each with the paper's sentence) and measurements\n"
    "(hardware-dependent numbers beside the paper's, no verdict).";

constexpr const char* kPrecisionHelp =
    "precision runs each selected model on one scenario along its\n"
    "cost knobs (substeps, iterations, node counts, integration\n"
    "rates) and draws run time against error, log-log, one line\n"
    "per model: error against the exact answer on a truth\n"
    "scenario, else against the model's own converged run\n"
    "(8x every cost knob); writes DIR/precision.json and\n"
    "DIR/precision.png (docs/precision.md).";

constexpr const char* kScenarioHelp =
    "scenario new writes the scenario that compare --groom runs:\n"
    "a TressFX groom under a built-in motion, with the unit, the\n"
    "pivot, the head sphere and its collider fitted, as a file to\n"
    "edit.";

struct KnobSpec {
  std::string name;
  std::vector<double> values;
};

struct CompareArgs {
  // As given on the command line.
  std::vector<std::string> scenarios;
  std::string models = ".*";
  bool models_given = false;
  std::vector<std::string> sets;   // --set, in order
  std::vector<std::string> presets;  // --preset, in order (before every --set)
  std::vector<std::string> knobs;  // --knob (sweep only, which needs exactly one)
  int threads = 0;
  std::string out;
  bool charts = true;
  std::string shard_arg;  // --shard I/N
  bool plan_only = false;  // --plan
  std::string costs;       // --costs REPORT.json
  // compare --groom: a TressFX groom under built-in motions instead of scenarios.
  std::string groom;
  std::vector<std::string> motions;
  std::string unit = "auto";
  std::optional<double> fit_above;
  // Resolved by prepare_compare.
  ShardSpec shard;
  CostModel cost_model;
  RunOptions run;
  std::vector<std::string> skipped;  // models left out, and why (printed once the inputs are good)
  std::optional<KnobSpec> knob;
  PluginLoad plugins;  // what load_plugins loaded and left out, for the report
};

// --models REGEX, compiled; a bad expression is an input error naming the option.
std::regex models_regex(const std::string& pattern) {
  try {
    return std::regex(pattern);
  } catch (const std::regex_error& e) {
    throw InputError("arguments", "--models", std::string("bad regular expression: ") + e.what());
  }
}

// Each --set MODEL.NAME=VALUE parsed, checked against the registry and appended.
void add_sets(const std::vector<std::string>& sets, std::vector<ParamOverride>& out) {
  for (const std::string& set : sets) {
    ParamOverride o = parse_param_override(set);
    check_param_override(o);
    out.push_back(o);
  }
}

// Why `m` does not run in a comparison on `device`, or "" when it does: it needs a device
// that is missing; and, unless --models names it (`named`), it is a GPU model on a CPU
// Vulkan device (lavapipe: seconds per frame) or a reference implementation (its fast
// model's bits, slower).
std::string why_not_run(const ModelInfo& m, const std::string& device, bool named) {
  std::string why = m.unavailable ? m.unavailable(ModelContext{nullptr, device}) : "";
#ifdef HAIRBENCH_HAS_VULKAN
  if (why.empty() && m.platform == Platform::Vulkan && !named && vk::Context::get(device)->device().type == "CPU")
    why = "the Vulkan device is a CPU (" + vk::Context::get(device)->device().name + "); name it in --models to run it";
#endif
  if (why.empty() && !named && !m.reference_of.empty())
    why = std::string(m.reference_tolerance == 0.0 ? "bit-identical" : "rounding-level") +
          " reference implementation of " + std::string(m.reference_of) + "; name it in --models to run it";
  return why;
}

// --knob NAME=V1,V2,...: a parameter name and distinct finite numbers.
KnobSpec parse_knob(const std::string& arg) {
  const auto eq = arg.find('=');
  if (eq == std::string::npos || eq == 0 || eq + 1 == arg.size())
    throw InputError("--knob", arg, "expected NAME=V1,V2,... (e.g. local_iterations=1,2,4,8)");
  KnobSpec k{arg.substr(0, eq), {}};
  std::size_t pos = eq + 1;
  while (pos <= arg.size()) {
    const std::size_t comma = std::min(arg.find(',', pos), arg.size());
    const std::string v = arg.substr(pos, comma - pos);
    const double x = parse_finite(v, "--knob", arg);
    for (double seen : k.values)
      if (seen == x) throw InputError("--knob", arg, "value '" + v + "' is given twice");
    k.values.push_back(x);
    pos = comma + 1;
  }
  return k;
}

// A sweep runs the selected models that have the knob's parameter (a note names the
// others), and every value must be valid for each of them.
void select_knob_models(CompareArgs& a) {
  const KnobSpec& k = *a.knob;
  std::vector<std::string> kept, left_out;
  for (const std::string& name : a.run.models) {
    const ModelInfo& m = *find_model(name);
    ParamSet probe(m.params, 0);
    if (!probe.has(k.name)) {
      left_out.push_back(name);
      continue;
    }
    for (double v : k.values) probe.set(k.name, v, {"--knob", name + "."});
    kept.push_back(name);
  }
  if (kept.empty())
    throw InputError("--knob", k.name, "no model selected by --models '" + a.models + "' has this parameter");
  for (const std::string& name : left_out)
    std::fprintf(stderr, "hairbench: sweep: %s has no parameter '%s': left out\n", name.c_str(), k.name.c_str());
  a.run.models = std::move(kept);
}

// The checks and lookups behind compare's and sweep's options, once CLI11 has read them.
void prepare_compare(CompareArgs& a, bool sweep) {
  for (const std::string& name : a.presets) {
    const Preset* p = find_preset(name);
    if (!p) throw InputError("--preset", name, "unknown preset (see `hairbench list presets`)");
    for (const PresetValue& v : p->values)
      a.run.overrides.push_back({std::string(v.model), std::string(v.param), v.value});
  }
  add_sets(a.sets, a.run.overrides);
  if (sweep) {
    if (a.knobs.size() != 1) throw InputError("arguments", "--knob", "give one --knob per sweep");
    a.knob = parse_knob(a.knobs.front());
  }
  const std::regex re = models_regex(a.models);
  // Models that need a missing device (no Vulkan): left out with a note by default, an
  // error when --models asked for them.
  for (const ModelInfo& m : model_registry()) {
    if (!std::regex_match(std::string(m.name), re)) continue;
    const std::string why = why_not_run(m, a.run.device, a.models_given);
    if (why.empty()) a.run.models.emplace_back(m.name);
    else if (a.models_given) throw InputError("arguments", "--models", std::string(m.name) + " cannot run: " + why);
    else a.skipped.push_back(std::string(m.name) + ": " + why);
  }
  if (a.run.models.empty()) throw InputError("arguments", "--models", "'" + a.models + "' matches no model");
  if (a.run.reference == kConvergedReference) {
    a.run.reference = kDefaultReference;
    const ModelInfo* ref = find_model(a.run.reference);
    if (!ref || ref->converged.empty())
      throw InputError("arguments", "--reference", a.run.reference + " has no converged setting");
    a.run.reference_overrides = converged_overrides(*ref);
  } else if (!a.run.reference.empty() && !find_model(a.run.reference)) {
    throw InputError("arguments", "--reference", "unknown model '" + a.run.reference + "' (or 'converged')");
  }
  if (a.knob) select_knob_models(a);
  if (!a.shard_arg.empty()) a.shard = parse_shard(a.shard_arg);
  if (!a.costs.empty()) a.cost_model = CostModel::from_report(a.costs);
}

void print_run(const nlohmann::json& r) {
  std::string label = r["model"].get<std::string>();
  if (r.contains("knob")) {
    char value[32];
    std::snprintf(value, sizeof value, "=%g", r["knob"]["value"].get<double>());
    label += " " + r["knob"]["name"].get<std::string>() + value;
  }
  auto f = [](const nlohmann::json& v, const char* fmt) {
    char buf[32];
    if (v.is_null()) return std::string("-");
    std::snprintf(buf, sizeof buf, fmt, v.get<double>());
    return std::string(buf);
  };
  std::printf("  %-14s %-9s %9s ms %8s ns/v ", label.c_str(), r["status"].get<std::string>().c_str(),
              f(r["timing"]["step_ms"]["median"], "%.3f").c_str(), f(r["timing"]["ns_per_vertex"], "%.1f").c_str());
  // Each metric the table abbreviates, by its headline summary (reports/frame_metrics.h).
  for (const metrics::FrameMetric& fm : metrics::frame_metrics()) {
    if (fm.cli.empty()) continue;
    const metrics::Summary& s = fm.summaries.front();
    const nlohmann::json& v = r["metrics"][std::string(fm.name)];
    std::printf(" %s %-9s", std::string(fm.cli).c_str(),
                f(s.key.empty() ? v : v[std::string(s.key)], std::string(s.format).c_str()).c_str());
  }
  std::printf("\n");
  // GPU runs: the device time back to back and in lockstep (docs/vulkan.md, Timing).
  const auto& t = r["timing"];
  if (t.contains("gpu_ms"))
    std::printf("  %-14s gpu %s ms back to back at %s MHz, %s ms in lockstep\n", "",
                f(t["gpu_ms"]["median"], "%.4f").c_str(), f(t["gpu_clock_mhz"], "%.0f").c_str(),
                t.contains("gpu_ms_lockstep") ? f(t["gpu_ms_lockstep"]["median"], "%.4f").c_str() : "-");
  // Substeps picked from the groom, and the bound that decided them.
  if (r.contains("substeps") && r["substeps"]["source"] == "auto") {
    const auto& c = r["substeps"];
    if (c["capped"].get<bool>())
      std::printf("  %-14s substeps %d (auto, capped: the bound asks for %d or more; %s)\n", "", c["value"].get<int>(),
                  c["needed"].get<int>(), c["bound"].get<std::string>().c_str());
    else
      std::printf("  %-14s substeps %d (auto; %s)\n", "", c["value"].get<int>(), c["bound"].get<std::string>().c_str());
  }
  // What --calibrate fitted, and how close it came.
  if (r.contains("calibration"))
    for (const auto& fit : r["calibration"]["fits"]) {
      std::string line = fit["role"].get<std::string>() + ": ";
      if (fit.contains("on"))
        line += fit["param"].get<std::string>() + " " + f(fit["from"], "%.3g") + " -> " + f(fit["to"], "%.3g") +
                " on " + fit["on"].get<std::string>() + " " + f(fit["reached"], "%.3g") + " (reference " +
                f(fit["target"], "%.3g") + (fit["within"].get<bool>() ? ", within" : ", not within") + ")";
      if (fit.contains("note")) line += (fit.contains("on") ? "; " : "") + fit["note"].get<std::string>();
      std::printf("  %-14s calibrated %s\n", "", line.c_str());
    }
  // Every class but ok says why, and where it was decided.
  const auto& v = r["verdict"];
  if (v["class"] != "ok") {
    std::string at;
    if (!v["frame"].is_null()) at = " at frame " + std::to_string(v["frame"].get<int>());
    std::printf("  %-14s %s%s: %s\n", "", v["class"].get<std::string>().c_str(), at.c_str(),
                v["reason"].get<std::string>().c_str());
  }
}

// The GPU that the selected models (or the reference) run on, with its clock as the
// command starts (context.devices); none when every model runs on the CPU.
std::vector<DeviceRecord> gpu_devices(const CompareArgs& a) {
  std::vector<DeviceRecord> out;
#ifdef HAIRBENCH_HAS_VULKAN
  std::vector<std::string> names = a.run.models;
  if (!a.run.reference.empty()) names.push_back(a.run.reference);
  for (const std::string& name : names) {
    const ModelInfo* m = find_model(name);
    if (!m || !m->unavailable) continue;
    const vk::DeviceInfo& d = vk::Context::get(a.run.device)->device();
    const GpuClock clock = read_gpu_clock(d.name);
    out.push_back({d.name, d.type, d.timestamp_period_ns, clock.mhz, {}, clock.max_mhz, clock.source});
    break;
  }
#endif
  return out;
}

// The report, then the chart step (reports/charts.py) unless --no-charts. The devices'
// clocks are read again as it is written.
int write_report(const CompareArgs& a, const ThreadPool& pool, std::vector<DeviceRecord> devices,
                 const std::vector<RunRecord>& runs, const std::vector<ScenarioRecord>& scenarios,
                 const nlohmann::json& sweep, const Plan& plan, const nlohmann::json& time_s) {
  for (DeviceRecord& d : devices) {
    const GpuClock clock = read_gpu_clock(d.name);
    d.clock_end_mhz = clock.mhz;
    if (!d.clock_max_mhz) d.clock_max_mhz = clock.max_mhz;
  }
  const std::filesystem::path out = std::filesystem::path(a.out) / "report.json";
  nlohmann::json report =
      make_report(ReportContext{pool.threads(), std::move(devices), plugins_json(a.plugins)}, runs, scenarios);
  if (!sweep.is_null()) report["sweep"] = sweep;
  if (a.shard.active()) report["shard"] = shard_json(plan, a.shard);
  report["time_s"] = time_s;
  write_json(out, report);
  std::printf("wrote %s\n", out.string().c_str());
  return a.charts ? draw_charts(out) : 0;
}

// Where compare --groom's time goes (printed once the runs are done).
struct GroomTimes {
  double load_s = 0.0, fit_s = 0.0;
};

// compare --groom: the groom is read, repaired and fitted once, then put under each motion.
std::vector<Scenario> load_groom_scenarios(const CompareArgs& a, GroomTimes& times) {
  const std::filesystem::path groom = std::filesystem::absolute(a.groom);
  std::error_code ec;
  if (!std::filesystem::is_regular_file(groom, ec)) throw InputError("--groom", a.groom, "no such file");
  const std::vector<std::string> motions = a.motions.empty() ? default_motions() : a.motions;
  const nlohmann::json doc = groom_scenario_json(groom, groom.string(), motions.front(), a.unit, a.fit_above);
  const auto start = std::chrono::steady_clock::now();
  const Scenario base =
      load_scenario_text(doc.dump(), std::filesystem::current_path() / (doc["name"].get<std::string>() + ".json"));
  const double total = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  times.fit_s = base.import->seconds_fit;
  times.load_s = total - times.fit_s;
  std::fputs(import_summary(base).c_str(), stdout);
  std::vector<Scenario> scenarios;
  for (const std::string& m : motions) scenarios.push_back(with_motion(base, m));
  return scenarios;
}

std::vector<Scenario> load_scenarios(const CompareArgs& a) {
  // Load every scenario before running any, so a bad file fails fast.
  std::vector<Scenario> scenarios;
  if (a.scenarios.empty()) scenarios = load_builtin_scenarios();
  for (const std::string& s : a.scenarios) scenarios.push_back(load_scenario(find_scenario(s)));
  for (const std::string& why : a.skipped) std::fprintf(stderr, "hairbench: skipped model %s\n", why.c_str());
  return scenarios;
}

void print_header(const Scenario& sc, const CompareArgs& a) {
  std::printf("%s: %zu strands, %zu vertices, %d frames\n", sc.name.c_str(), sc.groom.strand_count(),
              sc.groom.vertex_count(), a.run.frames > 0 ? a.run.frames : sc.frames);
}

// scenario new: the scenario compare --groom runs for one motion, as a file, with the
// groom's path relative to it and the unit resolved.
int cmd_scenario_new(const std::string& groom_arg, const std::string& motion, const std::string& unit,
                     std::optional<double> fit_above, const std::string& out_arg) {
  namespace fs = std::filesystem;
  const fs::path groom = fs::absolute(groom_arg), out = fs::absolute(out_arg);
  std::error_code ec;
  if (!fs::is_regular_file(groom, ec)) throw InputError("--groom", groom_arg, "no such file");
  if (out.extension() != ".json") throw InputError("--out", out_arg, "expected a .json file name");
  if (!fs::is_directory(out.parent_path(), ec)) throw InputError("--out", out_arg, "no such folder");
  nlohmann::json doc =
      groom_scenario_json(groom, fs::relative(groom, out.parent_path()).generic_string(), motion, unit, fit_above);
  // Loaded before it is written, so that a groom that cannot run leaves no file behind.
  const Scenario sc = load_scenario_text(doc.dump(), out);
  doc["groom"]["unit"] = sc.import->unit;
  std::ofstream file(out);
  file << doc.dump(2) << "\n";
  if (!file) throw InputError(out.string(), "file", "cannot be written");
  std::fputs(import_summary(sc).c_str(), stdout);
  std::printf("wrote %s\n", out.string().c_str());
  return 0;
}

// compare and sweep: per scenario, one lockstep batch per knob value (one batch without
// a knob), each running the plan's models of this shard (every model unsharded) beside
// the reference, which every batch runs for itself.
// --groom's options need --groom, and exclude --scenario.
void check_groom_args(const CompareArgs& a) {
  if (!a.groom.empty() && !a.scenarios.empty())
    throw InputError("arguments", "--groom", "give either --groom or --scenario, not both");
  if (a.groom.empty() && !a.motions.empty()) throw InputError("arguments", "--motion", "applies to --groom only");
  if (a.groom.empty() && a.unit != "auto") throw InputError("arguments", "--unit", "applies to --groom only");
  if (a.groom.empty() && a.fit_above) throw InputError("arguments", "--fit-above", "applies to --groom only");
}

// Where a comparison's time went (report.json's time_s): stepping the models is what it
// measures; the rest is overhead.
struct TimeSplit {
  double models_s = 0.0, runs_s = 0.0, probes_s = 0.0, twins_s = 0.0, setup_s = 0.0, extra_s = 0.0;
  double metrics_cpu_s = 0.0, animation_s = 0.0;
  void add(const RunRecord& r) {
    for (double ms : r.step_ms) models_s += std::isfinite(ms) ? ms / 1e3 : 0.0;
    probes_s += r.probe_s;
    twins_s += r.twin_s;
    setup_s += r.setup_s;
    extra_s += r.settle_extra_s;
    metrics_cpu_s += r.metrics_s;
    animation_s += r.animation_s;
  }
  double other_s() const { return runs_s - models_s - probes_s - twins_s - setup_s - extra_s - animation_s; }
  nlohmann::json json(const GroomTimes& groom) const {
    return {{"load", groom.load_s},   {"fit", groom.fit_s},       {"runs", runs_s},
            {"model_steps", models_s}, {"probes", probes_s},     {"twins", twins_s},
            {"setup", setup_s},        {"settle_extra", extra_s}, {"animation", animation_s},
            {"metrics_cpu", metrics_cpu_s}, {"other", other_s()},
            {"overhead_share", models_s > 0 ? nlohmann::json((runs_s - models_s) / models_s) : nlohmann::json()}};
  }
  void print(const GroomTimes& groom) const {
    std::printf("time: load %.3f s (read, repairs, follow hairs), fit %.3f s (unit, head sphere, collider), "
                "model steps %.3f s, the models' probes %.3f s, rest twins %.3f s, setup %.3f s, steps past the "
                "end %.3f s, the player's frames %.3f s, metrics (%.3f s of CPU) and the rest %.3f s\n",
                groom.load_s, groom.fit_s, models_s, probes_s, twins_s, setup_s, extra_s, animation_s,
                metrics_cpu_s, other_s());
  }
};

int run_batches(CompareArgs& a, bool sweep) {
  prepare_compare(a, sweep);
  check_groom_args(a);
  GroomTimes groom_times;
  const std::vector<Scenario> scenarios = a.groom.empty() ? load_scenarios(a) : load_groom_scenarios(a, groom_times);
  if (!a.groom.empty())
    for (const std::string& why : a.skipped) std::fprintf(stderr, "hairbench: skipped model %s\n", why.c_str());
  const std::vector<double> values = a.knob ? a.knob->values : std::vector<double>{};
  const std::string knob_name = a.knob ? a.knob->name : "";
  const Plan plan = plan_runs(scenarios, a.run, knob_name, values, a.cost_model, a.shard.active() ? a.shard.count : 1);
  if (a.plan_only) {
    std::fputs(plan_text(plan, sweep ? "sweep" : "compare").c_str(), stdout);
    return 0;
  }
  std::vector<DeviceRecord> devices = gpu_devices(a);
  const int mine = a.shard.active() ? a.shard.index : 1;
  int total = 0;
  for (const PlanItem& it : plan.items) total += it.shard == mine;

  TimeSplit time;
  ThreadPool pool(a.threads);
  AtRestCache at_rest;
  Progress progress(total, true);
  std::vector<RunRecord> runs;
  std::vector<ScenarioRecord> records;
  std::size_t item = 0;
  for (const Scenario& sc : scenarios) {
    bool recorded = false;
    for (std::size_t k = 0; k < std::max<std::size_t>(values.size(), 1); ++k) {
      RunOptions opt = a.run;
      opt.at_rest = &at_rest;
      opt.models.clear();
      for (const std::string& m : a.run.models)
        if (plan.items[item++].shard == mine) opt.models.push_back(m);
      if (opt.models.empty()) continue;
      if (!recorded) {
        print_header(sc, a);
        opt.scenario_record = &records.emplace_back();
        opt.animation = !sweep;  // a sweep's many runs of a scenario are not played
        recorded = true;
      }
      std::fflush(stdout);
      std::string what = sc.name;
      if (a.knob) {
        const double value = values[k];
        for (const std::string& m : opt.models) opt.model_overrides.push_back({m, knob_name, value});
        opt.knob = RunRecord::Knob{knob_name, value};
        char v[64];
        std::snprintf(v, sizeof v, " %s=%g", knob_name.c_str(), value);
        what += v;
      }
      opt.on_frame = [&](int done, int frames) { progress.frame(done, frames); };
      progress.begin(static_cast<int>(opt.models.size()), what);
      const auto start = std::chrono::steady_clock::now();
      std::vector<RunRecord> got = run_scenario(sc, opt, pool);
      time.runs_s += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      progress.end();
      // A deviation measures accuracy only against a reference that is ok.
      if (!got.empty() && got.front().reference_status != verdict::Status::ok)
        std::printf("  reference %s is %s here: every dev below is measured against it\n",
                    got.front().reference.c_str(), std::string(verdict::status_name(got.front().reference_status)).c_str());
      for (const RunRecord& r : got) {
        print_run(run_json(r));
        time.add(r);
      }
      std::fflush(stdout);
      for (RunRecord& r : got) runs.push_back(std::move(r));
    }
  }
  time.print(groom_times);
  nlohmann::json sweep_json;
  if (a.knob) sweep_json = {{"knob", knob_name}, {"values", values}, {"models", a.run.models}};
  return write_report(a, pool, std::move(devices), runs, records, sweep_json, plan, time.json(groom_times));
}

struct StressArgs {
  StressOptions opt;
  std::string models = ".*";
  std::string out = "reports/out/stress";
  int threads = 0;
  bool charts = true;
  std::string shard_arg;
  bool plan_only = false;
  std::string costs;
};

int cmd_stress(StressArgs& a) {
  // The CPU models: the GPU variants run the same algorithms (the agreement tests),
  // and on a CPU Vulkan device a sweep of them would take hours.
  const std::regex re = models_regex(a.models);
  for (const ModelInfo& m : model_registry())
    if (m.platform == Platform::Cpu && std::regex_match(std::string(m.name), re)) a.opt.models.emplace_back(m.name);
  if (a.opt.models.empty()) throw InputError("arguments", "--models", "'" + a.models + "' matches no CPU model");
  const ShardSpec shard = a.shard_arg.empty() ? ShardSpec{} : parse_shard(a.shard_arg);
  const CostModel costs = a.costs.empty() ? CostModel{} : CostModel::from_report(a.costs);
  Plan plan;
  if (shard.active() || a.plan_only) {
    plan = plan_stress(a.opt, costs, shard.active() ? shard.count : 1);
    if (a.plan_only) {
      std::fputs(plan_text(plan, "stress").c_str(), stdout);
      return 0;
    }
    a.opt.only.emplace();
    for (const PlanItem& it : plan.items)
      if (it.shard == shard.index) a.opt.only->insert(it.key);
  }
  ThreadPool pool(a.threads);
  const bool tty = isatty(fileno(stderr));
  const auto start = std::chrono::steady_clock::now();
  const StressResult result = run_stress(a.opt, pool, [&](int done, int total) {
    if (!tty) return;
    const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    std::fprintf(stderr, "\r  stress: %d/%d runs, %.0f s elapsed, ~%.0f s left   ", done, total, s,
                 s / done * (total - done));
    if (done == total) std::fputc('\n', stderr);
  });
  std::fputs(stress_table(result).c_str(), stdout);
  nlohmann::json report = make_report(ReportContext{pool.threads(), {}}, {});
  report["stress"] = stress_json(result);
  if (shard.active()) report["shard"] = shard_json(plan, shard);
  const std::filesystem::path file = std::filesystem::path(a.out) / "stress.json";
  write_json(file, report);
  std::printf("wrote %s\n", file.string().c_str());
  return a.charts ? draw_charts(file, "stress_chart.py") : 0;
}

struct PrecisionArgs {
  std::string scenario;
  std::string models = ".*";
  bool models_given = false;
  std::string reference;  // exact | self; empty: exact on a truth scenario
  std::vector<std::string> sets;
  std::size_t keep_every = 0;
  int frames = 0;
  int threads = 0;
  std::string out = "reports/out/precision";
  bool charts = true;
};

int cmd_precision(const PrecisionArgs& a) {
  const Scenario sc = load_scenario(find_scenario(a.scenario));
  PrecisionOptions o;
  if (a.reference == "exact") o.reference = PrecisionReference::exact;
  else if (a.reference == "self") o.reference = PrecisionReference::self;
  else if (!a.reference.empty()) throw InputError("arguments", "--reference", "'" + a.reference + "' is not exact or self");
  add_sets(a.sets, o.overrides);
  const std::regex re = models_regex(a.models);
  for (const ModelInfo& m : model_registry())
    if (std::regex_match(std::string(m.name), re) && why_not_run(m, "", a.models_given).empty())
      o.models.emplace_back(m.name);
  if (o.models.empty()) throw InputError("arguments", "--models", "'" + a.models + "' matches no model that can run");
  o.keep_every = a.keep_every;
  o.frames = a.frames;
  const bool tty = isatty(fileno(stderr));
  o.on_run = [tty](const std::string& model, int done, int) {
    if (tty) std::fprintf(stderr, "\r  precision: %d runs, %-16s", done, model.c_str());
  };
  ThreadPool pool(a.threads);
  const nlohmann::json pr = run_precision(sc, o, pool);
  if (tty) std::fputc('\n', stderr);
  std::fputs(precision_table(pr).c_str(), stdout);
  nlohmann::json report = make_report(ReportContext{pool.threads(), {}}, {});
  report["precision"] = pr;
  const std::filesystem::path file = std::filesystem::path(a.out) / "precision.json";
  write_json(file, report);
  std::printf("wrote %s\n", file.string().c_str());
  return a.charts ? draw_charts(file, "precision_chart.py") : 0;
}

struct MergeArgs {
  std::string out;
  std::vector<std::string> files;
  bool mix_machines = false;
  bool charts = true;
};

int cmd_merge(const MergeArgs& a) {
  std::vector<ShardReport> shards;
  for (const std::string& f : a.files) shards.push_back(read_shard_report(f));
  if (shards.front().report["schema"] == "hairbench-reproduce") {
    const nlohmann::json merged = merge_reproduce_reports(shards);
    std::printf("merged %zu reproduce shards of %d (%zu papers)\n", shards.size(), merged["merge"]["count"].get<int>(),
                merged["papers"].size());
    return write_reproduce(merged, a.out, a.charts);
  }
  const bool stress = shards.front().report.contains("stress");
  const nlohmann::json merged = stress ? merge_stress_reports(shards) : merge_reports(shards, a.mix_machines);
  const std::filesystem::path file = std::filesystem::path(a.out) / (stress ? "stress.json" : "report.json");
  write_json(file, merged);
  const nlohmann::json& m = merged["merge"];
  std::printf("merged %zu shards of %d (%zu %s, %zu machine%s) into %s\n", shards.size(), m["count"].get<int>(),
              (stress ? merged["stress"]["axes"].size() + merged["stress"]["degenerate"].size() : merged["runs"].size()),
              stress ? "stress rows" : "runs", m["machines"].size(), m["machines"].size() == 1 ? "" : "s",
              file.string().c_str());
  for (const nlohmann::json& s : m["shards"])
    std::printf("  shard %d: %s, machine %d: %s\n", s["index"].get<int>(), s["file"].get<std::string>().c_str(),
                s["machine"].get<int>() + 1, m["machines"][s["machine"].get<std::size_t>()].get<std::string>().c_str());
  if (!a.charts) return 0;
  return stress ? draw_charts(file, "stress_chart.py") : draw_charts(file);
}

// reproduce --shard I/N: whole papers, not runs, since each paper's checks compare rows
// measured in one process (ratios of times, growth with size); papers go to shards in
// turn. Returns false when this shard has no paper (or --plan printed the cut).
struct ReproduceShard {
  std::string arg;
  bool plan_only = false;
};

bool shard_papers(ReproduceOptions& opt, const ReproduceShard& rs) {
  if (rs.arg.empty() && !rs.plan_only) return true;
  const ShardSpec shard = rs.arg.empty() ? ShardSpec{1, 1} : parse_shard(rs.arg);
  std::vector<std::string>& papers = opt.papers;
  const nlohmann::json frames_cap = opt.frames > 0 ? nlohmann::json(opt.frames) : nlohmann::json(nullptr);
  Plan plan;
  plan.count = shard.count;
  plan.shard_seconds.assign(static_cast<std::size_t>(shard.count), 0.0);
  plan.cost_source = "whole papers, in turn";
  std::vector<std::string> mine;
  for (std::size_t i = 0; i < papers.size(); ++i) {
    PlanItem item;
    item.key = reproduce_plan_key(papers[i], frames_cap);
    item.label = papers[i];
    item.shard = static_cast<int>(i % static_cast<std::size_t>(shard.count)) + 1;
    if (item.shard == shard.index) mine.push_back(papers[i]);
    plan.items.push_back(std::move(item));
  }
  if (rs.plan_only) {
    std::printf("reproduce: %zu papers, %d shard%s; whole papers (no cost estimate: a paper is not a run list)\n",
                papers.size(), shard.count, shard.count == 1 ? "" : "s");
    for (int s = 1; s <= shard.count; ++s) {
      std::string list;
      for (const PlanItem& it : plan.items)
        if (it.shard == s) list += " " + it.label;
      std::printf("shard %d/%d:%s\n", s, shard.count, list.empty() ? " (none)" : list.c_str());
    }
    return false;
  }
  if (mine.empty()) {
    std::printf("reproduce: shard %d/%d has no paper (%zu papers): nothing to run\n", shard.index, shard.count,
                papers.size());
    return false;
  }
  papers = std::move(mine);
  opt.shard = shard_json(plan, shard);
  return true;
}

int cmd_list(const std::string& what) {
  if (what.empty())
    throw InputError("arguments", "list", "expected `list models`, `list scenarios`, `list presets` or `list devices`");
  if (what == "presets") {
    for (const Preset& p : presets()) {
      std::printf("%-18s %s\n", std::string(p.name).c_str(), std::string(p.summary).c_str());
      for (const PresetValue& v : p.values)
        std::printf("%-18s   --set %s.%s=%g\n", "", std::string(v.model).c_str(), std::string(v.param).c_str(), v.value);
    }
    return 0;
  }
  if (what == "models") {
    int width = 0;
    for (const ModelInfo& m : model_registry()) width = std::max(width, static_cast<int>(m.name.size()));
    for (const ModelInfo& m : model_registry()) {
      std::string line(m.summary);
      if (!m.reference_of.empty())
        line += "; the reference for " + std::string(m.reference_of) +
                (m.reference_tolerance == 0.0 ? " (same bits)" : " (to rounding)");
      if (!m.origin.empty()) line += " [plugin " + std::string(m.origin) + "]";
      std::printf("%-*s %s\n", width, std::string(m.name).c_str(), line.c_str());
    }
    return 0;
  }
  // One name a line, for scripts (ci/perf-gate): the models a default comparison runs.
  if (what == "compared") {
    for (const ModelInfo& m : model_registry())
      if (why_not_run(m, "", false).empty()) std::printf("%s\n", std::string(m.name).c_str());
    return 0;
  }
  if (what == "scenarios") {
    for (const Scenario& sc : load_builtin_scenarios())
      std::printf("%-18s %s\n", sc.name.c_str(), sc.description.c_str());
    return 0;
  }
  if (what == "devices") {
#ifdef HAIRBENCH_HAS_VULKAN
    try {
      for (const vk::DeviceInfo& d : vk::list_devices())
        std::printf("%u  %-40s %s\n", d.index, d.name.c_str(), d.type.c_str());
    } catch (const vk::Unavailable& e) {
      std::printf("%s\n", e.what());
    }
#else
    std::puts("no Vulkan backend in this build (configure with libvulkan-dev and glslc)");
#endif
    return 0;
  }
  throw InputError("arguments", "list " + what,
                   "expected `list models`, `list compared`, `list scenarios`, `list presets` or `list devices`");
}

// --frames, --threads, --keep-every: a whole number in [lo, hi]. The one place numbers
// on the command line are checked; CLI11 converts a value only once this accepts it.
CLI::Validator whole_number(long long lo, long long hi) {
  return CLI::Validator(
      [lo, hi](std::string& v) -> std::string {
        long long x = 0;
        const auto [end, ec] = std::from_chars(v.data(), v.data() + v.size(), x);
        if (ec == std::errc() && end == v.data() + v.size() && x >= lo && x <= hi) return "";
        return "'" + v + "' is not a whole number in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]";
      },
      "");
}

// --threads, the same for every subcommand that runs models.
void add_threads_option(CLI::App& sub, int& threads) {
  sub.add_option("--threads", threads, "worker threads, 1 to 1024 (default: one per hardware\nthread)")
      ->type_name("N")
      ->check(whole_number(1, 1024));
}

// --shard, --plan and --costs: the same for every subcommand that has a run list
// (reproduce cuts whole papers and takes no --costs).
void add_shard_options(CLI::App& sub, std::string& shard, bool& plan_only, std::string* costs, const char* unit) {
  sub.add_option("--shard", shard,
                 std::string("run only part I of N of the ") + unit + " list (1 <= I <=\n"
                 "N), cut by estimated cost; hairbench merge joins the parts")
      ->type_name("I/N");
  sub.add_flag_callback("--plan", [&plan_only] { plan_only = true; },
                        std::string("print the ") + unit + " list and each shard's part (with\nits estimated cost), and exit");
  if (costs)
    sub.add_option("--costs", *costs,
                   "estimate the runs' costs from this earlier report's step\ntimes instead of the built-in table")
        ->type_name("REPORT.json");
}

void add_merge_options(CLI::App& sub, MergeArgs& a) {
  sub.add_option("OUT_DIR", a.out, "where the merged report and its charts go")->type_name("OUT_DIR")->required();
  sub.add_option("REPORT", a.files, "the shards' report.json (or stress.json) files")
      ->type_name("REPORT.json...")
      ->expected(1, -1)
      ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll)
      ->required();
  sub.add_flag_callback("--mix-machines", [&a] { a.mix_machines = true; },
                        "let a chart compare times measured on different machines\n"
                        "(each such chart says so); by default each machine's\n"
                        "runs are timed apart");
  sub.add_flag_callback("--no-charts", [&a] { a.charts = false; }, "write the report only");
}

// The options compare and sweep share; sweep adds --knob and needs --scenario.
// --unit and --fit-above for a TressFX groom: the unit given or guessed from its size, and
// the height above which roots are on the head.
void add_groom_fit_options(CLI::App& sub, std::string& unit, std::optional<double>& fit_above) {
  sub.add_option("--fit-above", fit_above,
                 "fit the head sphere through the roots higher than Y (file\n"
                 "units) only, instead of finding the scalp's roots")
      ->type_name("Y");
  sub.add_option("--unit", unit, "the groom's unit: cm, mm, m, or auto (guessed from its\nsize)")
      ->type_name("cm|mm|m|auto")
      ->capture_default_str()
      ->check(CLI::Validator(
          [](std::string& v) -> std::string {
            return v == "cm" || v == "mm" || v == "m" || v == "auto" ? "" : "'" + v + "' is not cm, mm, m or auto";
          },
          ""));
}

// --frames N: every run's frame count instead of the scenario's (compare, sweep, precision).
void add_frames_option(CLI::App& sub, int& frames) {
  sub.add_option("--frames", frames, "frames per run, 1 to 10000000 (default: the scenario's)")
      ->type_name("N")
      ->check(whole_number(1, 10'000'000));
}

void add_run_options(CLI::App& sub, CompareArgs& a, bool sweep) {
  a.out = sweep ? "reports/out/sweep" : "reports/out/latest";
  if (!sweep) {
    sub.add_option("--groom", a.groom,
                   "a TressFX groom (.tfx or .tfxproj) to run under built-in\n"
                   "motions instead of scenarios, with its unit, pivot, head\n"
                   "and collider fitted")
        ->type_name("PATH");
    sub.add_option("--motion", a.motions,
                   "with --groom: a built-in scenario's head motion; repeatable\n"
                   "(default: idle, nod, shake, spin_fast, walk, wind_gust)")
        ->type_name("NAME")
        ->allow_extra_args(false);
    add_groom_fit_options(sub, a.unit, a.fit_above);
  }
  sub.add_option("--scenario", a.scenarios,
                 sweep ? "built-in scenario or scenario file; repeatable"
                       : "built-in scenario or scenario file; repeatable\n(default: every built-in scenario)")
      ->type_name("NAME|PATH")
      ->allow_extra_args(false)
      ->required(sweep);
  if (sweep)
    sub.add_option("--knob", a.knobs, "the parameter to vary and its values,\ne.g. local_iterations=1,2,4,8")
        ->type_name("NAME=V1,V2,...")
        ->expected(1)
        ->allow_extra_args(false)
        ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll)  // prepare_compare refuses a second
        ->required();
  sub.add_option("--models", a.models, "models whose whole name matches (default: all)")
      ->type_name("REGEX")
      ->each([&a](const std::string&) { a.models_given = true; });
  sub.add_option("--reference", a.run.reference,
                 "deviation is measured against MODEL (default: the\n"
                 "scenario's, " + std::string(kDefaultReference) + "); converged: " + std::string(kDefaultReference) +
                     " at the settings\nwhere it is its own converged solution (docs/cli.md)")
      ->type_name("MODEL|converged");
  add_frames_option(sub, a.run.frames);
  add_threads_option(sub, a.threads);
  sub.add_option("--set", a.sets, "parameter override; MODEL may be * for every model that\nhas NAME; repeatable")
      ->type_name("MODEL.NAME=VALUE")
      ->allow_extra_args(false);
  sub.add_option("--preset", a.presets,
                 "a paper's force law as written (list presets), applied\nbefore --set; repeatable")
      ->type_name("NAME")
      ->allow_extra_args(false);
  sub.add_option("--out", a.out, "the report's directory")->type_name("DIR")->capture_default_str();
  sub.add_flag_callback("--no-charts", [&a] { a.charts = false; }, "write the report only");
  sub.add_option("--device", a.run.device,
                 "Vulkan device of the *_vk models, by index or name (see\n"
                 "list devices; default: the first discrete GPU, else any)")
      ->type_name("NAME|INDEX");
  add_shard_options(sub, a.shard_arg, a.plan_only, &a.costs, "run");
  sub.add_flag_callback("--no-skip", [&a] { a.run.skip_inert = false; },
                        "run every stage even where the scene makes it inert (no\n"
                        "colliders, no wind, zero stiffness) and never let strands\n"
                        "sleep");
  sub.add_flag_callback("--calibrate", [&a] { a.run.calibrate = true; },
                        "fit each model's stiffness and damping so that its material\n"
                        "card matches the reference's, then run with them\n"
                        "(a parameter set on the command line is kept)");
}

void add_precision_options(CLI::App& sub, PrecisionArgs& a) {
  sub.add_option("--scenario", a.scenario, "built-in scenario or scenario file")->type_name("NAME|PATH")->required();
  sub.add_option("--models", a.models, "models whose whole name matches (default: every model\na comparison runs)")
      ->type_name("REGEX")
      ->each([&a](const std::string&) { a.models_given = true; });
  sub.add_option("--reference", a.reference,
                 "exact (a truth scenario's chain; the default there) or\nself (the model at 8x its cost knobs; the "
                 "default\nelsewhere)")
      ->type_name("exact|self");
  sub.add_option("--keep-every", a.keep_every,
                 "thin the groom to every N-th strand (default: at most 256\nstrands)")
      ->type_name("N")
      ->check(whole_number(1, 1'000'000));
  add_frames_option(sub, a.frames);
  add_threads_option(sub, a.threads);
  sub.add_option("--set", a.sets, "parameter override under the knobs' values; repeatable")
      ->type_name("MODEL.NAME=VALUE")
      ->allow_extra_args(false);
  sub.add_option("--out", a.out, "the report's directory")->type_name("DIR")->capture_default_str();
  sub.add_flag_callback("--no-charts", [&a] { a.charts = false; }, "write precision.json only");
}

struct NewScenarioArgs {
  std::string groom, motion = "shake", unit = "auto", out;
  std::optional<double> fit_above;
};

void add_scenario_new_options(CLI::App& sub, NewScenarioArgs& a) {
  sub.add_option("--groom", a.groom, "a TressFX groom, .tfx or .tfxproj")->type_name("PATH")->required();
  sub.add_option("--motion", a.motion, "the built-in scenario whose head motion it takes")
      ->type_name("NAME")
      ->capture_default_str();
  add_groom_fit_options(sub, a.unit, a.fit_above);
  sub.add_option("--out", a.out, "the scenario file to write")->type_name("FILE.json")->required();
}

void add_stress_options(CLI::App& sub, StressArgs& a) {
  sub.add_option("--models", a.models, "CPU models whose whole name matches (default: all)")->type_name("REGEX");
  sub.add_option("--base", a.opt.base, "the stable starting point: built-in scenario or scenario\nfile")
      ->type_name("SCENARIO")
      ->capture_default_str();
  sub.add_option("--axes", a.opt.axes, "axes whose whole name matches (default: all)")->type_name("REGEX");
  sub.add_option("--keep-every", a.opt.keep_every, "thin the base groom to every N-th strand, 1 to 1000000")
      ->type_name("N")
      ->check(whole_number(1, 1'000'000))
      ->capture_default_str();
  sub.add_flag_callback("--quick", [&a] { a.opt.value_stride = 2; }, "try every other value of each axis");
  add_threads_option(sub, a.threads);
  sub.add_option("--out", a.out, "the report's directory")->type_name("DIR")->capture_default_str();
  sub.add_flag_callback("--no-charts", [&a] { a.charts = false; }, "write stress.json only, no heatmap");
  add_shard_options(sub, a.shard_arg, a.plan_only, &a.costs, "run");
}

void add_reproduce_options(CLI::App& sub, std::vector<std::string>& tables, ReproduceOptions& o, ReproduceShard& rs) {
  sub.add_option("TABLE", tables, reproduce_paper_names() + " or all; several may be named")
      ->type_name("NAME");
  sub.add_option("--frames", o.frames, "cap every run at N frames (quick runs), 1 to 1000000")
      ->type_name("N")
      ->check(whole_number(1, 1'000'000));
  add_threads_option(sub, o.threads);
  sub.add_option("--device", o.device, "Vulkan device for Han & Harada's GPU table, by index or\nname")
      ->type_name("NAME|INDEX");
  sub.add_option("--out", o.out, "the report's directory")->type_name("DIR")->capture_default_str();
  sub.add_flag_callback("--no-charts", [&o] { o.charts = false; }, "no claim charts (reproduce.json, .md, .html only)");
  add_shard_options(sub, rs.arg, rs.plan_only, nullptr, "paper");
}

// CLI11's parse errors in the project's one-line form, naming the argument and the
// subcommand whose help lists what it takes.
InputError argument_error(const CLI::App& top, const CLI::ParseError& e) {
  // The application whose arguments were being read: the subcommand (there is at most
  // one) unless an extra argument came before any.
  const std::vector<CLI::App*> parsed = top.get_subcommands();
  const CLI::App* sub = parsed.empty() || e.get_name() == top.get_name() ? &top : parsed.front();
  const std::string help = sub == &top ? "hairbench --help" : "hairbench " + sub->get_name() + " --help";
  if (dynamic_cast<const CLI::ExtrasError*>(&e) && !sub->remaining().empty()) {
    const std::string arg = sub->remaining().front();
    const char* what = arg.starts_with('-') ? "unknown option"
                       : sub == &top        ? "unknown subcommand"
                                            : "unexpected argument";
    return InputError("arguments", arg, std::string(what) + " (see " + help + ")");
  }
  const std::string msg = e.what();
  if (dynamic_cast<const CLI::ArgumentMismatch*>(&e)) {
    // It names the option first: "--frames: ..." (a value missing at the end of the
    // line) or "quick was given a disallowed flag override".
    const std::string name = msg.substr(0, msg.find_first_of(": "));
    const CLI::Option* opt = sub->get_option_no_throw(name);
    if (!opt) opt = sub->get_option_no_throw("--" + name);
    if (opt && opt->get_items_expected_max() == 0) return InputError("arguments", opt->get_name(), "takes no value");
    if (opt) return InputError("arguments", opt->get_name(), "needs a value");
  }
  if (dynamic_cast<const CLI::RequiredError*>(&e) && sub != &top)
    return InputError("arguments", sub->get_name(), msg + " (see " + help + ")");
  return InputError("arguments: " + msg);
}

// --plugin, the same for every subcommand that lists or runs models.
void add_plugin_option(CLI::App& sub, std::vector<std::string>& paths) {
  sub.add_option("--plugin", paths,
                 "load models from a plugin library (docs/plugins.md), after\nthe default ones and "
                 "HAIRBENCH_PLUGIN_PATH's; repeatable")
      ->type_name("PATH.so")
      ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
}

int run(int argc, char** argv) {
  CLI::App app(kDescription, "hairbench");
  app.footer(kExitCodes);
  app.set_version_flag("--version", std::string("hairbench ") + HAIRBENCH_GIT_SHA,
                       "print the commit this binary was built from");
  app.require_subcommand(0, 1);
  // An option given twice keeps its last value; the repeatable ones (--scenario, --set)
  // keep every value.
  app.option_defaults()->multi_option_policy(CLI::MultiOptionPolicy::TakeLast);
  // A flag takes no value (`--no-charts=false` is a mistake, not a way to turn it off).
  app.option_defaults()->disable_flag_override();

  std::string list_what;
  CLI::App* list = app.add_subcommand("list", kListHelp);
  list->add_option("WHAT", list_what, "what to list")->type_name("models|compared|scenarios|presets|devices");
  std::vector<std::string> plugin_paths;

  CompareArgs compare_args, sweep_args;
  CLI::App* compare = app.add_subcommand("compare", kCompareHelp);
  add_run_options(*compare, compare_args, false);
  CLI::App* sweep = app.add_subcommand("sweep", kSweepHelp);
  add_run_options(*sweep, sweep_args, true);

  StressArgs stress_args;
  CLI::App* stress = app.add_subcommand("stress", kStressHelp);
  add_stress_options(*stress, stress_args);

  MergeArgs merge_args;
  CLI::App* merge = app.add_subcommand("merge", kMergeHelp);
  add_merge_options(*merge, merge_args);
  CLI::App* scenario = app.add_subcommand("scenario", kScenarioHelp);
  scenario->require_subcommand(1);
  NewScenarioArgs new_args;
  CLI::App* scenario_new = scenario->add_subcommand("new", kScenarioHelp);
  add_scenario_new_options(*scenario_new, new_args);
  PrecisionArgs precision_args;
  CLI::App* precision = app.add_subcommand("precision", kPrecisionHelp);
  add_precision_options(*precision, precision_args);

  std::vector<std::string> tables;
  ReproduceOptions reproduce_opt;
  ReproduceShard reproduce_shard;
  CLI::App* reproduce = app.add_subcommand("reproduce", kReproduceHelp);
  add_reproduce_options(*reproduce, tables, reproduce_opt, reproduce_shard);

  for (CLI::App* sub : {list, compare, sweep, stress, precision}) add_plugin_option(*sub, plugin_paths);

  // Without arguments the usage is the answer, with the exit code of a bad command line;
  // `hairbench help` is a documented spelling of --help.
  if (argc < 2 || std::string_view(argv[1]) == "help") {
    std::fputs(app.help().c_str(), stdout);
    return argc < 2 ? 2 : 0;
  }
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    if (e.get_exit_code() == 0) return app.exit(e);  // --help, -h, --version: printed on stdout
    throw argument_error(app, e);
  }
  if (list->parsed() || compare->parsed() || sweep->parsed() || stress->parsed() || precision->parsed())
    compare_args.plugins = sweep_args.plugins = load_plugins(plugin_paths);
  if (list->parsed()) return cmd_list(list_what);
  if (compare->parsed()) return run_batches(compare_args, false);
  if (sweep->parsed()) return run_batches(sweep_args, true);
  if (merge->parsed()) return cmd_merge(merge_args);
  if (stress->parsed()) return cmd_stress(stress_args);
  if (scenario_new->parsed())
    return cmd_scenario_new(new_args.groom, new_args.motion, new_args.unit, new_args.fit_above, new_args.out);
  if (precision->parsed()) return cmd_precision(precision_args);
  if (reproduce->parsed()) {
    reproduce_opt.papers = select_papers(tables);
    if (!shard_papers(reproduce_opt, reproduce_shard)) return 0;
    return cmd_reproduce(reproduce_opt);
  }
  throw InputError("arguments", "hairbench",
                   "name a subcommand: list, compare, sweep, stress, merge, reproduce, precision or scenario (see "
                   "hairbench --help)");
}

}  // namespace
}  // namespace hairbench

int main(int argc, char** argv) {
  try {
    return hairbench::run(argc, argv);
  } catch (const hairbench::InputError& e) {
    std::fprintf(stderr, "hairbench: %s\n", e.what());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "hairbench: internal error: %s\n", e.what());
    return 1;
  }
}
