// Every model by name (han_m1 ... plante_wisp; GPU variants end in _vk; docs/architecture.md).
#pragma once

#include "core/hair_model.h"

#include <functional>
#include <memory>
#include <span>
#include <string>
#include <string_view>

namespace hairbench {

struct ModelInfo {
  std::string_view name;
  std::string_view summary;  // one line, with the paper section it implements
  std::span<const ParamSpec> params;
  std::function<std::unique_ptr<HairModel>(const ModelContext&)> make;
  // For models that need hardware that may be missing (a Vulkan device): why the model
  // cannot run in this context, or "" when it can. Empty function: always available.
  std::function<std::string(const ModelContext&)> unavailable = {};
};

std::span<const ModelInfo> model_registry();
// nullptr if there is no such model.
const ModelInfo* find_model(std::string_view name);

}  // namespace hairbench
