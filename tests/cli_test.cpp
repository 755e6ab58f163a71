// The command line's contract: bad files and bad arguments give exit code 2 and one
// line naming what is wrong; good runs write a report that follows the schema.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <sys/wait.h>

namespace {

struct Result {
  int code;
  std::string out;
};

Result run_cli(const std::string& args) {
  const std::string cmd = std::string("\"") + HAIRBENCH_EXE + "\" " + args + " 2>&1";
  Result r{-1, {}};
  FILE* p = popen(cmd.c_str(), "r");
  if (!p) return r;
  char buf[4096];
  while (std::fgets(buf, sizeof buf, p)) r.out += buf;
  const int status = pclose(p);
  r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return r;
}

int count_lines(const std::string& s) {
  int n = 0;
  for (char c : s) n += c == '\n';
  return n;
}

// Every malformed scenario in tests/data/bad: exit 2, one line, naming file and key.
TEST(Cli, BadScenarioFilesAreOneLineErrors) {
  const std::filesystem::path dir = std::filesystem::path(HAIRBENCH_TEST_DATA_DIR) / "bad";
  std::ifstream manifest(dir / "expected.txt");
  ASSERT_TRUE(manifest) << "missing " << (dir / "expected.txt");
  std::string line;
  int cases = 0;
  while (std::getline(manifest, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream is(line);
    std::string file, expected;
    is >> file;
    std::getline(is >> std::ws, expected);
    const Result r = run_cli("compare --frames 1 --scenario \"" + (dir / file).string() + "\" --out /tmp/hairbench-cli-test");
    EXPECT_EQ(r.code, 2) << file << ": " << r.out;
    EXPECT_EQ(count_lines(r.out), 1) << file << ": " << r.out;
    EXPECT_NE(r.out.find(file), std::string::npos) << "message does not name the file: " << r.out;
    EXPECT_NE(r.out.find(expected), std::string::npos) << file << ": expected '" << expected << "' in: " << r.out;
    ++cases;
  }
  EXPECT_GE(cases, 8);
}

TEST(Cli, BadArgumentsExitTwo) {
  for (const char* args : {"compare --set han_m1.damping=2", "compare --set han_m1.nosuch=1",
                           "compare --set nosuch.damping=0.1", "compare --set damping", "compare --frames -3",
                           "compare --models 'nothing_matches'", "compare --models '('", "compare --bogus",
                           "compare --scenario no_such_scenario", "list things", "frobnicate",
                           "compare --set han_m1.local_iterations=2.5", "compare --reference nosuch"}) {
    const Result r = run_cli(args);
    EXPECT_EQ(r.code, 2) << args << ": " << r.out;
    EXPECT_EQ(count_lines(r.out), 1) << args << ": " << r.out;
  }
}

TEST(Cli, ListsModelsAndScenarios) {
  const Result models = run_cli("list models");
  EXPECT_EQ(models.code, 0);
  for (const char* m : {"han_m1", "han_m2", "han_m3"}) EXPECT_NE(models.out.find(m), std::string::npos) << m;
  const Result scenarios = run_cli("list scenarios");
  EXPECT_EQ(scenarios.code, 0);
  for (const char* s : {"idle", "nod", "shake", "spin_fast", "walk", "tilt_upside_down", "wind_gust", "ponytail"})
    EXPECT_NE(scenarios.out.find(s), std::string::npos) << s;
}

// A short compare writes a report with the contract's fields, and --set reaches the
// model (it shows in the run's params).
TEST(Cli, CompareWritesTheReportContract) {
  const std::filesystem::path out = std::filesystem::temp_directory_path() / "hairbench-cli-compare";
  std::filesystem::remove_all(out);
  const Result r = run_cli("compare --scenario shake --models 'han_m[123]' --frames 5 --threads 2 --set han_m2.local_iterations=7 --out " +
                           out.string());
  ASSERT_EQ(r.code, 0) << r.out;
  std::ifstream in(out / "report.json");
  ASSERT_TRUE(in);
  const nlohmann::json j = nlohmann::json::parse(in);
  EXPECT_EQ(j["schema"], "hairbench-report");
  EXPECT_EQ(j["schema_version"], 1);
  for (const char* k : {"date", "git_sha", "host", "cpu", "threads", "build_type", "compiler", "devices"})
    EXPECT_TRUE(j["context"].contains(k)) << k;
  ASSERT_EQ(j["runs"].size(), 3u);
  for (const auto& run : j["runs"]) {
    EXPECT_EQ(run["scenario"], "shake");
    EXPECT_EQ(run["status"], "ok");
    EXPECT_EQ(run["series"]["step_ms"].size(), 5u);
    for (const char* m : {"deviation_vs_reference", "jaggedness", "length_error", "rest_shape_error", "penetration",
                          "state_hash"})
      EXPECT_TRUE(run["metrics"].contains(m)) << m;
    for (const char* s : {"integrate", "global_shape", "local_shape", "length", "collision"})
      EXPECT_TRUE(run["timing"]["stage_ms"].contains(s)) << s;
    EXPECT_EQ(run["metrics"]["state_hash"].get<std::string>().size(), 16u);
  }
  EXPECT_EQ(j["runs"][1]["params"]["local_iterations"], 7);
  EXPECT_NE(j["runs"][0]["params"]["local_iterations"], 7);  // han_m1 keeps its own value
  EXPECT_EQ(j["runs"][0]["metrics"]["deviation_vs_reference"]["max"], 0.0);
}

}  // namespace
