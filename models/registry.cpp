#include "models/registry.h"

#include "models/han/model.h"
#include "models/han/settings.h"
#include "models/han_fused/model.h"
#include "models/halen_cascade/model.h"
#include "models/halen_cascade/settings.h"
#include "models/halen_forest/model.h"
#include "models/halen_forest/settings.h"
#include "models/halen_fused/model.h"
#include "models/halen_spring/model.h"
#include "models/halen_spring/settings.h"
#include "models/plante_wisp/model.h"
#include "models/plante_wisp/settings.h"
#ifdef HAIRBENCH_HAS_VULKAN
#include "models/han_vk/model.h"
#endif

#include <vector>

namespace hairbench {

std::span<const ModelInfo> model_registry() {
  static const std::vector<ModelInfo> models = {
      {"han_m1", "Han & Harada 2012 method 1: serial exact local/global transforms (Algorithm 3); fused SoA kernel",
       han::kParams, [](const ModelContext& c) { return han_fused::make(han::Method::Serial, c); }},
      {"han_m2", "Han & Harada 2012 method 2: Jacobi transforms from the last iteration (Algorithm 4); fused SoA kernel",
       han::kParams, [](const ModelContext& c) { return han_fused::make(han::Method::Jacobi, c); }},
      {"han_m3", "Han & Harada 2012 method 3: rest-state transforms (Algorithm 5); fused SoA kernel",
       han::kParams, [](const ModelContext& c) { return han_fused::make(han::Method::RestFrames, c); }},
      {"han_m1_ref", "han_m1 as one stage at a time over all strands (per-strand kernels; the reference for han_m1)",
       han::kParams, [](const ModelContext& c) { return han::make_han(han::Method::Serial, c); }},
      {"han_m2_ref", "han_m2 as one stage at a time over all strands (per-strand kernels; the reference for han_m2)",
       han::kParams, [](const ModelContext& c) { return han::make_han(han::Method::Jacobi, c); }},
      {"han_m3_ref", "han_m3 as one stage at a time over all strands (per-strand kernels; the reference for han_m3)",
       han::kParams, [](const ModelContext& c) { return han::make_han(han::Method::RestFrames, c); }},
      {"halen_spring", "Halén & Wester 2007 §4.4: springs to head-fixed reference nodes, tilt-weakened (§5.9); fused SoA kernel",
       halen_spring::kParams, [](const ModelContext& c) { return halen_fused::make(halen_fused::Model::Spring, c); }},
      {"halen_cascade", "Halén & Wester 2007 §4.3: cascading tangent spaces with up/down reference nodes (§5.9); fused SoA kernel",
       halen_cascade::kParams, [](const ModelContext& c) { return halen_fused::make(halen_fused::Model::Cascade, c); }},
      {"halen_forest", "Halén & Wester 2007 §4.2 (Di Giacomo et al. 2001): joint angles, x-primary axes (§5.9); fused SoA kernel",
       halen_forest::kParams, [](const ModelContext& c) { return halen_fused::make(halen_fused::Model::Forest, c); }},
      {"halen_spring_ref", "halen_spring as one stage at a time over all strands (per-strand kernels; the reference for halen_spring)",
       halen_spring::kParams, [](const ModelContext& c) { return halen_spring::make(c); }},
      {"halen_cascade_ref", "halen_cascade as one stage at a time over all strands (per-strand kernels; the reference for halen_cascade)",
       halen_cascade::kParams, [](const ModelContext& c) { return halen_cascade::make(c); }},
      {"halen_forest_ref", "halen_forest as one stage at a time over all strands (the reference for halen_forest)",
       halen_forest::kParams, [](const ModelContext& c) { return halen_forest::make(c); }},
      {"plante_wisp", "Plante, Cani & Poulin 2001: layered wisps (skeleton, envelope, strands) with anisotropic interactions (§3-5)",
       plante::kParams, [](const ModelContext& c) { return plante::make_plante_wisp(c); }},
      {"plante_wisp_ref", "plante_wisp one stage at a time over all wisps (the reference for plante_wisp)",
       plante::kParams, [](const ModelContext& c) { return plante::make_plante_wisp(c, plante::Schedule::PerStage); }},
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
