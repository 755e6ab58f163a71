#include "scenarios/head_motion.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace hairbench {

namespace {

// The script is evaluated in double and rounded to float once at the end, so that a
// long clip (large t) or a many-turn spin loses no precision before the model sees it.
struct Pose {
  Eigen::Quaterniond rotation = Eigen::Quaterniond::Identity();
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();
};

Eigen::Quaterniond key_rotation(const HeadKey& k) {
  return Eigen::Quaterniond(Eigen::AngleAxisd(k.angle, k.axis.cast<double>()));
}

Pose key_pose(const HeadKey& k) { return {key_rotation(k), k.translate.cast<double>()}; }

// Smoothstep 3s^2 - 2s^3: zero velocity at both keys, so a smooth segment starts and
// stops without a jolt (the harness measures hair response, not step discontinuities).
double ease(double s, bool linear) { return linear ? s : s * s * (3.0 - 2.0 * s); }

Pose interpolate(const HeadKey& a, const HeadKey& b, double t) {
  const double s = ease((t - a.t) / (b.t - a.t), b.linear);
  Pose p;
  p.translation = a.translate.cast<double>() + s * (b.translate - a.translate).cast<double>();
  if (a.axis == b.axis) {
    // Same axis: interpolate the angle itself, so that one segment can turn through
    // more than 180 degrees (a 720 degree spin); a slerp would take the short way round.
    p.rotation = Eigen::AngleAxisd(a.angle + s * (b.angle - a.angle), a.axis.cast<double>());
  } else {
    p.rotation = key_rotation(a).slerp(s, key_rotation(b));
  }
  return p;
}

Pose keyed_pose(const std::vector<HeadKey>& keys, double t) {
  if (keys.empty()) return {};
  if (t <= keys.front().t) return key_pose(keys.front());
  if (t >= keys.back().t) return key_pose(keys.back());
  const auto b = std::upper_bound(keys.begin(), keys.end(), t,
                                  [](double v, const HeadKey& k) { return v < k.t; });
  return interpolate(*(b - 1), *b, t);
}

double oscillator_value(const Oscillator& o, double t) {
  return o.amplitude * std::sin(2.0 * std::numbers::pi * o.frequency_hz * (t - o.start) + o.phase);
}

// Oscillators act in the world frame about the head centre: world = T * R_osc * R_key,
// so a nod stays a nod whatever the keys have turned the head to.
void add_oscillator(const Oscillator& o, double t, Pose& pose) {
  if (t < o.start || t > o.end) return;
  const double v = oscillator_value(o, t);
  const Eigen::Vector3d axis = o.axis.cast<double>();
  if (o.kind == Oscillator::Kind::Rotate)
    pose.rotation = Eigen::Quaterniond(Eigen::AngleAxisd(v, axis)) * pose.rotation;
  else
    pose.translation += v * axis;
}

}  // namespace

Affine3f HeadMotion::at(double t) const {
  Pose pose = keyed_pose(keys, t);
  for (const Oscillator& o : oscillators) add_oscillator(o, t, pose);
  Affine3f out = Affine3f::Identity();
  out.linear() = pose.rotation.normalized().toRotationMatrix().cast<float>();
  out.translation() = pose.translation.cast<float>();
  return out;
}

}  // namespace hairbench
