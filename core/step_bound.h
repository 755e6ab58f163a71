// The largest stable substep of a model with an explicit integrator on a given groom
// (ModelInfo::step_bound): `substeps: "auto"` divides the frame by it (docs/substeps.md).
#pragma once

#include <string>

namespace hairbench {

struct StepBound {
  double max_step = 0.0;  // seconds; 0 when no step is stable (the caller caps the count)
  std::string why;        // the binding term with its numbers, for the report
};

}  // namespace hairbench
