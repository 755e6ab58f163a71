// Which setting wins: a model's parameters for a scenario resolved from its defaults,
// the groom's, the scenario's and the command line's, and its substeps chosen from its
// step bound (docs/scenarios.md, Per-model parameters and regions; docs/substeps.md).
// Every value is checked by ParamSet (core/params.h) as it is set, and a bad one is an
// InputError naming where it came from.
#pragma once

#include "core/params.h"
#include "models/registry.h"
#include "scenarios/scenario.h"

#include <nlohmann/json.hpp>

#include <optional>
#include <string>
#include <vector>

namespace hairbench {

// --set MODEL.NAME=VALUE; model "*" means every model that has the parameter.
struct ParamOverride {
  std::string model;
  std::string name;
  double value;
};
// Parses "MODEL.NAME=VALUE"; throws InputError naming the argument.
ParamOverride parse_param_override(const std::string& arg);
// `text` as a finite number, all of it; otherwise an InputError(`option`, `arg`, why).
double parse_finite(const std::string& text, const std::string& option, const std::string& arg);
// Checks an override against the registry (the model exists; the parameter exists for
// it, or for at least one model when MODEL is "*").
void check_param_override(const ParamOverride& o);

// One model's parameters for a scenario. Precedence, weakest first: the model's
// defaults; the groom's region defaults (an asset's .tfxsim); a truth scenario's chain
// limit (ParamSet::set_chain_limit); the scenario's "*" then
// its model entry; their "regions" entries; command-line overrides ("*" then the model).
ParamSet resolve_params(const ModelInfo& model, const Scenario& scenario,
                        const std::vector<ParamOverride>& overrides);

// How a run's substeps were chosen (report runs[].substeps). Models with an explicit
// integrator (ModelInfo::step_bound) take, unless a number is given for them (a scenario's
// models."*" or models.MODEL, a region, or --set), the larger of their default and the
// smallest count whose substep is inside the bound for the simulated groom, capped at the
// parameter's maximum: `substeps: "auto"`, docs/substeps.md.
struct SubstepsChoice {
  int value = 0;
  std::string source;     // "auto", "given" or "default" (auto turned off: Scenario::auto_substeps)
  int needed = 0;         // auto: the count the bound asks for (more than value when capped)
  double max_step = 0.0;  // auto: the bound, seconds
  std::string why;        // auto: the binding term
  bool capped = false;
};
// Empty for a model without a step bound.
std::optional<SubstepsChoice> choose_substeps(const ModelInfo& model, const Scenario& scenario,
                                              const ParamSet& resolved, const std::vector<ParamOverride>& overrides);
// Sets `substeps` to what choose_substeps picks where it picks automatically (after a
// change to the parameters the bound reads: --calibrate's fitted stiffness).
void apply_auto_substeps(const ModelInfo& model, const Scenario& scenario, ParamSet& params,
                         const std::vector<ParamOverride>& overrides);
nlohmann::json substeps_json(const SubstepsChoice& c);

}  // namespace hairbench
