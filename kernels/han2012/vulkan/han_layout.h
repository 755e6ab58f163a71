// Shared by C++ (models/han2012/vulkan/) and GLSL (han_step.comp, follow_hairs.comp): workgroup
// sizes and the buffer layouts of the Vulkan Han & Harada kernel and of the follow hairs
// built from its guides. The struct declarations below are
// valid in both languages (C++ gets GLSL-named stand-ins for uint, vec3, vec4 and mat4);
// every member is 4 or 16 bytes, or a vec3 followed by a 4-byte member, and vec3/vec4/mat4
// sit at 16-byte offsets, so std430 and the C++ layout agree byte for byte (checked by
// static_asserts in models/han2012/vulkan/han_vulkan.cpp).
#ifndef HAIRBENCH_KERNELS_VULKAN_HAN_LAYOUT_H
#define HAIRBENCH_KERNELS_VULKAN_HAN_LAYOUT_H

// Invocations per workgroup. A workgroup holds GROUP_SIZE / LANES strands, each worked on
// by LANES invocations (a power of two chosen per groom), Han & Harada §5: "each thread
// group takes care of one hair strand", packing several short strands into one group.
#define HAN_VK_GROUP_SIZE 64
// Vertices one invocation owns at most ("a group of vertices in the same batch", §5).
#define HAN_VK_VERTICES_PER_LANE 4
// The longest strand the kernel takes: a whole workgroup's invocations, four vertices
// each, in shared memory.
#define HAN_VK_MAX_STRAND_VERTICES (HAN_VK_GROUP_SIZE * HAN_VK_VERTICES_PER_LANE)
// Per-frame upload capacity: solver passes per frame and collision spheres per pass.
#define HAN_VK_MAX_SUBSTEPS 64
#define HAN_VK_MAX_COLLIDERS 64

// Descriptor bindings (all storage buffers, set 0).
#define HAN_VK_BIND_POS 0          // vec4 per vertex: xyz, w = inverse mass (read/write)
#define HAN_VK_BIND_PREV 1         // vec4 per vertex: Verlet's previous position (read/write)
#define HAN_VK_BIND_ROT 2          // vec4 quaternion per vertex: method 2's frames (read/write)
#define HAN_VK_BIND_REST 3         // vec4 per vertex: rest position (head rest frame)
#define HAN_VK_BIND_REST_LOCAL 4   // vec4 per vertex: xyz = ^{i-1}P_i^0, w = rest edge length
#define HAN_VK_BIND_REST_ROT 5     // vec4 quaternion per vertex: wR_i^0 (Algorithm 2)
#define HAN_VK_BIND_STRANDS 6      // HanStrand per strand
#define HAN_VK_BIND_REGIONS 7      // HanRegion per groom region
#define HAN_VK_BIND_FRAME 8        // HanFrame, then HanSubstep[substeps]
#define HAN_VK_BIND_SPHERES 9      // vec4 (centre, radius) [substep * colliders + c], world space
#define HAN_VK_BINDINGS 10

// The follow hairs kernel (follow_hairs.comp), its own descriptor set. The position
// buffer is the step kernel's: the guides' vertices, then the follow strands' (in
// FollowHairs order), so that one readback brings the whole groom.
#define HAN_VK_FOLLOW_BIND_POS 0      // vec4 per vertex: reads the guides, writes the follow vertices
#define HAN_VK_FOLLOW_BIND_STRANDS 1  // HanFollowStrand per follow strand
#define HAN_VK_FOLLOW_BIND_VERTICES 2  // HanFollowVertex per follow vertex
#define HAN_VK_FOLLOW_BINDINGS 3

// Quaternions are vec4 (x, y, z, w): Eigen's coefficient order.

#ifdef __cplusplus
#include <cstdint>
namespace hairbench::vk_layout {
using uint = std::uint32_t;
struct vec3 { float x, y, z; };
struct vec4 { float x, y, z, w; };
struct mat4 { float m[16]; };  // column-major, as GLSL and Eigen store it
#endif

// One strand: its vertices [begin, begin + count), its region, and the length under
// which its rest edges are rounding-sized (kernels::rounding_sized_length; method 2).
struct HanStrand {
  uint begin;
  uint count;
  uint region;
  float rounding_edge;
};

// Solver settings of one region (models/han2012/settings.h).
struct HanRegion {
  float damping;
  float global_stiffness;
  float global_range;
  float local_stiffness;
  uint local_iterations;
  uint length_iterations;
  uint global_ramp;
  uint pad;
};

// What changes per frame, at the start of the HAN_VK_BIND_FRAME buffer.
struct HanFrame {
  vec4 gravity_dt;  // xyz gravity (m/s^2), w substep length (s)
  vec4 wind;        // xyz wind acceleration (m/s^2), w 1 when the wind blows
  uint substeps;
  uint colliders;
  uint strands;
  uint max_iterations;  // max over regions of local and length iterations
};

// One solver pass: the head interpolated to its end (Algorithm 1 per substep).
struct HanSubstep {
  mat4 head;           // head rest -> world
  vec4 head_rotation;  // wR_H as a quaternion
};

// One follow strand: its guide's vertices [guide_begin, guide_begin + count), the anchor
// vertex (a guide vertex) that orients the guide's root normal, and the index of its
// first vertex among the follow vertices.
struct HanFollowStrand {
  uint guide_begin;
  uint count;
  uint anchor;
  uint first;
};

// One follow vertex: its offset from the guide vertex, (tangent, normal, binormal)
// components in the guide's root frame, and its follow strand.
struct HanFollowVertex {
  vec3 offset;
  uint strand;
};

#ifdef __cplusplus
}  // namespace hairbench::vk_layout
#endif

#endif
