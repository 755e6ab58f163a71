#include "models/halen2007/reference/spring.h"

#include "core/parallel.h"
#include "kernels/halen2007/reference/halen_kernels.h"
#include "kernels/common/strand_kernels.h"
#include "models/halen2007/spring_settings.h"

namespace hairbench::halen_spring {

namespace k = hairbench::kernels;

SpringModel::SpringModel(const ModelContext& ctx) : ctx_(ctx) {}

void SpringModel::reset(const Groom& rest, const ParamSet& params) {
  rest_ = rest;
  rest_length_ = rest_edge_lengths(rest);
  pos_ = rest.positions;
  prev_ = rest.positions;
  const halen_spring::Settings settings = halen_spring::read_settings(params, rest.region_names.size());
  region_.clear();
  for (const halen_spring::RegionSettings& r : settings.regions)
    region_.push_back({r.damping, r.tilt_min, r.length_iterations});
  substeps_ = settings.substeps;
  sleep_.reset(rest.strand_count());

  k_.resize(rest.vertex_count());
  lift_.resize(rest.vertex_count());
  for (std::size_t s = 0; s < rest.strand_count(); ++s) {
    const std::size_t b = rest.strand_begin(s), n = rest.strand_size(s);
    const halen_spring::RegionSettings& r = settings.regions[rest.strand_region[s]];
    k::spring_setup(std::span(rest.positions).subspan(b, n), r.stiffness, r.falloff_scale, r.falloff_exponent,
                    std::span(k_).subspan(b, n), std::span(lift_).subspan(b, n));
  }
  ref_local_.resize(rest.vertex_count());
  for (std::size_t i = 0; i < rest.vertex_count(); ++i) ref_local_[i] = rest.positions[i].head<3>();
  ref_.assign(rest.vertex_count(), Vec3f::Zero());
}

bool SpringModel::start_from(std::span<const Vec4f> positions) {
  start_positions(positions, pos_);
  prev_ = pos_;
  return true;
}

std::size_t SpringModel::state_bytes() const {
  return (rest_.positions.size() + pos_.size() + prev_.size()) * sizeof(Vec4f) +
         (rest_length_.size() + k_.size() + lift_.size()) * sizeof(float) +
         (ref_local_.size() + ref_.size()) * sizeof(Vec3f);
}

template <class T>
std::span<T> SpringModel::strand(std::vector<T>& v, std::size_t s) {
  return std::span(v).subspan(rest_.strand_begin(s), rest_.strand_size(s));
}

// Visits every awake strand; a sleeping strand is not touched.
template <class F>
void SpringModel::for_each_strand(F&& f) {
  ctx_.pool->parallel_for(rest_.strand_count(), [&](std::size_t begin, std::size_t end) {
    for (std::size_t s = begin; s < end; ++s)
      if (!sleep_.asleep(s)) f(s, region_[rest_.strand_region[s]]);
  });
}

void SpringModel::step(const FrameInput& in, StageTimes& times) {
  const float dt = static_cast<float>(in.dt) / static_cast<float>(substeps_);
  const bool calm = sleep_.begin_step(in, ctx_.skip_inert);
  if (calm && sleep_.all_asleep()) {
    // Every strand sleeps: not even the per-strand checks run.
    for (Stage stage : {Stage::References, Stage::Integrate, Stage::Length, Stage::Collision}) times.skip(stage);
    return;
  }
  for (int i = 1; i <= substeps_; ++i) {
    const float s = static_cast<float>(i) / static_cast<float>(substeps_);
    substep(interpolate_head(in.head_prev, in.head, s), in, dt, times);
  }
  if (calm) {
    StageTimer t(times, Stage::Sleep);
    for_each_strand([&](std::size_t s, const RegionSettings&) { sleep_.observe(s, strand(pos_, s), strand(prev_, s), dt); });
    sleep_.end_observe();
  }
}

void SpringModel::substep(const Affine3f& head, const FrameInput& in, float dt, StageTimes& times) {
  const FramePlan plan = plan_frame(in, ctx_);
  // §4.4: "z is the up vector, z_h the up vector of the head" — up is against gravity.
  const Vec3f up = in.gravity.squaredNorm() > 0.0f ? Vec3f(-in.gravity.normalized()) : Vec3f::UnitY();
  // The head's up: the up of its rest orientation, turned by the head.
  const Vec3f rest_gravity = in.gravity_at_rest();
  const Vec3f rest_up = rest_gravity.squaredNorm() > 0.0f ? Vec3f(-rest_gravity.normalized()) : Vec3f::UnitY();
  const Vec3f head_up = head.linear() * rest_up;
  {
    StageTimer t(times, Stage::References);
    for_each_strand([&](std::size_t s, const RegionSettings&) {
      k::head_references(strand(ref_local_, s), strand(lift_, s), head, in.gravity, strand(ref_, s));
    });
  }
  {
    StageTimer t(times, Stage::Integrate);
    for_each_strand([&](std::size_t s, const RegionSettings& r) {
      const auto rest = std::span<const Vec4f>(rest_.positions).subspan(rest_.strand_begin(s), rest_.strand_size(s));
      k::follow_head(strand(pos_, s), strand(prev_, s), rest, head);
      k::verlet_integrate(strand(pos_, s), strand(prev_, s), in.gravity, in.wind, plan.wind, r.damping, dt);
      k::add_spring_acceleration(strand(pos_, s), strand(prev_, s), strand(ref_, s), strand(k_, s),
                                 k::tilt_factor(up, head_up, r.tilt_min), dt);
    });
  }
  {
    StageTimer t(times, Stage::Length);
    for_each_strand([&](std::size_t s, const RegionSettings& r) {
      for (int it = 0; it < r.length_iterations; ++it) k::edge_length(strand(pos_, s), strand(rest_length_, s));
    });
  }
  if (!plan.collision) {
    times.skip(Stage::Collision);
  } else {
    StageTimer t(times, Stage::Collision);
    spheres_.clear();
    for (const Sphere& c : in.colliders) {
      const Vec3f center = collider_center(c, head);
      spheres_.emplace_back(center.x(), center.y(), center.z(), c.radius);
    }
    for_each_strand([&](std::size_t s, const RegionSettings&) { k::collide_spheres(strand(pos_, s), spheres_); });
  }
}

std::unique_ptr<HairModel> make(const ModelContext& ctx) { return std::make_unique<SpringModel>(ctx); }

}  // namespace hairbench::halen_spring
