// Halén & Wester 2007 §4.3, cascading spaces: tangent spaces rebuilt from the root each
// step carry two reference nodes per free strand node, an upward one in the space of
// the segment above it and a downward one in the space of the segment two below it;
// zero-rest-length springs F = kL pull the node to both (Verlet, Eq. 4.1), then edge
// corrections (Eq. 4.2). The thesis fixes node 0, node 1's upward reference node in the
// given space at the root; the groom's pinned root edge is that space, and every pin the
// groom has is kept. Each spring is half of the torsion spring the reference nodes
// simulate: its elastic part pushes back on the segment that carries its space
// (kernels::cascade_accelerations). The reference nodes are displaced upward, rigidly
// with the head, to carry the nodes' weight at rest; spring strength falls with the
// distance from the root and the downward springs are a fraction of the upward ones
// (§5.9).
#pragma once

#include "core/hair_model.h"
#include "core/sleep.h"
#include "kernels/halen2007/reference/halen_kernels.h"

#include <memory>
#include <vector>

namespace hairbench::halen_cascade {

class CascadeModel final : public HairModel {
 public:
  explicit CascadeModel(const ModelContext& ctx);
  void reset(const Groom& rest, const ParamSet& params) override;
  bool start_from(std::span<const Vec4f> positions) override;
  void step(const FrameInput& in, StageTimes& out_times) override;
  std::span<const Vec4f> positions() const override { return pos_; }
  // Every per-vertex array a step reads or writes.
  std::size_t state_bytes() const override;

 private:
  struct RegionSettings {
    float damping;
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
  std::vector<float> k_up_, k_down_;               // per vertex, §5.9
  std::vector<kernels::Mat3f> rest_space_, space_;  // [B N T] per segment (by end vertex)
  std::vector<Vec3f> up_local_, down_local_;        // reference nodes in their spaces
  std::vector<float> lift_;                         // upward displacement per unit gravity
  std::vector<float> inv_mass_;                     // the groom's
  std::vector<int> base_;                           // rigid segment carrying each space
  std::vector<float> lever_;                        // ... and its rest length
  std::vector<Vec3f> acc_;                          // the springs' accelerations, this substep
  std::vector<float> twist_;                        // the springs' loads on each space's twist
  kernels::CascadeFrames frames_ = kernels::CascadeFrames::Transport;
  bool reactions_ = true;
  std::vector<RegionSettings> region_;
  int substeps_ = 1;
  StrandSleep sleep_;
  std::vector<Vec4f> pos_;
  std::vector<Vec4f> step_;  // each vertex's last step p - p_prev (the step form of strand_kernels.h)
  std::vector<Vec4f> spheres_;
};

std::unique_ptr<HairModel> make(const ModelContext& ctx);

}  // namespace hairbench::halen_cascade
