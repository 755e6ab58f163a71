// Threads of the fused block models (han_fused, halen_fused): each thread owns a fixed
// range of blocks (static partition, so no result depends on the thread count), and the
// blocks it samples time their stages (soa::StageClock). A stage's time is its share of
// the sampled time, times the step's wall time: no clock read per stage per block.
#pragma once

#include "core/hair_model.h"
#include "core/parallel.h"
#include "kernels/simd/soa_common.h"

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace hairbench {

struct alignas(64) BlockThread {
  std::array<std::int64_t, kStageCount> stage_ns{};  // by stage_index
  std::int64_t sampled_ns = 0;
  std::size_t first = 0, last = 0;  // the thread's blocks (or jobs) [first, last)
};

// run(t) for every thread t: on the pool when there is one, else thread 0 inline.
template <class F>
void for_each_block_thread(ThreadPool* pool, std::size_t threads, const F& run) {
  if (pool)
    pool->parallel_for(threads, [&run](std::size_t b, std::size_t e) {
      for (std::size_t t = b; t < e; ++t) run(static_cast<int>(t));
    });
  else
    run(0);
}

inline void clear_stage_clocks(std::vector<BlockThread>& threads) {
  for (BlockThread& t : threads) {
    t.stage_ns.fill(0);
    t.sampled_ns = 0;
  }
}

// The step's stage times from its threads' sampled clocks and its wall time.
class SampledStageTimes {
 public:
  SampledStageTimes(const std::vector<BlockThread>& threads, double wall_ms) : wall_ms_(wall_ms) {
    for (const BlockThread& t : threads) {
      for (std::size_t s = 0; s < kStageCount; ++s) ns_[s] += t.stage_ns[s];
      sampled_ += t.sampled_ns;
    }
  }
  // Adds `stage` to `times`, or marks it skipped when it did not run.
  void report(StageTimes& times, Stage stage, bool ran) const {
    if (!ran) {
      times.skip(stage);
      return;
    }
    const double share =
        sampled_ > 0 ? static_cast<double>(ns_[stage_index(stage)]) / static_cast<double>(sampled_) : 0.0;
    times.add(stage, wall_ms_ * share);
  }

 private:
  std::array<std::int64_t, kStageCount> ns_{};
  std::int64_t sampled_ = 0;
  double wall_ms_;
};

// The frame's substeps and forces for a block kernel; the wind term runs only when windy.
template <class SubstepT>
void set_block_frame(kernels::soa::BlockFrame<SubstepT>& f, const std::vector<SubstepT>& substeps, int substep_count,
                     const FrameInput& in, bool windy) {
  f.substeps = substeps.data();
  f.substep_count = substep_count;
  const Vec3f wind = in.wind.acceleration();
  for (int c = 0; c < 3; ++c) {
    f.gravity[c] = in.gravity[c];
    f.wind[c] = wind[c];
  }
  f.windy = windy;
}

}  // namespace hairbench
