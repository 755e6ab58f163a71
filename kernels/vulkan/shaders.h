// The SPIR-V of the compute shaders in this folder, compiled by glslc at build time.
#pragma once

#include <cstdint>
#include <span>

namespace hairbench::vk {

// han_step.comp: one frame of Han & Harada's Algorithm 1 for all strands.
std::span<const std::uint32_t> han_step_spirv();
// follow_hairs.comp: TressFX follow hairs from the guides' device positions.
std::span<const std::uint32_t> follow_hairs_spirv();

}  // namespace hairbench::vk
