#include "kernels/vulkan/shaders.h"

namespace hairbench::vk {

namespace {
const std::uint32_t kHanStep[] =
#include "han_step.comp.inc"
    ;
const std::uint32_t kFollowHairs[] =
#include "follow_hairs.comp.inc"
    ;
const std::uint32_t kMetrics[] =
#include "metrics.comp.inc"
    ;
}  // namespace

std::span<const std::uint32_t> han_step_spirv() { return kHanStep; }
std::span<const std::uint32_t> follow_hairs_spirv() { return kFollowHairs; }
std::span<const std::uint32_t> metrics_spirv() { return kMetrics; }

}  // namespace hairbench::vk
