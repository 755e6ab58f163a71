// Parameters of Halén & Wester 2007's interactive forest model (§4.2 after Di Giacomo et
// al. 2001, with §5.9's axis fix and stiffness falloff).
//
// Joint stiffness and damping are per unit inertia (s^-2 and s^-1), given at 8 nodes and
// scaled as ((nodes - 1) / 7)^2 (models/halen2007/nodes_model.h). Defaults are chosen for
// real gravity, 25 cm strands and 60 Hz frames. A joint's spring acts on its segment and,
// with the opposite sign, on the parent (Eq. 4.2.3); relative to the parent (Eq. 4.2.5)
// the joints then see a discrete Laplacian of the spring torques, whose slowest mode on n
// joints is about (π / 2n)² of k. The defaults are the material that k = 5000 s^-2 and
// v = 120 s^-1 made of 16-vertex strands, carried to 8 nodes (× (7/15)²). The fastest
// mode, about 4k, bounds the explicit Euler step of Eq. 4.2.6 (v ≥ 4k dt, and 4 v dt < 2):
// 3 substeps at 8 nodes, under the default twelve.
//
// Five defaults are not §4.2's; each is a parameter, and
//   --set halen_forest.gravity_compensation=0 --set halen_forest.inertia=0
//   --set halen_forest.root_angular_acceleration=1 --set halen_forest.drag=0
//   --set halen_forest.collision_damping=0
// selects the thesis as written (docs/limitations.md gives what it does; rest_hold acts
// only with inertia 1). Gravity compensation keeps the head-transformed rest pose in
// equilibrium, as the other two models' L = mg/k does; it takes the part of gravity normal
// to each rest segment off as a force, not as a constant torque, which in 3D would do net
// work on a segment that circles. J = m L ℓ scales the external torques to the strand:
// under §4.2's J ≈ mI a 1.7 cm segment gets at most L g = 0.16 rad/s² from gravity,
// against joint springs of thousands of s^-2 per radian (above), so gravity, the root's
// inertial force and the sphere penalty forces hardly bend the hair. The head's rotation
// reaches the joints through the inertial force of the moving root, which holds it at
// every segment end; Eq. 4.2.5's Ω̇_p = Ω̇_H for the first joint on top of that counts the
// head's angular acceleration twice (on `shake` the hair then never settles).
//
// The joint damping v reaches a strand's slowest swing as v (π / 2n)², 0.3 s^-1 at 32
// vertices unscaled, so finer strands swing on for many seconds: `drag` damps each segment's
// rotation relative to the head directly, at any segment count. A penalty force on a
// segment's end turns that segment alone while its parents move the end, a coupling that
// is not the gradient of an energy, and an undamped penalty returns all it stores:
// `collision_damping` damps the penalty along the sphere's normal. With J = m L ℓ gravity
// turns every segment at g/ℓ per radian of tilt, whatever the segment count, while the
// joints' slowest mode falls as k/n²: an upright strand (a mohawk, a groom resampled to
// 64 vertices) held in its rest pose by gravity compensation topples out of it.
// `rest_hold` raises such a strand's J, strand by strand, until its joints hold it.
#pragma once

#include "core/params.h"

#include <array>
#include <cstddef>
#include <vector>

namespace hairbench::halen_forest {

inline constexpr std::array<ParamSpec, 14> kParams{{
    {"nodes", 8, 2, 64, true,
     "simulated nodes per strand (Fig. 6.1.1: 4 and 8); the groom's vertices are drawn from them (§5.5), at most the groom's vertices per strand; joint stiffness and damping are given at 8 nodes and scale as ((nodes - 1) / 7)^2", ParamRole::cost_knob},
    {"joint_stiffness", 1100.0, 0.0, 1e6, false,
     "k of Eq. 4.2.2 at the root, angular acceleration per radian of joint deflection, s^-2", ParamRole::stiffness},
    {"joint_damping", 26.0, 0.0, 1e4, false, "v of Eq. 4.2.2, angular acceleration per rad/s, s^-1",
     ParamRole::chain_limit, 0.0},
    {"falloff_exponent", 2, 1, 3, true, "a of §5.9's k_L = k / (L c)^a: 1 linear, 2 quadratic, 3 cubic"},
    {"falloff_scale", 5.0, 0.0, 1e4, false,
     "c of §5.9, 1/m: the strength is k up to L = 1/c from the root, then falls as (L c)^-a"},
    {"axis_convention", 1, 0, 1, true,
     "primary joint axis: 1 the parent's x axis (Halén's fix, §5.9), 0 the parent's z axis "
     "(Di Giacomo et al.'s original, stiff near straight strands)"},
    {"collision_stiffness", 0.3, 0.0, 1.0, false,
     "sphere penalty force: the fraction of the penetration depth it would remove in one substep"},
    {"collision_damping", 1.0, 0.0, 1.5, false,
     "ζ: the penalty force is damped along the sphere's normal at ζ times critical for it, 2ζ √(collision_stiffness) / dt; "
     "held within that rate times depth / dt; 0 a spring only"},
    {"substeps", 12, 1, 64, true, "solver passes per frame; the head is interpolated between them", ParamRole::cost_knob},
    {"gravity_compensation", 1, 0, 1, true,
     "1: gravity's torque on the head-transformed rest segment is subtracted, so that pose is in "
     "equilibrium; 0: §4.2 as written, gravity bends the strand until the joint springs hold it",
     ParamRole::chain_limit, 0.0},
    {"inertia", 1, 0, 1, true,
     "J of Eq. 4.2.4 for the external torques: 1 J = m L ℓ (a straight strand swings like a pendulum of "
     "its length ℓ), 0 §4.2's J ≈ mI (angular acceleration L z × a)"},
    {"root_angular_acceleration", 0, 0, 1, true,
     "1: the head's angular acceleration is the first joint's Ω̇_p in Eq. 4.2.5 (§4.2 as written); 0: the "
     "head's rotation acts only through the inertial force of the moving root"},
    {"drag", 2.0, 0.0, 1e3, false,
     "d, s^-1: each segment's rotation relative to the head decays at d (every joint's rates kept "
     "exp(-d dt) a step); not in §4.2, whose joint damping v reaches a strand's slowest swing as "
     "v (π / 2n)² only", ParamRole::damping},
    {"rest_hold", 1, 0, 1, true,
     "with inertia 1: 1 a strand whose rest pose gravity would topple (upright segments) gets J = m L ℓ "
     "raised until its joints hold it under twice its weight (kernels::forest_rest_inertia_scale); 0 J as "
     "given on every strand"},
}};

// kParams read once from a ParamSet, per region where the parameter may differ by region:
// the reference (reference/forest.cpp) and the fused kernel (fused/halen_fused.cpp) both
// take their settings from here.
struct RegionSettings {
  float joint_stiffness, joint_damping, falloff_scale, collision_stiffness, collision_damping, drag;
  int falloff_exponent;
};
struct Settings {
  std::vector<RegionSettings> regions;
  int substeps;
  bool parent_z_axes;              // axis_convention 0 (§4.2 as written)
  bool mass_inertia;               // inertia 0: J = mI
  bool gravity_compensation;
  bool root_angular_acceleration;
  bool rest_hold;                  // asked for; it applies with the strand-pendulum inertia only
};
inline Settings read_settings(const ParamSet& p, std::size_t region_count) {
  Settings s{{},
             p.get_int("substeps"),
             p.get_int("axis_convention") == 0,
             p.get_int("inertia") == 0,
             p.get_int("gravity_compensation") != 0,
             p.get_int("root_angular_acceleration") != 0,
             p.get_int("rest_hold") != 0};
  for (std::size_t r = 0; r < region_count; ++r)
    s.regions.push_back({static_cast<float>(p.get("joint_stiffness", r)), static_cast<float>(p.get("joint_damping", r)),
                         static_cast<float>(p.get("falloff_scale", r)),
                         static_cast<float>(p.get("collision_stiffness", r)),
                         static_cast<float>(p.get("collision_damping", r)), static_cast<float>(p.get("drag", r)),
                         p.get_int("falloff_exponent", r)});
  return s;
}

}  // namespace hairbench::halen_forest
