#include "models/halen2007/reference/cascade.h"

#include "core/parallel.h"
#include "kernels/common/strand_kernels.h"
#include "models/halen2007/cascade_settings.h"

#include <algorithm>

namespace hairbench::halen_cascade {

namespace k = hairbench::kernels;

CascadeModel::CascadeModel(const ModelContext& ctx) : ctx_(ctx) {}

void CascadeModel::reset(const Groom& rest, const ParamSet& params) {
  rest_ = rest;
  rest_length_ = rest_edge_lengths(rest);
  pos_ = rest.positions;
  step_.assign(rest.vertex_count(), Vec4f::Zero());
  const halen_cascade::Settings settings = halen_cascade::read_settings(params, rest.region_names.size());
  region_.clear();
  for (const halen_cascade::RegionSettings& r : settings.regions) region_.push_back({r.damping, r.length_iterations});
  substeps_ = settings.substeps;
  sleep_.reset(rest.strand_count());

  frames_ = static_cast<k::CascadeFrames>(settings.frames);
  reactions_ = settings.reactions;
  const std::size_t nv = rest.vertex_count();
  for (auto* v : {&inv_mass_, &k_up_, &k_down_, &lift_, &lever_}) v->resize(nv);
  base_.resize(nv);
  rest_space_.resize(nv);
  up_local_.resize(nv);
  down_local_.resize(nv);
  for (std::size_t s = 0; s < rest.strand_count(); ++s) {
    const halen_cascade::RegionSettings& r = settings.regions[rest.strand_region[s]];
    k::cascade_setup(strand(rest_.positions, s), r.stiffness, r.falloff_scale, r.falloff_exponent, r.down_fraction,
                     frames_, strand(inv_mass_, s),
                     strand(k_up_, s), strand(k_down_, s), strand(lift_, s), strand(base_, s), strand(lever_, s),
                     strand(rest_space_, s), strand(up_local_, s), strand(down_local_, s));
  }
  space_ = rest_space_;
  acc_.assign(nv, Vec3f::Zero());
  twist_.assign(nv, 0.0f);
}

bool CascadeModel::start_from(std::span<const Vec4f> positions) {
  start_positions(positions, pos_);
  std::fill(step_.begin(), step_.end(), Vec4f::Zero());
  return true;
}

std::size_t CascadeModel::state_bytes() const {
  return (rest_.positions.size() + pos_.size() + step_.size()) * sizeof(Vec4f) +
         (rest_length_.size() + k_up_.size() + k_down_.size() + lift_.size() + inv_mass_.size() + lever_.size() +
          twist_.size()) *
             sizeof(float) +
         base_.size() * sizeof(int) + (rest_space_.size() + space_.size()) * sizeof(kernels::Mat3f) +
         (up_local_.size() + down_local_.size() + acc_.size()) * sizeof(Vec3f);
}

template <class T>
std::span<T> CascadeModel::strand(std::vector<T>& v, std::size_t s) {
  return std::span(v).subspan(rest_.strand_begin(s), rest_.strand_size(s));
}

// Visits every awake strand; a sleeping strand is not touched.
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
    for_each_strand([&](std::size_t s, const RegionSettings&) { sleep_.observe_steps(s, strand(step_, s), dt); });
    sleep_.end_observe();
  }
}

// §4.3's four steps: tangent spaces, reference nodes, simulation, correction.
void CascadeModel::substep(const Affine3f& head, const FrameInput& in, float dt, StageTimes& times) {
  const FramePlan plan = plan_frame(in, ctx_);
  const k::Mat3f head_rotation = head.linear();
  const Vec3f head_gravity = head_rotation * in.gravity_at_rest();
  {
    StageTimer t(times, Stage::References);
    for_each_strand([&](std::size_t s, const RegionSettings&) {
      const std::size_t b = rest_.strand_begin(s), n = rest_.strand_size(s);
      k::follow_head_steps(strand(pos_, s), strand(step_, s), std::span<const Vec4f>(rest_.positions).subspan(b, n), head);
      k::tangent_spaces(strand(pos_, s), head_rotation * rest_space_[b], frames_, strand(base_, s), strand(space_, s));
      const k::CascadeStrand cs{strand(inv_mass_, s), strand(k_up_, s),   strand(k_down_, s),   strand(lift_, s),
                                strand(base_, s),     strand(lever_, s),  strand(up_local_, s), strand(down_local_, s)};
      k::cascade_accelerations(strand(pos_, s), strand(space_, s), cs, reactions_, frames_, in.gravity,
                               head_gravity, strand(twist_, s), strand(acc_, s));
    });
  }
  {
    StageTimer t(times, Stage::Integrate);
    for_each_strand([&](std::size_t s, const RegionSettings& r) {
      // Gravity is in the accelerations (cascade_accelerations).
      k::verlet_integrate_steps(strand(pos_, s), strand(step_, s), Vec3f::Zero(), in.wind, plan.wind, r.damping, dt);
      k::add_acceleration(strand(pos_, s), strand(step_, s), strand(acc_, s), dt);
    });
  }
  {
    StageTimer t(times, Stage::Length);
    for_each_strand([&](std::size_t s, const RegionSettings& r) {
      for (int it = 0; it < r.length_iterations; ++it)
        k::edge_length_steps(strand(pos_, s), strand(step_, s), strand(rest_length_, s));
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
    for_each_strand(
        [&](std::size_t s, const RegionSettings&) { k::collide_spheres_steps(strand(pos_, s), strand(step_, s), spheres_); });
  }
}

std::unique_ptr<HairModel> make(const ModelContext& ctx) { return std::make_unique<CascadeModel>(ctx); }

}  // namespace hairbench::halen_cascade
