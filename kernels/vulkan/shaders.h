// The SPIR-V of the compute shaders (kernels/vulkan/CMakeLists.txt), compiled by glslc
// at build time.
#pragma once

#include <cstdint>
#include <span>

namespace hairbench::vk {

// han_step.comp: one frame of Han & Harada's Algorithm 1 for all strands.
std::span<const std::uint32_t> han_step_spirv();
// follow_hairs.comp: TressFX follow hairs from the guides' device positions.
std::span<const std::uint32_t> follow_hairs_spirv();
// metrics.comp: the harness's per-frame metrics per strand (kernels/vulkan/metrics.h).
std::span<const std::uint32_t> metrics_spirv();

}  // namespace hairbench::vk
