#include "harness/precision.h"

#include "core/error.h"
#include "core/parallel.h"
#include "models/registry.h"
#include "reports/verdict.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <functional>
#include <sstream>

namespace hairbench {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

nlohmann::json num(double x) { return std::isfinite(x) ? nlohmann::json(x) : nlohmann::json(nullptr); }

// A cost knob's value at `factor` times `base`: integers rounded and kept at 1 or more
// where the base is (no iterations at all is another method, not a cheaper one), and
// within the parameter's range.
double scaled(const ParamSpec& p, double base, double factor) {
  double v = base * factor;
  if (p.integer) v = std::max(base >= 1.0 ? 1.0 : 0.0, std::round(v));
  return std::clamp(v, p.min, p.max);
}

struct Knob {
  const ParamSpec* spec;
  double base;  // the run's value on this scenario (resolved, substeps auto included)
};

using Values = std::map<std::string, double>;

// Every knob at its factor times its base.
Values knob_values(const std::vector<Knob>& knobs, const std::function<double(const Knob&)>& factor) {
  Values v;
  for (const Knob& k : knobs) v[std::string(k.spec->name)] = scaled(*k.spec, k.base, factor(k));
  return v;
}

bool is_iteration(const Knob& k) { return k.spec->name.find("iterations") != std::string_view::npos; }

std::vector<ParamOverride> as_overrides(const std::string& model, const Values& v) {
  std::vector<ParamOverride> out;
  for (const auto& [name, value] : v) out.push_back({model, name, value});
  return out;
}

struct Point {
  double factor = 1.0;
  Values knobs;
  double ms_per_frame = kInf;
  double error = kInf;
  double damping = kInf;  // exact: the largest damping ratio |sigma| / exact omega (the exact one is 0)
  std::string status;
  std::string why;  // where there is no error
  bool pareto = false;
};

nlohmann::json point_json(const Point& p, bool exact) {
  nlohmann::json j = {{"factor", p.factor}, {"knobs", p.knobs},       {"ms_per_frame", num(p.ms_per_frame)},
                      {"error", num(p.error)}, {"status", p.status}};
  if (exact) j["damping_ratio"] = num(p.damping);
  if (!p.why.empty()) j["why"] = p.why;
  j["pareto"] = p.pareto;
  return j;
}

class Precision {
 public:
  Precision(const Scenario& sc, const PrecisionOptions& opt, ThreadPool& pool, PrecisionReference ref)
      : sc_(sc), opt_(opt), pool_(pool), ref_(ref) {}

  nlohmann::json line(const ModelInfo& m) {
    const ParamSet resolved = resolve_params(m, sc_, opt_.overrides);
    std::vector<Knob> knobs;
    for (const ParamSpec& p : m.params)
      if (p.role == ParamRole::cost_knob) knobs.push_back({&p, resolved.get(p.name)});
    if (knobs.empty())
      throw InputError("--models", std::string(m.name), "has no cost knob (ParamRole::cost_knob) to draw a line along");
    const std::string name(m.name);
    // Against itself: the work line against every knob at kSelfFactor times; the ladders,
    // which keep the resolution (nodes) as it is, against the step and the iterations at
    // kSelfFactor times and the same resolution.
    const Values self_all = knob_values(knobs, [](const Knob&) { return kSelfFactor; });
    const Values self_same = knob_values(knobs, [&](const Knob& k) {
      return k.spec->name == m.cost.multiplier || is_iteration(k) ? kSelfFactor : 1.0;
    });

    nlohmann::json out = {{"model", name}};
    nlohmann::json names = nlohmann::json::array();
    for (const Knob& k : knobs) names.push_back(k.spec->name);
    out["knobs"] = names;
    if (ref_ == PrecisionReference::self) out["self_reference"] = {{"work", self_all}, {"ladders", self_same}};

    std::vector<Point> work;
    for (double f : kWorkFactors)
      work.push_back(measure(m, knob_values(knobs, [f](const Knob&) { return f; }), f, self_all));
    dedupe(work);
    work_.emplace_back(name, work);

    const std::string step(m.cost.multiplier);
    const auto is_step = [&](const Knob& k) { return k.spec->name == step; };
    if (std::any_of(knobs.begin(), knobs.end(), is_step)) {
      // The step alone refined, the iterations at kLadderIterations times theirs so that
      // they do not hold the error up, a resolution (nodes) as it is.
      std::vector<Point> pts;
      for (double f : kLadderFactors)
        pts.push_back(measure(m, knob_values(knobs, [&](const Knob& k) {
                                return is_step(k) ? f : is_iteration(k) ? kLadderIterations : 1.0;
                              }),
                              f, self_same));
      dedupe(pts);
      const std::vector<Point> falling = falling_run(pts);
      out["step"] = {{"knob", step},
                     {"others_factor", kLadderIterations},
                     {"points", points_json(pts)},
                     {"orders", pairwise_orders(pts, step)},
                     {"order", num(order_fit(falling, step))},
                     {"falls_from", falling.empty() ? nlohmann::json(nullptr) : nlohmann::json(falling.front().knobs.at(step))},
                     {"falls_until", falling.empty() ? nlohmann::json(nullptr) : nlohmann::json(falling.back().knobs.at(step))}};
    } else {
      out["step"] = nullptr;
    }
    if (std::any_of(knobs.begin(), knobs.end(), is_iteration)) {
      std::vector<Point> pts;
      for (double f : kLadderFactors)
        pts.push_back(
            measure(m, knob_values(knobs, [f](const Knob& k) { return is_iteration(k) ? f : 1.0; }), f, self_same));
      dedupe(pts);
      const double rate = iteration_rate(falling_run(pts), knobs);
      out["iterations"] = {{"points", points_json(pts)}, {"rate", num(rate)}};
    } else {
      out["iterations"] = nullptr;
    }
    return out;
  }

  // The Pareto front over every line's work points: no other point is both faster and
  // more accurate.
  void mark_pareto() {
    for (auto& [name, pts] : work_)
      for (Point& p : pts) {
        if (!std::isfinite(p.error) || !std::isfinite(p.ms_per_frame)) continue;
        bool dominated = false;
        for (const auto& [other, qs] : work_)
          for (const Point& q : qs)
            dominated |= &q != &p && q.ms_per_frame <= p.ms_per_frame && q.error <= p.error &&
                         (q.ms_per_frame < p.ms_per_frame || q.error < p.error);
        p.pareto = !dominated;
      }
  }
  nlohmann::json work_json(const std::string& model) const {
    for (const auto& [name, pts] : work_)
      if (name == model) return points_json(pts);
    return nlohmann::json::array();
  }

 private:
  Point measure(const ModelInfo& m, const Values& knobs, double factor, const Values& self) {
    const std::string name(m.name);
    RunOptions run;
    run.models = {name};
    run.reference = name;
    run.frames = opt_.frames;
    run.overrides = opt_.overrides;
    run.model_overrides = as_overrides(name, knobs);
    if (ref_ == PrecisionReference::self) run.reference_overrides = as_overrides(name, self);
    run.probe = run.twin = run.material_card = false;
    const std::vector<RunRecord> records = run_scenario(sc_, run, pool_);
    const RunRecord& r = records.front();
    Point p;
    p.factor = factor;
    p.knobs = knobs;
    p.status = std::string(verdict::status_name(r.verdict.status));
    if (!r.step_ms.empty()) {
      double total = 0.0;
      for (double ms : r.step_ms) total += ms;
      p.ms_per_frame = total / static_cast<double>(r.step_ms.size());
    }
    if (r.failure) {
      p.why = "diverged at frame " + std::to_string(r.failure->frame);
    } else if (ref_ == PrecisionReference::exact) {
      read_truth(r, p);
    } else {
      double sum = 0.0;
      const std::vector<double>& d = r.series("deviation_vs_reference");
      for (double x : d) sum += x * x;
      p.error = d.empty() ? kInf : std::sqrt(sum / static_cast<double>(d.size()));
      if (!std::isfinite(p.error)) p.why = "the converged run diverged";
    }
    if (opt_.on_run) opt_.on_run(name, ++done_, 0);
    return p;
  }

  static void read_truth(const RunRecord& r, Point& p) {
    if (!r.truth || !r.truth->skipped_why.empty()) {
      p.why = r.truth ? r.truth->skipped_why : "no truth fit";
      return;
    }
    p.error = p.damping = 0.0;
    for (const auto& s : r.truth->strands) {
      if (!std::isfinite(s.frequency_error)) {
        p.error = p.damping = kInf;
        p.why = "mode " + std::to_string(s.mode) + " did not oscillate";
        return;
      }
      p.error = std::max(p.error, std::abs(s.frequency_error));
      p.damping = std::max(p.damping, std::abs(s.sigma) / s.exact_omega);
    }
  }

  // Points whose knobs came out the same (a knob at its range's end, or rounded to 1) are
  // one point, labelled with the factor nearest 1 (the run's own settings are x1).
  static void dedupe(std::vector<Point>& pts) {
    std::vector<Point> out;
    for (Point& p : pts) {
      const auto same = std::find_if(out.begin(), out.end(), [&](const Point& q) { return q.knobs == p.knobs; });
      if (same == out.end())
        out.push_back(p);
      else if (std::abs(std::log(p.factor)) < std::abs(std::log(same->factor)))
        same->factor = p.factor;
    }
    pts = std::move(out);
  }

  nlohmann::json points_json(const std::vector<Point>& pts) const {
    nlohmann::json j = nlohmann::json::array();
    for (const Point& p : pts) j.push_back(point_json(p, ref_ == PrecisionReference::exact));
    return j;
  }

  // The error's order in the step, h ~ 1 / (the step knob's value): the fall of log error
  // over each refinement, per unit of log refinement.
  static nlohmann::json pairwise_orders(const std::vector<Point>& pts, const std::string& knob) {
    nlohmann::json j = nlohmann::json::array();
    for (std::size_t i = 1; i < pts.size(); ++i)
      j.push_back(num(std::log(pts[i - 1].error / pts[i].error) / std::log(pts[i].knobs.at(knob) / pts[i - 1].knobs.at(knob))));
    return j;
  }
  // The longest run of consecutive `ok` points (the coarsest such run of that length)
  // over which the error keeps falling: where the knob sets the error. Before it a
  // coarse setting is unstable or stretched; past it a floor the knob does not reach (the
  // rounding of float positions, an iteration count, a resolution) holds the error up.
  static std::vector<Point> falling_run(const std::vector<Point>& pts) {
    std::vector<Point> best, run;
    for (const Point& p : pts) {
      const bool has = std::isfinite(p.error) && p.error > 0.0 && p.status == "ok";
      if (!has) {
        run.clear();
        continue;
      }
      if (!run.empty() && p.error >= run.back().error) run.clear();
      run.push_back(p);
      if (run.size() > best.size()) best = run;
    }
    return best;
  }
  // The least-squares slope of log error against log refinement (the regime where the
  // step sets the error).
  static double order_fit(const std::vector<Point>& pts, const std::string& knob) {
    double sx = 0, sy = 0, sxx = 0, sxy = 0;
    int n = 0;
    for (const Point& p : pts) {
      const double x = std::log(p.knobs.at(knob)), y = std::log(p.error);
      sx += x, sy += y, sxx += x * x, sxy += x * y, ++n;
    }
    if (n < 2 || n * sxx - sx * sx == 0.0) return std::numeric_limits<double>::quiet_NaN();
    return -(n * sxy - sx * sy) / (n * sxx - sx * sx);
  }
  // The geometric rate per iteration: e(k) ~ C rate^k over the total iteration count k of
  // each point, by least squares on log e.
  static double iteration_rate(const std::vector<Point>& pts, const std::vector<Knob>& knobs) {
    double sx = 0, sy = 0, sxx = 0, sxy = 0;
    int n = 0;
    for (const Point& p : pts) {
      double k = 0.0;
      for (const Knob& kn : knobs)
        if (is_iteration(kn)) k += p.knobs.at(std::string(kn.spec->name));
      sx += k, sy += std::log(p.error), sxx += k * k, sxy += k * std::log(p.error), ++n;
    }
    if (n < 2 || n * sxx - sx * sx == 0.0) return std::numeric_limits<double>::quiet_NaN();
    return std::exp((n * sxy - sx * sy) / (n * sxx - sx * sx));
  }

  const Scenario& sc_;
  const PrecisionOptions& opt_;
  ThreadPool& pool_;
  PrecisionReference ref_;
  int done_ = 0;
  std::vector<std::pair<std::string, std::vector<Point>>> work_;
};

}  // namespace

nlohmann::json run_precision(const Scenario& given, const PrecisionOptions& opt, ThreadPool& pool) {
  const PrecisionReference ref =
      opt.reference.value_or(given.truth ? PrecisionReference::exact : PrecisionReference::self);
  if (ref == PrecisionReference::exact && !given.truth)
    throw InputError("--reference", "exact",
                     given.name + " has no exact answer (only a truth scenario does; use --reference self)");
  Scenario sc = given;
  const std::size_t strands = sc.groom.strand_count();
  const std::size_t keep = opt.keep_every > 0 ? opt.keep_every : (strands + kPrecisionStrands - 1) / kPrecisionStrands;
  if (keep > 1) {
    if (sc.follow)
      throw InputError("--keep-every", std::to_string(keep),
                       sc.name + " rebuilds follow hairs from its guides and cannot be thinned; give --keep-every 1");
    sc.groom = every_nth_strand(sc.groom, keep);
  }
  Precision p(sc, opt, pool, ref);
  nlohmann::json lines = nlohmann::json::array();
  for (const std::string& m : opt.models) {
    const ModelInfo* info = find_model(m);
    if (!info) throw InputError("--models", m, "unknown model");
    lines.push_back(p.line(*info));
  }
  p.mark_pareto();
  for (nlohmann::json& l : lines) l["work"] = p.work_json(l["model"].get<std::string>());
  return {{"scenario", sc.name},
          {"reference", ref == PrecisionReference::exact ? "exact" : "self"},
          {"error", ref == PrecisionReference::exact
                        ? "the largest |frequency error| of the kicked modes against the exact chain (runs[].truth)"
                        : "deviation RMS / mean strand length, over the frames, from the model at " +
                              std::to_string(static_cast<int>(kSelfFactor)) + "x every cost knob"},
          {"keep_every", keep},
          {"strands", sc.groom.strand_count()},
          {"frames", opt.frames > 0 ? opt.frames : sc.frames},
          {"lines", lines}};
}

namespace {
// A number in three significant digits, or "-" where there is none.
std::string sig(const nlohmann::json& v) {
  if (!v.is_number()) return "-";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3g", v.get<double>());
  return buf;
}
}  // namespace

std::string precision_table(const nlohmann::json& pr) {
  std::ostringstream os;
  os << pr["scenario"].get<std::string>() << ", against " << pr["reference"].get<std::string>() << " ("
     << pr["error"].get<std::string>() << ")\n";
  for (const nlohmann::json& l : pr["lines"]) {
    const nlohmann::json& step = l["step"];
    const nlohmann::json& it = l["iterations"];
    os << "  " << l["model"].get<std::string>() << ": order in "
       << (step.is_null() ? std::string("the step -") : step["knob"].get<std::string>() + " " + sig(step["order"]))
       << ", rate per iteration " << (it.is_null() ? "-" : sig(it["rate"])) << "\n";
    for (const nlohmann::json& p : l["work"]) {
      char buf[160];
      std::snprintf(buf, sizeof buf, "    x%-5g %10s ms/frame  error %-9s %-9s %-8s", p["factor"].get<double>(),
                    sig(p["ms_per_frame"]).c_str(), sig(p["error"]).c_str(), p["pareto"].get<bool>() ? "(front)" : "",
                    p["status"].get<std::string>().c_str());
      os << buf;
      for (const auto& [k, v] : p["knobs"].items()) os << " " << k << "=" << v.get<double>();
      os << "\n";
    }
  }
  return os.str();
}

}  // namespace hairbench
