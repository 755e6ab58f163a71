// Sleeping strands: with the head still and no wind, a strand whose vertices
// all stayed below a speed threshold for kQuietFrames consecutive frames is no longer
// simulated until the head moves or wind starts. A sleeping strand's state is not
// touched at all, so on waking it resumes bit-exactly from where the model left it.
#pragma once

#include "core/types.h"

#include <cstdint>
#include <span>
#include <vector>

namespace hairbench {

class StrandSleep {
 public:
  static constexpr int kQuietFrames = 10;
  // Below this vertex speed a strand counts as at rest: 0.1 mm/s, 1/1000 of a strand
  // length of 10 cm per second, far below anything a frame at 60 Hz can show.
  static constexpr float kRestSpeed = 1e-4f;

  void reset(std::size_t strands);
  // At the start of a step: whether strands may sleep during it (the head holds still
  // over the whole step and there is no wind). When they may not, every strand wakes.
  bool begin_step(const FrameInput& in, bool enabled);
  bool asleep(std::size_t s) const { return asleep_[s] != 0; }
  // After a step in which sleeping was allowed, for each strand that was awake: its
  // vertices' largest displacement over the last (sub)step of length dt. Touches only
  // strand s's entries, so strands may be observed in parallel.
  void observe(std::size_t s, std::span<const Vec4f> pos, std::span<const Vec4f> prev, float dt);
  // The same from each vertex's step p - p_prev over that (sub)step (xyz).
  void observe_steps(std::size_t s, std::span<const Vec4f> step, float dt);
  // The same, for models whose state is not positions: a bound on the strand's largest
  // vertex speed, m/s.
  void observe_speed(std::size_t s, float speed);
  std::size_t asleep_count() const;
  // Whether every strand slept through the last observed step; refreshed by
  // end_observe(), after the step's observe() calls. A model then skips the whole step.
  void end_observe() { all_asleep_ = asleep_count() == asleep_.size(); }
  bool all_asleep() const { return all_asleep_; }

 private:
  // The largest squared travel of the strand's vertices over a (sub)step of length dt.
  void observe_travel(std::size_t s, float travel2, float dt);

  std::vector<std::uint8_t> asleep_;
  std::vector<std::int32_t> quiet_frames_;
  bool all_asleep_ = false;
};

}  // namespace hairbench
