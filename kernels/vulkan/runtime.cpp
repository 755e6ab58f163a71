#include "kernels/vulkan/runtime.h"

#include "core/error.h"

#include <dlfcn.h>

#include <algorithm>
#include <cctype>
#include <cstdlib>
#include <cstring>
#include <map>
#include <mutex>
#include <string_view>

#if defined(__SANITIZE_ADDRESS__)
// LeakSanitizer: lavapipe (Mesa 22.3, libvulkan_lvp.so) leaks 48 bytes per run of a
// pipeline; that is the driver's, not ours, and would fail every sanitized test binary
// and CLI run that touches Vulkan on CI's CPU device.
extern "C" const char* __lsan_default_suppressions() { return "leak:libvulkan_lvp.so\n"; }
#endif

namespace hairbench::vk {

namespace {

// The entry points used, resolved through vkGetInstanceProcAddr from a loader opened
// with dlopen: a machine without libvulkan gets an Unavailable error naming what is
// missing instead of a binary that does not start. Device functions are the loader's
// trampolines, which dispatch on the handle, so contexts on several devices coexist.
#define HB_VK_GLOBAL(X) X(vkCreateInstance)
#define HB_VK_INSTANCE(X)                    \
  X(vkEnumeratePhysicalDevices)              \
  X(vkGetPhysicalDeviceProperties)           \
  X(vkGetPhysicalDeviceQueueFamilyProperties) \
  X(vkGetPhysicalDeviceMemoryProperties)     \
  X(vkCreateDevice)
#define HB_VK_DEVICE(X)          \
  X(vkGetDeviceQueue)            \
  X(vkCreateBuffer)              \
  X(vkDestroyBuffer)             \
  X(vkGetBufferMemoryRequirements) \
  X(vkAllocateMemory)            \
  X(vkFreeMemory)                \
  X(vkBindBufferMemory)          \
  X(vkMapMemory)                 \
  X(vkCreateShaderModule)        \
  X(vkDestroyShaderModule)       \
  X(vkCreateDescriptorSetLayout) \
  X(vkDestroyDescriptorSetLayout) \
  X(vkCreatePipelineLayout)      \
  X(vkDestroyPipelineLayout)     \
  X(vkCreateComputePipelines)    \
  X(vkDestroyPipeline)           \
  X(vkCreateDescriptorPool)      \
  X(vkDestroyDescriptorPool)     \
  X(vkAllocateDescriptorSets)    \
  X(vkUpdateDescriptorSets)      \
  X(vkCreateCommandPool)         \
  X(vkAllocateCommandBuffers)    \
  X(vkFreeCommandBuffers)        \
  X(vkBeginCommandBuffer)        \
  X(vkEndCommandBuffer)          \
  X(vkCmdBindPipeline)           \
  X(vkCmdBindDescriptorSets)     \
  X(vkCmdDispatch)               \
  X(vkCmdPipelineBarrier)        \
  X(vkCmdCopyBuffer)             \
  X(vkCmdWriteTimestamp)         \
  X(vkCmdResetQueryPool)         \
  X(vkCreateQueryPool)           \
  X(vkDestroyQueryPool)          \
  X(vkGetQueryPoolResults)       \
  X(vkCreateFence)               \
  X(vkDestroyFence)              \
  X(vkResetFences)               \
  X(vkWaitForFences)             \
  X(vkQueueSubmit)

#define HB_VK_DECLARE(name) PFN_##name name = nullptr;
struct Api {
  void* library = nullptr;
  PFN_vkGetInstanceProcAddr vkGetInstanceProcAddr = nullptr;
  HB_VK_GLOBAL(HB_VK_DECLARE)
  HB_VK_INSTANCE(HB_VK_DECLARE)
  HB_VK_DEVICE(HB_VK_DECLARE)
};
#undef HB_VK_DECLARE

Api api;
std::mutex api_mutex;

const char* result_name(VkResult r) {
  switch (r) {
    case VK_SUCCESS: return "VK_SUCCESS";
    case VK_ERROR_OUT_OF_HOST_MEMORY: return "VK_ERROR_OUT_OF_HOST_MEMORY";
    case VK_ERROR_OUT_OF_DEVICE_MEMORY: return "VK_ERROR_OUT_OF_DEVICE_MEMORY";
    case VK_ERROR_INITIALIZATION_FAILED: return "VK_ERROR_INITIALIZATION_FAILED";
    case VK_ERROR_DEVICE_LOST: return "VK_ERROR_DEVICE_LOST";
    case VK_ERROR_LAYER_NOT_PRESENT: return "VK_ERROR_LAYER_NOT_PRESENT";
    case VK_ERROR_EXTENSION_NOT_PRESENT: return "VK_ERROR_EXTENSION_NOT_PRESENT";
    case VK_ERROR_INCOMPATIBLE_DRIVER: return "VK_ERROR_INCOMPATIBLE_DRIVER";
    default: return "VkResult error";
  }
}

void check(VkResult r, const char* what) {
  if (r != VK_SUCCESS)
    throw std::runtime_error(std::string("Vulkan: ") + what + " failed (" + result_name(r) + " " +
                             std::to_string(static_cast<int>(r)) + ")");
}

// Opens the loader and resolves the global entry points, once.
void load_loader() {
  if (api.library) return;
  void* lib = dlopen("libvulkan.so.1", RTLD_NOW | RTLD_LOCAL);
  if (!lib) lib = dlopen("libvulkan.so", RTLD_NOW | RTLD_LOCAL);
  if (!lib) throw Unavailable("Vulkan: no loader (libvulkan.so.1 not found; Debian package libvulkan1)");
  api.vkGetInstanceProcAddr = reinterpret_cast<PFN_vkGetInstanceProcAddr>(dlsym(lib, "vkGetInstanceProcAddr"));
  if (!api.vkGetInstanceProcAddr) throw Unavailable("Vulkan: the loader has no vkGetInstanceProcAddr");
#define HB_VK_LOAD(name)                                                                   \
  api.name = reinterpret_cast<PFN_##name>(api.vkGetInstanceProcAddr(VK_NULL_HANDLE, #name)); \
  if (!api.name) throw Unavailable("Vulkan: the loader has no " #name);
  HB_VK_GLOBAL(HB_VK_LOAD)
#undef HB_VK_LOAD
  api.library = lib;
}

void load_instance(VkInstance instance) {
#define HB_VK_LOAD(name)                                                              \
  api.name = reinterpret_cast<PFN_##name>(api.vkGetInstanceProcAddr(instance, #name)); \
  if (!api.name) throw std::runtime_error("Vulkan: instance has no " #name);
  HB_VK_INSTANCE(HB_VK_LOAD)
  HB_VK_DEVICE(HB_VK_LOAD)
#undef HB_VK_LOAD
}

// The process's one instance. It, and every Context, lives until the process ends:
// destroying the last instance unloads the driver, and a driver that keeps allocations
// in its globals (lavapipe does) would then show them to LeakSanitizer as leaks. The
// operating system reclaims all of it at exit.
VkInstance shared_instance() {
  static VkInstance instance = VK_NULL_HANDLE;
  if (instance) return instance;
  load_loader();
  VkApplicationInfo app{VK_STRUCTURE_TYPE_APPLICATION_INFO};
  app.pApplicationName = "hairbench";
  app.apiVersion = VK_API_VERSION_1_0;
  VkInstanceCreateInfo info{VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO};
  info.pApplicationInfo = &app;
  VkInstance created = VK_NULL_HANDLE;
  const VkResult r = api.vkCreateInstance(&info, nullptr, &created);
  if (r == VK_ERROR_INCOMPATIBLE_DRIVER)
    throw Unavailable("Vulkan: no driver (the loader found no ICD it could load; VK_LOADER_DEBUG=error,warn says "
                      "why; Debian package mesa-vulkan-drivers gives lavapipe)");
  if (r != VK_SUCCESS) throw Unavailable(std::string("Vulkan: cannot create an instance (") + result_name(r) + ")");
  load_instance(created);
  instance = created;
  return instance;
}

const char* type_name(VkPhysicalDeviceType t) {
  switch (t) {
    case VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU: return "discrete GPU";
    case VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU: return "integrated GPU";
    case VK_PHYSICAL_DEVICE_TYPE_VIRTUAL_GPU: return "virtual GPU";
    case VK_PHYSICAL_DEVICE_TYPE_CPU: return "CPU";
    default: return "other";
  }
}

std::vector<VkPhysicalDevice> physical_devices(VkInstance instance) {
  std::uint32_t count = 0;
  check(api.vkEnumeratePhysicalDevices(instance, &count, nullptr), "vkEnumeratePhysicalDevices");
  std::vector<VkPhysicalDevice> devices(count);
  check(api.vkEnumeratePhysicalDevices(instance, &count, devices.data()), "vkEnumeratePhysicalDevices");
  devices.resize(count);
  if (devices.empty())
    throw Unavailable("Vulkan: no device (no driver reports one; Debian package mesa-vulkan-drivers gives lavapipe)");
  return devices;
}

std::string lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

// The first queue family that runs compute, or -1.
int compute_family(VkPhysicalDevice d) {
  std::uint32_t count = 0;
  api.vkGetPhysicalDeviceQueueFamilyProperties(d, &count, nullptr);
  std::vector<VkQueueFamilyProperties> families(count);
  api.vkGetPhysicalDeviceQueueFamilyProperties(d, &count, families.data());
  for (std::uint32_t i = 0; i < count; ++i)
    if (families[i].queueFlags & VK_QUEUE_COMPUTE_BIT) return static_cast<int>(i);
  return -1;
}

// Valid bits of the compute queue family's timestamps (0: it writes none).
std::uint32_t timestamp_bits(VkPhysicalDevice d, int family) {
  if (family < 0) return 0;
  std::uint32_t count = 0;
  api.vkGetPhysicalDeviceQueueFamilyProperties(d, &count, nullptr);
  std::vector<VkQueueFamilyProperties> families(count);
  api.vkGetPhysicalDeviceQueueFamilyProperties(d, &count, families.data());
  return families[static_cast<std::size_t>(family)].timestampValidBits;
}

DeviceInfo device_info(VkPhysicalDevice d, std::uint32_t index) {
  VkPhysicalDeviceProperties p;
  api.vkGetPhysicalDeviceProperties(d, &p);
  const bool timed = timestamp_bits(d, compute_family(d)) > 0;
  return {index, p.deviceName, type_name(p.deviceType), timed ? static_cast<double>(p.limits.timestampPeriod) : 0.0};
}

}  // namespace

std::vector<DeviceInfo> list_devices() {
  std::lock_guard lock(api_mutex);
  const auto devices = physical_devices(shared_instance());
  std::vector<DeviceInfo> out;
  for (std::uint32_t i = 0; i < devices.size(); ++i) out.push_back(device_info(devices[i], i));
  return out;
}

// ---------------------------------------------------------------------------- Context

std::shared_ptr<Context> Context::get(const std::string& spec) {
  // One context per device for the whole process, shared by every Vulkan model and never
  // destroyed (see shared_instance()).
  static auto* contexts = new std::map<std::string, std::shared_ptr<Context>>();
  std::lock_guard lock(api_mutex);
  if (auto it = contexts->find(spec); it != contexts->end()) return it->second;
  std::shared_ptr<Context> ctx(new Context());
  ctx->init(spec);
  (*contexts)[spec] = ctx;
  return ctx;
}

void Context::init(const std::string& spec) {
  const auto devices = physical_devices(shared_instance());
  std::vector<VkPhysicalDeviceProperties> props(devices.size());
  for (std::size_t i = 0; i < devices.size(); ++i) api.vkGetPhysicalDeviceProperties(devices[i], &props[i]);

  std::optional<std::size_t> pick;
  if (spec.empty()) {
    for (std::size_t i = 0; i < devices.size() && !pick; ++i)
      if (props[i].deviceType == VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU && compute_family(devices[i]) >= 0) pick = i;
    for (std::size_t i = 0; i < devices.size() && !pick; ++i)
      if (compute_family(devices[i]) >= 0) pick = i;
  } else if (std::all_of(spec.begin(), spec.end(), [](char c) { return std::isdigit(static_cast<unsigned char>(c)); })) {
    const std::size_t i = std::stoul(spec);
    if (i < devices.size()) pick = i;
  } else {
    for (std::size_t i = 0; i < devices.size() && !pick; ++i)
      if (lower(props[i].deviceName).find(lower(spec)) != std::string::npos) pick = i;
  }
  if (!pick || compute_family(devices[*pick]) < 0) {
    std::string have;
    for (std::size_t i = 0; i < devices.size(); ++i)
      have += (i ? ", " : "") + std::to_string(i) + " '" + props[i].deviceName + "'";
    if (spec.empty()) throw Unavailable("Vulkan: no device with a compute queue (have: " + have + ")");
    throw InputError("--device", spec, "no Vulkan device with a compute queue matches (have: " + have + ")");
  }
  physical_ = devices[*pick];
  info_ = device_info(physical_, static_cast<std::uint32_t>(*pick));
  queue_family_ = static_cast<std::uint32_t>(compute_family(physical_));
  const std::uint32_t bits = timestamp_bits(physical_, static_cast<int>(queue_family_));
  if (bits > 0) timestamp_mask_ = bits >= 64 ? ~std::uint64_t{0} : (std::uint64_t{1} << bits) - 1;
  api.vkGetPhysicalDeviceMemoryProperties(physical_, &memory_);

  const float priority = 1.0f;
  VkDeviceQueueCreateInfo queue{VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO};
  queue.queueFamilyIndex = queue_family_;
  queue.queueCount = 1;
  queue.pQueuePriorities = &priority;
  VkDeviceCreateInfo info{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO};
  info.queueCreateInfoCount = 1;
  info.pQueueCreateInfos = &queue;
  check(api.vkCreateDevice(physical_, &info, nullptr, &device_), "vkCreateDevice");
  api.vkGetDeviceQueue(device_, queue_family_, 0, &queue_);

  VkCommandPoolCreateInfo pool{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
  pool.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
  pool.queueFamilyIndex = queue_family_;
  check(api.vkCreateCommandPool(device_, &pool, nullptr, &command_pool_), "vkCreateCommandPool");
}

std::uint32_t Context::memory_type(std::uint32_t allowed, Memory where) const {
  const VkMemoryPropertyFlags host = VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
  const VkMemoryPropertyFlags cached = host | VK_MEMORY_PROPERTY_HOST_CACHED_BIT;
  // Preferences, best first; the last entry of each list always exists for some type.
  // Device memory the host reads through its caches (CPU devices, integrated GPUs) is
  // taken and mapped. A discrete GPU's host-visible device memory (the PCI BAR) is not
  // cached: on an H200, reading tressfx_ponytail_shake's 1.3 MB of guide positions
  // through it takes about 50 ms a frame (25 MB/s), so there plain device memory is taken
  // and read back through a staging copy (Readback).
  std::vector<VkMemoryPropertyFlags> wanted;
  if (where == Memory::Device)
    wanted = {VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT | cached, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT, 0};
  else
    wanted = {cached, host};
  for (VkMemoryPropertyFlags w : wanted)
    for (std::uint32_t i = 0; i < memory_.memoryTypeCount; ++i)
      if ((allowed & (1u << i)) && (memory_.memoryTypes[i].propertyFlags & w) == w) return i;
  throw std::runtime_error("Vulkan: no suitable memory type");
}

Buffer Context::buffer(VkDeviceSize size, Memory where) const {
  Buffer b;
  b.ctx_ = this;
  b.size_ = size;
  VkBufferCreateInfo info{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
  info.size = std::max<VkDeviceSize>(size, 16);
  info.usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT;
  info.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
  check(api.vkCreateBuffer(device_, &info, nullptr, &b.buffer_), "vkCreateBuffer");
  VkMemoryRequirements req;
  api.vkGetBufferMemoryRequirements(device_, b.buffer_, &req);
  VkMemoryAllocateInfo alloc{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
  alloc.allocationSize = req.size;
  alloc.memoryTypeIndex = memory_type(req.memoryTypeBits, where);
  check(api.vkAllocateMemory(device_, &alloc, nullptr, &b.memory_), "vkAllocateMemory");
  check(api.vkBindBufferMemory(device_, b.buffer_, b.memory_, 0), "vkBindBufferMemory");
  const VkMemoryPropertyFlags flags = memory_.memoryTypes[alloc.memoryTypeIndex].propertyFlags;
  const bool readable = where == Memory::Host || (flags & VK_MEMORY_PROPERTY_HOST_CACHED_BIT);
  if ((flags & VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT) && readable && !(where == Memory::Device && staging_only()))
    check(api.vkMapMemory(device_, b.memory_, 0, VK_WHOLE_SIZE, 0, &b.mapped_), "vkMapMemory");
  return b;
}

VkCommandBuffer Context::new_command_buffer() const {
  VkCommandBufferAllocateInfo alloc{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
  alloc.commandPool = command_pool_;
  alloc.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
  alloc.commandBufferCount = 1;
  VkCommandBuffer cmd = VK_NULL_HANDLE;
  check(api.vkAllocateCommandBuffers(device_, &alloc, &cmd), "vkAllocateCommandBuffers");
  return cmd;
}

VkFence Context::new_fence() const {
  VkFenceCreateInfo info{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
  VkFence f = VK_NULL_HANDLE;
  check(api.vkCreateFence(device_, &info, nullptr, &f), "vkCreateFence");
  return f;
}

VkCommandBuffer Context::begin_once() const {
  const VkCommandBuffer cmd = new_command_buffer();
  VkCommandBufferBeginInfo begin{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
  begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
  check(api.vkBeginCommandBuffer(cmd, &begin), "vkBeginCommandBuffer");
  return cmd;
}

void Context::submit_and_wait(VkCommandBuffer cmd, VkFence fence) const {
  check(api.vkResetFences(device_, 1, &fence), "vkResetFences");
  VkSubmitInfo submit{VK_STRUCTURE_TYPE_SUBMIT_INFO};
  submit.commandBufferCount = 1;
  submit.pCommandBuffers = &cmd;
  {
    // The queue is externally synchronized (Vulkan spec, vkQueueSubmit): the runner reads
    // several models' positions at once from the pool's threads, and unserialized
    // submissions can lose the device (they do on an H200).
    const std::lock_guard lock(queue_mutex_);
    check(api.vkQueueSubmit(queue_, 1, &submit, fence), "vkQueueSubmit");
  }
  // Finite, so that a hung device is an error rather than a process that never returns;
  // far above any frame (a frame of Table 1's largest groom takes seconds on lavapipe).
  constexpr std::uint64_t kTimeoutNs = 600'000'000'000;
  const VkResult r = api.vkWaitForFences(device_, 1, &fence, VK_TRUE, kTimeoutNs);
  if (r == VK_TIMEOUT) throw std::runtime_error("Vulkan: the device did not finish a submission within 600 s");
  check(r, "vkWaitForFences");
}

void Context::copy(VkBuffer src, VkBuffer dst, VkDeviceSize bytes) const {
  VkCommandBuffer cmd = begin_once();
  const VkBufferCopy region{0, 0, bytes};
  api.vkCmdCopyBuffer(cmd, src, dst, 1, &region);
  check(api.vkEndCommandBuffer(cmd), "vkEndCommandBuffer");
  const VkFence fence = new_fence();
  submit_and_wait(cmd, fence);
  api.vkDestroyFence(device_, fence, nullptr);
  api.vkFreeCommandBuffers(device_, command_pool_, 1, &cmd);
}

void Context::upload(Buffer& dst, const void* data, std::size_t bytes) const {
  if (bytes == 0) return;
  if (dst.mapped()) {
    std::memcpy(dst.mapped(), data, bytes);
    return;
  }
  Buffer staging = buffer(bytes, Memory::Host);
  std::memcpy(staging.mapped(), data, bytes);
  copy(staging.handle(), dst.handle(), bytes);
}

void Context::copy(const Buffer& src, const Buffer& dst) const {
  if (dst.size() < src.size()) throw std::logic_error("Context::copy: the destination is smaller than the source");
  if (src.size() > 0) copy(src.handle(), dst.handle(), src.size());
}

std::unique_ptr<Readback> Context::readback(const Buffer& src) const {
  std::unique_ptr<Readback> r(new Readback(*this));
  r->size_ = src.size();
  r->mapped_ = src.mapped();
  if (r->mapped_) return r;
  r->staging_ = buffer(src.size(), Memory::Host);
  r->mapped_ = r->staging_.mapped();
  r->cmd_ = new_command_buffer();
  r->fence_ = new_fence();
  // Recorded once, submitted on every fetch. The kernel's closing barrier already makes
  // its writes visible to transfers; this one makes the copy visible to the host.
  VkCommandBufferBeginInfo begin{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
  check(api.vkBeginCommandBuffer(r->cmd_, &begin), "vkBeginCommandBuffer");
  const VkBufferCopy region{0, 0, src.size()};
  api.vkCmdCopyBuffer(r->cmd_, src.handle(), r->staging_.handle(), 1, &region);
  VkMemoryBarrier barrier{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
  barrier.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
  barrier.dstAccessMask = VK_ACCESS_HOST_READ_BIT;
  api.vkCmdPipelineBarrier(r->cmd_, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_HOST_BIT, 0, 1, &barrier, 0,
                           nullptr, 0, nullptr);
  check(api.vkEndCommandBuffer(r->cmd_), "vkEndCommandBuffer");
  return r;
}

bool Context::staging_only() {
  const char* v = std::getenv("HAIRBENCH_VK_STAGING");
  return v && *v && std::string_view(v) != "0";
}

std::unique_ptr<Kernel> Context::kernel(std::span<const std::uint32_t> spirv, std::uint32_t bindings,
                                        std::span<const std::uint32_t> specialization) const {
  std::unique_ptr<Kernel> k(new Kernel(*this));
  k->bindings_ = bindings;
  VkShaderModuleCreateInfo mi{VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO};
  mi.codeSize = spirv.size_bytes();
  mi.pCode = spirv.data();
  check(api.vkCreateShaderModule(device_, &mi, nullptr, &k->module_), "vkCreateShaderModule");

  std::vector<VkDescriptorSetLayoutBinding> b(bindings);
  for (std::uint32_t i = 0; i < bindings; ++i)
    b[i] = {i, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, VK_SHADER_STAGE_COMPUTE_BIT, nullptr};
  VkDescriptorSetLayoutCreateInfo li{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO};
  li.bindingCount = bindings;
  li.pBindings = b.data();
  check(api.vkCreateDescriptorSetLayout(device_, &li, nullptr, &k->set_layout_), "vkCreateDescriptorSetLayout");
  VkPipelineLayoutCreateInfo pli{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
  pli.setLayoutCount = 1;
  pli.pSetLayouts = &k->set_layout_;
  check(api.vkCreatePipelineLayout(device_, &pli, nullptr, &k->layout_), "vkCreatePipelineLayout");

  std::vector<VkSpecializationMapEntry> entries(specialization.size());
  for (std::uint32_t i = 0; i < entries.size(); ++i)
    entries[i] = {i, static_cast<std::uint32_t>(i * sizeof(std::uint32_t)), sizeof(std::uint32_t)};
  VkSpecializationInfo si{static_cast<std::uint32_t>(entries.size()), entries.data(), specialization.size_bytes(),
                          specialization.data()};
  VkComputePipelineCreateInfo ci{VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO};
  ci.stage = {VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO};
  ci.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
  ci.stage.module = k->module_;
  ci.stage.pName = "main";
  ci.stage.pSpecializationInfo = &si;
  ci.layout = k->layout_;
  check(api.vkCreateComputePipelines(device_, VK_NULL_HANDLE, 1, &ci, nullptr, &k->pipeline_),
        "vkCreateComputePipelines");

  const VkDescriptorPoolSize size{VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, bindings};
  VkDescriptorPoolCreateInfo pi{VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO};
  pi.maxSets = 1;
  pi.poolSizeCount = 1;
  pi.pPoolSizes = &size;
  check(api.vkCreateDescriptorPool(device_, &pi, nullptr, &k->pool_), "vkCreateDescriptorPool");
  VkDescriptorSetAllocateInfo ai{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO};
  ai.descriptorPool = k->pool_;
  ai.descriptorSetCount = 1;
  ai.pSetLayouts = &k->set_layout_;
  check(api.vkAllocateDescriptorSets(device_, &ai, &k->set_), "vkAllocateDescriptorSets");
  return k;
}

std::unique_ptr<Commands> Context::commands() const {
  std::unique_ptr<Commands> c(new Commands(*this));
  c->cmd_ = new_command_buffer();
  c->fence_ = new_fence();
  return c;
}

// ----------------------------------------------------------------------------- Buffer

void Buffer::swap(Buffer& o) noexcept {
  std::swap(ctx_, o.ctx_);
  std::swap(buffer_, o.buffer_);
  std::swap(memory_, o.memory_);
  std::swap(size_, o.size_);
  std::swap(mapped_, o.mapped_);
}

Buffer::~Buffer() {
  if (!ctx_) return;
  api.vkDestroyBuffer(ctx_->device_, buffer_, nullptr);
  api.vkFreeMemory(ctx_->device_, memory_, nullptr);  // unmaps implicitly
}

// ----------------------------------------------------------------------------- Kernel

Kernel::~Kernel() {
  const VkDevice d = ctx_.device_;
  api.vkDestroyDescriptorPool(d, pool_, nullptr);
  api.vkDestroyPipeline(d, pipeline_, nullptr);
  api.vkDestroyPipelineLayout(d, layout_, nullptr);
  api.vkDestroyDescriptorSetLayout(d, set_layout_, nullptr);
  api.vkDestroyShaderModule(d, module_, nullptr);
}

void Kernel::bind(std::span<const Buffer* const> buffers) {
  if (buffers.size() != bindings_) throw std::logic_error("Kernel::bind: wrong number of buffers");
  std::vector<VkDescriptorBufferInfo> infos(bindings_);
  std::vector<VkWriteDescriptorSet> writes(bindings_);
  for (std::uint32_t i = 0; i < bindings_; ++i) {
    infos[i] = {buffers[i]->handle(), 0, VK_WHOLE_SIZE};
    writes[i] = {VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
    writes[i].dstSet = set_;
    writes[i].dstBinding = i;
    writes[i].descriptorCount = 1;
    writes[i].descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
    writes[i].pBufferInfo = &infos[i];
  }
  api.vkUpdateDescriptorSets(ctx_.device_, bindings_, writes.data(), 0, nullptr);
}

// ----------------------------------------------------------------------------- Commands

Commands::~Commands() {
  const VkDevice d = ctx_.device_;
  api.vkDestroyQueryPool(d, queries_, nullptr);
  api.vkDestroyFence(d, fence_, nullptr);
  if (cmd_) api.vkFreeCommandBuffers(d, ctx_.command_pool_, 1, &cmd_);
}

void Commands::record(std::span<const Dispatch> dispatches) {
  const auto n = static_cast<std::uint32_t>(dispatches.size());
  if (ctx_.info_.timestamp_period_ns > 0.0 && (!queries_ || n != recorded_)) {
    api.vkDestroyQueryPool(ctx_.device_, queries_, nullptr);
    queries_ = VK_NULL_HANDLE;
    VkQueryPoolCreateInfo qi{VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO};
    qi.queryType = VK_QUERY_TYPE_TIMESTAMP;
    qi.queryCount = n + 1;
    check(api.vkCreateQueryPool(ctx_.device_, &qi, nullptr, &queries_), "vkCreateQueryPool");
  }
  recorded_ = n;
  VkCommandBufferBeginInfo begin{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
  check(api.vkBeginCommandBuffer(cmd_, &begin), "vkBeginCommandBuffer");
  if (queries_) {
    api.vkCmdResetQueryPool(cmd_, queries_, 0, n + 1);
    api.vkCmdWriteTimestamp(cmd_, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, queries_, 0);
  }
  // Host writes to the per-frame buffers are made visible by vkQueueSubmit itself.
  for (std::uint32_t i = 0; i < n; ++i) {
    const Kernel& k = *dispatches[i].kernel;
    api.vkCmdBindPipeline(cmd_, VK_PIPELINE_BIND_POINT_COMPUTE, k.pipeline_);
    api.vkCmdBindDescriptorSets(cmd_, VK_PIPELINE_BIND_POINT_COMPUTE, k.layout_, 0, 1, &k.set_, 0, nullptr);
    api.vkCmdDispatch(cmd_, dispatches[i].groups, 1, 1);
    VkMemoryBarrier barrier{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
    barrier.srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT;
    barrier.dstAccessMask = VK_ACCESS_HOST_READ_BIT | VK_ACCESS_TRANSFER_READ_BIT | VK_ACCESS_SHADER_READ_BIT;
    api.vkCmdPipelineBarrier(cmd_, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT,
                             VK_PIPELINE_STAGE_HOST_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT |
                                 VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT,
                             0, 1, &barrier, 0, nullptr, 0, nullptr);
    // After the barrier: the dispatch has finished when this is written.
    if (queries_) api.vkCmdWriteTimestamp(cmd_, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, queries_, i + 1);
  }
  check(api.vkEndCommandBuffer(cmd_), "vkEndCommandBuffer");
}

void Commands::run() { ctx_.submit_and_wait(cmd_, fence_); }

std::vector<std::uint64_t> Commands::timestamps() const {
  std::vector<std::uint64_t> t(recorded_ + 1);
  check(api.vkGetQueryPoolResults(ctx_.device_, queries_, 0, recorded_ + 1, t.size() * sizeof t[0], t.data(),
                                  sizeof t[0], VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT),
        "vkGetQueryPoolResults");
  return t;
}

namespace {
double ticks_ms(std::uint64_t from, std::uint64_t to, std::uint64_t mask, double period_ns) {
  return static_cast<double>((to - from) & mask) * period_ns * 1e-6;
}
}  // namespace

std::optional<double> Commands::last_ms() const {
  if (!queries_ || recorded_ == 0) return std::nullopt;
  const std::vector<std::uint64_t> t = timestamps();
  return ticks_ms(t.front(), t.back(), ctx_.timestamp_mask_, ctx_.info_.timestamp_period_ns);
}

std::optional<double> Commands::last_ms(std::size_t dispatch) const {
  if (!queries_ || dispatch >= recorded_) return std::nullopt;
  const std::vector<std::uint64_t> t = timestamps();
  return ticks_ms(t[dispatch], t[dispatch + 1], ctx_.timestamp_mask_, ctx_.info_.timestamp_period_ns);
}

// ----------------------------------------------------------------------------- Readback

Readback::~Readback() {
  const VkDevice d = ctx_.device_;
  api.vkDestroyFence(d, fence_, nullptr);
  if (cmd_) api.vkFreeCommandBuffers(d, ctx_.command_pool_, 1, &cmd_);
}

void Readback::fetch(void* data, std::size_t bytes) {
  if (bytes > size_) throw std::logic_error("Readback::fetch: more bytes than the buffer holds");
  if (bytes == 0) return;
  if (cmd_) ctx_.submit_and_wait(cmd_, fence_);
  std::memcpy(data, mapped_, bytes);
}

}  // namespace hairbench::vk
