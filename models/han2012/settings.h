// Parameters of Han & Harada 2012 methods 1-3 (names are a contract: docs/scenarios.md).
//
// Defaults are chosen for real gravity (9.81 m/s^2, strands in metres) at 60 Hz frames.
// TressFX's sample values (damping 0.1, S_L 0.5, S_G 0.2 over 30% of the strand) with
// Table 2's counts (2 length, 3 local iterations, one pass per frame) were tuned for
// assets in centimetres; under metric gravity they let a 16-vertex strand stretch past
// 50% within six frames (PBD chains lose stiffness as g dt^2 n^2 / iterations). Six
// substeps with a ramped global constraint over the whole strand (§3.3) keep edges
// within 1% and the start quiet; the paper's counts remain available through --set.
#pragma once

#include "core/params.h"

#include <array>
#include <cstddef>
#include <vector>

namespace hairbench::han {

inline constexpr std::array<ParamSpec, 9> kParams{{
    {"damping", 0.03, 0.0, 1.0, false,
     "fraction of velocity removed per (sub)step in Verlet (Halén Eq. 4.1: k = 1 - damping)", ParamRole::damping},
    {"global_stiffness", 0.2, 0.0, 1.0, false, "S_G of Eq. 2; 1 freezes hair to the rest shape",
     ParamRole::chain_limit, 0.0},
    {"global_range", 1.0, 0.0, 1.0, false,
     "fraction of each strand, from the root, that the global constraint acts on"},
    {"global_ramp", 1.0, 0.0, 1.0, true,
     "1: S_G falls linearly to 0 at the end of global_range (§3.3)"},
    {"local_stiffness", 0.9, 0.0, 1.0, false, "S_L of Eq. 3-4", ParamRole::stiffness},
    // Up to a strand's most vertices (kMaxStrandVertices): method 2 (Algorithm 4) moves a
    // correction one vertex per iteration, so converging it on the longest strand takes that many.
    {"local_iterations", 1, 0, 256, true, "local shape constraint iterations per (sub)step", ParamRole::cost_knob},
    {"length_iterations", 3, 0, 64, true, "edge length constraint iterations per (sub)step", ParamRole::cost_knob},
    {"substeps", 6, 1, 64, true, "solver passes per frame; the head is interpolated between them",
     ParamRole::cost_knob},
    {"method", 0, 0, 3, true,
     "local shape method for this region: 1, 2 or 3, 0 = the model's own (§6: a cheaper method as LOD)"},
}};

// One region's parameters as kParams names them, read once from a ParamSet: the
// reference, fused and Vulkan variants all take their settings from here.
struct RegionSettings {
  float damping;           // of Verlet (Halén Eq. 4.1)
  float global_stiffness;  // S_G, Eq. 2
  float global_range;      // share of the strand from the root
  bool global_ramp;        // §3.3
  float local_stiffness;   // S_L, Eq. 3-4
  int local_iterations;
  int length_iterations;
  int method;  // 0: the model's own; else this region's (§6: LOD by region)
};

struct Settings {
  std::vector<RegionSettings> regions;  // one per groom region
  int substeps;                         // per frame, the base value (not per region)
};

inline Settings read_settings(const ParamSet& p, std::size_t region_count) {
  Settings s{{}, p.get_int("substeps")};
  for (std::size_t r = 0; r < region_count; ++r)
    s.regions.push_back({static_cast<float>(p.get("damping", r)), static_cast<float>(p.get("global_stiffness", r)),
                         static_cast<float>(p.get("global_range", r)), p.get_int("global_ramp", r) != 0,
                         static_cast<float>(p.get("local_stiffness", r)), p.get_int("local_iterations", r),
                         p.get_int("length_iterations", r), p.get_int("method", r)});
  return s;
}

}  // namespace hairbench::han
