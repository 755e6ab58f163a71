// Sharded runs (docs/sharding.md): shards run as separate processes and merged give the
// runs of the unsharded command, bit for bit; merge refuses what cannot make one sound
// report, each with its one-line message and exit code 2.
#include "cli_support.h"
#include "git_sha.h"
#include "harness/shard.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <unistd.h>
#include <fstream>
#include <regex>
#include <set>
#include <string>
#include <vector>

namespace {

namespace fs = std::filesystem;
using hairbench::test::run_cli;
using nlohmann::json;

const std::string kTinyShake = std::string(HAIRBENCH_TEST_DATA_DIR) + "/reports/tiny_shake.json";
// Two batches (knob values) of two models, one of them the reference at its own
// parameters in the first batch: the reference lane is shared there and run by every
// shard that runs part of a batch.
std::string sweep_of(const std::string& scenario) {
  return "sweep --scenario \"" + scenario +
         "\" --models 'han_m[12]' --knob local_iterations=1,3 --frames 20 --threads 2 --no-charts";
}
const std::string kSweep = sweep_of(kTinyShake);

json read(const fs::path& file) {
  std::ifstream in(file);
  return json::parse(in);
}

void write(const fs::path& file, const json& j) { std::ofstream(file) << j.dump(1); }

fs::path fresh_dir(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / name;
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

// A run without what depends on the machine and the moment: its timings, its step
// times and the shard that ran it.
json without_timing(json run) {
  run.erase("timing");
  run.erase("shard");
  run["series"].erase("step_ms");
  return run;
}

// The unsharded sweep and its three shards, each its own process, once for the tests
// below.
class Shards : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    // Per process: ctest runs each test of the suite in its own process, in parallel.
    dir_ = fresh_dir("hairbench-shard-test-" + std::to_string(getpid()));
    ASSERT_EQ(run_cli(kSweep + " --out " + (dir_ / "full").string()).code, 0);
    for (int i = 1; i <= 3; ++i) {
      const hairbench::test::CliResult r =
          run_cli(kSweep + " --shard " + std::to_string(i) + "/3 --out " + (dir_ / (std::string("s") + std::to_string(i))).string());
      ASSERT_EQ(r.code, 0) << r.out;
    }
  }
  static std::string shard(int i) { return (dir_ / (std::string("s") + std::to_string(i)) / "report.json").string(); }
  static inline fs::path dir_;
};

TEST_F(Shards, MergedEqualsTheUnshardedSweep) {
  const hairbench::test::CliResult r =
      run_cli("merge " + (dir_ / "merged").string() + " --no-charts " + shard(3) + " " + shard(1) + " " + shard(2));
  ASSERT_EQ(r.code, 0) << r.out;
  const json full = read(dir_ / "full" / "report.json"), merged = read(dir_ / "merged" / "report.json");
  ASSERT_EQ(merged["runs"].size(), full["runs"].size());
  ASSERT_EQ(full["runs"].size(), 4u);
  std::set<int> shards;
  for (std::size_t i = 0; i < full["runs"].size(); ++i) {
    const json& a = full["runs"][i];
    const json& b = merged["runs"][i];
    EXPECT_EQ(b["metrics"]["state_hash"], a["metrics"]["state_hash"]) << a["model"] << " " << a["knob"];
    EXPECT_EQ(without_timing(b), without_timing(a)) << a["model"] << " " << a["knob"];
    shards.insert(b["shard"].get<int>());
  }
  EXPECT_EQ(shards.size(), 3u);  // the plan gave each shard a run
  EXPECT_EQ(merged["scenarios"], full["scenarios"]);
  EXPECT_EQ(merged["sweep"], full["sweep"]);
  EXPECT_FALSE(merged.contains("shard"));
  // Every shard's context is kept, and they name one machine (this one).
  ASSERT_EQ(merged["merge"]["shards"].size(), 3u);
  EXPECT_EQ(merged["merge"]["machines"].size(), 1u);
  for (const json& s : merged["merge"]["shards"]) EXPECT_EQ(s["context"]["git_sha"], HAIRBENCH_GIT_SHA);
}

// Each shard ran the reference itself, and got the bits of the unsharded run.
TEST_F(Shards, EveryShardRunsTheSameReference) {
  const std::string ref = read(dir_ / "full" / "report.json")["scenarios"][0]["reference_state_hash"];
  EXPECT_EQ(ref.size(), 16u);
  for (int i = 1; i <= 3; ++i) EXPECT_EQ(read(shard(i))["scenarios"][0]["reference_state_hash"], ref) << i;
}

// The charts of a merged report: one machine, so the panels are not split.
TEST_F(Shards, MergedReportHasItsCharts) {
  const hairbench::test::CliResult r =
      run_cli("merge " + (dir_ / "charts").string() + " " + shard(1) + " " + shard(2) + " " + shard(3));
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_TRUE(fs::exists(dir_ / "charts" / "report.html"));
  const json manifest = read(dir_ / "charts" / "report_charts.json");
  ASSERT_EQ(manifest["charts"]["time_vs_error"]["panels"].size(), 1u);
  EXPECT_TRUE(manifest["charts"]["time_vs_error"]["panels"][0]["machine"].is_null());
}

// Two machines: without --mix-machines a chart panel holds one machine's times; with it
// one panel, marked.
TEST_F(Shards, TimesFromTwoMachinesAreChartedApart) {
  json other = read(shard(2));
  other["context"]["host"] = "another-host";
  write(dir_ / "other_host.json", other);
  const std::string files = " " + shard(1) + " " + (dir_ / "other_host.json").string() + " " + shard(3);
  ASSERT_EQ(run_cli("merge " + (dir_ / "apart").string() + files).code, 0);
  const json apart = read(dir_ / "apart" / "report_charts.json")["charts"]["time_vs_error"]["panels"];
  ASSERT_EQ(apart.size(), 2u);
  for (const json& p : apart) {
    EXPECT_FALSE(p["machine"].is_null());
    EXPECT_FALSE(p["mixed_machines"].get<bool>());
  }
  ASSERT_EQ(run_cli("merge " + (dir_ / "mixed").string() + " --mix-machines" + files).code, 0);
  const json mixed = read(dir_ / "mixed" / "report_charts.json")["charts"]["time_vs_error"]["panels"];
  ASSERT_EQ(mixed.size(), 1u);
  EXPECT_TRUE(mixed[0]["mixed_machines"].get<bool>());
  EXPECT_TRUE(read(dir_ / "mixed" / "report.json")["merge"]["mix_machines"].get<bool>());
}

// merge's refusals: exit 2, one line, nothing written.
void expect_refused(const std::string& args, const std::string& expected) {
  const hairbench::test::CliResult r = run_cli("merge " + args);
  EXPECT_EQ(r.code, 2) << args << ": " << r.out;
  EXPECT_EQ(r.out, "hairbench: " + expected + "\n") << args;
}

TEST_F(Shards, MissingShardIsRefusedNamingItsRuns) {
  // The plan says which runs shard 2 holds; the message names each of them.
  std::vector<std::string> missing;
  const json first = read(shard(1));
  for (const json& p : first["shard"]["plan"])
    if (p["shard"] == 2) missing.push_back(p["key"]);
  ASSERT_FALSE(missing.empty());
  std::string names;
  for (const std::string& m : missing) names += (names.empty() ? "" : ", ") + m;
  expect_refused((dir_ / "m").string() + " " + shard(1) + " " + shard(3),
                 "merge: runs: " + std::to_string(missing.size()) +
                     " of 4 runs of the plan are missing, from shard 2/3 (not given): " + names);
  EXPECT_FALSE(fs::exists(dir_ / "m"));
}

TEST_F(Shards, ShardOfAnotherBuildIsRefused) {
  json other = read(shard(2));
  other["context"]["git_sha"] = "0123456789ab";
  const fs::path f = dir_ / "other_build.json";
  write(f, other);
  expect_refused((dir_ / "m").string() + " " + shard(1) + " " + f.string() + " " + shard(3),
                 f.string() + ": context.git_sha: 0123456789ab differs from " + HAIRBENCH_GIT_SHA + " in " + shard(1) +
                     ": shards of different builds cannot be merged");
}

// A shard run on an edited copy of the scenario (same name, another amplitude).
TEST_F(Shards, TamperedScenarioIsRefused) {
  std::ifstream in(kTinyShake);
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::string edited = std::regex_replace(text, std::regex("\"amplitude_deg\": *[0-9.]+"), "\"amplitude_deg\": 31");
  ASSERT_NE(edited, text);
  const fs::path copy = dir_ / "tiny_shake.json";
  std::ofstream(copy) << edited;
  ASSERT_EQ(run_cli(sweep_of(copy.string()) + " --shard 2/3 --out " + (dir_ / "tampered").string()).code, 0);
  const std::string t = (dir_ / "tampered" / "report.json").string();
  const std::string ours = read(shard(1))["scenarios"][0]["definition_hash"];
  const std::string theirs = read(t)["scenarios"][0]["definition_hash"];
  ASSERT_NE(ours, theirs);
  expect_refused((dir_ / "m").string() + " " + shard(1) + " " + t + " " + shard(3),
                 t + ": scenarios[tiny_shake].definition_hash: " + theirs + " differs from " + ours + " in " + shard(1) +
                     ": a different scenario definition (its file, --frames, --set or --reference)");
}

TEST_F(Shards, DifferentReferenceBitsAreRefused) {
  json other = read(shard(3));
  other["scenarios"][0]["reference_state_hash"] = "0000000000000000";
  const fs::path f = dir_ / "other_reference.json";
  write(f, other);
  const std::string ours = read(shard(1))["scenarios"][0]["reference_state_hash"];
  expect_refused((dir_ / "m").string() + " " + shard(1) + " " + shard(2) + " " + f.string(),
                 f.string() + ": scenarios[tiny_shake].reference_state_hash: 0000000000000000 differs from " + ours +
                     " in " + shard(1) + ": the reference runs ended in different states");
}

TEST_F(Shards, DuplicatesAreRefused) {
  expect_refused((dir_ / "m").string() + " " + shard(1) + " " + shard(2) + " " + shard(2),
                 shard(2) + ": shard.index: shard 2/3 is also " + shard(2));
  // A run that two shards claim (a shard's report edited to hold another's run).
  json s1 = read(shard(1)), s2 = read(shard(2));
  s2["runs"].push_back(s1["runs"][0]);
  const fs::path f = dir_ / "duplicate_run.json";
  write(f, s2);
  expect_refused((dir_ / "m").string() + " " + shard(1) + " " + f.string() + " " + shard(3),
                 f.string() + ": runs: " + hairbench::run_key(s1["runs"][0]) + " is also in " + shard(1) +
                     ": a duplicate run");
}

TEST_F(Shards, ReportOfAnotherPlanIsRefused) {
  const std::string two = (dir_ / "two").string();
  ASSERT_EQ(run_cli(kSweep + " --shard 1/2 --out " + two).code, 0);
  const hairbench::test::CliResult r = run_cli("merge " + (dir_ / "m").string() + " " + shard(1) + " " + two + "/report.json");
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_NE(r.out.find(two + "/report.json: shard.plan_hash: shard 1/2 of plan "), std::string::npos) << r.out;
  // An unsharded report is no shard.
  const hairbench::test::CliResult full =
      run_cli("merge " + (dir_ / "m").string() + " " + (dir_ / "full" / "report.json").string());
  EXPECT_EQ(full.code, 2);
  EXPECT_NE(full.out.find("full/report.json: shard: missing: not the report of a shard"), std::string::npos) << full.out;
}

// --plan: the run list with each run's shard, the same on every call, and the shards'
// runs are what the plan says.
TEST_F(Shards, PlanIsDeterministicAndIsWhatTheShardsRan) {
  const hairbench::test::CliResult a = run_cli(kSweep + " --shard 1/3 --plan", "", "2>/dev/null");
  const hairbench::test::CliResult b = run_cli(kSweep + " --shard 3/3 --plan", "", "2>/dev/null");
  ASSERT_EQ(a.code, 0);
  EXPECT_EQ(a.out, b.out);
  EXPECT_NE(a.out.find("sweep: 4 runs in 2 batches, 3 shards; costs from the built-in table"), std::string::npos) << a.out;
  for (int i = 1; i <= 3; ++i) {
    const json r = read(shard(i));
    std::set<std::string> planned, ran;
    for (const json& p : r["shard"]["plan"])
      if (p["shard"] == i) planned.insert(p["key"]);
    for (const json& run : r["runs"]) ran.insert(hairbench::run_key(run));
    EXPECT_EQ(ran, planned) << "shard " << i;
    EXPECT_NE(a.out.find("shard " + std::to_string(i) + "/3: " + std::to_string(planned.size()) + " runs"),
              std::string::npos)
        << a.out;
  }
}

// --costs: a previous report's step times replace the table, per run.
TEST_F(Shards, CostsFromAReport) {
  const hairbench::test::CliResult r =
      run_cli(kSweep + " --plan --costs " + (dir_ / "full" / "report.json").string(), "", "2>/dev/null");
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("costs from " + (dir_ / "full" / "report.json").string()), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("costs: run"), std::string::npos) << r.out;
}

TEST(ShardArguments, BadValuesAreOneLineErrors) {
  const std::string none = " --models nothing_matches";
  for (const char* bad : {"0/3", "4/3", "3", "a/b", "1/0", "-1/2", "1/3x"}) {
    const hairbench::test::CliResult r = run_cli("compare --shard " + std::string(bad) + " --frames 1");
    EXPECT_EQ(r.code, 2) << bad << ": " << r.out;
    EXPECT_EQ(r.out, "hairbench: --shard: " + std::string(bad) +
                         ": expected I/N, whole numbers with 1 <= I <= N <= 10000 (e.g. 2/4)\n")
        << bad;
  }
  const std::string sweep = "sweep --models han_m1 --knob local_iterations=1 --plan --scenario \"" + kTinyShake + "\"";
  const hairbench::test::CliResult costs = run_cli(sweep + " --costs /nonexistent/r.json");
  EXPECT_EQ(costs.code, 2);
  EXPECT_EQ(costs.out, "hairbench: --costs: /nonexistent/r.json: cannot read the report\n");
  const hairbench::test::CliResult bad_costs = run_cli(sweep + " --costs \"" + kTinyShake + "\"");
  EXPECT_EQ(bad_costs.code, 2);
  EXPECT_EQ(bad_costs.out, "hairbench: " + kTinyShake + ": schema: not a hairbench-report\n");
  const hairbench::test::CliResult merge = run_cli("merge /tmp/hairbench-merge-none");
  EXPECT_EQ(merge.code, 2);
  EXPECT_EQ(merge.out, "hairbench: arguments: merge: REPORT is required (see hairbench merge --help)\n");
}

// stress --shard: the cells of every axis and the degenerate grooms, merged, are the
// unsharded stress run's.
TEST(StressShards, MergedEqualsUnsharded) {
  const fs::path dir = fresh_dir("hairbench-stress-shard-test");
  const std::string stress = "stress --models han_m3 --axes 'teleport|damping' --keep-every 40 --threads 2 --no-charts";
  ASSERT_EQ(run_cli(stress + " --out " + (dir / "full").string()).code, 0);
  std::string files;
  for (int i = 1; i <= 2; ++i) {
    const std::string out = (dir / (std::string("s") + std::to_string(i))).string();
    ASSERT_EQ(run_cli(stress + " --shard " + std::to_string(i) + "/2 --out " + out).code, 0);
    files += " " + out + "/stress.json";
  }
  const hairbench::test::CliResult r = run_cli("merge " + (dir / "m").string() + " --no-charts" + files);
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_EQ(read(dir / "m" / "stress.json")["stress"], read(dir / "full" / "stress.json")["stress"]);
}

// reproduce --shard cuts whole papers, in turn.
TEST(ReproduceShards, PlanCutsWholePapers) {
  const hairbench::test::CliResult r = run_cli("reproduce all --shard 1/2 --plan", "", "2>/dev/null");
  ASSERT_EQ(r.code, 0);
  EXPECT_EQ(r.out,
            "reproduce: 3 papers, 2 shards; whole papers (no cost estimate: a paper is not a run list)\n"
            "shard 1/2: han2012 plante2001\n"
            "shard 2/2: halen2007\n");
}

// reproduce shards merge into one report: every paper once, in the plan's order, the
// summary counted over all of them; a missing paper and a shard of another frame cap
// are refused.
TEST(ReproduceShards, MergedHoldsEveryPaperOnce) {
  const fs::path dir = fresh_dir("hairbench-reproduce-shard-test");
  const std::string cmd = "reproduce halen2007 plante2001 --threads 2 --no-charts";
  for (int i = 1; i <= 2; ++i) {
    const std::string out = (dir / ("s" + std::to_string(i))).string();
    ASSERT_EQ(run_cli(cmd + " --frames 2 --shard " + std::to_string(i) + "/2 --out " + out, "", "2>/dev/null").code, 0);
  }
  ASSERT_EQ(run_cli(cmd + " --frames 3 --shard 2/2 --out " + (dir / "other_cap").string(), "", "2>/dev/null").code, 0);
  const std::string s1 = (dir / "s1" / "reproduce.json").string(), s2 = (dir / "s2" / "reproduce.json").string();
  const hairbench::test::CliResult r = run_cli("merge " + (dir / "m").string() + " --no-charts " + s2 + " " + s1);
  ASSERT_EQ(r.code, 0) << r.out;
  const json merged = read(dir / "m" / "reproduce.json");
  ASSERT_EQ(merged["papers"].size(), 2u);
  EXPECT_EQ(merged["papers"][0], read(s1)["papers"][0]);
  EXPECT_EQ(merged["papers"][1], read(s2)["papers"][0]);
  for (const char* kind : {"holds", "differs", "not_testable"})
    EXPECT_EQ(merged["summary"]["claims"][kind].get<int>(),
              read(s1)["summary"]["claims"][kind].get<int>() + read(s2)["summary"]["claims"][kind].get<int>())
        << kind;
  EXPECT_TRUE(fs::exists(dir / "m" / "reproduce.html"));

  const hairbench::test::CliResult missing = run_cli("merge " + (dir / "m2").string() + " --no-charts " + s1);
  EXPECT_EQ(missing.code, 2);
  EXPECT_EQ(missing.out,
            "hairbench: merge: runs: 1 of 2 runs of the plan are missing, from shard 2/2 (not given): plante2001 "
            "--frames 2\n");
  const hairbench::test::CliResult cap =
      run_cli("merge " + (dir / "m3").string() + " --no-charts " + s1 + " " + (dir / "other_cap" / "reproduce.json").string());
  EXPECT_EQ(cap.code, 2);
  EXPECT_NE(cap.out.find("shard.plan_hash"), std::string::npos) << cap.out;
}

}  // namespace
