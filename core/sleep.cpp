#include "core/sleep.h"

#include <algorithm>

namespace hairbench {

void StrandSleep::reset(std::size_t strands) {
  all_asleep_ = false;
  asleep_.assign(strands, 0);
  quiet_frames_.assign(strands, 0);
}

bool StrandSleep::begin_step(const FrameInput& in, bool enabled) {
  // Exact comparison on purpose: a head that moved by any amount must wake the hair.
  const bool calm = enabled && in.head_prev.matrix() == in.head.matrix() && !in.wind.active();
  if (!calm) {
    all_asleep_ = false;
    std::fill(asleep_.begin(), asleep_.end(), std::uint8_t{0});
    std::fill(quiet_frames_.begin(), quiet_frames_.end(), 0);
  }
  return calm;
}

void StrandSleep::observe(std::size_t s, std::span<const Vec4f> pos, std::span<const Vec4f> prev, float dt) {
  float travel2 = 0.0f;
  for (std::size_t i = 0; i < pos.size(); ++i)
    travel2 = std::max(travel2, (pos[i].head<3>() - prev[i].head<3>()).squaredNorm());
  observe_travel(s, travel2, dt);
}

void StrandSleep::observe_steps(std::size_t s, std::span<const Vec4f> step, float dt) {
  float travel2 = 0.0f;
  for (const Vec4f& d : step) travel2 = std::max(travel2, d.head<3>().squaredNorm());
  observe_travel(s, travel2, dt);
}

void StrandSleep::observe_travel(std::size_t s, float travel2, float dt) {
  const float limit = kRestSpeed * dt;
  if (travel2 < limit * limit) {
    if (++quiet_frames_[s] >= kQuietFrames) asleep_[s] = 1;
  } else {
    quiet_frames_[s] = 0;
  }
}

void StrandSleep::observe_speed(std::size_t s, float speed) {
  if (speed < kRestSpeed) {
    if (++quiet_frames_[s] >= kQuietFrames) asleep_[s] = 1;
  } else {
    quiet_frames_[s] = 0;
  }
}

std::size_t StrandSleep::asleep_count() const {
  return static_cast<std::size_t>(std::count(asleep_.begin(), asleep_.end(), std::uint8_t{1}));
}

}  // namespace hairbench
