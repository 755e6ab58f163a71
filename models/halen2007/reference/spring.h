// Halén & Wester 2007 §4.4, the spring model: fixed-length segments (Eq. 4.1, 4.2), each
// free node tied by a zero-rest-length spring to one reference node that is rigid with
// the head and displaced upward by L = mg/k so that the rest shape is in equilibrium
// under gravity; the spring strength falls with the distance from the root (§5.9) and
// weakens as the head tilts (k_m).
#pragma once

#include "core/hair_model.h"
#include "core/sleep.h"

#include <memory>
#include <vector>

namespace hairbench::halen_spring {

class SpringModel final : public HairModel {
 public:
  explicit SpringModel(const ModelContext& ctx);
  void reset(const Groom& rest, const ParamSet& params) override;
  bool start_from(std::span<const Vec4f> positions) override;
  void step(const FrameInput& in, StageTimes& out_times) override;
  std::span<const Vec4f> positions() const override { return pos_; }
  // Every per-vertex array a step reads or writes.
  std::size_t state_bytes() const override;

 private:
  struct RegionSettings {
    float damping, tilt_min;
    int length_iterations;
  };
  void substep(const Affine3f& head, const FrameInput& in, float dt, StageTimes& times);
  template <class F>
  void for_each_strand(F&& f);
  template <class T>
  std::span<T> strand(std::vector<T>& v, std::size_t s);

  ModelContext ctx_;
  Groom rest_;
  std::vector<float> rest_length_;
  std::vector<float> k_;            // k_L per vertex (§5.9)
  std::vector<Vec3f> ref_local_;    // reference nodes in the head's rest frame
  std::vector<float> lift_;         // their upward displacement per unit gravity, 1/k_L
  std::vector<Vec3f> ref_;          // ... in world space, this substep
  std::vector<RegionSettings> region_;
  int substeps_ = 1;
  StrandSleep sleep_;
  std::vector<Vec4f> pos_, prev_;
  std::vector<Vec4f> spheres_;
};

std::unique_ptr<HairModel> make(const ModelContext& ctx);

}  // namespace hairbench::halen_spring
