// Plante, Cani & Poulin 2001, "A Layered Wisp Model for Simulating Interactions inside
// Long Hair": the groom's strands clustered into wisps (§3.1), each a damped spring
// skeleton (§3.2) coated by a deformable envelope (§3.3), with anisotropic wisp-wisp and
// wisp-body interactions (§4), stepped by the loop of §5.1 at the rates of §5.3. The
// groom's strands are the render layer (§3.4, §5.2): fixed coordinates in their wisp's
// sections, rebuilt after every step.
#pragma once

#include "core/hair_model.h"
#include "core/parallel.h"
#include "core/sleep.h"
#include "kernels/plante2001/wisp_grid.h"
#include "kernels/plante2001/reference/wisp_kernels.h"

#include <array>
#include <atomic>
#include <chrono>
#include <memory>
#include <string_view>
#include <vector>

namespace hairbench::plante {

// What the reference (reference/wisp_reference.h, plante_wisp_ref) and the fused schedule
// (fused/wisp_fused.h, plante_wisp) share: the wisps built from the groom, the loop of §5.1 at
// the rates of §5.3, the wisp-wisp detection's grid and chunks, and the strands' rebuild.
// The two differ only in how a step visits the wisps (the hooks below); both run the same
// kernels in the same order per wisp, so their results are bit-identical.
class WispModel : public HairModel {
 public:
  void reset(const Groom& rest, const ParamSet& params) override;
  // Stages: integrate, body_collision, self_interaction, rebuild.
  void step(const FrameInput& in, StageTimes& out_times) override;
  std::span<const Vec4f> positions() const override { return pos_; }
  // What a step reads and writes: the skeleton's and envelope's state and forces, the
  // section frames, and the rebuilt strands.
  std::size_t state_bytes() const override;
  // The skeletons are the simulated groom: one strand per wisp, its nodes' rest positions
  // with w = 1 / the node's mass (0 pinned), their edges the axial springs; the groom's
  // strands are drawn from them (§3.4).
  const Groom* simulated_groom() const override { return &skeletons_; }
  std::span<const Vec4f> simulated_positions() const override { return skeleton_pos_; }
  // The free nodes at the given positions (the skeletons' layout), every velocity 0, the
  // envelopes at their rest radii and the sections' frames rebuilt from the skeleton.
  bool start_from(std::span<const Vec4f> positions) override;

  // The simulation state, for tests and inspection. Tests may edit velocities.
  const kernels::WispSystem& wisps() const { return sys_; }
  kernels::WispSystem& wisps() { return sys_; }
  // Wisp of each groom strand, and each groom vertex's coordinates in its wisp
  // (kernels::strand_coord, relative to node section_nodes()[vertex]).
  std::span<const std::uint32_t> strand_wisp() const { return strand_wisp_; }
  std::span<const Vec4f> section_coords() const { return coord_; }
  std::span<const std::uint32_t> section_nodes() const { return vertex_node_; }
  // Rebuilds positions() from the current wisp state under head transform `head` (done
  // at the end of every step; public so that tests can rebuild from an edited state).
  void rebuild(const Affine3f& head);
  // Contacts of the last wisp-wisp detection, and the grid it built (its segments,
  // boxes and cells as they were then: kernels::grid_test_counts).
  std::span<const kernels::WispContact> contacts() const { return contacts_; }
  const kernels::SegmentGrid& grid() const { return grid_; }

 protected:
  explicit WispModel(const ModelContext& ctx);

  // One integration step's inputs (§5.1), for integrate().
  struct StepInput {
    const FrameInput& in;
    Affine3f head;
    Eigen::Matrix3f head_rot;
    float h;                       // the integration step, s
    const kernels::BodyStep& body;
    float drag;                    // the bodies' viscous friction over this step
    bool body_on;                  // sliding contacts are modified on this step
    bool body_due;                 // and body contacts detected
    bool interact;                 // wisp-wisp interactions detected and responded to
  };
  // The hooks each schedule implements:
  // after reset's clustering, with the number of threads;
  virtual void prepare(std::size_t threads) = 0;
  // §5.1 (1)-(4) for one integration step: forces, the wisp-wisp interactions when
  // s.interact (detect_self_interactions and their response), velocities, positions and
  // the bodies' modifications, timed as the stages;
  virtual void integrate(const StepInput& s, StageTimes& times) = 0;
  // the detection grid's cells, after its segments are set up;
  virtual void build_cells(std::size_t threads) = 0;
  // the narrow phase of segments [begin, end) on thread `thread`, after
  // begin_narrow_phase(thread, segments) for each thread of a detection;
  virtual void begin_narrow_phase(std::size_t thread, std::size_t segments) = 0;
  virtual void narrow_phase(std::size_t thread, std::size_t begin, std::size_t end,
                            std::vector<kernels::WispContact>& out) = 0;
  // the rebuild's section points and weights of strand s (strand_points_,
  // strand_weights_), after prepare_sections once per rebuild.
  virtual void prepare_sections(const Eigen::Matrix3f& head_rot) = 0;
  virtual void section_points(std::size_t strand, const Eigen::Matrix3f& head_rot) = 0;

  void cluster(const Groom& rest, int wisps, int strands_per_wisp, int segments, int root_blend, float width_max,
               float r_min);
  // f(begin, end) over [0, count), split statically over the threads.
  template <class F>
  void for_each(std::size_t count, F&& f);
  void detect_self_interactions();
  // skeletons_ from the wisps cluster() built.
  void set_skeletons(const Groom& rest);

  ModelContext ctx_;
  Groom rest_;
  std::vector<kernels::WispParams> params_;  // per groom region
  kernels::InteractionParams interaction_;
  double integration_hz_ = 1000, collision_hz_ = 120, interaction_hz_ = 24;
  int threads_min_wisps_ = 64;
  // Wisps touch each other, so the hair sleeps as a whole: one "strand" in StrandSleep
  // that stands for every wisp.
  StrandSleep sleep_;

  kernels::WispSystem sys_;
  std::vector<std::uint32_t> strand_wisp_;
  std::vector<Vec4f> coord_;              // per groom vertex
  std::vector<std::uint32_t> vertex_node_;  // per groom vertex: the node coord_ is relative to
  std::vector<Vec4f> pos_;
  Groom skeletons_;                  // simulated_groom()
  std::vector<Vec4f> skeleton_pos_;  // sys_.x, refreshed with every rebuild
  // The rebuild's section point and weight of each vertex (section_points).
  std::vector<Vec3f> strand_points_;
  std::vector<float> strand_weights_;

  kernels::SegmentGrid grid_;
  // The narrow phase's ranges of segments and their contacts (detect_self_interactions).
  static constexpr std::size_t kChunksPerThread = 8;
  std::vector<std::vector<kernels::WispContact>> chunk_contacts_;
  std::vector<std::size_t> chunk_bounds_, chunk_offset_;
  std::size_t threads_ = 1;  // of the pool, or 1
  std::vector<kernels::WispContact> contacts_;
  bool contacts_known_ = false;  // a body detection has run since reset
  std::vector<Vec4f> spheres_;
  std::vector<std::int32_t> sphere_moves_;
};

template <class F>
void WispModel::for_each(std::size_t count, F&& f) {
  // Static partition (ThreadPool::parallel_for); every caller's results are the same
  // whichever thread runs which range. Below threads_min_wisps wisps, one thread.
  if (ctx_.pool && sys_.wisp_count() >= static_cast<std::size_t>(threads_min_wisps_))
    ctx_.pool->parallel_for(count, [&](std::size_t begin, std::size_t end) { f(begin, end); });
  else
    f(std::size_t{0}, count);
}

}  // namespace hairbench::plante
