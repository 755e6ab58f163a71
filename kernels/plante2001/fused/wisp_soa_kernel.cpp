// The wisp block kernels of wisp_soa.h. This file is compiled once per ISA variant
// (kernels/CMakeLists.txt), each time with HAIRBENCH_ISA_VARIANT naming the namespace; the
// loops over lanes are written plainly so the compiler turns each into vector
// instructions of that variant. Each lane repeats the operations of the per-wisp kernel
// (wisp_kernels.cpp) in Eigen's evaluation order for 3-vectors (wisp_lanes.h).
#include "kernels/simd/vec_math.h"
#include "kernels/plante2001/fused/wisp_lanes.h"
#include "kernels/plante2001/fused/wisp_soa.h"

#include <cmath>

#if defined(__AVX512F__)
#include <immintrin.h>
#endif

#ifndef HAIRBENCH_ISA_VARIANT
#error "HAIRBENCH_ISA_VARIANT must name the ISA variant"
#endif

namespace hairbench::kernels::wisp_soa::HAIRBENCH_ISA_VARIANT {

namespace {

constexpr int W = kLanes;
constexpr int N = kMaxNodes;
constexpr int Q = kEnvelopePerSection;

#define LANES _Pragma("GCC ivdep") for (int l = 0; l < W; ++l)
#define EACH_Q _Pragma("GCC unroll 4") for (int q = 0; q < Q; ++q)

// minimal_rotate of wisp_kernels.cpp; `bad` is set on a half turn.
inline F3 minimal_rotate(F3 a, F3 b, F3 v, int& bad) {
  const float c = dot(a, b);
  bad |= 1.0f + c < 1e-6f;
  const F3 k = cross(a, b);
  return add(add(mul(c, v), cross(k, v)), mul(dot(k, v) / (1.0f + c), k));
}

// Per node, the lanes' values of a vector quantity.
struct V3 {
  float x[W], y[W], z[W];
  F3 get(int l) const { return {x[l], y[l], z[l]}; }
  void set(int l, F3 v) {
    x[l] = v.x;
    y[l] = v.y;
    z[l] = v.z;
  }
};

// Copies a block's wisps into lanes and back. Only the lanes of the block's `count`
// wisps whose result is valid are written back; the others are left to the per-wisp
// kernels. Lanes past `count` repeat the first wisp (real data, so that they take the
// common branches) and are never written back.
struct Block {
  int n = 0, count = 0;
  std::uint32_t base[W];
  int bad[W];

  Block(const WispSystem& s, const std::uint32_t* wisps, int used) : count(used) {
    n = static_cast<int>(s.node_begin[wisps[0] + 1] - s.node_begin[wisps[0]]);
    for (int l = 0; l < W; ++l) {
      base[l] = s.node_begin[wisps[lane(l)]];
      bad[l] = 0;
    }
  }
  // The wisp (index into the block's wisps) lane l computes.
  int lane(int l) const { return l < count ? l : 0; }
#if defined(__AVX512F__)
  // A wisp's values lie in one run of floats (its nodes are consecutive), and a block
  // keeps them as rows of one float of every lane (V3: rows x, y, z of node 0, then of
  // node 1...). With AVX-512 the runs are read 16 floats a lane at a time and turned into
  // rows by a 16 x 16 transpose (transpose16). (GCC 12 warns that the intrinsics'
  // internal undefined operand may be uninitialised; it is a false positive, as in
  // soa_rows.h.)
  static_assert(W == 16, "one 512-bit vector of lanes");
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
  void load_rows(const float* const* run, int m, float* rows) const {
    for (int k0 = 0; k0 < m; k0 += 16) {
      const int take = m - k0 < 16 ? m - k0 : 16;
      const __mmask16 tail = static_cast<__mmask16>(take == 16 ? 0xFFFF : (1u << take) - 1);
      __m512 r[16];
      for (int l = 0; l < 16; ++l) r[l] = _mm512_maskz_loadu_ps(tail, run[l] + k0);
      transpose16(r);
      // Unrolled, so that the rows are stored from registers: as a loop GCC copies the
      // transposed rows to the stack and on with `rep movsq`.
#pragma GCC unroll 16
      for (int j = 0; j < 16; ++j)
        if (j < take) _mm512_storeu_ps(rows + (k0 + j) * W, r[j]);
    }
  }
  void load(V3* dst, const std::vector<Vec3f>& src) const {
    const float* run[W];
    for (int l = 0; l < W; ++l) run[l] = src[base[l]].data();
    load_rows(run, 3 * n, reinterpret_cast<float*>(dst));
  }
  void load(float* dst, const std::vector<float>& src, int per_node) const {
    const float* run[W];
    for (int l = 0; l < W; ++l) run[l] = src.data() + static_cast<std::size_t>(base[l]) * per_node;
    load_rows(run, n * per_node, dst);
  }
  // The inverse, into the runs of the lanes that keep their results (lanes of the block's
  // wisps, not bad).
  void store_rows(const float* rows, int m, float* const* run) const {
    for (int k0 = 0; k0 < m; k0 += 16) {
      const int take = m - k0 < 16 ? m - k0 : 16;
      const __mmask16 tail = static_cast<__mmask16>(take == 16 ? 0xFFFF : (1u << take) - 1);
      __m512 r[16];
      for (int j = 0; j < 16; ++j) r[j] = j < take ? _mm512_loadu_ps(rows + (k0 + j) * W) : _mm512_setzero_ps();
      transpose16(r);
      for (int l = 0; l < count; ++l)
        if (!bad[l]) _mm512_mask_storeu_ps(run[l] + k0, tail, r[l]);
    }
  }
  // `free` is not needed here: the kernels leave a pinned node's rows as loaded, so
  // writing them back changes nothing (the scalar variant skips them; the ISA variants
  // test checks the two agree).
  void store(std::vector<Vec3f>& dst, const V3* src, const float* /*free*/ = nullptr) const {
    float* run[W];
    for (int l = 0; l < W; ++l) run[l] = dst[base[l]].data();
    store_rows(reinterpret_cast<const float*>(src), 3 * n, run);
  }
  void store(std::vector<float>& dst, const float* src, int per_node) const {
    float* run[W];
    for (int l = 0; l < W; ++l) run[l] = dst.data() + static_cast<std::size_t>(base[l]) * per_node;
    store_rows(src, n * per_node, run);
  }
#pragma GCC diagnostic pop
#else
  void load(V3* dst, const std::vector<Vec3f>& src) const {
    for (int i = 0; i < n; ++i)
      for (int l = 0; l < W; ++l) dst[i].set(l, {src[base[l] + i].x(), src[base[l] + i].y(), src[base[l] + i].z()});
  }
  void load(float* dst, const std::vector<float>& src, int per_node) const { load_as_float(dst, src, per_node); }
  void store(std::vector<Vec3f>& dst, const V3* src, const float* free = nullptr) const {
    for (int l = 0; l < count; ++l) {
      if (bad[l]) continue;
      for (int i = 0; i < n; ++i)
        if (!free || free[i * W + l] != 0.0f) dst[base[l] + i] = Vec3f(src[i].x[l], src[i].y[l], src[i].z[l]);
    }
  }
  void store(std::vector<float>& dst, const float* src, int per_node) const {
    for (int l = 0; l < count; ++l) {
      if (bad[l]) continue;
      for (int i = 0; i < n; ++i)
        for (int q = 0; q < per_node; ++q) dst[(base[l] + i) * per_node + q] = src[(i * per_node + q) * W + l];
    }
  }
#endif
  template <class T>
  void load_as_float(float* dst, const std::vector<T>& src, int per_node) const {
    for (int i = 0; i < n; ++i)
      for (int q = 0; q < per_node; ++q)
        for (int l = 0; l < W; ++l) dst[(i * per_node + q) * W + l] = static_cast<float>(src[(base[l] + i) * per_node + q]);
  }
  // 1 for a free node, 0 for a pinned one.
  void load_free(float* dst, const std::vector<std::uint8_t>& pinned) const {
    load_as_float(dst, pinned, 1);
    for (int k = 0; k < n * W; ++k) dst[k] = dst[k] == 0.0f ? 1.0f : 0.0f;
  }
};

// wisp_forces_and_velocities for a block (see there for the physics, §3.2, §3.3, §5.1).
// Its F3 temporaries are not const: in this function GCC 12's scalar replacement keeps
// const F3 locals in memory ("a store to a read-only decl" in -fdump-tree-sra-details),
// and then not one of its lane loops is vectorised (-fopt-info-vec-missed: "more than one
// data ref in stmt"); without const every one of them is.
void velocities(WispSystem& s, const std::uint32_t* wisps, int count, const WispParams& p,
                const Eigen::Matrix3f& head_rot, const Vec3f& gravity, const Wind& wind, float h) {
  Block blk(s, wisps, count);
  const int n = blk.n;
  V3 x[N], v[N], e1[N], e2[N], bl[N], acc[N], seg_t[N], bishop_u[N], kappa[N];
  float rest_len[N * W], free[N * W], r_rest[N * W], seg_len[N * W], seg_inv_len[N * W], twist_load[N * W];
  float seg_mass[N * W], inv_mass[N * W], bend_scale[N * W];
  float r[N * Q * W], rdot[N * Q * W], racc[N * Q * W];
  blk.load(x, s.x);
  blk.load(v, s.v);
  blk.load(e1, s.e1);
  blk.load(e2, s.e2);
  blk.load(bl, s.bend_local);
  blk.load(rest_len, s.rest_len, 1);
  blk.load(seg_mass, s.seg_mass, 1);
  blk.load(inv_mass, s.inv_mass, 1);
  blk.load(bend_scale, s.bend_scale, 1);
  blk.load_free(free, s.pinned);
  blk.load(r_rest, s.r_rest, 1);
  blk.load(r, s.r, Q);
  blk.load(rdot, s.rdot, Q);
  int* bad = blk.bad;

  F3 g{gravity.x(), gravity.y(), gravity.z()};
  const Vec3f wind_v = wind.acceleration();
  F3 wa{wind_v.x(), wind_v.y(), wind_v.z()};
  const bool windy = wind.active();
  for (int i = 0; i < n; ++i) {
    LANES {
      F3 a = sub(g, mul(p.air_drag, v[i].get(l)));
      if (windy && i > 0) {
        F3 d = sub(x[i].get(l), x[i - 1].get(l));
        const float n2 = dot(d, d);
        F3 t = n2 > 1e-24f ? quot(d, std::sqrt(n2)) : F3{0.0f, 0.0f, 0.0f};
        a = add(a, sub(wa, mul(dot(wa, t), t)));
      }
      acc[i].set(l, a);
    }
  }
  // Axial springs. Segment 0 (before the first node) has no length.
  LANES seg_len[l] = seg_inv_len[l] = 0.0f;
  for (int i = 1; i < n; ++i) {
    LANES {
      F3 d = sub(x[i].get(l), x[i - 1].get(l));
      const float len = std::sqrt(dot(d, d));
      seg_len[i * W + l] = len;
      bad[l] |= !(len > 0.0f);
      const float inv_len = 1.0f / len;
      seg_inv_len[i * W + l] = inv_len;
      F3 t = mul(inv_len, d);
      seg_t[i].set(l, t);
      const float f = seg_mass[i * W + l] * (p.axial_stiffness * (len - rest_len[i * W + l]) +
                                             p.axial_damping * dot(sub(v[i].get(l), v[i - 1].get(l)), t));
      acc[i - 1].set(l, add(acc[i - 1].get(l), mul(f * inv_mass[(i - 1) * W + l], t)));
      acc[i].set(l, sub(acc[i].get(l), mul(f * inv_mass[i * W + l], t)));
    }
  }
  float sin_angle[W], angle[W];
  F3 axis[W];
  if (p.bending == BendingLaw::kPaper) {
    // The paper's springs on the bend angles (§3.2, paper_bending): no frames.
    float rest_bend[N * W];
    blk.load(rest_bend, s.rest_bend, 1);
    for (int i = 2; i < n; ++i) {
      float cos_angle[W];
      LANES {
        F3 t = seg_t[i].get(l), t_prev = seg_t[i - 1].get(l);
        axis[l] = cross(t_prev, t);
        sin_angle[l] = std::sqrt(dot(axis[l], axis[l]));
        cos_angle[l] = dot(t_prev, t);
        angle[l] = sin_angle[l] > 1e-7f ? atan2_upper(sin_angle[l], cos_angle[l]) : 0.0f;
      }
      LANES {
        F3 t = seg_t[i].get(l), t_prev = seg_t[i - 1].get(l);
        const bool bends = sin_angle[l] > 1e-7f;
        const float c = cos_angle[l];
        const float q = p.bending_stiffness * (angle[l] - rest_bend[i * W + l]) * bend_scale[i * W + l] / sin_angle[l];
        F3 zero{0.0f, 0.0f, 0.0f};
        F3 fk = pick(bends, mul(q * seg_inv_len[i * W + l], sub(t_prev, mul(c, t))), zero);
        F3 fk2 = pick(bends, mul(q * seg_inv_len[(i - 1) * W + l], sub(mul(c, t_prev), t)), zero);
        F3 dv = sub(v[i].get(l), v[i - 1].get(l));
        F3 damp = mul(p.bending_damping * seg_mass[i * W + l], sub(dv, mul(dot(dv, t), t)));
        acc[i].set(l, add(acc[i].get(l), mul(inv_mass[i * W + l], sub(fk, damp))));
        acc[i - 2].set(l, add(acc[i - 2].get(l), mul(inv_mass[(i - 2) * W + l], fk2)));
        acc[i - 1].set(l, sub(acc[i - 1].get(l), mul(inv_mass[(i - 1) * W + l], sub(add(fk, fk2), damp))));
      }
    }
  } else {
    // Bending springs (bishop_bending): the Bishop frames from the head-carried
    // one of the first segment (Eigen's expressions per lane, as there), the springs, then
    // their loads on the frames' twist, tip to root.
    V3 root_t;
    {
      V3 u;
      for (int l = 0; l < W; ++l) {
        const std::uint32_t w = s.node_wisp[blk.base[l]];
        const Vec3f rt = head_rot * s.root_t[w], ru = head_rot * s.rest_e1[w];
        root_t.set(l, {rt.x(), rt.y(), rt.z()});
        u.set(l, {ru.x(), ru.y(), ru.z()});
      }
      for (int i = 1; i < n; ++i) {
        const V3& prev = i > 1 ? seg_t[i - 1] : root_t;
        LANES {
          F3 t = seg_t[i].get(l), prev_t = prev.get(l), ul = u.get(l);
          const float c = dot(prev_t, t);
          bad[l] |= 1.0f + c < 1e-6f;
          F3 k_axis = cross(prev_t, t);
          F3 kap = mul(1.0f / (1.0f + c), k_axis);
          kappa[i].set(l, kap);
          F3 turned = add(add(mul(c, ul), cross(k_axis, ul)), mul(dot(k_axis, ul), kap));
          F3 normal = sub(turned, mul(dot(turned, t), t));
          const float n2 = dot(normal, normal);
          bad[l] |= !(n2 > 1e-24f);
          F3 ui = mul(1.0f / std::sqrt(n2), normal);
          u.set(l, ui);
          bishop_u[i].set(l, ui);
        }
      }
    }
    for (int k = 0; k < n * W; ++k) twist_load[k] = 0.0f;
    for (int i = 2; i < n; ++i) {
      LANES {
        F3 t = seg_t[i].get(l), t_prev = seg_t[i - 1].get(l), u = bishop_u[i - 1].get(l);
        F3 b = bl[i].get(l);
        F3 target = add(add(mul(b.x, u), mul(b.y, cross(t_prev, u))), mul(b.z, t_prev));
        axis[l] = cross(target, t);
        sin_angle[l] = std::sqrt(dot(axis[l], axis[l]));
        angle[l] = sin_angle[l] > 1e-7f ? atan2_upper(sin_angle[l], dot(target, t)) : 0.0f;
        bl[i].set(l, target);  // the target from here on
      }
      LANES {
        F3 t = seg_t[i].get(l), t_prev = seg_t[i - 1].get(l), target = bl[i].get(l);
        const bool bends = sin_angle[l] > 1e-7f;
        const float q = p.bending_stiffness * angle[l] * bend_scale[i * W + l] / sin_angle[l];
        F3 zero{0.0f, 0.0f, 0.0f};
        F3 fk = pick(bends, mul(q * seg_inv_len[i * W + l], sub(target, mul(dot(target, t), t))), zero);
        F3 fk2 = pick(bends, mul(q * seg_inv_len[(i - 1) * W + l], cross(t_prev, axis[l])), zero);
        twist_load[(i - 1) * W + l] = bends ? -q * dot(t_prev, axis[l]) : 0.0f;
        F3 dv = sub(v[i].get(l), v[i - 1].get(l));
        F3 damp = mul(p.bending_damping * seg_mass[i * W + l], sub(dv, mul(dot(dv, t), t)));
        acc[i].set(l, add(acc[i].get(l), mul(inv_mass[i * W + l], sub(fk, damp))));
        acc[i - 2].set(l, add(acc[i - 2].get(l), mul(inv_mass[(i - 2) * W + l], fk2)));
        acc[i - 1].set(l, sub(acc[i - 1].get(l), mul(inv_mass[(i - 1) * W + l], sub(add(fk, fk2), damp))));
      }
    }
    {
      // Segment i's bend turns the frames of segments i.. : its load is the sum of theirs.
      // Nodes i and i - 1 take the part through segment i, nodes i - 1 and i - 2 the part
      // through segment i - 1 (none for i = 1: segment 0 is the head's).
      float load[W];
      LANES load[l] = 0.0f;
      // A lane whose segment has no length is bad (the axial springs): the others need no
      // test.
      for (int i = n - 1; i > 1; --i) {
        LANES {
          load[l] += twist_load[i * W + l];
          F3 kap = kappa[i].get(l);
          F3 fn = mul(load[l] * seg_inv_len[i * W + l], kap);
          F3 fp = mul(load[l] * seg_inv_len[(i - 1) * W + l], kap);
          acc[i].set(l, add(acc[i].get(l), mul(inv_mass[i * W + l], fn)));
          F3 ai1 = sub(acc[i - 1].get(l), mul(inv_mass[(i - 1) * W + l], fn));
          acc[i - 1].set(l, add(ai1, mul(inv_mass[(i - 1) * W + l], fp)));
          acc[i - 2].set(l, sub(acc[i - 2].get(l), mul(inv_mass[(i - 2) * W + l], fp)));
        }
      }
      LANES {
        load[l] += twist_load[W + l];
        F3 fn = mul(load[l] * seg_inv_len[W + l], kappa[1].get(l));
        acc[1].set(l, add(acc[1].get(l), mul(inv_mass[W + l], fn)));
        acc[0].set(l, sub(acc[0].get(l), mul(inv_mass[l], fn)));
      }
    }
  }
  // A wisp pinned at its tip as well: its last free segment's bending spring towards the
  // head-carried rest direction (see wisp_forces_and_velocities), on the lanes of such
  // wisps. The target is Eigen's expression there, per lane (scalar code keeps its order).
  bool any_tip = false;
  int tip[W];
  F3 tip_target[W];
  for (int l = 0; l < W; ++l) {
    const std::uint32_t b = blk.base[l];
    tip[l] = s.pinned[b + n - 1] && !s.pinned[b + n - 2];
    any_tip = any_tip || tip[l];
    const Vec3f target =
        tip[l] ? Vec3f(head_rot * (s.rest_x[b + n - 1] - s.rest_x[b + n - 2]).normalized()) : Vec3f::UnitX();
    tip_target[l] = {target.x(), target.y(), target.z()};
  }
  if (any_tip) {
    const int i = n - 1;  // the pinned tip; node i - 1 takes the spring
    LANES {
      F3 t = seg_t[i].get(l);
      axis[l] = cross(t, tip_target[l]);
      sin_angle[l] = std::sqrt(dot(axis[l], axis[l]));
      angle[l] = tip[l] && sin_angle[l] > 1e-7f ? atan2_upper(sin_angle[l], dot(tip_target[l], t)) : 0.0f;
    }
    LANES {
      const float len = seg_len[i * W + l], l0 = rest_len[i * W + l], m = seg_mass[i * W + l];
      const float im = inv_mass[(i - 1) * W + l];
      F3 t = seg_t[i].get(l);
      const float torque = p.bending_stiffness * angle[l] * l0 * l0 * m;
      F3 spring = mul((torque / len) * im, cross(quot(axis[l], sin_angle[l]), t));
      F3 before = acc[i - 1].get(l);
      F3 turned = sin_angle[l] > 1e-7f ? sub(before, spring) : before;
      F3 dv = sub(v[i - 1].get(l), v[i].get(l));
      F3 damped = sub(turned, mul((p.bending_damping * m) * im, sub(dv, mul(dot(dv, t), t))));
      acc[i - 1].set(l, pick(tip[l] != 0, damped, before));
    }
  }
  // Envelope: radial springs, then ring springs, on the free nodes.
  const float sqrt2 = std::sqrt(2.0f);
  for (int i = 0; i < n; ++i) {
    LANES {
      const bool is_free = free[i * W + l] != 0.0f;
      const float r0 = r_rest[i * W + l];
      F3 frame_acc = sub(g, acc[i].get(l));
      F3 u1 = e1[i].get(l), u2 = e2[i].get(l);
      F3 dirs[Q] = {u1, u2, {-u1.x, -u1.y, -u1.z}, {-u2.x, -u2.y, -u2.z}};
      F3 vel = v[i].get(l);
      F3 reaction{0.0f, 0.0f, 0.0f};
      float ra_[Q], rd_[Q], out[Q];
      EACH_Q {
        ra_[q] = r[(i * Q + q) * W + l];
        rd_[q] = rdot[(i * Q + q) * W + l];
      }
      EACH_Q {
        const float rr = ra_[q], rd = rd_[q];
        const float compress = -p.radial_stiffness * (rr - r0) * (r0 / rr);
        const float stretch = -p.radial_stiffness * p.radial_stretch * (rr - r0);
        const float spring = rr < r0 ? compress : stretch;
        const float radial = spring - p.radial_damping * rd;
        reaction = sub(reaction, mul(p.envelope_mass * radial, dirs[q]));
        out[q] = radial + dot(frame_acc, dirs[q]) - p.air_drag * (dot(vel, dirs[q]) + rd);
      }
      const float d0 = r0 * sqrt2;
      EACH_Q {
        const int q2 = (q + 1) % Q;
        const float ra = ra_[q], rb = ra_[q2];
        const float d = std::sqrt(ra * ra + rb * rb);
        bad[l] |= is_free & !(d > 0.0f);
        const float ddot = (ra * rd_[q] + rb * rd_[q2]) / d;
        const float tension = p.ring_stiffness * (d - d0) + p.ring_damping * ddot;
        out[q] -= tension * ra / d;
        out[q2] -= tension * rb / d;
      }
      EACH_Q racc[(i * Q + q) * W + l] = is_free ? out[q] : 0.0f;
      acc[i].set(l, pick(is_free, add(acc[i].get(l), reaction), acc[i].get(l)));
    }
  }
  // Velocities of the free masses.
  for (int i = 0; i < n; ++i) {
    LANES {
      const bool is_free = free[i * W + l] != 0.0f;
      F3 vi = v[i].get(l);
      v[i].set(l, pick(is_free, add(vi, mul(h, acc[i].get(l))), vi));
    }
  }
  for (int j = 0; j < n * Q; ++j) {
    LANES {
      const float rd = rdot[j * W + l];
      rdot[j * W + l] = free[j / Q * W + l] != 0.0f ? rd + h * racc[j * W + l] : rd;
    }
  }
  blk.store(s.v, v, free);
  blk.store(s.rdot, rdot, Q);
  for (int l = 0; l < count; ++l)
    if (bad[l]) wisp_forces_and_velocities(s, wisps[l], p, head_rot, gravity, wind, h);
}

// wisp_positions (and wisp_frames) for a block (§3.3, §5.1 step 4).
void positions(WispSystem& s, const std::uint32_t* wisps, int count, const Vec3f* root_e1, float h) {
  Block blk(s, wisps, count);
  const int n = blk.n;
  // The new positions and radii go to arrays of their own: a lane-wise choice written back
  // over its input compiles to a masked store, which the loads after it cannot be
  // forwarded from.
  V3 x_old[N], x[N], v[N], e1[N], e2[N], nn[N];
  float free[N * W], r_rest[N * W], r_old[N * Q * W], rdot_old[N * Q * W], r[N * Q * W], rdot[N * Q * W];
  blk.load(x_old, s.x);
  blk.load(v, s.v);
  blk.load_free(free, s.pinned);
  blk.load(r_rest, s.r_rest, 1);
  blk.load(r_old, s.r, Q);
  blk.load(rdot_old, s.rdot, Q);
  int* bad = blk.bad;

  for (int i = 0; i < n; ++i) {
    LANES {
      const F3 xi = x_old[i].get(l);
      x[i].set(l, pick(free[i * W + l] != 0.0f, add(xi, mul(h, v[i].get(l))), xi));
    }
  }
  // Section frames (wisp_frames): normals bisecting the segments, e1 carried root to tip
  // by minimal rotation.
  V3 prev_t;
  LANES {
    const F3 t = unit(sub(x[1].get(l), x[0].get(l)), bad[l]);
    nn[0].set(l, t);
    prev_t.set(l, t);
  }
  for (int i = 1; i + 1 < n; ++i) {
    LANES {
      const F3 t = unit(sub(x[i + 1].get(l), x[i].get(l)), bad[l]);
      nn[i].set(l, unit(add(prev_t.get(l), t), bad[l]));
      prev_t.set(l, t);
    }
  }
  LANES {
    nn[n - 1].set(l, prev_t.get(l));
    const Vec3f& root = root_e1[blk.lane(l)];
    const F3 re{root.x(), root.y(), root.z()};
    const F3 n0 = nn[0].get(l);
    const F3 first = unit(sub(re, mul(dot(re, n0), n0)), bad[l]);
    e1[0].set(l, first);
    e2[0].set(l, cross(n0, first));
  }
  for (int i = 1; i < n; ++i) {
    LANES {
      const F3 ni = nn[i].get(l);
      F3 a = minimal_rotate(nn[i - 1].get(l), ni, e1[i - 1].get(l), bad[l]);
      a = unit(sub(a, mul(dot(a, ni), ni)), bad[l]);
      e1[i].set(l, a);
      e2[i].set(l, cross(ni, a));
    }
  }
  // Envelope radii within [0.25, 2] rest radii.
  for (int i = 0; i < n; ++i) {
    LANES {
      const bool is_free = free[i * W + l] != 0.0f;
      const float r_min = 0.25f * r_rest[i * W + l], r_max = 2.0f * r_rest[i * W + l];
      EACH_Q {
        const float ri = r_old[(i * Q + q) * W + l];
        const float rd = rdot_old[(i * Q + q) * W + l];
        const float moved = ri + h * rd;
        const bool low = moved < r_min, high = moved > r_max;
        const float rd_low = rd < 0.0f ? 0.0f : rd, rd_high = 0.0f < rd ? 0.0f : rd;
        const float r_cap = high ? r_max : moved, rd_cap = high ? rd_high : rd;
        const float r_new = low ? r_min : r_cap;
        const float rd_new = low ? rd_low : rd_cap;
        r[(i * Q + q) * W + l] = is_free ? r_new : ri;
        rdot[(i * Q + q) * W + l] = is_free ? rd_new : rd;
      }
    }
  }
  blk.store(s.x, x, free);
  blk.store(s.n, nn);
  blk.store(s.e1, e1);
  blk.store(s.e2, e2);
  blk.store(s.r, r, Q);
  blk.store(s.rdot, rdot, Q);
  for (int l = 0; l < count; ++l)
    if (bad[l]) wisp_positions(s, wisps[l], root_e1[l], h);
}

// wisp_body_detect for a block where no mass is inside a body (§4.2): then the
// detection only records each free mass's nearest sphere within the threshold. Each
// lane follows nearest_sphere (wisp_kernels.cpp): the first sphere of least gap
// |p - c| - R. A lane with a mass inside (gap < 0) is left to the per-wisp kernel, which
// moves the masses out.
std::uint32_t body_detect(WispSystem& s, const std::uint32_t* wisps, int count, const BodyLanes& body,
                          float threshold) {
  Block blk(s, wisps, count);
  const int n = blk.n;
  V3 x[N], e1[N], e2[N];
  float free[N * W], r[N * Q * W];
  float node_body[N * W], env_body[N * Q * W];
  blk.load(x, s.x);
  blk.load(e1, s.e1);
  blk.load(e2, s.e2);
  blk.load_free(free, s.pinned);
  blk.load(r, s.r, Q);
  int* bad = blk.bad;
  int touches[W] = {};
  const int spheres = static_cast<int>(body.count);
  // The lanes' masses at (px, py, pz): their nearest spheres into `out` (-1 for none
  // within the threshold, or for a pinned node's masses).
  float px[W], py[W], pz[W];
  auto record = [&](int i, float* out) {
    float gap[W], best[W];
    LANES {
      gap[l] = INFINITY;
      best[l] = -1.0f;
    }
    for (int c = 0; c < spheres; ++c) {
      const F3 centre{body.spheres[4 * c], body.spheres[4 * c + 1], body.spheres[4 * c + 2]};
      const float radius = body.spheres[4 * c + 3], index = static_cast<float>(c);
      LANES {
        const F3 d = sub(F3{px[l], py[l], pz[l]}, centre);
        const float g = std::sqrt(dot(d, d)) - radius;
        const float was = gap[l], had = best[l];
        const bool nearer = g < was;
        gap[l] = nearer ? g : was;
        best[l] = nearer ? index : had;
      }
    }
    LANES {
      // Bitwise & and |: a comparison after && is not vector code.
      const bool contact = (free[i * W + l] != 0.0f) & (best[l] >= 0.0f) & (gap[l] < threshold);
      out[l] = contact ? best[l] : -1.0f;
      touches[l] |= contact;
      bad[l] |= contact & (gap[l] < 0.0f);
    }
  };
  for (int i = 0; i < n; ++i) {
    LANES {
      px[l] = x[i].x[l];
      py[l] = x[i].y[l];
      pz[l] = x[i].z[l];
    }
    record(i, &node_body[i * W]);
    EACH_Q {
      // envelope_dir: +e1, +e2, -e1, -e2.
      const V3& axis = q % 2 == 0 ? e1[i] : e2[i];
      const float sign = q < 2 ? 1.0f : -1.0f;
      const float* rq = &r[(i * Q + q) * W];
      LANES {
        const F3 dir{sign * axis.x[l], sign * axis.y[l], sign * axis.z[l]};
        const F3 p = add(x[i].get(l), mul(rq[l], dir));
        px[l] = p.x;
        py[l] = p.y;
        pz[l] = p.z;
      }
      record(i, &env_body[(i * Q + q) * W]);
    }
  }
  std::uint32_t fallback = 0;
  for (int l = 0; l < count; ++l) {
    if (bad[l]) {
      fallback |= 1u << l;
      continue;
    }
    const std::uint32_t b = blk.base[l];
    for (int i = 0; i < n; ++i) {
      s.node_body[b + i] = static_cast<std::int32_t>(node_body[i * W + l]);
      for (int q = 0; q < Q; ++q)
        s.env_body[Q * (b + i) + q] = static_cast<std::int32_t>(env_body[(i * Q + q) * W + l]);
    }
    s.wisp_touches[wisps[l]] = static_cast<std::uint8_t>(touches[l]);
  }
  return fallback;
}

}  // namespace

// wisp_grid_kernel.cpp
void contacts(const SegmentGrid& g, const WispSystem& s, std::size_t begin, std::size_t end,
              std::vector<WispContact>& out);
// wisp_contact_kernel.cpp
void impulses(const WispSystem& s, const ContactNode* nodes, std::span<const WispContact> contacts, std::size_t begin,
              std::size_t end, const InteractionParams& ip, std::span<const WispParams> params, float h,
              ContactImpulse* out);

// wisp_strand_kernel.cpp
void strand_points(const WispSystem& s, const NodeSection* sections, const std::uint32_t* node, const Vec4f* coord,
                   std::uint32_t n, Vec3f* point, float* weight);

// wisp_body_kernel.cpp
void body_slide(WispSystem& s, std::uint32_t first, std::uint32_t count, const BodyLanes& body, float drag);
void body_hold(WispSystem& s, std::uint32_t first, std::uint32_t count, const BodyLanes& body);

Kernels kernels() {
  return {velocities, positions, contacts, impulses, strand_points, body_slide, body_hold, body_detect};
}

}  // namespace hairbench::kernels::wisp_soa::HAIRBENCH_ISA_VARIANT
