// The harness's metrics kernel (metrics.comp) over a model's device positions: the
// DeviceMetrics a Vulkan model hands out (core/device_metrics.h). Model-agnostic: it
// needs only the position buffer (vec4 per vertex, the whole groom) and its context.
#pragma once

#include "core/device_metrics.h"
#include "kernels/vulkan/runtime.h"

#include <memory>
#include <vector>

namespace hairbench::vk {

class MetricsKernel final : public DeviceMetrics {
 public:
  // `positions` (vertices vec4s) must outlive this object.
  MetricsKernel(std::shared_ptr<Context> context, const Buffer& positions, std::size_t vertices);
  void prepare(const DeviceMetricsRest& rest) override;
  bool read_reference(const DeviceMetrics& reference) override;
  std::span<const StrandMetrics> measure(const DeviceMetricsFrame& frame) override;
  void keep() override;
  std::span<const Vec4f> kept() override;

 private:
  void record();

  std::shared_ptr<Context> context_;
  const Buffer& pos_;
  std::size_t vertices_;
  std::size_t strands_ = 0;
  float far_ = 0.0f;
  Buffer prev_, rest_, edge_, offsets_, frame_, out_;
  // The reference's positions: uploaded per frame (host_reference_), or another model's
  // buffer on this device.
  Buffer host_reference_;
  const Buffer* reference_ = nullptr;
  Buffer kept_;
  std::unique_ptr<Readback> kept_readback_;
  std::vector<Vec4f> kept_host_;
  std::unique_ptr<Kernel> kernel_;
  std::unique_ptr<Commands> commands_;
};

}  // namespace hairbench::vk
