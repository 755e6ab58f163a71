// Halén & Wester 2007 §4.2, the interactive forest of Di Giacomo et al. 2001 without
// branching: each segment is a joint with two angles (θ, φ) relative to its parent;
// external forces become torques τ = L z × F, joints are damped angular springs whose
// torques also act on the parent, angles are integrated with Euler's method and the
// positions rebuilt from them, so segment lengths are exact. §5.9: the primary axis is
// the parent's x axis by default (the original z axis is selectable), and the joint
// stiffness falls with the distance from the root. The forest's counterpart of the other
// two models' L = mg/k, on by default: gravity's torque on the head-transformed rest
// segments is subtracted, so the head-transformed rest pose is in equilibrium (settings.h
// lists this and the two other departures from §4.2, and selects the thesis as written).
#pragma once

#include "core/hair_model.h"
#include "core/sleep.h"
#include "kernels/halen2007/reference/halen_kernels.h"

#include <limits>
#include <memory>
#include <vector>

namespace hairbench::halen_forest {

class ForestModel final : public HairModel {
 public:
  explicit ForestModel(const ModelContext& ctx);
  void reset(const Groom& rest, const ParamSet& params) override;
  // The joint angles that pose the given polyline (forest_rest on it: its pinned segments
  // are the rest's, so the root frames are too), their rates 0.
  bool start_from(std::span<const Vec4f> positions) override;
  void step(const FrameInput& in, StageTimes& out_times) override;
  std::span<const Vec4f> positions() const override { return pos_; }
  // Every per-vertex array a step reads or writes.
  std::size_t state_bytes() const override;

 private:
  void pose(const Affine3f& head);
  kernels::ForestStrand strand_view(std::size_t s);
  template <class F>
  void for_each_strand(F&& f);

  ModelContext ctx_;
  Groom rest_;
  kernels::ForestAxes axes_ = kernels::ForestAxes::ParentX;
  kernels::ForestInertia inertia_ = kernels::ForestInertia::StrandPendulum;
  bool gravity_compensation_ = true, root_angular_acceleration_ = false;
  std::vector<kernels::Mat3f> rest_frame_, frame_;
  std::vector<float> length_, theta0_, phi0_, k_;
  std::vector<Vec3f> joint_torque_;
  std::vector<float> theta_, phi_, dtheta_, dphi_;
  void hold_rest(const Vec3f& gravity);

  std::vector<float> inv_strand_length_;  // 1/ℓ per strand
  // Per strand, the gain of the external torques under J = m L ℓ: 1/ℓ, divided by
  // kernels::forest_rest_inertia_scale for the gravity it was last given (rest_hold).
  std::vector<float> inv_inertia_length_;
  bool rest_hold_ = true;
  Vec3f held_for_ = Vec3f::Constant(std::numeric_limits<float>::quiet_NaN());
  std::vector<float> joint_damping_, drag_, collision_stiffness_, collision_damping_;  // per region
  int substeps_ = 1;
  Affine3f head_hist_[2];  // head transforms of the last two substeps (the root's inertia)
  std::vector<Vec4f> pos_;
  std::vector<Vec4f> spheres_;
  StrandSleep sleep_;
};

std::unique_ptr<HairModel> make(const ModelContext& ctx);

}  // namespace hairbench::halen_forest
