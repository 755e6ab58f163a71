// Halén & Wester 2007's spring (§4.4) and cascading spaces (§4.3) models as one fused
// pass per block of strands, structure of arrays: a block holds kLanes strands of one
// region and one vertex count, field by field and vertex by vertex ([field][vertex][lane]),
// so one vector instruction advances kLanes strands. A block's positions and previous
// positions live in this layout across frames; the pass keeps the block in L1 through
// every substep's stages (references, integration, edge corrections, collisions), then
// writes the positions of the lanes asked for to the groom-ordered float4 array (the
// HairModel interface).
//
// Every lane performs the same floating-point operations in the same order as the
// per-strand kernels of strand_kernels.cpp and halen_kernels.cpp, with Eigen's evaluation
// order written out (baseline build): affine · v = t + ((m00 v0 + m01 v1) + m02 v2),
// Matrix3f · v and Matrix3f · Matrix3f = a0 b0 + (a1 b1 + a2 b2) per coefficient, dot
// products and squared norms x + (y + z). FMA contraction is off (top CMakeLists.txt), so
// the states are bit-identical to halen_spring_ref / halen_cascade_ref on any ISA variant
// and for any thread count.
#pragma once

#include "kernels/simd/soa_common.h"

#include <cstddef>
#include <cstdint>

namespace hairbench::kernels::halen_soa {

inline constexpr int kLanes = 16;

enum class Model : int { Spring, Cascade, Forest };

// Read-only fields of a block, each n rows of kLanes floats.
enum Field : int {
  RX, RY, RZ,  // rest positions in the head's rest frame (the spring model's reference nodes)
  IW,          // inverse mass (0 = pinned)
  RL,          // rest length of edge (i-1, i), 0 at the root
  LIFT,        // upward displacement of the reference nodes per unit gravity (L = mg/k)
  KU,          // spring model: k_L; cascade: the upward springs' k
  kSpringFields,
  KD = kSpringFields,  // cascade: the downward springs' k
  UX, UY, UZ,          // cascade: upward reference nodes in their tangent spaces
  DX, DY, DZ,          // cascade: downward reference nodes in their tangent spaces
  BS,                  // cascade: j - base[j] of the rigid segment carrying space j, 0 = the head's
  LV,                  // cascade: that segment's rest length (cascade_setup's lever)
  kCascadeFields
};
// The cascade keeps the given tangent space at the root ([B N T], 9 rows, column by
// column) after its fields.
inline constexpr int kRootSpaceRows = 9;
inline constexpr std::size_t block_floats(Model m, int n) {  // Spring or Cascade
  return m == Model::Spring ? static_cast<std::size_t>(kSpringFields * n) * kLanes
                            : static_cast<std::size_t>(kCascadeFields * n + kRootSpaceRows) * kLanes;
}
// The state of a block (Spring or Cascade), n rows of kLanes floats each, persistent
// across frames.
// Positions, and the spring model's previous positions or the cascade's last steps.
enum StateField : int { PX, PY, PZ, QX, QY, QZ, kStateFields };
inline constexpr std::size_t state_floats(int n) { return static_cast<std::size_t>(kStateFields * n) * kLanes; }
// Per-thread scratch for a block of n vertices: the cascade's spring accelerations, and
// per space the springs' load on its twist, its bend's κ and whether the bend is taken.
inline constexpr std::size_t scratch_floats(int n) { return static_cast<std::size_t>(8 * n) * kLanes; }

// What a row (one vertex of every lane) holds: most rows are all free or all pinned.
enum RowKind : std::uint8_t { kRowFree, kRowPinned, kRowMixed };

struct Block {
  const float* data;              // block_floats(model, n) floats
  float* state;                   // state_floats(n) floats
  int n;                          // vertices per strand
  const std::uint32_t* offset;    // per lane: the strand's first vertex in the float4 arrays
  const RowKind* rows;            // n entries
  const std::uint8_t* write;      // per lane: 1 = write its positions out (awake, not a repeat)
};

// Per-region settings of a block.
struct BlockParams {
  float keep;                // 1 - damping
  int length_iterations;
  const float* spring_scale; // spring model: §4.4's tilt factor k_m / k per substep
  bool reactions;            // cascade: the springs push back on their spaces' segments
  bool transport;            // cascade: CascadeFrames::Transport (else Cross)
};

// One substep's head pose and colliders, computed once per step for every block.
struct Substep {
  float m[9];  // head linear part, row-major
  float t[3];  // head translation
  float dt2;
  float hg[3];  // cascade: gravity turned by the head (head linear part · gravity)
  const float* spheres;  // world-space x, y, z, r
  int sphere_count;
};

using Frame = soa::BlockFrame<Substep>;

// ---- the interactive forest (§4.2, §5.9) ---------------------------------------------
//
// The same blocks for halen_forest, with its own fields. Unlike the spring models, the
// forest's lanes do not repeat the per-strand kernels' operations bit for bit: the joint
// rotation R_primary(θ) R_y(φ) is written in closed form and sin/cos are a vectorisable
// polynomial (kernels/simd/vec_math.h), so the kernel agrees with halen_forest_ref to rounding
// (tests/halen_fused_test.cpp bounds the difference).
enum ForestField : int {
  FRX, FRY, FRZ,  // rest positions in the head's rest frame
  FIW,            // inverse mass (0 = pinned: the segment ending here is rigid with the head)
  FLEN,           // segment length L_i
  FTH0, FPH0,     // rest angles
  FK,             // joint stiffness per unit inertia
  FR0, FR1, FR2, FR3, FR4, FR5, FR6, FR7, FR8,  // rest frame (head at identity), column by column
  kForestFields
};
// A lane's 1/ℓ (forest_integrate), one row after the fields.
inline constexpr std::size_t forest_block_floats(int n) {
  return static_cast<std::size_t>(kForestFields * n + 1) * kLanes;
}
enum ForestState : int { TH, PH, DTH, DPH, kForestStateFields };  // joint angles and their rates
inline constexpr std::size_t forest_state_floats(int n) {
  return static_cast<std::size_t>(kForestStateFields * n) * kLanes;
}
// Scratch: every vertex's frame, position and joint torque.
inline constexpr std::size_t forest_scratch_floats(int n) { return static_cast<std::size_t>(15 * n) * kLanes; }

struct ForestSubstep {
  float m[9];        // head linear part, row-major
  float t[3];        // head translation
  float inertia[12]; // a(p) = inertia · (p, 1), row-major 3x4
  float root_angular[3];  // ForestForces::root_angular_acceleration
  const float* spheres;  // world-space x, y, z, r
  int sphere_count;
};
// substeps: substep_count of them, then the frame's final head pose.
struct ForestFrame : soa::BlockFrame<ForestSubstep> {
  bool parent_x;  // ForestAxes::ParentX (else ParentZ)
  bool mass_inertia;          // ForestInertia::Mass (else StrandPendulum)
  bool gravity_compensation;  // ForestForces::gravity_compensation
  float dt;
};
struct ForestParams {
  float joint_damping;
  float drag;  // s^-1; the joint rates are kept exp(-drag dt) a step (forest_integrate)
  float collision_stiffness;
  float collision_damping;  // ζ of forest_integrate's damped penalty
};
using ForestFrameFn = void (*)(const Block& block, const ForestParams& params, const ForestFrame& frame, float* out,
                               float* scratch, soa::LineFeed& feed, std::int64_t* stage_ns);
ForestFrameFn forest_kernel();
ForestFrameFn forest_kernel_baseline();

// Advances every lane of one block by one frame and writes the xyz of the lanes with
// write[l] set to `out` (float4 per vertex, groom order). scratch holds scratch_floats(n)
// floats. feed holds the next block's memory, requested stage by stage (soa::LineFeed).
// With stage_ns non-null, adds the nanoseconds spent in each Stage (callers pass it for a
// sample of blocks only).
using FrameFn = void (*)(Model model, const Block& block, const BlockParams& params, const Frame& frame, float* out,
                         float* scratch, soa::LineFeed& feed, std::int64_t* stage_ns);

// The variant for this CPU: x86-64-v4 (AVX-512) when the CPU has it, else the baseline
// build. Both give the same bits (the forest's too: its polynomial is the same code).
FrameFn frame_kernel();
// The baseline variant, for the tests that compare ISA variants.
FrameFn frame_kernel_baseline();

}  // namespace hairbench::kernels::halen_soa
