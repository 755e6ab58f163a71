// The per-frame metrics (docs/metrics.md). All are computed by the
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
  // The length scale s of each strand's edge errors (length_error): the median of its rest
  // edge lengths, or, where that is 0 or below 1e-6 of the mean rest edge of the simulated
  // strands, that mean. Exporters write edges of 0 m and 2.4e-7 m, whose own length would
  // turn float rounding into a 100% error.
  std::vector<double> edge_scale;         // per strand
  std::vector<double> vertex_edge_scale;  // per vertex, its strand's edge_scale (the loops over the groom)
  // d0, the |kb_{i+1} - kb_i| of the rest shape (strand_kb_changes): per vertex, indexed
  // as strand_kb_changes writes them.
  std::vector<double> rest_kb_change;
  // Per vertex, indexed as rest_kb_change: 1 for a pair that counts in jaggedness, 0 for
  // one that reads a rest edge shorter than kMinTurnEdge of its strand's edge_scale. Such
  // an edge (exporters write 2.4e-7 m ones) has no direction of its own: moving the
  // strand rounds its ends by about 1e-7 m and turns it by order 1 radian, so a turning
  // angle across it is rounding, not a kink.
  std::vector<double> kb_weight;
  // The strands jaggedness computes several at a time (one size >= 4, in groups of its
  // lane count, metrics.cpp), and the others, one at a time; each in index order.
  std::vector<std::uint32_t> jagged_grouped, jagged_alone;
  double head_extent;                    // largest root distance from the head centre (rest frame origin)
  std::size_t simulated_strands;
};

// sqrt(mean over vertices |p - p_ref|^2) / L-bar.
double deviation(std::span<const Vec4f> p, std::span<const Vec4f> ref, double mean_length);

// Jaggedness reads new kinks: how much the change of curvature along each strand differs
// from the rest shape's. With the discrete curvature binormal at interior vertex i
//   kb_i = 2 (e_{i-1} x e_i) / (|e_{i-1}||e_i| + e_{i-1}.e_i)      (Bergou et al. 2008)
// (e_i = p_{i+1} - p_i; |kb_i| = 2 tan(phi_i / 2) for the turning angle phi_i), the change
// between neighbours d_i = |kb_{i+1} - kb_i|, and d0_i the same on the rest shape,
//   J_s = sqrt( mean_i (d_i - d0_i)^2 ),   i = 1 .. n-3 (n vertices, n-3 pairs; 0 if n < 4)
//   jaggedness = mean over strands of J_s.
// J_s >= 0, and 0 on the rest shape. kb is a vector that turns with the strand, so d_i is
// unchanged by a rigid motion (up to the rounding of the moved float positions). A uniform
// bend keeps kb nearly constant along the strand (d ~ 0), a zig-zag flips it at every
// vertex (d ~ 2|kb|): the metric reads new changes of curvature, not curvature, and a
// styled wave or curl flattened out scores above 0 like any other departure from rest.

inline constexpr double kMinTurnEdge = 1e-3;

// d_i of one strand, written to out[i + 1] (the vertex of kb_{i+1}) for i = 1 .. n-3;
// out[0], out[1] and out[n-1] are left as they are. out.size() == strand.size().
void strand_kb_changes(std::span<const Vec4f> strand, std::span<double> out);
// J_s of one strand, with rest_kb_change and kb_weight its strand's spans of RestInfo's
// (indexed as strand_kb_changes writes them): each term (d_i - d0_i) is weighted.
double strand_jaggedness(std::span<const Vec4f> strand, std::span<const double> rest_kb_change,
                         std::span<const double> kb_weight);
// J_s of strand s of the positions p (the whole groom's).
double strand_jaggedness(const RestInfo& rest, std::span<const Vec4f> p, std::size_t s);
// Groom jaggedness: mean over strands of strand_jaggedness.
double jaggedness(const RestInfo& rest, std::span<const Vec4f> p);

struct LengthError {
  double rms = 0.0;
  double max = 0.0;
  // Where max is: the strand, and the edge by its second vertex's index within the strand
  // (edge k joins vertices k-1 and k, k >= 1, as blowup_reason names edges). The first such
  // edge in strand order; 0 and 0 when max is 0.
  std::uint32_t worst_strand = 0, worst_edge = 0;
};
// |edge - rest edge| / s over all edges, s the edge's strand's RestInfo::edge_scale.
LengthError length_error(const RestInfo& rest, std::span<const Vec4f> p);

// sqrt(mean |p - T_H p^0|^2) / L-bar: deviation from the head-transformed rest shape.
double rest_shape_error(const RestInfo& rest, std::span<const Vec4f> p, const Affine3f& head);

// Deepest vertex inside any sphere (xyz centre, w radius), metres; 0 if none.
double penetration(std::span<const Vec4f> p, std::span<const Vec4f> world_spheres);

// Empty if the state is sane, else why the model has diverged: NaN/Inf, or a vertex farther
// than 10 L-bar from the head (beyond the head's extent about `head_center`: see
// metrics.cpp). Stretched edges are the `stretched` verdict's (reports/verdict.h).
std::string blowup_reason(const RestInfo& rest, std::span<const Vec4f> p, const Vec3f& head_center);
// The distance from the head centre beyond which a vertex has blown up (metrics.cpp).
double blowup_distance(const RestInfo& rest);

// Mean specific mechanical energy per vertex, in J/kg: kinetic ½|v|² with the frame's
// velocity v = (p - prev) / dt, plus gravitational -g·p. The divergence check's energy growth test
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
