#include "models/registry.h"

#include "core/error.h"
#include "models/halen2007/cascade_settings.h"
#include "models/halen2007/forest_settings.h"
#include "models/halen2007/fused/halen_fused.h"
#include "models/halen2007/nodes_model.h"
#include "models/halen2007/reference/cascade.h"
#include "models/halen2007/reference/forest.h"
#include "models/halen2007/reference/spring.h"
#include "models/halen2007/spring_settings.h"
#include "models/han2012/fused/han_fused.h"
#include "models/han2012/reference/han_reference.h"
#include "models/han2012/settings.h"
#include "models/plante2001/fused/wisp_fused.h"
#include "models/plante2001/reference/wisp_reference.h"
#include "models/plante2001/settings.h"
#ifdef HAIRBENCH_HAS_VULKAN
#include "models/han2012/vulkan/han_vulkan.h"
#endif

#include <iterator>
#include <vector>

namespace hairbench {

namespace {

// Halén & Wester's models simulate `nodes` nodes a strand and draw the groom from them
// (models/halen2007/nodes_model.h); their step bounds are taken on those nodes.
std::unique_ptr<HairModel> at_nodes(std::unique_ptr<HairModel> inner, const halen::NodeTraits& traits,
                                    const ModelContext& c) {
  return std::make_unique<halen::NodesModel>(std::move(inner), traits, c);
}
// Han & Harada's methods 1-3 (fused); the reference implementations and the Vulkan
// models repeat their iterations, so the same parameters scale them.
constexpr StepCost kHanCost[] = {
    {12.3, true, "substeps", {{{"local_iterations", 0.55}, {"length_iterations", 0.08}}}},
    {17.2, true, "substeps", {{{"local_iterations", 0.69}, {"length_iterations", 0.05}}}},
    {8.3, true, "substeps", {{{"local_iterations", 0.10}, {"length_iterations", 0.14}}}},
};
// The methods iterated far past their defaults (32 local and length iterations, 4
// substeps), so that a deviation from them is an absolute error (--reference converged).
const std::vector<ParamValue> kHanConverged = {{"local_iterations", 32}, {"length_iterations", 32}, {"substeps", 4}};

template <halen::BoundFn bound, const halen::NodeTraits& traits>
StepBound bound_at_nodes(const Groom& g, const ParamSet& p, const Vec3f& gravity) {
  return halen::bound_at_nodes(bound, traits, g, p, gravity);
}

std::vector<ModelInfo> built_in_models() {
  return {
      // Han & Harada 2012 (models/han2012)
      {.name = "han_m1",
       .summary = "Han & Harada 2012 method 1: serial exact local/global transforms (Algorithm 3); fused SoA kernel",
       .params = han::kParams,
       .make = [](const ModelContext& c) { return han_fused::make(han::Method::Serial, c); },
       .step_bound = halen::travel_bound,
       .cost = kHanCost[0],
       .converged = kHanConverged},
      {.name = "han_m2",
       .summary = "Han & Harada 2012 method 2: Jacobi transforms from the last iteration (Algorithm 4); fused SoA kernel",
       .params = han::kParams,
       .make = [](const ModelContext& c) { return han_fused::make(han::Method::Jacobi, c); },
       .step_bound = halen::travel_bound,
       .cost = kHanCost[1],
       .converged = kHanConverged},
      {.name = "han_m3",
       .summary = "Han & Harada 2012 method 3: rest-state transforms (Algorithm 5); fused SoA kernel",
       .params = han::kParams,
       .make = [](const ModelContext& c) { return han_fused::make(han::Method::RestFrames, c); },
       .step_bound = halen::travel_bound,
       .cost = kHanCost[2],
       .converged = kHanConverged},
      {.name = "han_m1_ref",
       .summary = "han_m1 as one stage at a time over all strands with the per-strand kernels",
       .params = han::kParams,
       .make = [](const ModelContext& c) { return han::make_reference(han::Method::Serial, c); },
       .reference_of = "han_m1",
       .step_bound = halen::travel_bound,
       .cost = {247.0, true, "substeps", {{{"local_iterations", 0.55}, {"length_iterations", 0.08}}}},
       .converged = kHanConverged},
      {.name = "han_m2_ref",
       .summary = "han_m2 as one stage at a time over all strands with the per-strand kernels",
       .params = han::kParams,
       .make = [](const ModelContext& c) { return han::make_reference(han::Method::Jacobi, c); },
       .reference_of = "han_m2",
       .step_bound = halen::travel_bound,
       .cost = {188.0, true, "substeps", {{{"local_iterations", 0.69}, {"length_iterations", 0.05}}}},
       .converged = kHanConverged},
      {.name = "han_m3_ref",
       .summary = "han_m3 as one stage at a time over all strands with the per-strand kernels",
       .params = han::kParams,
       .make = [](const ModelContext& c) { return han::make_reference(han::Method::RestFrames, c); },
       .reference_of = "han_m3",
       .step_bound = halen::travel_bound,
       .cost = {102.0, true, "substeps", {{{"local_iterations", 0.10}, {"length_iterations", 0.14}}}},
       .converged = kHanConverged},
      // Halén & Wester 2007 (models/halen2007)
      {.name = "halen_spring",
       .summary = "Halén & Wester 2007 §4.4: springs to head-fixed reference nodes, tilt-weakened (§5.9); fused SoA kernel",
       .params = halen_spring::kParams,
       .make = [](const ModelContext& c) { return at_nodes(halen_fused::make(halen_fused::Model::Spring, c), halen::kSpringNodes, c); },
       .step_bound = bound_at_nodes<halen::spring_bound, halen::kSpringNodes>,
       .cost = {12.7, true, "substeps", {{{"length_iterations", 0.13}}}}},
      {.name = "halen_cascade",
       .summary = "Halén & Wester 2007 §4.3: cascading tangent spaces with up/down reference nodes (§5.9); fused SoA kernel",
       .params = halen_cascade::kParams,
       .make = [](const ModelContext& c) { return at_nodes(halen_fused::make(halen_fused::Model::Cascade, c), halen::kCascadeNodes, c); },
       .step_bound = bound_at_nodes<halen::cascade_bound, halen::kCascadeNodes>,
       .cost = {55.0, true, "substeps"}},
      {.name = "halen_forest",
       .summary = "Halén & Wester 2007 §4.2 (Di Giacomo et al. 2001): joint angles, x-primary axes (§5.9); fused SoA kernel",
       .params = halen_forest::kParams,
       .make = [](const ModelContext& c) { return at_nodes(halen_fused::make(halen_fused::Model::Forest, c), halen::kForestNodes, c); },
       .step_bound = bound_at_nodes<halen::forest_bound, halen::kForestNodes>,
       .cost = {25.5, true, "substeps"}},
      {.name = "halen_spring_ref",
       .summary = "halen_spring as one stage at a time over all strands with the per-strand kernels",
       .params = halen_spring::kParams,
       .make = [](const ModelContext& c) { return at_nodes(halen_spring::make(c), halen::kSpringNodes, c); },
       .reference_of = "halen_spring",
       .step_bound = bound_at_nodes<halen::spring_bound, halen::kSpringNodes>,
       .cost = {129.0, true, "substeps", {{{"length_iterations", 0.13}}}}},
      {.name = "halen_cascade_ref",
       .summary = "halen_cascade as one stage at a time over all strands with the per-strand kernels",
       .params = halen_cascade::kParams,
       .make = [](const ModelContext& c) { return at_nodes(halen_cascade::make(c), halen::kCascadeNodes, c); },
       .reference_of = "halen_cascade",
       .step_bound = bound_at_nodes<halen::cascade_bound, halen::kCascadeNodes>,
       .cost = {264.0, true, "substeps"}},
      {.name = "halen_forest_ref",
       .summary = "halen_forest as one stage at a time over all strands with the per-strand kernels",
       .params = halen_forest::kParams,
       .make = [](const ModelContext& c) { return at_nodes(halen_forest::make(c), halen::kForestNodes, c); },
       .reference_of = "halen_forest",
       // The fused forest composes the joint rotations in another order and takes sin/cos
       // from a polynomial (kernels/simd/vec_math.h).
       .reference_tolerance = 1e-5,
       .step_bound = bound_at_nodes<halen::forest_bound, halen::kForestNodes>,
       .cost = {233.0, true, "substeps"}},
      // Plante, Cani & Poulin 2001 (models/plante2001)
      {.name = "plante_wisp",
       .summary = "Plante, Cani & Poulin 2001: layered wisps (skeleton, envelope, strands) with anisotropic interactions (§3-5)",
       .params = plante::kParams,
       .make = [](const ModelContext& c) { return plante::make_fused(c); },
       .cost = {111.0, false, "integration_hz"}},
      {.name = "plante_wisp_ref",
       .summary = "plante_wisp one stage at a time over all wisps with the per-wisp kernels",
       .params = plante::kParams,
       .make = [](const ModelContext& c) { return plante::make_reference(c); },
       .reference_of = "plante_wisp",
       .cost = {251.0, false, "integration_hz"}},
#ifdef HAIRBENCH_HAS_VULKAN
      {.name = "han_m1_vk",
       .summary = "Han & Harada 2012 method 1 on a Vulkan device (§5: a workgroup per strand, shared memory)",
       .params = han::kParams,
       .make = [](const ModelContext& c) { return han_vk::make(han::Method::Serial, c); },
       .platform = Platform::Vulkan,
       .unavailable = han_vk::unavailable,
       .step_bound = halen::travel_bound,
       .cost = kHanCost[0],
       .converged = kHanConverged},
      {.name = "han_m2_vk",
       .summary = "Han & Harada 2012 method 2 on a Vulkan device (Algorithm 4 with a barrier)",
       .params = han::kParams,
       .make = [](const ModelContext& c) { return han_vk::make(han::Method::Jacobi, c); },
       .platform = Platform::Vulkan,
       .unavailable = han_vk::unavailable,
       .step_bound = halen::travel_bound,
       .cost = kHanCost[1],
       .converged = kHanConverged},
      {.name = "han_m3_vk",
       .summary = "Han & Harada 2012 method 3 on a Vulkan device (Algorithm 5)",
       .params = han::kParams,
       .make = [](const ModelContext& c) { return han_vk::make(han::Method::RestFrames, c); },
       .platform = Platform::Vulkan,
       .unavailable = han_vk::unavailable,
       .step_bound = halen::travel_bound,
       .cost = kHanCost[2],
       .converged = kHanConverged},
#endif
  };
}

std::deque<ModelInfo>& registry() {
  static std::deque<ModelInfo> models = [] {
    std::vector<ModelInfo> v = built_in_models();
    return std::deque<ModelInfo>(std::make_move_iterator(v.begin()), std::make_move_iterator(v.end()));
  }();
  return models;
}

}  // namespace

const std::deque<ModelInfo>& model_registry() { return registry(); }

void add_models(std::vector<ModelInfo> models, const std::string& source) {
  for (const ModelInfo& m : models)
    if (const ModelInfo* taken = find_model(m.name))
      throw InputError(source, "models",
                       "model name '" + std::string(m.name) + "' is taken by " +
                           (taken->origin.empty() ? std::string("a built-in model") : std::string(taken->origin)));
  for (ModelInfo& m : models) registry().push_back(std::move(m));
}

std::span<const Preset> presets() {
  // Each value for a model and its reference implementation.
  auto both = [](std::string_view model, std::string_view ref, std::vector<std::pair<std::string_view, double>> v) {
    std::vector<PresetValue> out;
    for (std::string_view m : {model, ref})
      for (const auto& [param, value] : v) out.push_back({m, param, value});
    return out;
  };
  // §4.2 as written (forest_settings.h): gravity bends the strand, J ≈ mI, the head's
  // angular acceleration in the first joint, no drag, an undamped penalty.
  const std::vector<PresetValue> forest =
      both("halen_forest", "halen_forest_ref",
           {{"gravity_compensation", 0}, {"inertia", 0}, {"root_angular_acceleration", 1}, {"drag", 0},
            {"collision_damping", 0}});
  // §4.3 as written (cascade_settings.h): reference nodes fixed during the step, and
  // B = N × T_parent.
  const std::vector<PresetValue> cascade =
      both("halen_cascade", "halen_cascade_ref", {{"reactions", 0}, {"frames", 0}});
  std::vector<PresetValue> thesis = forest;
  thesis.insert(thesis.end(), cascade.begin(), cascade.end());
  static const std::vector<Preset> all = {
      {"halen2007", "Halén & Wester 2007's forest (§4.2) and cascade (§4.3) as the thesis writes them", thesis},
      {"halen2007_forest",
       "halen_forest as §4.2 writes it: gravity uncompensated, J = mI, the head's angular acceleration in the "
       "first joint, no drag, an undamped penalty",
       forest},
      {"halen2007_cascade", "halen_cascade as §4.3 writes it: fixed reference nodes, B = N x T_parent", cascade},
      // §3.2 as written (plante2001/settings.h): angle springs between segments.
      {"plante2001", "plante_wisp's bending springs as §3.2 writes them (bending=0)",
       both("plante_wisp", "plante_wisp_ref", {{"bending", 0}})},
  };
  return all;
}

const Preset* find_preset(std::string_view name) {
  for (const Preset& p : presets())
    if (p.name == name) return &p;
  return nullptr;
}

const ModelInfo* find_model(std::string_view name) {
  for (const ModelInfo& m : model_registry())
    if (m.name == name) return &m;
  return nullptr;
}

const ModelInfo* find_reference(std::string_view model) {
  for (const ModelInfo& m : model_registry())
    if (!m.reference_of.empty() && m.reference_of == model) return &m;
  return nullptr;
}

}  // namespace hairbench
