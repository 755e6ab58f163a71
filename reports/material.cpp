#include "reports/material.h"

#include <Eigen/Dense>
#include <Eigen/Eigenvalues>

#include <algorithm>
#include <complex>
#include <vector>
#include <cmath>
#include <numbers>

namespace hairbench::material {

std::vector<PronyMode> prony_modes(std::span<const double> x, double dt, std::size_t first, double floor) {
  double peak = 0.0;
  for (std::size_t i = first; i < x.size(); ++i) peak = std::max(peak, std::abs(x[i]));
  std::size_t last = first;
  for (std::size_t i = first; i < x.size(); ++i)
    if (std::abs(x[i]) > floor * peak) last = i;
  const int n = static_cast<int>(last - first) + 1;
  const int order = std::min(kModeOrder, n / 3);
  if (!(peak > 0.0) || order < 2) return {};
  Eigen::VectorXd w(n);
  for (int i = 0; i < n; ++i) w[i] = x[first + static_cast<std::size_t>(i)] / peak;
  // Linear prediction w_i = sum_k a_k w_(i-k), least squares; the SVD solve gives the
  // smallest a where the signal holds fewer modes than the order (its extra roots then
  // carry no amplitude).
  Eigen::MatrixXd lp(n - order, order);
  Eigen::VectorXd rhs(n - order);
  for (int i = order; i < n; ++i) {
    for (int k = 0; k < order; ++k) lp(i - order, k) = w[i - 1 - k];
    rhs[i - order] = w[i];
  }
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(lp, Eigen::ComputeThinU | Eigen::ComputeThinV);
  svd.setThreshold(1e-9);
  const Eigen::VectorXd a = svd.solve(rhs);
  // The modes: the roots z_k of z^order - sum a_k z^(order-k), the companion matrix's
  // eigenvalues; their amplitudes c_k by least squares on w_i = sum c_k z_k^i.
  Eigen::MatrixXd companion = Eigen::MatrixXd::Zero(order, order);
  companion.row(0) = a.transpose();
  for (int k = 1; k < order; ++k) companion(k, k - 1) = 1.0;
  const Eigen::VectorXcd z = Eigen::EigenSolver<Eigen::MatrixXd>(companion, false).eigenvalues();
  Eigen::MatrixXcd vander(n, order);
  for (int k = 0; k < order; ++k) {
    std::complex<double> p = 1.0;
    for (int i = 0; i < n; ++i, p *= z[k]) vander(i, k) = p;
  }
  const Eigen::VectorXcd c = vander.colPivHouseholderQr().solve(w.cast<std::complex<double>>());
  // Each mode's share of the signal's energy over the window.
  std::vector<double> energy(order, 0.0);
  double total = 0.0;
  for (int k = 0; k < order; ++k) {
    for (int i = 0; i < n; ++i) energy[k] += std::norm(c[k] * vander(i, k));
    total += energy[k];
  }
  std::vector<PronyMode> out;
  for (int k = 0; k < order; ++k) {
    if (!std::isfinite(std::abs(z[k]))) continue;
    out.push_back({-std::log(std::abs(z[k])) / dt, std::abs(std::arg(z[k])) / dt, total > 0.0 ? energy[k] / total : 0.0});
  }
  return out;
}

// The slowest (largest |z|, smallest sigma) of the modes holding at least kModeShare.
Mode slowest_mode(std::span<const double> x, double dt, std::size_t first, double floor) {
  Mode m;
  const std::vector<PronyMode> modes = prony_modes(x, dt, first, floor);
  const PronyMode* slowest = nullptr;
  for (const PronyMode& p : modes)
    if (p.share >= kModeShare && (!slowest || p.sigma < slowest->sigma)) slowest = &p;
  if (!slowest) return m;
  m.sigma = slowest->sigma;
  m.omega = slowest->omega;
  return m;
}

Ratios ratios(const Card& card, const Card& reference) {
  auto over = [](double a, double b) {
    return std::isfinite(a) && std::isfinite(b) && b != 0.0 ? a / b : kNaN;
  };
  return {over(card.sag, reference.sag), over(card.stretch, reference.stretch), over(card.sigma, reference.sigma),
          over(card.omega, reference.omega)};
}

namespace {
nlohmann::json num(double x) { return std::isfinite(x) ? nlohmann::json(x) : nlohmann::json(nullptr); }
}  // namespace

nlohmann::json card_json(const Card& card, const Card* reference) {
  if (!card.measured) return {{"skipped", card.skipped_why}};
  nlohmann::json j = {{"strands", card.strands}, {"settle_s", card.settle_s}, {"sag", num(card.sag)},
                      {"stretch", num(card.stretch)}, {"sigma", num(card.sigma)}, {"omega", num(card.omega)}};
  if (reference && reference->measured) {
    const Ratios r = ratios(card, *reference);
    j["vs_reference"] = {{"sag", num(r.sag)}, {"stretch", num(r.stretch)}, {"sigma", num(r.sigma)},
                         {"omega", num(r.omega)}};
  }
  return j;
}

nlohmann::json calibration_json(const Calibration& c) {
  nlohmann::json fits = nlohmann::json::array();
  for (const Calibration::Fit& f : c.fits) {
    nlohmann::json j = {{"role", f.role}, {"param", f.param}};
    if (!f.on.empty())
      j.update({{"on", f.on},
                {"factor", num(f.factor)},
                {"from", num(f.from)},
                {"to", num(f.to)},
                {"target", num(f.target)},
                {"reached", num(f.reached)},
                {"within", f.within},
                {"evaluations", f.evaluations}});
    if (!f.note.empty()) j["note"] = f.note;
    fits.push_back(std::move(j));
  }
  return {{"fits", std::move(fits)}, {"seconds", c.seconds}};
}

}  // namespace hairbench::material
