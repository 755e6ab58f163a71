// The command line's contract: bad files and bad arguments give exit code 2 and one
// line naming what is wrong; good runs write a report that follows the schema.
#include "cli_support.h"
#include "git_sha.h"
#include "reports/report.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cstdio>
#include <filesystem>
#include <cmath>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

namespace {

using hairbench::test::run_cli;

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
    const hairbench::test::CliResult r = run_cli("compare --frames 1 --scenario \"" + (dir / file).string() + "\" --out /tmp/hairbench-cli-test");
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
    const hairbench::test::CliResult r = run_cli(args);
    EXPECT_EQ(r.code, 2) << args << ": " << r.out;
    EXPECT_EQ(count_lines(r.out), 1) << args << ": " << r.out;
  }
}

// --version prints the commit the binary was built from, on standard output.
TEST(Cli, VersionNamesTheBuiltCommit) {
  const hairbench::test::CliResult r = run_cli("--version", "", "2>/dev/null");
  EXPECT_EQ(r.code, 0);
  EXPECT_EQ(r.out, std::string("hairbench ") + HAIRBENCH_GIT_SHA + "\n");
}

// `hairbench --help` and `hairbench SUB --help` (and -h): usage on standard output, exit
// 0, naming every option of that subcommand and none that only another one takes.
TEST(Cli, HelpNamesEveryOption) {
  const std::vector<std::string> run_options = {"--scenario", "--models",  "--reference", "--frames", "--threads",
                                                "--set",      "--out",     "--no-charts", "--device", "--no-skip",
                                                "--shard",    "--plan",    "--costs",     "--preset",  "--calibrate",
                                                "--plugin"};
  std::vector<std::string> sweep_options = run_options;
  sweep_options.push_back("--knob");
  struct Help {
    std::string sub;
    std::vector<std::string> names, absent;
  };
  const std::vector<Help> cases = {
      {"", {"--help", "--version", "list", "compare", "sweep", "stress", "merge", "reproduce", "precision"}, {"--frames"}},
      {"list", {"--help", "models|compared|scenarios|presets|devices", "--plugin"}, {"--out"}},
      {"compare", run_options, {"--knob", "--quick"}},
      {"sweep", sweep_options, {"--quick", "--keep-every"}},
      {"stress",
       {"--models", "--base", "--axes", "--keep-every", "--quick", "--threads", "--out", "--no-charts", "--shard",
        "--plan", "--costs", "--plugin"},
       {"--scenario", "--set", "--knob", "--preset"}},
      {"merge", {"OUT_DIR", "REPORT.json", "--mix-machines", "--no-charts"}, {"--frames", "--models", "--costs", "--plugin"}},
      {"precision",
       {"--scenario", "--models", "--reference", "--keep-every", "--frames", "--threads", "--set", "--out",
        "--no-charts", "--plugin"},
       {"--knob", "--shard", "--device"}},
      {"reproduce",
       {"han2012", "halen2007", "plante2001", "all", "--frames", "--threads", "--device", "--out", "--shard", "--plan"},
       {"--models", "--set", "--costs", "--plugin"}}};
  for (const Help& h : cases)
    for (const char* flag : {"--help", "-h"}) {
      const std::string args = h.sub + " " + flag;
      const hairbench::test::CliResult r = run_cli(args, "", "2>/dev/null");
      EXPECT_EQ(r.code, 0) << args << ": " << r.out;
      EXPECT_NE(r.out.find("Usage: hairbench " + h.sub), std::string::npos) << args << ": " << r.out;
      for (const std::string& name : h.names) EXPECT_NE(r.out.find(name), std::string::npos) << args << ": " << name;
      for (const std::string& name : h.absent) EXPECT_EQ(r.out.find(name), std::string::npos) << args << ": " << name;
    }
  // No subcommand at all: the usage, and the exit code of a bad command line; `help`
  // prints the same and succeeds.
  const hairbench::test::CliResult bare = run_cli("", "", "2>/dev/null");
  EXPECT_EQ(bare.code, 2);
  EXPECT_NE(bare.out.find("Usage: hairbench"), std::string::npos) << bare.out;
  const hairbench::test::CliResult help = run_cli("help", "", "2>/dev/null");
  EXPECT_EQ(help.code, 0);
  EXPECT_EQ(help.out, bare.out);
}

// A bad command line: exit 2 and one line on standard error, nothing on standard output,
// naming the offending option or argument. --models nothing_matches makes a case that
// wrongly parsed fail at once, with another message, instead of running.
TEST(Cli, ArgumentErrorsNameTheOption) {
  const std::string none = " --models nothing_matches";
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"compare --bogus" + none, "arguments: --bogus: unknown option (see hairbench compare --help)"},
      {"stress --quick --bogus 3" + none, "arguments: --bogus: unknown option"},
      {"compare --frames abc" + none, "arguments: --frames: 'abc' is not a whole number in [1, 10000000]"},
      {"stress --threads -1" + none, "arguments: --threads: '-1' is not a whole number in [1, 1024]"},
      {"stress --keep-every 0" + none, "arguments: --keep-every: '0' is not a whole number"},
      {"reproduce all --frames 1.5", "arguments: --frames: '1.5' is not a whole number"},
      {"compare" + none + " --threads", "arguments: --threads: needs a value"},
      {"reproduce plante2001 --out", "arguments: --out: needs a value"},
      {"sweep --scenario shake" + none, "arguments: sweep: --knob is required"},
      {"stress --quick=1" + none, "arguments: --quick: takes no value"},
      {"compare shake" + none, "arguments: shake: unexpected argument"},
      {"frobnicate", "arguments: frobnicate: unknown subcommand (see hairbench --help)"}};
  for (const auto& [args, expected] : cases) {
    const hairbench::test::CliResult r = run_cli(args);
    EXPECT_EQ(r.code, 2) << args << ": " << r.out;
    EXPECT_EQ(count_lines(r.out), 1) << args << ": " << r.out;
    EXPECT_EQ(r.out.rfind("hairbench: " + expected, 0), 0u) << args << ": " << r.out;
    EXPECT_EQ(run_cli(args, "", "2>/dev/null").out, "") << args;
  }
}

TEST(Cli, ListsModelsAndScenarios) {
  const hairbench::test::CliResult models = run_cli("list models");
  EXPECT_EQ(models.code, 0);
  for (const char* m : {"han_m1", "han_m2", "han_m3"}) EXPECT_NE(models.out.find(m), std::string::npos) << m;
  // A reference implementation says which model it checks and how closely (ModelInfo).
  EXPECT_NE(models.out.find("the reference for han_m1 (same bits)"), std::string::npos) << models.out;
  EXPECT_NE(models.out.find("the reference for halen_forest (to rounding)"), std::string::npos) << models.out;
  const hairbench::test::CliResult scenarios = run_cli("list scenarios");
  EXPECT_EQ(scenarios.code, 0);
  for (const char* s : {"idle", "nod", "shake", "spin_fast", "walk", "tilt_upside_down", "wind_gust", "ponytail"})
    EXPECT_NE(scenarios.out.find(s), std::string::npos) << s;
}

// A preset stands for the --sets of a paper's force law as written (list presets prints
// them): the report's parameters are the thesis cascade's, a --set after it still wins,
// and an unknown preset is a one-line error naming the option.
TEST(Cli, PresetsSetThePapersLawsAndAreListed) {
  const hairbench::test::CliResult list = run_cli("list presets");
  EXPECT_EQ(list.code, 0);
  for (const char* p : {"halen2007", "halen2007_forest", "halen2007_cascade", "plante2001",
                        "--set halen_cascade.reactions=0", "--set plante_wisp.bending=0"})
    EXPECT_NE(list.out.find(p), std::string::npos) << p << "\n" << list.out;
  const std::filesystem::path out = std::filesystem::temp_directory_path() / "hairbench-cli-preset";
  std::filesystem::remove_all(out);
  const hairbench::test::CliResult r =
      run_cli("compare --scenario shake --models halen_cascade --frames 1 --no-charts --preset halen2007 "
              "--set halen_cascade.frames=1 --out " + out.string());
  ASSERT_EQ(r.code, 0) << r.out;
  std::ifstream in(out / "report.json");
  const nlohmann::json report = nlohmann::json::parse(in);
  bool found = false;
  for (const auto& run : report["runs"]) {
    if (run["model"] != "halen_cascade") continue;
    found = true;
    EXPECT_EQ(run["params"]["reactions"], 0.0);
    EXPECT_EQ(run["params"]["frames"], 1.0) << "a --set after the preset wins";
  }
  EXPECT_TRUE(found);
  const hairbench::test::CliResult bad = run_cli("compare --scenario shake --preset nope --frames 1 --no-charts");
  EXPECT_EQ(bad.code, 2);
  EXPECT_NE(bad.out.find("--preset: nope: unknown preset"), std::string::npos) << bad.out;
}

// The report names the commit the binary was built from, as recorded at build time (not
// one seen at an earlier configure, nor the checkout's HEAD at run time); it needs no git
// at run time (none on PATH here).
TEST(Cli, ReportNamesTheBuiltCommit) {
  const std::filesystem::path out = std::filesystem::temp_directory_path() / "hairbench-cli-nogit";
  std::filesystem::remove_all(out);
  const hairbench::test::CliResult r =
      run_cli("compare --scenario shake --models han_m3 --frames 1 --no-charts --out " + out.string(),
              "PATH=/nonexistent ");
  ASSERT_EQ(r.code, 0) << r.out;
  std::ifstream in(out / "report.json");
  ASSERT_TRUE(in);
  const std::string sha = nlohmann::json::parse(in)["context"]["git_sha"];
  EXPECT_EQ(sha, HAIRBENCH_GIT_SHA);
  EXPECT_EQ(sha.size(), 12u) << sha;  // this checkout has git: a commit, not "unknown"
}

// A short compare writes a report with the contract's fields, and --set reaches the
// model (it shows in the run's params).
TEST(Cli, CompareWritesTheReportContract) {
  const std::filesystem::path out = std::filesystem::temp_directory_path() / "hairbench-cli-compare";
  std::filesystem::remove_all(out);
  // Han's three methods: the stage names below are theirs (other models name their own).
  const hairbench::test::CliResult r = run_cli("compare --scenario shake --models 'han_m[123]' --frames 5 --threads 2 "
                           "--set han_m2.local_iterations=7 --out " + out.string());
  ASSERT_EQ(r.code, 0) << r.out;
  std::ifstream in(out / "report.json");
  ASSERT_TRUE(in);
  const nlohmann::json j = nlohmann::json::parse(in);
  EXPECT_EQ(j["schema"], "hairbench-report");
  EXPECT_EQ(j["schema_version"], 3);
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
    // The state a step touches holds at least the positions (float4) and the
    // previous positions (xyz); the ratio to its streaming time is reported.
    EXPECT_GE(run["timing"]["state_bytes"].get<double>(), 28.0 * run["groom"]["vertices"].get<double>());
    EXPECT_GT(run["timing"]["roofline_ratio"].get<double>(), 0.0);
  }
  EXPECT_EQ(j["runs"][1]["params"]["local_iterations"], 7);
  EXPECT_NE(j["runs"][0]["params"]["local_iterations"], 7);  // han_m1 keeps its own value
  EXPECT_EQ(j["runs"][0]["metrics"]["deviation_vs_reference"]["max"], 0.0);
}

nlohmann::json read_report(const std::filesystem::path& dir) {
  std::ifstream in(dir / "report.json");
  return nlohmann::json::parse(in);
}

const std::string kTinyShake = std::string(HAIRBENCH_TEST_DATA_DIR) + "/reports/tiny_shake.json";

TEST(Cli, SweepBadArgumentsExitTwo) {
  const std::string sc = " --scenario \"" + kTinyShake + "\" --no-charts --out /tmp/hairbench-cli-sweep-bad";
  for (const std::string& args :
       {std::string("sweep --knob local_iterations=1"), "sweep" + sc, "sweep" + sc + " --knob local_iterations=",
        "sweep" + sc + " --knob local_iterations=1,x", "sweep" + sc + " --knob local_iterations=1,1",
        "sweep" + sc + " --knob local_iterations=300", "sweep" + sc + " --knob nosuch=1",
        "sweep" + sc + " --knob local_iterations=1.5", "sweep" + sc + " --knob =1",
        "sweep" + sc + " --knob local_iterations=1 --knob substeps=2",
        "sweep" + sc + " --knob local_iterations=1 --reference bogus",
        "compare" + sc + " --knob local_iterations=1", std::string("precision --models han_m1"),
        "precision" + sc + " --reference exact", "precision" + sc + " --reference bogus",
        "precision" + sc + " --models nosuch", "precision" + sc + " --set han_m1.nosuch=1"}) {
    const hairbench::test::CliResult r = run_cli(args);
    EXPECT_EQ(r.code, 2) << args << ": " << r.out;
    EXPECT_EQ(count_lines(r.out), 1) << args << ": " << r.out;
  }
}

// Strand-snapshot deviation, recomputed from the report's positions: RMS over the
// snapshot vertices of |p - p_ref| / L-bar.
double snapshot_deviation(const nlohmann::json& snap, const nlohmann::json& ref, double lbar) {
  const nlohmann::json& strands = snap["strands"];
  double sum = 0.0;
  std::size_t n = 0;
  for (std::size_t s = 0; s < strands.size(); ++s) {
    const std::vector<double> q = hairbench::decode_snapshot_strand(ref[s].get<std::string>());
    const std::vector<double> p = hairbench::decode_snapshot_strand(
        strands[s].get<std::string>(), snap.value("relative_to_reference", false) ? &q : nullptr);
    for (std::size_t i = 0; i + 2 < p.size(); i += 3, ++n) {
      double d2 = 0.0;
      for (int k = 0; k < 3; ++k) {
        const double d = p[i + k] - q[i + k];
        d2 += d * d;
      }
      sum += d2;
    }
  }
  return std::sqrt(sum / static_cast<double>(n)) / lbar;
}

// A sweep: every model at every knob value, each run carrying its value; the reference
// is han_m1 at the scenario's parameters, so han_m1 at that value is the reference
// itself (deviation exactly 0) and other values are not. The snapshots agree with the
// deviation series, and the phases come from the head script.
TEST(Cli, SweepRecordsKnobsPhasesAndSnapshots) {
  const std::filesystem::path out = std::filesystem::temp_directory_path() / "hairbench-cli-sweep";
  std::filesystem::remove_all(out);
  const hairbench::test::CliResult r = run_cli("sweep --scenario \"" + kTinyShake +
                           "\" --models 'han_m[12]' --knob local_iterations=1,3 --frames 30 --threads 2 --no-charts --out " +
                           out.string());
  ASSERT_EQ(r.code, 0) << r.out;
  const nlohmann::json j = read_report(out);
  EXPECT_EQ(j["sweep"]["knob"], "local_iterations");
  ASSERT_EQ(j["runs"].size(), 4u);
  std::map<std::string, double> dev;
  for (const auto& run : j["runs"]) {
    ASSERT_TRUE(run.contains("knob"));
    EXPECT_EQ(run["knob"]["name"], "local_iterations");
    EXPECT_EQ(run["params"]["local_iterations"], run["knob"]["value"]);
    dev[run["model"].get<std::string>() + "@" + run["knob"]["value"].dump()] =
        run["metrics"]["deviation_vs_reference"]["max"].get<double>();
  }
  EXPECT_EQ(dev.at("han_m1@1.0"), 0.0);
  EXPECT_GT(dev.at("han_m1@3.0"), 0.0);
  EXPECT_GT(dev.at("han_m2@1.0"), 0.0);

  ASSERT_EQ(j["scenarios"].size(), 1u);
  const auto& sc = j["scenarios"][0];
  ASSERT_EQ(sc["phases"].size(), 1u);  // the oscillator, 0 to 0.4 s
  EXPECT_EQ(sc["phases"][0]["kind"], "oscillate");
  EXPECT_NEAR(sc["phases"][0]["end"].get<double>(), 0.4, 1e-9);
  const auto& snaps = sc["snapshots"];
  EXPECT_EQ(snaps["strands"].size(), 24u);  // every strand of a groom under 200
  ASSERT_EQ(snaps["frames"].size(), 2u);
  EXPECT_EQ(snaps["frames"][0]["label"], "most_violent");
  EXPECT_GT(snaps["frames"][0]["violence"].get<double>(), 0.0);
  EXPECT_EQ(snaps["frames"][1]["frame"], 29);
  const double lbar = sc["mean_strand_length"].get<double>();
  const auto& ref = snaps["reference"]["snapshots"];
  for (const auto& run : j["runs"]) {
    ASSERT_EQ(run["snapshots"].size(), 2u);
    for (int k = 0; k < 2; ++k) {
      const int frame = snaps["frames"][k]["frame"].get<int>();
      EXPECT_EQ(run["snapshots"][k]["frame"], frame);
      // Positions are rounded to 10 micrometres in the report.
      EXPECT_NEAR(snapshot_deviation(run["snapshots"][k], ref[k]["strands"], lbar),
                  run["series"]["deviation_vs_reference"][frame].get<double>(), 1e-4)
          << run["model"] << " frame " << frame;
    }
  }
}

// --reference converged: han_m1 iterated to convergence, so method 1 at the scenario's
// parameters has an error of its own, and the report says what the reference was.
TEST(Cli, ConvergedReferenceMeasuresMethodOneToo) {
  const std::filesystem::path out = std::filesystem::temp_directory_path() / "hairbench-cli-converged";
  std::filesystem::remove_all(out);
  const hairbench::test::CliResult r = run_cli("sweep --scenario \"" + kTinyShake +
                           "\" --models han_m1 --knob local_iterations=1 --reference converged --frames 20 --no-charts --out " +
                           out.string());
  ASSERT_EQ(r.code, 0) << r.out;
  const nlohmann::json j = read_report(out);
  ASSERT_EQ(j["runs"].size(), 1u);
  const auto& d = j["runs"][0]["metrics"]["deviation_vs_reference"];
  EXPECT_GT(d["max"].get<double>(), 0.0);
  EXPECT_EQ(d["reference_overrides"]["local_iterations"], 32);
  EXPECT_EQ(d["reference_overrides"]["length_iterations"], 32);
  EXPECT_EQ(d["reference_overrides"]["substeps"], 4);
}

// Without a usable interpreter the report is still written, exit 0, and the CLI says
// what to install and the command that draws the charts later.
TEST(Cli, ChartStepSaysHowToDrawLater) {
  const std::filesystem::path out = std::filesystem::temp_directory_path() / "hairbench-cli-nocharts";
  std::filesystem::remove_all(out);
  const hairbench::test::CliResult r = run_cli("compare --scenario \"" + kTinyShake + "\" --models han_m3 --frames 3 --out " + out.string(),
                           "HAIRBENCH_PYTHON=/nonexistent/python3 ");
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_TRUE(std::filesystem::exists(out / "report.json"));
  EXPECT_NE(r.out.find("python3-matplotlib"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("charts.py " + (out / "report.json").string()), std::string::npos) << r.out;
}


// ---- compare --groom and scenario new (docs/groom-import.md) ---------------------------

const std::string kMohawkTfx = std::string(HAIRBENCH_ASSET_DIR) + "/ratboy_mohawk_v4.0/Ratboy_mohawk.tfx";
const std::string kTestHair1 = std::string(HAIRBENCH_ASSET_DIR) + "/testhair1/TestHair1.tfxproj";

// Every refusal of a groom run: exit 2, one line that names what is wrong, and nothing
// written.
TEST(Cli, GroomErrorsAreOneLine) {
  const std::string out = " --out /tmp/hairbench-cli-groom-bad";
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"compare --groom /no/such/groom.tfx" + out, "--groom: /no/such/groom.tfx: no such file"},
      {"compare --groom " + kMohawkTfx + " --scenario shake" + out,
       "arguments: --groom: give either --groom or --scenario, not both"},
      {"compare --motion shake --models han_m1" + out, "arguments: --motion: applies to --groom only"},
      {"compare --unit cm --models han_m1" + out, "arguments: --unit: applies to --groom only"},
      {"compare --groom " + kMohawkTfx + " --unit furlong" + out, "arguments: --unit: 'furlong' is not cm, mm, m or auto"},
      {"compare --groom " + kMohawkTfx + " --motion moonwalk" + out, "--motion: moonwalk: not a built-in scenario"},
      // All the mohawk's roots (down the neck) fit a head in mm; its strands are hair in cm.
      {"compare --groom " + kMohawkTfx + " --fit-above -1000" + out,
       kMohawkTfx + ": unit: cannot tell the unit: no unit fits every cue"},
      {"compare --groom " + std::string(HAIRBENCH_TEST_DATA_DIR) + "/reports/tiny_shake.json" + out,
       "expected a TressFX .tfx or .tfxproj file"},
      {"scenario new --groom /no/such/groom.tfx --out /tmp/hairbench-cli-groom.json",
       "--groom: /no/such/groom.tfx: no such file"},
      {"scenario new --groom " + kMohawkTfx + " --out /tmp/hairbench-cli-groom.txt",
       "--out: /tmp/hairbench-cli-groom.txt: expected a .json file name"},
      {"scenario new --groom " + kMohawkTfx + " --fit-above -1000 --out /tmp/hairbench-cli-groom.json",
       "unit: cannot tell the unit"}};
  std::filesystem::remove("/tmp/hairbench-cli-groom.json");
  for (const auto& [args, expected] : cases) {
    const hairbench::test::CliResult r = run_cli(args);
    EXPECT_EQ(r.code, 2) << args << ": " << r.out;
    EXPECT_EQ(count_lines(r.out), 1) << args << ": " << r.out;
    EXPECT_NE(r.out.find(expected), std::string::npos) << args << ": expected '" << expected << "' in: " << r.out;
    EXPECT_EQ(r.out.rfind("hairbench: ", 0), 0u) << r.out;
  }
  // A refused unit says how to give it.
  EXPECT_NE(run_cli("compare --groom " + kMohawkTfx + " --fit-above -1000" + out).out.find("--unit"), std::string::npos);
  EXPECT_FALSE(std::filesystem::exists("/tmp/hairbench-cli-groom.json"));
}

// compare --groom with no scenario file prints what it fitted and runs; substeps are
// picked from the groom unless a number is given, which wins; scenario new writes the
// same as a file that compare --scenario runs.
TEST(Cli, CompareGroomFitsRunsAndScenarioNewWrites) {
  const std::filesystem::path out = std::filesystem::temp_directory_path() / "hairbench-cli-groom";
  std::filesystem::remove_all(out);
  std::filesystem::create_directories(out);
  const std::string run = "compare --groom " + kTestHair1 +
                          " --motion shake --models 'han_m1|halen_spring' --frames 2 --threads 2 --no-charts";
  const hairbench::test::CliResult r = run_cli(run + " --out " + (out / "auto").string());
  ASSERT_EQ(r.code, 0) << r.out;
  for (const char* line : {"unit cm (guessed: median strand 11 file units = 0.11 m", "pivot [5.326, 10.65, -1.855]",
                           "not a scalp", "head radius", "colliders: r", "repairs:", "substeps ", "(auto; ",
                           "time: load", "the models' probes"})
    EXPECT_NE(r.out.find(line), std::string::npos) << line << " in: " << r.out;
  const nlohmann::json a = read_report(out / "auto");
  ASSERT_EQ(a["runs"].size(), 2u);
  // Each model's probe at rest ran outside its timed steps, and is timed on its own.
  for (const auto& run_json : a["runs"]) {
    EXPECT_GT(run_json["timing"]["overhead_s"]["probe"].get<double>(), 0.0) << run_json["model"];
    EXPECT_GT(run_json["timing"]["overhead_s"]["setup"].get<double>(), 0.0) << run_json["model"];
  }
  EXPECT_EQ(a["runs"][1]["model"], "halen_spring");
  EXPECT_EQ(a["runs"][1]["substeps"]["source"], "auto");
  EXPECT_GE(a["runs"][1]["substeps"]["value"].get<int>(), 6);  // never under the model's default
  EXPECT_EQ(a["scenarios"][0]["groom"]["unit"], "cm");
  EXPECT_EQ(a["scenarios"][0]["groom"]["fit"]["scalp"], false);

  // A number given with --set wins over the bound, even a smaller one.
  const hairbench::test::CliResult given =
      run_cli(run + " --set halen_spring.substeps=3 --out " + (out / "given").string());
  ASSERT_EQ(given.code, 0) << given.out;
  const nlohmann::json g = read_report(out / "given");
  EXPECT_EQ(g["runs"][1]["substeps"]["source"], "given");
  EXPECT_EQ(g["runs"][1]["substeps"]["value"], 3);
  EXPECT_EQ(g["runs"][1]["params"]["substeps"], 3);

  const std::filesystem::path file = out / "th1_nod.json";
  const hairbench::test::CliResult made =
      run_cli("scenario new --groom " + kTestHair1 + " --motion nod --out " + file.string());
  ASSERT_EQ(made.code, 0) << made.out;
  EXPECT_NE(made.out.find("wrote " + file.string()), std::string::npos) << made.out;
  std::ifstream in(file);
  const nlohmann::json doc = nlohmann::json::parse(in);
  EXPECT_EQ(doc["groom"]["unit"], "cm");  // resolved, so that the file does not guess again
  EXPECT_EQ(doc["groom"]["pivot"], "fit");
  EXPECT_EQ(doc["head"]["radius"], "fit");
  const hairbench::test::CliResult ran = run_cli("compare --scenario " + file.string() +
                                                 " --models han_m1 --frames 1 --no-charts --out " +
                                                 (out / "file").string());
  EXPECT_EQ(ran.code, 0) << ran.out;
}

}  // namespace
