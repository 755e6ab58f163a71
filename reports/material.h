// The material card of a run: what material a model at its run's settings describes, so
// that a deviation between two models can be read as method or as material
// (docs/metrics.md, The material card). Measured with the head still on a few strands of
// the scenario's groom (harness/probe.h):
//   sag      the strands' mean tip drop along gravity after settling, in mean strand
//            lengths;
//   stretch  the RMS edge length error there (metrics::length_error, edge scales);
//   sigma, omega  the slowest mode's response to a small kick, x ~ e^(-sigma t) cos(omega t),
//            fitted on the frames after it (slowest_mode); omega 0 where it does not
//            oscillate (an overdamped position-based solver).
#pragma once

#include <nlohmann/json.hpp>

#include <cstddef>
#include <limits>
#include <span>
#include <string>
#include <vector>

namespace hairbench::material {

inline constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

struct Card {
  bool measured = false;
  std::string skipped_why;  // when not measured
  std::size_t strands = 0;  // strands measured
  double settle_s = 0.0;    // how long the strands settled before sag and stretch were read
  double sag = kNaN;
  double stretch = kNaN;
  double sigma = kNaN;  // 1/s, > 0 decays
  double omega = kNaN;  // rad/s, 0 overdamped
};

// The slowest mode of a sampled decay x_0, x_1, ... (step dt) that holds a fair share of
// it, by Prony's method: a linear prediction of order kModeOrder fitted by least squares
// on the samples from `first` to the last one above `floor` times the largest, its roots
// z_k (the modes: z = e^((-sigma + i omega) dt)) and their amplitudes by least squares;
// of the modes holding at least kModeShare of the window's energy, the one with the
// largest |z|: sigma = -ln|z| / dt, omega = |arg z| / dt (0 for a real positive root, a mode
// that does not oscillate). NaN when fewer than 6 samples remain or no mode is found.
inline constexpr int kModeOrder = 8;
inline constexpr double kModeShare = 0.05;
struct Mode {
  double sigma = kNaN, omega = kNaN;
};
Mode slowest_mode(std::span<const double> x, double dt, std::size_t first = 0, double floor = 1e-3);

// Every mode Prony's method finds in the window slowest_mode reads (the same fit), with
// its share of the window's energy; empty where slowest_mode would give NaN. A real
// oscillation is a conjugate pair, two entries of the same sigma and omega.
struct PronyMode {
  double sigma = kNaN, omega = kNaN;
  double share = 0.0;
};
std::vector<PronyMode> prony_modes(std::span<const double> x, double dt, std::size_t first = 0, double floor = 1e-3);

// Each of the card's numbers over the reference's: NaN where either is not finite or the
// reference's is 0.
struct Ratios {
  double sag = kNaN, stretch = kNaN, sigma = kNaN, omega = kNaN;
};
Ratios ratios(const Card& card, const Card& reference);

nlohmann::json card_json(const Card& card, const Card* reference);

// What --calibrate did to one run (harness/calibrate.h): one fit per role.
struct Calibration {
  struct Fit {
    std::string role;      // "stiffness" or "damping"
    std::string param;     // the parameter scaled; empty when the model has none
    std::string on;        // what it was fitted on: "sag", "mode" (|sigma + i omega|), "sigma"
    double factor = 1.0;   // the scale applied to every region's value
    double from = kNaN, to = kNaN;  // its base value before and after
    double target = kNaN, reached = kNaN;  // the quantity's target and value
    bool within = false;   // reached within the tolerance
    int evaluations = 0;   // card runs
    std::string note;      // why it was not fitted, or how far it stays
  };
  std::vector<Fit> fits;
  double seconds = 0.0;
};

nlohmann::json calibration_json(const Calibration& c);

}  // namespace hairbench::material
