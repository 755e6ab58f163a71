// Shared by C++ (kernels/vulkan/metrics.cpp) and GLSL (metrics.comp): the buffers of the
// harness's metrics kernel. Every member is 4 or 16 bytes and vec4/mat4 sit at 16-byte
// offsets, so std430 and the C++ layout agree byte for byte (static_asserts in
// metrics.cpp, against core/device_metrics.h's StrandMetrics too).
#ifndef HAIRBENCH_KERNELS_VULKAN_METRICS_LAYOUT_H
#define HAIRBENCH_KERNELS_VULKAN_METRICS_LAYOUT_H

// One invocation per strand.
#define METRICS_VK_GROUP_SIZE 64
#define METRICS_VK_MAX_SPHERES 64

// Descriptor bindings (all storage buffers, set 0).
#define METRICS_VK_BIND_POS 0        // vec4 per vertex: the model's positions (read)
#define METRICS_VK_BIND_PREV 1       // vec4 per vertex: the previous frame's positions (read, then written)
#define METRICS_VK_BIND_REFERENCE 2  // vec4 per vertex: the reference's positions (read)
#define METRICS_VK_BIND_REST 3       // vec4 per vertex: rest position (head rest frame)
#define METRICS_VK_BIND_EDGE 4       // vec4 per vertex: rest edge length, edge scale, d0, kb weight
#define METRICS_VK_BIND_OFFSETS 5    // uint per strand and one more: strand offsets
#define METRICS_VK_BIND_FRAME 6      // MetricsFrame
#define METRICS_VK_BIND_OUT 7        // MetricsStrand per strand
#define METRICS_VK_BINDINGS 8

#ifdef __cplusplus
#include <cstdint>
namespace hairbench::vk_layout {
using uint = std::uint32_t;
struct vec4 { float x, y, z, w; };
struct mat4 { float m[16]; };  // column-major, as GLSL and Eigen store it
#endif

struct MetricsFrame {
  mat4 head;          // rest -> world at the end of the frame
  mat4 carry;         // head * head_prev^-1
  vec4 centre_far;    // xyz the head centre, w the blow-up distance from it
  vec4 gravity_dt;    // xyz gravity, w the frame's dt
  uint spheres;
  uint pad0;
  uint pad1;
  uint pad2;
  vec4 sphere[METRICS_VK_MAX_SPHERES];  // world xyz, w radius
};

// core/device_metrics.h StrandMetrics.
struct MetricsStrand {
  float deviation2;
  float jaggedness;
  float length2;
  float length_max;
  uint length_worst;
  float rest2;
  float penetration;
  float energy;
  float kinetic;
  uint bad_vertex;
  uint bad_kind;
  uint pad;
};

#ifdef __cplusplus
}  // namespace hairbench::vk_layout
#endif

#endif
