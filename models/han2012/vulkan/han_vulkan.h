// Han & Harada 2012 methods 1-3 on a Vulkan device: the algorithm of models/han2012/reference/ (same
// parameters, same stages, same order of operations) as one compute dispatch per frame,
// one workgroup per strand or several short strands per workgroup, each strand in shared
// memory for all substeps (§5). Rest data goes up once in reset(); per frame only the
// head transforms, colliders, wind and gravity; positions come back only when asked for.
// With follow hairs (TressFX), a second dispatch in the same submission builds them from
// the guides' device positions.
#pragma once

#include "core/hair_model.h"
#include "kernels/han2012/vulkan/han_layout.h"
#include "kernels/vulkan/metrics.h"
#include "kernels/vulkan/runtime.h"
#include "models/han2012/reference/han_reference.h"

#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

namespace hairbench::han_vk {

class HanVkModel final : public HairModel {
 public:
  // Opens (or shares) the Vulkan context of ctx.device; throws vk::Unavailable when
  // there is no Vulkan device.
  HanVkModel(han::Method method, const ModelContext& ctx);
  // Builds these follow hairs on the device after every step, from the guides' device
  // positions (apply_follow_hairs's formula, in float); call before reset(), which then
  // takes the guides expanded by the follow hairs (tfx::expand_follow_hairs) and
  // simulates the guides only. Throws std::invalid_argument for an inconsistent layout.
  bool set_follow_hairs(const FollowHairsView& follow) override;
  // Throws InputError for a strand longer than HAN_VK_MAX_STRAND_VERTICES.
  void reset(const Groom& rest, const ParamSet& params) override;
  // The positions and previous positions uploaded at the given ones (method 2's frames
  // stay at rest, as the CPU models' do); false where follow hairs are built on the device
  // (a truth scenario has none).
  bool start_from(std::span<const Vec4f> positions) override;
  // Uploads the frame's inputs, runs the dispatches and waits for them (stages "upload",
  // "dispatch"; their device time is last_gpu_ms()).
  void step(const FrameInput& in, StageTimes& out_times) override;
  // Runs the step with `in` back to back for `seconds` (twice at least) and puts the state
  // back as it was, on the device.
  void warm_up(const FrameInput& in, double seconds) override;
  // Reads the positions (the follow hairs' too) back on the first call after a step.
  std::span<const Vec4f> positions() const override;
  Backend backend() const override { return {"vulkan", context_->device().name}; }
  std::optional<double> last_gpu_ms() const override { return gpu_ms_; }
  // The harness's metrics on the device, over the whole groom (the follow hairs too).
  DeviceMetrics* device_metrics() override { return metrics_.get(); }
  // Device time of the last step's follow hairs dispatch; nullopt without follow hairs.
  std::optional<double> last_follow_gpu_ms() const { return follow_gpu_ms_; }

  // Invocations per strand the kernel uses for this groom (a power of two).
  std::uint32_t lanes() const { return lanes_; }

 private:
  void upload_frame(const FrameInput& in);

  han::Method method_;
  std::shared_ptr<vk::Context> context_;
  std::unique_ptr<vk::Kernel> kernel_, follow_kernel_;
  std::unique_ptr<vk::Commands> commands_;
  std::unique_ptr<vk::Readback> readback_;  // pos_ to host_pos_
  std::unique_ptr<vk::MetricsKernel> metrics_;  // reads pos_
  vk::Buffer pos_, prev_, rot_, rest_, rest_local_, rest_rot_, strands_, regions_, frame_, spheres_;
  vk::Buffer follow_strands_, follow_vertices_;
  // The follow hairs in the device's layout (han_layout.h), and the guides' strand
  // offsets they were made for; empty without follow hairs.
  std::vector<vk_layout::HanFollowStrand> follow_strands_host_;
  std::vector<vk_layout::HanFollowVertex> follow_vertices_host_;
  std::vector<std::uint32_t> follow_guide_offsets_;
  std::size_t strand_count_ = 0;
  std::uint32_t lanes_ = 1;
  std::uint32_t max_iterations_ = 0;
  int substeps_ = 1;
  std::optional<double> gpu_ms_, follow_gpu_ms_;
  mutable std::vector<Vec4f> host_pos_;
  mutable bool host_current_ = true;
};

std::unique_ptr<HairModel> make(han::Method method, const ModelContext& ctx);
// "" when a Vulkan model can run with ctx.device, else the one-line reason.
std::string unavailable(const ModelContext& ctx);

}  // namespace hairbench::han_vk
