// Parameters of Halén & Wester 2007's cascading spaces model (§4.3 with §5.9's falloff
// and weakened downward springs).
//
// Stiffnesses are per unit node mass (s^-2), so the node mass m of L = mg/k cancels.
// Defaults are chosen for real gravity, 25 cm strands of 16 vertices and 60 Hz frames:
// k = 1500 s^-2 at the root falling quadratically past 20 cm, downward springs at a
// quarter of the upward ones (§5.9), six substeps with six edge corrections. Each
// node's upward reference extrapolates the segment above it, so a disturbance is passed
// down the strand with a gain of up to 3 per node (2 u_{i-1} - u_{i-2}); on 16-node
// strands only strong damping (0.1 per substep, about 36/s) keeps that in check, and
// the strand still returns to its rest shape slowly (seconds, not frames).
#pragma once

#include "core/params.h"

#include <array>

namespace hairbench::halen_cascade {

inline constexpr std::array<ParamSpec, 7> kParams{{
    {"damping", 0.1, 0.0, 1.0, false,
     "fraction of velocity removed per substep in Verlet (Eq. 4.1: k = 1 - damping)"},
    {"stiffness", 1500.0, 0.0, 1e6, false,
     "k: upward reference spring strength at the root per unit node mass, s^-2 (§4.3, §5.9)"},
    {"falloff_exponent", 2, 1, 3, true, "a of §5.9's k_L = k / (L c)^a: 1 linear, 2 quadratic, 3 cubic"},
    {"falloff_scale", 5.0, 0.0, 1e4, false,
     "c of §5.9, 1/m: the strength is k up to L = 1/c from the root, then falls as (L c)^-a"},
    {"down_fraction", 0.25, 0.0, 1.0, false,
     "downward reference springs' strength as a fraction of the upward ones (§5.9; 1 = equal)"},
    {"length_iterations", 6, 0, 64, true, "edge corrections (Eq. 4.2) per substep"},
    {"substeps", 6, 1, 64, true, "solver passes per frame; the head is interpolated between them"},
}};

}  // namespace hairbench::halen_cascade
