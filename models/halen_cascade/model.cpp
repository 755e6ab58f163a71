#include "models/halen_cascade/model.h"

#include "core/parallel.h"
#include "kernels/cpu/strand_kernels.h"

namespace hairbench::halen_cascade {

namespace k = hairbench::kernels;

CascadeModel::CascadeModel(const ModelContext& ctx) : ctx_(ctx) {}

void CascadeModel::reset(const Groom& rest, const ParamSet& params) {
  rest_ = rest;
  rest_length_ = rest_edge_lengths(rest);
  pos_ = rest.positions;
  prev_ = rest.positions;
  region_.clear();
  for (std::size_t r = 0; r < rest.region_names.size(); ++r)
    region_.push_back({static_cast<float>(params.get("damping", r)), params.get_int("length_iterations", r)});
  substeps_ = params.get_int("substeps");
  sleep_.reset(rest.strand_count());

  const std::size_t nv = rest.vertex_count();
  std::vector<float> arc(nv);
  k_up_.assign(nv, 0.0f);
  k_down_.assign(nv, 0.0f);
  rest_space_.assign(nv, k::Mat3f::Identity());
  for (std::size_t s = 0; s < rest.strand_count(); ++s) {
    const std::size_t b = rest.strand_begin(s), n = rest.strand_size(s), r = rest.strand_region[s];
    const auto strand_rest = std::span(rest.positions).subspan(b, n);
    k::arc_lengths(strand_rest, std::span(arc).subspan(b, n));
    const float stiffness = static_cast<float>(params.get("stiffness", r));
    const float c = static_cast<float>(params.get("falloff_scale", r));
    const int a = params.get_int("falloff_exponent", r);
    const float down = static_cast<float>(params.get("down_fraction", r));
    for (std::size_t i = 2; i < n; ++i) {
      k_up_[b + i] = k::falloff_stiffness(stiffness, arc[b + i], c, a);
      // Only nodes with a segment two below them have a downward reference node.
      if (i + 2 < n) k_down_[b + i] = down * k_up_[b + i];
    }
    const Vec3f root_dir = (strand_rest[1].head<3>() - strand_rest[0].head<3>()).normalized();
    k::tangent_spaces(strand_rest, k::root_tangent_space(root_dir), std::span(rest_space_).subspan(b, n));
  }
  space_ = rest_space_;
  // §4.3: the reference nodes are the rest positions of the nodes in the tangent spaces
  // of the rest shape, displaced upward so that their springs carry the node's weight:
  // L = mg/k, and with an upward and a downward node both by mg/(k_up + k_down) ("half
  // the distance" when the two are equally strong). The displacement is along world up,
  // so the head-transformed rest shape is in equilibrium in any head pose.
  up_local_.assign(nv, Vec3f::Zero());
  down_local_.assign(nv, Vec3f::Zero());
  lift_.assign(nv, 0.0f);
  for (std::size_t s = 0; s < rest.strand_count(); ++s) {
    const std::size_t b = rest.strand_begin(s), n = rest.strand_size(s);
    auto p = [&](std::size_t i) -> Vec3f { return rest.positions[b + i].head<3>(); };
    for (std::size_t i = 2; i < n; ++i) {
      const float ksum = k_up_[b + i] + k_down_[b + i];
      lift_[b + i] = ksum > 0.0f ? 1.0f / ksum : 0.0f;
      up_local_[b + i] = rest_space_[b + i - 1].transpose() * (p(i) - p(i - 1));
      if (i + 2 < n) down_local_[b + i] = rest_space_[b + i + 2].transpose() * (p(i) - p(i + 2));
    }
  }
  up_ref_.assign(nv, Vec3f::Zero());
  down_ref_.assign(nv, Vec3f::Zero());
}

template <class T>
std::span<T> CascadeModel::strand(std::vector<T>& v, std::size_t s) {
  return std::span(v).subspan(rest_.strand_begin(s), rest_.strand_size(s));
}

// Visits every awake strand; a sleeping strand is not touched (issue 8).
template <class F>
void CascadeModel::for_each_strand(F&& f) {
  ctx_.pool->parallel_for(rest_.strand_count(), [&](std::size_t begin, std::size_t end) {
    for (std::size_t s = begin; s < end; ++s)
      if (!sleep_.asleep(s)) f(s, region_[rest_.strand_region[s]]);
  });
}

void CascadeModel::step(const FrameInput& in, StageTimes& times) {
  const float dt = static_cast<float>(in.dt) / static_cast<float>(substeps_);
  const bool calm = sleep_.begin_step(in, ctx_.skip_inert);
  if (calm && sleep_.all_asleep()) {
    // Every strand sleeps: not even the per-strand checks run (issue 8).
    for (std::string_view stage : {"references", "integrate", "length", "collision"}) times.skip(stage);
    return;
  }
  for (int i = 1; i <= substeps_; ++i) {
    const float s = static_cast<float>(i) / static_cast<float>(substeps_);
    substep(interpolate_head(in.head_prev, in.head, s), in, dt, times);
  }
  if (calm) {
    StageTimer t(times, "sleep");
    for_each_strand([&](std::size_t s, const RegionSettings&) { sleep_.observe(s, strand(pos_, s), strand(prev_, s), dt); });
    sleep_.end_observe();
  }
}

// §4.3's four steps: tangent spaces, reference nodes, simulation, correction.
void CascadeModel::substep(const Affine3f& head, const FrameInput& in, float dt, StageTimes& times) {
  const FramePlan plan = plan_frame(in, ctx_);
  const k::Mat3f head_rotation = head.linear();
  {
    StageTimer t(times, "references");
    for_each_strand([&](std::size_t s, const RegionSettings&) {
      const std::size_t b = rest_.strand_begin(s), n = rest_.strand_size(s);
      k::follow_head(strand(pos_, s), strand(prev_, s), std::span<const Vec4f>(rest_.positions).subspan(b, n), head);
      k::tangent_spaces(strand(pos_, s), head_rotation * rest_space_[b + 1], strand(space_, s));
      k::cascade_references(strand(pos_, s), strand(space_, s), strand(up_local_, s), strand(down_local_, s),
                            strand(lift_, s), in.gravity, strand(up_ref_, s), strand(down_ref_, s));
    });
  }
  {
    StageTimer t(times, "integrate");
    for_each_strand([&](std::size_t s, const RegionSettings& r) {
      const std::size_t n = rest_.strand_size(s);
      k::verlet_integrate(strand(pos_, s), strand(prev_, s), in.gravity, in.wind, plan.wind, r.damping, dt);
      k::add_spring_acceleration(strand(pos_, s), strand(prev_, s), strand(up_ref_, s), strand(k_up_, s), 1.0f, dt);
      if (n > 2)
        k::add_spring_acceleration(strand(pos_, s).first(n - 2), strand(prev_, s).first(n - 2),
                                   strand(down_ref_, s).first(n - 2), strand(k_down_, s).first(n - 2), 1.0f, dt);
    });
  }
  {
    StageTimer t(times, "length");
    for_each_strand([&](std::size_t s, const RegionSettings& r) {
      for (int it = 0; it < r.length_iterations; ++it) k::edge_length(strand(pos_, s), strand(rest_length_, s));
    });
  }
  if (!plan.collision) {
    times.skip("collision");
  } else {
    StageTimer t(times, "collision");
    spheres_.clear();
    for (const Sphere& c : in.colliders) {
      const Vec3f center = collider_center(c, head);
      spheres_.emplace_back(center.x(), center.y(), center.z(), c.radius);
    }
    for_each_strand([&](std::size_t s, const RegionSettings&) { k::collide_spheres(strand(pos_, s), spheres_); });
  }
}

std::unique_ptr<HairModel> make(const ModelContext& ctx) { return std::make_unique<CascadeModel>(ctx); }

}  // namespace hairbench::halen_cascade
