#include "harness/follow_adapter.h"

#include <algorithm>
#include <stdexcept>

namespace hairbench {

FollowHairsAdapter::FollowHairsAdapter(std::unique_ptr<HairModel> inner, const Groom& guides,
                                       const tfx::FollowHairs& follow, ThreadPool* pool)
    : inner_(std::move(inner)), guides_(guides), follow_(follow), pool_(pool) {}

void FollowHairsAdapter::reset(const Groom& rest, const ParamSet& params) {
  // Anything else would make positions() disagree with the groom the metrics expect.
  if (rest.vertex_count() != guides_.vertex_count() + follow_.vertex_count() ||
      follow_.guide_offsets != guides_.strand_offsets)
    throw std::logic_error("FollowHairsAdapter: the rest groom is not the guides expanded by the follow hairs");
  inner_->reset(guides_, params);
  positions_.resize(rest.vertex_count());
  rebuild();
}

void FollowHairsAdapter::step(const FrameInput& in, StageTimes& out_times) {
  inner_->step(in, out_times);
  const StageTimer timer(out_times, Stage::FollowHairs);
  rebuild();
}

void FollowHairsAdapter::rebuild() {
  const std::span<const Vec4f> guides = inner_->positions();
  std::copy(guides.begin(), guides.end(), positions_.begin());
  tfx::apply_follow_hairs(follow_, guides, std::span<Vec4f>(positions_).subspan(guides.size()), pool_);
}

}  // namespace hairbench
