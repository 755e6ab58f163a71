// What a region of Halén & Wester's spring (§4.4) and cascade (§4.3) models shares: the
// Verlet damping (Eq. 4.1), the spring strength at the root with §5.9's falloff, and the
// edge corrections (Eq. 4.2) per substep; each model's settings add their own.
#pragma once

#include "core/params.h"

#include <cstddef>

namespace hairbench::halen {

struct SpringRegion {
  float damping, stiffness, falloff_scale;
  int falloff_exponent, length_iterations;
};

inline SpringRegion read_spring_region(const ParamSet& p, std::size_t region) {
  return {static_cast<float>(p.get("damping", region)), static_cast<float>(p.get("stiffness", region)),
          static_cast<float>(p.get("falloff_scale", region)), p.get_int("falloff_exponent", region),
          p.get_int("length_iterations", region)};
}

}  // namespace hairbench::halen
