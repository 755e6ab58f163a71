// The per-frame metrics of DESIGN.md ("Metrics (contract)"). All are computed by the
// harness from positions alone, so every model is measured by the same code.
#pragma once

#include "core/groom.h"
#include "core/types.h"

#include <cstdint>
#include <span>
#include <string>
#include <vector>

namespace hairbench::metrics {

// What the metrics need of the rest groom, computed once per run.
struct RestInfo {
  // `simulated_strands`: how many leading strands the models simulate; the strands after
  // them are follow hairs rebuilt from those (a scenario's follow_hairs "follow"). All by
  // default.
  explicit RestInfo(const Groom& rest, std::size_t simulated_strands = SIZE_MAX);
  const Groom* groom;
  std::vector<float> rest_length;        // per edge, indexed by its second vertex
  std::size_t edge_count;                // edges of all strands (vertices less one per strand)
  double mean_strand_length;             // L-bar
  std::vector<double> rest_jaggedness;   // per strand, raw (not rest-subtracted)
  // The strands jaggedness computes several at a time (one size >= 4, in groups of its
  // lane count, metrics.cpp), and the others, one at a time; each in index order.
  std::vector<std::uint32_t> jagged_grouped, jagged_alone;
  double head_extent;                    // largest root distance from the head centre (rest frame origin)
  std::size_t simulated_strands;
};

// sqrt(mean over vertices |p - p_ref|^2) / L-bar.
double deviation(std::span<const Vec4f> p, std::span<const Vec4f> ref, double mean_length);

// sqrt(mean_i |kb_{i+1} - kb_i|^2) of one strand, with the discrete curvature binormal
// kb_i = 2 (e_{i-1} x e_i) / (|e_{i-1}||e_i| + e_{i-1}.e_i) (Bergou et al. 2008);
// 0 for strands with fewer than 4 vertices (no pair of binormals).
double strand_jaggedness_raw(std::span<const Vec4f> strand);
// Groom jaggedness: mean over strands of (raw - raw on the rest shape).
double jaggedness(const RestInfo& rest, std::span<const Vec4f> p);

struct LengthError {
  double rms = 0.0;
  double max = 0.0;
};
// |edge - rest edge| / rest edge over all edges.
LengthError length_error(const RestInfo& rest, std::span<const Vec4f> p);

// sqrt(mean |p - T_H p^0|^2) / L-bar: deviation from the head-transformed rest shape.
double rest_shape_error(const RestInfo& rest, std::span<const Vec4f> p, const Affine3f& head);

// Deepest vertex inside any sphere (xyz centre, w radius), metres; 0 if none.
double penetration(std::span<const Vec4f> p, std::span<const Vec4f> world_spheres);

// Empty if the state is sane, else why the model is declared unstable: NaN/Inf, an edge of
// a simulated strand stretched or shrunk by more than 50%, or a vertex farther than
// 10 L-bar from the head (beyond the head's extent about `head_center`: see metrics.cpp).
std::string blowup_reason(const RestInfo& rest, std::span<const Vec4f> p, const Vec3f& head_center);

// Mean specific mechanical energy per vertex, in J/kg: kinetic ½|v|² with the frame's
// velocity v = (p - prev) / dt, plus gravitational -g·p. The stress test's growth check
// watches it while nothing drives the hair.
double mechanical_energy(std::span<const Vec4f> p, std::span<const Vec4f> prev, double dt, const Vec3f& gravity);

// "Energy growing for N frames with the head still": the frames are grouped in
// windows of kWindow; a model fails when, with the head still and no wind for the whole
// time, the window mean of mechanical_energy rose by more than kRise * g * L-bar (every
// vertex lifted by 5% of a strand length) over each of kWindows consecutive windows, i.e.
// for N = kWindow * kWindows = 60 frames (after a first window to compare with). A damped model at rest loses energy; the
// shape constraints may lift hair back toward its rest shape, but not by that much for
// that long, so only sustained growth (a slow instability) trips it.
class EnergyGrowthCheck {
 public:
  static constexpr int kWindow = 10;
  static constexpr int kWindows = 6;
  static constexpr double kRise = 0.05;
  EnergyGrowthCheck(double mean_strand_length, double gravity_norm)
      : min_rise_(kRise * gravity_norm * mean_strand_length) {}
  // One frame's energy and whether anything drove the hair during it (head moved, wind
  // blew). Returns a failure reason, or "" while the check holds.
  std::string add(double energy, bool driven);

 private:
  double min_rise_;
  double sum_ = 0.0;
  int in_window_ = 0;
  double last_mean_ = 0.0;
  bool have_last_ = false;
  int rising_ = 0;
};

// 64-bit FNV-1a over the bits of every position (xyzw): bit-exact determinism checks.
std::uint64_t state_hash(std::span<const Vec4f> p);
std::string hash_hex(std::uint64_t h);

}  // namespace hairbench::metrics
