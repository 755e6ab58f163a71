// plante_wisp_ref: the layered wisp model (models/plante2001/wisp_model.h) one stage at a
// time over all wisps, with the per-wisp kernels (kernels/plante2001/reference/) and the
// plain narrow phase: the readable reference the fused schedule is checked against bit
// for bit.
#pragma once

#include "models/plante2001/wisp_model.h"

namespace hairbench::plante {

class PlanteWispRef final : public WispModel {
 public:
  explicit PlanteWispRef(const ModelContext& ctx) : WispModel(ctx) {}

 private:
  void prepare(std::size_t threads) override;
  void integrate(const StepInput& s, StageTimes& times) override;
  void build_cells(std::size_t threads) override;
  void begin_narrow_phase(std::size_t thread, std::size_t segments) override;
  void narrow_phase(std::size_t thread, std::size_t begin, std::size_t end,
                    std::vector<kernels::WispContact>& out) override;
  void prepare_sections(const Eigen::Matrix3f&) override {}
  void section_points(std::size_t strand, const Eigen::Matrix3f& head_rot) override;
  // f(w) for every wisp, over the threads, timed as `stage`.
  template <class F>
  void stage_pass(StageTimes& times, Stage stage, F&& f);

  // Each thread's mailbox of the segments it has tested (Amanatides & Woo): a segment is
  // tested once by one thread, so a thread's mailbox serves all its chunks.
  std::vector<std::vector<std::uint32_t>> thread_mailbox_;
};

std::unique_ptr<HairModel> make_reference(const ModelContext& ctx);

}  // namespace hairbench::plante
