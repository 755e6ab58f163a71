// The driver of `hairbench reproduce`: runs the selected papers (one file each in this
// folder), counts the three kinds of rows apart, writes the report, its charts and pages.
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

namespace hairbench {

using nlohmann::json;

namespace {

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

std::vector<std::string> select_papers(const std::vector<std::string>& names) {
  auto named = [&](const std::string& p) { return std::find(names.begin(), names.end(), p) != names.end(); };
  for (const std::string& n : names)
    if (n != "all" && std::ranges::find(kReproducePapers, n) == std::end(kReproducePapers))
      throw InputError("arguments", "reproduce " + n, "expected han2012, halen2007, plante2001 or all");
  if (names.empty()) throw InputError("arguments", "reproduce", "name a table: han2012, halen2007, plante2001 or all");
  std::vector<std::string> papers;
  for (const char* p : kReproducePapers)
    if (named(p) || named("all")) papers.emplace_back(p);
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
  for (const std::string& p : opt.papers) {
    if (p == "han2012") papers.push_back(reproduce::to_json(reproduce::reproduce_han(c)));
    else if (p == "halen2007") papers.push_back(reproduce::to_json(reproduce::reproduce_halen(c)));
    else papers.push_back(reproduce::to_json(reproduce::reproduce_plante(c)));
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
