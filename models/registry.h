// Every model by name, with its paper, parameters, backend and reference implementation
// (docs/architecture.md).
#pragma once

#include "core/hair_model.h"
#include "core/step_bound.h"

#include <array>
#include <deque>
#include <functional>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace hairbench {

// Where a model runs.
enum class Platform { Cpu, Vulkan };

// What a step costs, for sharding a sweep (harness/shard.h): the median step time per
// vertex at the model's defaults on the `shake` scenario (2,000 strands of 16 vertices,
// --no-skip, its first 120 frames), 2 threads on the development machine (a 2-core x86-64
// VM, idle), and how the step grows with the parameters that repeat its work, from sweeps
// of them there. A GPU model carries its CPU method's: the lockstep waits for it either way.
struct StepCost {
  double ns_per_vertex = 0.0;  // 0: not measured (a plugin that gives none)
  // Whether its strands fall asleep when nothing drives them.
  bool sleeps = true;
  // A parameter the whole step scales with (substeps, an integration rate).
  std::string_view multiplier;
  // Parameters that repeat one stage: each unit above the default adds this share of the
  // default step.
  std::array<std::pair<std::string_view, double>, 2> linear{};
};

// A parameter value, for the settings a model needs to converge.
struct ParamValue {
  std::string_view name;
  double value;
};

struct ModelInfo {
  std::string_view name;
  std::string_view summary;  // one line, with the paper section it implements
  std::span<const ParamSpec> params;
  std::function<std::unique_ptr<HairModel>(const ModelContext&)> make;
  // The model this one is the readable reference implementation of: one stage at a time
  // over all strands with the per-strand kernels, bit-identical to that model for any
  // thread count (tests/fused_reference_test.cpp). Empty for the models a comparison
  // runs by default; a reference runs only when --models names it.
  std::string_view reference_of = {};
  // 0: bit-identical. Otherwise the fast kernel reorders rounding, and this bounds the
  // RMS vertex distance between the two, over the mean strand length.
  double reference_tolerance = 0.0;
  Platform platform = Platform::Cpu;
  // For models that need hardware that may be missing (a Vulkan device): why the model
  // cannot run in this context, or "" when it can. Empty function: always available.
  std::function<std::string(const ModelContext&)> unavailable = {};
  // For models with an explicit integrator: the largest stable substep on a groom with
  // the resolved parameters and gravity (`substeps: "auto"`, harness/substeps.h). Empty:
  // the model's step has no such limit (position-based, or a rate in Hz of its own).
  std::function<StepBound(const Groom&, const ParamSet&, const Vec3f&)> step_bound = {};
  StepCost cost = {};
  // The settings at which the model is its own converged solution (`--reference
  // converged`: every model's deviation from it is then an absolute error): its cost knobs
  // far past their defaults. Empty: the model has no such setting.
  std::vector<ParamValue> converged = {};
  // Where the model comes from: empty for a built-in model, else the plugin library's
  // path (models/plugin/plugin_models.h); the report and `list models` show it.
  std::string_view origin = {};
};

// Every model: the built-in ones, then those the loaded plugins added, in load order. The
// entries never move (a std::deque), so a ModelInfo* stays valid after a plugin loads.
const std::deque<ModelInfo>& model_registry();
// Appends models (a plugin's); throws InputError naming `source` if a name is taken.
void add_models(std::vector<ModelInfo> models, const std::string& source);

// A paper's force law as written, where a model's default differs from it: named
// parameter values (`hairbench compare --preset NAME`), applied before any --set.
struct PresetValue {
  std::string_view model;
  std::string_view param;
  double value;
};
struct Preset {
  std::string_view name;
  std::string_view summary;
  std::vector<PresetValue> values;
};
std::span<const Preset> presets();
// nullptr if there is no such preset.
const Preset* find_preset(std::string_view name);
// nullptr if there is no such model.
const ModelInfo* find_model(std::string_view name);
// The reference implementation of `model` (the entry whose reference_of names it), or
// nullptr if it has none.
const ModelInfo* find_reference(std::string_view model);

}  // namespace hairbench
