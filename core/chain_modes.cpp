#include "core/chain_modes.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <string>

namespace hairbench::chain {

namespace {

// The symmetric tridiagonal A = M^-1/2 K M^-1/2 (same eigenvalues w^2; eigenvectors
// u = M^1/2 x): diagonal d, off-diagonal e (e[k] couples k and k+1).
struct Tridiagonal {
  std::vector<double> d, e;
};

Tridiagonal assemble(std::span<const double> m, std::span<const double> l, double g) {
  const std::size_t n = m.size();
  std::vector<double> c(n + 1, 0.0);  // c[k] = T_k / l_k for link k (0-based: link k ends at mass k)
  double below = 0.0;
  for (std::size_t k = n; k-- > 0;) {
    below += m[k];
    c[k] = g * below / l[k];
  }
  Tridiagonal a{std::vector<double>(n), std::vector<double>(n > 0 ? n - 1 : 0)};
  for (std::size_t k = 0; k < n; ++k) {
    a.d[k] = (c[k] + c[k + 1]) / m[k];
    if (k + 1 < n) a.e[k] = -c[k + 1] / std::sqrt(m[k] * m[k + 1]);
  }
  return a;
}

// Sturm count: how many eigenvalues of `a` lie below x, the negative pivots of the LDL^T
// factorisation of A - x I.
std::size_t below(const Tridiagonal& a, double x) {
  std::size_t count = 0;
  double q = 1.0;
  for (std::size_t k = 0; k < a.d.size(); ++k) {
    const double off = k > 0 ? a.e[k - 1] * a.e[k - 1] : 0.0;
    q = a.d[k] - x - (k > 0 ? off / q : 0.0);
    if (q == 0.0) q = -1e-300;  // x hit a pivot exactly: count it as just below
    if (q < 0.0) ++count;
  }
  return count;
}

// The i-th smallest eigenvalue (0-based) by bisection on the Sturm count, inside the
// Gershgorin interval.
double eigenvalue(const Tridiagonal& a, std::size_t i) {
  double lo = 0.0, hi = 0.0;
  for (std::size_t k = 0; k < a.d.size(); ++k) {
    const double r = (k > 0 ? std::abs(a.e[k - 1]) : 0.0) + (k + 1 < a.d.size() ? std::abs(a.e[k]) : 0.0);
    lo = std::min(lo, a.d[k] - r);
    hi = std::max(hi, a.d[k] + r);
  }
  for (int it = 0; it < 200 && hi - lo > 4.0 * std::numeric_limits<double>::epsilon() * std::max(std::abs(lo), std::abs(hi));
       ++it) {
    const double mid = 0.5 * (lo + hi);
    (below(a, mid) > i ? hi : lo) = mid;
  }
  return 0.5 * (lo + hi);
}

// The eigenvector of eigenvalue `lambda` by inverse iteration: (A - s I) u_new = u with a
// shift s a hair off lambda, by the tridiagonal (Thomas) elimination with partial pivots
// avoided by the shift; three passes from a vector with every component non-zero.
std::vector<double> eigenvector(const Tridiagonal& a, double lambda) {
  const std::size_t n = a.d.size();
  const double s = lambda * (1.0 + 1e-10) + 1e-300;
  std::vector<double> u(n, 1.0), c(n), r(n);
  for (int pass = 0; pass < 3; ++pass) {
    // Forward elimination of the tridiagonal system with diagonal d - s.
    double den = a.d[0] - s;
    c[0] = n > 1 ? a.e[0] / den : 0.0;
    r[0] = u[0] / den;
    for (std::size_t k = 1; k < n; ++k) {
      den = a.d[k] - s - a.e[k - 1] * c[k - 1];
      if (den == 0.0) den = 1e-300;
      c[k] = k + 1 < n ? a.e[k] / den : 0.0;
      r[k] = (u[k] - a.e[k - 1] * r[k - 1]) / den;
    }
    u[n - 1] = r[n - 1];
    for (std::size_t k = n - 1; k-- > 0;) u[k] = r[k] - c[k] * u[k + 1];
    double norm = 0.0;
    for (double v : u) norm = std::max(norm, std::abs(v));
    for (double& v : u) v /= norm;
  }
  return u;
}

void check(std::span<const double> m, std::span<const double> l, double g) {
  if (m.empty()) throw std::invalid_argument("chain: no mass");
  if (l.size() != m.size())
    throw std::invalid_argument("chain: " + std::to_string(l.size()) + " link lengths for " +
                                std::to_string(m.size()) + " masses");
  for (std::size_t k = 0; k < m.size(); ++k) {
    if (!(std::isfinite(m[k]) && m[k] > 0.0))
      throw std::invalid_argument("chain: mass " + std::to_string(k) + " is not finite and positive");
    if (!(std::isfinite(l[k]) && l[k] > 0.0))
      throw std::invalid_argument("chain: link " + std::to_string(k) + " is not finite and positive");
  }
  if (!(std::isfinite(g) && g > 0.0)) throw std::invalid_argument("chain: gravity is not finite and positive");
}

}  // namespace

std::vector<Mode> modes(std::span<const double> masses, std::span<const double> lengths, double g,
                        std::size_t count) {
  check(masses, lengths, g);
  const Tridiagonal a = assemble(masses, lengths, g);
  const std::size_t n = std::min(count, masses.size());
  std::vector<Mode> out(n);
  for (std::size_t i = 0; i < n; ++i) {
    const double lambda = eigenvalue(a, i);
    out[i].omega = std::sqrt(std::max(lambda, 0.0));
    std::vector<double> x = eigenvector(a, lambda);
    double peak = 0.0;
    for (std::size_t k = 0; k < x.size(); ++k) {
      x[k] /= std::sqrt(masses[k]);  // x = M^-1/2 u
      peak = std::max(peak, std::abs(x[k]));
    }
    const double sign = x.back() < 0.0 ? -1.0 : 1.0;
    for (double& v : x) v *= sign / peak;
    out[i].shape = std::move(x);
  }
  return out;
}

double bessel_j0_zero(int n) {
  if (n < 1) throw std::invalid_argument("bessel_j0_zero: n must be at least 1");
  // Newton on J0 (J0' = -J1) from McMahon's first term, (n - 1/4) pi.
  double x = (n - 0.25) * std::numbers::pi;
  for (int it = 0; it < 50; ++it) {
    const double step = std::cyl_bessel_j(0.0, x) / -std::cyl_bessel_j(1.0, x);
    x -= step;
    if (std::abs(step) < 1e-15 * x) break;
  }
  return x;
}

double continuous_omega(int n, double length, double g) { return 0.5 * bessel_j0_zero(n) * std::sqrt(g / length); }

double modal_amplitude(const Mode& mode, std::span<const double> masses, std::span<const double> x) {
  double num = 0.0, den = 0.0;
  for (std::size_t k = 0; k < masses.size(); ++k) {
    num += mode.shape[k] * masses[k] * x[k];
    den += mode.shape[k] * masses[k] * mode.shape[k];
  }
  return num / den;
}

}  // namespace hairbench::chain
