#include "harness/reproduce/rows.h"

#include "core/error.h"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>

namespace hairbench::reproduce {

using nlohmann::json;

namespace {

json jnum(double v) { return std::isfinite(v) ? json(v) : json(nullptr); }

json jnums(const std::vector<double>& v) {
  json a = json::array();
  for (double x : v) a.push_back(jnum(x));
  return a;
}

// Two-sided 95% quantile of Student's t with df degrees of freedom (df = 1 .. 30; the
// normal 1.96 beyond, where the two differ by under 2%).
double t975(double df) {
  static constexpr double kT[] = {12.706, 4.303, 3.182, 2.776, 2.571, 2.447, 2.365, 2.306, 2.262, 2.228,
                                  2.201,  2.179, 2.160, 2.145, 2.131, 2.120, 2.110, 2.101, 2.093, 2.086,
                                  2.080,  2.074, 2.069, 2.064, 2.060, 2.056, 2.052, 2.048, 2.045, 2.042};
  const int i = static_cast<int>(df);
  return i >= 1 && i <= 30 ? kT[i - 1] : 1.96;
}

json source_json(const Source& s) { return {{"where", s.where}, {"quote", s.quote}}; }

}  // namespace

std::string num(double v) {
  if (!std::isfinite(v)) return "-";
  char b[32];
  std::snprintf(b, sizeof b, std::fabs(v) >= 1e4 ? "%.0f" : "%.3g", v);
  return b;
}

json to_json(const SetupRow& r) {
  return {{"kind", "setup"},         {"id", r.id},
          {"what", r.what},          {"source", source_json(r.source)},
          {"published", r.published}, {"measured", r.measured},
          {"verdict", r.matches ? "matches" : "mismatch"}, {"note", r.note}};
}

json to_json(const ClaimRow& r) {
  std::string verdict, reason;
  if (r.not_testable) {
    verdict = "not testable";
    reason = *r.not_testable;
  } else {
    const bool holds =
        std::isfinite(r.measured) && (!r.min || r.measured >= *r.min) && (!r.max || r.measured <= *r.max);
    verdict = holds ? "holds" : "differs";
    if (!holds) {
      reason = "measured " + num(r.measured) + (std::isfinite(r.measured) ? "" : " (no finite value)");
      if (r.min && r.max) reason += ", outside " + num(*r.min) + " to " + num(*r.max);
      else if (r.min) reason += ", below " + num(*r.min);
      else if (r.max) reason += ", above " + num(*r.max);
      if (!r.why_differs.empty()) reason += ": " + r.why_differs;
    }
  }
  json chart = nullptr;
  if (r.chart) {
    json series = json::array();
    for (const Series& s : r.chart->series) series.push_back({{"label", s.label}, {"y", jnums(s.y)}});
    chart = {{"title", r.chart->title}, {"x_label", r.chart->x_label}, {"y_label", r.chart->y_label},
             {"x", jnums(r.chart->x)},   {"series", series},          {"log_x", r.chart->log_x},
             {"log_y", r.chart->log_y}};
  }
  json numbers = json::array();
  for (const Number& n : r.numbers)
    numbers.push_back({{"label", n.label},
                       {"published", n.published ? jnum(*n.published) : json(nullptr)},
                       {"measured", jnum(n.measured)}});
  return {{"kind", "claim"},
          {"id", r.id},
          {"source", source_json(r.source)},
          {"settings", r.settings},
          {"numbers", numbers},
          {"quantity", r.quantity},
          {"published", r.published ? jnum(*r.published) : json(nullptr)},
          {"measured", r.not_testable ? json(nullptr) : jnum(r.measured)},
          {"holds_if", {{"min", r.min ? json(*r.min) : json(nullptr)}, {"max", r.max ? json(*r.max) : json(nullptr)}}},
          {"threshold_why", r.threshold_why},
          {"detail", r.detail},
          {"verdict", verdict},
          {"reason", reason},
          {"chart", chart}};
}

json to_json(const MeasurementRow& r) {
  return {{"kind", "measurement"},    {"id", r.id},
          {"what", r.what},           {"source", source_json(r.source)},
          {"unit", r.unit},           {"columns", r.columns},
          {"published", jnums(r.published)}, {"measured", jnums(r.measured)},
          {"note", r.note}};
}

json to_json(const PaperResult& p) {
  json setups = json::array(), claims = json::array(), measurements = json::array();
  for (const SetupRow& r : p.setups) setups.push_back(to_json(r));
  for (const ClaimRow& r : p.claims) claims.push_back(to_json(r));
  for (const MeasurementRow& r : p.measurements) measurements.push_back(to_json(r));
  return {{"id", p.id}, {"paper", p.paper}, {"setups", setups}, {"claims", claims}, {"measurements", measurements}};
}

json load_published(const std::string& name) {
  const std::filesystem::path file = std::filesystem::path(HAIRBENCH_PUBLISHED_DIR) / (name + ".json");
  std::ifstream in(file);
  if (!in) throw InputError(file.string(), "", "cannot read the published table");
  json j = json::parse(in, nullptr, false);
  if (j.is_discarded() || !j.contains("tables")) throw InputError(file.string(), "tables", "missing or not JSON");
  if (!j.contains("claims") || !j["claims"].is_array()) throw InputError(file.string(), "claims", "missing");
  return j;
}

Source claim_source(const json& published, const std::string& id) {
  for (const json& c : published["claims"])
    if (c.value("id", "") == id) return {c.value("source", ""), c.value("quote", "")};
  throw InputError(std::string(HAIRBENCH_PUBLISHED_DIR), "claims[" + id + "]", "no such claim in the published file");
}

LineFit fit_line(const std::vector<double>& x, const std::vector<double>& y) {
  const double n = static_cast<double>(x.size());
  double mx = 0.0, my = 0.0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    mx += x[i] / n;
    my += y[i] / n;
  }
  double sxx = 0.0, sxy = 0.0, syy = 0.0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    sxx += (x[i] - mx) * (x[i] - mx);
    sxy += (x[i] - mx) * (y[i] - my);
    syy += (y[i] - my) * (y[i] - my);
  }
  LineFit f;
  f.b = sxy / sxx;
  f.a = my - f.b * mx;
  double sse = 0.0;
  for (std::size_t i = 0; i < x.size(); ++i) sse += std::pow(y[i] - (f.a + f.b * x[i]), 2);
  f.r2 = syy > 0.0 ? 1.0 - sse / syy : 1.0;
  if (x.size() < 3) {
    f.b_ci95 = std::numeric_limits<double>::quiet_NaN();
    return f;
  }
  const double se = std::sqrt(sse / (n - 2.0) / sxx);
  f.b_ci95 = t975(n - 2.0) * se;
  return f;
}

}  // namespace hairbench::reproduce
