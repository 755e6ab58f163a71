// hairbench command line (DESIGN.md, "CLI (contract)").
#include "core/error.h"
#include "core/parallel.h"
#include "harness/charts.h"
#include "harness/progress.h"
#include "harness/args.h"
#include "harness/reproduce.h"
#include "harness/runner.h"
#include "harness/stress.h"
#include "models/registry.h"
#include "reports/report.h"
#include "scenarios/scenario.h"
#ifdef HAIRBENCH_HAS_VULKAN
#include "kernels/vulkan/runtime.h"
#endif

#include <chrono>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <regex>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include <unistd.h>

namespace hairbench {
namespace {

constexpr const char* kUsage = R"(usage:
  hairbench list models|scenarios|devices
  hairbench compare [--scenario NAME|PATH]... [--models REGEX] [--reference MODEL|converged]
                    [--frames N] [--threads N] [--set MODEL.NAME=VALUE]... [--out DIR] [--no-charts]
                    [--device NAME|INDEX] [--no-skip]
  hairbench sweep --scenario NAME|PATH [--scenario ...] --knob NAME=V1,V2,... [--models REGEX]
                  [--reference MODEL|converged] [--frames N] [--threads N] [--set MODEL.NAME=VALUE]...
                  [--out DIR] [--no-charts]
  hairbench stress [--models REGEX] [--base SCENARIO] [--axes REGEX] [--keep-every N]
                   [--quick] [--threads N] [--out DIR] [--no-charts]
  hairbench reproduce han2012|halen2007|plante2001|all [--frames N] [--threads N]
                      [--device NAME|INDEX] [--out DIR]

compare runs every selected model in lockstep on each scenario (default: every built-in
scenario) and writes DIR/report.json (default DIR: reports/out/latest), then its charts,
DIR/report_summary.md and DIR/report.html.
sweep runs every selected model that has parameter NAME at each value, and writes one
report whose runs carry the value as "knob" (default DIR: reports/out/sweep).
  --models REGEX     models whose whole name matches (default: all)
  --reference MODEL  deviation is measured against MODEL (default: the scenario's, han_m1);
                     converged: han_m1 with 32 local and length iterations and 4 substeps
  --set M.NAME=V     parameter override; M may be * for every model that has NAME
  --no-charts        write the report only
  --no-skip          run every stage even where the scene makes it inert (no colliders,
                     no wind, zero stiffness) and never let strands sleep
  --device D         Vulkan device of the *_vk models, by index or name (see list
                     devices; default: the first discrete GPU, else any device)
stress escalates one axis at a time (time step, head angular velocity and acceleration,
teleports, strand vertices and length, every stiffness, iteration count and damping)
from the stable base scenario (default shake, every 10th strand) until each model fails,
runs degenerate grooms, prints the table, writes DIR/stress.json (default DIR:
reports/out/stress) and draws its heatmap DIR/stress_heatmap.png. --quick tries every other value
of each axis.
reproduce runs the configurations of the papers' published tables (reports/published/)
and writes DIR/reproduce.json, .md and .html (default DIR: reports/out/reproduce): per
row the published and measured values and a hardware-independent comparison, and the
papers' claims as checks, each with a verdict (holds / differs). --frames N caps every
run at N frames (quick runs).
exit codes: 0 done (unstable models are results, not errors), 1 internal error or chart
script failure, 2 bad arguments or files)";

struct KnobSpec {
  std::string name;
  std::vector<double> values;
};

struct CompareArgs {
  std::vector<std::string> scenarios;
  std::string models = ".*";
  bool models_given = false;
  std::vector<std::string> skipped;  // models left out, and why (printed once the inputs are good)
  RunOptions run;
  int threads = 0;
  std::string out;
  bool charts = true;
  std::optional<KnobSpec> knob;  // sweep only
};

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
    std::size_t used = 0;
    double x = 0.0;
    try {
      x = std::stod(v, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used == 0 || used != v.size()) throw InputError("--knob", arg, "'" + v + "' is not a number");
    if (!std::isfinite(x)) throw InputError("--knob", arg, "value is NaN or infinite");
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

CompareArgs parse_compare(const std::vector<std::string>& args, bool sweep) {
  CompareArgs a;
  a.out = sweep ? "reports/out/sweep" : "reports/out/latest";
  for (std::size_t i = 0; i < args.size(); ++i) {
    const std::string& flag = args[i];
    auto value = [&]() -> const std::string& {
      if (i + 1 >= args.size()) throw InputError("arguments", flag, "needs a value");
      return args[++i];
    };
    if (flag == "--scenario") a.scenarios.push_back(value());
    else if (flag == "--models") {
      a.models = value();
      a.models_given = true;
    } else if (flag == "--device") a.run.device = value();
    else if (flag == "--reference") a.run.reference = value();
    else if (flag == "--frames") a.run.frames = parse_int(flag, value(), 1, 10'000'000);
    else if (flag == "--threads") a.threads = parse_int(flag, value(), 1, 1024);
    else if (flag == "--set") {
      ParamOverride o = parse_param_override(value());
      check_param_override(o);
      a.run.overrides.push_back(o);
    } else if (flag == "--out") a.out = value();
    else if (flag == "--no-charts") a.charts = false;
    else if (flag == "--no-skip") a.run.skip_inert = false;
    else if (sweep && flag == "--knob") {
      if (a.knob) throw InputError("arguments", flag, "give one --knob per sweep");
      a.knob = parse_knob(value());
    } else throw InputError("arguments", flag, "unknown option (see hairbench --help)");
  }
  if (sweep && a.scenarios.empty()) throw InputError("arguments", "sweep", "needs --scenario NAME|PATH");
  if (sweep && !a.knob) throw InputError("arguments", "sweep", "needs --knob NAME=V1,V2,...");
  std::regex re;
  try {
    re = std::regex(a.models);
  } catch (const std::regex_error& e) {
    throw InputError("arguments", "--models", std::string("bad regular expression: ") + e.what());
  }
  // Models that need a missing device (no Vulkan): left out with a note by default, an
  // error when --models asked for them.
  for (const ModelInfo& m : model_registry()) {
    if (!std::regex_match(std::string(m.name), re)) continue;
    std::string why = m.unavailable ? m.unavailable(ModelContext{nullptr, a.run.device}) : "";
#ifdef HAIRBENCH_HAS_VULKAN
    // On a CPU Vulkan device (lavapipe) the GPU models take seconds per frame: run them
    // only when --models asks for them.
    if (why.empty() && m.unavailable && !a.models_given &&
        vk::Context::get(a.run.device)->device().type == "CPU")
      why = "the Vulkan device is a CPU (" + vk::Context::get(a.run.device)->device().name +
            "); name it in --models to run it";
#endif
    // The _ref variants are today's straightforward implementations kept for issue 10's
    // side-by-side speed-ups; their results are bit-identical to the fast models'.
    if (why.empty() && !a.models_given && std::string_view(m.name).ends_with("_ref"))
      why = "bit-identical reference implementation of " + std::string(m.name.substr(0, m.name.size() - 4)) +
            "; name it in --models to run it";
    if (why.empty()) a.run.models.emplace_back(m.name);
    else if (a.models_given) throw InputError("arguments", "--models", std::string(m.name) + " cannot run: " + why);
    else a.skipped.push_back(std::string(m.name) + ": " + why);
  }
  if (a.run.models.empty()) throw InputError("arguments", "--models", "'" + a.models + "' matches no model");
  if (a.run.reference == kConvergedReference) {
    a.run.reference = "han_m1";
    a.run.reference_overrides = converged_reference_overrides();
  } else if (!a.run.reference.empty() && !find_model(a.run.reference)) {
    throw InputError("arguments", "--reference", "unknown model '" + a.run.reference + "' (or 'converged')");
  }
  if (a.knob) select_knob_models(a);
  return a;
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
  const auto& m = r["metrics"];
  std::printf("  %-14s %-8s %9s ms %8s ns/v  dev %-9s jag %-9s len %-9s rest %-9s\n", label.c_str(), r["status"].get<std::string>().c_str(),
              f(r["timing"]["step_ms"]["median"], "%.3f").c_str(), f(r["timing"]["ns_per_vertex"], "%.1f").c_str(),
              f(m["deviation_vs_reference"]["rms"], "%.3g").c_str(), f(m["jaggedness"]["mean"], "%.3g").c_str(),
              f(m["length_error"]["rms"], "%.2g").c_str(), f(m["rest_shape_error"], "%.3g").c_str());
  if (!r["failure"].is_null())
    std::printf("  %-14s unstable at frame %d: %s\n", "", r["failure"]["frame"].get<int>(),
                r["failure"]["reason"].get<std::string>().c_str());
}

// The report, then the chart step (reports/charts.py) unless --no-charts.
int write_report(const CompareArgs& a, const ThreadPool& pool, const std::vector<RunRecord>& runs,
                 const std::vector<ScenarioRecord>& scenarios, const nlohmann::json& sweep) {
  const std::filesystem::path out = std::filesystem::path(a.out) / "report.json";
  nlohmann::json report = make_report(ReportContext{pool.threads()}, runs, scenarios);
  if (!sweep.is_null()) report["sweep"] = sweep;
  write_json(out, report);
  std::printf("wrote %s\n", out.string().c_str());
  return a.charts ? draw_charts(out) : 0;
}

std::vector<Scenario> load_scenarios(const CompareArgs& a) {
  // Load every scenario before running any, so a bad file fails fast. Built-in
  // scenarios whose asset is missing are skipped with a message; named ones are errors.
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

int cmd_compare(const std::vector<std::string>& args) {
  CompareArgs a = parse_compare(args, false);
  const std::vector<Scenario> scenarios = load_scenarios(a);

  ThreadPool pool(a.threads);
  Progress progress(static_cast<int>(scenarios.size() * a.run.models.size()), true);
  std::vector<RunRecord> runs;
  std::vector<ScenarioRecord> records;
  for (const Scenario& sc : scenarios) {
    print_header(sc, a);
    std::fflush(stdout);
    RunOptions opt = a.run;
    opt.scenario_record = &records.emplace_back();
    opt.on_frame = [&](int done, int frames) { progress.frame(done, frames); };
    progress.begin(static_cast<int>(a.run.models.size()), sc.name);
    std::vector<RunRecord> got = run_scenario(sc, opt, pool);
    progress.end();
    for (const RunRecord& r : got) print_run(run_json(r));
    std::fflush(stdout);
    for (RunRecord& r : got) runs.push_back(std::move(r));
  }
  return write_report(a, pool, runs, records, nullptr);
}

// Every selected model at every knob value, one lockstep batch per value: the reference
// (at the scenario's parameters, or converged) is the same in every batch.
int cmd_sweep(const std::vector<std::string>& args) {
  CompareArgs a = parse_compare(args, true);
  const KnobSpec& knob = *a.knob;
  const std::vector<Scenario> scenarios = load_scenarios(a);

  ThreadPool pool(a.threads);
  const int per_batch = static_cast<int>(a.run.models.size());
  Progress progress(static_cast<int>(scenarios.size() * knob.values.size()) * per_batch, true);
  std::vector<RunRecord> runs;
  std::vector<ScenarioRecord> records;
  for (const Scenario& sc : scenarios) {
    print_header(sc, a);
    std::fflush(stdout);
    for (std::size_t k = 0; k < knob.values.size(); ++k) {
      const double value = knob.values[k];
      RunOptions opt = a.run;
      for (const std::string& m : a.run.models) opt.model_overrides.push_back({m, knob.name, value});
      opt.knob = RunRecord::Knob{knob.name, value};
      if (k == 0) opt.scenario_record = &records.emplace_back();
      opt.on_frame = [&](int done, int frames) { progress.frame(done, frames); };
      char what[160];
      std::snprintf(what, sizeof what, "%s %s=%g", sc.name.c_str(), knob.name.c_str(), value);
      progress.begin(per_batch, what);
      std::vector<RunRecord> got = run_scenario(sc, opt, pool);
      progress.end();
      for (const RunRecord& r : got) print_run(run_json(r));
      std::fflush(stdout);
      for (RunRecord& r : got) runs.push_back(std::move(r));
    }
  }
  const nlohmann::json sweep = {{"knob", knob.name}, {"values", knob.values}, {"models", a.run.models}};
  return write_report(a, pool, runs, records, sweep);
}

int cmd_stress(const std::vector<std::string>& args) {
  StressOptions opt;
  std::string models = ".*", out = "reports/out/stress";
  int threads = 0;
  bool no_charts = false;
  for (std::size_t i = 0; i < args.size(); ++i) {
    const std::string& flag = args[i];
    auto value = [&]() -> const std::string& {
      if (i + 1 >= args.size()) throw InputError("arguments", flag, "needs a value");
      return args[++i];
    };
    if (flag == "--models") models = value();
    else if (flag == "--base") opt.base = value();
    else if (flag == "--axes") opt.axes = value();
    else if (flag == "--keep-every") opt.keep_every = static_cast<std::size_t>(parse_int(flag, value(), 1, 1'000'000));
    else if (flag == "--quick") opt.value_stride = 2;
    else if (flag == "--threads") threads = parse_int(flag, value(), 1, 1024);
    else if (flag == "--out") out = value();
    else if (flag == "--no-charts") no_charts = true;
    else throw InputError("arguments", flag, "unknown option (see hairbench --help)");
  }
  // The CPU models: the GPU variants run the same algorithms (issue 7's agreement
  // tests), and on a CPU Vulkan device a sweep of them would take hours.
  std::regex re;
  try {
    re = std::regex(models);
  } catch (const std::regex_error& e) {
    throw InputError("arguments", "--models", std::string("bad regular expression: ") + e.what());
  }
  for (const ModelInfo& m : model_registry())
    if (!m.unavailable && std::regex_match(std::string(m.name), re)) opt.models.emplace_back(m.name);
  if (opt.models.empty()) throw InputError("arguments", "--models", "'" + models + "' matches no CPU model");
  ThreadPool pool(threads);
  const bool tty = isatty(fileno(stderr));
  const auto start = std::chrono::steady_clock::now();
  const StressResult result = run_stress(opt, pool, [&](int done, int total) {
    if (!tty) return;
    const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    std::fprintf(stderr, "\r  stress: %d/%d runs, %.0f s elapsed, ~%.0f s left   ", done, total, s,
                 s / done * (total - done));
    if (done == total) std::fputc('\n', stderr);
  });
  std::fputs(stress_table(result).c_str(), stdout);
  nlohmann::json report = make_report(ReportContext{pool.threads()}, {});
  report["stress"] = stress_json(result);
  const std::filesystem::path file = std::filesystem::path(out) / "stress.json";
  write_json(file, report);
  std::printf("wrote %s\n", file.string().c_str());
  return no_charts ? 0 : draw_charts(file, "stress_chart.py");
}

int cmd_list(const std::vector<std::string>& args) {
  if (args.size() != 1)
    throw InputError("arguments", "list", "expected `list models`, `list scenarios` or `list devices`");
  if (args[0] == "models") {
    for (const ModelInfo& m : model_registry())
      std::printf("%-14s %s\n", std::string(m.name).c_str(), std::string(m.summary).c_str());
    return 0;
  }
  if (args[0] == "scenarios") {
    for (const Scenario& sc : load_builtin_scenarios())
      std::printf("%-18s %s\n", sc.name.c_str(), sc.description.c_str());
    return 0;
  }
  if (args[0] == "devices") {
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
  throw InputError("arguments", "list " + args[0], "expected `list models`, `list scenarios` or `list devices`");
}

int run(int argc, char** argv) {
  std::vector<std::string> args(argv + 1, argv + argc);
  if (args.empty() || args[0] == "--help" || args[0] == "-h" || args[0] == "help") {
    std::puts(kUsage);
    return args.empty() ? 2 : 0;
  }
  const std::string cmd = args[0];
  args.erase(args.begin());
  if (cmd == "compare") return cmd_compare(args);
  if (cmd == "sweep") return cmd_sweep(args);
  if (cmd == "list") return cmd_list(args);
  if (cmd == "stress") return cmd_stress(args);
  if (cmd == "reproduce") return cmd_reproduce(args);
  throw InputError("arguments", cmd, "unknown command (see hairbench --help)");
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
