// Parameters of Halén & Wester 2007's spring model (§4.4 with §5.9's falloff).
//
// Stiffnesses are per unit node mass (s^-2: acceleration per metre of spring stretch),
// so the node mass m of L = mg/k cancels. Defaults are chosen for real gravity, 25 cm
// strands of 16 vertices and 60 Hz frames: k = 900 s^-2 at the root, falling
// quadratically past 20 cm (k/1.56 at the tip). A steeper falloff (c = 25: k/39 at the
// tip) lets the weak tip springs' equilibria, each g/k_m below its rest node, crowd
// closer together than the segment length once the head tilts, and the strand folds
// into zig-zags (jaggedness 1-10 on `nod` and `tilt_upside_down`): the spring model has
// no bending stiffness of its own. Six substeps with six edge corrections keep edges
// within 1% RMS on `shake`.
#pragma once

#include "core/params.h"
#include "models/halen2007/spring_region.h"

#include <array>
#include <cstddef>
#include <vector>

namespace hairbench::halen_spring {

inline constexpr std::array<ParamSpec, 8> kParams{{
    {"nodes", 8, 2, 64, true,
     "simulated nodes per strand (Fig. 6.1.1: 4 and 8); the groom's vertices are drawn from them (§5.5), at most the groom's vertices per strand", ParamRole::cost_knob},
    {"damping", 0.04, 0.0, 1.0, false,
     "fraction of velocity removed per sixth of a frame in Verlet (Eq. 4.1: k = 1 - damping), taken per "
     "substep as the same per frame at any substep count", ParamRole::damping},
    {"stiffness", 900.0, 0.0, 1e6, false,
     "k: spring strength at the root per unit node mass, s^-2 (§4.4, §5.9)", ParamRole::stiffness},
    {"falloff_exponent", 2, 1, 3, true, "a of §5.9's k_L = k / (L c)^a: 1 linear, 2 quadratic, 3 cubic"},
    {"falloff_scale", 5.0, 0.0, 1e4, false,
     "c of §5.9, 1/m: the strength is k up to L = 1/c from the root, then falls as (L c)^-a"},
    {"tilt_min", 0.3, 0.0, 1.0, false,
     "alpha/k of §4.4's k_m: the fraction of the strength kept with the head upside down; 1 turns "
     "the tilt weakening off"},
    {"length_iterations", 6, 0, 64, true, "edge corrections (Eq. 4.2) per substep", ParamRole::cost_knob},
    {"substeps", 6, 1, 64, true, "solver passes per frame; the head is interpolated between them", ParamRole::cost_knob},
}};

// kParams read once from a ParamSet, per region where the parameter may differ by region:
// the reference (reference/spring.cpp) and the fused kernel (fused/halen_fused.cpp) both
// take their settings from here.
struct RegionSettings : halen::SpringRegion {
  float tilt_min;  // §5.9's tilt weakening floor
};
struct Settings {
  std::vector<RegionSettings> regions;
  int substeps;
};
inline Settings read_settings(const ParamSet& p, std::size_t region_count) {
  Settings s{{}, p.get_int("substeps")};
  for (std::size_t r = 0; r < region_count; ++r)
    s.regions.push_back({halen::read_spring_region(p, r), static_cast<float>(p.get("tilt_min", r))});
  return s;
}

}  // namespace hairbench::halen_spring
