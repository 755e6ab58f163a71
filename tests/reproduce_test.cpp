// `hairbench reproduce`: bad arguments are one-line errors with exit code 2;
// a quick run of one table writes the report's three files, and every verdict in it
// follows from the measured value and the stated bounds.
#include "harness/reproduce.h"

#include "cli_support.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <string>

namespace {

using hairbench::test::run_cli;

std::string slurp(const std::filesystem::path& f) {
  std::ifstream in(f);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// The rule the report states: holds iff the measured value is a number within the bounds.
void expect_verdict_follows(const nlohmann::json& c) {
  SCOPED_TRACE(c["id"].get<std::string>());
  const auto& lo = c["holds_if"]["min"];
  const auto& hi = c["holds_if"]["max"];
  ASSERT_TRUE(!lo.is_null() || !hi.is_null()) << "a check without bounds decides nothing";
  const bool holds = c["measured"].is_number() && (lo.is_null() || c["measured"].get<double>() >= lo.get<double>()) &&
                     (hi.is_null() || c["measured"].get<double>() <= hi.get<double>());
  EXPECT_EQ(c["verdict"], holds ? "holds" : "differs");
  EXPECT_EQ(c["reason"].get<std::string>().empty(), holds) << "a reason exactly when it differs";
  if (!holds) {
    EXPECT_EQ(c["reason"].get<std::string>().find('\n'), std::string::npos) << "one line";
  }
}

TEST(Reproduce, BadArgumentsExitTwo) {
  for (const char* args : {"reproduce", "reproduce nosuch", "reproduce han2012 --frames 0", "reproduce all --bogus",
                           "reproduce plante2001 --frames", "reproduce halen2007 --threads x"}) {
    const hairbench::test::CliResult r = run_cli(args);
    EXPECT_EQ(r.code, 2) << args << ": " << r.out;
    EXPECT_EQ(std::count(r.out.begin(), r.out.end(), '\n'), 1) << args << ": " << r.out;
  }
}

TEST(Reproduce, VerdictFollowsTheBounds) {
  hairbench::ReproduceCheck c;
  c.id = "x";
  c.min = 1.0;
  c.max = 2.0;
  c.why_differs = "because";
  for (double v : {1.0, 1.5, 2.0}) {
    c.measured = v;
    EXPECT_EQ(hairbench::check_json(c)["verdict"], "holds") << v;
  }
  for (double v : {0.5, 2.5, std::numeric_limits<double>::quiet_NaN()}) {
    c.measured = v;
    const nlohmann::json j = hairbench::check_json(c);
    EXPECT_EQ(j["verdict"], "differs") << v;
    EXPECT_NE(j["reason"].get<std::string>().find("because"), std::string::npos);
  }
}

// Plante's table at two frames per style: seconds, and every part of the report.
TEST(Reproduce, QuickPlanteRunWritesTheReport) {
  const std::filesystem::path out = std::filesystem::temp_directory_path() / "hairbench-reproduce-test";
  std::filesystem::remove_all(out);
  const hairbench::test::CliResult r = run_cli("reproduce plante2001 --frames 2 --threads 1 --out \"" + out.string() + "\"");
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("## Verdicts"), std::string::npos) << r.out;

  const nlohmann::json rep = nlohmann::json::parse(slurp(out / "reproduce.json"));
  EXPECT_EQ(rep["schema"], "hairbench-reproduce");
  EXPECT_EQ(rep["frames_cap"], 2);
  ASSERT_EQ(rep["papers"].size(), 1u);
  const auto& paper = rep["papers"][0];
  EXPECT_EQ(paper["id"], "plante2001");
  ASSERT_EQ(paper["tables"].size(), 1u);
  const auto& table = paper["tables"][0];
  ASSERT_EQ(table["rows"].size(), 3u);  // short, medium, long
  int checks = 0, holds = 0;
  for (const auto& row : table["rows"]) {
    SCOPED_TRACE(row["label"].get<std::string>());
    EXPECT_EQ(row["published"].size(), table["published_columns"].size());
    ASSERT_EQ(row["measured"].size(), table["measured_columns"].size());
    // The styles' structure is the paper's: its wisp counts.
    EXPECT_EQ(row["measured"][0], row["published"][0]);
    // The comparison is computed from the row's measured interaction share.
    const auto& c = row["comparison"];
    ASSERT_TRUE(c.is_object());
    EXPECT_DOUBLE_EQ(c["measured"].get<double>(), row["measured"][3].get<double>());
    EXPECT_GT(c["measured"].get<double>(), 0.0);
    EXPECT_LT(c["measured"].get<double>(), 1.0);
    expect_verdict_follows(c);
    ++checks;
    holds += c["verdict"] == "holds";
  }
  ASSERT_GE(paper["checks"].size(), 3u);
  for (const auto& c : paper["checks"]) {
    expect_verdict_follows(c);
    ++checks;
    holds += c["verdict"] == "holds";
  }
  EXPECT_EQ(rep["summary"]["holds"], holds);
  EXPECT_EQ(rep["summary"]["differs"], checks - holds);

  const std::string md = slurp(out / "reproduce.md");
  const std::string html = slurp(out / "reproduce.html");
  for (const auto& c : paper["checks"]) {
    EXPECT_NE(md.find(c["id"].get<std::string>()), std::string::npos) << c["id"];
    EXPECT_NE(html.find(c["id"].get<std::string>()), std::string::npos) << c["id"];
  }
  // Self-contained: one file to open or attach, nothing loaded from elsewhere.
  EXPECT_NE(html.find("<table>"), std::string::npos);
  EXPECT_EQ(html.find("src="), std::string::npos);
  EXPECT_EQ(html.find("<link"), std::string::npos);
  std::filesystem::remove_all(out);
}

}  // namespace
