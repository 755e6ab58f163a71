// hairbench command line (DESIGN.md, "CLI (contract)").
#include "core/error.h"
#include "core/parallel.h"
#include "harness/runner.h"
#include "models/registry.h"
#include "reports/report.h"
#include "scenarios/scenario.h"
#ifdef HAIRBENCH_HAS_VULKAN
#include "kernels/vulkan/runtime.h"
#endif

#include <cstdio>
#include <iostream>
#include <regex>
#include <string>
#include <thread>
#include <vector>

namespace hairbench {
namespace {

constexpr const char* kUsage = R"(usage:
  hairbench list models|scenarios|devices
  hairbench compare [--scenario NAME|PATH]... [--models REGEX] [--reference MODEL]
                    [--frames N] [--threads N] [--set MODEL.NAME=VALUE]... [--out DIR]
                    [--device NAME|INDEX]

compare runs every selected model in lockstep on each scenario (default: every built-in
scenario) and writes DIR/report.json (default DIR: reports/out/latest).
  --models REGEX     models whose whole name matches (default: all)
  --reference MODEL  deviation is measured against MODEL (default: the scenario's, han_m1)
  --set M.NAME=V     parameter override; M may be * for every model that has NAME
  --device D         Vulkan device of the *_vk models, by index or name (see list
                     devices; default: the first discrete GPU, else any device)
exit codes: 0 done (unstable models are results, not errors), 2 bad arguments or files)";

struct CompareArgs {
  std::vector<std::string> scenarios;
  std::string models = ".*";
  bool models_given = false;
  std::vector<std::string> skipped;  // models left out, and why (printed once the inputs are good)
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

CompareArgs parse_compare(const std::vector<std::string>& args) {
  CompareArgs a;
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
    else throw InputError("arguments", flag, "unknown option (see hairbench --help)");
  }
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
    if (why.empty()) a.run.models.emplace_back(m.name);
    else if (a.models_given) throw InputError("arguments", "--models", std::string(m.name) + " cannot run: " + why);
    else a.skipped.push_back(std::string(m.name) + ": " + why);
  }
  if (a.run.models.empty()) throw InputError("arguments", "--models", "'" + a.models + "' matches no model");
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
  for (const std::string& why : a.skipped) std::fprintf(stderr, "hairbench: skipped model %s\n", why.c_str());

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

int cmd_list(const std::vector<std::string>& args) {
  if (args.size() != 1)
    throw InputError("arguments", "list", "expected `list models`, `list scenarios` or `list devices`");
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
  if (cmd == "list") return cmd_list(args);
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
