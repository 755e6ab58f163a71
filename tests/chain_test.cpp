// The hanging chain's exact small oscillations (core/chain_modes.h), the answer the truth
// scenarios hold every model to: against closed forms, against Eigen's dense generalized
// eigensolver on the assembled K and M, and against the uniform heavy chain's Bessel
// limit as the number of masses grows.
#include "core/chain_modes.h"
#include "reports/material.h"

#include <Eigen/Dense>
#include <Eigen/Eigenvalues>
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>
#include <span>
#include <stdexcept>
#include <vector>

namespace hairbench {
namespace {

// The double pendulum of equal masses and links: w^2 = (g / l)(2 -+ sqrt 2), the link
// angles in the ratio theta_2 / theta_1 = +-sqrt 2, so the masses' displacements
// x_1 = l theta_1, x_2 = l (theta_1 + theta_2) in the ratio x_1 / x_2 = 1 / (1 +- sqrt 2).
TEST(Chain, EqualDoublePendulumHasItsClosedForm) {
  const double g = 9.81, l = 0.3;
  const std::vector<double> m = {0.2, 0.2}, len = {l, l};
  const auto modes = chain::modes(m, len, g);
  ASSERT_EQ(modes.size(), 2u);
  EXPECT_NEAR(modes[0].omega, std::sqrt(g / l * (2.0 - std::sqrt(2.0))), 1e-12);
  EXPECT_NEAR(modes[1].omega, std::sqrt(g / l * (2.0 + std::sqrt(2.0))), 1e-12);
  EXPECT_NEAR(modes[0].shape[0] / modes[0].shape[1], 1.0 / (1.0 + std::sqrt(2.0)), 1e-10);
  EXPECT_NEAR(modes[1].shape[0] / modes[1].shape[1], 1.0 / (1.0 - std::sqrt(2.0)), 1e-10);
  // A single pendulum: w = sqrt(g / l).
  EXPECT_NEAR(chain::modes(std::vector<double>{1.0}, std::vector<double>{l}, g)[0].omega, std::sqrt(g / l), 1e-12);
}

// Unequal masses and links (the forest's joints, the wisp's nodes are such chains): every
// frequency and shape as Eigen's GeneralizedSelfAdjointEigenSolver finds them on the
// dense K and M, and the shapes M-orthogonal, so modal_amplitude reads one mode alone.
TEST(Chain, AgreesWithADenseGeneralizedEigensolverOnAnUnevenChain) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> mass(0.5, 2.0), link(0.01, 0.05);
  for (const int n : {3, 8, 32}) {
    SCOPED_TRACE(n);
    std::vector<double> m(n), l(n);
    for (int k = 0; k < n; ++k) {
      m[k] = mass(rng) * 1e-4;
      l[k] = link(rng);
    }
    const double g = 9.81;
    Eigen::MatrixXd K = Eigen::MatrixXd::Zero(n, n), M = Eigen::MatrixXd::Zero(n, n);
    for (int k = 0; k < n; ++k) {
      double weight = 0.0;
      for (int j = k; j < n; ++j) weight += m[j];
      const double c = g * weight / l[k];  // link k ends at mass k
      K(k, k) += c;
      if (k > 0) {
        K(k - 1, k - 1) += c;
        K(k - 1, k) -= c;
        K(k, k - 1) -= c;
      }
      M(k, k) = m[k];
    }
    Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> dense(K, M);
    ASSERT_EQ(dense.info(), Eigen::Success);
    const auto modes = chain::modes(m, l, g);
    ASSERT_EQ(modes.size(), static_cast<std::size_t>(n));
    for (int i = 0; i < n; ++i) {
      const double w = std::sqrt(dense.eigenvalues()[i]);
      EXPECT_NEAR(modes[i].omega, w, 1e-9 * w) << "mode " << i;
      Eigen::VectorXd v = dense.eigenvectors().col(i);
      v /= v.cwiseAbs().maxCoeff() * (v[n - 1] < 0 ? -1.0 : 1.0);
      for (int k = 0; k < n; ++k) EXPECT_NEAR(modes[i].shape[k], v[k], 1e-7) << "mode " << i << " mass " << k;
      for (int j = 0; j < std::min(n, 4); ++j)
        EXPECT_NEAR(chain::modal_amplitude(modes[i], m, modes[j].shape), i == j ? 1.0 : 0.0, 1e-8) << i << " " << j;
    }
  }
}

TEST(Chain, BesselZerosAreZerosOfJ0) {
  EXPECT_NEAR(chain::bessel_j0_zero(1), 2.404825557695773, 1e-13);
  for (int n = 1; n <= 6; ++n) {
    const double a = chain::bessel_j0_zero(n);
    EXPECT_LT(std::abs(std::cyl_bessel_j(0.0, a)), 1e-14) << n;
    if (n > 1) {
      EXPECT_GT(a - chain::bessel_j0_zero(n - 1), 3.0) << n;  // about pi apart
    }
  }
}

// N equal masses on N equal links tend to the uniform heavy chain, at first order: the
// lumped masses hang the chain's weight half a link low, so each frequency's relative
// error falls like 1/N once the mode spans many links (measured: about -1/(4N) for the
// first three modes from N = 32 on). The test reads the observed order over two
// fourfold refinements, and the error at N = 512.
TEST(Chain, EqualMassesTendToTheBesselLimitAtFirstOrder) {
  const double g = 9.81, L = 0.25;
  double previous[3] = {0.0, 0.0, 0.0};
  for (const int n : {32, 128, 512}) {
    const std::vector<double> m(n, 1.0 / n), l(n, L / n);
    const auto modes = chain::modes(m, l, g, 3);
    for (int i = 0; i < 3; ++i) {
      const double exact = chain::continuous_omega(i + 1, L, g);
      const double err = std::abs(modes[i].omega / exact - 1.0);
      RecordProperty("N" + std::to_string(n) + "_mode" + std::to_string(i + 1), std::to_string(err));
      if (previous[i] > 0.0) {
        const double order = std::log(previous[i] / err) / std::log(4.0);
        EXPECT_NEAR(order, 1.0, 0.1) << "N " << n << " mode " << i + 1;
      }
      if (n == 512) {
        EXPECT_LT(err, 1e-3) << "mode " << i + 1;
      }
      previous[i] = err;
    }
  }
}

// The linearisation itself, against the chain's full nonlinear motion: N point masses on
// rigid massless links in the link angles theta_i from the vertical, whose Lagrangian
// equations are
//   sum_j A_ij l_i l_j [cos(th_i - th_j) th_j'' + sin(th_i - th_j) th_j'^2] + g l_i B_i sin th_i = 0
// with B_i = m_i + ... + m_N and A_ij = B_max(i,j), integrated by classical RK4.
std::vector<double> chain_accelerations(std::span<const double> m, std::span<const double> l, double g,
                                        std::span<const double> th, std::span<const double> w) {
  const int n = static_cast<int>(m.size());
  std::vector<double> B(n);
  double below = 0.0;
  for (int k = n; k-- > 0;) B[k] = below += m[k];
  Eigen::MatrixXd A(n, n);
  Eigen::VectorXd rhs(n);
  for (int i = 0; i < n; ++i) {
    rhs[i] = -g * l[i] * B[i] * std::sin(th[i]);
    for (int j = 0; j < n; ++j) {
      const double a = B[std::max(i, j)] * l[i] * l[j];
      A(i, j) = a * std::cos(th[i] - th[j]);
      rhs[i] -= a * std::sin(th[i] - th[j]) * w[j] * w[j];
    }
  }
  const Eigen::VectorXd acc = A.ldlt().solve(rhs);
  return std::vector<double>(acc.data(), acc.data() + n);
}

// Started from rest in `mode`'s shape with the masses displaced by `amplitude` (x_k =
// amplitude * shape_k), six periods at 200 RK4 steps each: the Prony fit
// (material::slowest_mode) of the modal amplitude sampled every tenth step.
material::Mode swing(std::span<const double> m, std::span<const double> l, double g, const chain::Mode& mode,
                     double amplitude) {
  const std::size_t n = m.size();
  // Angles from the displacements: sin th_k = (x_k - x_{k-1}) / l_k.
  std::vector<double> th(n), w(n, 0.0);
  for (std::size_t k = 0; k < n; ++k)
    th[k] = std::asin(amplitude * (mode.shape[k] - (k ? mode.shape[k - 1] : 0.0)) / l[k]);
  const double dt = 2.0 * std::numbers::pi / mode.omega / 200.0;
  auto add = [](std::vector<double> y, const std::vector<double>& dy, double h) {
    for (std::size_t k = 0; k < y.size(); ++k) y[k] += h * dy[k];
    return y;
  };
  std::vector<double> q;
  for (int step = 0; step <= 200 * 6; ++step) {
    if (step % 10 == 0) {
      std::vector<double> x(n);
      double sum = 0.0;
      for (std::size_t k = 0; k < n; ++k) x[k] = sum += l[k] * std::sin(th[k]);
      q.push_back(chain::modal_amplitude(mode, m, x));
    }
    const auto a1 = chain_accelerations(m, l, g, th, w);
    const auto t2 = add(th, w, dt / 2), w2 = add(w, a1, dt / 2);
    const auto a2 = chain_accelerations(m, l, g, t2, w2);
    const auto t3 = add(th, w2, dt / 2), w3 = add(w, a2, dt / 2);
    const auto a3 = chain_accelerations(m, l, g, t3, w3);
    const auto t4 = add(th, w3, dt), w4 = add(w, a3, dt);
    const auto a4 = chain_accelerations(m, l, g, t4, w4);
    for (std::size_t k = 0; k < n; ++k) {
      th[k] += dt / 6 * (w[k] + 2 * w2[k] + 2 * w3[k] + w4[k]);
      w[k] += dt / 6 * (a1[k] + 2 * a2[k] + 2 * a3[k] + a4[k]);
    }
  }
  return material::slowest_mode(q, 10 * dt);
}

// The nonlinear chain's frequencies tend to the linear ones as the swing shrinks: what
// is left is the amplitude's own shift, a pendulum's softening, which falls as the
// square of the amplitude. At 1e-4 of the chain's length each of the first three modes
// swings within 2e-6 of w_n (measured 8.6e-9, 7.5e-8 and 8.4e-7; RK4's phase error at
// 200 steps a period is about 1e-8, the fit's below 1e-8), and ten times the amplitude
// lowers the frequency about a hundred times as much (modes 2 and 3, whose shift there
// stands above that floor: 6.7e-6 and 8.3e-5). An undamped chain does not decay.
TEST(Chain, TheNonlinearChainSwingsAtItsModesFrequencies) {
  const int n = 8;
  const double g = 9.81, L = 0.25;
  const std::vector<double> m(n, 1e-4), l(n, L / n);
  const auto modes = chain::modes(m, l, g, 3);
  for (int mode = 0; mode < 3; ++mode) {
    SCOPED_TRACE(mode + 1);
    const material::Mode small = swing(m, l, g, modes[mode], 1e-4 * L);
    const material::Mode large = swing(m, l, g, modes[mode], 1e-3 * L);
    const double shift_small = small.omega / modes[mode].omega - 1.0, shift_large = large.omega / modes[mode].omega - 1.0;
    RecordProperty("mode" + std::to_string(mode + 1) + "_shift_1e-4", std::to_string(shift_small));
    RecordProperty("mode" + std::to_string(mode + 1) + "_shift_1e-3", std::to_string(shift_large));
    EXPECT_LT(std::abs(shift_small), 2e-6);
    if (mode > 0) {
      EXPECT_LT(shift_large, 0.0) << "a pendulum softens with amplitude";
      EXPECT_NEAR(shift_large / shift_small, 100.0, 50.0) << "the shift is not the amplitude's square";
    }
    EXPECT_LT(std::abs(small.sigma), 1e-6 * modes[mode].omega) << "an undamped chain does not decay";
  }
}

TEST(Chain, BadChainsAreRefused) {
  const std::vector<double> one = {1.0};
  EXPECT_THROW(chain::modes(std::vector<double>{}, std::vector<double>{}, 9.81), std::invalid_argument);
  EXPECT_THROW(chain::modes(one, std::vector<double>{1.0, 1.0}, 9.81), std::invalid_argument);
  EXPECT_THROW(chain::modes(std::vector<double>{std::nan("")}, one, 9.81), std::invalid_argument);
  EXPECT_THROW(chain::modes(one, std::vector<double>{0.0}, 9.81), std::invalid_argument);
  EXPECT_THROW(chain::modes(one, one, 0.0), std::invalid_argument);
}

}  // namespace
}  // namespace hairbench
