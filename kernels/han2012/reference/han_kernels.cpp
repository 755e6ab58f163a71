#include "kernels/han2012/reference/han_kernels.h"

#include "kernels/common/strand_kernels.h"
#include "kernels/han2012/frames.h"

#include <algorithm>
#include <cmath>
#include <vector>

namespace hairbench::kernels {

namespace {
Vec3f xyz(const Vec4f& v) { return v.head<3>(); }
}  // namespace

void global_shape(std::span<Vec4f> pos, std::span<const Vec4f> rest, const Affine3f& head,
                  float stiffness, float range, bool ramp) {
  const float reach = range * static_cast<float>(pos.size());
  for (std::size_t i = 0; i < pos.size() && static_cast<float>(i) < reach; ++i) {
    if (pos[i].w() == 0.0f) continue;
    const float s = ramp ? stiffness * (1.0f - static_cast<float>(i) / reach) : stiffness;
    const Vec3f goal = head * xyz(rest[i]);
    pos[i].head<3>() += s * (goal - xyz(pos[i]));
  }
}

void init_rest_frames(std::span<const Vec4f> rest, std::span<Quatf> rest_rotation,
                      std::span<Vec3f> rest_local) {
  const std::size_t n = rest.size();
  rest_rotation[0] = root_frame((xyz(rest[1]) - xyz(rest[0])).normalized());
  rest_local[0] = Vec3f::Zero();
  for (std::size_t i = 1; i < n; ++i) {
    const Vec3f edge = xyz(rest[i]) - xyz(rest[i - 1]);
    const Quatf& parent = rest_rotation[i - 1];
    rest_local[i] = parent.conjugate() * edge;  // ^{i-1}P_i^0
    // Algorithm 2 line 8: ^{i-1}T_i^0 is the rotation from (1,0,0) to ^{i-1}x_i^0.
    rest_rotation[i] = (parent * rotation_from_x(rest_local[i].normalized())).normalized();
  }
}

void init_rounding_sized_frames(std::span<const float> rest_length, std::span<const Vec3f> rest_local,
                                std::span<std::uint8_t> rounding_sized, std::span<Quatf> rest_relative) {
  std::fill(rounding_sized.begin(), rounding_sized.end(), std::uint8_t{0});
  std::fill(rest_relative.begin(), rest_relative.end(), Quatf::Identity());
  const float shortest = rounding_sized_length(rest_length);
  for (std::size_t i = 1; i < rest_length.size(); ++i) {
    if (!(rest_length[i] < shortest)) continue;
    rounding_sized[i] = 1;
    rest_relative[i] = rotation_from_x(rest_local[i].normalized());
  }
}

namespace {
// Frame of vertex i from its parent's frame and the current edge (Algorithm 3, lines
// 10-12): ^{i-1}x_i = R_{i-1}^T x_i, then R_i = R_{i-1} · rot(x → ^{i-1}x_i). The edge is
// read in the parent's world frame `world`; the result is composed onto `parent`, which
// is `world` itself (method 1) or its head-relative form, world = R_H · parent (method 2).
Quatf child_frame(const Quatf& parent, const Quatf& world, const Vec4f& a, const Vec4f& b) {
  const Vec3f edge = xyz(b) - xyz(a);
  const float len = edge.norm();
  if (!(len > 0.0f)) return parent;
  return (parent * rotation_from_x(world.conjugate() * (edge / len))).normalized();
}
}  // namespace

void local_shape_m1(std::span<Vec4f> pos, std::span<const Quatf> rest_rotation,
                    std::span<const Vec3f> rest_local, const Quatf& head_rotation, float stiffness) {
  const std::size_t n = pos.size();
  if (n < 3) return;
  // Vertices 0 and 1 are pinned: their frames are the head-transformed rest frames
  // (Algorithm 3, line 6).
  Quatf frame = head_rotation * rest_rotation[1];
  for (std::size_t i = 2; i < n; ++i) {
    const Vec3f goal = xyz(pos[i - 1]) + frame * rest_local[i];
    local_shape_edge(pos[i - 1], pos[i], goal, stiffness);
    frame = child_frame(frame, frame, pos[i - 1], pos[i]);
  }
}

void local_shape_m2(std::span<Vec4f> pos, std::span<Quatf> rotation, std::span<Quatf> scratch,
                    std::span<const Quatf> rest_rotation, std::span<const Vec3f> rest_local,
                    std::span<const std::uint8_t> rounding_sized, std::span<const Quatf> rest_relative,
                    const Quatf& head_rotation, float stiffness) {
  const std::size_t n = pos.size();
  if (n < 3) return;
  // The transforms are kept relative to the head (line 13 applies the constraint "using
  // wT_temp_{i-1} and wT_H"): a head motion between iterations does not make them stale,
  // and those of the pinned vertices 0 and 1 (line 10) are their rest frames.
  rotation[0] = rest_rotation[0];
  rotation[1] = rest_rotation[1];
  // Line 5: wT_temp_i <- wT_i; every goal and every parent frame is read from the copy.
  for (std::size_t i = 0; i < n; ++i) scratch[i] = rotation[i];
  // Lines 12-16 are one thread's work on vertex i: its constraint, then its frame from
  // the edge that constraint has just corrected, before the other batch (§5) moves the
  // edge's ends again. Line 14's ^{i-1}x_i is the direction of a rest edge that may be
  // rounding-sized, and then it is rounding noise: read anew each iteration, the noise
  // would persist in these frames (they are state, unlike method 1's, which are rebuilt
  // from the root every iteration) and feed back through every goal below the edge. Such
  // a vertex takes the rest relative rotation ^{i-1}T_i^0 instead, the frame its rest
  // state says.
  for (std::size_t first : {std::size_t{2}, std::size_t{3}})
    for (std::size_t i = first; i < n; i += 2) {
      const Quatf parent = head_rotation * scratch[i - 1];
      const Vec3f goal = xyz(pos[i - 1]) + parent * rest_local[i];
      local_shape_edge(pos[i - 1], pos[i], goal, stiffness);
      rotation[i] = rounding_sized[i] ? (scratch[i - 1] * rest_relative[i]).normalized()
                                      : child_frame(scratch[i - 1], parent, pos[i - 1], pos[i]);
    }
}

void local_shape_m3(std::span<Vec4f> pos, std::span<const Vec4f> rest, const Quatf& head_rotation,
                    float stiffness) {
  const std::size_t n = pos.size();
  for (std::size_t first : {std::size_t{2}, std::size_t{3}})
    for (std::size_t i = first; i < n; i += 2) {
      const Vec3f goal = xyz(pos[i - 1]) + head_rotation * (xyz(rest[i]) - xyz(rest[i - 1]));
      local_shape_edge(pos[i - 1], pos[i], goal, stiffness);
    }
}

}  // namespace hairbench::kernels
