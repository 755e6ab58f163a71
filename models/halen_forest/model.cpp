#include "models/halen_forest/model.h"

#include "core/parallel.h"

#include <chrono>
#include <cmath>

namespace hairbench::halen_forest {

namespace k = hairbench::kernels;

// PerStrand: one strand in this many times its stages.
constexpr std::size_t kSampleEvery = 16;

ForestModel::ForestModel(Schedule schedule, const ModelContext& ctx) : schedule_(schedule), ctx_(ctx) {}

void ForestModel::reset(const Groom& rest, const ParamSet& params) {
  rest_ = rest;
  axes_ = params.get_int("axis_convention") == 0 ? k::ForestAxes::ParentZ : k::ForestAxes::ParentX;
  substeps_ = params.get_int("substeps");
  joint_damping_.clear();
  collision_stiffness_.clear();
  for (std::size_t r = 0; r < rest.region_names.size(); ++r) {
    joint_damping_.push_back(static_cast<float>(params.get("joint_damping", r)));
    collision_stiffness_.push_back(static_cast<float>(params.get("collision_stiffness", r)));
  }

  const std::size_t nv = rest.vertex_count();
  rest_frame_.assign(nv, k::Mat3f::Identity());
  length_.assign(nv, 0.0f);
  theta0_.assign(nv, 0.0f);
  phi0_.assign(nv, 0.0f);
  k_.assign(nv, 0.0f);
  inv_strand_length_.assign(rest.strand_count(), 0.0f);
  std::vector<float> arc(nv);
  for (std::size_t s = 0; s < rest.strand_count(); ++s) {
    const std::size_t b = rest.strand_begin(s), n = rest.strand_size(s), r = rest.strand_region[s];
    const auto strand_rest = std::span(rest.positions).subspan(b, n);
    k::forest_rest(strand_rest, axes_, std::span(rest_frame_).subspan(b, n), std::span(theta0_).subspan(b, n),
                   std::span(phi0_).subspan(b, n), std::span(length_).subspan(b, n));
    k::arc_lengths(strand_rest, std::span(arc).subspan(b, n));
    inv_strand_length_[s] = 1.0f / arc[b + n - 1];
    const float stiffness = static_cast<float>(params.get("joint_stiffness", r));
    const float c = static_cast<float>(params.get("falloff_scale", r));
    const int a = params.get_int("falloff_exponent", r);
    // The joint of segment i sits at vertex i-1.
    for (std::size_t i = 1; i < n; ++i) k_[b + i] = k::falloff_stiffness(stiffness, arc[b + i - 1], c, a);
  }
  theta_ = theta0_;
  phi_ = phi0_;
  dtheta_.assign(nv, 0.0f);
  dphi_.assign(nv, 0.0f);
  frame_ = rest_frame_;
  joint_torque_.assign(nv, Vec3f::Zero());
  pos_ = rest.positions;
  head_hist_[0] = head_hist_[1] = Affine3f::Identity();
  sleep_.reset(rest.strand_count());
  heads_.assign(static_cast<std::size_t>(substeps_) + 1, Affine3f::Identity());
  forces_.assign(static_cast<std::size_t>(substeps_), k::ForestForces{});
  spheres_.reserve(static_cast<std::size_t>(substeps_) * 16);
  thread_times_.assign(static_cast<std::size_t>(ctx_.pool ? ctx_.pool->threads() : 1), ThreadTimes{});
  pose(Affine3f::Identity());
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

// Visits every awake strand; a sleeping strand is not touched (issue 8).
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

void ForestModel::step(const FrameInput& in, StageTimes& times) {
  const float dt = static_cast<float>(in.dt) / static_cast<float>(substeps_);
  const bool calm = sleep_.begin_step(in, ctx_.skip_inert);
  if (calm && sleep_.all_asleep()) {
    // Every strand sleeps: not even the per-strand checks run (issue 8). The head has
    // been still for kQuietFrames frames, so head_hist_ already holds it.
    for (std::string_view stage : {"pose", "integrate"}) times.skip(stage);
    return;
  }
  if (schedule_ == Schedule::PerStage)
    step_per_stage(in, dt, times);
  else
    step_per_strand(in, dt, times);
  if (calm) {
    StageTimer t(times, "sleep");
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

// The forces of one substep with head pose `head`; advances head_hist_. The colliders go
// to `spheres` (one per collider).
k::ForestForces ForestModel::substep_forces(const FrameInput& in, const Affine3f& head, float dt,
                                            std::span<Vec4f> spheres) {
  k::ForestForces f;
  f.gravity = in.gravity;
  f.wind = in.wind;
  f.head_rotation = head.linear();
  // The acceleration of a point rigid with the head, by central differences of the
  // head transform over the last three substeps: a(p) = (H_s - 2H_{s-1} + H_{s-2}) H_s^-1 p / dt².
  const Eigen::Matrix4f second = head.matrix() - 2.0f * head_hist_[1].matrix() + head_hist_[0].matrix();
  f.inertia = (second * head.inverse(Eigen::Isometry).matrix()).topRows<3>() / (dt * dt);
  head_hist_[0] = head_hist_[1];
  head_hist_[1] = head;
  for (std::size_t c = 0; c < in.colliders.size(); ++c) {
    const Vec3f center = collider_center(in.colliders[c], head);
    spheres[c] = Vec4f(center.x(), center.y(), center.z(), in.colliders[c].radius);
  }
  f.spheres = spheres;
  f.dt = dt;
  return f;
}

k::ForestForces ForestModel::strand_forces(const k::ForestForces& f, std::size_t s) const {
  k::ForestForces fs = f;
  const std::size_t r = rest_.strand_region[s];
  fs.joint_damping = joint_damping_[r];
  fs.collision_stiffness = collision_stiffness_[r];
  fs.inv_inertia_length = inv_strand_length_[s];
  return fs;
}

void ForestModel::step_per_stage(const FrameInput& in, float dt, StageTimes& times) {
  spheres_.resize(in.colliders.size());
  for (int i = 1; i <= substeps_; ++i) {
    const Affine3f head = interpolate_head(in.head_prev, in.head, static_cast<float>(i) / static_cast<float>(substeps_));
    {
      StageTimer t(times, "pose");
      pose(head);
    }
    StageTimer t(times, "integrate");
    const k::ForestForces f = substep_forces(in, head, dt, spheres_);
    for_each_strand([&](std::size_t s) { k::forest_integrate(strand_view(s), axes_, strand_forces(f, s)); });
  }
  StageTimer t(times, "pose");
  pose(in.head);
}

// This thread's share of the strands (a static partition: which thread runs a strand
// never changes a bit of its result), every substep of one strand before the next.
void ForestModel::run_strands(int t) {
  const std::size_t count = rest_.strand_count(), threads = thread_times_.size();
  const std::size_t begin = count * static_cast<std::size_t>(t) / threads;
  const std::size_t end = count * (static_cast<std::size_t>(t) + 1) / threads;
  ThreadTimes& tt = thread_times_[static_cast<std::size_t>(t)];
  using Clock = std::chrono::steady_clock;
  auto ns = [](Clock::time_point a, Clock::time_point b) {
    return std::chrono::duration_cast<std::chrono::nanoseconds>(b - a).count();
  };
  for (std::size_t s = begin; s < end; ++s) {
    if (sleep_.asleep(s)) continue;
    const k::ForestStrand view = strand_view(s);
    if (s % kSampleEvery != 0) {
      for (std::size_t i = 0; i < forces_.size(); ++i) {
        k::forest_pose(view, axes_, heads_[i]);
        k::forest_integrate(view, axes_, strand_forces(forces_[i], s));
      }
      k::forest_pose(view, axes_, heads_.back());
      continue;
    }
    Clock::time_point a = Clock::now();
    const Clock::time_point start = a;
    for (std::size_t i = 0; i < forces_.size(); ++i) {
      k::forest_pose(view, axes_, heads_[i]);
      const Clock::time_point b = Clock::now();
      tt.pose_ns += ns(a, b);
      k::forest_integrate(view, axes_, strand_forces(forces_[i], s));
      a = Clock::now();
      tt.integrate_ns += ns(b, a);
    }
    k::forest_pose(view, axes_, heads_.back());
    const Clock::time_point b = Clock::now();
    tt.pose_ns += ns(a, b);
    tt.sampled_ns += ns(start, b);
  }
}

void ForestModel::step_per_strand(const FrameInput& in, float dt, StageTimes& times) {
  const auto start = std::chrono::steady_clock::now();
  const std::size_t nc = in.colliders.size();
  // Grows only when a scene has more colliders than any before (reserved for 16).
  if (spheres_.size() < nc * forces_.size()) spheres_.resize(nc * forces_.size());
  for (int i = 1; i <= substeps_; ++i) {
    const Affine3f head = interpolate_head(in.head_prev, in.head, static_cast<float>(i) / static_cast<float>(substeps_));
    const std::size_t k = static_cast<std::size_t>(i - 1);
    heads_[k] = head;
    forces_[k] = substep_forces(in, head, dt, std::span(spheres_).subspan(k * nc, nc));
  }
  heads_.back() = in.head;
  for (ThreadTimes& tt : thread_times_) tt = ThreadTimes{};
  ForestModel* self = this;  // one pointer: the std::function stores it without allocating
  if (ctx_.pool)
    ctx_.pool->parallel_for(thread_times_.size(), [self](std::size_t b, std::size_t e) {
      for (std::size_t t = b; t < e; ++t) self->run_strands(static_cast<int>(t));
    });
  else
    run_strands(0);
  // Each stage's share of the sampled strands' time, times the step's wall time.
  const double wall_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  ThreadTimes sum;
  for (const ThreadTimes& tt : thread_times_) {
    sum.pose_ns += tt.pose_ns;
    sum.integrate_ns += tt.integrate_ns;
    sum.sampled_ns += tt.sampled_ns;
  }
  const double scale = sum.sampled_ns > 0 ? wall_ms / static_cast<double>(sum.sampled_ns) : 0.0;
  times.add("pose", scale * static_cast<double>(sum.pose_ns));
  times.add("integrate", scale * static_cast<double>(sum.integrate_ns));
}

std::unique_ptr<HairModel> make(Schedule schedule, const ModelContext& ctx) {
  return std::make_unique<ForestModel>(schedule, ctx);
}

}  // namespace hairbench::halen_forest
