// Parameters of Halén & Wester 2007's interactive forest model (§4.2 after Di Giacomo et
// al. 2001, with §5.9's axis fix and stiffness falloff).
//
// Joint stiffness and damping are per unit inertia (s^-2 and s^-1). Defaults are chosen
// for real gravity, 25 cm strands of 16 vertices and 60 Hz frames. A joint's spring acts
// on its segment and, with the opposite sign, on the parent (Eq. 4.2.3); relative to the
// parent (Eq. 4.2.5) the joints then see a discrete Laplacian of the spring torques, whose
// slowest mode on n joints is about (π / 2n)² of k: 16 nodes need k in the thousands for
// the strand to swing back within a second. Its fastest mode, about 4k, bounds the
// explicit Euler step of Eq. 4.2.6 (v ≥ 4k dt, and 4 v dt < 2): twelve substeps with
// v = 120 s^-1.
#pragma once

#include "core/params.h"

#include <array>

namespace hairbench::halen_forest {

inline constexpr std::array<ParamSpec, 7> kParams{{
    {"joint_stiffness", 5000.0, 0.0, 1e6, false,
     "k of Eq. 4.2.2 at the root, angular acceleration per radian of joint deflection, s^-2"},
    {"joint_damping", 120.0, 0.0, 1e4, false, "v of Eq. 4.2.2, angular acceleration per rad/s, s^-1"},
    {"falloff_exponent", 2, 1, 3, true, "a of §5.9's k_L = k / (L c)^a: 1 linear, 2 quadratic, 3 cubic"},
    {"falloff_scale", 5.0, 0.0, 1e4, false,
     "c of §5.9, 1/m: the strength is k up to L = 1/c from the root, then falls as (L c)^-a"},
    {"axis_convention", 1, 0, 1, true,
     "primary joint axis: 1 the parent's x axis (Halén's fix, §5.9), 0 the parent's z axis "
     "(Di Giacomo et al.'s original, stiff near straight strands)"},
    {"collision_stiffness", 0.3, 0.0, 1.0, false,
     "sphere penalty force: the fraction of the penetration depth it would remove in one substep"},
    {"substeps", 12, 1, 64, true, "solver passes per frame; the head is interpolated between them"},
}};

}  // namespace hairbench::halen_forest
