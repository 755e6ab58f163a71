// The GPU's shader clock, recorded beside device times (docs/vulkan.md, Timing): a kernel's
// device time scales with it, and an idle GPU drops it. Vulkan has no query for it; on
// NVIDIA, nvidia-smi (NVML's command line) reads it.
#pragma once

#include <optional>
#include <string>

namespace hairbench {

struct GpuClock {
  std::optional<double> mhz;      // the current shader (SM) clock
  std::optional<double> max_mhz;  // its maximum
  // "nvidia-smi" where read; otherwise "not queryable: " and why.
  std::string source;
};

// The clock of the GPU named `device` (the Vulkan device's name, as nvidia-smi names it
// too), from `nvidia-smi --query-gpu=name,clocks.sm,clocks.max.sm` found on PATH.
GpuClock read_gpu_clock(const std::string& device);

}  // namespace hairbench
