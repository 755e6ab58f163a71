// Pieces shared by the structure-of-arrays block kernels (han_soa, halen_soa): the
// per-stage clock of sampled blocks and the head transform in Eigen's evaluation order.
#pragma once

#include "core/stage.h"

#include <chrono>
#include <cstddef>
#include <cstdint>

namespace hairbench::kernels::soa {

// Adds the nanoseconds since the last lap to ns[stage_index(stage)] (kStageCount entries);
// does nothing when ns is null (a block that is not sampled), so unsampled blocks read no
// clock.
class StageClock {
 public:
  explicit StageClock(std::int64_t* ns) : ns_(ns) {
    if (ns_) last_ = now();
  }
  void lap(Stage stage) {
    if (!ns_) return;
    const std::int64_t t = now();
    ns_[stage_index(stage)] += t - last_;
    last_ = t;
  }

 private:
  static std::int64_t now() {
    return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now().time_since_epoch())
        .count();
  }
  std::int64_t* ns_;
  std::int64_t last_ = 0;
};

// The next job's memory, requested a few cache lines at a time while this job computes.
// A block's rows are too short for the hardware prefetchers to ramp up, and one burst
// of a few hundred prefetches fills the core's miss buffers and stalls the job's own
// loads. Spread over the job, the lines arrive as this job's own lines are last used.
class LineFeed {
 public:
  static constexpr int kMaxRanges = 40;
  static constexpr std::size_t kLine = 64;

  void clear() {
    ranges_ = range_ = 0;
    lines_ = 0;
  }
  // Adds [p, p + bytes); ranges past kMaxRanges are left to the hardware.
  void add(const void* p, std::size_t bytes) {
    if (ranges_ == kMaxRanges || bytes == 0) return;
    const std::uintptr_t b = reinterpret_cast<std::uintptr_t>(p) & ~(kLine - 1);
    const std::uintptr_t e = reinterpret_cast<std::uintptr_t>(p) + bytes;
    begin_[ranges_] = b;
    end_[ranges_] = e;
    lines_ += (e - b + kLine - 1) / kLine;
    if (ranges_++ == 0) cursor_ = b;
  }
  // Spreads the lines over `steps` calls of step().
  void pace(int steps) { per_step_ = steps > 0 ? (lines_ + static_cast<std::size_t>(steps) - 1) / steps : lines_; }
  void step() { issue(per_step_); }
  void finish() { issue(lines_); }

 private:
  void issue(std::size_t k) {
    for (; k > 0 && range_ < ranges_; --k) {
      __builtin_prefetch(reinterpret_cast<const void*>(cursor_), 1, 3);
      cursor_ += kLine;
      if (cursor_ >= end_[range_] && ++range_ < ranges_) cursor_ = begin_[range_];
    }
  }
  std::uintptr_t begin_[kMaxRanges], end_[kMaxRanges];
  std::uintptr_t cursor_ = 0;
  int ranges_ = 0, range_ = 0;
  std::size_t lines_ = 0, per_step_ = 0;
};

// The head transform (row-major linear part m, translation t) in locals, so the
// vectoriser sees no aliasing with the rows, applied as Eigen evaluates
// Affine3f · Vector3f: t + ((m00 x + m01 y) + m02 z). Same bits as the per-strand kernels.
struct AffinePose {
  float m0, m1, m2, m3, m4, m5, m6, m7, m8, t0, t1, t2;
  AffinePose(const float* m, const float* t)
      : m0(m[0]), m1(m[1]), m2(m[2]), m3(m[3]), m4(m[4]), m5(m[5]), m6(m[6]), m7(m[7]), m8(m[8]), t0(t[0]),
        t1(t[1]), t2(t[2]) {}
  float x(float a, float b, float c) const { return t0 + ((m0 * a + m1 * b) + m2 * c); }
  float y(float a, float b, float c) const { return t1 + ((m3 * a + m4 * b) + m5 * c); }
  float z(float a, float b, float c) const { return t2 + ((m6 * a + m7 * b) + m8 * c); }
};

// One frame of a block kernel: its substeps (head pose and colliders, computed once per
// step for every block) and the forces. The wind is the wind acceleration, used only
// when windy.
template <class SubstepT>
struct BlockFrame {
  const SubstepT* substeps;
  int substep_count;
  float gravity[3];
  float wind[3];
  bool windy;
};

}  // namespace hairbench::kernels::soa
