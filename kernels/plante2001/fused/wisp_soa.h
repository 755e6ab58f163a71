// The integration of Plante et al. 2001 (§5.1 steps 1, 3 and 4: forces, velocities,
// positions and section frames) for a block of kLanes wisps at once, one wisp per lane.
// Every lane performs the floating-point operations of the per-wisp kernels
// (wisp_kernels.h) in their order, so a wisp gets the same bits either way; the per-wisp
// kernels stay the reference (plante_wisp_ref) and take over for any wisp of a block that
// meets one of their rare branches (a zero-length segment, a frame fallback axis, a
// half-turn minimal rotation). Compiled once per ISA variant and chosen at run time, like
// the Han and Halén block kernels (kernels/CMakeLists.txt).
#pragma once

#include "kernels/plante2001/reference/wisp_kernels.h"

namespace hairbench::kernels {
struct SegmentGrid;
}

namespace hairbench::kernels::wisp_soa {

inline constexpr int kLanes = 16;
// Longest wisp (in nodes) a block takes; longer ones go through the per-wisp kernels.
inline constexpr int kMaxNodes = 32;

// Whether wisp w can be a lane of a block: between 3 and kMaxNodes nodes.
bool block_eligible(const WispSystem& s, std::size_t w);

// The `count` wisps `wisps` (1 <= count <= kLanes; each block_eligible, all of one node
// count and one params set): wisp_forces_and_velocities for each (after wisp_pin). A
// block of fewer than kLanes wisps repeats its first in the other lanes, whose results
// are dropped.
using VelocitiesFn = void (*)(WispSystem& s, const std::uint32_t* wisps, int count, const WispParams& p,
                              const Eigen::Matrix3f& head_rot, const Vec3f& gravity, const Wind& wind, float h);
// wisp_positions for each, root_e1[l] the head-attached first axis of wisps[l].
using PositionsFn = void (*)(WispSystem& s, const std::uint32_t* wisps, int count, const Vec3f* root_e1, float h);

// The narrow phase of the wisp-wisp interactions on a SegmentGrid (wisp_grid.h):
// segments [begin, end) against every later segment sharing a cell with it: bounding
// boxes, then the masses of each segment (node seg+1 and its envelope) tested against
// the other's volume (§4.1). Segments of one wisp closer than
// three apart along it are never a pair (neighbours touch by construction). The contacts
// come in a fixed order (segment, then cell, then segment index), so splitting the range
// across threads and concatenating the outputs in range order gives the serial list.
// Same contacts in the same order as grid_contacts_ref.
using ContactsFn = void (*)(const SegmentGrid& g, const WispSystem& s, std::size_t begin, std::size_t end,
                            std::vector<WispContact>& out);

// What contact_impulse reads of a node, as two rows of 16 floats: the impulse kernel
// takes a contact's point node and its segment's two nodes as whole rows, 16 contacts at
// a time, and turns them into lanes by transposes (copied lane by lane, about 45 moves a
// contact, they would take most of the kernel's time). Copies of the state, so the
// lanes get the bits they would read from it.
struct alignas(64) ContactNode {
  enum : int { kX = 0, kV = 3, kN = 6, kR = 9, kRRest = 13, kEnvelopeMass = 14 };  // row `a`
  enum : int { kE1 = 0, kE2 = 3, kRdot = 6 };                                      // row `b`
  float a[16];  // x, v, n, the envelope radii r, r_rest, the envelope mass of the node's wisp
  float b[16];  // e1, e2, the envelope rates rdot
};
// ContactNode of nodes [begin, end) into out[begin, end).
void contact_nodes(const WispSystem& s, std::span<const WispParams> params, std::size_t begin, std::size_t end,
                   ContactNode* out);

// contact_impulse (wisp_kernels.h) of contacts [begin, end) into out[begin, end), with
// the same bits; `nodes` holds every node's ContactNode of the current state.
using ImpulsesFn = void (*)(const WispSystem& s, const ContactNode* nodes, std::span<const WispContact> contacts,
                            std::size_t begin, std::size_t end, const InteractionParams& ip,
                            std::span<const WispParams> params, float h, ContactImpulse* out);

// The rebuild's strand points (§5.2) of one strand of n vertices, vertex i at
// coordinates coord[i] relative to node node[i]: strand_point (from every node's
// NodeSection, `sections`) into point[i] and section_weight into weight[i], 16 vertices
// at a time, with the per-vertex kernel's bits.
using StrandPointsFn = void (*)(const WispSystem& s, const NodeSection* sections, const std::uint32_t* node,
                                const Vec4f* coord, std::uint32_t n, Vec3f* point, float* weight);

// A BodyStep as the lane kernels read it, in plain floats: Eigen's fixed-size types may
// be aligned, so laid out, differently in the ISA variants' builds (AVX-512 aligns a
// 4 x 4 matrix to 64 bytes), so the variants do not read a BodyStep itself.
struct BodyLanes {
  const float* spheres;        // per sphere: xyz centre, radius
  std::size_t count;           // spheres
  const std::int32_t* moves;   // BodyStep::moves
  float motion[3][4];          // the rows of BodyStep::motion's matrix
  float h;
  explicit BodyLanes(const BodyStep& body);
};

// plante_wisp's wisp-body passes between detections for the wisps [first, first +
// count), over the contacts wisp_body_list listed: wisp_body_slide (its skeleton
// masses, then its envelope masses) and wisp_body_hold, 16 masses at a time, with the
// per-wisp kernels' bits.
using BodySlideFn = void (*)(WispSystem& s, std::uint32_t first, std::uint32_t count, const BodyLanes& body,
                             float drag);
using BodyHoldFn = void (*)(WispSystem& s, std::uint32_t first, std::uint32_t count, const BodyLanes& body);
// wisp_body_detect for the block's wisps (as VelocitiesFn) where none of a wisp's masses
// is inside a body: their contacts are recorded. Returns the lanes (bit l: wisps[l])
// with a mass inside, which it leaves untouched for wisp_body_detect.
using BodyDetectFn = std::uint32_t (*)(WispSystem& s, const std::uint32_t* wisps, int count, const BodyLanes& body,
                                       float threshold);

struct Kernels {
  VelocitiesFn velocities;
  PositionsFn positions;
  ContactsFn contacts;
  ImpulsesFn impulses;
  StrandPointsFn strand_points;
  BodySlideFn body_slide;
  BodyHoldFn body_hold;
  BodyDetectFn body_detect;
};

// The variant for this CPU.
Kernels kernels();
// The baseline variant, for the tests that compare ISA variants.
Kernels kernels_baseline();

}  // namespace hairbench::kernels::wisp_soa
