#include "models/han2012/vulkan/han_vulkan.h"

#include "models/han2012/settings.h"

#include "core/error.h"
#include "kernels/common/strand_kernels.h"
#include "kernels/han2012/reference/han_kernels.h"
#include "kernels/han2012/vulkan/han_layout.h"
#include "kernels/vulkan/shaders.h"

#include <algorithm>
#include <array>
#include <bit>
#include <chrono>
#include <cstddef>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <optional>
#include <stdexcept>

namespace hairbench::han_vk {

namespace L = hairbench::vk_layout;

// The std430 layout the shader sees (kernels/han2012/vulkan/han_layout.h).
static_assert(sizeof(L::HanStrand) == 16 && sizeof(L::HanRegion) == 32 && sizeof(L::HanFollowStrand) == 16);
static_assert(sizeof(L::HanFollowVertex) == 16 && offsetof(L::HanFollowVertex, strand) == 12);
static_assert(sizeof(L::HanFrame) == 48 && offsetof(L::HanFrame, substeps) == 32);
static_assert(sizeof(L::HanSubstep) == 80 && offsetof(L::HanSubstep, head_rotation) == 64);
static_assert(sizeof(Vec4f) == 16 && sizeof(L::vec4) == 16);

namespace {

L::vec4 vec4(float x, float y, float z, float w) { return {x, y, z, w}; }
L::vec4 quat(const Quatf& q) { return {q.x(), q.y(), q.z(), q.w()}; }

template <class T>
vk::Buffer device_buffer(const vk::Context& ctx, std::span<const T> data) {
  vk::Buffer b = ctx.buffer(data.size_bytes(), vk::Memory::Device);
  ctx.upload(b, data.data(), data.size_bytes());
  return b;
}

template <class T>
vk::Buffer device_buffer(const vk::Context& ctx, const std::vector<T>& data) {
  return device_buffer(ctx, std::span<const T>(data));
}

}  // namespace

HanVkModel::HanVkModel(han::Method method, const ModelContext& ctx)
    : method_(method), context_(vk::Context::get(ctx.device)) {}

// What the follow kernel indexes with is checked here (as apply_follow_hairs checks its
// layout), so that no layout can make it read or write out of bounds.
bool HanVkModel::set_follow_hairs(const FollowHairsView& f) {
  const auto fail = [](const char* what) { throw std::invalid_argument(std::string("set_follow_hairs: ") + what); };
  if (f.guide_offsets.empty() || f.guide_offsets.front() != 0) fail("guide offsets must start at 0");
  for (std::size_t g = 1; g < f.guide_offsets.size(); ++g)
    if (f.guide_offsets[g] < f.guide_offsets[g - 1]) fail("guide offsets decrease");
  const std::size_t guides = f.guide_offsets.size() - 1;
  const std::uint32_t guide_vertices = f.guide_offsets.back();
  if (f.anchor.size() != f.guide.size() || f.follow_offsets.size() != f.guide.size() + 1 ||
      f.follow_offsets.front() != 0 || f.follow_offsets.back() != f.offsets.size())
    fail("inconsistent follow strand arrays");
  if (f.offsets.size() > std::numeric_limits<std::uint32_t>::max() - guide_vertices)
    fail("guides and follow hairs together exceed 2^32 vertices");
  std::vector<L::HanFollowStrand> strands(f.guide.size());
  std::vector<L::HanFollowVertex> vertices(f.offsets.size());
  for (std::size_t s = 0; s < f.guide.size(); ++s) {
    if (f.guide[s] >= guides || f.anchor[s] >= guide_vertices) fail("guide or anchor out of range");
    const std::uint32_t begin = f.guide_offsets[f.guide[s]], n = f.guide_offsets[f.guide[s] + 1] - begin;
    if (n < 2) fail("a guide has fewer than 2 vertices");
    if (f.follow_offsets[s] > f.follow_offsets[s + 1] || f.follow_offsets[s + 1] - f.follow_offsets[s] != n)
      fail("a follow strand's vertex count differs from its guide's");
    strands[s] = {begin, n, f.anchor[s], f.follow_offsets[s]};
    for (std::uint32_t v = f.follow_offsets[s]; v < f.follow_offsets[s + 1]; ++v)
      vertices[v] = {{f.offsets[v].x(), f.offsets[v].y(), f.offsets[v].z()}, static_cast<std::uint32_t>(s)};
  }
  follow_guide_offsets_.assign(f.guide_offsets.begin(), f.guide_offsets.end());
  follow_strands_host_ = std::move(strands);
  follow_vertices_host_ = std::move(vertices);
  return true;
}

namespace {

// Invocations per strand (a power of two). Methods 2 and 3 spread a strand's vertices over
// as many invocations as the group allows, one each where it can: their batches run in
// parallel along the strand. Method 1's local shape step is one serial walk per strand
// (Algorithm 3) by one invocation: with half as many invocations per strand, a workgroup
// holds twice the walkers. That pays where the strands are long enough for the walk to
// dominate and the groom fills the GPU with workgroups even so (on an H200: Table 1's
// grooms and the TressFX ponytail and mohawk, but not `shake`'s 2,000 strands, 250
// workgroups at half, nor TestHair1's 4-vertex strands; HAIRBENCH_VK_LANES overrides the
// choice for such sweeps). Methods 2 and 3 are fastest at their default on every groom of
// BM_HanVk.
constexpr std::size_t kMethod1MinVertices = 8;
constexpr std::size_t kMethod1MinGroups = 512;

// Whether `lanes` invocations per strand hold the longest strand (each owns at most
// HAN_VK_VERTICES_PER_LANE vertices).
bool lanes_hold(std::size_t lanes, std::size_t longest) {
  return (longest + lanes - 1) / lanes <= HAN_VK_VERTICES_PER_LANE;
}

std::uint32_t choose_lanes(han::Method method, std::size_t longest, std::size_t strands) {
  const auto widest = static_cast<std::uint32_t>(std::min<std::size_t>(HAN_VK_GROUP_SIZE, std::bit_ceil(longest)));
  if (method != han::Method::Serial || longest < kMethod1MinVertices) return widest;
  const std::uint32_t half = widest / 2;
  const bool fills = (strands * half + HAN_VK_GROUP_SIZE - 1) / HAN_VK_GROUP_SIZE >= kMethod1MinGroups;
  return lanes_hold(half, longest) && fills ? half : widest;
}

// HAIRBENCH_VK_LANES, a tuning override (README, Vulkan backend): any choice gives the same
// bits. Null when unset; a value the groom cannot take is a one-line error.
std::optional<std::uint32_t> lanes_override(std::size_t longest) {
  const char* v = std::getenv("HAIRBENCH_VK_LANES");
  if (!v || !*v) return std::nullopt;
  char* end = nullptr;
  const long want = std::strtol(v, &end, 10);
  if (*end == '\0' && want >= 1 && want <= HAN_VK_GROUP_SIZE &&
      std::has_single_bit(static_cast<unsigned long>(want)) && lanes_hold(static_cast<std::size_t>(want), longest))
    return static_cast<std::uint32_t>(want);
  const std::size_t fewest = std::bit_ceil((longest + HAN_VK_VERTICES_PER_LANE - 1) / HAN_VK_VERTICES_PER_LANE);
  throw InputError("HAIRBENCH_VK_LANES", v,
                   "must be a power of two from " + std::to_string(fewest) + " to " +
                       std::to_string(HAN_VK_GROUP_SIZE) + " for this groom (longest strand " +
                       std::to_string(longest) + " vertices, at most " + std::to_string(HAN_VK_VERTICES_PER_LANE) +
                       " per invocation)");
}

}  // namespace

void HanVkModel::reset(const Groom& rest, const ParamSet& params) {
  const vk::Context& ctx = *context_;
  // With follow hairs the groom is the guides, then the follow strands: only the guides
  // are simulated (strand_count_ strands, nv vertices).
  const bool follow = !follow_guide_offsets_.empty();
  if (follow && (rest.strand_offsets.size() < follow_guide_offsets_.size() ||
                 !std::equal(follow_guide_offsets_.begin(), follow_guide_offsets_.end(), rest.strand_offsets.begin()) ||
                 rest.vertex_count() != follow_guide_offsets_.back() + follow_vertices_host_.size()))
    throw std::logic_error("HanVkModel: the rest groom is not the guides expanded by the follow hairs");
  const std::size_t nv = follow ? follow_guide_offsets_.back() : rest.vertex_count();
  strand_count_ = follow ? follow_guide_offsets_.size() - 1 : rest.strand_count();

  std::uint32_t longest = 0;
  std::vector<L::HanStrand> strands(strand_count_);
  for (std::size_t s = 0; s < strand_count_; ++s) {
    const std::uint32_t n = rest.strand_size(s);
    if (n > HAN_VK_MAX_STRAND_VERTICES)
      throw InputError("groom", "strand " + std::to_string(s),
                       std::to_string(n) + " vertices; the Vulkan models keep a strand in one workgroup's shared "
                       "memory, at most " + std::to_string(HAN_VK_MAX_STRAND_VERTICES) + " vertices (" +
                       std::to_string(HAN_VK_GROUP_SIZE) + " invocations x " +
                       std::to_string(HAN_VK_VERTICES_PER_LANE) + ")");
    longest = std::max(longest, n);
  }
  lanes_ = lanes_override(longest).value_or(choose_lanes(method_, longest, strand_count_));

  // Rest frames and lengths exactly as the CPU model computes them (Algorithm 2), and
  // each strand's length under which a rest edge is rounding-sized (method 2 takes the
  // frame across such an edge from the rest state, kernels::local_shape_m2).
  const std::vector<float> rest_length = rest_edge_lengths(rest);
  std::vector<Quatf> rest_rotation(nv, Quatf::Identity());
  std::vector<Vec3f> rest_local(nv, Vec3f::Zero());
  for (std::size_t s = 0; s < strand_count_; ++s) {
    const std::size_t b = rest.strand_begin(s), n = rest.strand_size(s);
    kernels::init_rest_frames(std::span(rest.positions).subspan(b, n), std::span(rest_rotation).subspan(b, n),
                              std::span(rest_local).subspan(b, n));
    strands[s] = {rest.strand_begin(s), rest.strand_size(s), rest.strand_region[s],
                  kernels::rounding_sized_length(std::span(rest_length).subspan(b, n))};
  }
  std::vector<L::vec4> local(nv), rot(nv);
  for (std::size_t i = 0; i < nv; ++i) {
    local[i] = vec4(rest_local[i].x(), rest_local[i].y(), rest_local[i].z(), rest_length[i]);
    rot[i] = quat(rest_rotation[i]);
  }

  std::vector<L::HanRegion> regions;
  max_iterations_ = 0;
  const han::Settings settings = han::read_settings(params, rest.region_names.size());
  for (std::size_t r = 0; r < settings.regions.size(); ++r) {
    const han::RegionSettings& given = settings.regions[r];
    // The method is a specialization constant of the one pipeline, so every region
    // runs the model's own method; a region asking for another is refused, not ignored.
    if (given.method != 0 && given.method != static_cast<int>(method_))
      throw InputError("regions." + rest.region_names[r], "method",
                       std::to_string(given.method) + " differs from this model's method " +
                           std::to_string(static_cast<int>(method_)) +
                           "; per-region methods run on the CPU models only");
    L::HanRegion g{};
    g.damping = given.damping;
    g.global_stiffness = given.global_stiffness;
    g.global_range = given.global_range;
    g.global_ramp = given.global_ramp ? 1u : 0u;
    g.local_stiffness = given.local_stiffness;
    g.local_iterations = static_cast<std::uint32_t>(given.local_iterations);
    g.length_iterations = static_cast<std::uint32_t>(given.length_iterations);
    max_iterations_ = std::max({max_iterations_, g.local_iterations, g.length_iterations});
    regions.push_back(g);
  }
  substeps_ = settings.substeps;

  // The kernels and the readback hold buffers by handle: drop them before the buffers.
  metrics_.reset();
  commands_.reset();
  kernel_.reset();
  follow_kernel_.reset();
  readback_.reset();
  const std::span<const Vec4f> guides = std::span(rest.positions).first(nv);
  pos_ = device_buffer(ctx, rest.positions);
  prev_ = device_buffer(ctx, guides);
  // Method 2's frames persist across iterations and frames; they start at rest.
  rot_ = method_ == han::Method::Jacobi ? device_buffer(ctx, rot) : ctx.buffer(16, vk::Memory::Device);
  rest_ = device_buffer(ctx, guides);
  rest_local_ = device_buffer(ctx, local);
  rest_rot_ = device_buffer(ctx, rot);
  strands_ = device_buffer(ctx, strands);
  regions_ = device_buffer(ctx, regions);
  frame_ = ctx.buffer(sizeof(L::HanFrame) + HAN_VK_MAX_SUBSTEPS * sizeof(L::HanSubstep), vk::Memory::Host);
  spheres_ = ctx.buffer(HAN_VK_MAX_SUBSTEPS * HAN_VK_MAX_COLLIDERS * sizeof(L::vec4), vk::Memory::Host);

  const std::uint32_t per_lane = (longest + lanes_ - 1) / lanes_;
  const std::array<std::uint32_t, 3> spec{lanes_, static_cast<std::uint32_t>(method_), per_lane};
  kernel_ = ctx.kernel(vk::han_step_spirv(), HAN_VK_BINDINGS, spec);
  const std::array<const vk::Buffer*, HAN_VK_BINDINGS> bound{&pos_,        &prev_,     &rot_,     &rest_,
                                                            &rest_local_, &rest_rot_, &strands_, &regions_,
                                                            &frame_,      &spheres_};
  kernel_->bind(bound);
  const std::uint32_t per_group = HAN_VK_GROUP_SIZE / lanes_;
  std::vector<vk::Dispatch> dispatches{
      {kernel_.get(), static_cast<std::uint32_t>((strand_count_ + per_group - 1) / per_group)}};
  if (follow && !follow_vertices_host_.empty()) {
    follow_strands_ = device_buffer(ctx, follow_strands_host_);
    follow_vertices_ = device_buffer(ctx, follow_vertices_host_);
    const auto follow_vertices = static_cast<std::uint32_t>(follow_vertices_host_.size());
    const std::array<std::uint32_t, 2> follow_spec{static_cast<std::uint32_t>(nv), follow_vertices};
    follow_kernel_ = ctx.kernel(vk::follow_hairs_spirv(), HAN_VK_FOLLOW_BINDINGS, follow_spec);
    const std::array<const vk::Buffer*, HAN_VK_FOLLOW_BINDINGS> follow_bound{&pos_, &follow_strands_,
                                                                             &follow_vertices_};
    follow_kernel_->bind(follow_bound);
    dispatches.push_back({follow_kernel_.get(), (follow_vertices + HAN_VK_GROUP_SIZE - 1) / HAN_VK_GROUP_SIZE});
  }
  commands_ = ctx.commands();
  commands_->record(dispatches);
  readback_ = ctx.readback(pos_);
  metrics_ = std::make_unique<vk::MetricsKernel>(context_, pos_, rest.vertex_count());

  host_pos_ = rest.positions;
  host_current_ = true;
  gpu_ms_.reset();
  follow_gpu_ms_.reset();
}

bool HanVkModel::start_from(std::span<const Vec4f> positions) {
  if (follow_kernel_) return false;
  start_positions(positions, host_pos_);  // host_pos_ is reset()'s groom, w included
  context_->upload(pos_, host_pos_.data(), host_pos_.size() * sizeof(Vec4f));
  context_->upload(prev_, host_pos_.data(), host_pos_.size() * sizeof(Vec4f));
  return true;
}

void HanVkModel::upload_frame(const FrameInput& in) {
  if (in.colliders.size() > HAN_VK_MAX_COLLIDERS)
    throw InputError("colliders", std::to_string(in.colliders.size()),
                     "the Vulkan models take at most " + std::to_string(HAN_VK_MAX_COLLIDERS) + " spheres");
  auto* bytes = static_cast<std::byte*>(frame_.mapped());
  L::HanFrame f{};
  const float dt = static_cast<float>(in.dt) / static_cast<float>(substeps_);
  f.gravity_dt = vec4(in.gravity.x(), in.gravity.y(), in.gravity.z(), dt);
  const Vec3f wind = in.wind.acceleration();
  f.wind = vec4(wind.x(), wind.y(), wind.z(), in.wind.active() ? 1.0f : 0.0f);
  f.substeps = static_cast<std::uint32_t>(substeps_);
  f.colliders = static_cast<std::uint32_t>(in.colliders.size());
  f.strands = static_cast<std::uint32_t>(strand_count_);
  f.max_iterations = max_iterations_;
  std::memcpy(bytes, &f, sizeof f);
  auto* sub = reinterpret_cast<L::HanSubstep*>(bytes + sizeof f);
  auto* spheres = static_cast<L::vec4*>(spheres_.mapped());
  // The head at the end of each substep, interpolated as the CPU model does.
  for (int k = 1; k <= substeps_; ++k) {
    const Affine3f head = interpolate_head(in.head_prev, in.head, static_cast<float>(k) / static_cast<float>(substeps_));
    L::HanSubstep& h = sub[k - 1];
    std::memcpy(h.head.m, head.matrix().data(), sizeof h.head.m);
    h.head_rotation = quat(Quatf(head.rotation()));
    for (std::size_t c = 0; c < in.colliders.size(); ++c) {
      const Vec3f centre = collider_center(in.colliders[c], head);
      spheres[(k - 1) * in.colliders.size() + c] = vec4(centre.x(), centre.y(), centre.z(), in.colliders[c].radius);
    }
  }
}

void HanVkModel::step(const FrameInput& in, StageTimes& times) {
  {
    StageTimer t(times, Stage::Upload);
    upload_frame(in);
  }
  {
    StageTimer t(times, Stage::Dispatch);
    commands_->run();
  }
  gpu_ms_ = commands_->last_ms();
  if (follow_kernel_) follow_gpu_ms_ = commands_->last_ms(1);
  host_current_ = false;
}

// The device's first runs of a pipeline can be slow (compilation, cold caches) and an
// idle GPU runs at a low clock until work keeps it busy (docs/vulkan.md, Timing).
void HanVkModel::warm_up(const FrameInput& in, double seconds) {
  const vk::Context& ctx = *context_;
  // What a step changes, kept aside on the device.
  const vk::Buffer pos = ctx.buffer(pos_.size(), vk::Memory::Device);
  const vk::Buffer prev = ctx.buffer(prev_.size(), vk::Memory::Device);
  const vk::Buffer rot = ctx.buffer(rot_.size(), vk::Memory::Device);
  ctx.copy(pos_, pos);
  ctx.copy(prev_, prev);
  ctx.copy(rot_, rot);
  upload_frame(in);
  const auto start = std::chrono::steady_clock::now();
  for (int runs = 0; runs < 2 || std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() < seconds;
       ++runs)
    commands_->run();
  ctx.copy(pos, pos_);
  ctx.copy(prev, prev_);
  ctx.copy(rot, rot_);
}

std::span<const Vec4f> HanVkModel::positions() const {
  if (!host_current_) {
    readback_->fetch(host_pos_.data(), host_pos_.size() * sizeof(Vec4f));
    host_current_ = true;
  }
  return host_pos_;
}

std::unique_ptr<HairModel> make(han::Method method, const ModelContext& ctx) {
  return std::make_unique<HanVkModel>(method, ctx);
}

std::string unavailable(const ModelContext& ctx) {
  try {
    vk::Context::get(ctx.device);
    return "";
  } catch (const vk::Unavailable& e) {
    return e.what();
  }
}

}  // namespace hairbench::han_vk
