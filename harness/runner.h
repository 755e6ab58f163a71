// The lockstep runner: every selected model steps through the same scenario frame by
// frame with the identical FrameInput; metrics are taken after each step against the
// reference model's positions of the same frame (DESIGN.md, "Data flow").
#pragma once

#include "core/params.h"
#include "models/registry.h"
#include "reports/report.h"
#include "scenarios/scenario.h"

#include <functional>
#include <string>
#include <vector>

namespace hairbench {

class ThreadPool;

// --set MODEL.NAME=VALUE; model "*" means every model that has the parameter.
struct ParamOverride {
  std::string model;
  std::string name;
  double value;
};
// Parses "MODEL.NAME=VALUE"; throws InputError naming the argument.
ParamOverride parse_param_override(const std::string& arg);
// Checks an override against the registry (the model exists; the parameter exists for
// it, or for at least one model when MODEL is "*").
void check_param_override(const ParamOverride& o);

// One model's parameters for a scenario. Precedence, weakest first: the model's
// defaults; the groom's region defaults (an asset's .tfxsim); the scenario's "*" then
// its model entry; their "regions" entries; command-line overrides ("*" then the model).
ParamSet resolve_params(const ModelInfo& model, const Scenario& scenario,
                        const std::vector<ParamOverride>& overrides);

struct RunOptions {
  std::vector<std::string> models;  // to report, in order
  std::string reference = "";       // empty: the scenario's reference
  int frames = 0;                   // > 0 overrides the scenario's frame count
  std::vector<ParamOverride> overrides;
  // Stress runs (issue 8): a model whose mechanical energy keeps growing while the head
  // is still and no wind blows also fails (metrics::EnergyGrowthCheck).
  bool energy_check = false;
};

// Runs one scenario; a model that becomes unstable stops there (recorded in its
// RunRecord) and the others go on. Throws InputError for bad parameters.
std::vector<RunRecord> run_scenario(const Scenario& scenario, const RunOptions& options, ThreadPool& pool);

}  // namespace hairbench
