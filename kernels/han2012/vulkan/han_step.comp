// One frame of Han & Harada 2012, Algorithm 1, for every strand: all substeps of
// integrate, global shape, the local shape / edge length iterations and collisions, with
// the strand's positions in shared memory for the whole frame (§5). The same algorithm
// as models/han2012/reference/ with kernels/han2012/reference/han_kernels.cpp and
// kernels/common/strand_kernels.cpp, operation for operation, so that the
// two agree to float rounding.
#version 450
#extension GL_GOOGLE_include_directive : require

#include "han_layout.h"

layout(local_size_x = HAN_VK_GROUP_SIZE) in;

// Invocations per strand (a power of two dividing HAN_VK_GROUP_SIZE), the method
// (1 Algorithm 3, 2 Algorithm 4, 3 Algorithm 5) and the vertices each invocation owns
// (at most HAN_VK_VERTICES_PER_LANE; as few as the groom allows, since every owned
// vertex costs registers and a loop trip even where the strand is shorter).
layout(constant_id = 0) const uint LANES = 16;
layout(constant_id = 1) const uint METHOD = 1;
layout(constant_id = 2) const uint VPL = 1;

layout(std430, binding = HAN_VK_BIND_POS) buffer PosBuf { vec4 g_pos[]; };
layout(std430, binding = HAN_VK_BIND_PREV) buffer PrevBuf { vec4 g_prev[]; };
layout(std430, binding = HAN_VK_BIND_ROT) buffer RotBuf { vec4 g_rot[]; };
layout(std430, binding = HAN_VK_BIND_REST) readonly buffer RestBuf { vec4 g_rest[]; };
layout(std430, binding = HAN_VK_BIND_REST_LOCAL) readonly buffer RestLocalBuf { vec4 g_rest_local[]; };
layout(std430, binding = HAN_VK_BIND_REST_ROT) readonly buffer RestRotBuf { vec4 g_rest_rot[]; };
layout(std430, binding = HAN_VK_BIND_STRANDS) readonly buffer StrandBuf { HanStrand g_strands[]; };
layout(std430, binding = HAN_VK_BIND_REGIONS) readonly buffer RegionBuf { HanRegion g_regions[]; };
layout(std430, binding = HAN_VK_BIND_FRAME) readonly buffer FrameBuf {
  HanFrame frame;
  HanSubstep g_substeps[];
};
layout(std430, binding = HAN_VK_BIND_SPHERES) readonly buffer SphereBuf { vec4 g_spheres[]; };

// The group's strands, LANES * VPL vertices per strand slot (§5: "loads that
// information into shared memory to take advantage of fast access").
shared vec4 s_pos[HAN_VK_GROUP_SIZE * VPL];
shared vec4 s_prev[HAN_VK_GROUP_SIZE * VPL];
// Method 2's wT_temp (Algorithm 4, line 5).
shared vec4 s_rot[HAN_VK_GROUP_SIZE * VPL];

// Every invocation reaches every sync(): the loops around them run the same number of
// times in the whole group, and per-strand conditions only guard the work between. In a
// Vulkan compute shader barrier() also orders the shared-memory accesses around it.
void sync() { barrier(); }

vec4 qmul(vec4 a, vec4 b) {
  return vec4(a.w * b.x + a.x * b.w + a.y * b.z - a.z * b.y,
              a.w * b.y + a.y * b.w + a.z * b.x - a.x * b.z,
              a.w * b.z + a.z * b.w + a.x * b.y - a.y * b.x,
              a.w * b.w - a.x * b.x - a.y * b.y - a.z * b.z);
}

vec4 qconj(vec4 q) { return vec4(-q.xyz, q.w); }

// q v q*, in the form Eigen uses: v + 2w (q.xyz x v) + q.xyz x (2 q.xyz x v).
vec3 qrot(vec4 q, vec3 v) {
  vec3 uv = cross(q.xyz, v);
  uv += uv;
  return v + q.w * uv + cross(q.xyz, uv);
}

vec4 qnormalize(vec4 q) { return q / sqrt(dot(q, q)); }

// kernels/han2012/frames.h rotation_from_x: the minimal rotation taking (1,0,0) to unit v,
// half a turn about z for v = -x.
vec4 rotation_from_x(vec3 v) {
  float w = 1.0 + v.x;
  if (w < 1e-6) return vec4(0.0, 0.0, 1.0, 0.0);
  return qnormalize(vec4(0.0, -v.z, v.y, w));
}

// Frame of vertex b from its parent's frame and the edge a -> b (Algorithm 3, 10-12):
// the edge is read in the parent's world frame `world`, the result composed onto
// `parent` (`world` itself for method 1, its head-relative form for method 2).
vec4 child_frame(vec4 parent, vec4 world, vec3 a, vec3 b) {
  vec3 edge = b - a;
  float len = sqrt(dot(edge, edge));
  if (!(len > 0.0)) return parent;
  return qnormalize(qmul(parent, rotation_from_x(qrot(qconj(world), edge / len))));
}

// Eq. 4 with inverse-mass weights on edge (a, b) of shared memory.
void local_shape_edge(uint a, uint b, vec3 goal, float stiffness) {
  float wa = s_pos[a].w, wb = s_pos[b].w;
  float wsum = wa + wb;
  if (wsum == 0.0) return;
  vec3 d = stiffness * (goal - s_pos[b].xyz);
  s_pos[a].xyz -= d * (wa / wsum);
  s_pos[b].xyz += d * (wb / wsum);
}

// Edge length constraint on edge (a, b) (Müller et al. 2007; Halén Eq. 4.2).
void edge_length(uint a, uint b, float rest_length) {
  float wa = s_pos[a].w, wb = s_pos[b].w;
  float wsum = wa + wb;
  if (wsum == 0.0) return;
  vec3 d = s_pos[b].xyz - s_pos[a].xyz;
  float len = sqrt(dot(d, d));
  if (!(len > 0.0)) return;
  vec3 corr = d * ((len - rest_length) / (len * wsum));
  s_pos[a].xyz += wa * corr;
  s_pos[b].xyz -= wb * corr;
}

vec3 transform(mat4 m, vec3 p) { return (m * vec4(p, 1.0)).xyz; }

// Verlet with damping for shared-memory vertex v (kernels/common/strand_kernels.cpp verlet_integrate).
void integrate(uint v, float keep, float dt2) {
  if (s_pos[v].w == 0.0) return;
  vec3 acc = frame.gravity_dt.xyz;
  if (frame.wind.w != 0.0) {
    vec3 edge = s_pos[v].xyz - s_pos[v - 1].xyz;
    float len2 = dot(edge, edge);
    vec3 t = len2 > 0.0 ? edge / sqrt(len2) : vec3(0.0);
    acc += frame.wind.xyz - dot(frame.wind.xyz, t) * t;
  }
  vec3 p = s_pos[v].xyz;
  s_pos[v].xyz = p + keep * (p - s_prev[v].xyz) + acc * dt2;
  s_prev[v].xyz = p;
}

void main() {
  const uint strands_per_group = HAN_VK_GROUP_SIZE / LANES;
  const uint slot = gl_LocalInvocationID.x / LANES;
  const uint lane = gl_LocalInvocationID.x % LANES;
  const uint s = gl_WorkGroupID.x * strands_per_group + slot;
  // Slots past the last strand have no vertices; they still reach every barrier.
  HanStrand st = HanStrand(0u, 0u, 0u, 0.0);
  if (s < frame.strands) st = g_strands[s];
  const uint n = st.count, b = st.begin;
  const uint base = slot * LANES * VPL;  // the strand's first vertex in shared memory
  const HanRegion r = g_regions[st.region];

  // What this invocation keeps in registers for its vertices i = lane + k * LANES.
  vec4 rest[VPL];
  vec4 rest_local[VPL];  // xyz ^{i-1}P_i^0, w rest length of edge (i-1, i)
  vec3 rest_edge[VPL];   // P_i^0 - P_{i-1}^0, method 3's goal edge before the head rotation
  vec4 rot[VPL];         // method 2's persistent frames wT_i
  for (uint k = 0u; k < VPL; ++k) {
    const uint i = lane + k * LANES;
    if (i >= n) break;
    s_pos[base + i] = g_pos[b + i];
    s_prev[base + i] = g_prev[b + i];
    rest[k] = g_rest[b + i];
    rest_local[k] = g_rest_local[b + i];
    rest_edge[k] = i > 0u ? g_rest[b + i].xyz - g_rest[b + i - 1u].xyz : vec3(0.0);
    if (METHOD == 2u) rot[k] = g_rot[b + i];
  }
  sync();

  const float dt = frame.gravity_dt.w;
  const float dt2 = dt * dt;
  const float keep = 1.0 - r.damping;
  const float reach = r.global_range * float(n);
  const bool windy = frame.wind.w != 0.0;

  for (uint sub = 0u; sub < frame.substeps; ++sub) {
    const mat4 head = g_substeps[sub].head;
    const vec4 head_rotation = g_substeps[sub].head_rotation;

    // Integrate: pinned vertices follow the head (§3.2), free ones take a Verlet step.
    for (uint k = 0u; k < VPL; ++k) {
      const uint i = lane + k * LANES;
      if (i >= n) break;
      if (rest[k].w != 0.0) continue;
      s_prev[base + i] = s_pos[base + i];
      s_pos[base + i].xyz = transform(head, rest[k].xyz);
    }
    sync();
    if (!windy) {
      for (uint k = 0u; k < VPL; ++k) {
        const uint i = lane + k * LANES;
        if (i >= n) break;
        if (i >= 1u) integrate(base + i, keep, dt2);
      }
    } else if (lane == 0u) {
      // The CPU kernel's wind term reads the edge to the already integrated vertex
      // i - 1, a serial dependency along the strand: one invocation walks it.
      for (uint i = 1u; i < n; ++i) integrate(base + i, keep, dt2);
    }
    sync();

    // Global shape constraint (Eq. 2), ramped over global_range (§3.3).
    for (uint k = 0u; k < VPL; ++k) {
      const uint i = lane + k * LANES;
      if (i >= n || !(float(i) < reach)) break;
      if (s_pos[base + i].w == 0.0) continue;
      const float sg = r.global_ramp != 0u ? r.global_stiffness * (1.0 - float(i) / reach) : r.global_stiffness;
      const vec3 goal = transform(head, rest[k].xyz);
      s_pos[base + i].xyz += sg * (goal - s_pos[base + i].xyz);
    }
    sync();

    // Algorithm 1, lines 7-9: local shape and edge length constraints alternate; each
    // region stops after its own counts.
    for (uint it = 0u; it < frame.max_iterations; ++it) {
      const bool local = it < r.local_iterations && n >= 3u;
      if (METHOD == 1u) {
        // Algorithm 3: one serial sweep root to tip, each frame rebuilt from the
        // corrected edge right after its constraint.
        if (local && lane == 0u) {
          vec4 f = qmul(head_rotation, g_rest_rot[b + 1u]);
          for (uint i = 2u; i < n; ++i) {
            const vec3 goal = s_pos[base + i - 1u].xyz + qrot(f, g_rest_local[b + i].xyz);
            local_shape_edge(base + i - 1u, base + i, goal, r.local_stiffness);
            f = child_frame(f, f, s_pos[base + i - 1u].xyz, s_pos[base + i].xyz);
          }
        }
        sync();
      } else if (METHOD == 2u) {
        // Algorithm 4: the frames are kept relative to the head and composed with its
        // rotation where used (line 13); those of vertices 0 and 1 stay their rest
        // frames. Goals and parents read the previous iteration's frames (wT_temp, line
        // 5), shared after a barrier (line 6); even then odd edges (§5); each invocation
        // rebuilds its vertex's frame right after its own constraint (lines 12-16),
        // before the other batch moves the edge. Where the rest edge is rounding-sized
        // its direction is rounding noise, which the kept frames would feed back: the
        // frame is the parent's composed with the rest relative rotation ^{i-1}T_i^0
        // (Algorithm 2 line 8) instead, as kernels::local_shape_m2.
        for (uint k = 0u; k < VPL; ++k) {
          const uint i = lane + k * LANES;
          if (i >= n || !local) break;
          s_rot[base + i] = rot[k];
        }
        sync();
        for (uint first = 2u; first <= 3u; ++first) {
          for (uint k = 0u; k < VPL; ++k) {
            const uint i = lane + k * LANES;
            if (i >= n || !local) break;
            if (i < first || (i - first) % 2u != 0u) continue;
            const vec4 parent = s_rot[base + i - 1u];
            const vec4 world = qmul(head_rotation, parent);
            const vec3 goal = s_pos[base + i - 1u].xyz + qrot(world, rest_local[k].xyz);
            local_shape_edge(base + i - 1u, base + i, goal, r.local_stiffness);
            if (rest_local[k].w < st.rounding_edge)
              rot[k] = qnormalize(qmul(parent, rotation_from_x(normalize(rest_local[k].xyz))));
            else
              rot[k] = child_frame(parent, world, s_pos[base + i - 1u].xyz, s_pos[base + i].xyz);
          }
          sync();
        }
      } else {
        // Algorithm 5: the head-rotated rest edges, even then odd edges (§5).
        for (uint first = 2u; first <= 3u; ++first) {
          for (uint k = 0u; k < VPL; ++k) {
            const uint i = lane + k * LANES;
            if (i >= n || it >= r.local_iterations) break;
            if (i < first || (i - first) % 2u != 0u) continue;
            const vec3 goal = s_pos[base + i - 1u].xyz + qrot(head_rotation, rest_edge[k]);
            local_shape_edge(base + i - 1u, base + i, goal, r.local_stiffness);
          }
          sync();
        }
      }

      // Edge lengths, odd then even edges (§5).
      for (uint first = 1u; first <= 2u; ++first) {
        for (uint k = 0u; k < VPL; ++k) {
          const uint i = lane + k * LANES;
          if (i >= n || it >= r.length_iterations) break;
          if (i < first || (i - first) % 2u != 0u) continue;
          edge_length(base + i - 1u, base + i, rest_local[k].w);
        }
        sync();
      }
    }

    // Sphere collisions (§3.5): up to four passes so that leaving one sphere does not
    // leave the vertex inside another.
    for (uint k = 0u; k < VPL; ++k) {
      const uint i = lane + k * LANES;
      if (i >= n) break;
      vec4 p = s_pos[base + i];
      if (p.w == 0.0) continue;
      for (uint pass = 0u; pass < 4u; ++pass) {
        bool moved = false;
        for (uint c = 0u; c < frame.colliders; ++c) {
          const vec4 sphere = g_spheres[sub * frame.colliders + c];
          const vec3 d = p.xyz - sphere.xyz;
          const float dist2 = dot(d, d);
          if (dist2 >= sphere.w * sphere.w) continue;
          const float dist = sqrt(dist2);
          const vec3 normal = dist > 0.0 ? d / dist : vec3(0.0, 1.0, 0.0);
          p.xyz = sphere.xyz + normal * sphere.w;
          moved = true;
        }
        if (!moved) break;
      }
      s_pos[base + i] = p;
    }
    sync();
  }

  for (uint k = 0u; k < VPL; ++k) {
    const uint i = lane + k * LANES;
    if (i >= n) break;
    g_pos[b + i] = s_pos[base + i];
    g_prev[b + i] = s_prev[base + i];
    if (METHOD == 2u) g_rot[b + i] = rot[k];
  }
}
