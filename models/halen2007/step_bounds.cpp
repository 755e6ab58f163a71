#include "models/halen2007/step_bounds.h"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <limits>
#include <sstream>

namespace hairbench::halen {
namespace {

std::string num(double v) {
  std::ostringstream os;
  os << std::setprecision(3) << v;
  return os.str();
}

// The largest base stiffness over the groom's regions (the falloff only lowers it).
double max_param(const Groom& g, const ParamSet& p, const char* name) {
  double k = 0.0;
  for (std::size_t r = 0; r < g.region_names.size(); ++r) k = std::max(k, p.get(name, r));
  return k;
}

// The shortest rest edge with a free end, and the largest ratio of a free edge to the
// edge before it.
struct Edges {
  double shortest = std::numeric_limits<double>::infinity();
  double ratio = 1.0;
};
Edges free_edges(const Groom& g) {
  Edges e;
  for (std::size_t s = 0; s < g.strand_count(); ++s) {
    const std::uint32_t b = g.strand_begin(s), n = g.strand_size(s);
    double before = 0.0;
    for (std::uint32_t i = 1; i < n; ++i) {
      const double l = (g.positions[b + i] - g.positions[b + i - 1]).head<3>().cast<double>().norm();
      const bool free = g.positions[b + i].w() != 0.0f || g.positions[b + i - 1].w() != 0.0f;
      if (free) {
        e.shortest = std::min(e.shortest, l);
        if (before > 0.0) e.ratio = std::max(e.ratio, l / before);
      }
      before = l;
    }
  }
  return e;
}

StepBound explicit_spring_bound(const Groom& g, double k, const Vec3f& gravity, const std::string& k_text) {
  const Edges e = free_edges(g);
  StepBound b;
  const double spring = k > 0.0 ? kOmegaStep / std::sqrt(k) : std::numeric_limits<double>::infinity();
  const double gn = gravity.cast<double>().norm();
  const double edge = gn > 0.0 && std::isfinite(e.shortest) ? std::sqrt(kEdgeTravel * e.shortest / (2.0 * gn))
                                                            : std::numeric_limits<double>::infinity();
  if (spring <= edge) {
    b.max_step = spring;
    b.why = "spring: omega h <= " + num(kOmegaStep) + " with " + k_text;
  } else {
    b.max_step = edge;
    b.why = "edge correction: 2|g|h^2 <= " + num(kEdgeTravel) + " x the shortest free edge (" + num(e.shortest) +
            " m)";
  }
  if (!std::isfinite(b.max_step)) b.max_step = std::numeric_limits<double>::max();
  return b;
}

}  // namespace

StepBound spring_bound(const Groom& g, const ParamSet& p, const Vec3f& gravity) {
  const double k = max_param(g, p, "stiffness");
  return explicit_spring_bound(g, k, gravity, "k = " + num(k) + " s^-2");
}

StepBound cascade_bound(const Groom& g, const ParamSet& p, const Vec3f& gravity) {
  const double k = max_param(g, p, "stiffness");
  double down = 0.0;
  for (std::size_t r = 0; r < g.region_names.size(); ++r) down = std::max(down, p.get("down_fraction", r));
  const double ratio = p.get_int("reactions") != 0 ? free_edges(g).ratio : 0.0;
  const double k_eff = k * (1.0 + down) * (1.0 + ratio) * (1.0 + ratio);
  return explicit_spring_bound(g, k_eff, gravity,
                               "k (1 + down)(1 + r)^2 = " + num(k_eff) + " s^-2, edge ratio r = " + num(ratio));
}

StepBound forest_bound(const Groom& g, const ParamSet& p, const Vec3f&) {
  const double k = max_param(g, p, "joint_stiffness");
  double v = std::numeric_limits<double>::infinity();
  for (std::size_t r = 0; r < g.region_names.size(); ++r) v = std::min(v, p.get("joint_damping", r));
  StepBound b;
  if (!(v > 0.0)) {
    b.why = "joint_damping 0: explicit Euler of an undamped joint grows at any step";
    return b;
  }
  const double damped = k > 0.0 ? v / (4.0 * k) : std::numeric_limits<double>::max();
  const double euler = 1.0 / (2.0 * v);
  b.max_step = std::min(damped, euler);
  b.why = damped < euler ? "joints: v >= 4 k h with k = " + num(k) + " s^-2, v = " + num(v) + " s^-1"
                         : "joints: 4 v h <= 2 with v = " + num(v) + " s^-1";
  return b;
}

}  // namespace hairbench::halen
