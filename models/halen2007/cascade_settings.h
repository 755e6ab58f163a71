// Parameters of Halén & Wester 2007's cascading spaces model (§4.3 with §5.9's falloff
// and weakened downward springs).
//
// Stiffnesses are per unit node mass (s^-2), so the node mass m of L = mg/k cancels.
// Each reference spring, with its reaction on what places its reference node (the segment
// that carries its space, and the twist of the spaces above it), is half of a torsion
// spring: the springs are the negative gradient of their energy and make none
// (kernels::cascade_accelerations). They make a strand an elastic rod whose slowest mode,
// the strand turning about its root, has a stiffness of about k (ℓ/L)^4 for segments ℓ of
// a strand L; the stiffness is given at the thesis's 8 nodes and scaled with the node
// count (models/halen2007/nodes_model.h). Defaults are chosen for real gravity, 25 cm
// strands and 60 Hz frames: k = 6000 s^-2 at the root falling quadratically past 20 cm;
// downward springs at a quarter of the upward ones (§5.9); six edge corrections; damping
// 0.03 per sixth of a frame (11/s: the thesis gives Eq. 4.1's k no value), under which
// the hair comes back to its style within seconds of the head stopping; at 0.1 the slow
// mode creeps (docs/limitations.md, "The cascade").
#pragma once

#include "core/params.h"
#include "models/halen2007/spring_region.h"

#include <array>
#include <cstddef>
#include <vector>

namespace hairbench::halen_cascade {

inline constexpr std::array<ParamSpec, 10> kParams{{
    {"nodes", 8, 2, 64, true,
     "simulated nodes per strand (Fig. 6.1.1: 4 and 8); the groom's vertices are drawn from them (§5.5), at most the groom's vertices per strand; stiffness is given at 8 nodes and scales as ((nodes - 1) / 7)^3.6", ParamRole::cost_knob},
    {"damping", 0.03, 0.0, 1.0, false,
     "fraction of velocity removed per sixth of a frame in Verlet (Eq. 4.1: k = 1 - damping), taken per "
     "substep as the same per frame at any substep count", ParamRole::damping},
    {"stiffness", 6000.0, 0.0, 1e6, false,
     "k: upward reference spring strength at the root per unit node mass, s^-2 (§4.3, §5.9)", ParamRole::stiffness},
    {"falloff_exponent", 2, 1, 3, true, "a of §5.9's k_L = k / (L c)^a: 1 linear, 2 quadratic, 3 cubic"},
    {"falloff_scale", 5.0, 0.0, 1e4, false,
     "c of §5.9, 1/m: the strength is k up to L = 1/c from the root, then falls as (L c)^-a"},
    {"down_fraction", 0.25, 0.0, 1.0, false,
     "downward reference springs' strength as a fraction of the upward ones (§5.9; 1 = equal)"},
    {"length_iterations", 6, 0, 64, true, "edge corrections (Eq. 4.2) per substep", ParamRole::cost_knob},
    {"substeps", 6, 1, 1024, true, "solver passes per frame; the head is interpolated between them", ParamRole::cost_knob},
    {"reactions", 1, 0, 1, true,
     "1: each reference spring pushes back on the segment that carries its space (the torsion spring "
     "§4.3 says the reference nodes simulate); 0: the reference nodes are fixed during the step"},
    {"frames", 1, 0, 1, true,
     "how a tangent space takes B and T from its parent's: 0 the thesis's B = N x T_parent (§4.3), "
     "1 parallel transport (the parent's space turned with the segment)"},
}};

// kParams read once from a ParamSet, per region where the parameter may differ by region:
// the reference (reference/cascade.cpp) and the fused kernel (fused/halen_fused.cpp) both
// take their settings from here.
struct RegionSettings : halen::SpringRegion {
  float down_fraction;  // the downward reference springs' strength over the upward ones (§5.9)
};
struct Settings {
  std::vector<RegionSettings> regions;
  int substeps;
  int frames;      // kernels::CascadeFrames
  bool reactions;  // the springs' reactions through the spaces (§4.3)
};
inline Settings read_settings(const ParamSet& p, std::size_t region_count) {
  Settings s{{}, p.get_int("substeps"), p.get_int("frames"), p.get_int("reactions") != 0};
  for (std::size_t r = 0; r < region_count; ++r)
    s.regions.push_back({halen::read_spring_region(p, r), static_cast<float>(p.get("down_fraction", r))});
  return s;
}

}  // namespace hairbench::halen_cascade
