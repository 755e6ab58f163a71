// Parameters of Plante, Cani & Poulin 2001's layered wisp model (models/plante2001/).
//
// Rates (§5.3): explicit integration at 1000 Hz, body collision detection at 120 Hz,
// wisp self-interaction detection at 24 Hz. A frame is consumed in ceil(dt * rate)
// equal integration steps; a detection runs on the step that crosses a multiple of its
// period, and body collisions also on a frame's last step, so that no mass ends a frame
// inside a body (the harness measures after each frame). A rate of 0 switches that
// interaction off. The wisp-wisp contacts a detection finds get their velocity
// modifications (§5.1 step 3) in that step, their drag standing for the detection
// period; a body contact is a sliding contact until the next body detection and is
// modified on every step in between (models/plante2001/wisp_model.cpp).
//
// Masses are the hair a node carries, in strand-metres (kernels/plante2001/reference/wisp_kernels.h):
// half of each adjacent segment's, the length of the wisp's strands along it. A
// segment's springs scale with its hair: stiffnesses are accelerations per metre (1/s^2)
// and dampings 1/s of the hair they hold, so that a node of a skeleton of equal segments
// accelerates by stiffness x stretch whatever its wisp's strand count, and no node by
// more than twice its springs' stiffness (lumped masses), whatever the segments. The
// defaults keep the explicit integration stable at 1000 Hz with the highest axial mode
// at omega h ~ 1.3 (< 2), and hold a 25 cm wisp's skeleton within 2% of its rest length
// under gravity (idle: 1.9% at most, next to the root). The bending springs derive from
// an energy (kernels::bishop_bending, kernels::paper_bending); their zigzag mode has
// omega^2 ~ 16 k, so explicit integration at 1000 Hz holds up to k ~ 2.5e5 (measured on `idle` without
// gravity: `ok` at 2e5, the probe growing at 2.5e5 and 4e5). 1e5 (omega h ~
// 1.3) is the stiffest default with that margin; it holds the style against metric
// gravity far better than 5e3 (rest_shape_error on `idle` 0.049 L-bar against 0.12).
// Nothing but bending holds the style (§3.2): the root of a horizontal wisp of length L
// on segments of L0 sags by about g L^2 / (2 k L0^3), 0.2 rad for 23 cm on 10 segments.
// Stiffer bending also bounds the bend changes at the nodes, which the rebuilt strands
// turn into edge length error (wisp_width_max). None of these numbers are the paper's
// (it gives none).
//
// `bending` chooses the bending springs' law (parameters take numbers only: 0 paper, 1
// bishop). §3.2 gives "a damped spring for which the force increases linearly with the
// bending angle": bending 0 is that spring on the angle between consecutive segments,
// towards its rest angle (kernels::paper_bending). It has no azimuth, so a curved wisp
// rests in any turn of a bent segment about the one before it, and holds a curved style
// only as far as gravity and contacts leave its bends' planes alone (§6 leaves the
// style's memory to oriented particles). The default, 1, springs each segment towards its
// rest direction in Bishop frames (kernels::bishop_bending): the paper's angle spring
// where the rest wisp is straight, and the bend's azimuth besides where it is curved.
// It stays the default because it holds the groom's style (docs/plante-wisp.md, the
// bending springs; docs/limitations.md has what the paper's law does on curved wisps).
//
// Also ours, not the paper's (docs/plante-wisp.md): the body is the head sphere and the
// scenario's sphere colliders, not the character's polygons (§4.2), so that every model
// meets the same body; `root_blend` turns the rebuilt strands' section axes from
// head-carried to the sections' own over the first free nodes, since a strand is rooted
// at its own point of the scalp while its wisp's sections turn about the wisp's axis;
// the envelope masses stay within 0.25 and 2 times their rest radius (the stable step
// of the stiffening compression spring, and strands that would otherwise fly apart,
// kMinRadiusFraction and kMaxRadiusFraction in kernels/plante2001/reference/wisp_kernels.h); and the
// skeleton's bend bounds, finer skeletons at folds and averaged axes on curls
// (skeleton_of in wisp_model.cpp).
#pragma once

#include "core/params.h"

#include <array>

namespace hairbench::plante {

// The skeleton's resolution from the wisp's width (skeleton_segments 0): the paper's
// wisps have segments "mostly as wide as they are long" (§4.1, footnote 1) and 4.0, 9.9
// and 7.7 segments on average in its three styles (§5.3).
inline constexpr int kMinSegments = 4, kMaxSegments = 10;

inline constexpr std::array<ParamSpec, 27> kParams{{
    {"strands_per_wisp", 3, 1, 10000, true,
     "groom strands per wisp when `wisps` is 0: wisps = round(strands / strands_per_wisp) (§3.1)",
     ParamRole::chain_limit, 1.0},
    {"wisps", 0, 0, 1000000, true, "number of wisps (0: from strands_per_wisp); root-weighted k-means on the rest strands"},
    {"skeleton_segments", 0, 0, 256, true,
     "free skeleton segments per wisp (0: free length / wisp width, clamped to 4-10, §4.1 fn. 1, §5.3); "
     "never more than the strands' free edges"},
    {"wisp_width_max", 0.5, 0.01, 1000, false,
     "wisps wider than this many skeleton segments (strand distance from their mean curve) are split (§4.1 fn. 1)"},
    {"wisp_radius_min", 0.003, 1e-5, 1.0, false,
     "smallest rest envelope radius, metres (a wisp of one strand has no spread of its own)"},
    {"root_blend", 3, 0, 64, true,
     "free nodes over which the strand rebuild turns from head-carried to section axes (ours; 0: the paper's layer)"},
    {"integration_hz", 1000, 1, 100000, false, "explicit integration rate (§5.3: 1000 Hz)", ParamRole::cost_knob},
    {"collision_hz", 120, 0, 100000, false, "wisp-body collision detection rate (§5.3: 120 Hz); 0 off",
     ParamRole::chain_limit, 0.0},
    {"interaction_hz", 24, 0, 100000, false, "wisp-wisp interaction detection rate (§5.3: 24 Hz); 0 off",
     ParamRole::chain_limit, 0.0},
    {"air_drag", 5.0, 0, 1000, false, "air resistance on every mass, 1/s (§5.1 step 1)", ParamRole::damping},
    {"axial_stiffness", 4e5, 0, 1e7, false, "linear axial springs of the skeleton, 1/s^2 (§3.2)"},
    {"axial_damping", 40, 0, 1000, false, "damping of the axial springs, 1/s (§3.2); acts along a segment, on its stretch rate, so a chain's small swing does not feel it"},
    {"bending_stiffness", 1e5, 0, 1e6, false,
     "bending springs: lateral acceleration = k * angle * segment rest length, 1/s^2 (§3.2)", ParamRole::stiffness},
    {"bending_damping", 60, 0, 1000, false, "damping of the relative lateral velocity, 1/s (§3.2)",
     ParamRole::chain_limit, 0.0},
    {"bending", 1, 0, 1, true,
     "bending law: 0 paper (§3.2 as written: a spring on the angle between consecutive segments, towards its "
     "rest angle; no azimuth), 1 bishop (towards each segment's rest direction in Bishop frames: the angle "
     "and its azimuth, the style's memory)"},
    {"envelope_mass", 0.1, 1e-3, 1, false, "envelope mass / skeleton mass (§3.3: much lighter)"},
    {"radial_stiffness", 5e4, 0, 1e6, false,
     "envelope-skeleton springs at rest, 1/s^2; compression stiffens as r0/r (§3.3); 0 leaves the skeleton "
     "unloaded by its envelope", ParamRole::chain_limit, 0.0},
    {"radial_stretch", 0.3, 0, 1, false, "stretch stiffness of the radial springs as a fraction of compression"},
    {"radial_damping", 300, 0, 1000, false, "damping of the radial springs, 1/s (highly viscous, §3.3)",
     ParamRole::chain_limit, 0.0},
    {"ring_stiffness", 1e4, 0, 1e6, false, "soft springs between a section's envelope masses, 1/s^2 (§3.3)"},
    {"ring_damping", 200, 0, 1000, false, "damping of the ring springs, 1/s (highly damped, §3.3)"},
    {"contact_threshold", 0.002, 0, 0.1, false, "sliding contact distance to a body, metres (§4.2)"},
    {"body_friction", 20, 0, 10000, false, "viscous tangential drag against a body, 1/s (§4.2)"},
    {"hair_friction", 5, 0, 10000, false,
     "viscous drag between quasi-parallel wisps, 1/s at rest density (x density x dt, §4.1)"},
    {"parallel_angle", 30, 0, 90, false, "degrees: widest angle between wisps treated as quasi-parallel (§4.1)"},
    {"in_plane_angle", 30, 0, 90, false,
     "degrees: widest angle between their relative velocity and their plane (§4.1)"},
    {"threads_min_wisps", 64, 1, 1000000, true,
     "below this many wisps a step runs on one thread (thread hand-offs cost more than the work)"},
}};

}  // namespace hairbench::plante
