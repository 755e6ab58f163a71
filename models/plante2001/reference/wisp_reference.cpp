#include "models/plante2001/reference/wisp_reference.h"

#include <limits>

namespace hairbench::plante {

namespace k = hairbench::kernels;

void PlanteWispRef::prepare(std::size_t threads) { thread_mailbox_.assign(threads, {}); }

template <class F>
void PlanteWispRef::stage_pass(StageTimes& times, Stage stage, F&& f) {
  StageTimer t(times, stage);
  for_each(sys_.wisp_count(), [&](std::size_t begin, std::size_t end) {
    for (std::size_t w = begin; w < end; ++w) f(w);
  });
}

// The same stages in the same order as the fused schedule, one pass over all wisps each
// (it reads every wisp's state once per stage).
void PlanteWispRef::integrate(const StepInput& s, StageTimes& times) {
  stage_pass(times, Stage::Integrate, [&](std::size_t w) {
    k::wisp_pin(sys_, w, s.head, s.h);
    k::wisp_forces_and_velocities(sys_, w, params_[sys_.wisp_params[w]], s.head_rot, s.in.gravity, s.in.wind, s.h);
  });
  if (s.body_on) stage_pass(times, Stage::BodyCollision, [&](std::size_t w) { k::wisp_body_slide(sys_, w, s.body, s.drag); });
  if (s.interact) {
    StageTimer t(times, Stage::SelfInteraction);
    detect_self_interactions();
    k::wisp_contacts_respond(sys_, contacts_, interaction_, params_, static_cast<float>(1.0 / interaction_hz_));
  }
  stage_pass(times, Stage::Integrate,
             [&](std::size_t w) { k::wisp_positions(sys_, w, s.head_rot * sys_.rest_e1[w], s.h); });
  if (s.body_on) stage_pass(times, Stage::BodyCollision, [&](std::size_t w) { k::wisp_body_hold(sys_, w, s.body); });
  if (s.body_due)
    stage_pass(times, Stage::BodyCollision, [&](std::size_t w) {
      k::wisp_body_detect(sys_, w, s.body, s.head_rot * sys_.rest_e1[w], interaction_.contact_threshold);
    });
}

void PlanteWispRef::build_cells(std::size_t) { k::grid_cells(grid_); }

void PlanteWispRef::begin_narrow_phase(std::size_t thread, std::size_t segments) {
  thread_mailbox_[thread].assign(segments, std::numeric_limits<std::uint32_t>::max());
}

void PlanteWispRef::narrow_phase(std::size_t thread, std::size_t begin, std::size_t end,
                                 std::vector<k::WispContact>& out) {
  k::grid_contacts_ref(grid_, sys_, begin, end, thread_mailbox_[thread], out);
}

// Each point alone, the two nodes' parts of the section frame included (§5.2).
void PlanteWispRef::section_points(std::size_t strand, const Eigen::Matrix3f& head_rot) {
  const std::uint32_t vb = rest_.strand_begin(strand), n = rest_.strand_size(strand);
  for (std::uint32_t i = vb; i < vb + n; ++i) {
    strand_points_[i] = k::strand_point(sys_, vertex_node_[i], coord_[i], head_rot);
    strand_weights_[i] = k::section_weight(sys_, vertex_node_[i], coord_[i].x());
  }
}

std::unique_ptr<HairModel> make_reference(const ModelContext& ctx) { return std::make_unique<PlanteWispRef>(ctx); }

}  // namespace hairbench::plante
