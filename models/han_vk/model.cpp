#include "models/han_vk/model.h"

#include "core/error.h"
#include "kernels/cpu/strand_kernels.h"
#include "kernels/vulkan/han_layout.h"
#include "kernels/vulkan/shaders.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cstddef>
#include <cstdlib>
#include <cstring>
#include <optional>

namespace hairbench::han_vk {

namespace L = hairbench::vk_layout;

// The std430 layout the shader sees (kernels/vulkan/han_layout.h).
static_assert(sizeof(L::HanStrand) == 16 && sizeof(L::HanRegion) == 32);
static_assert(sizeof(L::HanFrame) == 48 && offsetof(L::HanFrame, substeps) == 32);
static_assert(sizeof(L::HanSubstep) == 80 && offsetof(L::HanSubstep, head_rotation) == 64);
static_assert(sizeof(Vec4f) == 16 && sizeof(L::vec4) == 16);

namespace {

L::vec4 vec4(float x, float y, float z, float w) { return {x, y, z, w}; }
L::vec4 quat(const Quatf& q) { return {q.x(), q.y(), q.z(), q.w()}; }

template <class T>
vk::Buffer device_buffer(const vk::Context& ctx, const std::vector<T>& data) {
  vk::Buffer b = ctx.buffer(data.size() * sizeof(T), vk::Memory::Device);
  ctx.upload(b, data.data(), data.size() * sizeof(T));
  return b;
}

}  // namespace

HanVkModel::HanVkModel(han::Method method, const ModelContext& ctx)
    : method_(method), context_(vk::Context::get(ctx.device)) {}

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
  const std::size_t nv = rest.vertex_count();
  strand_count_ = rest.strand_count();

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
  for (std::size_t r = 0; r < rest.region_names.size(); ++r) {
    // The method is a specialization constant of the one pipeline, so every region
    // runs the model's own method; a region asking for another is refused, not ignored.
    const int method = params.get_int("method", r);
    if (method != 0 && method != static_cast<int>(method_))
      throw InputError("regions." + rest.region_names[r], "method",
                       std::to_string(method) + " differs from this model's method " +
                           std::to_string(static_cast<int>(method_)) +
                           "; per-region methods run on the CPU models only");
    L::HanRegion g{};
    g.damping = static_cast<float>(params.get("damping", r));
    g.global_stiffness = static_cast<float>(params.get("global_stiffness", r));
    g.global_range = static_cast<float>(params.get("global_range", r));
    g.global_ramp = params.get_int("global_ramp", r) != 0 ? 1u : 0u;
    g.local_stiffness = static_cast<float>(params.get("local_stiffness", r));
    g.local_iterations = static_cast<std::uint32_t>(params.get_int("local_iterations", r));
    g.length_iterations = static_cast<std::uint32_t>(params.get_int("length_iterations", r));
    max_iterations_ = std::max({max_iterations_, g.local_iterations, g.length_iterations});
    regions.push_back(g);
  }
  substeps_ = params.get_int("substeps");

  // The kernel and the readback hold buffers by handle: drop them before the buffers.
  kernel_.reset();
  readback_.reset();
  pos_ = device_buffer(ctx, rest.positions);
  prev_ = device_buffer(ctx, rest.positions);
  // Method 2's frames persist across iterations and frames; they start at rest.
  rot_ = method_ == han::Method::Jacobi ? device_buffer(ctx, rot) : ctx.buffer(16, vk::Memory::Device);
  rest_ = device_buffer(ctx, rest.positions);
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
  kernel_->record_dispatch(static_cast<std::uint32_t>((strand_count_ + per_group - 1) / per_group));
  readback_ = ctx.readback(pos_);

  host_pos_ = rest.positions;
  host_current_ = true;
  gpu_ms_.reset();
}

void HanVkModel::step(const FrameInput& in, StageTimes& times) {
  {
    StageTimer t(times, "upload");
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
  {
    StageTimer t(times, "dispatch");
    kernel_->run();
  }
  gpu_ms_ = kernel_->last_ms();
  host_current_ = false;
}

std::span<const Vec4f> HanVkModel::positions() const {
  if (!host_current_) {
    readback_->fetch(host_pos_.data(), host_pos_.size() * sizeof(Vec4f));
    host_current_ = true;
  }
  return host_pos_;
}

std::unique_ptr<HairModel> make_han_vk(han::Method method, const ModelContext& ctx) {
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
