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
//
// Three defaults are not §4.2's; each is a parameter, and
//   --set halen_forest.gravity_compensation=0 --set halen_forest.inertia=0
//   --set halen_forest.root_angular_acceleration=1
// selects the thesis as written (docs/limitations.md gives what it does). Gravity
// compensation keeps the head-transformed rest pose in equilibrium, as the other two
// models' L = mg/k does. J = m L ℓ scales the external torques to the strand: under §4.2's
// J ≈ mI a 1.7 cm segment gets at most L g = 0.16 rad/s² from gravity, against joint
// springs of thousands of s^-2 per radian (above), so gravity, the root's inertial force
// and the sphere penalty forces hardly bend the hair. The head's rotation reaches the
// joints through the inertial force of the moving root, which holds it at every segment
// end; Eq. 4.2.5's Ω̇_p = Ω̇_H for the first joint on top of that counts the head's angular
// acceleration twice (on `shake` the hair then never settles).
#pragma once

#include "core/params.h"

#include <array>

namespace hairbench::halen_forest {

inline constexpr std::array<ParamSpec, 10> kParams{{
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
    {"gravity_compensation", 1, 0, 1, true,
     "1: gravity's torque on the head-transformed rest segment is subtracted, so that pose is in "
     "equilibrium; 0: §4.2 as written, gravity bends the strand until the joint springs hold it"},
    {"inertia", 1, 0, 1, true,
     "J of Eq. 4.2.4 for the external torques: 1 J = m L ℓ (a straight strand swings like a pendulum of "
     "its length ℓ), 0 §4.2's J ≈ mI (angular acceleration L z × a)"},
    {"root_angular_acceleration", 0, 0, 1, true,
     "1: the head's angular acceleration is the first joint's Ω̇_p in Eq. 4.2.5 (§4.2 as written); 0: the "
     "head's rotation acts only through the inertial force of the moving root"},
}};

}  // namespace hairbench::halen_forest
