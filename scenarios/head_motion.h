// The scripted head motion of a scenario: keyframes plus sinusoidal oscillators,
// evaluated at any time t directly from the script (never integrated or accumulated),
// so every model receives the bit-identical head transform for a frame.
#pragma once

#include "core/types.h"

#include <vector>

namespace hairbench {

struct HeadKey {
  double t = 0.0;
  Vec3f translate = Vec3f::Zero();  // metres
  Vec3f axis = Vec3f::UnitY();      // unit length
  double angle = 0.0;               // radians (files say degrees)
  // How the segment that ENDS at this key is eased: smooth (C1, zero velocity at both
  // keys, smoothstep in time) or linear (constant velocity between the keys).
  bool linear = false;
};

struct Oscillator {
  enum class Kind { Rotate, Translate };
  Kind kind = Kind::Rotate;
  Vec3f axis = Vec3f::UnitY();  // rotation axis, or translation direction (unit length)
  double amplitude = 0.0;       // radians for Rotate, metres for Translate
  double frequency_hz = 1.0;
  double phase = 0.0;           // radians
  double start = 0.0, end = 0.0;  // seconds; active on [start, end]
};

class HeadMotion {
 public:
  std::vector<HeadKey> keys;  // sorted by t; may be empty (identity)
  std::vector<Oscillator> oscillators;

  // head rest frame -> world at time t. Keys: slerp of rotation and lerp of translation
  // between the surrounding keys (held before the first and after the last; two keys
  // with the same axis interpolate the angle, so a segment may turn past 180°); then the
  // oscillators, in file order, add A*sin(2*pi*f*(t-start)+phase) rotation about the
  // head centre or translation along their axis while start <= t <= end.
  Affine3f at(double t) const;
};

}  // namespace hairbench
