#include "models/registry.h"

#include "models/han/model.h"
#include "models/han/settings.h"
#ifdef HAIRBENCH_HAS_VULKAN
#include "models/han_vk/model.h"
#endif

#include <vector>

namespace hairbench {

std::span<const ModelInfo> model_registry() {
  static const std::vector<ModelInfo> models = {
      {"han_m1", "Han & Harada 2012 method 1: serial exact local/global transforms (Algorithm 3)",
       han::kParams, [](const ModelContext& c) { return han::make_han(han::Method::Serial, c); }},
      {"han_m2", "Han & Harada 2012 method 2: Jacobi transforms from the last iteration (Algorithm 4)",
       han::kParams, [](const ModelContext& c) { return han::make_han(han::Method::Jacobi, c); }},
      {"han_m3", "Han & Harada 2012 method 3: rest-state transforms (Algorithm 5)",
       han::kParams, [](const ModelContext& c) { return han::make_han(han::Method::RestFrames, c); }},
#ifdef HAIRBENCH_HAS_VULKAN
      {"han_m1_vk", "Han & Harada 2012 method 1 on a Vulkan device (§5: a workgroup per strand, shared memory)",
       han::kParams, [](const ModelContext& c) { return han_vk::make_han_vk(han::Method::Serial, c); },
       han_vk::unavailable},
      {"han_m2_vk", "Han & Harada 2012 method 2 on a Vulkan device (Algorithm 4 with a barrier)",
       han::kParams, [](const ModelContext& c) { return han_vk::make_han_vk(han::Method::Jacobi, c); },
       han_vk::unavailable},
      {"han_m3_vk", "Han & Harada 2012 method 3 on a Vulkan device (Algorithm 5)",
       han::kParams, [](const ModelContext& c) { return han_vk::make_han_vk(han::Method::RestFrames, c); },
       han_vk::unavailable},
#endif
  };
  return models;
}

const ModelInfo* find_model(std::string_view name) {
  for (const ModelInfo& m : model_registry())
    if (m.name == name) return &m;
  return nullptr;
}

}  // namespace hairbench
