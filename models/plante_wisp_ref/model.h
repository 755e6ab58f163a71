// plante_wisp_ref: plante_wisp as it stood before the issue-10 speed work (one pass per
// stage over all wisps, a parallel_for per stage, the per-wisp kernels unchanged), kept
// as the reference that plante_wisp's speed-up and agreement are measured against
// (tests/plante_test.cpp, hairbench_bench BM_step). Physics: models/plante_wisp.
// Plante, Cani & Poulin 2001, "A Layered Wisp Model for Simulating Interactions inside
// Long Hair": the groom's strands clustered into wisps (§3.1), each a damped spring
// skeleton (§3.2) coated by a deformable envelope (§3.3), with anisotropic wisp-wisp and
// wisp-body interactions (§4), stepped by the loop of §5.1 at the rates of §5.3. The
// groom's strands are the render layer (§3.4, §5.2): fixed coordinates in their wisp's
// sections, rebuilt after every step.
#pragma once

#include "core/hair_model.h"
#include "core/sleep.h"
#include "models/plante_wisp_ref/wisp_grid.h"
#include "models/plante_wisp_ref/wisp_kernels.h"

#include <memory>
#include <vector>

namespace hairbench::plante_ref {

class PlanteWispRefModel final : public HairModel {
 public:
  explicit PlanteWispRefModel(const ModelContext& ctx);
  void reset(const Groom& rest, const ParamSet& params) override;
  // Stages: "integration", "body_collision", "self_interaction", "rebuild".
  void step(const FrameInput& in, StageTimes& out_times) override;
  std::span<const Vec4f> positions() const override { return pos_; }
  // What a step reads and writes: the skeleton's and envelope's state and forces, the
  // section frames, and the rebuilt strands.
  std::size_t state_bytes() const override;

  // The simulation state, for tests and inspection. Tests may edit velocities.
  const plante_ref::WispSystem& wisps() const { return sys_; }
  plante_ref::WispSystem& wisps() { return sys_; }
  // Wisp of each groom strand, and each groom vertex's coordinates in its wisp
  // (plante_ref::strand_coord, relative to the node of the same index).
  std::span<const std::uint32_t> strand_wisp() const { return strand_wisp_; }
  std::span<const Vec4f> section_coords() const { return coord_; }
  // Rebuilds positions() from the current wisp state under head transform `head` (done
  // at the end of every step; public so that tests can rebuild from an edited state).
  void rebuild(const Affine3f& head);
  // Contacts of the last wisp-wisp detection.
  std::span<const plante_ref::WispContact> contacts() const { return contacts_; }

 private:
  void cluster(const Groom& rest, int wisps, int strands_per_wisp, int root_blend, float width_max);
  template <class F>
  void for_each_wisp(F&& f);
  void detect_self_interactions();

  ModelContext ctx_;
  Groom rest_;
  std::vector<plante_ref::WispParams> params_;  // per groom region
  plante_ref::InteractionParams interaction_;
  double integration_hz_ = 1000, collision_hz_ = 120, interaction_hz_ = 24;
  int threads_min_wisps_ = 64;
  // Wisps touch each other, so the hair sleeps as a whole: one "strand" in StrandSleep
  // that stands for every wisp (issue 8).
  StrandSleep sleep_;

  plante_ref::WispSystem sys_;
  std::vector<std::uint32_t> strand_wisp_;
  std::vector<Vec4f> coord_;  // per groom vertex
  std::vector<Vec4f> pos_;

  plante_ref::SegmentGrid grid_;
  std::vector<std::vector<plante_ref::WispContact>> chunk_contacts_;
  std::vector<std::vector<std::uint32_t>> chunk_mailbox_;
  std::vector<plante_ref::WispContact> contacts_;
  bool contacts_known_ = false;  // a body detection has run since reset
  std::vector<Vec4f> spheres_;
  std::vector<std::uint8_t> sphere_moves_;
};

std::unique_ptr<HairModel> make_plante_wisp_ref(const ModelContext& ctx);

}  // namespace hairbench::plante_ref
