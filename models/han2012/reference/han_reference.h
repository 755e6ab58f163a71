// Han & Harada 2012, "Real-time Hair Simulation with Efficient Hair Style Preservation":
// Algorithm 1 (integrate, global shape, local shape + edge length iterations, collision)
// with the three ways of updating the local/global transforms of §4.2.
#pragma once

#include "core/hair_model.h"
#include "core/sleep.h"
#include "models/han2012/settings.h"

#include <cstdint>
#include <memory>
#include <vector>

namespace hairbench::han {

enum class Method {
  Serial = 1,    // method 1, Algorithm 3: exact transforms, serial within a strand
  Jacobi = 2,    // method 2, Algorithm 4: transforms from the previous iteration
  RestFrames = 3 // method 3, Algorithm 5: rest-state transforms under the head rotation
};

class HanModel final : public HairModel {
 public:
  HanModel(Method method, const ModelContext& ctx);
  void reset(const Groom& rest, const ParamSet& params) override;
  // Positions and previous positions both at the given ones; the frames stay at rest (they
  // matter only with the shape terms on, which a kicked chain has off).
  bool start_from(std::span<const Vec4f> positions) override;
  void step(const FrameInput& in, StageTimes& out_times) override;
  std::span<const Vec4f> positions() const override { return pos_; }
  // Every array a frame reads or writes (the roofline's streaming floor).
  std::size_t state_bytes() const override {
    return (pos_.size() + prev_.size() + rest_.positions.size()) * sizeof(Vec4f) +
           rest_length_.size() * sizeof(float) +
           (rest_rotation_.size() + rotation_.size() + scratch_.size() + rest_relative_.size()) * sizeof(Quatf) +
           rest_local_.size() * sizeof(Vec3f) + rounding_sized_.size();
  }

 private:
  // Per-region solver settings: the region's parameters (settings.h, read once in reset())
  // and what reset() decides from them.
  struct RegionSettings : han::RegionSettings {
    Method local_method;  // this region's local shape method (§6: LOD by region)
    bool global_pass;     // false when S_G or the range is 0 and inert stages are skipped
    bool local_pass;      // false when S_L is 0 or there are no local iterations
  };
  void substep(const Affine3f& head, const FrameInput& in, const FramePlan& plan, float dt, StageTimes& times);
  template <class F>
  void for_each_strand(F&& f);
  std::span<Vec4f> strand(std::vector<Vec4f>& v, std::size_t s);

  Method method_;
  ModelContext ctx_;
  Groom rest_;
  std::vector<float> rest_length_;
  std::vector<Quatf> rest_rotation_;  // wR_i^0 (Algorithm 2)
  std::vector<Vec3f> rest_local_;     // ^{i-1}P_i^0
  // Method 2: whether rest edge (i-1, i) is rounding-sized, and there ^{i-1}T_i^0
  // (kernels::init_rounding_sized_frames).
  std::vector<std::uint8_t> rounding_sized_;
  std::vector<Quatf> rest_relative_;
  std::vector<RegionSettings> region_;
  int substeps_ = 1;
  int max_iterations_ = 0;
  bool any_global_pass_ = false, any_local_pass_ = false;
  StrandSleep sleep_;

  std::vector<Vec4f> pos_, prev_;
  std::vector<Quatf> rotation_, scratch_;  // method 2's persistent frames and their copy
  std::vector<Vec4f> spheres_;             // world-space colliders of the current substep
};

std::unique_ptr<HairModel> make_reference(Method method, const ModelContext& ctx);

}  // namespace hairbench::han
