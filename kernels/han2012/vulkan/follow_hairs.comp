// TressFX follow hairs from the simulated guides, on the device, after han_step.comp in
// the same submission: each follow vertex is its guide vertex plus a fixed offset in the
// guide's root frame (scenarios/tfx/follow_hairs.cpp, apply_follow_hairs: the same
// formula, in float where the CPU works in double and rounds once). One invocation per
// follow vertex.
#version 450
#extension GL_GOOGLE_include_directive : require

#include "han_layout.h"

layout(local_size_x = HAN_VK_GROUP_SIZE) in;

// Where the follow vertices start in the position buffer (the guides' vertex count), and
// how many there are.
layout(constant_id = 0) const uint GUIDE_VERTICES = 0;
layout(constant_id = 1) const uint FOLLOW_VERTICES = 0;

layout(std430, binding = HAN_VK_FOLLOW_BIND_POS) buffer PosBuf { vec4 g_pos[]; };
layout(std430, binding = HAN_VK_FOLLOW_BIND_STRANDS) readonly buffer StrandBuf { HanFollowStrand g_strands[]; };
layout(std430, binding = HAN_VK_FOLLOW_BIND_VERTICES) readonly buffer VertexBuf { HanFollowVertex g_vertices[]; };

vec3 unit(vec3 v) { return v / sqrt(dot(v, v)); }

// any_perpendicular: t x (the axis farther from t), normalised.
vec3 any_perpendicular(vec3 t) {
  const vec3 axis = abs(t.x) < 0.5 ? vec3(1.0, 0.0, 0.0) : vec3(0.0, 1.0, 0.0);
  return unit(cross(t, axis));
}

void main() {
  const uint v = gl_GlobalInvocationID.x;
  if (v >= FOLLOW_VERTICES) return;
  const vec3 offset = g_vertices[v].offset;
  const HanFollowStrand s = g_strands[g_vertices[v].strand];
  const uint i = v - s.first;
  const vec4 g = g_pos[s.guide_begin + i];

  // root_frame: the tangent along the guide's root edge, the normal towards the anchor
  // (perpendicular_part), the binormal t x n. Root and anchor are pinned, so the frame
  // turns exactly with the head.
  const vec3 root = g_pos[s.guide_begin].xyz;
  const vec3 t = unit(g_pos[s.guide_begin + 1u].xyz - root);
  const vec3 a = g_pos[s.anchor].xyz - root;
  const vec3 p = a - dot(a, t) * t;
  const float pn = sqrt(dot(p, p));
  const vec3 n = pn > 1e-12 * (1.0 + sqrt(dot(a, a))) ? p / pn : any_perpendicular(t);
  const vec3 b = cross(t, n);

  const vec3 out_xyz = ((g.xyz + offset.x * t) + offset.y * n) + offset.z * b;
  g_pos[GUIDE_VERTICES + v] = vec4(out_xyz, i < 2u ? 0.0 : g.w);
}
