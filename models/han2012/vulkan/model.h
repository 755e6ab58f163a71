// Han & Harada 2012 methods 1-3 on a Vulkan device: the algorithm of models/han2012/reference/ (same
// parameters, same stages, same order of operations) as one compute dispatch per frame,
// one workgroup per strand or several short strands per workgroup, each strand in shared
// memory for all substeps (§5). Rest data goes up once in reset(); per frame only the
// head transforms, colliders, wind and gravity; positions come back only when asked for.
#pragma once

#include "core/hair_model.h"
#include "kernels/vulkan/runtime.h"
#include "models/han2012/reference/model.h"

#include <memory>
#include <string>
#include <vector>

namespace hairbench::han_vk {

class HanVkModel final : public HairModel {
 public:
  // Opens (or shares) the Vulkan context of ctx.device; throws vk::Unavailable when
  // there is no Vulkan device.
  HanVkModel(han::Method method, const ModelContext& ctx);
  // Throws InputError for a strand longer than HAN_VK_MAX_STRAND_VERTICES.
  void reset(const Groom& rest, const ParamSet& params) override;
  // Uploads the frame's inputs, runs the dispatch and waits for it (stages "upload",
  // "dispatch"; the device time of the dispatch is last_gpu_ms()).
  void step(const FrameInput& in, StageTimes& out_times) override;
  // Reads the positions back on the first call after a step.
  std::span<const Vec4f> positions() const override;
  Backend backend() const override { return {"vulkan", context_->device().name}; }
  std::optional<double> last_gpu_ms() const override { return gpu_ms_; }

  // Invocations per strand the kernel uses for this groom (a power of two).
  std::uint32_t lanes() const { return lanes_; }

 private:
  han::Method method_;
  std::shared_ptr<vk::Context> context_;
  std::unique_ptr<vk::Kernel> kernel_;
  std::unique_ptr<vk::Readback> readback_;  // pos_ to host_pos_
  vk::Buffer pos_, prev_, rot_, rest_, rest_local_, rest_rot_, strands_, regions_, frame_, spheres_;
  std::size_t strand_count_ = 0;
  std::uint32_t lanes_ = 1;
  std::uint32_t max_iterations_ = 0;
  int substeps_ = 1;
  std::optional<double> gpu_ms_;
  mutable std::vector<Vec4f> host_pos_;
  mutable bool host_current_ = true;
};

std::unique_ptr<HairModel> make_han_vk(han::Method method, const ModelContext& ctx);
// "" when a Vulkan model can run with ctx.device, else the one-line reason.
std::string unavailable(const ModelContext& ctx);

}  // namespace hairbench::han_vk
