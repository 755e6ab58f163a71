// The rows of a `hairbench reproduce` report, in three kinds that are counted apart:
//
//   setup        the configuration matches the paper's (groom sizes, iteration counts,
//                rates). It decides whether the other rows test the paper's set-up; it is
//                never counted as a claim that holds.
//   claim        a property the paper asserts, tested in a form that survives a change of
//                hardware: holds, differs (with a reason built from measured numbers), or
//                not testable here (with the reason).
//   measurement  a number that depends on the machine, on the 2001/2007/2012 code or on
//                the paper's grooms (a time, a time share, a count the wisps' spacing
//                sets), shown beside the paper's, with no verdict.
//
// Every verdict follows from the row's own JSON fields, so a reader can recompute it.
#pragma once

#include "core/parallel.h"
#include "harness/reproduce.h"

#include <nlohmann/json.hpp>

#include <functional>
#include <limits>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace hairbench::reproduce {

// Where a row comes from in the paper, and its sentence or caption, quoted.
struct Source {
  std::string where{};  // "Section 6", "Figure 6.1.1"
  std::string quote{};
};

struct SetupRow {
  std::string id{}, what{};
  Source source{};
  std::string published{}, measured{};  // as the paper states it; what this run used
  bool matches = false;
  std::string note{};
};

// A trend the claim is about, drawn as a small chart: one or more series over a shared
// x axis (NaN where a series has no value).
struct Series {
  std::string label{};
  std::vector<double> y{};
};
struct Chart {
  std::string title{}, x_label{}, y_label{};
  std::vector<double> x{};
  std::vector<Series> series{};
  bool log_x = false, log_y = false;
};

// A plain number a reader compares with the paper's first (an absolute speed-up whose
// ratio the claim tests, say): shown before the claim's quantity, never read by the verdict.
struct Number {
  std::string label{};
  std::optional<double> published{};
  double measured = std::numeric_limits<double>::quiet_NaN();
};

struct ClaimRow {
  std::string id{};
  Source source{};
  std::string settings{};   // the configuration it ran at (the paper's), in words
  std::string quantity{};   // what `measured` is
  std::optional<double> published{};  // the paper's value of the quantity, when it has one
  double measured = 0.0;
  std::optional<double> min{}, max{};  // holds when measured is finite and within these
  std::vector<Number> numbers{};       // shown first, beside the paper's; not the verdict's
  std::string threshold_why{};         // why these bounds: what makes the claim true
  std::string detail{};                // the measured values the quantity comes from
  // Set only when the claim cannot be tested here; then `measured` and the bounds are
  // not used and the verdict is "not testable".
  std::optional<std::string> not_testable{};
  // The reason when it differs: must name measured numbers (filled by the paper's code
  // from its runs; an assumed cause is not a reason).
  std::string why_differs{};
  std::optional<Chart> chart{};
};

struct MeasurementRow {
  std::string id{}, what{};
  Source source{};
  std::string unit{};
  std::vector<std::string> columns{};
  std::vector<double> published{}, measured{};  // per column; NaN where none
  std::string note{};  // why it is a measurement, not a claim; what the machine was
};

// One paper's section of the report.
struct PaperResult {
  std::string id{}, paper{};
  std::vector<SetupRow> setups{};
  std::vector<ClaimRow> claims{};
  std::vector<MeasurementRow> measurements{};
};

nlohmann::json to_json(const SetupRow& r);
nlohmann::json to_json(const ClaimRow& r);
nlohmann::json to_json(const MeasurementRow& r);
nlohmann::json to_json(const PaperResult& p);

// What every paper's runs need: the options, the worker threads, the progress log.
struct Ctx {
  const ReproduceOptions& opt;
  ThreadPool& pool;
  const std::function<void(const std::string&)>& log;
  // `wanted` frames, or the --frames cap when it is smaller.
  int frames(int wanted) const { return opt.frames > 0 ? std::min(opt.frames, wanted) : wanted; }
};

// The paper's tables as stored data (reports/published/NAME.json).
nlohmann::json load_published(const std::string& name);
// A claim's text and source from the published file, by id (InputError when missing).
Source claim_source(const nlohmann::json& published, const std::string& id);

// Least-squares line y = a + b x with the 95% confidence half-width of the slope
// (Student t with n - 2 degrees of freedom); needs n >= 3 distinct x.
struct LineFit {
  double a = 0.0, b = 0.0, b_ci95 = 0.0, r2 = 0.0;
};
LineFit fit_line(const std::vector<double>& x, const std::vector<double>& y);

// Short number formatting for reasons and tables ("-" for NaN).
std::string num(double v);

// One thing a paper says that the report checks, and the function that checks it: it
// adds that statement's rows (setup, claim or measurement rows) to the paper's result.
// `Shared` is the paper's context, what several of its claims use, built once.
template <class Shared>
struct Claim {
  std::string_view id;       // the rows' ids as reproduce.json writes them; a{b,c} is ab and ac
  std::string_view section;  // where in the paper
  std::string_view quote;    // the paper's words being checked (or, where it has none, the rows' subject)
  void (*check)(const Shared& shared, PaperResult& out);
};

// A paper's rows: its context built once (a `Shared` holds the published file as `pub`),
// then each of its claims in the table's order, which is the report's.
template <class Shared, std::size_t N>
PaperResult check_claims(const Ctx& c, const std::string& paper, const Claim<Shared> (&claims)[N]) {
  const Shared shared(c);
  PaperResult out{paper, shared.pub["paper"]};
  for (const Claim<Shared>& claim : claims) {
    c.log(out.id + " " + std::string(claim.id) + " (" + std::string(claim.section) + ")");
    claim.check(shared, out);
  }
  return out;
}

// Each paper's rows (its file in this folder): its context, then its claims. The driver's
// table of papers (reproduce.cpp) names them.
PaperResult reproduce_han(const Ctx& c);
PaperResult reproduce_halen(const Ctx& c);
PaperResult reproduce_plante(const Ctx& c);

}  // namespace hairbench::reproduce
