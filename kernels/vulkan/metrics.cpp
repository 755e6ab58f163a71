#include "kernels/vulkan/metrics.h"

#include "core/error.h"
#include "kernels/vulkan/metrics_layout.h"
#include "kernels/vulkan/shaders.h"

#include <array>
#include <cstddef>
#include <cstring>
#include <stdexcept>
#include <string>

namespace hairbench::vk {

namespace L = hairbench::vk_layout;

static_assert(sizeof(L::MetricsFrame) == 176 + 16 * METRICS_VK_MAX_SPHERES && offsetof(L::MetricsFrame, sphere) == 176);
static_assert(sizeof(L::MetricsStrand) == sizeof(StrandMetrics) && sizeof(StrandMetrics) == 48);
static_assert(offsetof(L::MetricsStrand, length_worst) == offsetof(StrandMetrics, length_worst) &&
              offsetof(L::MetricsStrand, kinetic) == offsetof(StrandMetrics, kinetic) &&
              offsetof(L::MetricsStrand, bad_kind) == offsetof(StrandMetrics, bad_kind));

MetricsKernel::MetricsKernel(std::shared_ptr<Context> context, const Buffer& positions, std::size_t vertices)
    : context_(std::move(context)), pos_(positions), vertices_(vertices) {}

void MetricsKernel::prepare(const DeviceMetricsRest& rest) {
  const Context& ctx = *context_;
  if (rest.rest.size() != vertices_ || rest.edge.size() != vertices_ || rest.start.size() != vertices_ ||
      rest.strand_offsets.empty() || rest.strand_offsets.back() != vertices_)
    throw std::logic_error("MetricsKernel: the rest data is not of the model's groom");
  commands_.reset();
  kernel_.reset();
  kept_readback_.reset();
  strands_ = rest.strand_offsets.size() - 1;
  far_ = rest.far;
  const std::size_t bytes = vertices_ * sizeof(Vec4f);
  prev_ = ctx.buffer(bytes, Memory::Device);
  ctx.upload(prev_, rest.start.data(), bytes);
  rest_ = ctx.buffer(bytes, Memory::Device);
  ctx.upload(rest_, rest.rest.data(), bytes);
  edge_ = ctx.buffer(bytes, Memory::Device);
  ctx.upload(edge_, rest.edge.data(), bytes);
  offsets_ = ctx.buffer(rest.strand_offsets.size() * sizeof(std::uint32_t), Memory::Device);
  ctx.upload(offsets_, rest.strand_offsets.data(), rest.strand_offsets.size() * sizeof(std::uint32_t));
  frame_ = ctx.buffer(sizeof(L::MetricsFrame), Memory::Host);
  // Written by the device, read by the host once a frame: host memory, no staging copy.
  out_ = ctx.buffer(strands_ * sizeof(StrandMetrics), Memory::Host);
  host_reference_ = ctx.buffer(bytes, Memory::Host);
  reference_ = &host_reference_;
  kept_ = ctx.buffer(bytes, Memory::Device);
  const std::array<std::uint32_t, 1> spec{static_cast<std::uint32_t>(strands_)};
  kernel_ = ctx.kernel(metrics_spirv(), METRICS_VK_BINDINGS, spec);
  commands_ = ctx.commands();
  record();
}

// A descriptor set rebound invalidates the commands recorded with it: both again.
void MetricsKernel::record() {
  const std::array<const Buffer*, METRICS_VK_BINDINGS> bound{&pos_,   &prev_,    reference_, &rest_,
                                                             &edge_,  &offsets_, &frame_,    &out_};
  kernel_->bind(bound);
  const std::array<Dispatch, 1> dispatch{
      {{kernel_.get(), static_cast<std::uint32_t>((strands_ + METRICS_VK_GROUP_SIZE - 1) / METRICS_VK_GROUP_SIZE)}}};
  commands_->record(dispatch);
}

bool MetricsKernel::read_reference(const DeviceMetrics& reference) {
  const auto* other = dynamic_cast<const MetricsKernel*>(&reference);
  if (!kernel_ || !other || other->context_ != context_ || other->vertices_ != vertices_) return false;
  reference_ = &other->pos_;
  host_reference_ = Buffer();
  record();
  return true;
}

std::span<const StrandMetrics> MetricsKernel::measure(const DeviceMetricsFrame& in) {
  if (!kernel_) throw std::logic_error("MetricsKernel: measure() before prepare()");
  if (in.spheres.size() > METRICS_VK_MAX_SPHERES)
    throw InputError("colliders", std::to_string(in.spheres.size()),
                     "the device metrics take at most " + std::to_string(METRICS_VK_MAX_SPHERES) + " spheres");
  if (!in.reference.empty()) {
    if (reference_ != &host_reference_ || in.reference.size() != vertices_)
      throw std::logic_error("MetricsKernel: host reference positions for a kernel that reads them on the device");
    std::memcpy(host_reference_.mapped(), in.reference.data(), in.reference.size_bytes());
  }
  L::MetricsFrame f{};
  std::memcpy(f.head.m, in.head.matrix().data(), sizeof f.head.m);
  std::memcpy(f.carry.m, in.carry.matrix().data(), sizeof f.carry.m);
  const Vec3f c = in.head.translation();
  f.centre_far = {c.x(), c.y(), c.z(), far_};
  f.gravity_dt = {in.gravity.x(), in.gravity.y(), in.gravity.z(), in.dt};
  f.spheres = static_cast<std::uint32_t>(in.spheres.size());
  for (std::size_t k = 0; k < in.spheres.size(); ++k)
    f.sphere[k] = {in.spheres[k].x(), in.spheres[k].y(), in.spheres[k].z(), in.spheres[k].w()};
  std::memcpy(frame_.mapped(), &f, sizeof f);
  commands_->run();
  return {static_cast<const StrandMetrics*>(out_.mapped()), strands_};
}

void MetricsKernel::keep() { context_->copy(pos_, kept_); }

std::span<const Vec4f> MetricsKernel::kept() {
  if (!kept_readback_) kept_readback_ = context_->readback(kept_);
  kept_host_.resize(vertices_);
  kept_readback_->fetch(kept_host_.data(), vertices_ * sizeof(Vec4f));
  return kept_host_;
}

}  // namespace hairbench::vk
