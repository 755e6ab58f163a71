// The SPIR-V of the compute shaders in this folder, compiled by glslc at build time.
#pragma once

#include <cstdint>
#include <span>

namespace hairbench::vk {

// han_step.comp: one frame of Han & Harada's Algorithm 1 for all strands.
std::span<const std::uint32_t> han_step_spirv();

}  // namespace hairbench::vk
