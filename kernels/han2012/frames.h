// Rotation helpers for the local frames of Han & Harada §3.1/§4: the frame of vertex i
// has its x axis along the edge P_i - P_{i-1}.
#pragma once

#include "core/types.h"

namespace hairbench::kernels {

// The minimal rotation taking (1, 0, 0) to the unit vector v ("rotation from vector
// (1, 0, 0) to x", Algorithms 2-4). For v = -x, where the minimal rotation is not
// unique, it turns half a revolution about z, so the result is always defined.
inline Quatf rotation_from_x(const Vec3f& v) {
  const float w = 1.0f + v.x();
  if (w < 1e-6f) return Quatf(0.0f, 0.0f, 0.0f, 1.0f);
  // axis = x × v = (0, -v.z, v.y); the quaternion (1 + x·v, x × v) normalised is the
  // half-angle form of that rotation.
  return Quatf(w, 0.0f, -v.z(), v.y()).normalized();
}

// The rest frame of a strand's root (Algorithm 2, line 4): x_0 along P_1 - P_0, y_0 from
// x_0 crossed with an arbitrary vector, or with another, orthogonal one when the first
// is (nearly) parallel to x_0 (§4.1).
inline Quatf root_frame(const Vec3f& x0) {
  Vec3f y = x0.cross(Vec3f::UnitZ());
  if (y.squaredNorm() < 1e-8f) y = x0.cross(Vec3f::UnitY());
  y.normalize();
  const Vec3f z = x0.cross(y);
  Eigen::Matrix3f m;
  m.col(0) = x0;
  m.col(1) = y;
  m.col(2) = z;
  return Quatf(m).normalized();
}

}  // namespace hairbench::kernels
