// hairbench command line (DESIGN.md, "CLI (contract)").
#include "core/error.h"
#include "core/parallel.h"
#include "harness/runner.h"
#include "harness/stress.h"
#include "models/registry.h"
#include "reports/report.h"
#include "scenarios/scenario.h"

#include <chrono>
#include <cstdio>
#include <iostream>
#include <regex>
#include <string>
#include <thread>
#include <vector>

#include <unistd.h>

namespace hairbench {
namespace {

constexpr const char* kUsage = R"(usage:
  hairbench list models|scenarios
  hairbench compare [--scenario NAME|PATH]... [--models REGEX] [--reference MODEL]
                    [--frames N] [--threads N] [--set MODEL.NAME=VALUE]... [--out DIR]
  hairbench stress [--models REGEX] [--base SCENARIO] [--axes REGEX] [--keep-every N]
                   [--quick] [--threads N] [--out DIR]

compare runs every selected model in lockstep on each scenario (default: every built-in
scenario) and writes DIR/report.json (default DIR: reports/out/latest).
  --models REGEX     models whose whole name matches (default: all)
  --reference MODEL  deviation is measured against MODEL (default: the scenario's, han_m1)
  --set M.NAME=V     parameter override; M may be * for every model that has NAME
stress escalates one axis at a time (time step, head angular velocity and acceleration,
teleports, strand vertices and length, every stiffness, iteration count and damping)
from the stable base scenario (default shake, every 10th strand) until each model fails,
runs degenerate grooms, prints the table and writes DIR/stress.json (default DIR:
reports/out/stress). --quick tries every other value of each axis.
exit codes: 0 done (unstable models are results, not errors), 2 bad arguments or files)";

struct CompareArgs {
  std::vector<std::string> scenarios;
  std::string models = ".*";
  RunOptions run;
  int threads = 0;
  std::string out = "reports/out/latest";
};

int parse_int(const std::string& flag, const std::string& v, int lo, int hi) {
  std::size_t used = 0;
  long long x = 0;
  try {
    x = std::stoll(v, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used == 0 || used != v.size() || x < lo || x > hi)
    throw InputError("arguments", flag, "'" + v + "' is not a whole number in [" + std::to_string(lo) + ", " +
                                            std::to_string(hi) + "]");
  return static_cast<int>(x);
}

// Every registered model whose whole name matches the --models regex.
std::vector<std::string> select_models(const std::string& pattern) {
  std::regex re;
  try {
    re = std::regex(pattern);
  } catch (const std::regex_error& e) {
    throw InputError("arguments", "--models", std::string("bad regular expression: ") + e.what());
  }
  std::vector<std::string> names;
  for (const ModelInfo& m : model_registry())
    if (std::regex_match(std::string(m.name), re)) names.emplace_back(m.name);
  if (names.empty()) throw InputError("arguments", "--models", "'" + pattern + "' matches no model");
  return names;
}

CompareArgs parse_compare(const std::vector<std::string>& args) {
  CompareArgs a;
  for (std::size_t i = 0; i < args.size(); ++i) {
    const std::string& flag = args[i];
    auto value = [&]() -> const std::string& {
      if (i + 1 >= args.size()) throw InputError("arguments", flag, "needs a value");
      return args[++i];
    };
    if (flag == "--scenario") a.scenarios.push_back(value());
    else if (flag == "--models") a.models = value();
    else if (flag == "--reference") a.run.reference = value();
    else if (flag == "--frames") a.run.frames = parse_int(flag, value(), 1, 10'000'000);
    else if (flag == "--threads") a.threads = parse_int(flag, value(), 1, 1024);
    else if (flag == "--set") {
      ParamOverride o = parse_param_override(value());
      check_param_override(o);
      a.run.overrides.push_back(o);
    } else if (flag == "--out") a.out = value();
    else throw InputError("arguments", flag, "unknown option (see hairbench --help)");
  }
  a.run.models = select_models(a.models);
  if (!a.run.reference.empty() && !find_model(a.run.reference))
    throw InputError("arguments", "--reference", "unknown model '" + a.run.reference + "'");
  return a;
}

std::vector<Scenario> load_builtin(FILE* note) {
  std::vector<std::string> skipped;
  std::vector<Scenario> scenarios = load_builtin_scenarios(&skipped);
  for (const std::string& why : skipped) std::fprintf(note, "hairbench: skipped: %s\n", why.c_str());
  return scenarios;
}

void print_run(const nlohmann::json& r) {
  auto f = [](const nlohmann::json& v, const char* fmt) {
    char buf[32];
    if (v.is_null()) return std::string("-");
    std::snprintf(buf, sizeof buf, fmt, v.get<double>());
    return std::string(buf);
  };
  const auto& m = r["metrics"];
  std::printf("  %-14s %-8s %9s ms %8s ns/v  dev %-9s jag %-9s len %-9s rest %-9s\n",
              r["model"].get<std::string>().c_str(), r["status"].get<std::string>().c_str(),
              f(r["timing"]["step_ms"]["median"], "%.3f").c_str(), f(r["timing"]["ns_per_vertex"], "%.1f").c_str(),
              f(m["deviation_vs_reference"]["rms"], "%.3g").c_str(), f(m["jaggedness"]["mean"], "%.3g").c_str(),
              f(m["length_error"]["rms"], "%.2g").c_str(), f(m["rest_shape_error"], "%.3g").c_str());
  if (!r["failure"].is_null())
    std::printf("  %-14s unstable at frame %d: %s\n", "", r["failure"]["frame"].get<int>(),
                r["failure"]["reason"].get<std::string>().c_str());
}

int cmd_compare(const std::vector<std::string>& args) {
  CompareArgs a = parse_compare(args);
  // Load every scenario before running any, so a bad file fails fast. Built-in
  // scenarios whose asset is missing are skipped with a message; named ones are errors.
  std::vector<Scenario> scenarios;
  if (a.scenarios.empty()) scenarios = load_builtin(stderr);
  for (const std::string& s : a.scenarios) scenarios.push_back(load_scenario(find_scenario(s)));

  ThreadPool pool(a.threads);
  std::vector<RunRecord> runs;
  for (const Scenario& sc : scenarios) {
    std::printf("%s: %zu strands, %zu vertices, %d frames\n", sc.name.c_str(), sc.groom.strand_count(),
                sc.groom.vertex_count(), a.run.frames > 0 ? a.run.frames : sc.frames);
    std::fflush(stdout);
    std::vector<RunRecord> got = run_scenario(sc, a.run, pool);
    for (const RunRecord& r : got) print_run(run_json(r));
    std::fflush(stdout);
    for (RunRecord& r : got) runs.push_back(std::move(r));
  }
  const std::filesystem::path out = std::filesystem::path(a.out) / "report.json";
  write_json(out, make_report(ReportContext{pool.threads()}, runs));
  std::printf("wrote %s\n", out.string().c_str());
  return 0;
}

int cmd_stress(const std::vector<std::string>& args) {
  StressOptions opt;
  std::string models = ".*", out = "reports/out/stress";
  int threads = 0;
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
    else throw InputError("arguments", flag, "unknown option (see hairbench --help)");
  }
  opt.models = select_models(models);
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
  return 0;
}

int cmd_list(const std::vector<std::string>& args) {
  if (args.size() != 1) throw InputError("arguments", "list", "expected `list models` or `list scenarios`");
  if (args[0] == "models") {
    for (const ModelInfo& m : model_registry())
      std::printf("%-14s %s\n", std::string(m.name).c_str(), std::string(m.summary).c_str());
    return 0;
  }
  if (args[0] == "scenarios") {
    for (const Scenario& sc : load_builtin(stderr))
      std::printf("%-18s %s\n", sc.name.c_str(), sc.description.c_str());
    return 0;
  }
  throw InputError("arguments", "list " + args[0], "expected `list models` or `list scenarios`");
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
  if (cmd == "list") return cmd_list(args);
  if (cmd == "stress") return cmd_stress(args);
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
