// `hairbench reproduce`: bad arguments are one-line errors with exit code 2; every
// verdict follows from its row's own fields; a quick run of every paper writes the three
// kinds of rows, counted apart (no setup row counted as a claim), each claim with the
// paper's sentence, and a self-contained page.
#include "harness/reproduce.h"
#include "harness/reproduce/rows.h"

#include "cli_support.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <sstream>
#include <string>

namespace {

using hairbench::test::run_cli;
namespace rp = hairbench::reproduce;

std::string slurp(const std::filesystem::path& f) {
  std::ifstream in(f);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// The rule the report states: a claim holds iff the measured value is a number within the
// bounds; a reason exactly when it does not hold; "not testable" carries its reason and no
// measured value.
void expect_claim_verdict_follows(const nlohmann::json& c) {
  SCOPED_TRACE(c["id"].get<std::string>());
  EXPECT_FALSE(c["source"]["quote"].get<std::string>().empty()) << "every claim quotes the paper";
  EXPECT_FALSE(c["source"]["where"].get<std::string>().empty());
  EXPECT_FALSE(c["settings"].get<std::string>().empty()) << "every claim says what it ran at";
  const std::string reason = c["reason"];
  EXPECT_EQ(reason.find('\n'), std::string::npos) << "one line";
  if (c["verdict"] == "not testable") {
    EXPECT_TRUE(c["measured"].is_null());
    EXPECT_FALSE(reason.empty());
    return;
  }
  const auto& lo = c["holds_if"]["min"];
  const auto& hi = c["holds_if"]["max"];
  ASSERT_TRUE(!lo.is_null() || !hi.is_null()) << "a claim without bounds decides nothing";
  EXPECT_FALSE(c["threshold_why"].get<std::string>().empty()) << "every bound says why";
  const bool holds = c["measured"].is_number() && (lo.is_null() || c["measured"].get<double>() >= lo.get<double>()) &&
                     (hi.is_null() || c["measured"].get<double>() <= hi.get<double>());
  EXPECT_EQ(c["verdict"], holds ? "holds" : "differs");
  EXPECT_EQ(reason.empty(), holds) << "a reason exactly when it differs";
}

// A claim's plain numbers (each with a label and the paper's value) lead its cells in the
// Markdown claims table, before the tested quantity; m3_5_to_29x's are each model's M1/M3
// beside Table 2's, in whole sets of the three models.
void expect_numbers_shown_first(const nlohmann::json& paper, const nlohmann::json& c, const std::string& md) {
  SCOPED_TRACE(c["id"].get<std::string>());
  ASSERT_TRUE(c["numbers"].is_array());
  for (const auto& n : c["numbers"]) EXPECT_FALSE(n["label"].get<std::string>().empty());
  if (c["id"] == "m3_5_to_29x") {
    const nlohmann::json pub = rp::load_published("han2012");
    std::map<std::string, double> m1, m3;
    for (const auto& row : pub["tables"]["table2"]["rows"])
      (row[1] == "m1" ? m1 : m3)[row[0].get<std::string>()] = row[4].get<double>();
    ASSERT_FALSE(c["numbers"].empty()) << "the absolute M1/M3 beside the paper's";
    ASSERT_EQ(c["numbers"].size() % 3, 0u);
    for (std::size_t i = 0; i < c["numbers"].size(); ++i) {
      const std::string model = "model" + std::to_string(i % 3 + 1);
      EXPECT_EQ(c["numbers"][i]["label"].get<std::string>().rfind(model, 0), 0u) << c["numbers"][i];
      EXPECT_NEAR(c["numbers"][i]["published"].get<double>(), m1[model] / m3[model], 1e-12);
    }
  }
  if (c["numbers"].empty()) return;
  const std::string head = "| " + paper["id"].get<std::string>() + " | " + c["id"].get<std::string>() + " |";
  const std::size_t row = md.find(head);
  ASSERT_NE(row, std::string::npos);
  const std::string line = md.substr(row, md.find('\n', row) - row);
  const std::size_t first = line.find(c["numbers"][0]["label"].get<std::string>());
  EXPECT_NE(first, std::string::npos) << line;
  EXPECT_LT(first, line.find("; tested ")) << line;
}

// m2_as_smooth_with_iterations reads its chart: the largest ratio of a model's deviation
// at one iteration count to the one before (a model's counts are its non-null points).
void expect_steps_give_the_measured(const nlohmann::json& c) {
  ASSERT_FALSE(c["chart"].is_null());
  double worst = -std::numeric_limits<double>::infinity();
  for (const auto& s : c["chart"]["series"]) {
    double prev = std::numeric_limits<double>::quiet_NaN();
    int points = 0;
    for (const auto& y : s["y"]) {
      if (!y.is_number()) continue;
      if (points++ > 0) worst = std::max(worst, y.get<double>() / prev);
      prev = y.get<double>();
    }
    EXPECT_EQ(points, 4) << s["label"] << ": Table 2's count, 8, 32, 128";
  }
  EXPECT_NEAR(c["measured"].get<double>(), worst, 1e-9 * worst);
}

TEST(Reproduce, BadArgumentsExitTwo) {
  for (const char* args : {"reproduce", "reproduce nosuch", "reproduce han2012 --frames 0", "reproduce all --bogus",
                           "reproduce plante2001 --frames", "reproduce halen2007 --threads x",
                           "reproduce han2012 --no-charts=1"}) {
    const hairbench::test::CliResult r = run_cli(args);
    EXPECT_EQ(r.code, 2) << args << ": " << r.out;
    EXPECT_EQ(std::count(r.out.begin(), r.out.end(), '\n'), 1) << args << ": " << r.out;
  }
}

TEST(Reproduce, ClaimVerdictFollowsTheBounds) {
  rp::ClaimRow c;
  c.id = "x";
  c.min = 1.0;
  c.max = 2.0;
  c.why_differs = "because";
  for (double v : {1.0, 1.5, 2.0}) {
    c.measured = v;
    EXPECT_EQ(rp::to_json(c)["verdict"], "holds") << v;
  }
  for (double v : {0.5, 2.5, std::numeric_limits<double>::quiet_NaN()}) {
    c.measured = v;
    const nlohmann::json j = rp::to_json(c);
    EXPECT_EQ(j["verdict"], "differs") << v;
    EXPECT_NE(j["reason"].get<std::string>().find("because"), std::string::npos);
  }
  c.measured = 1.5;
  c.not_testable = "no GPU here";
  const nlohmann::json j = rp::to_json(c);
  EXPECT_EQ(j["verdict"], "not testable");
  EXPECT_EQ(j["reason"], "no GPU here");
  EXPECT_TRUE(j["measured"].is_null());

  rp::SetupRow s{"s", "what", {}, "3 spheres", "3 spheres", true};
  EXPECT_EQ(rp::to_json(s)["verdict"], "matches");
  s.matches = false;
  EXPECT_EQ(rp::to_json(s)["verdict"], "mismatch");
  EXPECT_FALSE(rp::to_json(rp::MeasurementRow{}).contains("verdict")) << "a measurement has no verdict";
}

// The scaling claims fit t = a + b N: exact on a line, and the slope's interval covers the
// slope of noisy points drawn around one.
TEST(Reproduce, LineFitRecoversSlopeAndInterval) {
  const rp::LineFit exact = rp::fit_line({9, 25, 49, 121}, {5 + 2 * 9., 5 + 2 * 25., 5 + 2 * 49., 5 + 2 * 121.});
  EXPECT_NEAR(exact.a, 5.0, 1e-9);
  EXPECT_NEAR(exact.b, 2.0, 1e-12);
  EXPECT_NEAR(exact.b_ci95, 0.0, 1e-9);
  EXPECT_NEAR(exact.r2, 1.0, 1e-12);
  const std::vector<double> x = {9, 25, 49, 81, 121, 169};
  const std::vector<double> noise = {0.3, -0.5, 0.2, 0.4, -0.3, -0.1};
  std::vector<double> y;
  for (std::size_t i = 0; i < x.size(); ++i) y.push_back(1.0 + 0.2 * x[i] + noise[i]);
  const rp::LineFit f = rp::fit_line(x, y);
  EXPECT_GT(f.b_ci95, 0.0);
  EXPECT_LT(std::fabs(f.b - 0.2), f.b_ci95);
  EXPECT_LT(f.b_ci95, 0.02) << "six points with noise of 0.5 pin a slope to a few percent";
}

// Every paper at two frames per run: every part of the report and its rules.
TEST(Reproduce, QuickRunOfEveryPaperWritesTheThreeKindsOfRows) {
  const std::filesystem::path out = std::filesystem::temp_directory_path() / "hairbench-reproduce-test";
  std::filesystem::remove_all(out);
  const hairbench::test::CliResult r = run_cli("reproduce all --frames 2 --threads 2 --out \"" + out.string() + "\"");
  ASSERT_EQ(r.code, 0) << r.out;
  for (const char* heading : {"## Claims", "## Setup", "## Measurements"})
    EXPECT_NE(r.out.find(heading), std::string::npos) << heading << "\n" << r.out;

  const nlohmann::json rep = nlohmann::json::parse(slurp(out / "reproduce.json"));
  EXPECT_EQ(rep["schema"], "hairbench-reproduce");
  EXPECT_EQ(rep["schema_version"], 3);
  EXPECT_EQ(rep["frames_cap"], 2);
  ASSERT_EQ(rep["papers"].size(), 3u);
  int matches = 0, mismatches = 0, holds = 0, differs = 0, untestable = 0, measurements = 0;
  const std::string md = slurp(out / "reproduce.md");
  const std::string html = slurp(out / "reproduce.html");
  for (const auto& paper : rep["papers"]) {
    SCOPED_TRACE(paper["id"].get<std::string>());
    EXPECT_FALSE(paper["setups"].empty());
    // A paper may have no claim row: Plante et al.'s §5.3 numbers are set by their grooms
    // and machine, so they are measurements.
    EXPECT_FALSE(paper["measurements"].empty());
    for (const auto& s : paper["setups"]) {
      EXPECT_EQ(s["kind"], "setup");
      ASSERT_TRUE(s["verdict"] == "matches" || s["verdict"] == "mismatch") << s;
      // The configuration is the papers' whatever the frame cap: every setup row matches.
      EXPECT_EQ(s["verdict"], "matches") << s;
      (s["verdict"] == "matches" ? matches : mismatches)++;
    }
    for (const auto& c : paper["claims"]) {
      EXPECT_EQ(c["kind"], "claim");
      expect_claim_verdict_follows(c);
      const std::string v = c["verdict"];
      (v == "holds" ? holds : v == "differs" ? differs : untestable)++;
      EXPECT_NE(md.find(c["source"]["quote"].get<std::string>()), std::string::npos) << "the paper's sentence";
      EXPECT_NE(html.find(c["id"].get<std::string>()), std::string::npos) << c["id"];
      expect_numbers_shown_first(paper, c, md);
      if (c["id"] == "m2_as_smooth_with_iterations") expect_steps_give_the_measured(c);
      if (!c["chart"].is_null()) {
        EXPECT_TRUE(std::filesystem::exists(out / "charts" /
                                            (paper["id"].get<std::string>() + "_" + c["id"].get<std::string>() + ".png")))
            << c["id"];
        for (const auto& s : c["chart"]["series"]) EXPECT_EQ(s["y"].size(), c["chart"]["x"].size());
      }
    }
    for (const auto& m : paper["measurements"]) {
      EXPECT_EQ(m["kind"], "measurement");
      EXPECT_FALSE(m.contains("verdict"));
      EXPECT_EQ(m["published"].size(), m["columns"].size()) << m["id"];
      EXPECT_EQ(m["measured"].size(), m["columns"].size()) << m["id"];
      ++measurements;
    }
  }
  EXPECT_GT(holds + differs + untestable, 0);
  EXPECT_EQ(rep["summary"]["setup"]["matches"], matches);
  EXPECT_EQ(rep["summary"]["setup"]["mismatches"], mismatches);
  EXPECT_EQ(rep["summary"]["claims"]["holds"], holds);
  EXPECT_EQ(rep["summary"]["claims"]["differs"], differs);
  EXPECT_EQ(rep["summary"]["claims"]["not_testable"], untestable);
  EXPECT_EQ(rep["summary"]["measurements"], measurements);

  // Self-contained: one file to open or attach; its only images are inlined.
  EXPECT_NE(html.find("<table>"), std::string::npos);
  EXPECT_EQ(html.find("<link"), std::string::npos);
  for (std::size_t i = html.find("src=\""); i != std::string::npos; i = html.find("src=\"", i + 1))
    EXPECT_EQ(html.compare(i, 16, "src=\"data:image/"), 0) << html.substr(i, 40);
  std::filesystem::remove_all(out);
}

}  // namespace
