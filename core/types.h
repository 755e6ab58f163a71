// Plain value types shared by the harness, the kernels and every model.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <cstdint>
#include <optional>
#include <span>

namespace hairbench {

using Vec3f = Eigen::Vector3f;
// Vertex positions are float4: xyz in metres, w = inverse mass (0 = pinned), the layout
// of TressFX and of the GPU buffers, so CPU and Vulkan models share one memory picture.
using Vec4f = Eigen::Vector4f;
using Quatf = Eigen::Quaternionf;
using Affine3f = Eigen::Affine3f;

// A collision sphere. Head-attached spheres are given in the head's rest frame and move
// with the head transform; the others are fixed in the world.
struct Sphere {
  Vec3f center = Vec3f::Zero();
  float radius = 0.0f;
  bool head_attached = true;
};

// Wind as an acceleration (m/s^2) acting on the part of each edge it meets face-on.
struct Wind {
  Vec3f direction = Vec3f::UnitX();  // unit length
  float strength = 0.0f;             // m/s^2
  bool active() const { return strength != 0.0f; }
  Vec3f acceleration() const { return direction * strength; }
};

// Everything a model is told about one step. The harness evaluates the head script at
// both ends of the step (never accumulates), so every model gets bit-identical input.
struct FrameInput {
  int frame = 0;          // index of the step, 0-based
  double t = 0.0;         // time at the END of the step, seconds
  double dt = 0.0;        // step length, seconds
  Affine3f head_prev = Affine3f::Identity();  // head rest -> world at t - dt
  Affine3f head = Affine3f::Identity();       // head rest -> world at t
  Vec3f gravity = Vec3f::Zero();
  Wind wind;
  std::span<const Sphere> colliders;
  // Gravity as the head sees it in its rest orientation, for a model whose forces are
  // fixed to the head (Halén & Wester §4.4: a displacement "kept static in relation to
  // the base", a stiffness that weakens as the head tilts from up). Unset, as in every
  // scripted run, it is `gravity`: the step works in the world, whose frame is the head's
  // at rest. A step that works in another frame (the rest twin, harness/twin.h, steps in
  // the head's frame at its final pose) sets it, so that such a model sees the same head.
  std::optional<Vec3f> rest_gravity;
  Vec3f gravity_at_rest() const { return rest_gravity ? *rest_gravity : gravity; }
};

// Head transform at a fraction s in [0, 1] of the step: slerp of the rotation and lerp
// of the translation between the two ends, for models that substep.
Affine3f interpolate_head(const Affine3f& a, const Affine3f& b, float s);

// World-space centre of a collider under head transform `head`.
inline Vec3f collider_center(const Sphere& s, const Affine3f& head) {
  return s.head_attached ? Vec3f(head * s.center) : s.center;
}

// The colliders as world-space x, y, z, radius quadruples under head transform `head`
// (the sphere arrays of the block kernels); out holds 4 * colliders.size() floats.
inline void write_spheres(std::span<const Sphere> colliders, const Affine3f& head, float* out) {
  for (std::size_t c = 0; c < colliders.size(); ++c) {
    const Vec3f center = collider_center(colliders[c], head);
    out[4 * c] = center.x();
    out[4 * c + 1] = center.y();
    out[4 * c + 2] = center.z();
    out[4 * c + 3] = colliders[c].radius;
  }
}

}  // namespace hairbench
