#include "models/halen2007/reference/forest.h"

#include "core/parallel.h"
#include "models/halen2007/forest_settings.h"

#include <algorithm>
#include <cmath>

namespace hairbench::halen_forest {

namespace k = hairbench::kernels;

ForestModel::ForestModel(const ModelContext& ctx) : ctx_(ctx) {}

void ForestModel::reset(const Groom& rest, const ParamSet& params) {
  rest_ = rest;
  const halen_forest::Settings settings = halen_forest::read_settings(params, rest.region_names.size());
  axes_ = settings.parent_z_axes ? k::ForestAxes::ParentZ : k::ForestAxes::ParentX;
  substeps_ = settings.substeps;
  inertia_ = settings.mass_inertia ? k::ForestInertia::Mass : k::ForestInertia::StrandPendulum;
  gravity_compensation_ = settings.gravity_compensation;
  root_angular_acceleration_ = settings.root_angular_acceleration;
  rest_hold_ = inertia_ == k::ForestInertia::StrandPendulum && settings.rest_hold;
  joint_damping_.clear();
  drag_.clear();
  collision_stiffness_.clear();
  collision_damping_.clear();
  for (const halen_forest::RegionSettings& r : settings.regions) {
    joint_damping_.push_back(r.joint_damping);
    drag_.push_back(r.drag);
    collision_stiffness_.push_back(r.collision_stiffness);
    collision_damping_.push_back(r.collision_damping);
  }

  const std::size_t nv = rest.vertex_count();
  rest_frame_.assign(nv, k::Mat3f::Identity());
  length_.assign(nv, 0.0f);
  theta0_.assign(nv, 0.0f);
  phi0_.assign(nv, 0.0f);
  k_.assign(nv, 0.0f);
  inv_strand_length_.assign(rest.strand_count(), 0.0f);
  for (std::size_t s = 0; s < rest.strand_count(); ++s) {
    const std::size_t b = rest.strand_begin(s), n = rest.strand_size(s);
    const halen_forest::RegionSettings& r = settings.regions[rest.strand_region[s]];
    inv_strand_length_[s] = k::forest_setup(
        std::span(rest.positions).subspan(b, n), axes_, r.joint_stiffness, r.falloff_scale, r.falloff_exponent,
        std::span(rest_frame_).subspan(b, n), std::span(theta0_).subspan(b, n), std::span(phi0_).subspan(b, n),
        std::span(length_).subspan(b, n), std::span(k_).subspan(b, n));
  }
  inv_inertia_length_ = inv_strand_length_;
  held_for_ = Vec3f::Constant(std::numeric_limits<float>::quiet_NaN());
  theta_ = theta0_;
  phi_ = phi0_;
  dtheta_.assign(nv, 0.0f);
  dphi_.assign(nv, 0.0f);
  frame_ = rest_frame_;
  joint_torque_.assign(nv, Vec3f::Zero());
  pos_ = rest.positions;
  head_hist_[0] = head_hist_[1] = Affine3f::Identity();
  sleep_.reset(rest.strand_count());
  pose(Affine3f::Identity());
}

bool ForestModel::start_from(std::span<const Vec4f> positions) {
  std::vector<Vec4f> given = rest_.positions;
  start_positions(positions, given);
  std::vector<k::Mat3f> frames(given.size());
  std::vector<float> lengths(given.size());
  for (std::size_t s = 0; s < rest_.strand_count(); ++s) {
    const std::size_t b = rest_.strand_begin(s), n = rest_.strand_size(s);
    k::forest_rest(std::span<const Vec4f>(given).subspan(b, n), axes_, std::span(frames).subspan(b, n),
                   std::span(theta_).subspan(b, n), std::span(phi_).subspan(b, n), std::span(lengths).subspan(b, n));
  }
  std::fill(dtheta_.begin(), dtheta_.end(), 0.0f);
  std::fill(dphi_.begin(), dphi_.end(), 0.0f);
  pose(Affine3f::Identity());
  return true;
}

std::size_t ForestModel::state_bytes() const {
  return rest_.positions.size() * sizeof(Vec4f) + (rest_frame_.size() + frame_.size()) * sizeof(k::Mat3f) +
         (length_.size() + theta0_.size() + phi0_.size() + k_.size() + theta_.size() + phi_.size() + dtheta_.size() +
          dphi_.size()) *
             sizeof(float) +
         joint_torque_.size() * sizeof(Vec3f) + pos_.size() * sizeof(Vec4f);
}

k::ForestStrand ForestModel::strand_view(std::size_t s) {
  const std::size_t b = rest_.strand_begin(s), n = rest_.strand_size(s);
  return {std::span<const Vec4f>(rest_.positions).subspan(b, n),
          std::span<const k::Mat3f>(rest_frame_).subspan(b, n),
          std::span<const float>(length_).subspan(b, n),
          std::span<const float>(theta0_).subspan(b, n),
          std::span<const float>(phi0_).subspan(b, n),
          std::span<const float>(k_).subspan(b, n),
          std::span(theta_).subspan(b, n),
          std::span(phi_).subspan(b, n),
          std::span(dtheta_).subspan(b, n),
          std::span(dphi_).subspan(b, n),
          std::span(frame_).subspan(b, n),
          std::span(joint_torque_).subspan(b, n),
          std::span(pos_).subspan(b, n)};
}

// Visits every awake strand; a sleeping strand is not touched.
template <class F>
void ForestModel::for_each_strand(F&& f) {
  ctx_.pool->parallel_for(rest_.strand_count(), [&](std::size_t begin, std::size_t end) {
    for (std::size_t s = begin; s < end; ++s)
      if (!sleep_.asleep(s)) f(s);
  });
}

void ForestModel::pose(const Affine3f& head) {
  for_each_strand([&](std::size_t s) { k::forest_pose(strand_view(s), axes_, head); });
}

// Gravity reaches the model with the first frame, so the strands' J is raised there, and
// again only if it changes.
void ForestModel::hold_rest(const Vec3f& gravity) {
  held_for_ = gravity;
  if (!rest_hold_) return;
  ctx_.pool->parallel_for(rest_.strand_count(), [&](std::size_t begin, std::size_t end) {
    for (std::size_t s = begin; s < end; ++s) {
      const std::size_t b = rest_.strand_begin(s), n = rest_.strand_size(s);
      inv_inertia_length_[s] =
          inv_strand_length_[s] / k::forest_rest_inertia_scale(std::span<const Vec4f>(rest_.positions).subspan(b, n),
                                                               std::span<const float>(length_).subspan(b, n),
                                                               std::span<const float>(k_).subspan(b, n),
                                                               inv_strand_length_[s], gravity, k::kForestRestMargin);
    }
  });
}

void ForestModel::step(const FrameInput& in, StageTimes& times) {
  if (in.gravity != held_for_) hold_rest(in.gravity);
  const float dt = static_cast<float>(in.dt) / static_cast<float>(substeps_);
  const bool calm = sleep_.begin_step(in, ctx_.skip_inert);
  if (calm && sleep_.all_asleep()) {
    // Every strand sleeps: not even the per-strand checks run. The head has been still
    // for kQuietFrames frames, so head_hist_ already holds it.
    for (Stage stage : {Stage::Pose, Stage::Integrate}) times.skip(stage);
    return;
  }
  for (int i = 1; i <= substeps_; ++i) {
    const Affine3f head = interpolate_head(in.head_prev, in.head, static_cast<float>(i) / static_cast<float>(substeps_));
    {
      StageTimer t(times, Stage::Pose);
      pose(head);
    }
    StageTimer t(times, Stage::Integrate);
    k::ForestForces f;
    f.gravity = in.gravity;
    f.wind = in.wind;
    f.head_rotation = head.linear();
    f.inertia = k::root_inertia(head, head_hist_[1], head_hist_[0], dt);
    f.inertia_model = inertia_;
    f.gravity_compensation = gravity_compensation_;
    if (root_angular_acceleration_)
      f.root_angular_acceleration = k::head_angular_acceleration(head, head_hist_[1], head_hist_[0], dt);
    head_hist_[0] = head_hist_[1];
    head_hist_[1] = head;
    spheres_.clear();
    for (const Sphere& c : in.colliders) {
      const Vec3f center = collider_center(c, head);
      spheres_.emplace_back(center.x(), center.y(), center.z(), c.radius);
    }
    f.spheres = spheres_;
    f.dt = dt;
    for_each_strand([&](std::size_t s) {
      k::ForestForces fs = f;
      const std::size_t r = rest_.strand_region[s];
      fs.joint_damping = joint_damping_[r];
      fs.keep = std::exp(-drag_[r] * dt);
      fs.collision_stiffness = collision_stiffness_[r];
      fs.collision_damping = collision_damping_[r];
      fs.inv_inertia_length = inv_inertia_length_[s];
      k::forest_integrate(strand_view(s), axes_, fs);
    });
  }
  {
    StageTimer t(times, Stage::Pose);
    pose(in.head);
  }
  if (calm) {
    StageTimer t(times, Stage::Sleep);
    // A bound on the fastest vertex: every joint's angular speed acting over the whole
    // strand length (Eq. 4.2.6's angles are the state; positions follow from them).
    for_each_strand([&](std::size_t s) {
      const std::size_t b = rest_.strand_begin(s), n = rest_.strand_size(s);
      float omega = 0.0f;
      for (std::size_t i = b; i < b + n; ++i) omega += std::abs(dtheta_[i]) + std::abs(dphi_[i]);
      sleep_.observe_speed(s, omega / inv_strand_length_[s]);
    });
    sleep_.end_observe();
  }
}

std::unique_ptr<HairModel> make(const ModelContext& ctx) { return std::make_unique<ForestModel>(ctx); }

}  // namespace hairbench::halen_forest
