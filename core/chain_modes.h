// The small oscillations of a hanging chain: the exact answer the truth scenarios hold
// every model to (docs/truth.md). N point masses m_1..m_N hang from a fixed pivot on N
// inextensible links, link k (length l_k) joining mass k-1 (the pivot for k = 1) to mass
// k. At rest link k carries the weight below it, T_k = g (m_k + ... + m_N). For small
// horizontal displacements x_k of the masses (x_0 = 0 at the pivot), with c_k = T_k / l_k
// and c_{N+1} = 0,
//   m_k x_k'' = c_{k+1} (x_{k+1} - x_k) - c_k (x_k - x_{k-1}),
// that is M x'' = -K x with M = diag(m) and K tridiagonal (K_kk = c_k + c_{k+1},
// K_{k,k+1} = K_{k+1,k} = -c_{k+1}): the modes are the generalized eigenpairs
// K x = w^2 M x, each horizontal direction on its own. For N equal masses on equal links
// of a chain of length L the angular frequencies tend, as N grows, to those of the
// uniform heavy chain, w_n = (a_n / 2) sqrt(g / L), a_n the n-th zero of the Bessel
// function J0 (D. Bernoulli; e.g. Goldstein, Classical Mechanics).
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

namespace hairbench::chain {

struct Mode {
  double omega = 0.0;  // angular frequency, rad/s
  // Horizontal displacement of each mass (masses in order from the pivot), scaled so that
  // the largest |x_k| is 1 and the last mass's is positive.
  std::vector<double> shape;
};

// The modes of the chain, slowest first (all N of them, or the first `count`). Throws
// std::invalid_argument for no mass, a mass or length that is not finite and positive, a
// length count different from the mass count, or g <= 0.
std::vector<Mode> modes(std::span<const double> masses, std::span<const double> lengths, double g,
                        std::size_t count = SIZE_MAX);

// The n-th positive zero of J0 (n >= 1), to double precision.
double bessel_j0_zero(int n);

// w_n of the uniform heavy chain of length L under gravity g (the limit above).
double continuous_omega(int n, double length, double g);

// The modal amplitude of displacements `x` (one per mass) in `mode`: the M-weighted
// projection (x_n^T M x) / (x_n^T M x_n), which separates the modes because they are
// M-orthogonal.
double modal_amplitude(const Mode& mode, std::span<const double> masses, std::span<const double> x);

}  // namespace hairbench::chain
