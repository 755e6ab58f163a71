// The plugin ABI through the command line (docs/plugins.md): a library that cannot be
// loaded is one line and exit 2; a plugin model that fails at run time (NaN positions, an
// exception across the boundary, an error status, the wrong vertex count) ends its own run
// as `diverged` with the reason and the other models run on; the default plugin
// (muller_ftl) is in every comparison, and a missing one is one line, not a failure.
#include "cli_support.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <fstream>
#include <string>

namespace {

using hairbench::test::run_cli;
namespace fs = std::filesystem;

const fs::path kPlugins = HAIRBENCH_TEST_PLUGIN_DIR;

std::string plugin(const std::string& name) { return "--plugin \"" + (kPlugins / (name + ".so")).string() + "\""; }

int lines(const std::string& s) { return static_cast<int>(std::count(s.begin(), s.end(), '\n')); }

nlohmann::json read_report(const fs::path& dir) {
  std::ifstream in(dir / "report.json");
  return nlohmann::json::parse(in);
}

const nlohmann::json* find_run(const nlohmann::json& report, const std::string& model) {
  for (const nlohmann::json& r : report["runs"])
    if (r["model"] == model) return &r;
  return nullptr;
}

// A short comparison of `model` beside han_m3 on `idle`; returns the report.
nlohmann::json compare_with(const std::string& model, const std::string& out_name) {
  const fs::path out = fs::temp_directory_path() / out_name;
  fs::remove_all(out);
  const auto r = run_cli("compare --scenario idle --frames 12 --no-charts --models 'han_m3|" + model + "' " +
                         plugin(model) + " --out \"" + out.string() + "\"");
  EXPECT_EQ(r.code, 0) << r.out;
  return read_report(out);
}

TEST(Plugin, AWrongAbiVersionIsOneLineAndExitTwo) {
  const auto r = run_cli("list models " + plugin("faulty_abi"));
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_EQ(lines(r.out), 1) << r.out;
  EXPECT_NE(r.out.find("faulty_abi.so: abi_version: built for plugin ABI 2; this hairbench speaks ABI 1"),
            std::string::npos)
      << r.out;
}

TEST(Plugin, ALibraryWithoutTheEntryPointOrNoFileIsOneLineAndExitTwo) {
  auto r = run_cli("compare --scenario idle --frames 2 --no-charts " + plugin("no_entry"));
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_EQ(lines(r.out), 1) << r.out;
  EXPECT_NE(r.out.find("no_entry.so: hairbench_plugin: no such entry point"), std::string::npos) << r.out;
  r = run_cli("list models " + plugin("no_such_plugin"));
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_EQ(lines(r.out), 1) << r.out;
  EXPECT_NE(r.out.find("no_such_plugin.so: plugin: no such file"), std::string::npos) << r.out;
}

TEST(Plugin, NanPositionsEndTheRunAsDivergedAndTheOthersRunOn) {
  const nlohmann::json report = compare_with("faulty_nan", "hairbench-plugin-nan");
  const nlohmann::json* run = find_run(report, "faulty_nan");
  ASSERT_NE(run, nullptr);
  EXPECT_EQ((*run)["status"], "diverged");
  EXPECT_EQ((*run)["failure"]["frame"], 5);
  EXPECT_EQ((*run)["origin"], (kPlugins / "faulty_nan.so").string());
  const nlohmann::json* other = find_run(report, "han_m3");
  ASSERT_NE(other, nullptr);
  EXPECT_EQ((*other)["status"], "ok");
  EXPECT_EQ((*other)["frames_run"], 12);
  EXPECT_EQ((*other)["origin"], "built-in");
}

// A faulty model's run beside han_m3: `diverged` at `frame`, its reason holding `why`,
// han_m3 ok.
void expect_diverged(const std::string& model, int frame, const std::string& why) {
  const nlohmann::json report = compare_with(model, "hairbench-plugin-" + model);
  const nlohmann::json* run = find_run(report, model);
  ASSERT_NE(run, nullptr);
  EXPECT_EQ((*run)["status"], "diverged");
  EXPECT_EQ((*run)["failure"]["frame"], frame);
  const std::string reason = (*run)["failure"]["reason"];
  EXPECT_NE(reason.find(why), std::string::npos) << reason;
  EXPECT_EQ((*find_run(report, "han_m3"))["status"], "ok");
}

TEST(Plugin, AnExceptionAcrossTheBoundaryIsTheRunsVerdict) {
  expect_diverged("faulty_throw", 5, "step: threw across the ABI boundary: the faulty plugin's planted exception");
}

TEST(Plugin, AnErrorStatusCarriesThePluginsMessage) {
  expect_diverged("faulty_status", 5, "step: the faulty plugin's planted error at frame 5");
}

TEST(Plugin, TheWrongVertexCountEndsTheRunAtItsFirstFrame) {
  expect_diverged("faulty_count", 0, "positions: returned 31999 positions for a groom of 32000 vertices");
}

TEST(Plugin, TheSearchPathLoadsEveryLibraryInAFolder) {
  const fs::path dir = fs::temp_directory_path() / "hairbench-plugin-path";
  fs::remove_all(dir);
  fs::create_directories(dir);
  fs::copy_file(kPlugins / "faulty_nan.so", dir / "faulty_nan.so");
  const auto r = run_cli("list models", "HAIRBENCH_PLUGIN_PATH=\"" + dir.string() + "\" ");
  EXPECT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("faulty_nan"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("[plugin " + (dir / "faulty_nan.so").string() + "]"), std::string::npos) << r.out;
}

TEST(Plugin, TheDefaultComparisonLoadsMullerFtlThroughTheAbi) {
  const auto r = run_cli("list models");
  EXPECT_EQ(r.code, 0) << r.out;
  const fs::path so = fs::path(HAIRBENCH_EXE).parent_path() / "plugins" / "muller_ftl.so";
  EXPECT_NE(r.out.find("[plugin " + so.string() + "]"), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find("not loaded"), std::string::npos) << r.out;
}

// The binary copied where no plugin folder is: the default plugin is left out with one
// line, and the built-in models run.
TEST(Plugin, AMissingDefaultPluginIsOneLineAndTheOthersRun) {
  const fs::path dir = fs::temp_directory_path() / "hairbench-plugin-missing";
  fs::remove_all(dir);
  fs::create_directories(dir / "bin");
  fs::copy_file(HAIRBENCH_EXE, dir / "bin" / "hairbench");
  const std::string exe = "\"" + (dir / "bin" / "hairbench").string() + "\" ";
  const std::string cmd = exe + "compare --scenario idle --frames 4 --no-charts --models han_m3 --out \"" +
                          (dir / "out").string() + "\" 2>&1";
  FILE* p = popen(cmd.c_str(), "r");
  ASSERT_NE(p, nullptr);
  std::string out;
  char buf[4096];
  while (std::fgets(buf, sizeof buf, p)) out += buf;
  EXPECT_EQ(WEXITSTATUS(pclose(p)), 0) << out;
  EXPECT_NE(out.find("hairbench: plugin muller_ftl: not loaded: no muller_ftl.so in " + (dir / "bin" / "plugins").string()),
            std::string::npos)
      << out;
  const nlohmann::json report = read_report(dir / "out");
  ASSERT_EQ(report["context"]["plugins"]["not_loaded"].size(), 1u);
  EXPECT_EQ((*find_run(report, "han_m3"))["status"], "ok");
}

}  // namespace
