#include "harness/calibrate.h"

#include "harness/probe.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>

namespace hairbench {

namespace {

std::string text(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%.3g", v);
  return b;
}

const ParamSpec* with_role(const ModelInfo& info, ParamRole role) {
  for (const ParamSpec& p : info.params)
    if (p.role == role) return &p;
  return nullptr;
}

// The factors that keep every region's value of `spec` inside its range.
std::pair<double, double> factor_range(const ParamSet& params, const ParamSpec& spec) {
  double lo = 0.0, hi = std::numeric_limits<double>::infinity();
  auto bound = [&](double v) {
    if (!(v > 0.0)) return;
    lo = std::max(lo, spec.min / v);
    hi = std::min(hi, spec.max / v);
  };
  bound(params.get(spec.name));
  for (std::size_t r = 0; r < params.regions().size(); ++r) bound(params.get(spec.name, r));
  return {lo, hi};
}

// One fit: the factor on `spec` whose measure is nearest `target`, within tolerance.
struct Search {
  const ParamSpec& spec;
  std::function<double(double)> measure;  // the quantity at a factor
  double target;
  std::function<bool(double)> within;
  std::function<double(double)> distance;  // how far a value is from the target
};

void fit(const Search& s, const ParamSet& params, material::Calibration::Fit& out) {
  const auto [lo, hi] = factor_range(params, s.spec);
  out.from = params.get(s.spec.name);
  out.target = s.target;
  struct Point {
    double factor, value;
  };
  std::vector<Point> grid;
  for (int k = -3; k <= 3; ++k) {
    const double f = std::pow(4.0, k);
    if (f < lo || f > hi || !(out.from > 0.0)) continue;
    grid.push_back({f, s.measure(f)});
    ++out.evaluations;
  }
  if (grid.empty()) {
    out.note = out.param + " " + text(out.from) + " cannot be scaled inside its range";
    return;
  }
  std::size_t best = 0;
  for (std::size_t i = 1; i < grid.size(); ++i)
    if (s.distance(grid[i].value) < s.distance(grid[best].value)) best = i;
  Point at = grid[best];
  // Bisect between the best point and a neighbour on the target's other side.
  auto side = [&](double v) { return v > s.target; };
  for (const std::size_t n : {best + 1, best - 1}) {
    if (s.within(at.value) || n >= grid.size() || !std::isfinite(grid[n].value) || !std::isfinite(at.value) ||
        side(grid[n].value) == side(at.value))
      continue;
    Point a = at, b = grid[n];
    for (int i = 0; i < kMaxBisections && !s.within(at.value); ++i) {
      const Point m{std::sqrt(a.factor * b.factor), s.measure(std::sqrt(a.factor * b.factor))};
      ++out.evaluations;
      if (s.distance(m.value) < s.distance(at.value)) at = m;
      (side(m.value) == side(a.value) ? a : b) = m;
    }
    break;
  }
  out.reached = at.value;
  out.within = s.within(at.value);
  // A material that cannot be matched is left as it is: a step towards the target would
  // change it without making it the reference's (and stiffening the wisp model towards a
  // sag it cannot reach made it unstable on five default scenarios).
  out.factor = out.within ? at.factor : 1.0;
  out.to = out.from * out.factor;
  if (!out.within)
    out.note = "cannot reach the reference's " + out.on + " " + text(s.target) + ": " + text(at.value) +
               " at the closest, " + out.param + " " + text(out.from * at.factor) + " (range " + text(s.spec.min) +
               " to " + text(s.spec.max) + "); left as it is";
}

}  // namespace

ParamSet calibrate(const ModelInfo& info, const Scenario& sc, ParamSet params, const material::Card& target,
                   const std::vector<ParamOverride>& given, ThreadPool& pool, const std::string& device,
                   material::Calibration& out) {
  const auto start = std::chrono::steady_clock::now();
  auto scaled = [&](const ParamSpec& spec, double factor) {
    ParamSet p = params;
    p.scale(spec.name, factor);
    apply_auto_substeps(info, sc, p, given);
    return p;
  };
  auto sag = [&](const ParamSpec& spec, double factor) {
    return probe_at_rest(info, sc, scaled(spec, factor), pool, device, {false, false}).card.sag;
  };
  auto given_here = [&](const ParamSpec& spec) {
    return std::any_of(given.begin(), given.end(), [&](const ParamOverride& o) {
      return o.name == spec.name && (o.model == "*" || o.model == info.name);
    });
  };

  material::Calibration::Fit stiffness;
  stiffness.role = "stiffness";
  const ParamSpec* spec = with_role(info, ParamRole::stiffness);
  if (spec) stiffness.param = std::string(spec->name);
  if (!spec) {
    stiffness.note = "the model marks no stiffness parameter";
  } else if (given_here(*spec)) {
    stiffness.note = stiffness.param + " is given on the command line: kept";
  } else {
    const double tolerance = std::max(kSagTolerance * std::abs(target.sag), kSagFloor);
    const double own = sag(*spec, 1.0), softer = sag(*spec, 0.25);
    if (!(std::abs(softer - own) > tolerance)) {
      stiffness.note = "the sag does not answer " + stiffness.param + " (" + text(own) + " at its value, " +
                       text(softer) + " at a quarter of it): left as it is";
    } else {
      stiffness.on = "sag";
      fit({*spec, [&](double x) { return sag(*spec, x); }, target.sag,
           [&](double v) { return std::abs(v - target.sag) <= tolerance; },
           [&](double v) { return std::isfinite(v) ? std::abs(v - target.sag) : HUGE_VAL; }},
          params, stiffness);
      if (stiffness.factor != 1.0) params = scaled(*spec, stiffness.factor);
    }
    stiffness.evaluations += 2;
  }
  out.fits.push_back(stiffness);

  // The damping is not fitted: the card's decay rate moves with the frames it is read
  // from, and fitted on it the damping made runs unstable or slow to return
  // (docs/metrics.md, Calibration). Its residual is the card's vs_reference.sigma.
  material::Calibration::Fit damping;
  damping.role = "damping";
  const ParamSpec* damper = with_role(info, ParamRole::damping);
  damping.param = damper ? std::string(damper->name) : "";
  damping.note = damper ? damping.param + " not fitted (the decay rate is reported, not matched): its residual is "
                                          "the card's sigma over the reference's"
                        : "the model marks no damping parameter";
  out.fits.push_back(damping);
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return params;
}

}  // namespace hairbench
