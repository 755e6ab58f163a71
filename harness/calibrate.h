// --calibrate: fit a model's material to the reference's (docs/metrics.md, Calibration).
//
// Deviation from the reference measures method only between models of the same material.
// For each model but the reference, calibrate() scales the parameter its spec marks as
// its stiffness (ParamRole::stiffness), in every region by one factor, so that its
// material card's static sag (reports/material.h) matches the reference's on the scenario
// within max(kSagTolerance of the target, kSagFloor L̄), where the sag answers the
// stiffness (a quarter of it moves the sag by more than that tolerance); a model that
// carries the hair's weight on its springs' offsets sags 0 at any stiffness and is left as
// it is, with the reason, and so is one whose sag no value in its range brings within
// tolerance (with the closest it came). The damping (ParamRole::damping) is not fitted:
// the card's decay rate is reported beside the reference's (docs/metrics.md, Calibration
// says why).
// The fit walks factors 4^k (k = -3..3, inside the parameter's range), keeps the one
// nearest the target, and bisects (in log) between it and a neighbour on the target's
// other side until within tolerance or kMaxBisections. Substeps picked automatically are
// picked again for every trial (a stiffer spring may need more). Deterministic, as the
// card runs are.
#pragma once

#include "core/params.h"
#include "harness/runner.h"
#include "models/registry.h"
#include "reports/material.h"
#include "scenarios/scenario.h"

#include <string>
#include <vector>

namespace hairbench {

class ThreadPool;

inline constexpr double kSagTolerance = 0.1, kSagFloor = 0.005;
inline constexpr int kMaxBisections = 6;

// Fits `params` (already resolved for the scenario) so that the model's card matches
// `target`. A parameter that `given` sets for the model (or for "*": --set, a sweep's knob)
// is kept. Returns the fitted parameters; `out` says what was done.
ParamSet calibrate(const ModelInfo& info, const Scenario& sc, ParamSet params, const material::Card& target,
                   const std::vector<ParamOverride>& given, ThreadPool& pool, const std::string& device,
                   material::Calibration& out);

}  // namespace hairbench
