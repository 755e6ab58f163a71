// plante_wisp: the layered wisp model (models/plante2001/wisp_model.h) with each wisp
// taken through all of a step's per-wisp stages in one pass while it is in cache (split
// around the wisp-wisp response on the steps that detect), consecutive wisps of one node
// count and parameter set integrated 16 at a time, one wisp per vector lane, and the
// vector narrow phase (kernels/plante2001/fused/). Bit-identical to plante_wisp_ref
// (reference/wisp_reference.h) for any thread count and ISA variant.
#pragma once

#include "kernels/plante2001/fused/wisp_soa.h"
#include "models/plante2001/wisp_model.h"

#include <array>
#include <atomic>
#include <chrono>

namespace hairbench::plante {

class PlanteWispModel final : public WispModel {
 public:
  explicit PlanteWispModel(const ModelContext& ctx) : WispModel(ctx) {}
  // The block and narrow-phase kernels' ISA variant (by default this CPU's best), for the
  // tests that compare variants; and how many wisps the block kernels take.
  void use_kernels(const kernels::wisp_soa::Kernels& k) { block_ = k; }
  std::size_t block_wisps() const;

 private:
  void prepare(std::size_t threads) override;
  void integrate(const StepInput& s, StageTimes& times) override;
  void build_cells(std::size_t threads) override;
  void begin_narrow_phase(std::size_t, std::size_t) override {}
  void narrow_phase(std::size_t thread, std::size_t begin, std::size_t end,
                    std::vector<kernels::WispContact>& out) override;
  void prepare_sections(const Eigen::Matrix3f& head_rot) override;
  void section_points(std::size_t strand, const Eigen::Matrix3f& head_rot) override;

  // The stages a fused pass over the wisps times (see wisp_pass).
  enum PassStage { kIntegration = 0, kBody = 1 };
  struct WispClock {
    bool on = false;
    std::chrono::steady_clock::time_point last;
    std::array<std::atomic<std::int64_t>*, 2> sampled_ns{};
    void lap(int stage);  // time since the last lap to `stage`, on sampled wisps
  };
  // The schedule's units of work, in wisp order: blocks of up to wisp_soa::kLanes
  // consecutive wisps that the block kernels take together (one node count and one
  // params set each), and single wisps.
  struct WispRun {
    std::uint32_t first, count;
  };
  // f(run, clock) for every run of wisps (runs_), over the threads; adds the pass's
  // time to the stages.
  template <class F>
  void wisp_pass(StageTimes& times, F&& f);
  // k::wisp_contacts_respond over the threads, for the contacts of the last detection.
  void respond_to_contacts(float h);

  std::vector<WispRun> runs_;
  std::vector<std::size_t> run_bounds_;  // thread t's runs: [run_bounds_[t], run_bounds_[t + 1])
  // During a pass, the runs of thread t's range not yet taken (wisp_pass).
  struct alignas(64) RunRange {
    std::atomic<std::uint64_t> range{0};
  };
  std::vector<RunRange> run_ranges_;
  kernels::wisp_soa::Kernels block_ = kernels::wisp_soa::kernels();  // and the narrow phase
  // Per node, its part of the section frames (prepare_sections).
  std::vector<kernels::NodeSection> node_sections_;
  std::vector<kernels::ContactImpulse> impulses_;  // per contact (respond_to_contacts)
  std::vector<kernels::wisp_soa::ContactNode> contact_nodes_;  // per node, the impulses' input rows
  // Thread t sums the contacts on nodes [node_bounds_[t], node_bounds_[t + 1]) (respond_to_contacts).
  std::vector<std::uint32_t> node_bounds_;
  std::array<std::atomic<std::int64_t>, 2> sampled_ns_{};
};

std::unique_ptr<HairModel> make_fused(const ModelContext& ctx);

}  // namespace hairbench::plante
