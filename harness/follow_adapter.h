// Runs a CPU model on the guide strands of an imported groom and rebuilds the follow hairs
// from them after every step, as TressFX does: the follow strands cost no simulation, and
// the metrics still see the full groom. (The Vulkan models build them on the device:
// make_model in harness/runner.cpp.)
#pragma once

#include "core/hair_model.h"
#include "scenarios/tfx/tfx.h"

#include <memory>
#include <vector>

namespace hairbench {

class FollowHairsAdapter final : public HairModel {
 public:
  // `guides`, `follow` and `pool` must outlive the adapter; `follow` is laid out on
  // `guides`. The follow strands are rebuilt over the pool's threads (null: on the caller's).
  FollowHairsAdapter(std::unique_ptr<HairModel> inner, const Groom& guides, const tfx::FollowHairs& follow,
                     ThreadPool* pool);

  // `rest` is the full groom (guides, then follow strands); the inner model is reset
  // with the guides only.
  void reset(const Groom& rest, const ParamSet& params) override;
  // Steps the inner model, then rebuilds the follow strands (stage "follow_hairs").
  void step(const FrameInput& in, StageTimes& out_times) override;
  // The guides' positions, then the follow strands'.
  std::span<const Vec4f> positions() const override { return positions_; }
  Backend backend() const override { return inner_->backend(); }
  std::optional<double> last_gpu_ms() const override { return inner_->last_gpu_ms(); }
  // Of the guides: a follow hair moves with its guide.
  std::size_t static_strands() const override { return inner_->static_strands(); }
  const Groom* simulated_groom() const override { return inner_->simulated_groom(); }
  std::span<const Vec4f> simulated_positions() const override { return inner_->simulated_positions(); }
  const ParamSet* run_params() const override { return inner_->run_params(); }
  std::string failure() const override { return inner_->failure(); }

 private:
  void rebuild();

  std::unique_ptr<HairModel> inner_;
  const Groom& guides_;
  const tfx::FollowHairs& follow_;
  ThreadPool* pool_;
  std::vector<Vec4f> positions_;
};

}  // namespace hairbench
