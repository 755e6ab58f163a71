// Han & Harada 2012's own constraints, the readable reference kernels: the global shape
// constraint (Eq. 2), the rest-state frames (Algorithm 2) and the local shape constraint
// of methods 1-3 (Eq. 4, Algorithms 3-5), as pure functions over one strand's plain
// arrays (positions are float4: xyz + inverse mass w). The fused block kernels
// (kernels/han2012/fused/) and the shader (kernels/han2012/vulkan/) perform the same
// operations.
#pragma once

#include "core/types.h"

#include <cstdint>
#include <span>

namespace hairbench::kernels {

// Global shape constraint (Han & Harada Eq. 2): P_i += S_G (T_H · P_i^0 - P_i) for the
// free vertices with i < range · n; with `ramp`, S_G falls linearly to 0 at that point
// ("gradually reduce S_G from root of hair to the end", §3.3).
void global_shape(std::span<Vec4f> pos, std::span<const Vec4f> rest, const Affine3f& head,
                  float stiffness, float range, bool ramp);

// Rest-state frames (Algorithm 2): the global rotation of every vertex's frame and the
// position of vertex i in frame i-1, ^{i-1}P_i^0 (index 0 unused).
void init_rest_frames(std::span<const Vec4f> rest, std::span<Quatf> rest_rotation,
                      std::span<Vec3f> rest_local);

// Method 2's frames across rounding-sized rest edges, one strand: rounding_sized[i] is 1
// where edge (i-1, i) is shorter than rounding_sized_length, and there rest_relative[i]
// is ^{i-1}T_i^0, the rotation from (1,0,0) to ^{i-1}x_i^0 (Algorithm 2 line 8, the bits
// init_rest_frames composes: wR_i^0 = wR_{i-1}^0 · ^{i-1}T_i^0, normalised); 0 and the
// identity elsewhere.
void init_rounding_sized_frames(std::span<const float> rest_length, std::span<const Vec3f> rest_local,
                                std::span<std::uint8_t> rounding_sized, std::span<Quatf> rest_relative);

// The local shape constraint for edge (i-1, i) (Han & Harada Eq. 4): with
// d = goal - P_i, P_{i-1} -= S_L d·w_{i-1}/(w_{i-1}+w_i) and P_i += S_L d·w_i/(...).
// Equal masses give the paper's ½ S_L d on each end; a pinned end takes none.
inline void local_shape_edge(Vec4f& a, Vec4f& b, const Vec3f& goal, float stiffness) {
  const float wsum = a.w() + b.w();
  if (wsum == 0.0f) return;
  const Vec3f d = stiffness * (goal - b.head<3>());
  a.head<3>() -= d * (a.w() / wsum);
  b.head<3>() += d * (b.w() / wsum);
}

// Method 1 (Algorithm 3): one serial sweep root to tip; the frame of each vertex is
// rebuilt from the corrected edge right after its constraint, so every goal uses exact,
// current transforms.
void local_shape_m1(std::span<Vec4f> pos, std::span<const Quatf> rest_rotation,
                    std::span<const Vec3f> rest_local, const Quatf& head_rotation, float stiffness);

// Method 2 (Algorithm 4): Jacobi-style. Goals use the frames of the previous iteration
// (`rotation` on entry, copied to `scratch`); constraints run in even/odd edge batches
// (§5), and each edge's frame is rebuilt from its parent's previous-iteration frame right
// after that edge's constraint (lines 12-16, one thread's sequence). `rotation` persists
// across iterations, substeps and frames: the transforms are simulation state (§5).
// Where the rest edge is rounding-sized (init_rounding_sized_frames), the frame is the
// parent's composed with the rest relative rotation rest_relative[i] instead of one
// rebuilt from the edge's direction, which is rounding noise there.
void local_shape_m2(std::span<Vec4f> pos, std::span<Quatf> rotation, std::span<Quatf> scratch,
                    std::span<const Quatf> rest_rotation, std::span<const Vec3f> rest_local,
                    std::span<const std::uint8_t> rounding_sized, std::span<const Quatf> rest_relative,
                    const Quatf& head_rotation, float stiffness);

// Method 3 (Algorithm 5): the rest-state frames under the head rotation, never updated:
// wR_H · wR^0_{i-1} · ^{i-1}P_i^0 is the head-rotated rest edge. Even/odd batches (§5).
void local_shape_m3(std::span<Vec4f> pos, std::span<const Vec4f> rest, const Quatf& head_rotation,
                    float stiffness);

}  // namespace hairbench::kernels
