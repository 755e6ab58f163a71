#include "reports/truth.h"

#include "reports/material.h"

#include <cmath>
#include <limits>
#include <map>
#include <stdexcept>

namespace hairbench::truth {

namespace {
using Vec3d = Eigen::Vector3d;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
nlohmann::json num(double x) { return std::isfinite(x) ? nlohmann::json(x) : nlohmann::json(nullptr); }
}  // namespace

StrandChain strand_chain(const Groom& g, std::size_t strand) {
  const std::size_t b = g.strand_begin(strand), n = g.strand_size(strand);
  const std::string name = "strand " + std::to_string(strand);
  std::size_t pinned = 0;
  while (pinned < n && g.positions[b + pinned].w() == 0.0f) ++pinned;
  if (pinned == 0 || pinned == n) throw std::invalid_argument(name + " has no pinned vertex or no free one: not a hanging chain");
  StrandChain c;
  c.pivot = b + pinned - 1;
  c.first = b + pinned;
  for (std::size_t i = c.first; i < b + n; ++i) {
    if (g.positions[i].w() == 0.0f)
      throw std::invalid_argument(name + " has a pinned vertex past its free ones: not a hanging chain");
    c.masses.push_back(1.0 / g.positions[i].w());
    c.lengths.push_back((g.positions[i] - g.positions[i - 1]).head<3>().cast<double>().norm());
    c.length += c.lengths.back();
  }
  return c;
}

Observer::Observer(const Groom& simulated, const Kick& kick, const Vec3f& gravity)
    : rest_(simulated.positions), kicked_(simulated.positions), direction_(kick.direction.normalized()) {
  const Vec3d down = gravity.cast<double>().normalized(), across = direction_.cast<double>();
  const double g = gravity.cast<double>().norm();
  for (std::size_t s = 0; s < simulated.strand_count(); ++s) {
    Strand st;
    st.chain = strand_chain(simulated, s);
    st.index = kick.modes[s % kick.modes.size()];
    if (static_cast<std::size_t>(st.index) > st.chain.masses.size())
      throw std::invalid_argument("strand " + std::to_string(s) + " has " + std::to_string(st.chain.masses.size()) +
                                  " masses in the simulated groom, too few for mode " + std::to_string(st.index));
    st.mode = chain::modes(st.chain.masses, st.chain.lengths, g, static_cast<std::size_t>(st.index)).back();
    st.continuous_omega = chain::continuous_omega(st.index, st.chain.length, g);
    // Link k turned so that its horizontal run is the shape's step: every mass lands
    // a L shape_k across from where it hung, and the link keeps its length.
    const double a = kick.amplitude * st.chain.length;
    Vec3d p = simulated.positions[st.chain.pivot].head<3>().cast<double>();
    double x_prev = 0.0;
    for (std::size_t k = 0; k < st.chain.masses.size(); ++k) {
      const double dx = a * st.mode.shape[k] - x_prev, l = st.chain.lengths[k];
      p += dx * across + std::sqrt(std::max(0.0, l * l - dx * dx)) * down;
      x_prev = a * st.mode.shape[k];
      kicked_[st.chain.first + k].head<3>() = p.cast<float>();
    }
    strands_.push_back(std::move(st));
  }
  q_.assign(strands_.size(), {});
}

void Observer::add(std::span<const Vec4f> positions) {
  for (std::size_t s = 0; s < strands_.size(); ++s) {
    const Strand& st = strands_[s];
    x_.resize(st.chain.masses.size());
    for (std::size_t k = 0; k < x_.size(); ++k) {
      const std::size_t v = st.chain.first + k;
      x_[k] = (positions[v] - rest_[v]).head<3>().cast<double>().dot(direction_.cast<double>());
    }
    q_[s].push_back(chain::modal_amplitude(st.mode, st.chain.masses, x_));
  }
}

// The fitted mode is the oscillating one (omega > 0) that holds the most of q's energy:
// a slower or steadier component, such as a drift of the equilibrium, is not the mode.
std::vector<Observer::StrandResult> Observer::result(double dt) const {
  std::vector<StrandResult> out;
  for (std::size_t s = 0; s < strands_.size(); ++s) {
    const Strand& st = strands_[s];
    StrandResult r;
    r.mode = st.index;
    r.masses = st.chain.masses.size();
    r.exact_omega = st.mode.omega;
    r.resolution_error = st.mode.omega / st.continuous_omega - 1.0;
    r.omega = r.sigma = r.frequency_error = kNaN;
    bool found = false;
    for (const material::PronyMode& m : material::prony_modes(q_[s], dt, 0, 0.0)) {
      if (!(m.omega > 0.0) || (found && m.share <= r.share)) continue;
      found = true;
      r.omega = m.omega;
      r.sigma = m.sigma;
      r.share = m.share;
    }
    if (found) {
      r.share *= 2.0;  // the pair's
      r.frequency_error = r.omega / r.exact_omega - 1.0;
    }
    out.push_back(r);
  }
  return out;
}

nlohmann::json result_json(std::span<const Observer::StrandResult> strands) {
  std::map<int, std::vector<const Observer::StrandResult*>> by_mode;
  for (const auto& r : strands) by_mode[r.mode].push_back(&r);
  nlohmann::json modes = nlohmann::json::array();
  for (const auto& [mode, rs] : by_mode) {
    double exact = 0.0, omega = 0.0, sigma = 0.0, share = 0.0, resolution = 0.0;
    for (const auto* r : rs) {
      exact += r->exact_omega;
      resolution += r->resolution_error;
      omega += r->omega;
      sigma += r->sigma;
      share += r->share;
    }
    const double n = static_cast<double>(rs.size());
    exact /= n;
    omega /= n;
    sigma /= n;
    modes.push_back({{"mode", mode},
                     {"strands", rs.size()},
                     {"masses", rs.front()->masses},
                     {"exact_omega", num(exact)},
                     {"omega", num(omega)},
                     {"frequency_error", num(omega / exact - 1.0)},
                     {"resolution_error", num(resolution / n)},
                     {"sigma", num(sigma)},
                     {"damping_ratio", num(sigma / omega)},
                     {"share", num(share / n)}});
  }
  return modes;
}

}  // namespace hairbench::truth
