// Every model by name (DESIGN.md: han_m1 ... plante_wisp; GPU variants end in _vk).
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
};

std::span<const ModelInfo> model_registry();
// nullptr if there is no such model.
const ModelInfo* find_model(std::string_view name);

}  // namespace hairbench
