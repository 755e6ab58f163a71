// hairbench precision (docs/precision.md): work-precision diagrams. Each selected model
// runs one scenario along its cost knobs (the parameters with ParamRole::cost_knob:
// substeps, iterations, node counts, integration rates), and each run's error is measured
// against the exact answer (a truth scenario's chain modes, reports/truth.h) or against
// the model's own converged run (every cost knob at kSelfFactor times the run's).
#pragma once

#include "harness/runner.h"

#include <nlohmann/json.hpp>

#include <functional>
#include <string>
#include <vector>

namespace hairbench {

class ThreadPool;

// The factors every cost knob is scaled by together: the line of a work-precision chart.
inline constexpr double kWorkFactors[] = {0.25, 0.5, 1.0, 2.0, 4.0};
// The factors of the step ladder (the knob the whole step scales with, ModelInfo::cost's
// multiplier; the knobs named *iterations at kLadderIterations times theirs, a resolution
// such as nodes as it is) and of the iteration ladder (the *iterations knobs, the others
// as they are): the order in the step and the geometric rate in the iteration count.
inline constexpr double kLadderFactors[] = {0.25, 0.5, 1.0, 2.0, 4.0};
inline constexpr double kLadderIterations = 4.0;
// --reference self: the model at every cost knob times this (capped at each knob's
// maximum); the work line's last points show how close it has converged.
inline constexpr double kSelfFactor = 8.0;
// Without --keep-every, a groom of more strands is thinned to at most this many (every
// k-th strand): the models' strands are independent but for the wisps' interactions, and
// a work-precision diagram is a property of the method, not of the groom's size.
inline constexpr std::size_t kPrecisionStrands = 256;

enum class PrecisionReference { exact, self };

struct PrecisionOptions {
  std::vector<std::string> models;
  // Unset: exact on a truth scenario, self elsewhere.
  std::optional<PrecisionReference> reference;
  std::size_t keep_every = 0;  // 0: thin to at most kPrecisionStrands strands
  int frames = 0;              // > 0 overrides the scenario's frame count
  std::vector<ParamOverride> overrides;  // --set, under the knobs' values
  std::function<void(const std::string& model, int done, int total)> on_run;
};

// Runs the diagrams and returns report["precision"] (docs/report-schema.md). Throws
// InputError for an exact reference on a scenario without an exact answer, and for a
// model with no cost knob.
nlohmann::json run_precision(const Scenario& scenario, const PrecisionOptions& options, ThreadPool& pool);

// The report's lines as a table for the terminal.
std::string precision_table(const nlohmann::json& precision);

}  // namespace hairbench
