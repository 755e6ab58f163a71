// 3-vector arithmetic for the lane loops of the wisp kernels (wisp_soa_kernel.cpp,
// wisp_contact_kernel.cpp), in Eigen's evaluation order for 3-vectors, so that a lane
// gets the bits of the per-wisp kernels (wisp_kernels.cpp): a dot product or squared
// norm is x + (y + z) (Eigen's unrolled reduction halves the terms), a vector over a
// scalar divides each component, sums of vector terms go left to right. The kernel
// files are compiled once per ISA variant, so these have internal linkage: each variant
// keeps its own code.
#pragma once

#include <cmath>

namespace hairbench::kernels::wisp_soa {
namespace {

struct F3 {
  float x, y, z;
};
inline F3 sub(F3 a, F3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
inline F3 add(F3 a, F3 b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
inline F3 mul(float s, F3 a) { return {s * a.x, s * a.y, s * a.z}; }
inline F3 quot(F3 a, float s) { return {a.x / s, a.y / s, a.z / s}; }
inline float dot(F3 a, F3 b) { return a.x * b.x + (a.y * b.y + a.z * b.z); }
inline F3 cross(F3 a, F3 b) { return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x}; }
inline F3 pick(bool c, F3 a, F3 b) { return {c ? a.x : b.x, c ? a.y : b.y, c ? a.z : b.z}; }

// unit_or of wisp_kernels.cpp; `bad` is set where the fallback would be taken (set
// without a branch, so that the lane loops stay vector code).
inline F3 unit(F3 v, int& bad) {
  const float n2 = dot(v, v);
  bad |= !(n2 > 1e-24f);
  return quot(v, std::sqrt(n2));
}

}  // namespace
}  // namespace hairbench::kernels::wisp_soa
