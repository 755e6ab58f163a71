// Verdicts: what a run's motion says about the model, in five classes
// (docs/verdicts.md). Each class has one detector here, fed frame by frame by the runner;
// the detectors read positions only, so every model is judged by the same code.
//
//   diverged   NaN/Inf, a vertex beyond the blow-up distance, or mechanical energy
//              growing with nothing driving the hair: the run stops there.
//   unstable   self-excited motion: with the head still and no wind, motion relative to
//              the head that does not decay (SettleCheck), or a tiny perturbation at rest
//              that grows (the probe, harness/probe.h). The run goes on and is measured.
//   deformed   the hair does not return: at the end of the settle window it is more than
//              Return::kLimit from where the same model rests with the head held still at
//              the run's final pose (Return). Measured, never a reason to stop.
//   stretched  a constraint violated: some edge more than kStretchLimit longer or shorter
//              than at rest (StretchTracker). Measured, never a reason to stop.
//   ok         none of these.
#pragma once

#include "core/types.h"
#include "reports/metrics.h"

#include <nlohmann/json.hpp>

#include <cstdint>
#include <limits>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace hairbench::verdict {

// In rank order: a run gets the worst class any detector finds.
enum class Status { ok, stretched, deformed, unstable, diverged };
std::string_view status_name(Status s);

// An edge error (metrics::length_error: relative to the strand's median rest edge) above
// this is a stretched frame: half an edge length, far beyond what a converging
// constraint solver leaves and well before a strand looks broken.
inline constexpr double kStretchLimit = 0.5;

struct Stretch {
  double peak = 0.0;        // largest edge error of any frame
  int peak_frame = -1;
  std::uint32_t worst_strand = 0, worst_edge = 0;  // where the peak was
  int frames_above = 0;     // frames whose largest edge error exceeds kStretchLimit
  int first_above = -1;     // the first of them (-1: none)
  // The worst edge joins a free vertex to one the groom pins past the root edge (a TressFX
  // strand tied at its tip, say): a model that cannot close the loop stretches it there.
  bool pinned_end = false;
};

class StretchTracker {
 public:
  void add(int frame, const metrics::LengthError& e);
  const Stretch& result() const { return s_; }

 private:
  Stretch s_;
};

// Motion that does not die out with nothing driving it. Over the frames at or after the
// scenario's settle time (the motion has ended at least a second earlier) during which
// the head holds still and no wind blows, the kinetic energy per unit mass relative to
// the head, mean |p - H H_prev^-1 p_prev|^2 / (2 dt^2), is averaged over the first and
// the second half of those frames, and its rate ln(second / first) / (time between the
// halves' centres) taken, and the same rate of the halves' peaks. The motion has not
// decayed when either rate is above -kMinDecayRate while the second half stays above the floor of hair at rest (every
// vertex slower than kRestSpeed): it grows, or holds a limit cycle (contact chatter, a
// self-excited flutter). The window is about a second, too short to tell a limit cycle
// from a decay much slower than kMinDecayRate; a damped model's energy falls faster
// than that by orders of magnitude (a velocity damping of 0.1 per substep at six
// substeps and 60 Hz removes energy at about 76/s).
// Where motion that has not decayed is: the relative kinetic energy per strand, summed
// over the last half of the frames stepped past the scenario's end. A flutter of one
// strand and a whole groom that will not settle read the same in the groom's mean; this
// tells them apart and names the strand to look at.
struct EnergySpread {
  std::size_t strands = 0;         // strands measured; 0: not measured
  std::size_t strands_for_90 = 0;  // the fewest strands that hold 90% of the energy
  std::uint32_t strand = 0;        // the strand with the most
  double share = std::numeric_limits<double>::quiet_NaN();  // its fraction of the energy
  bool guides = false;  // the strands are guides, each with its follow hairs' energy
};
// From per-strand energies; strands = 0 when their sum is not positive and finite.
EnergySpread energy_spread(std::span<const double> per_strand);

struct Settle {
  int frames = 0;                                          // still frames after settle_from
  int extra_frames = 0;  // of those, frames stepped past the scenario's end (SettleCheck::kExtraSeconds)
  double energy_first = std::numeric_limits<double>::quiet_NaN();   // m^2/s^2, first half's mean
  double energy_second = std::numeric_limits<double>::quiet_NaN();  // second half's mean
  // ln(energy_second / energy_first) / (time between the halves' centres), 1/s: < 0 decays.
  double rate = std::numeric_limits<double>::quiet_NaN();
  // The same rate of the halves' largest energies. A swing's energy peaks twice a period;
  // its halves' means depend on the phase where a half ends, its peaks do not once each
  // half holds one, so a limit cycle that the means read as decaying keeps peak_rate ~0.
  double peak_rate = std::numeric_limits<double>::quiet_NaN();
  bool decays = true;
  EnergySpread spread;  // measured when frames past the end were stepped
};

class SettleCheck {
 public:
  // Energy that takes longer than 10 s to fall by a factor e has not decayed.
  static constexpr double kMinDecayRate = 0.1;
  // 1 mm/s: 1/100 of a strand length of 10 cm per second, invisible at 60 Hz.
  static constexpr double kRestSpeed = 1e-3;
  static constexpr int kMinFrames = 20;  // fewer still frames than this: no verdict
  // A second of frames cannot tell a slow swing's decay from growth: its kinetic energy
  // rises and falls twice a period, and halves shorter than that sample it at different
  // phases. A run whose check says "not decayed" at the scenario's end goes on for this
  // long, head still and no wind, outside the timed run and its series, and the check
  // reads the whole window: a decaying swing then passes, growth and a limit cycle do not.
  static constexpr double kExtraSeconds = 3.0;

  // One frame's relative kinetic energy; counted when the frame ends at or after
  // settle_from and nothing drove the hair during it.
  void add(double t, double energy, bool driven, double settle_from);
  // One frame stepped past the scenario's end (kExtraSeconds): always counted.
  void add_past_end(double t, double energy);
  void set_spread(const EnergySpread& spread) { spread_ = spread; }
  Settle result() const;

 private:
  std::vector<double> t_, e_;
  int extra_ = 0;
  EnergySpread spread_;
};

// Kinetic energy per unit mass relative to the head between two frames (see Settle).
double relative_kinetic_energy(std::span<const Vec4f> p, std::span<const Vec4f> prev, const Affine3f& head,
                               const Affine3f& head_prev, double dt);

// The seeded perturbation probe at rest (harness/probe.h): growth of the distance
// between a run kicked by a tiny head pulse and its unkicked twin.
struct Probe {
  bool run = false;
  std::string skipped_why;  // when not run
  double kick = 0.0;        // RMS distance right after the pulse, in mean strand lengths
  double first = 0.0, last = 0.0;  // its mean over the first and the last kWindow frames after that
  double rate = 0.0;        // ln(last / kick) / time from the kick to the last window's centre, 1/s
  bool grows = false;
};

// Does the hair come back? The rest groom is not where a model's hair rests (it sags, and
// a head tilted at the end hangs it another way), so the run's state is compared with a
// twin: the same model at the same settings, started from the rest groom and held still
// at the run's final head pose for as many frames as the run (harness/twin.h). The
// distance is the RMS over vertices, in the head's frame, in mean strand lengths, taken
// every frame of the settle window (the frames SettleCheck reads); its rate is the slope
// of ln(distance) over them.
struct Return {
  // Above this RMS distance at the window's last frame, in mean strand lengths, the run is
  // deformed. Measured on the default comparison (84 runs): every run but two ends within
  // 0.035 of its twin (the Han methods within 1e-5; the cascade up to 0.034, returning at
  // 1.2 to 1.7/s), and those two, the cascade on the TressFX ponytail's spin and on
  // TestHair1, end 0.29 and 0.45 from it, returning with e-folding times of 2.5 and 2.9 s.
  // 0.1 (1 cm on a 10 cm strand) is the geometric middle of that gap.
  static constexpr double kLimit = 0.1;
  bool measured = false;
  std::string skipped_why;  // when not measured
  int frames = 0;           // settle-window frames measured
  int twin_frames = 0;      // frames the twin stepped before it stopped (harness/twin.h)
  double first = 0.0, last = 0.0;  // distance at the window's first and last frame
  double rate = 0.0;        // d ln(distance) / dt over the window, 1/s (< 0: coming back)
  std::uint32_t worst_strand = 0;  // the strand farthest from its twin at the last frame
  double worst = 0.0;              // its RMS distance, mean strand lengths
  bool deformed = false;
};

// Accumulates Return over the settle window: one distance per frame.
class ReturnTracker {
 public:
  void add(double t, double distance);
  // The farthest strand of the latest frame.
  void set_worst(std::uint32_t strand, double distance);
  Return result() const;

 private:
  std::vector<double> t_, d_;
  std::uint32_t worst_strand_ = 0;
  double worst_ = 0.0;
};

// The verdict of one run.
struct Verdict {
  Status status = Status::ok;
  std::string reason;  // empty for ok
  int frame = -1;      // where it was decided (diverged: the frame it stopped; stretched: the peak)
  double t = 0.0;
  Stretch stretch;
  Settle settle;
  Probe probe;
  Return back;
};

// Combines the detectors: the worst class wins (diverged > unstable > deformed > stretched
// > ok). `diverged` is the blow-up reason when the run stopped, with its frame and time.
Verdict decide(const std::optional<std::pair<int, double>>& stop, const std::string& diverged, const Stretch& stretch,
               const Settle& settle, const Probe& probe, const Return& back, double dt);

nlohmann::json verdict_json(const Verdict& v);

}  // namespace hairbench::verdict
