// Plante, Cani & Poulin 2001, "A Layered Wisp Model for Simulating Interactions inside
// Long Hair": the groom's strands clustered into wisps (§3.1), each a damped spring
// skeleton (§3.2) coated by a deformable envelope (§3.3), with anisotropic wisp-wisp and
// wisp-body interactions (§4), stepped by the loop of §5.1 at the rates of §5.3. The
// groom's strands are the render layer (§3.4, §5.2): fixed coordinates in their wisp's
// sections, rebuilt after every step.
#pragma once

#include "core/hair_model.h"
#include "core/sleep.h"
#include "kernels/plante2001/wisp_grid.h"
#include "kernels/plante2001/reference/wisp_kernels.h"
#include "kernels/plante2001/fused/wisp_soa.h"

#include <array>
#include <atomic>
#include <chrono>
#include <memory>
#include <string_view>
#include <vector>

namespace hairbench::plante {

// How a step visits the wisps. Fused: each wisp goes through all of a step's stages in
// one pass while it is in cache (plante_wisp). PerStage: one pass over all wisps per
// stage (plante_wisp_ref, the reference); both run the same kernels in the same order
// per wisp, so their results are bit-identical.
enum class Schedule { Fused, PerStage };

class PlanteWispModel final : public HairModel {
 public:
  explicit PlanteWispModel(const ModelContext& ctx, Schedule schedule = Schedule::Fused);
  void reset(const Groom& rest, const ParamSet& params) override;
  // Stages: integrate, body_collision, self_interaction, rebuild.
  void step(const FrameInput& in, StageTimes& out_times) override;
  std::span<const Vec4f> positions() const override { return pos_; }
  // What a step reads and writes: the skeleton's and envelope's state and forces, the
  // section frames, and the rebuilt strands.
  std::size_t state_bytes() const override;

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
  // Contacts of the last wisp-wisp detection.
  std::span<const kernels::WispContact> contacts() const { return contacts_; }
  // The block and narrow-phase kernels' ISA variant (by default this CPU's best), for the
  // tests that compare variants; and how many wisps the block kernels take.
  void use_kernels(const kernels::wisp_soa::Kernels& k) { block_ = k; }
  std::size_t block_wisps() const;

 private:
  void cluster(const Groom& rest, int wisps, int strands_per_wisp, int segments, int root_blend, float width_max,
               float r_min);
  // The stages a fused pass over the wisps times (see wisp_pass).
  enum PassStage { kIntegration = 0, kBody = 1 };
  struct WispClock {
    bool on = false;
    std::chrono::steady_clock::time_point last;
    std::array<std::atomic<std::int64_t>*, 2> sampled_ns{};
    void lap(int stage);  // time since the last lap to `stage`, on sampled wisps
  };
  // f(begin, end) over [0, count), split statically over the threads.
  template <class F>
  void for_each(std::size_t count, F&& f);
  // f(run, clock) for every run of wisps (runs_), over the threads; adds the pass's
  // time to the stages.
  template <class F>
  void wisp_pass(StageTimes& times, F&& f);
  // f(w) for every wisp, over the threads, timed as `stage` (the per-stage schedule).
  template <class F>
  void stage_pass(StageTimes& times, Stage stage, F&& f);
  void detect_self_interactions();
  // k::wisp_contacts_respond over the threads, for the contacts of the last detection.
  void respond_to_contacts(float h);

  ModelContext ctx_;
  Schedule schedule_;
  Groom rest_;
  std::vector<kernels::WispParams> params_;  // per groom region
  kernels::InteractionParams interaction_;
  double integration_hz_ = 1000, collision_hz_ = 120, interaction_hz_ = 24;
  int threads_min_wisps_ = 64;
  // Wisps touch each other, so the hair sleeps as a whole: one "strand" in StrandSleep
  // that stands for every wisp.
  StrandSleep sleep_;

  kernels::WispSystem sys_;
  // The fused schedule's units of work, in wisp order: blocks of up to wisp_soa::kLanes
  // consecutive wisps that the block kernels take together (one node count and one
  // params set each), and single wisps.
  struct WispRun {
    std::uint32_t first, count;
  };
  std::vector<WispRun> runs_;
  std::vector<std::size_t> run_bounds_;  // thread t's runs: [run_bounds_[t], run_bounds_[t + 1])
  // During a pass, the runs of thread t's range not yet taken (wisp_pass).
  struct alignas(64) RunRange {
    std::atomic<std::uint64_t> range{0};
  };
  std::vector<RunRange> run_ranges_;
  kernels::wisp_soa::Kernels block_ = kernels::wisp_soa::kernels();  // and the narrow phase
  std::vector<std::uint32_t> strand_wisp_;
  std::vector<Vec4f> coord_;              // per groom vertex
  std::vector<std::uint32_t> vertex_node_;  // per groom vertex: the node coord_ is relative to
  std::vector<Vec4f> pos_;
  // The rebuild's (plante_wisp): per node, and each vertex's section point and weight.
  std::vector<kernels::NodeSection> node_sections_;
  std::vector<Vec3f> strand_points_;
  std::vector<float> strand_weights_;

  kernels::SegmentGrid grid_;
  // The narrow phase's ranges of segments and their contacts (detect_self_interactions).
  static constexpr std::size_t kChunksPerThread = 8;
  std::vector<std::vector<kernels::WispContact>> chunk_contacts_;
  std::vector<std::size_t> chunk_bounds_, chunk_offset_;
  std::vector<std::vector<std::uint32_t>> thread_mailbox_;
  std::vector<kernels::WispContact> contacts_;
  std::vector<kernels::ContactImpulse> impulses_;  // per contact (respond_to_contacts)
  std::vector<kernels::wisp_soa::ContactNode> contact_nodes_;  // per node, the impulses' input rows
  // Thread t sums the contacts on nodes [node_bounds_[t], node_bounds_[t + 1]) (respond_to_contacts).
  std::vector<std::uint32_t> node_bounds_;
  bool contacts_known_ = false;  // a body detection has run since reset
  std::vector<Vec4f> spheres_;
  std::vector<std::int32_t> sphere_moves_;
  std::array<std::atomic<std::int64_t>, 2> sampled_ns_{};
};

std::unique_ptr<HairModel> make_plante_wisp(const ModelContext& ctx, Schedule schedule = Schedule::Fused);

}  // namespace hairbench::plante
