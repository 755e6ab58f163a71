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

// The head sphere through a groom's roots (vertex 0 of every strand), fitted robustly
// (fit_head below), or through the roots higher than `above` (y, the groom's units) when
// given, which overrides the robust fit.
struct HeadFit {
  Vec3f center = Vec3f::Zero();
  float radius = 0.0f;
  // Whether the roots lie near a sphere: the least-squares sphere's RMS distance from the
  // roots is at most kSphereResidual of its radius and its radius at most kSphereSpread
  // times the roots' own spread. Otherwise (a fur groom on a body, roots on a plane or a
  // line) center is the roots' bounding-box centre, radius a sphere inside their box
  // (never 0), and `note` says why. A sphere is the pivot and the collider.
  bool sphere = false;
  // Whether that sphere is a scalp, and so its radius evidence of the unit (guess_unit):
  // the residual of the roots it was fitted on is at most kScalpResidual of the radius
  // and they cover a cap of it (`cap` at least kScalpCap). A sphere that is not a scalp
  // (TestHair1's roots all round a 64-unit ball, 0.15 of its radius off it) still gives
  // the pivot; `note` says why it was not used for the unit.
  bool scalp = false;
  double rms_residual = 0.0;  // RMS of |p - c| - r over the roots fitted, in the groom's units
  double cap = 0.0;           // |mean of (p - c) / |p - c||: 1 for one point, 0 all round
  // Which roots the sphere went through: "consensus" (the scalp's, the others rejected),
  // "all roots" (no scalp found: the least-squares sphere of every root) or "above" (the
  // roots above the given height).
  std::string method;
  std::size_t roots = 0;                // strands
  std::vector<std::uint32_t> rejected;  // strands whose roots the fit left out, ascending
  std::string note;
};

inline constexpr double kSphereResidual = 0.2;
inline constexpr double kSphereSpread = 4.0;
// A human scalp is an ellipsoid, not a sphere: adult proportions (half-breadth 7-8 cm,
// half-length 9.8-11 cm, crown height 10-13 cm) cut anywhere from 0.3 of the height below
// the ears' level to 0.3 above it deviate from their best sphere by 0.064-0.098 of its
// radius RMS (uniform roots), the ponytail asset's stylised head by 0.11, the mohawk's
// crown by 0.063. 1/8 admits them all; TestHair1's 0.155 is not a head.
inline constexpr double kScalpResidual = 0.125;
// The same scalps cover a cap: the mean unit direction from the centre is 0.23-0.59 long
// (0.40 on the ponytail, 0.83 on the mohawk's crown); roots all round a sphere give about
// 0 (TestHair1: 0.04).
inline constexpr double kScalpCap = 0.15;

// The robust fit's consensus: a root belongs to a sphere of radius r when it lies within
// kFitBand r of it. A band of half-width 0.2 r holds a scalp's roots (their RMS residual
// is at most kScalpResidual r; a uniform band of half-width b has RMS b/sqrt(3) = 0.115 r)
// and leaves out a neck, a beard or a ponytail's tie, which run off the sphere.
inline constexpr double kFitBand = 0.2;
// The scalp holds at least this share of the roots: the Ratboy mohawk's crown holds 0.43
// of its roots (the rest run down its neck and back); a patch of TestHair1's ball that a
// head-sized sphere fits holds 0.04 of them.
inline constexpr double kScalpShare = 0.25;
// The prior: a head's radius, for people and for most animals a groom is made for.
inline constexpr double kHeadPriorMin = 0.08, kHeadPriorMax = 0.15;

// The head sphere, deterministic (docs/groom-import.md, "The fitted head"). Without
// `above`, for each unit in `metres_per_unit` (empty: the units the groom's strand
// lengths, span and root spacing admit, unit_cues):
//  1. the consensus sphere with a radius in the accepted head range [kHeadRadiusMin,
//     kHeadRadiusMax): from each of 32 seed roots spread over the groom (farthest-point
//     order), the least-squares sphere of the roots within the range's largest radius
//     of it, then refitted on the roots within kFitBand of it until they no longer change,
//     its radius held in the range; the seed whose sphere holds the most roots wins, and
//     is refitted on its core (the roots within 3 robust standard deviations of it). It is
//     the head when its radius settles inside the range (a sphere pressed against the top
//     of the range is a surface larger than any head: a neck and back with the crown) and
//     its roots are a scalp holding kScalpShare of them;
//  2. otherwise the same consensus with the radius held in the prior [kHeadPriorMin,
//     kHeadPriorMax], the head when its roots are a scalp holding kScalpShare of them.
// The unit whose head holds the most roots wins. With no head, the least-squares sphere
// of every root, classified as above. Least squares: |p|^2 = 2 c.p + (r^2 - |c|^2) is
// linear in (c, r^2 - |c|^2), solved in double precision, centred on the roots' mean.
HeadFit fit_head(const Groom& g, std::optional<double> above = std::nullopt,
                 std::vector<float> metres_per_unit = {});

// The unit of a groom from its size, in metres per file unit. Each cue below admits the
// units (m, cm, mm) under which its size is that of real hair on a real head, and the
// unit is the one every cue admits (docs/groom-import.md, "Units"):
//  - the head radius, when the fitted sphere is a scalp (HeadFit::scalp);
//  - the median strand length: hair long enough to be simulated, and no longer than hair;
//  - the roots' bounding-box diagonal: a palm-sized patch to a body;
//  - the median distance from a root to its nearest neighbour: guides no denser than
//    hair follicles, and close enough to cover a scalp.
// Throws InputError naming `source` and "unit" when no unit or more than one passes
// every cue (the message gives each cue's size and the units it admits, and says --unit).
struct UnitGuess {
  std::string unit;  // "cm", "mm" or "m"
  float metres_per_unit = 0.0f;
  std::string why;  // the sizes it was read from, for the terminal and the report
};
UnitGuess guess_unit(const Groom& g, const HeadFit& fit, const std::string& source);
// The units (metres per file unit) every cue but the head radius admits.
std::vector<float> unit_cues(const Groom& g);
// Head radii in metres: a child's head to a helmet (and the ponytail asset's outsized
// 32 cm head).
inline constexpr double kHeadRadiusMin = 0.04, kHeadRadiusMax = 0.4;
// Median strand length in metres. Below 2 cm hair hardly moves: a hair held at its root
// sags under its weight by (L/L_g)^3/8 of its length, L_g = (E I / (rho A g))^(1/3) about
// 5 cm for a human hair (E 4 GPa, 40 um radius, 1.3 g/cm^3), so 0.8% at 2 cm; a groom
// whose median strand is that short is not one to simulate. Above 2 m it is not hair.
inline constexpr double kStrandLengthMin = 0.02, kStrandLengthMax = 2.0;
// The roots' bounding-box diagonal: a palm-sized patch to a body.
inline constexpr double kRootSpanMin = 0.05, kRootSpanMax = 3.0;
// Median nearest-neighbour distance between roots (coincident roots left out). A scalp
// carries at most about 300 hairs/cm^2, whose nearest neighbours are about
// 0.5/sqrt(300/cm^2) = 0.3 mm apart; guides are a subset of the hairs (0.1 mm allows
// clustered exports). Over 5 cm apart, a whole scalp (about 600 cm^2) has some 25 guides.
inline constexpr double kRootSpacingMin = 1e-4, kRootSpacingMax = 0.05;
float metres_per_unit(const std::string& unit);

// ---- import hygiene ------------------------------------------------------------------

// A rest edge shorter than this fraction of its strand's median edge is near zero: its
// direction is rounding noise or an exporter's duplicate vertex, and an explicit
// integrator's step would have to shrink with it.
inline constexpr double kNearZeroEdge = 1e-2;
// A rest edge shorter than this fraction of its strand's median edge, though not near
// zero, turns the frames a position-based solver reads the next edge's shape in by
// e / l for an error e at its end (Han & Harada 2012 §3.4 reads method 1's local goals in
// the current parent edge's frame), so short edges amplify the iteration's error by the
// ratio of the edges beyond it to it. Measured with method 1 at its defaults: a straight
// 16-vertex strand with one edge shortened to r of the others rests at r = 0.15 and
// flutters at r = 0.1; a folded TressFX ponytail guide flutters with its 2 mm edge at
// r = 0.21 (docs/limitations.md). A quarter leaves a margin above both.
inline constexpr double kShortEdge = 0.25;
// A strand shorter than this fraction of the groom's median strand length is far
// shorter than the rest: its edges are too short for a solver tuned to the groom.
inline constexpr double kShortStrand = 0.1;
// A strand under kStrandLengthMin (2 cm: it sags by under 1% of its length, and hardly
// moves) and under this fraction of the median strand is pinned too. Its edges are under
// a quarter of the groom's (kShortEdge's ratio, strand for strand), and position-based
// solvers tuned to the groom leave its edges stretched by many of their own lengths: the
// Ratboy mohawk's 0.80 and 0.86 cm strands (of 32 vertices; median 8 cm) by 3.4 under the
// wisp model and 10-13 under Han & Harada's methods on `shake`. The mohawk's built-in
// scenario pins the same 115 strands (rigid_strands_below 0.02).
inline constexpr double kShortFineStrand = 0.25;

enum class DegeneratePolicy { Repair, Refuse };

struct Repair {
  std::string kind;  // "near_zero_edges", "short_edges", "coincident_roots", "short_strands"
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
//  - short edges (kShortEdge, not near zero): resampled the same way;
//  - coincident roots, a strand whose every vertex repeats an earlier strand's: removed;
//  - short strands (kShortStrand): every vertex pinned, so they move rigidly with the head.
// The importers run it before they make follow hairs, which copy their guides. Returns
// what was done, empty when the groom was clean.
std::vector<Repair> repair_groom(Groom& g, DegeneratePolicy policy, const std::string& source);

// One line for the terminal: "repairs: 31 near-zero edges in 12 strands resampled, ...".
std::string repairs_text(const std::vector<Repair>& repairs);

}  // namespace hairbench
