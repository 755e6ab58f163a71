// What a scenario needs of an imported groom that the file does not say: the head sphere
// through the roots (pivot and radius), the unit, and the repair of degenerate strands.
// Pure functions over a Groom; the loaders call them (docs/scenarios.md, "Fitted heads
// and units" and "Import hygiene").
#pragma once

#include "core/groom.h"
#include "core/types.h"

#include <optional>
#include <string>
#include <vector>

namespace hairbench {

// The sphere through a groom's roots (vertex 0 of every strand), or of the roots higher
// than `above` (y, the groom's units) when given: a groom whose roots run past the scalp
// (the Ratboy mohawk's run down the neck) is fitted on its crown.
struct HeadFit {
  Vec3f center = Vec3f::Zero();
  float radius = 0.0f;
  // Whether the roots lie near a sphere: the least-squares sphere's RMS distance from the
  // roots is at most kSphereResidual of its radius and its radius at most kSphereSpread
  // times the roots' own spread. Otherwise (a fur groom on a body, roots on a plane or a
  // line) center is the roots' bounding-box centre, radius a sphere inside their box
  // (never 0), and `note` says why.
  bool sphere = false;
  double rms_residual = 0.0;  // RMS of |p - c| - r over the roots, in the groom's units
  std::string note;
};

inline constexpr double kSphereResidual = 0.2;
inline constexpr double kSphereSpread = 4.0;

// Least squares: |p|^2 = 2 c.p + (r^2 - |c|^2) is linear in (c, r^2 - |c|^2), solved in
// double precision over the roots, centred on their mean for conditioning.
HeadFit fit_head(const Groom& g, std::optional<double> above = std::nullopt);

// The unit of a groom from its size, in metres per file unit: the one of cm, mm and m
// under which the fitted head radius (or, without a sphere, the roots' bounding-box
// diagonal) is human-sized. Throws InputError naming `source` and "unit" when no unit or
// more than one fits (the message gives the size and the accepted ranges).
struct UnitGuess {
  std::string unit;  // "cm", "mm" or "m"
  float metres_per_unit = 0.0f;
  std::string why;  // the size it was read from, for the terminal and the report
};
UnitGuess guess_unit(const Groom& g, const HeadFit& fit, const std::string& source);
// Head radii in metres that identify a unit: a child's head to a helmet.
inline constexpr double kHeadRadiusMin = 0.04, kHeadRadiusMax = 0.4;
// Without a sphere: the roots' bounding-box diagonal, a palm-sized patch to a body.
inline constexpr double kRootSpanMin = 0.05, kRootSpanMax = 3.0;
float metres_per_unit(const std::string& unit);

// ---- import hygiene ------------------------------------------------------------------

// A rest edge shorter than this fraction of its strand's median edge is near zero: its
// direction is rounding noise or an exporter's duplicate vertex, and an explicit
// integrator's step would have to shrink with it.
inline constexpr double kNearZeroEdge = 1e-2;
// A strand shorter than this fraction of the groom's median strand length is far
// shorter than the rest: its edges are too short for a solver tuned to the groom.
inline constexpr double kShortStrand = 0.1;

enum class DegeneratePolicy { Repair, Refuse };

struct Repair {
  std::string kind;  // "near_zero_edges", "coincident_roots", "short_strands"
  std::size_t strands = 0;  // strands affected
  std::size_t items = 0;    // edges, strands
  std::string action;       // what was done
  std::string example;      // the first one: "strand S edge E (L m)"
};

// Repairs a groom (positions in metres) in place, or throws InputError naming `source`,
// the strand and the edge under DegeneratePolicy::Refuse:
//  - near-zero edges (kNearZeroEdge, exact zeros included): the strand is resampled to
//    the same vertex count at equal arc-length steps along its polyline (every new vertex
//    lies on the old polyline; vertices keep their inverse masses by index);
//  - coincident roots, a strand whose every vertex repeats an earlier strand's: removed;
//  - short strands (kShortStrand): every vertex pinned, so they move rigidly with the head.
// The importers run it before they make follow hairs, which copy their guides. Returns
// what was done, empty when the groom was clean.
std::vector<Repair> repair_groom(Groom& g, DegeneratePolicy policy, const std::string& source);

// One line for the terminal: "repairs: 31 near-zero edges in 12 strands resampled, ...".
std::string repairs_text(const std::vector<Repair>& repairs);

}  // namespace hairbench
