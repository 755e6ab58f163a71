#include "models/halen2007/step_bounds.h"

#include "kernels/halen2007/reference/halen_kernels.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <deque>
#include <iomanip>
#include <limits>
#include <mutex>
#include <sstream>
#include <span>
#include <vector>

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
// free edge before it (a segment pinned at both ends is the head's: a spring's reaction
// on it moves nothing).
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
      before = free ? l : 0.0;
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

StepBound travel_bound(const Groom& g, const ParamSet& /*p*/, const Vec3f& gravity) {
  double shortest = std::numeric_limits<double>::infinity();
  std::vector<double> free;
  for (std::size_t s = 0; s < g.strand_count(); ++s) {
    const std::uint32_t b = g.strand_begin(s), n = g.strand_size(s);
    free.clear();
    for (std::uint32_t i = 1; i < n; ++i)
      if (g.positions[b + i].w() != 0.0f || g.positions[b + i - 1].w() != 0.0f)
        free.push_back((g.positions[b + i] - g.positions[b + i - 1]).head<3>().cast<double>().norm());
    if (free.empty()) continue;
    std::nth_element(free.begin(), free.begin() + static_cast<std::ptrdiff_t>(free.size() / 2), free.end());
    shortest = std::min(shortest, free[free.size() / 2]);
  }
  StepBound b;
  const double gn = gravity.cast<double>().norm();
  b.max_step = gn > 0.0 && std::isfinite(shortest) ? std::sqrt(kEdgeTravel * shortest / (2.0 * gn))
                                                   : std::numeric_limits<double>::max();
  b.why = "travel: 2|g|h^2 <= " + num(kEdgeTravel) + " x the shortest median free edge of a strand (" +
          num(shortest) + " m)";
  return b;
}

StepBound spring_bound(const Groom& g, const ParamSet& p, const Vec3f& gravity) {
  const double k = max_param(g, p, "stiffness");
  return explicit_spring_bound(g, k, gravity, "k = " + num(k) + " s^-2");
}

namespace {

double measure_rest_stiffness(const Groom& g, const ParamSet& p) {
  namespace k = kernels;
  const auto frames = static_cast<k::CascadeFrames>(p.get_int("frames"));
  const bool reactions = p.get_int("reactions") != 0;
  double largest = 0.0;
  for (std::size_t s = 0; s < g.strand_count(); ++s) {
    const std::size_t n = g.strand_size(s), r = g.strand_region[s];
    const auto rest = std::span(g.positions).subspan(g.strand_begin(s), n);
    std::vector<float> inv(n), ku(n), kd(n), lift(n), lever(n), twist(n);
    std::vector<int> base(n);
    std::vector<k::Mat3f> rest_space(n), space(n);
    std::vector<Vec3f> up(n), down(n), plus(n), minus(n);
    k::cascade_setup(rest, static_cast<float>(p.get("stiffness", r)), static_cast<float>(p.get("falloff_scale", r)),
                     p.get_int("falloff_exponent", r), static_cast<float>(p.get("down_fraction", r)), frames, inv, ku,
                     kd, lift, base, lever, rest_space, up, down);
    const k::CascadeStrand cs{inv, ku, kd, lift, base, lever, up, down};
    float shortest = std::numeric_limits<float>::infinity();
    for (std::size_t i = 1; i < n; ++i) shortest = std::min(shortest, (rest[i] - rest[i - 1]).head<3>().norm());
    if (!(shortest > 0.0f)) continue;
    // Power iteration on v -> -P J P v, J the springs' Jacobian at rest by central
    // differences of displacements 1% of the shortest edge (the forces are float; smaller
    // ones round), P the projection on the moves that keep every edge's length (root to
    // tip, each vertex's move less its part along its edge relative to its parent's
    // move): the edge corrections take the rest, so the springs' stiffness along the
    // edges bounds no step.
    const float eps = 0.01f * shortest;
    std::vector<Vec3f> v(n);
    for (std::size_t i = 0; i < n; ++i)
      v[i] = Vec3f(std::sin(1.0f + i), std::cos(2.0f + 3.0f * i), std::sin(5.0f * i + 0.5f));
    auto project = [&] {
      for (std::size_t i = 0; i < n; ++i) {
        if (inv[i] == 0.0f) {
          v[i].setZero();
          continue;
        }
        if (i == 0) continue;
        const Vec3f e = (rest[i] - rest[i - 1]).head<3>().normalized();
        v[i] -= (v[i] - v[i - 1]).dot(e) * e;
      }
    };
    std::vector<Vec4f> x(rest.begin(), rest.end());
    double lambda = 0.0;
    for (int it = 0; it < 40; ++it) {
      project();
      double norm = 0.0;
      for (const Vec3f& vi : v) norm += vi.cast<double>().squaredNorm();
      norm = std::sqrt(norm);
      if (!(norm > 0.0)) break;
      for (Vec3f& vi : v) vi /= static_cast<float>(norm);
      auto forces = [&](float sign, std::vector<Vec3f>& out) {
        for (std::size_t i = 0; i < n; ++i) x[i].head<3>() = rest[i].head<3>() + sign * eps * v[i];
        k::tangent_spaces(x, rest_space[0], frames, base, space);
        k::cascade_accelerations(x, space, cs, reactions, frames, Vec3f::Zero(), Vec3f::Zero(), twist, out);
      };
      forces(1.0f, plus);
      forces(-1.0f, minus);
      for (std::size_t i = 0; i < n; ++i) v[i] = (minus[i] - plus[i]) / (2.0f * eps);
      project();
      double applied = 0.0;
      for (const Vec3f& vi : v) applied += vi.cast<double>().squaredNorm();
      lambda = std::sqrt(applied);
    }
    largest = std::max(largest, lambda);
  }
  return largest;
}

// Everything measure_rest_stiffness reads, exactly: the groom's vertices, strands and
// regions, and the parameters of each region and of the whole groom.
struct StiffnessKey {
  std::vector<Vec4f> positions;
  std::vector<std::uint32_t> strand_offsets;
  std::vector<std::uint16_t> strand_region;
  std::vector<double> params;

  StiffnessKey(const Groom& g, const ParamSet& p)
      : positions(g.positions), strand_offsets(g.strand_offsets), strand_region(g.strand_region) {
    params = {static_cast<double>(p.get_int("frames")), static_cast<double>(p.get_int("reactions"))};
    for (std::size_t r = 0; r < g.region_names.size(); ++r)
      for (const char* name : {"stiffness", "falloff_scale", "falloff_exponent", "down_fraction"})
        params.push_back(p.get(name, r));
  }
  bool operator==(const StiffnessKey& o) const {
    return params == o.params && strand_offsets == o.strand_offsets && strand_region == o.strand_region &&
           positions.size() == o.positions.size() &&
           std::memcmp(positions.data(), o.positions.data(), positions.size() * sizeof(Vec4f)) == 0;
  }
};

}  // namespace

// The measurement is a power iteration of 40 rounds per strand, and a comparison asks for
// it again and again with the same groom and parameters: for each run, its rest twin and
// its probes, and for every scenario on the same procedural groom. The last few answers
// are kept; an answer depends on its inputs alone, so a kept one is the one the
// measurement would give.
double cascade_rest_stiffness(const Groom& g, const ParamSet& p) {
  constexpr std::size_t kKept = 8;
  static std::mutex mutex;
  static std::deque<std::pair<StiffnessKey, double>> kept;
  StiffnessKey key(g, p);
  {
    const std::lock_guard<std::mutex> lock(mutex);
    for (const auto& [k, value] : kept)
      if (k == key) return value;
  }
  const double value = measure_rest_stiffness(g, p);
  const std::lock_guard<std::mutex> lock(mutex);
  kept.emplace_front(std::move(key), value);
  if (kept.size() > kKept) kept.pop_back();
  return value;
}

StepBound cascade_bound(const Groom& g, const ParamSet& p, const Vec3f& gravity) {
  const double k = max_param(g, p, "stiffness");
  double down = 0.0;
  for (std::size_t r = 0; r < g.region_names.size(); ++r) down = std::max(down, p.get("down_fraction", r));
  const double ratio = p.get_int("reactions") != 0 ? free_edges(g).ratio : 0.0;
  const double k_eff = k * (1.0 + down) * (1.0 + ratio) * (1.0 + ratio);
  const double measured = cascade_rest_stiffness(g, p);
  if (measured > k_eff)
    return explicit_spring_bound(g, measured, gravity,
                                 "the springs' stiffest mode at rest, " + num(measured) + " s^-2");
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
