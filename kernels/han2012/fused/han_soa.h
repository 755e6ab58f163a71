// Han & Harada 2012 Algorithm 1 as one fused pass per block of strands, structure of
// arrays: a block holds kLanes strands of equal vertex count, field by field and vertex by
// vertex ([field][vertex][lane]), so one vector instruction advances kLanes strands.
// A block stays in L1 through a whole frame: its positions are read from the
// groom-ordered float4 array (the HairModel interface) into rows, then every substep's
// integration, global shape, local shape / edge length iterations and collisions run,
// then one write puts the positions back. The positions live only in that array, not in
// the block as well: method 3's state on the Table 1 model-1 groom is 9.3 MiB rather
// than 12.7, at the cost of a transpose per row per frame.
//
// Every lane performs the same floating-point operations in the same order as the
// per-strand kernels of kernels/han2012/reference/han_kernels.cpp and
// kernels/common/strand_kernels.cpp (with Eigen's evaluation order written out:
// affine · v = t + ((m00 v0 + m01 v1) + m02 v2), |v|² = x² + (y² + z²), Eigen's SSE
// quaternion product and q · v = v + w·2(q×v) + q×2(q×v)), and the build keeps FMA
// contraction off, so the results are bit-identical to the reference models
// (han_m*_ref) on any ISA variant and for any thread count.
#pragma once

#include "kernels/simd/soa_common.h"

#include <cstddef>
#include <cstdint>

namespace hairbench::kernels::han_soa {

inline constexpr int kLanes = 16;
inline constexpr std::uint32_t kNoStrand = 0xffffffffu;

// Fields of a block, each n rows of kLanes floats. Method 1 adds the rest positions of
// every vertex in its parent's frame (^{i-1}P_i^0, Algorithm 2); method 2 adds those and
// the persistent frames (Algorithm 4). The positions and inverse masses are not fields:
// they are the float4 array's (Block::in_offset).
enum Field : int {
  QX, QY, QZ,  // previous positions (Verlet)
  RX, RY, RZ,  // rest positions in the head's rest frame
  RL,          // rest length of edge (i-1, i), 0 at the root
  kM3Fields,
  LX = kM3Fields, LY, LZ,  // ^{i-1}P_i^0
  kM1Fields,
  OW = kM1Fields, OX, OY, OZ,  // method 2's frames wR_i relative to the head, persistent
  kM2Fields
};
inline constexpr int field_count(int method) {
  return method == 3 ? kM3Fields : method == 1 ? kM1Fields : kM2Fields;
}
// Method 1 also keeps the rest frames of vertices 0 and 1 (w, x, y, z each, one row
// of kLanes per component) after the fields.
inline constexpr int kRestFrameRows = 8;
inline constexpr std::size_t block_floats(int method, int n) {
  return static_cast<std::size_t>(field_count(method) * n + (method == 1 ? kRestFrameRows : 0)) * kLanes;
}
// Floats of per-thread scratch a block of n vertices needs (method 3's head-rotated rest
// edges or method 2's copy of the frames, the local constraint's mass weights, and the
// positions and inverse masses read from the float4 array).
inline constexpr std::size_t scratch_floats(int n) { return static_cast<std::size_t>(10 * n) * kLanes; }

// Method 2: a row with a rounding-sized rest edge in some lane (kernels::
// init_rounding_sized_frames, reference/han_kernels.h). `on` is 1 in those lanes and 0 in the
// others; there the frame is the parent's composed with the rest relative rotation
// ^{i-1}T_i^0 (x, y, z, w) rather than rebuilt from the edge's direction, rounding noise.
struct RoundingRow {
  int row;  // the vertex i of edge (i-1, i)
  float on[kLanes];
  float qx[kLanes], qy[kLanes], qz[kLanes], qw[kLanes];
};

// What a row (one vertex of every lane) holds: free and pinned vertices need different
// work, and most rows are all one or the other.
enum RowKind : std::uint8_t { kRowFree, kRowPinned, kRowMixed };

struct Block {
  float* data;                      // block_floats(method, n) floats
  int n;                            // vertices per strand
  int method;                       // 1, 2 or 3 (Han & Harada §4.2)
  const std::uint32_t* out_offset;  // per lane: first vertex in the float4 output, or kNoStrand
  // Per lane: the first vertex in the float4 array to read the positions from. A lane
  // without a strand of its own (kNoStrand out) reads the strand it repeats.
  const std::uint32_t* in_offset;
  const RowKind* rows;              // n entries
  // Method 2: the rows with a rounding-sized rest edge in some lane, by row (none
  // elsewhere, and in most blocks).
  const RoundingRow* rounding_rows;
  int rounding_row_count;
};

// Per-region solver settings, with the stages a region does not need switched off.
struct BlockParams {
  float keep;  // 1 - damping
  float global_stiffness, global_reach;  // reach = global_range · n
  bool global_on, global_ramp;
  float local_stiffness;
  int local_iterations;  // 0 = no local pass and no frame update
  int length_iterations;
};

// One substep's head pose and colliders, precomputed once per step for every block.
struct Substep {
  float m[9];  // head linear part, row-major
  float t[3];  // head translation
  float q[4];  // head rotation quaternion x, y, z, w
  float dt2;
  float gravity_dt2[3];
  const float* spheres;  // world-space x, y, z, r
  int sphere_count;
};

using Frame = soa::BlockFrame<Substep>;


// Advances `count` (1..kMaxBlocks) blocks of one vertex count, method and parameter set
// by one frame, side by side, reading their positions from pos (float4 per vertex, w the
// inverse mass) and writing them back there.
// Two blocks at a time give method 1's serial chains something to overlap with; scratch
// holds count * scratch_floats(n) floats. feed holds the next job's memory, requested
// stage by stage. With stage_ns non-null, adds the nanoseconds spent in each Stage (a
// few clock reads per substep; callers pass it for a sample of blocks only).
inline constexpr int kMaxBlocks = 2;
using FrameFn = void (*)(const Block* blocks, int count, const BlockParams& params, const Frame& frame, float* pos,
                         float* scratch, soa::LineFeed& feed, std::int64_t* stage_ns);

// The variant for this CPU: x86-64-v4 (AVX-512) when the CPU has it, else the baseline
// build. Both give the same bits.
FrameFn frame_kernel();
// The baseline variant, for the tests that compare ISA variants.
FrameFn frame_kernel_baseline();

}  // namespace hairbench::kernels::han_soa
