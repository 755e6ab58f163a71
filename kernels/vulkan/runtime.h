// A small Vulkan compute runtime: the loader (opened at run time, so binaries start on
// machines without Vulkan), device selection, buffers, compute pipelines with their
// descriptor sets, command buffers of dispatches in order, fences and timestamp queries.
#pragma once

#define VK_NO_PROTOTYPES
#include <vulkan/vulkan.h>

#include <cstdint>
#include <memory>
#include <mutex>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

namespace hairbench::vk {

// No Vulkan loader, no instance, or no device at all: the one-line reason. Tests skip
// on this (and only this); the CLI leaves Vulkan models out with it.
class Unavailable : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct DeviceInfo {
  std::uint32_t index;
  std::string name;
  std::string type;  // "discrete GPU", "integrated GPU", "CPU", ...
  // Nanoseconds per timestamp tick (VkPhysicalDeviceLimits::timestampPeriod); 0 where
  // the compute queue writes no timestamps.
  double timestamp_period_ns = 0.0;
};

// The devices the loader reports; throws Unavailable when there is no loader or device.
std::vector<DeviceInfo> list_devices();

class Context;

// A buffer and its memory. Host-visible memory stays mapped (mapped() != nullptr).
class Buffer {
 public:
  Buffer() = default;
  ~Buffer();
  Buffer(Buffer&& o) noexcept { swap(o); }
  Buffer& operator=(Buffer&& o) noexcept {
    swap(o);
    return *this;
  }
  Buffer(const Buffer&) = delete;
  Buffer& operator=(const Buffer&) = delete;

  VkBuffer handle() const { return buffer_; }
  VkDeviceSize size() const { return size_; }
  void* mapped() const { return mapped_; }

 private:
  friend class Context;
  void swap(Buffer& o) noexcept;
  const Context* ctx_ = nullptr;
  VkBuffer buffer_ = VK_NULL_HANDLE;
  VkDeviceMemory memory_ = VK_NULL_HANDLE;
  VkDeviceSize size_ = 0;
  void* mapped_ = nullptr;
};

// Where a buffer lives: on the device (mapped too where the host reads device memory
// through its caches, as on CPU devices and integrated GPUs; never through a discrete
// GPU's uncached BAR), or in host memory the device reads and writes (per-frame uploads,
// staging). HAIRBENCH_VK_STAGING=1 (tests) leaves device buffers unmapped on any device,
// so that lavapipe runs the staging paths a discrete GPU takes.
enum class Memory { Device, Host };

// A compute pipeline over `bindings` storage buffers (set 0) with specialization
// constants 0..n-1, and its descriptor set. Dispatched through Commands.
class Kernel {
 public:
  ~Kernel();
  Kernel(const Kernel&) = delete;
  Kernel& operator=(const Kernel&) = delete;

  // Points binding i at buffers[i].
  void bind(std::span<const Buffer* const> buffers);

 private:
  friend class Context;
  friend class Commands;
  explicit Kernel(const Context& ctx) : ctx_(ctx) {}
  const Context& ctx_;
  VkShaderModule module_ = VK_NULL_HANDLE;
  VkDescriptorSetLayout set_layout_ = VK_NULL_HANDLE;
  VkPipelineLayout layout_ = VK_NULL_HANDLE;
  VkPipeline pipeline_ = VK_NULL_HANDLE;
  VkDescriptorPool pool_ = VK_NULL_HANDLE;
  VkDescriptorSet set_ = VK_NULL_HANDLE;
  std::uint32_t bindings_ = 0;
};

// One kernel's dispatch of `groups` workgroups.
struct Dispatch {
  const Kernel* kernel;
  std::uint32_t groups;
};

// A command buffer recorded once and submitted on every run(): dispatches in order, each
// followed by a barrier that makes its writes visible to the next dispatch, to transfers
// and to the host, with a timestamp before the first and after each.
class Commands {
 public:
  ~Commands();
  Commands(const Commands&) = delete;
  Commands& operator=(const Commands&) = delete;

  // Records the dispatches (the kernels must outlive this recording).
  void record(std::span<const Dispatch> dispatches);
  // Submits what was recorded and waits for it.
  void run();
  // Device time of the last run(), in ms: all of it, or dispatch i alone; nullopt when
  // the queue has no timestamps.
  std::optional<double> last_ms() const;
  std::optional<double> last_ms(std::size_t dispatch) const;

 private:
  friend class Context;
  explicit Commands(const Context& ctx) : ctx_(ctx) {}
  std::vector<std::uint64_t> timestamps() const;
  const Context& ctx_;
  VkCommandBuffer cmd_ = VK_NULL_HANDLE;
  VkFence fence_ = VK_NULL_HANDLE;
  VkQueryPool queries_ = VK_NULL_HANDLE;
  std::uint32_t recorded_ = 0;  // dispatches in the recording
};

// Brings a device buffer's contents to the host: straight from the mapping where the
// buffer is mapped, else through a host buffer and a copy recorded once and submitted on
// each fetch. Made by Context::readback; must not outlive the buffer's memory (make a new
// one when the buffer is replaced).
class Readback {
 public:
  ~Readback();
  Readback(const Readback&) = delete;
  Readback& operator=(const Readback&) = delete;
  // Copies the buffer's first `bytes` out; waits for the copy.
  void fetch(void* data, std::size_t bytes);

 private:
  friend class Context;
  explicit Readback(const Context& ctx) : ctx_(ctx) {}
  const Context& ctx_;
  VkDeviceSize size_ = 0;
  const void* mapped_ = nullptr;  // the buffer's own mapping, or staging_'s
  Buffer staging_;
  VkCommandBuffer cmd_ = VK_NULL_HANDLE;
  VkFence fence_ = VK_NULL_HANDLE;
};

class Context {
 public:
  // The shared context for a device: `spec` empty picks the first discrete GPU, else
  // the first device; a number picks by index (list_devices order); anything else is
  // matched case-insensitively against device names. Throws Unavailable when Vulkan or
  // any device is missing, and InputError("--device", spec, ...) when nothing matches.
  static std::shared_ptr<Context> get(const std::string& spec);
  Context(const Context&) = delete;
  Context& operator=(const Context&) = delete;

  const DeviceInfo& device() const { return info_; }

  Buffer buffer(VkDeviceSize size, Memory where) const;
  // Copies bytes into the buffer (through a staging buffer when it is not mapped).
  void upload(Buffer& dst, const void* data, std::size_t bytes) const;
  // Copies all of `src` into `dst` on the device and waits for the copy.
  void copy(const Buffer& src, const Buffer& dst) const;
  // The way back for a buffer the host reads repeatedly (see Readback).
  std::unique_ptr<Readback> readback(const Buffer& src) const;

  std::unique_ptr<Kernel> kernel(std::span<const std::uint32_t> spirv, std::uint32_t bindings,
                                 std::span<const std::uint32_t> specialization) const;
  std::unique_ptr<Commands> commands() const;

 private:
  friend class Buffer;
  friend class Kernel;
  friend class Commands;
  friend class Readback;
  static bool staging_only();
  Context() = default;
  void init(const std::string& spec);
  VkCommandBuffer new_command_buffer() const;  // a primary one from command_pool_
  VkFence new_fence() const;                    // unsignalled
  VkCommandBuffer begin_once() const;           // new_command_buffer(), begun for one submission
  void submit_and_wait(VkCommandBuffer cmd, VkFence fence) const;
  void copy(VkBuffer src, VkBuffer dst, VkDeviceSize bytes) const;
  std::uint32_t memory_type(std::uint32_t allowed, Memory where) const;

  DeviceInfo info_;
  VkPhysicalDevice physical_ = VK_NULL_HANDLE;
  VkDevice device_ = VK_NULL_HANDLE;
  VkQueue queue_ = VK_NULL_HANDLE;
  std::uint32_t queue_family_ = 0;
  VkCommandPool command_pool_ = VK_NULL_HANDLE;
  mutable std::mutex queue_mutex_;  // vkQueueSubmit from several threads (Readback::fetch)
  VkPhysicalDeviceMemoryProperties memory_{};
  std::uint64_t timestamp_mask_ = 0;  // info_.timestamp_period_ns > 0 only
};

}  // namespace hairbench::vk
