// The harness's per-frame metrics on the device (docs/metrics.md; reports/metrics.cpp and
// verdict::relative_kinetic_energy on the host), one invocation per strand: each strand's
// share of every metric in float, written to MetricsStrand, which the host adds in
// strand order in double (reports/device_metrics.cpp). The formulas are the host's, term
// for term; the host takes differences and sums in double where this kernel has float
// (docs/metrics.md, Where the metrics are computed, gives the difference).
#version 450
#extension GL_GOOGLE_include_directive : require

#include "metrics_layout.h"

layout(local_size_x = METRICS_VK_GROUP_SIZE) in;

layout(constant_id = 0) const uint STRANDS = 0;

layout(std430, binding = METRICS_VK_BIND_POS) readonly buffer PosBuf { vec4 g_pos[]; };
layout(std430, binding = METRICS_VK_BIND_PREV) buffer PrevBuf { vec4 g_prev[]; };
layout(std430, binding = METRICS_VK_BIND_REFERENCE) readonly buffer RefBuf { vec4 g_ref[]; };
layout(std430, binding = METRICS_VK_BIND_REST) readonly buffer RestBuf { vec4 g_rest[]; };
layout(std430, binding = METRICS_VK_BIND_EDGE) readonly buffer EdgeBuf { vec4 g_edge[]; };
layout(std430, binding = METRICS_VK_BIND_OFFSETS) readonly buffer OffsetBuf { uint g_offsets[]; };
layout(std430, binding = METRICS_VK_BIND_FRAME) readonly buffer FrameBuf { MetricsFrame frame; };
layout(std430, binding = METRICS_VK_BIND_OUT) writeonly buffer OutBuf { MetricsStrand g_out[]; };

const uint kSane = 0u, kNonFinite = 1u, kFar = 2u;  // core/device_metrics.h StrandMetrics

float norm2(vec3 v) { return (v.x * v.x + v.y * v.y) + v.z * v.z; }

// jaggedness's curvature binormal (metrics.cpp curvature_binormal): 2 (e0 x e1) / (l0 l1 +
// e0.e1), the denominator floored at 1e-12 l0 l1 so that an exact hairpin stays finite.
// Where an edge has length 0 the cross product is 0 and so is kb, as on the host (whose
// floor of 1e-42 for l0 l1 = 0 float cannot hold).
vec3 curvature_binormal(vec3 e0, float l0, vec3 e1, float l1) {
  const float lens = l0 * l1;
  if (!(lens > 0.0)) return vec3(0.0);
  const float denom = max(lens + dot(e0, e1), 1e-12 * lens);
  return 2.0 * cross(e0, e1) / denom;
}

bool finite(vec4 p) { return all(lessThanEqual(abs(p), vec4(3.402823466e38))); }

void main() {
  const uint s = gl_GlobalInvocationID.x;
  if (s >= STRANDS) return;
  const uint b = g_offsets[s], n = g_offsets[s + 1u] - b;
  const mat3 m = mat3(frame.head);
  const vec3 t = frame.head[3].xyz;
  const vec3 centre = frame.centre_far.xyz;
  const float far = frame.centre_far.w;
  const vec3 g = frame.gravity_dt.xyz;
  const float dt = frame.gravity_dt.w;

  MetricsStrand o;
  o.deviation2 = 0.0;
  o.length2 = 0.0;
  o.length_max = 0.0;
  o.length_worst = 0u;
  o.rest2 = 0.0;
  o.penetration = 0.0;
  o.energy = 0.0;
  o.kinetic = 0.0;
  o.bad_vertex = 0u;
  o.bad_kind = kSane;
  o.pad = 0u;
  float jag = 0.0;

  vec3 last = vec3(0.0), e0 = vec3(0.0), kb0 = vec3(0.0);
  float l0 = 0.0;
  for (uint k = 0u; k < n; ++k) {
    const uint i = b + k;
    const vec4 p4 = g_pos[i];
    const vec3 p = p4.xyz;
    const vec3 prev = g_prev[i].xyz;

    // deviation_vs_reference: |p - q|^2.
    o.deviation2 += norm2(p - g_ref[i].xyz);

    // rest_shape_error: H p0 as metrics.cpp forms it in float (Eigen's order, no
    // contraction), then |p - H p0|^2 summed x^2 + (y^2 + z^2).
    const vec3 r = g_rest[i].xyz;
    precise vec3 h;
    h.x = t.x + ((m[0][0] * r.x + m[1][0] * r.y) + m[2][0] * r.z);
    h.y = t.y + ((m[0][1] * r.x + m[1][1] * r.y) + m[2][1] * r.z);
    h.z = t.z + ((m[0][2] * r.x + m[1][2] * r.y) + m[2][2] * r.z);
    const vec3 dh = p - h;
    o.rest2 += dh.x * dh.x + (dh.y * dh.y + dh.z * dh.z);

    // mechanical_energy: 1/2 |v|^2 - g.p with v = (p - prev) / dt.
    const vec3 v = (p - prev) / dt;
    o.energy += 0.5 * norm2(v) - dot(g, p);

    // relative_kinetic_energy: |p - carry prev|^2.
    const vec3 carried = mat3(frame.carry) * prev + frame.carry[3].xyz;
    o.kinetic += norm2(p - carried);

    // penetration: the deepest vertex in any sphere (NaN depths are skipped).
    for (uint c = 0u; c < frame.spheres; ++c) {
      const vec4 sph = frame.sphere[c];
      const float depth = sph.w - sqrt(norm2(p - sph.xyz));
      o.penetration = depth > o.penetration ? depth : o.penetration;
    }

    // blowup_reason: the strand's first vertex that is not finite or is beyond `far`.
    if (o.bad_kind == kSane) {
      if (!finite(p4)) {
        o.bad_vertex = k;
        o.bad_kind = kNonFinite;
      } else if (sqrt(norm2(p - centre)) > far) {
        o.bad_vertex = k;
        o.bad_kind = kFar;
      }
    }

    if (k > 0u) {
      // length_error of edge k: | |p_k - p_{k-1}| - r_k | / s; the first largest stays.
      const vec4 rest_edge = g_edge[i];
      const vec3 e1 = p - last;
      const float l1 = sqrt(norm2(e1));
      const float err = abs(l1 - rest_edge.x) / rest_edge.y;
      o.length2 += err * err;
      if (o.length_max < err) {
        o.length_max = err;
        o.length_worst = k;
      }
      // jaggedness: kb at vertex k - 1 once its two edges are known, and from vertex 2 on
      // the pair (kb_{k-1}, kb_{k-2}), whose d0 and weight sit at vertex k - 1.
      if (k >= 2u) {
        const vec3 kb1 = curvature_binormal(e0, l0, e1, l1);
        if (k >= 3u) {
          const vec4 pair = g_edge[i - 1u];
          const float diff = (sqrt(norm2(kb1 - kb0)) - pair.z) * pair.w;
          jag += diff * diff;
        }
        kb0 = kb1;
      }
      e0 = e1;
      l0 = l1;
    }
    last = p;
    g_prev[i] = p4;
  }
  o.jaggedness = n >= 4u ? sqrt(jag / float(n - 3u)) : 0.0;
  g_out[s] = o;
}
