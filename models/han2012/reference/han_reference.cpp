#include "models/han2012/reference/han_reference.h"

#include "core/parallel.h"
#include "kernels/common/strand_kernels.h"
#include "kernels/han2012/reference/han_kernels.h"
#include "models/han2012/settings.h"

#include <algorithm>

namespace hairbench::han {

namespace k = hairbench::kernels;

HanModel::HanModel(Method method, const ModelContext& ctx) : method_(method), ctx_(ctx) {}

void HanModel::reset(const Groom& rest, const ParamSet& params) {
  rest_ = rest;
  rest_length_ = rest_edge_lengths(rest);
  pos_ = rest.positions;
  prev_ = rest.positions;
  rest_rotation_.assign(rest.vertex_count(), Quatf::Identity());
  rest_local_.assign(rest.vertex_count(), Vec3f::Zero());
  rounding_sized_.assign(rest.vertex_count(), 0);
  rest_relative_.assign(rest.vertex_count(), Quatf::Identity());
  for (std::size_t s = 0; s < rest.strand_count(); ++s) {
    const std::size_t b = rest.strand_begin(s), n = rest.strand_size(s);
    k::init_rest_frames(std::span(rest.positions).subspan(b, n),
                        std::span(rest_rotation_).subspan(b, n), std::span(rest_local_).subspan(b, n));
    k::init_rounding_sized_frames(std::span<const float>(rest_length_).subspan(b, n),
                                  std::span<const Vec3f>(rest_local_).subspan(b, n),
                                  std::span(rounding_sized_).subspan(b, n), std::span(rest_relative_).subspan(b, n));
  }
  rotation_ = rest_rotation_;
  scratch_ = rest_rotation_;

  region_.clear();
  max_iterations_ = 0;
  any_global_pass_ = any_local_pass_ = false;
  const Settings settings = read_settings(params, rest.region_names.size());
  for (const han::RegionSettings& given : settings.regions) {
    // A pass whose stiffness or reach is 0 changes nothing, so it is not run.
    const RegionSettings rs{given, given.method == 0 ? method_ : static_cast<Method>(given.method),
                            !ctx_.skip_inert || (given.global_stiffness != 0.0f && given.global_range != 0.0f),
                            given.local_iterations > 0 && (!ctx_.skip_inert || given.local_stiffness != 0.0f)};
    any_global_pass_ = any_global_pass_ || rs.global_pass;
    any_local_pass_ = any_local_pass_ || rs.local_pass;
    max_iterations_ = std::max({max_iterations_, rs.local_iterations, rs.length_iterations});
    region_.push_back(rs);
  }
  substeps_ = settings.substeps;
  sleep_.reset(rest.strand_count());
}

std::span<Vec4f> HanModel::strand(std::vector<Vec4f>& v, std::size_t s) {
  return std::span(v).subspan(rest_.strand_begin(s), rest_.strand_size(s));
}

// Visits every awake strand; a sleeping strand is not touched by any stage.
template <class F>
void HanModel::for_each_strand(F&& f) {
  ctx_.pool->parallel_for(rest_.strand_count(), [&](std::size_t begin, std::size_t end) {
    for (std::size_t s = begin; s < end; ++s)
      if (!sleep_.asleep(s)) f(s, region_[rest_.strand_region[s]]);
  });
}

bool HanModel::start_from(std::span<const Vec4f> positions) {
  start_positions(positions, pos_);
  prev_ = pos_;
  return true;
}

void HanModel::step(const FrameInput& in, StageTimes& times) {
  const float dt = static_cast<float>(in.dt) / static_cast<float>(substeps_);
  const bool calm = sleep_.begin_step(in, ctx_.skip_inert);
  if (calm && sleep_.all_asleep()) {
    // Every strand sleeps: not even the per-strand checks run.
    for (Stage stage : {Stage::Integrate, Stage::GlobalShape, Stage::LocalShape, Stage::Length, Stage::Collision}) times.skip(stage);
    return;
  }
  const FramePlan plan = plan_frame(in, ctx_);
  for (int k = 1; k <= substeps_; ++k) {
    const float s = static_cast<float>(k) / static_cast<float>(substeps_);
    substep(interpolate_head(in.head_prev, in.head, s), in, plan, dt, times);
  }
  if (calm) {
    StageTimer t(times, Stage::Sleep);
    for_each_strand([&](std::size_t s, const RegionSettings&) { sleep_.observe(s, strand(pos_, s), strand(prev_, s), dt); });
    sleep_.end_observe();
  }
}

// One pass of Algorithm 1.
void HanModel::substep(const Affine3f& head, const FrameInput& in, const FramePlan& plan, float dt,
                       StageTimes& times) {
  const Quatf head_rotation(head.rotation());
  {
    StageTimer t(times, Stage::Integrate);
    for_each_strand([&](std::size_t s, const RegionSettings& r) {
      k::follow_head(strand(pos_, s), strand(prev_, s),
                     std::span<const Vec4f>(rest_.positions).subspan(rest_.strand_begin(s), rest_.strand_size(s)),
                     head);
      k::verlet_integrate(strand(pos_, s), strand(prev_, s), in.gravity, in.wind, plan.wind, r.damping, dt);
    });
  }
  if (!any_global_pass_) {
    times.skip(Stage::GlobalShape);
  } else {
    StageTimer t(times, Stage::GlobalShape);
    for_each_strand([&](std::size_t s, const RegionSettings& r) {
      if (!r.global_pass) return;
      const std::size_t b = rest_.strand_begin(s), n = rest_.strand_size(s);
      k::global_shape(strand(pos_, s), std::span<const Vec4f>(rest_.positions).subspan(b, n), head,
                      r.global_stiffness, r.global_range, r.global_ramp);
    });
  }
  // Algorithm 1 lines 7-9: local shape and edge length constraints alternate; each
  // region stops after its own iteration counts.
  for (int it = 0; it < max_iterations_; ++it) {
    if (!any_local_pass_) {
      times.skip(Stage::LocalShape);
    } else {
      StageTimer t(times, Stage::LocalShape);
      for_each_strand([&](std::size_t s, const RegionSettings& r) {
        if (!r.local_pass || it >= r.local_iterations) return;
        const std::size_t b = rest_.strand_begin(s), n = rest_.strand_size(s);
        const auto rest_rot = std::span<const Quatf>(rest_rotation_).subspan(b, n);
        const auto rest_loc = std::span<const Vec3f>(rest_local_).subspan(b, n);
        switch (r.local_method) {
          case Method::Serial:
            k::local_shape_m1(strand(pos_, s), rest_rot, rest_loc, head_rotation, r.local_stiffness);
            break;
          case Method::Jacobi:
            k::local_shape_m2(strand(pos_, s), std::span(rotation_).subspan(b, n),
                              std::span(scratch_).subspan(b, n), rest_rot, rest_loc,
                              std::span<const std::uint8_t>(rounding_sized_).subspan(b, n),
                              std::span<const Quatf>(rest_relative_).subspan(b, n), head_rotation,
                              r.local_stiffness);
            break;
          case Method::RestFrames:
            k::local_shape_m3(strand(pos_, s), std::span<const Vec4f>(rest_.positions).subspan(b, n),
                              head_rotation, r.local_stiffness);
            break;
        }
      });
    }
    {
      StageTimer t(times, Stage::Length);
      for_each_strand([&](std::size_t s, const RegionSettings& r) {
        if (it >= r.length_iterations) return;
        k::edge_length(strand(pos_, s),
                       std::span<const float>(rest_length_).subspan(rest_.strand_begin(s), rest_.strand_size(s)));
      });
    }
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

std::unique_ptr<HairModel> make_reference(Method method, const ModelContext& ctx) {
  return std::make_unique<HanModel>(method, ctx);
}

}  // namespace hairbench::han
