// Every model by name, with its paper, parameters, backend and reference implementation
// (docs/architecture.md).
#pragma once

#include "models/halen2007/step_bounds.h"

#include "core/hair_model.h"

#include <functional>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace hairbench {

// Where a model runs.
enum class Platform { Cpu, Vulkan };

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
  std::function<halen::StepBound(const Groom&, const ParamSet&, const Vec3f&)> step_bound = {};
};

std::span<const ModelInfo> model_registry();

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
