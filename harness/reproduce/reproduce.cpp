// The driver of `hairbench reproduce`: runs the selected papers (one file each in this
// folder, each a table of its claims over a context it builds once, rows.h), counts the
// three kinds of rows apart, writes the report, its charts and pages.
#include "harness/reproduce.h"

#include "core/error.h"
#include "core/parallel.h"
#include "harness/charts.h"
#include "harness/reproduce/rows.h"
#include "reports/report.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <string_view>

namespace hairbench {

using nlohmann::json;

namespace {

// The papers, in the report's order: the one list, which the command line's names (and
// so the shard split, over ReproduceOptions::papers), the help and the driver read.
struct Paper {
  std::string_view name;                                // on the command line and as papers[].id
  std::string_view title;                               // in the progress log
  reproduce::PaperResult (*run)(const reproduce::Ctx&);  // its context, then its claims (rows.h)
};
constexpr Paper kPapers[] = {
    {"han2012", "Han & Harada 2012", reproduce::reproduce_han},
    {"halen2007", "Halén & Wester 2007", reproduce::reproduce_halen},
    {"plante2001", "Plante, Cani & Poulin 2001", reproduce::reproduce_plante},
};

const Paper* find_paper(std::string_view name) {
  const auto it = std::ranges::find(kPapers, name, &Paper::name);
  return it == std::end(kPapers) ? nullptr : it;
}

json load_average() {
  std::ifstream in("/proc/loadavg");
  double l = std::numeric_limits<double>::quiet_NaN();
  in >> l;
  return std::isfinite(l) ? json(l) : json(nullptr);
}

}  // namespace

json reproduce_summary(const json& papers) {
  int matches = 0, mismatches = 0, holds = 0, differs = 0, untestable = 0, measurements = 0;
  for (const json& p : papers) {
    for (const json& r : p["setups"]) (r["verdict"] == "matches" ? matches : mismatches)++;
    for (const json& r : p["claims"]) {
      const std::string v = r["verdict"];
      (v == "holds" ? holds : v == "differs" ? differs : untestable)++;
    }
    measurements += static_cast<int>(p["measurements"].size());
  }
  return {{"setup", {{"matches", matches}, {"mismatches", mismatches}}},
          {"claims", {{"holds", holds}, {"differs", differs}, {"not_testable", untestable}}},
          {"measurements", measurements}};
}

std::string reproduce_plan_key(const std::string& paper, const json& frames_cap) {
  return frames_cap.is_null() ? paper : paper + " --frames " + frames_cap.dump();
}

std::string reproduce_paper_names() {
  std::string s;
  for (const Paper& p : kPapers) s += (s.empty() ? "" : ", ") + std::string(p.name);
  return s;
}

std::vector<std::string> select_papers(const std::vector<std::string>& names) {
  auto named = [&](std::string_view p) { return std::find(names.begin(), names.end(), p) != names.end(); };
  for (const std::string& n : names)
    if (n != "all" && !find_paper(n))
      throw InputError("arguments", "reproduce " + n, "expected " + reproduce_paper_names() + " or all");
  if (names.empty())
    throw InputError("arguments", "reproduce", "name a table: " + reproduce_paper_names() + " or all");
  std::vector<std::string> papers;
  for (const Paper& p : kPapers)
    if (named(p.name) || named("all")) papers.emplace_back(p.name);
  return papers;
}

json run_reproduce(const ReproduceOptions& opt, const std::function<void(const std::string&)>& log) {
  const auto start = std::chrono::steady_clock::now();
  ThreadPool pool(opt.threads);
  const reproduce::Ctx c{opt, pool, log};
  json report = {{"schema", "hairbench-reproduce"}, {"schema_version", 3}};
  report["context"] = make_report(ReportContext{pool.threads(), {}}, {})["context"];
  const json load_start = load_average();
  json papers = json::array();
  for (const std::string& name : opt.papers) {
    const Paper* p = find_paper(name);
    if (!p) throw InputError("arguments", "reproduce " + name, "expected " + reproduce_paper_names() + " or all");
    log(name + ": " + std::string(p->title));
    papers.push_back(reproduce::to_json(p->run(c)));
  }
  report["papers"] = papers;
  report["frames_cap"] = opt.frames > 0 ? json(opt.frames) : json(nullptr);
  report["load_average"] = {{"start", load_start}, {"end", load_average()}};
  report["wall_s"] = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  report["summary"] = reproduce_summary(papers);
  if (!opt.shard.is_null()) report["shard"] = opt.shard;
  return report;
}

int write_reproduce(const json& report, const std::filesystem::path& out, bool charts) {
  const std::filesystem::path json_file = out / "reproduce.json";
  write_json(json_file, report);
  int chart_status = 0;
  if (charts) chart_status = draw_charts(json_file, "reproduce_charts.py");
  const std::string md = reproduce_markdown(report);
  std::ofstream(out / "reproduce.md") << md;
  std::ofstream(out / "reproduce.html") << reproduce_html(report, out / "charts");
  // The terminal gets the three summary tables, not the per-paper detail.
  std::fputs(md.substr(0, md.find("\n## Details")).c_str(), stdout);
  std::printf("\nwrote %s (.md, .html%s)\n", json_file.string().c_str(), charts ? ", charts/" : "");
  return chart_status;
}

int cmd_reproduce(const ReproduceOptions& opt) {
  const auto start = std::chrono::steady_clock::now();
  const json report = run_reproduce(opt, [&](const std::string& line) {
    const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    std::fprintf(stderr, "[%6.1f s] %s\n", s, line.c_str());
  });
  return write_reproduce(report, opt.out, opt.charts);
}

}  // namespace hairbench
