// `hairbench reproduce`: runs the papers' claims and tables (reports/published/*.json) at
// the papers' own settings on this machine and writes a report of three kinds of rows,
// counted apart (harness/reproduce/rows.h): setup rows (the configuration is the paper's),
// claim rows (holds, differs or not testable here, each in a form that survives a change
// of hardware) and measurement rows (hardware-dependent numbers beside the paper's).
#pragma once

#include <nlohmann/json.hpp>

#include <filesystem>
#include <functional>
#include <string>
#include <vector>

namespace hairbench {

// The papers `reproduce` runs, in the report's order, as the command line names them:
// "han2012, halen2007, plante2001" (the one list, in harness/reproduce/reproduce.cpp).
std::string reproduce_paper_names();

struct ReproduceOptions {
  std::vector<std::string> papers;  // in reproduce_paper_names' order
  int frames = 0;                   // > 0: every run stops after this many frames (quick runs)
  int threads = 0;                  // 0: every hardware thread
  std::string device;               // Vulkan device for Han & Harada's GPU table
  std::filesystem::path out = "reports/out/reproduce";
  bool charts = true;               // --no-charts: no claim charts
  // With --shard I/N: the report's `shard` object (harness/shard.h's shard_json over the
  // papers, each a plan item keyed by reproduce_plan_key), which hairbench merge reads.
  nlohmann::json shard = nullptr;
};

// A paper's key in a sharded reproduce's plan: the paper, and the frame cap, so that
// shards run with different caps are of different plans and never merged.
std::string reproduce_plan_key(const std::string& paper, const nlohmann::json& frames_cap);

// The tables named on the command line (each of reproduce_paper_names or "all") as
// ReproduceOptions::papers, in that order; throws InputError naming a bad one.
std::vector<std::string> select_papers(const std::vector<std::string>& names);

// Runs the selected papers; `log` gets one line per configuration as it starts.
nlohmann::json run_reproduce(const ReproduceOptions& opt, const std::function<void(const std::string&)>& log);

// The report as Markdown (charts linked as charts/NAME.png) and as one self-contained
// HTML page (the charts of `charts_dir`, when there, inlined as data URIs).
std::string reproduce_markdown(const nlohmann::json& report);
std::string reproduce_html(const nlohmann::json& report, const std::filesystem::path& charts_dir);

// The counts of a report's `summary`: setups by match, claims by verdict, measurements.
nlohmann::json reproduce_summary(const nlohmann::json& papers);

// Writes OUT/reproduce.json, draws the claims' charts into OUT/charts/ (unless `charts`
// is false), writes OUT/reproduce.{md,html} and prints the three kinds of rows. Returns
// the chart step's exit code.
int write_reproduce(const nlohmann::json& report, const std::filesystem::path& out, bool charts);

// The command: run, then write_reproduce.
int cmd_reproduce(const ReproduceOptions& opt);

}  // namespace hairbench
