#include "kernels/vulkan/shaders.h"

namespace hairbench::vk {

namespace {
const std::uint32_t kHanStep[] =
#include "han_step.comp.inc"
    ;
}  // namespace

std::span<const std::uint32_t> han_step_spirv() { return kHanStep; }

}  // namespace hairbench::vk
