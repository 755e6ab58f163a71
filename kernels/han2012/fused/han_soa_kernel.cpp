// The fused block kernel of han_soa.h. This file is compiled once per ISA variant
// (kernels/CMakeLists.txt), each time with HAIRBENCH_ISA_VARIANT naming the namespace; the
// loops over lanes are written plainly so the compiler turns each into vector
// instructions of that variant.
#include "kernels/han2012/fused/han_soa.h"
#include "kernels/simd/soa_common.h"
#include "kernels/simd/soa_rows.h"

#include <cmath>
#include <cstring>

#if defined(__AVX512F__)
#include <immintrin.h>
#endif

#ifndef HAIRBENCH_ISA_VARIANT
#error "HAIRBENCH_ISA_VARIANT must name the ISA variant"
#endif

namespace hairbench::kernels::han_soa::HAIRBENCH_ISA_VARIANT {

namespace {

constexpr int W = kLanes;
static_assert(W == soa::kRowLanes, "soa_rows.h takes rows of 16 lanes");

#define LANES _Pragma("GCC ivdep") for (int l = 0; l < W; ++l)

struct Quat {
  float x[W], y[W], z[W], w[W];
};

// Eigen's quaternion product, in the order of its SSE kernel (quat_product<SSE>):
// component by component (a·b_w - a' b') + (a'' b'' + a_w b), the w row negated.
inline void quat_mul(const float* ax, const float* ay, const float* az, const float* aw, const float* bx,
                     const float* by, const float* bz, const float* bw, Quat& r) {
  LANES {
    const float x = (ax[l] * bw[l] - az[l] * by[l]) + (ay[l] * bz[l] + aw[l] * bx[l]);
    const float y = (ay[l] * bw[l] - ax[l] * bz[l]) + (az[l] * bx[l] + aw[l] * by[l]);
    const float z = (az[l] * bw[l] - ay[l] * bx[l]) + (ax[l] * by[l] + aw[l] * bz[l]);
    const float w = (aw[l] * bw[l] - ax[l] * bx[l]) - (az[l] * bz[l] + ay[l] * by[l]);
    r.x[l] = x;
    r.y[l] = y;
    r.z[l] = z;
    r.w[l] = w;
  }
}

// q · v in Eigen's form: uv = q×v, uv += uv, v + w uv + q×uv.
inline void rotate(float qx, float qy, float qz, float qw, float vx, float vy, float vz, float& ox, float& oy,
                   float& oz) {
  float ux = qy * vz - qz * vy, uy = qz * vx - qx * vz, uz = qx * vy - qy * vx;
  ux += ux;
  uy += uy;
  uz += uz;
  ox = vx + qw * ux + (qy * uz - qz * uy);
  oy = vy + qw * uy + (qz * ux - qx * uz);
  oz = vz + qw * uz + (qx * uy - qy * ux);
}

// GCC 12 warns that _mm512_sqrt_ps's internal undefined operand is or may be
// uninitialised wherever it is inlined; a false positive (as in soa_rows.h). The rows
// and frames here are read and written with unaligned loads and stores: Quat and the
// block's rows are not declared 64-byte aligned.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wuninitialized"
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
// The frame of vertex i from its parent's frame and the edge (a, b): Algorithm 3, lines
// 10-12, as kernels::child_frame (han2012/reference/han_kernels.cpp) with rotation_from_x (frames.h).
// The edge is read in the parent's world frame `world`; the result is composed onto
// `parent`, which is `world` itself (method 1) or its head-relative form (method 2).
// out may be parent or world (each lane reads them before its result is stored).
inline void child_frame(const Quat& parent, const Quat& world, const float* ax, const float* ay, const float* az,
                        const float* bx, const float* by, const float* bz, Quat& out) {
  Quat r;
  alignas(64) float ok[W];
  LANES {
    const float ex = bx[l] - ax[l], ey = by[l] - ay[l], ez = bz[l] - az[l];
    const float len = std::sqrt(ex * ex + (ey * ey + ez * ez));
    ok[l] = len > 0.0f ? 1.0f : 0.0f;
    float vx, vy, vz;  // world^-1 · (edge / len): the conjugate's vector part is negated
    rotate(-world.x[l], -world.y[l], -world.z[l], world.w[l], ex / len, ey / len, ez / len, vx, vy, vz);
    // rotation_from_x(v): (1 + v_x, 0, -v_z, v_y) normalised; half a turn about z at v = -x.
    const float w = 1.0f + vx;
    const float n2 = (0.0f * 0.0f + vy * vy) + (vz * vz + w * w);
    const float s = std::sqrt(n2);
    const bool flip = w < 1e-6f;
    r.x[l] = 0.0f;  // 0 / s with s >= 1e-6: +0 either way
    r.y[l] = flip ? 0.0f : -vz / s;
    r.z[l] = flip ? 1.0f : vy / s;
    r.w[l] = flip ? 0.0f : w / s;
  }
  Quat m;
  quat_mul(parent.x, parent.y, parent.z, parent.w, r.x, r.y, r.z, r.w, m);
  // Eigen's Quaternion::normalized(): coefficients (x, y, z, w) divided by the root of
  // (x² + z²) + (y² + w²) (its SSE horizontal sum), unchanged when that is 0. Every lane
  // of `out` is written from values in registers: a select that keeps some lanes of an
  // array becomes a masked store, and the next edge's loads of the frame cannot take
  // their values from a masked store still in the store queue (they wait for it).
#if defined(__AVX512F__)
  // Intrinsics, so that every store is whole: GCC writes the loop below with a masked
  // store before each whole one (out may be parent).
  const __m512 zero = _mm512_setzero_ps();
  const __m512 mx = _mm512_loadu_ps(m.x), my = _mm512_loadu_ps(m.y);
  const __m512 mz = _mm512_loadu_ps(m.z), mw = _mm512_loadu_ps(m.w);
  const __m512 n2 = _mm512_add_ps(_mm512_add_ps(_mm512_mul_ps(mx, mx), _mm512_mul_ps(mz, mz)),
                                  _mm512_add_ps(_mm512_mul_ps(my, my), _mm512_mul_ps(mw, mw)));
  const __m512 rn = _mm512_sqrt_ps(n2);
  const __mmask16 scale = _mm512_cmp_ps_mask(n2, zero, _CMP_GT_OQ);
  const __mmask16 keep = _mm512_cmp_ps_mask(_mm512_loadu_ps(ok), zero, _CMP_EQ_OQ);
  const __m512 px = _mm512_loadu_ps(parent.x), py = _mm512_loadu_ps(parent.y), pz = _mm512_loadu_ps(parent.z);
  const __m512 pw = _mm512_loadu_ps(parent.w);
  _mm512_storeu_ps(out.x, _mm512_mask_mov_ps(_mm512_mask_div_ps(mx, scale, mx, rn), keep, px));
  _mm512_storeu_ps(out.y, _mm512_mask_mov_ps(_mm512_mask_div_ps(my, scale, my, rn), keep, py));
  _mm512_storeu_ps(out.z, _mm512_mask_mov_ps(_mm512_mask_div_ps(mz, scale, mz, rn), keep, pz));
  _mm512_storeu_ps(out.w, _mm512_mask_mov_ps(_mm512_mask_div_ps(mw, scale, mw, rn), keep, pw));
#else
  LANES {
    const float n2 = (m.x[l] * m.x[l] + m.z[l] * m.z[l]) + (m.y[l] * m.y[l] + m.w[l] * m.w[l]);
    const float rn = std::sqrt(n2);
    const bool scale = n2 > 0.0f, keep = ok[l] == 0.0f;
    const float x = scale ? m.x[l] / rn : m.x[l], y = scale ? m.y[l] / rn : m.y[l],
                z = scale ? m.z[l] / rn : m.z[l], w = scale ? m.w[l] / rn : m.w[l];
    out.x[l] = keep ? parent.x[l] : x;
    out.y[l] = keep ? parent.y[l] : y;
    out.z[l] = keep ? parent.z[l] : z;
    out.w[l] = keep ? parent.w[l] : w;
  }
#endif
}
#pragma GCC diagnostic pop

// Where `on`, an edge constraint's new end positions replace a and b (one lane's values).
inline void move_edge_if(bool on, float& ax, float& ay, float& az, float& bx, float& by, float& bz, float nax,
                         float nay, float naz, float nbx, float nby, float nbz) {
  ax = on ? nax : ax;
  ay = on ? nay : ay;
  az = on ? naz : az;
  bx = on ? nbx : bx;
  by = on ? nby : by;
  bz = on ? nbz : bz;
}

// Eq. 4 (local_shape_edge) on one lane's values: a and b move towards goal g by their
// mass weights ka, kb (mass_weights), where `on` (not both pinned).
inline void local_lane(float& ax, float& ay, float& az, float& bx, float& by, float& bz, bool on, float ka, float kb,
                       float gx, float gy, float gz, float stiffness) {
  const float dx = stiffness * (gx - bx), dy = stiffness * (gy - by), dz = stiffness * (gz - bz);
  const float nax = ax - dx * ka, nay = ay - dy * ka, naz = az - dz * ka;
  const float nbx = bx + dx * kb, nby = by + dy * kb, nbz = bz + dz * kb;
  move_edge_if(on, ax, ay, az, bx, by, bz, nax, nay, naz, nbx, nby, nbz);
}

// The local shape constraint of edge (a, b) towards goal (Eq. 4, local_shape_edge).
// ka, kb: the edge's mass weights (mass_weights). With AVX-512 the select of the lanes
// that move is a masked operation on the full row, stored whole: as GCC writes the loop,
// it is a masked store, which the next edge of method 1 (its goal from the frame this
// edge moves) cannot load from until it has left the store queue.
inline void local_edge(float* __restrict ax, float* __restrict ay, float* __restrict az, const float* aw,
                       float* __restrict bx, float* __restrict by, float* __restrict bz, const float* bw,
                       const float* ka, const float* kb, const float* gx, const float* gy, const float* gz,
                       float stiffness) {
#if defined(__AVX512F__)
  const __m512 wsum = _mm512_add_ps(_mm512_loadu_ps(aw), _mm512_loadu_ps(bw));
  const __mmask16 on = _mm512_cmp_ps_mask(wsum, _mm512_setzero_ps(), _CMP_NEQ_UQ);
  const __m512 k = _mm512_set1_ps(stiffness), wa = _mm512_loadu_ps(ka), wb = _mm512_loadu_ps(kb);
  auto axis = [&](float* a, float* b, const float* g) {
    const __m512 va = _mm512_loadu_ps(a), vb = _mm512_loadu_ps(b);
    const __m512 d = _mm512_mul_ps(k, _mm512_sub_ps(_mm512_loadu_ps(g), vb));
    _mm512_storeu_ps(a, _mm512_mask_sub_ps(va, on, va, _mm512_mul_ps(d, wa)));
    _mm512_storeu_ps(b, _mm512_mask_add_ps(vb, on, vb, _mm512_mul_ps(d, wb)));
  };
  axis(ax, bx, gx);
  axis(ay, by, gy);
  axis(az, bz, gz);
#else
  LANES {
    float x0 = ax[l], y0 = ay[l], z0 = az[l], x1 = bx[l], y1 = by[l], z1 = bz[l];
    local_lane(x0, y0, z0, x1, y1, z1, aw[l] + bw[l] != 0.0f, ka[l], kb[l], gx[l], gy[l], gz[l], stiffness);
    ax[l] = x0;
    ay[l] = y0;
    az[l] = z0;
    bx[l] = x1;
    by[l] = y1;
    bz[l] = z1;
  }
#endif
}

struct Rows {
  float *px, *py, *pz, *qx, *qy, *qz;
  const float *iw, *rx, *ry, *rz, *rl;
};

// Pinned vertices follow the head (follow_head), free ones are Verlet-integrated
// (verlet_integrate); row by row, so the wind term sees vertex i-1 already moved, as in
// the per-strand kernel.
template <bool kWindy, RowKind kKind>
inline void integrate_row(const Rows& r, int i, const soa::AffinePose& h, const Substep& s, const Frame& f, float keep) {
  const int o = i * W;
  float *px = r.px + o, *py = r.py + o, *pz = r.pz + o, *qx = r.qx + o, *qy = r.qy + o, *qz = r.qz + o;
  const float *iw = r.iw + o, *rx = r.rx + o, *ry = r.ry + o, *rz = r.rz + o;
  if constexpr (kKind == kRowPinned) {
    soa::follow_head_row(h, px, py, pz, qx, qy, qz, rx, ry, rz);
    return;
  }
  const bool root = i == 0;  // the integrator starts at vertex 1; the root only follows the head
  if (root && kKind == kRowFree) return;
  const float *ux = px - W, *uy = py - W, *uz = pz - W;  // vertex i-1, already moved
  const float gdx = s.gravity_dt2[0], gdy = s.gravity_dt2[1], gdz = s.gravity_dt2[2];
  [[maybe_unused]] const float dt2 = s.dt2, grx = f.gravity[0], gry = f.gravity[1], grz = f.gravity[2],
                               wx = f.wind[0], wy = f.wind[1], wz = f.wind[2];
  if (root) {  // a mixed root row: its pinned lanes follow, its free lanes stay
    LANES {
      const bool pinned = iw[l] == 0.0f;
      const float x = px[l], y = py[l], z = pz[l];
      const float gx = h.x(rx[l], ry[l], rz[l]), gy = h.y(rx[l], ry[l], rz[l]), gz = h.z(rx[l], ry[l], rz[l]);
      px[l] = pinned ? gx : x;
      py[l] = pinned ? gy : y;
      pz[l] = pinned ? gz : z;
      qx[l] = pinned ? x : qx[l];
      qy[l] = pinned ? y : qy[l];
      qz[l] = pinned ? z : qz[l];
    }
    return;
  }
  LANES {
    const float x = px[l], y = py[l], z = pz[l];
    float adx, ady, adz;
    if constexpr (kWindy) {
      const float ex = x - ux[l], ey = y - uy[l], ez = z - uz[l];
      const float len2 = ex * ex + (ey * ey + ez * ez);
      const float len = std::sqrt(len2);
      const bool has = len2 > 0.0f;
      const float tx = has ? ex / len : 0.0f, ty = has ? ey / len : 0.0f, tz = has ? ez / len : 0.0f;
      const float dot = wx * tx + (wy * ty + wz * tz);
      adx = (grx + (wx - dot * tx)) * dt2;
      ady = (gry + (wy - dot * ty)) * dt2;
      adz = (grz + (wz - dot * tz)) * dt2;
    } else {
      adx = gdx;
      ady = gdy;
      adz = gdz;
    }
    const float nx = x + keep * (x - qx[l]) + adx;
    const float ny = y + keep * (y - qy[l]) + ady;
    const float nz = z + keep * (z - qz[l]) + adz;
    if constexpr (kKind == kRowMixed) {
      const bool pinned = iw[l] == 0.0f;
      px[l] = pinned ? h.x(rx[l], ry[l], rz[l]) : nx;
      py[l] = pinned ? h.y(rx[l], ry[l], rz[l]) : ny;
      pz[l] = pinned ? h.z(rx[l], ry[l], rz[l]) : nz;
    } else {
      px[l] = nx;
      py[l] = ny;
      pz[l] = nz;
    }
    qx[l] = x;
    qy[l] = y;
    qz[l] = z;
  }
}

// Eq. 2 (global_shape) on row i: free vertices below reach move towards T_H · P_i^0. The
// pose is taken by value, as in follow_head_row.
[[gnu::always_inline]] inline void global_row(const Rows& r, RowKind kind, int i, const soa::AffinePose h,
                                              const BlockParams& p) {
  if (kind == kRowPinned || !(static_cast<float>(i) < p.global_reach)) return;
  const int o = i * W;
  float *px = r.px + o, *py = r.py + o, *pz = r.pz + o;
  const float *iw = r.iw + o, *rx = r.rx + o, *ry = r.ry + o, *rz = r.rz + o;
  const float k = p.global_ramp ? p.global_stiffness * (1.0f - static_cast<float>(i) / p.global_reach)
                                : p.global_stiffness;
  // A free row moves every lane, with no test: with the test GCC 12 leaves this loop
  // scalar (the select becomes a branch per lane).
  if (kind == kRowFree) {
    LANES {
      const float gx = h.x(rx[l], ry[l], rz[l]), gy = h.y(rx[l], ry[l], rz[l]), gz = h.z(rx[l], ry[l], rz[l]);
      px[l] = px[l] + k * (gx - px[l]);
      py[l] = py[l] + k * (gy - py[l]);
      pz[l] = pz[l] + k * (gz - pz[l]);
    }
    return;
  }
  LANES {
    const bool on = iw[l] != 0.0f;
    const float gx = h.x(rx[l], ry[l], rz[l]), gy = h.y(rx[l], ry[l], rz[l]), gz = h.z(rx[l], ry[l], rz[l]);
    px[l] = on ? px[l] + k * (gx - px[l]) : px[l];
    py[l] = on ? py[l] + k * (gy - py[l]) : py[l];
    pz[l] = on ? pz[l] + k * (gz - pz[l]) : pz[l];
  }
}

// Pinned vertices follow the head (follow_head), free ones are Verlet-integrated
// (verlet_integrate); row by row, so the wind term sees vertex i-1 already moved, as in
// the per-strand kernel. With kGlobal, the global shape constraint (global_row) follows
// one row behind, while the rows are still in L1 and registers: row i-1 once row i, the
// last to read it, has been integrated. The same bits as the two stages one after the
// other.
template <bool kWindy, bool kGlobal>
void integrate(const Rows& r, const RowKind* kinds, int n, const Substep& s, const Frame& f, const BlockParams& p) {
  const soa::AffinePose h(s.m, s.t);
  for (int i = 0; i < n; ++i) {
    switch (kinds[i]) {
      case kRowFree:
        integrate_row<kWindy, kRowFree>(r, i, h, s, f, p.keep);
        break;
      case kRowPinned:
        integrate_row<kWindy, kRowPinned>(r, i, h, s, f, p.keep);
        break;
      default:
        integrate_row<kWindy, kRowMixed>(r, i, h, s, f, p.keep);
        break;
    }
    if (kGlobal && i > 0) global_row(r, kinds[i - 1], i - 1, h, p);
  }
  if (kGlobal && n > 0) global_row(r, kinds[n - 1], n - 1, h, p);
}

// Eq. 2 as a stage of its own (the blocks that time their stages).
void global_shape(const Rows& r, const RowKind* kinds, int n, const Substep& s, const BlockParams& p) {
  const soa::AffinePose h(s.m, s.t);
  for (int i = 0; i < n; ++i) global_row(r, kinds[i], i, h, p);
}

// The local constraint's mass weights w_{i-1}/(w_{i-1}+w_i) and w_i/(w_{i-1}+w_i) of
// every edge: constant, so divided once per frame instead of once per iteration.
void mass_weights(const Rows& r, int n, float* __restrict ka, float* __restrict kb) {
  const float* __restrict iw = r.iw;
  for (int i = 1; i < n; ++i) {
    const int a = (i - 1) * W, b = i * W;
    LANES {
      const float wsum = iw[a + l] + iw[b + l];
      ka[b + l] = iw[a + l] / wsum;
      kb[b + l] = iw[b + l] / wsum;
    }
  }
}

// Method 3 (Algorithm 5): the head-rotated rest edges, once per substep into scratch...
void rest_edges_m3(const Rows& r, int n, const Substep& s, float* ex, float* ey, float* ez) {
  for (int i = 2; i < n; ++i) {
    const int o = i * W;
    LANES {
      rotate(s.q[0], s.q[1], s.q[2], s.q[3], r.rx[o + l] - r.rx[o + l - W], r.ry[o + l] - r.ry[o + l - W],
             r.rz[o + l] - r.rz[o + l - W], ex[o + l], ey[o + l], ez[o + l]);
    }
  }
}

// ...then every iteration's goals are P_{i-1} + that edge, in even/odd batches (§5): see
// edge_pass below.
struct LocalRows {
  const float *ex, *ey, *ez;  // the rest edges of rest_edges_m3
  const float *ka, *kb;       // mass_weights
  float stiffness;
};

// The edge length constraint (edge_length) of an edge (a, b), on one lane's values.
inline void length_lane(float& ax, float& ay, float& az, float& bx, float& by, float& bz, float aw, float bw,
                        float rl) {
  const float wsum = aw + bw;
  const float dx = bx - ax, dy = by - ay, dz = bz - az;
  const float len = std::sqrt(dx * dx + (dy * dy + dz * dz));
  const bool on = wsum != 0.0f && len > 0.0f;
  const float k = (len - rl) / (len * wsum);
  const float cx = dx * k, cy = dy * k, cz = dz * k;
  const float nax = ax + aw * cx, nay = ay + aw * cy, naz = az + aw * cz;
  const float nbx = bx - bw * cx, nby = by - bw * cy, nbz = bz - bw * cz;
  move_edge_if(on, ax, ay, az, bx, by, bz, nax, nay, naz, nbx, nby, nbz);
}

// A pass over the edges (i-1, i), i = first, first + 2, ... < n: the local constraint of
// method 3 (Algorithm 5's even/odd batches; its edges start at i = 2) or the length
// constraint (its edges start at i = 1), or both, one after the other on each edge.
// Algorithm 1 alternates local and length iterations, each an even and an odd batch:
// local i = 2, 4, ... then 3, 5, ...; length 1, 3, ... then 2, 4, .... The last batch of
// one iteration and the first of the next take the same pairs of vertices, and the pairs
// of a batch are disjoint, so applying both constraints to a pair before moving to the
// next gives every constraint the positions it had batch by batch: the same bits, with
// the pair loaded and stored once instead of twice.
enum class EdgeOp : std::uint8_t { kNone, kLocal, kLength };

// The rows one edge reads and writes, as restrict pointers, so that the compiler need
// not assume a store to a position may change the weights or rest edges.
struct EdgeRowPtrs {
  float *__restrict ax, *__restrict ay, *__restrict az, *__restrict bx, *__restrict by, *__restrict bz;
  const float *__restrict aw, *__restrict bw, *__restrict rl, *__restrict ka, *__restrict kb, *__restrict ex,
      *__restrict ey, *__restrict ez;
};

template <EdgeOp kOp>
inline void apply_edge(float& ax, float& ay, float& az, float& bx, float& by, float& bz, float aw, float bw,
                       const EdgeRowPtrs& e, float stiffness, int l) {
  if constexpr (kOp == EdgeOp::kLocal)  // method 3's goal: P_{i-1} + the rotated rest edge
    local_lane(ax, ay, az, bx, by, bz, aw + bw != 0.0f, e.ka[l], e.kb[l], ax + e.ex[l], ay + e.ey[l], az + e.ez[l],
               stiffness);
  else if constexpr (kOp == EdgeOp::kLength)
    length_lane(ax, ay, az, bx, by, bz, aw, bw, e.rl[l]);
}

// Inlined, as edge_batch: a batch of a model-1 strand is about five edges, and a call per
// batch cost more than the merging saved.
template <EdgeOp kFirst, EdgeOp kSecond>
[[gnu::always_inline]] inline void edge_pass(const Rows& r, const LocalRows& m, int first, int n) {
  const float stiffness = m.stiffness;
  const bool local = kFirst == EdgeOp::kLocal || kSecond == EdgeOp::kLocal;
  for (int i = first; i < n; i += 2) {
    const int a = (i - 1) * W, b = i * W;
    const EdgeRowPtrs e{r.px + a,
                        r.py + a,
                        r.pz + a,
                        r.px + b,
                        r.py + b,
                        r.pz + b,
                        r.iw + a,
                        r.iw + b,
                        r.rl + b,
                        local ? m.ka + b : nullptr,
                        local ? m.kb + b : nullptr,
                        local ? m.ex + b : nullptr,
                        local ? m.ey + b : nullptr,
                        local ? m.ez + b : nullptr};
    LANES {
      float ax = e.ax[l], ay = e.ay[l], az = e.az[l], bx = e.bx[l], by = e.by[l], bz = e.bz[l];
      const float aw = e.aw[l], bw = e.bw[l];
      apply_edge<kFirst>(ax, ay, az, bx, by, bz, aw, bw, e, stiffness, l);
      apply_edge<kSecond>(ax, ay, az, bx, by, bz, aw, bw, e, stiffness, l);
      e.ax[l] = ax;
      e.ay[l] = ay;
      e.az[l] = az;
      e.bx[l] = bx;
      e.by[l] = by;
      e.bz[l] = bz;
    }
  }
}

// One batch of parity `odd` (edges i = 1, 3, ... or 2, 4, ...) applying `first` then
// `second` (kNone: one constraint only). Edge (0, 1) has no local constraint.
[[gnu::always_inline]] inline void edge_batch(const Rows& r, const LocalRows& m, int n, bool odd, EdgeOp first,
                                              EdgeOp second) {
  if (odd && (first == EdgeOp::kLength || second == EdgeOp::kLength))
    edge_pass<EdgeOp::kLength, EdgeOp::kNone>(r, m, 1, n < 2 ? n : 2);
  const int i = odd ? 3 : 2;
  if (first == EdgeOp::kLocal && second == EdgeOp::kLength)
    edge_pass<EdgeOp::kLocal, EdgeOp::kLength>(r, m, i, n);
  else if (first == EdgeOp::kLength && second == EdgeOp::kLocal)
    edge_pass<EdgeOp::kLength, EdgeOp::kLocal>(r, m, i, n);
  else if (first == EdgeOp::kLocal)
    edge_pass<EdgeOp::kLocal, EdgeOp::kNone>(r, m, i, n);
  else
    edge_pass<EdgeOp::kLength, EdgeOp::kNone>(r, m, i, n);
}

// Algorithm 1 lines 7-9 for method 3: local shape and edge length iterations alternate,
// each up to its count, as batches batch(odd, first, second) in order. With merge, a batch
// of the parity of the one before joins it (see edge_pass).
template <class Batch>
void m3_iterations(int local_iterations, int length_iterations, bool merge, Batch&& batch) {
  bool open = false, odd = false;
  EdgeOp first = EdgeOp::kNone, second = EdgeOp::kNone;
  auto add = [&](bool parity, EdgeOp op) {
    if (open && merge && parity == odd && second == EdgeOp::kNone) {
      second = op;
      return;
    }
    if (open) batch(odd, first, second);
    open = true;
    odd = parity;
    first = op;
    second = EdgeOp::kNone;
  };
  const int iterations = local_iterations > length_iterations ? local_iterations : length_iterations;
  for (int it = 0; it < iterations; ++it) {
    if (it < local_iterations) {
      add(false, EdgeOp::kLocal);
      add(true, EdgeOp::kLocal);
    }
    if (it < length_iterations) {
      add(true, EdgeOp::kLength);
      add(false, EdgeOp::kLength);
    }
  }
  if (open) batch(odd, first, second);
}

// Method 1 (Algorithm 3): serial root to tip, the frame rebuilt after every edge. Each
// edge waits on the frame of the one before (a chain of square roots and divisions), so
// C blocks run side by side: their chains are independent and overlap in the core.
struct M1Block {
  Rows r;
  const float *lx, *ly, *lz, *rest_frames, *ka, *kb;
};

template <int C>
void local_m1(const M1Block* blk, int n, const Substep& s, float stiffness) {
  if (n < 3) return;
  alignas(64) float hx[W], hy[W], hz[W], hw[W], gx[C][W], gy[C][W], gz[C][W];
  LANES {
    hx[l] = s.q[0];
    hy[l] = s.q[1];
    hz[l] = s.q[2];
    hw[l] = s.q[3];
  }
  Quat frame[C];
  for (int j = 0; j < C; ++j) {
    const float* rr1 = blk[j].rest_frames + 4 * W;  // w, x, y, z rows of wR_1^0
    quat_mul(hx, hy, hz, hw, rr1 + W, rr1 + 2 * W, rr1 + 3 * W, rr1, frame[j]);
  }
  for (int i = 2; i < n; ++i) {
    const int a = (i - 1) * W, b = i * W;
    for (int j = 0; j < C; ++j) {
      const M1Block& k = blk[j];
      const Rows& r = k.r;
      LANES {
        float ox, oy, oz;
        rotate(frame[j].x[l], frame[j].y[l], frame[j].z[l], frame[j].w[l], k.lx[b + l], k.ly[b + l], k.lz[b + l], ox,
               oy, oz);
        gx[j][l] = r.px[a + l] + ox;
        gy[j][l] = r.py[a + l] + oy;
        gz[j][l] = r.pz[a + l] + oz;
      }
      local_edge(r.px + a, r.py + a, r.pz + a, r.iw + a, r.px + b, r.py + b, r.pz + b, r.iw + b, k.ka + b, k.kb + b,
                 gx[j], gy[j], gz[j], stiffness);
      child_frame(frame[j], frame[j], r.px + a, r.py + a, r.pz + a, r.px + b, r.py + b, r.pz + b, frame[j]);
    }
  }
}

// Method 2 (Algorithm 4, local_shape_m2): the frames are kept relative to the head and
// composed with its rotation where used; goals and parents come from the previous
// iteration's frames (copied to scratch), even/odd batches, each edge's frame rebuilt
// right after that edge's constraint, except where the rest edge is rounding-sized
// (`rounding`, count rows): there the frame is the parent's composed with the rest
// relative rotation. Rows 0 and 1 of the frames hold the rest frames of the pinned
// vertices from the start and are never written.
void local_m2(const Rows& r, int n, const float* lx, const float* ly, const float* lz, float* ow, float* ox, float* oy,
              float* oz, float* scratch, const float* ka, const float* kb, const RoundingRow* rounding, int count,
              const Substep& s, float stiffness) {
  if (n < 3) return;
  alignas(64) float hx[W], hy[W], hz[W], hw[W], gx[W], gy[W], gz[W];
  LANES {
    hx[l] = s.q[0];
    hy[l] = s.q[1];
    hz[l] = s.q[2];
    hw[l] = s.q[3];
  }
  const int nw = n * W;
  float *sw = scratch, *sx = scratch + nw, *sy = scratch + 2 * nw, *sz = scratch + 3 * nw;
  const std::size_t bytes = static_cast<std::size_t>(nw) * sizeof(float);
  std::memcpy(sw, ow, bytes);
  std::memcpy(sx, ox, bytes);
  std::memcpy(sy, oy, bytes);
  std::memcpy(sz, oz, bytes);
  for (int first : {2, 3})
    for (int i = first; i < n; i += 2) {
      const int a = (i - 1) * W, b = i * W;
      Quat parent, world, out;
      LANES {
        parent.x[l] = sx[a + l];
        parent.y[l] = sy[a + l];
        parent.z[l] = sz[a + l];
        parent.w[l] = sw[a + l];
      }
      quat_mul(hx, hy, hz, hw, parent.x, parent.y, parent.z, parent.w, world);
      LANES {
        float tx, ty, tz;
        rotate(world.x[l], world.y[l], world.z[l], world.w[l], lx[b + l], ly[b + l], lz[b + l], tx, ty, tz);
        gx[l] = r.px[a + l] + tx;
        gy[l] = r.py[a + l] + ty;
        gz[l] = r.pz[a + l] + tz;
      }
      local_edge(r.px + a, r.py + a, r.pz + a, r.iw + a, r.px + b, r.py + b, r.pz + b, r.iw + b, ka + b, kb + b, gx, gy, gz,
                 stiffness);
      child_frame(parent, world, r.px + a, r.py + a, r.pz + a, r.px + b, r.py + b, r.pz + b, out);
      LANES {
        ow[b + l] = out.w[l];
        ox[b + l] = out.x[l];
        oy[b + l] = out.y[l];
        oz[b + l] = out.z[l];
      }
    }
  // Rounding-sized rest edges: (parent · ^{i-1}T_i^0).normalized() from the previous
  // iteration's parent. It reads no position, so writing it after both batches gives the
  // bits the reference writes right after the edge's constraint.
  for (int k = 0; k < count; ++k) {
    const RoundingRow& e = rounding[k];
    const int a = (e.row - 1) * W, b = e.row * W;
    Quat m;
    quat_mul(sx + a, sy + a, sz + a, sw + a, e.qx, e.qy, e.qz, e.qw, m);
    LANES {
      // Eigen's Quaternion::normalized(), as in child_frame.
      const float n2 = (m.x[l] * m.x[l] + m.z[l] * m.z[l]) + (m.y[l] * m.y[l] + m.w[l] * m.w[l]);
      const float rn = std::sqrt(n2);
      const bool on = e.on[l] != 0.0f, scale = n2 > 0.0f;
      ow[b + l] = on ? (scale ? m.w[l] / rn : m.w[l]) : ow[b + l];
      ox[b + l] = on ? (scale ? m.x[l] / rn : m.x[l]) : ox[b + l];
      oy[b + l] = on ? (scale ? m.y[l] / rn : m.y[l]) : oy[b + l];
      oz[b + l] = on ? (scale ? m.z[l] / rn : m.z[l]) : oz[b + l];
    }
  }
}

// Edge length constraints (edge_length) in even/odd batches.
void edge_length(const Rows& r, int n) {
  const LocalRows none{};
  edge_batch(r, none, n, true, EdgeOp::kLength, EdgeOp::kNone);
  edge_batch(r, none, n, false, EdgeOp::kLength, EdgeOp::kNone);
}

// The lanes of a row (x, y, z, inverse mass) inside sphere (cx, cy, cz, r), as a bit
// mask: pinned lanes (w = 0) never are. With AVX-512 the compare gives the mask
// directly; the loop's form costs a reduction over the lanes (eight instructions).
inline unsigned inside_mask(const float* px, const float* py, const float* pz, const float* iw, float cx, float cy,
                            float cz, float cr) {
#if defined(__AVX512F__)
  const __m512 dx = _mm512_sub_ps(_mm512_load_ps(px), _mm512_set1_ps(cx));
  const __m512 dy = _mm512_sub_ps(_mm512_load_ps(py), _mm512_set1_ps(cy));
  const __m512 dz = _mm512_sub_ps(_mm512_load_ps(pz), _mm512_set1_ps(cz));
  const __m512 d2 = _mm512_add_ps(_mm512_mul_ps(dx, dx), _mm512_add_ps(_mm512_mul_ps(dy, dy), _mm512_mul_ps(dz, dz)));
  const __mmask16 in = _mm512_cmp_ps_mask(d2, _mm512_set1_ps(cr * cr), _CMP_LT_OQ);
  return _mm512_mask_cmp_ps_mask(in, _mm512_load_ps(iw), _mm512_setzero_ps(), _CMP_NEQ_UQ);
#else
  unsigned mask = 0;
  for (int l = 0; l < W; ++l) {
    const float dx = px[l] - cx, dy = py[l] - cy, dz = pz[l] - cz;
    const float d2 = dx * dx + (dy * dy + dz * dz);
    mask |= static_cast<unsigned>((iw[l] != 0.0f) & (d2 < cr * cr)) << l;
  }
  return mask;
#endif
}

// Sphere collisions (collide_spheres): up to four passes. A pass depends on the row alone,
// so passes stop once one leaves the row as it was, bit for bit: every pass after it
// would do the same. That is the case when no lane was inside, and also often when the
// lanes projected onto a sphere round to points still inside it: the projection then
// repeats itself (on a groom resting on its spheres, such as model 1's, a large share of
// the passes over rows in contact).
// Most rows have no lane inside any sphere: they are found by one test of every sphere
// (a row outside every sphere is not moved by any pass).
void collide(const Rows& r, const RowKind* kinds, int n, const Substep& s) {
  constexpr int kPasses = 4;
  const float* sp = s.spheres;
  for (int i = 0; i < n; ++i) {
    if (kinds[i] == kRowPinned) continue;
    const int o = i * W;
    float *px = r.px + o, *py = r.py + o, *pz = r.pz + o;
    const float* iw = r.iw + o;
    unsigned any = 0;
    for (int c = 0; c < s.sphere_count; ++c)
      any |= inside_mask(px, py, pz, iw, sp[4 * c], sp[4 * c + 1], sp[4 * c + 2], sp[4 * c + 3]);
    if (!any) continue;
    for (int pass = 0; pass < kPasses; ++pass) {
      alignas(64) float ox[W], oy[W], oz[W];  // the row before this pass
      std::memcpy(ox, px, sizeof ox);
      std::memcpy(oy, py, sizeof oy);
      std::memcpy(oz, pz, sizeof oz);
      bool moved = false;
      for (int c = 0; c < s.sphere_count; ++c) {
        const float cx = sp[4 * c], cy = sp[4 * c + 1], cz = sp[4 * c + 2], cr = sp[4 * c + 3];
        if (!inside_mask(px, py, pz, iw, cx, cy, cz, cr)) continue;
        moved = true;
        LANES {
          const float dx = px[l] - cx, dy = py[l] - cy, dz = pz[l] - cz;
          const float d2 = dx * dx + (dy * dy + dz * dz);
          const bool inside = (iw[l] != 0.0f) & (d2 < cr * cr);
          const float d = std::sqrt(d2);
          const bool centre = !(d > 0.0f);
          const float nx = centre ? 0.0f : dx / d, ny = centre ? 1.0f : dy / d, nz = centre ? 0.0f : dz / d;
          px[l] = inside ? cx + nx * cr : px[l];
          py[l] = inside ? cy + ny * cr : py[l];
          pz[l] = inside ? cz + nz * cr : pz[l];
        }
      }
      if (!moved || (soa::same_bits(ox, px) && soa::same_bits(oy, py) && soa::same_bits(oz, pz))) break;
    }
  }
}

// The block's positions and inverse masses from the groom-ordered float4 array into rows.
void read_in(float* px, float* py, float* pz, float* iw, int n, const std::uint32_t* offset, const float* pos) {
  const float* lane_in[W];
  for (int l = 0; l < W; ++l) lane_in[l] = pos + 4 * static_cast<std::size_t>(offset[l]);
  soa::read_rows_float4(lane_in, n, px, py, pz, iw);
}

// The block's positions back to the float4 array (w: the inverse mass, as read).
void write_back(const Rows& r, int n, const std::uint32_t* offset, float* pos) {
  float* lane_out[W];
  for (int l = 0; l < W; ++l)
    lane_out[l] = offset[l] == kNoStrand ? nullptr : pos + 4 * static_cast<std::size_t>(offset[l]);
  soa::write_rows_float4(r.px, r.py, r.pz, r.iw, n, lane_out);
}

// What the stages need of one block.
struct Ctx {
  Rows r;
  const RowKind* kinds;
  float* d;
  float *scratch, *ka, *kb;
  const float* rest_frames;
  const RoundingRow* rounding_rows;
  int rounding_row_count;
  float* field(int k) const { return d + static_cast<std::size_t>(k) * rows; }
  std::size_t rows;
};

void frame(const Block* blocks, int count, const BlockParams& p, const Frame& f, float* pos, float* scratch,
           soa::LineFeed& feed, std::int64_t* stage_ns) {
  const int n = blocks[0].n, method = blocks[0].method;
  const std::size_t rows = static_cast<std::size_t>(n) * W;
  Ctx c[kMaxBlocks];
  M1Block m1[kMaxBlocks];
  for (int j = 0; j < count; ++j) {
    float* d = blocks[j].data;
    auto field = [&](int k) { return d + static_cast<std::size_t>(k) * rows; };
    float* sc = scratch + static_cast<std::size_t>(j) * scratch_floats(n);
    // Scratch rows 0-3: method 3's rest edges or method 2's frames; 4-5: the mass
    // weights; 6-9: the positions and inverse masses.
    float *px = sc + 6 * rows, *py = sc + 7 * rows, *pz = sc + 8 * rows, *iw = sc + 9 * rows;
    read_in(px, py, pz, iw, n, blocks[j].in_offset, pos);
    c[j] = Ctx{{px, py, pz, field(QX), field(QY), field(QZ), iw, field(RX), field(RY), field(RZ), field(RL)},
               blocks[j].rows,
               d,
               sc,
               sc + 4 * rows,
               sc + 5 * rows,
               method == 1 ? d + static_cast<std::size_t>(field_count(method)) * rows : nullptr,
               blocks[j].rounding_rows,
               blocks[j].rounding_row_count,
               rows};
    if (method == 1)
      m1[j] = M1Block{c[j].r, field(LX), field(LY), field(LZ), c[j].rest_frames, c[j].ka, c[j].kb};
  }
  const bool local_on = p.local_iterations > 0;
  const int iterations = p.local_iterations > p.length_iterations ? p.local_iterations : p.length_iterations;
  // Stages that share their passes over the rows (global shape inside integration;
  // method 3's local and length batches merged, edge_pass) do so except in the sampled
  // blocks that time their stages: those run every stage apart, so that each has its own
  // clock reads. The same bits either way.
  const bool fuse = stage_ns == nullptr;
  const bool global_apart = p.global_on && !fuse;
  int m3_batches = 0;
  if (method == 3)
    m3_iterations(p.local_iterations, p.length_iterations, fuse, [&](bool, EdgeOp, EdgeOp) { ++m3_batches; });
  soa::StageClock clock(stage_ns);
  // Each finished stage requests its share of the next job's lines.
  const int solve = method == 3 ? local_on + m3_batches : p.local_iterations + p.length_iterations;
  const int per_substep = 1 + global_apart + solve + (f.substep_count > 0 && f.substeps[0].sphere_count > 0);
  feed.pace(local_on + f.substep_count * per_substep);
  auto done = [&](Stage stage) {
    clock.lap(stage);
    feed.step();
  };
  if (local_on) {
    for (int j = 0; j < count; ++j) mass_weights(c[j].r, n, c[j].ka, c[j].kb);
    done(Stage::LocalShape);
  }
  for (int k = 0; k < f.substep_count; ++k) {
    const Substep& s = f.substeps[k];
    auto integrate_blocks = [&]<bool kWindy, bool kGlobal>() {
      for (int j = 0; j < count; ++j) integrate<kWindy, kGlobal>(c[j].r, c[j].kinds, n, s, f, p);
    };
    const bool global_in = p.global_on && fuse;
    if (f.windy)
      global_in ? integrate_blocks.template operator()<true, true>()
                : integrate_blocks.template operator()<true, false>();
    else
      global_in ? integrate_blocks.template operator()<false, true>()
                : integrate_blocks.template operator()<false, false>();
    done(Stage::Integrate);
    if (global_apart) {
      for (int j = 0; j < count; ++j) global_shape(c[j].r, c[j].kinds, n, s, p);
      done(Stage::GlobalShape);
    }
    if (method == 3) {
      if (local_on) {
        for (int j = 0; j < count; ++j)
          rest_edges_m3(c[j].r, n, s, c[j].scratch, c[j].scratch + rows, c[j].scratch + 2 * rows);
        done(Stage::LocalShape);
      }
      m3_iterations(p.local_iterations, p.length_iterations, fuse, [&](bool odd, EdgeOp first, EdgeOp second) {
        for (int j = 0; j < count; ++j) {
          const Ctx& b = c[j];
          const LocalRows m{b.scratch, b.scratch + rows, b.scratch + 2 * rows, b.ka, b.kb, p.local_stiffness};
          edge_batch(b.r, m, n, odd, first, second);
        }
        done(first == EdgeOp::kLocal ? Stage::LocalShape : Stage::Length);
      });
    }
    // Algorithm 1 lines 7-9 for methods 1 and 2: local shape and edge length alternate,
    // each up to its count.
    for (int it = 0; method != 3 && it < iterations; ++it) {
      if (it < p.local_iterations) {
        if (method == 1) {
          if (count == 2)
            local_m1<2>(m1, n, s, p.local_stiffness);
          else
            local_m1<1>(m1, n, s, p.local_stiffness);
        } else {
          for (int j = 0; j < count; ++j) {
            const Ctx& b = c[j];
            local_m2(b.r, n, b.field(LX), b.field(LY), b.field(LZ), b.field(OW), b.field(OX), b.field(OY),
                     b.field(OZ), b.scratch, b.ka, b.kb, b.rounding_rows, b.rounding_row_count, s,
                     p.local_stiffness);
          }
        }
        done(Stage::LocalShape);
      }
      if (it < p.length_iterations) {
        for (int j = 0; j < count; ++j) edge_length(c[j].r, n);
        done(Stage::Length);
      }
    }
    if (s.sphere_count > 0) {
      for (int j = 0; j < count; ++j) collide(c[j].r, c[j].kinds, n, s);
      done(Stage::Collision);
    }
  }
  for (int j = 0; j < count; ++j) write_back(c[j].r, n, blocks[j].out_offset, pos);
  feed.finish();
}

}  // namespace

FrameFn frame_fn() { return &frame; }

}  // namespace hairbench::kernels::han_soa::HAIRBENCH_ISA_VARIANT
