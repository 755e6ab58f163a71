// What a truth scenario reads from a run (docs/truth.md): each strand hangs as a chain
// from its last pinned vertex, starts displaced into one of its chain's modes
// (chain::modes, on the masses 1/w and the rest links of the groom the model simulates),
// and the modal amplitude q(t) of that mode, the M-weighted projection of the strand's
// horizontal displacement, is recorded every frame. Prony's method (material::prony_modes)
// then gives the mode's measured frequency and decay rate; with every damping term off
// the decay is the model's numerical damping.
#pragma once

#include "core/chain_modes.h"
#include "core/groom.h"
#include "core/types.h"

#include <nlohmann/json.hpp>

#include <span>
#include <string>
#include <vector>

namespace hairbench::truth {

// One strand as a chain: its free vertices below the last leading pinned one (the pivot).
struct StrandChain {
  std::size_t pivot = 0;  // the last pinned vertex, an index into the groom
  std::size_t first = 0;  // the first free vertex; the chain is [first, first + masses.size())
  std::vector<double> masses, lengths;
  double length = 0.0;    // the links' sum
};
// Throws std::invalid_argument naming the strand when it has no free vertex or a pinned
// vertex after a free one.
StrandChain strand_chain(const Groom& g, std::size_t strand);

struct Kick {
  std::vector<int> modes;  // strand s in mode modes[s % size()], 1 the slowest
  double amplitude = 1e-3; // the largest displacement over the chain's length
  Vec3f direction = Vec3f::UnitX();
};

// Follows one run: the kick on the model's simulated groom, and each strand's modal
// amplitude frame by frame.
class Observer {
 public:
  // Throws std::invalid_argument where a strand is not a chain or has fewer masses than
  // its mode.
  Observer(const Groom& simulated, const Kick& kick, const Vec3f& gravity);
  // The rest groom with every strand displaced into its mode by amplitude * L * shape_k
  // along the direction, each link turned about the vertex above it so that its length
  // stays the rest length.
  const std::vector<Vec4f>& kicked() const { return kicked_; }
  // One frame's positions, the simulated groom's layout.
  void add(std::span<const Vec4f> positions);
  std::size_t frames() const { return q_.empty() ? 0 : q_[0].size(); }

  struct StrandResult {
    int mode = 0;
    std::size_t masses = 0;
    double exact_omega = 0.0;   // rad/s, the chain's
    // The chain's own distance from the continuous strand of its length (Bernoulli's
    // w_n = (a_n / 2) sqrt(g / L)): exact_omega over that, minus 1; what the model's
    // resolution costs before its integrator and solver add their error.
    double resolution_error = 0.0;
    double omega = 0.0;         // rad/s, measured; NaN where no oscillation was found
    double frequency_error = 0.0;  // omega / exact_omega - 1
    double sigma = 0.0;         // 1/s, the amplitude's decay rate (> 0 decays)
    double share = 0.0;         // the fitted mode's share of q's energy (both roots of its pair)
  };
  // The fits, over the frames added at spacing dt.
  std::vector<StrandResult> result(double dt) const;

 private:
  struct Strand {
    StrandChain chain;
    chain::Mode mode;
    int index = 0;
    double continuous_omega = 0.0;
  };
  std::vector<Strand> strands_;
  std::vector<Vec4f> rest_, kicked_;
  Vec3f direction_;
  std::vector<std::vector<double>> q_;  // per strand, per frame
  std::vector<double> x_;               // add()'s scratch: one strand's displacements
};

// Per mode (the strands kicked in it averaged): mode, masses, exact and measured omega,
// frequency_error, resolution_error, sigma, damping_ratio (sigma / omega), share;
// docs/report-schema.md.
nlohmann::json result_json(std::span<const Observer::StrandResult> strands);

}  // namespace hairbench::truth
