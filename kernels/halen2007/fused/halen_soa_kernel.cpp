// The fused block kernel of halen_soa.h. This file is compiled once per ISA variant
// (kernels/CMakeLists.txt), each time with HAIRBENCH_ISA_VARIANT naming the namespace; the
// loops over lanes are written plainly so the compiler turns each into vector
// instructions of that variant.
#include "kernels/halen2007/fused/halen_soa.h"
#include "kernels/simd/soa_common.h"
#include "kernels/simd/soa_rows.h"

#include <cmath>
#include <cstdint>
#include <cstring>

#ifndef HAIRBENCH_ISA_VARIANT
#error "HAIRBENCH_ISA_VARIANT must name the ISA variant"
#endif

namespace hairbench::kernels::halen_soa::HAIRBENCH_ISA_VARIANT {

namespace {

constexpr int W = kLanes;
static_assert(W == soa::kRowLanes, "soa_rows.h takes rows of 16 lanes");

#define LANES _Pragma("GCC ivdep") for (int l = 0; l < W; ++l)

// A block's rows: [component][vertex][lane].
struct Rows {
  int n;
  // Positions; the spring model's previous positions, the cascade's last steps p - p_prev
  // (the step form of strand_kernels.h).
  float *px, *py, *pz, *qx, *qy, *qz;
  float *ax, *ay, *az;                 // the cascade's spring accelerations
  // The cascade's twist (cascade_accelerations): per space the springs' load on its
  // twist, its bend's κ, and 1 where the bend is taken (a space of its own, not folded back).
  float *tw, *kx, *ky, *kz, *bend;
  const float* c;                      // the block's fields
  const RowKind* kind;
  const float* field(int f, int i) const { return c + (static_cast<std::size_t>(f) * n + i) * W; }
};

// Pinned vertices follow the head (follow_head_steps): pos = head · rest, step = the
// move; the cascade's, before its references read the moved roots. The pose is taken by value:
// through a reference the compiler must assume the row stores may change it, and leaves
// the lane loop scalar.
void follow_head(const Rows& r, const soa::AffinePose h) {
  for (int i = 0; i < r.n; ++i) {
    if (r.kind[i] == kRowFree) continue;
    const int o = i * W;
    const float *rx = r.field(RX, i), *ry = r.field(RY, i), *rz = r.field(RZ, i), *iw = r.field(IW, i);
    float *px = r.px + o, *py = r.py + o, *pz = r.pz + o, *qx = r.qx + o, *qy = r.qy + o, *qz = r.qz + o;
    LANES {
      const bool pinned = iw[l] == 0.0f;
      const float x = px[l], y = py[l], z = pz[l];
      px[l] = pinned ? h.x(rx[l], ry[l], rz[l]) : x;
      py[l] = pinned ? h.y(rx[l], ry[l], rz[l]) : y;
      pz[l] = pinned ? h.z(rx[l], ry[l], rz[l]) : z;
      qx[l] = pinned ? px[l] - x : qx[l];
      qy[l] = pinned ? py[l] - y : qy[l];
      qz[l] = pinned ? pz[l] - z : qz[l];
    }
  }
}

// One substep's integration, row by row; every stage of the per-strand kernels reads only
// its own row, so they run fused on a row while it is in registers: for the spring model
// the reference node rigid with the head, lifted against gravity (§4.4, head_references)
// and follow_head; then Verlet with damping from vertex 1 (verlet_integrate; the
// cascade's in step form, verlet_integrate_steps), and the springs: the spring model's
// zero-rest-length pull towards its reference node (add_spring_acceleration),
// p += (scale k dt²)(ref - p_start); the cascade's accelerations from cascade_forces
// (add_acceleration), p and its step += dt² a. The one read across
// rows is the wind term's, which sees vertex i-1 as Verlet left it, before its springs:
// that row is kept aside. Rows whose lanes are all free or all pinned take no per-lane
// selects.
struct Integration {
  soa::AffinePose h;
  float gx, gy, gz, wx, wy, wz;
  float keep, dt2;
  float scale;  // the spring model's tilt factor, 1 for the cascade
};

// Vertex i-1 after Verlet, before its springs (the wind term's).
struct Moved {
  alignas(64) float x[W], y[W], z[W];
};

template <Model kModel, bool kWindy, RowKind kKind, bool kRoot>
inline void integrate_row(const Rows& r, int i, const Integration& in, Moved& m) {
  constexpr bool kSpring = kModel == Model::Spring;
  const soa::AffinePose h = in.h;
  const float gx = in.gx, gy = in.gy, gz = in.gz, keep = in.keep, dt2 = in.dt2, scale = in.scale;
  [[maybe_unused]] const float wx = in.wx, wy = in.wy, wz = in.wz;
  const float gdx = gx * dt2, gdy = gy * dt2, gdz = gz * dt2;
  const int o = i * W;
  const float *rx = r.field(RX, i), *ry = r.field(RY, i), *rz = r.field(RZ, i), *iw = r.field(IW, i);
  float *px = r.px + o, *py = r.py + o, *pz = r.pz + o, *qx = r.qx + o, *qy = r.qy + o, *qz = r.qz + o;
  float *mx = m.x, *my = m.y, *mz = m.z;
  if constexpr (kKind == kRowPinned) {
    if constexpr (kSpring) soa::follow_head_row(h, px, py, pz, qx, qy, qz, rx, ry, rz);
    if constexpr (kWindy)
      LANES {
        mx[l] = px[l];
        my[l] = py[l];
        mz[l] = pz[l];
      }
    return;
  }
  const float *lift = r.field(LIFT, i), *ku = r.field(KU, i);
  const float *cx = r.ax + o, *cy = r.ay + o, *cz = r.az + o;
  LANES {
    const bool free = kKind == kRowFree || iw[l] != 0.0f;
    const float x = px[l], y = py[l], z = pz[l];
    float nx = x, ny = y, nz = z, ox = qx[l], oy = qy[l], oz = qz[l];
    if constexpr (kSpring && kKind == kRowMixed) {  // follow_head
      nx = free ? x : h.x(rx[l], ry[l], rz[l]);
      ny = free ? y : h.y(rx[l], ry[l], rz[l]);
      nz = free ? z : h.z(rx[l], ry[l], rz[l]);
      ox = free ? ox : x;
      oy = free ? oy : y;
      oz = free ? oz : z;
    }
    if constexpr (!kRoot) {  // verlet_integrate
      float ddx = gdx, ddy = gdy, ddz = gdz;
      if constexpr (kWindy) {
        const float ex = x - mx[l], ey = y - my[l], ez = z - mz[l];
        const float len2 = ex * ex + (ey * ey + ez * ez);
        const float len = std::sqrt(len2);
        const bool ok = len2 > 0.0f;
        const float tx = ok ? ex / len : 0.0f, ty = ok ? ey / len : 0.0f, tz = ok ? ez / len : 0.0f;
        const float dw = wx * tx + (wy * ty + wz * tz);
        ddx = (gx + (wx - dw * tx)) * dt2;
        ddy = (gy + (wy - dw * ty)) * dt2;
        ddz = (gz + (wz - dw * tz)) * dt2;
      }
      if constexpr (kSpring) {
        nx = free ? (x + keep * (x - ox)) + ddx : nx;
        ny = free ? (y + keep * (y - oy)) + ddy : ny;
        nz = free ? (z + keep * (z - oz)) + ddz : nz;
        ox = free ? x : ox;
        oy = free ? y : oy;
        oz = free ? z : oz;
      } else {  // verlet_integrate_steps
        const float sx = keep * ox + ddx, sy = keep * oy + ddy, sz = keep * oz + ddz;
        nx = free ? x + sx : nx;
        ny = free ? y + sy : ny;
        nz = free ? z + sz : nz;
        ox = free ? sx : ox;
        oy = free ? sy : oy;
        oz = free ? sz : oz;
      }
    }
    if constexpr (kWindy) {
      mx[l] = nx;
      my[l] = ny;
      mz[l] = nz;
    }
    if constexpr (kSpring) {
      const float ax = h.x(rx[l], ry[l], rz[l]) - gx * lift[l];  // the reference node
      const float ay = h.y(rx[l], ry[l], rz[l]) - gy * lift[l];
      const float az = h.z(rx[l], ry[l], rz[l]) - gz * lift[l];
      const float c = (scale * ku[l]) * dt2;
      nx = free ? nx + c * (ax - ox) : nx;
      ny = free ? ny + c * (ay - oy) : ny;
      nz = free ? nz + c * (az - oz) : nz;
    } else {  // add_acceleration: the position and its step
      const float ddx = dt2 * cx[l], ddy = dt2 * cy[l], ddz = dt2 * cz[l];
      nx = free ? nx + ddx : nx;
      ny = free ? ny + ddy : ny;
      nz = free ? nz + ddz : nz;
      ox = free ? ox + ddx : ox;
      oy = free ? oy + ddy : oy;
      oz = free ? oz + ddz : oz;
    }
    px[l] = nx;
    py[l] = ny;
    pz[l] = nz;
    qx[l] = ox;
    qy[l] = oy;
    qz[l] = oz;
  }
}

template <Model kModel, bool kWindy, bool kRoot>
inline void integrate_row(const Rows& r, int i, const Integration& in, Moved& m) {
  switch (r.kind[i]) {
    case kRowFree:
      integrate_row<kModel, kWindy, kRowFree, kRoot>(r, i, in, m);
      break;
    case kRowPinned:
      integrate_row<kModel, kWindy, kRowPinned, kRoot>(r, i, in, m);
      break;
    default:
      integrate_row<kModel, kWindy, kRowMixed, kRoot>(r, i, in, m);
      break;
  }
}

template <Model kModel, bool kWindy>
void integrate(const Rows& r, const Integration& in) {
  Moved m;
  // The integrator starts at vertex 1.
  integrate_row<kModel, kWindy, true>(r, 0, in, m);
  for (int i = 1; i < r.n; ++i) integrate_row<kModel, kWindy, false>(r, i, in, m);
}

// Edge length constraints (edge_length): odd edges, then even ones, mass-weighted; kSteps:
// each correction also to the vertices' steps (edge_length_steps).
template <bool kSteps>
void edge_length(const Rows& r) {
  for (int first : {1, 2})
    for (int i = first; i < r.n; i += 2) {
      if (r.kind[i] == kRowPinned && r.kind[i - 1] == kRowPinned) continue;
      const int o = i * W;
      const float *aw = r.field(IW, i - 1), *bw = r.field(IW, i), *rl = r.field(RL, i);
      float *ax = r.px + o - W, *ay = r.py + o - W, *az = r.pz + o - W;
      float *bx = r.px + o, *by = r.py + o, *bz = r.pz + o;
      float *sax = r.qx + o - W, *say = r.qy + o - W, *saz = r.qz + o - W;
      float *sbx = r.qx + o, *sby = r.qy + o, *sbz = r.qz + o;
      LANES {
        const float wsum = aw[l] + bw[l];
        const float dx = bx[l] - ax[l], dy = by[l] - ay[l], dz = bz[l] - az[l];
        const float len = std::sqrt(dx * dx + (dy * dy + dz * dz));
        const bool on = wsum != 0.0f && len > 0.0f;
        const float s = (len - rl[l]) / (len * wsum);
        const float cx = dx * s, cy = dy * s, cz = dz * s;
        const float acx = aw[l] * cx, acy = aw[l] * cy, acz = aw[l] * cz;
        const float bcx = bw[l] * cx, bcy = bw[l] * cy, bcz = bw[l] * cz;
        ax[l] = on ? ax[l] + acx : ax[l];
        ay[l] = on ? ay[l] + acy : ay[l];
        az[l] = on ? az[l] + acz : az[l];
        bx[l] = on ? bx[l] - bcx : bx[l];
        by[l] = on ? by[l] - bcy : by[l];
        bz[l] = on ? bz[l] - bcz : bz[l];
        if constexpr (kSteps) {
          sax[l] = on ? sax[l] + acx : sax[l];
          say[l] = on ? say[l] + acy : say[l];
          saz[l] = on ? saz[l] + acz : saz[l];
          sbx[l] = on ? sbx[l] - bcx : sbx[l];
          sby[l] = on ? sby[l] - bcy : sby[l];
          sbz[l] = on ? sbz[l] - bcz : sbz[l];
        }
      }
    }
}

// Whether any of a row's W int flags (0 or 1) is set: the flags as bytes, read back in
// 8-byte words (an OR reduction over int lanes compiles to one extract per lane).
inline bool any_lane(const int* flags) {
  alignas(64) std::uint8_t bytes[W];
  LANES { bytes[l] = static_cast<std::uint8_t>(flags[l]); }
  std::uint64_t any = 0;
  for (int w = 0; w < W; w += 8) {
    std::uint64_t word;
    std::memcpy(&word, bytes + w, sizeof word);
    any |= word;
  }
  return any != 0;
}

// Sphere collisions (collide_spheres). A vector test finds the rows with a free lane
// inside any sphere (about one in five on the model-1 ponytail); a vertex outside every
// sphere is not moved by any pass, so only those rows take the per-strand kernel's
// passes, all lanes at once with the lanes outside masked off. A lane whose pass moved
// nothing would move no more in later passes (the same position meets the same tests), so
// the row stops when no lane moved, as each strand's loop does; and, for the same reason,
// when a pass left the row as it was, bit for bit (lanes projected onto a sphere that
// round to points still inside it repeat the same projection; han_soa_kernel.cpp).
// Vector pushes beat one scalar push per lane inside: the cascade's strands rest on the
// spheres with several lanes of a row inside (on model 1; the spring model does no
// worse).
// The test accumulates into every lane with bitwise operations (no branch, no reduction
// per sphere), so it stays one vector loop per sphere. kSteps: a lane's whole move is
// added to its step (collide_spheres_steps).
template <bool kSteps>
void collide(const Rows& r, const Substep& s) {
  constexpr int kPasses = 4;
  for (int i = 0; i < r.n; ++i) {
    if (r.kind[i] == kRowPinned) continue;
    const int o = i * W;
    const float* iw = r.field(IW, i);
    float *px = r.px + o, *py = r.py + o, *pz = r.pz + o;
    alignas(64) int hit[W];
    LANES { hit[l] = 0; }
    for (int c = 0; c < s.sphere_count; ++c) {
      const float sx = s.spheres[4 * c], sy = s.spheres[4 * c + 1], sz = s.spheres[4 * c + 2],
                  rad = s.spheres[4 * c + 3];
      const float rad2 = rad * rad;
      LANES {
        const float dx = px[l] - sx, dy = py[l] - sy, dz = pz[l] - sz;
        const float dist2 = dx * dx + (dy * dy + dz * dz);
        hit[l] |= static_cast<int>(!(dist2 >= rad2));
      }
    }
    LANES { hit[l] &= static_cast<int>(iw[l] != 0.0f); }
    if (!any_lane(hit)) continue;
    alignas(64) float x0[W], y0[W], z0[W];  // the row before any pass
    if constexpr (kSteps) {
      std::memcpy(x0, px, sizeof x0);
      std::memcpy(y0, py, sizeof y0);
      std::memcpy(z0, pz, sizeof z0);
    }
    for (int pass = 0; pass < kPasses; ++pass) {
      alignas(64) int moved[W];
      alignas(64) float ox[W], oy[W], oz[W];  // the row before this pass
      std::memcpy(ox, px, sizeof ox);
      std::memcpy(oy, py, sizeof oy);
      std::memcpy(oz, pz, sizeof oz);
      LANES { moved[l] = 0; }
      for (int c = 0; c < s.sphere_count; ++c) {
        const float sx = s.spheres[4 * c], sy = s.spheres[4 * c + 1], sz = s.spheres[4 * c + 2],
                    rad = s.spheres[4 * c + 3];
        const float rad2 = rad * rad;
        LANES {
          const float x = px[l], y = py[l], z = pz[l];
          const float dx = x - sx, dy = y - sy, dz = z - sz;
          const float dist2 = dx * dx + (dy * dy + dz * dz);
          const bool inside = (hit[l] != 0) & !(dist2 >= rad2);
          const float dist = std::sqrt(dist2);
          // A vertex exactly at the centre has no closest point; push it straight up.
          const bool off = dist > 0.0f;
          px[l] = inside ? sx + (off ? dx / dist : 0.0f) * rad : x;
          py[l] = inside ? sy + (off ? dy / dist : 1.0f) * rad : y;
          pz[l] = inside ? sz + (off ? dz / dist : 0.0f) * rad : z;
          moved[l] |= static_cast<int>(inside);
        }
      }
      const bool same = soa::same_bits(ox, px) && soa::same_bits(oy, py) && soa::same_bits(oz, pz);
      if (!any_lane(moved) || same) break;
    }
    if constexpr (kSteps) {
      float *qx = r.qx + o, *qy = r.qy + o, *qz = r.qz + o;
      LANES {
        const bool on = hit[l] != 0;
        qx[l] = on ? qx[l] + (px[l] - x0[l]) : qx[l];
        qy[l] = on ? qy[l] + (py[l] - y0[l]) : qy[l];
        qz[l] = on ? qz[l] + (pz[l] - z0[l]) : qz[l];
      }
    }
  }
}

// A tangent space [B N T] of every lane, column by column.
struct Space {
  alignas(64) float v[9][W];
};

// One reference spring (cascade_accelerations' reference_spring): vertex i towards the
// node (lx, ly, lz) of space m, that of the segment ending at row j, and, with
// `reactions`, the elastic part's reaction on the rigid segment (j - BS, j); in the
// reference's order: vertex i, then j, then the segment's first node.
void reference_spring(const Rows& r, const Space& m, int i, int j, const float* lx, const float* ly,
                      const float* lz, const float* k, const Substep& s, bool reactions) {
  const int oi = i * W, oj = j * W;
  const float hgx = s.hg[0], hgy = s.hg[1], hgz = s.hg[2];
  const float *lift = r.field(LIFT, i), *iwi = r.field(IW, i), *lever = r.field(LV, j);
  float *aix = r.ax + oi, *aiy = r.ay + oi, *aiz = r.az + oi;
  const float *pix = r.px + oi, *piy = r.py + oi, *piz = r.pz + oi;
  const float *pjx = r.px + oj, *pjy = r.py + oj, *pjz = r.pz + oj;
  alignas(64) float rx[W], ry[W], rz[W];  // R = -F, the elastic part's reaction
  alignas(64) float fx[W], fy[W], fz[W];  // its share f_A on the segment's first node
  alignas(64) float dx[W], dy[W], dz[W];  // the reference node's offset M w
  LANES {
    const float a = lx[l], b = ly[l], c = lz[l];
    dx[l] = m.v[0][l] * a + (m.v[3][l] * b + m.v[6][l] * c);
    dy[l] = m.v[1][l] * a + (m.v[4][l] * b + m.v[7][l] * c);
    dz[l] = m.v[2][l] * a + (m.v[5][l] * b + m.v[8][l] * c);
    const float kk = k[l];
    const float ex = kk * (dx[l] - (pix[l] - pjx[l]));
    const float ey = kk * (dy[l] - (piy[l] - pjy[l]));
    const float ez = kk * (dz[l] - (piz[l] - pjz[l]));
    const float kl = kk * lift[l];
    const bool free = iwi[l] != 0.0f;
    aix[l] = free ? aix[l] + (ex - kl * hgx) : aix[l];
    aiy[l] = free ? aiy[l] + (ey - kl * hgy) : aiy[l];
    aiz[l] = free ? aiz[l] + (ez - kl * hgz) : aiz[l];
    rx[l] = -ex;
    ry[l] = -ey;
    rz[l] = -ez;
    const float dot = m.v[3][l] * rx[l] + (m.v[4][l] * ry[l] + m.v[5][l] * rz[l]);
    fx[l] = (dot * dx[l] - b * rx[l]) / lever[l];
    fy[l] = (dot * dy[l] - b * ry[l]) / lever[l];
    fz[l] = (dot * dz[l] - b * rz[l]) / lever[l];
  }
  if (!reactions || j == 0) return;  // space 0 is the head's
  const float *bs = r.field(BS, j), *iwj = r.field(IW, j);
  float* tw = r.tw + oj;
  LANES {
    // The spring's load on the twist of space j, N · (d × elastic) (reference_spring).
    const float ex = -rx[l], ey = -ry[l], ez = -rz[l];
    const float cx = dy[l] * ez - dz[l] * ey, cy = dz[l] * ex - dx[l] * ez, cz = dx[l] * ey - dy[l] * ex;
    tw[l] = bs[l] != 0.0f ? tw[l] + (m.v[3][l] * cx + (m.v[4][l] * cy + m.v[5][l] * cz)) : tw[l];
  }
  float *ajx = r.ax + oj, *ajy = r.ay + oj, *ajz = r.az + oj;
  LANES {
    const bool on = bs[l] != 0.0f && iwj[l] != 0.0f;
    ajx[l] = on ? ajx[l] + (rx[l] - fx[l]) : ajx[l];
    ajy[l] = on ? ajy[l] + (ry[l] - fy[l]) : ajy[l];
    ajz[l] = on ? ajz[l] + (rz[l] - fz[l]) : ajz[l];
  }
  // The segment's first node: j-1, or further back where segment j is rounding-sized.
  const float* iwa = r.field(IW, j - 1);
  float *aax = ajx - W, *aay = ajy - W, *aaz = ajz - W;
  alignas(64) int far[W];
  LANES {
    const bool on = bs[l] == 1.0f && iwa[l] != 0.0f;
    aax[l] = on ? aax[l] + fx[l] : aax[l];
    aay[l] = on ? aay[l] + fy[l] : aay[l];
    aaz[l] = on ? aaz[l] + fz[l] : aaz[l];
    far[l] = static_cast<int>(bs[l] > 1.0f);
  }
  if (!any_lane(far)) return;
  for (int l = 0; l < W; ++l) {
    if (!far[l]) continue;
    const int o = (j - static_cast<int>(bs[l])) * W + l;
    if (r.c[static_cast<std::size_t>(IW) * r.n * W + o] == 0.0f) continue;
    r.ax[o] += fx[l];
    r.ay[o] += fy[l];
    r.az[o] += fz[l];
  }
}

// Space j from its parent's, for every lane whose segment has its own direction
// (tangent_spaces); narrow[l] marks the lanes whose B is undefined that way.
template <bool kTransport>
inline void own_space(const Space& parent, Space& cur, const float* ax, const float* ay, const float* az,
                      const float* bx, const float* by, const float* bz, const float* bs, int* narrow) {
  LANES {
    const float ex = bx[l] - ax[l], ey = by[l] - ay[l], ez = bz[l] - az[l];
    const float len = std::sqrt(ex * ex + (ey * ey + ez * ez));
    // & rather than &&: a comparison after && is conditional, which under trapping maths
    // (these kernels keep it) is control flow to GCC, and the loop stays scalar.
    const bool own = (bs[l] == 1.0f) & (len > 0.0f);
    const float nx = ex / len, ny = ey / len, nz = ez / len;
    float b0, b1, b2;
    bool ok;
    if constexpr (kTransport) {
      const float mx = parent.v[3][l], my = parent.v[4][l], mz = parent.v[5][l];
      const float c = mx * nx + (my * ny + mz * nz);
      ok = c > -0.999f;
      const float qx = my * nz - mz * ny, qy = mz * nx - mx * nz, qz = mx * ny - my * nx;  // N_{j-1} × N
      const float Bx = parent.v[0][l], By = parent.v[1][l], Bz = parent.v[2][l];
      const float sc = (qx * Bx + (qy * By + qz * Bz)) / (1.0f + c);
      b0 = (c * Bx + (qy * Bz - qz * By)) + sc * qx;
      b1 = (c * By + (qz * Bx - qx * Bz)) + sc * qy;
      b2 = (c * Bz + (qx * By - qy * Bx)) + sc * qz;
      const float dn = b0 * nx + (b1 * ny + b2 * nz);
      b0 = b0 - dn * nx;
      b1 = b1 - dn * ny;
      b2 = b2 - dn * nz;
      const float bn2 = b0 * b0 + (b1 * b1 + b2 * b2);
      const float bn = std::sqrt(bn2);
      b0 = bn2 > 0.0f ? b0 / bn : b0;
      b1 = bn2 > 0.0f ? b1 / bn : b1;
      b2 = bn2 > 0.0f ? b2 / bn : b2;
    } else {
      const float Tx = parent.v[6][l], Ty = parent.v[7][l], Tz = parent.v[8][l];
      b0 = ny * Tz - nz * Ty;
      b1 = nz * Tx - nx * Tz;
      b2 = nx * Ty - ny * Tx;
      const float bl = std::sqrt(b0 * b0 + (b1 * b1 + b2 * b2));
      ok = bl > 1e-6f;
      b0 = b0 / bl;
      b1 = b1 / bl;
      b2 = b2 / bl;
    }
    narrow[l] = static_cast<int>(own) & static_cast<int>(!ok);
    cur.v[0][l] = own ? b0 : parent.v[0][l];
    cur.v[1][l] = own ? b1 : parent.v[1][l];
    cur.v[2][l] = own ? b2 : parent.v[2][l];
    cur.v[3][l] = own ? nx : parent.v[3][l];
    cur.v[4][l] = own ? ny : parent.v[4][l];
    cur.v[5][l] = own ? nz : parent.v[5][l];
    cur.v[6][l] = own ? ny * b2 - nz * b1 : parent.v[6][l];
    cur.v[7][l] = own ? nz * b0 - nx * b2 : parent.v[7][l];
    cur.v[8][l] = own ? nx * b1 - ny * b0 : parent.v[8][l];
  }
}

// |P_i - P_{i-1}| of every lane, as the reference's norm.
inline void edge_lengths(const Rows& r, int i, float* len) {
  const int o = i * W;
  LANES {
    const float ex = r.px[o + l] - r.px[o - W + l], ey = r.py[o + l] - r.py[o - W + l],
                ez = r.pz[o + l] - r.pz[o - W + l];
    len[l] = std::sqrt(ex * ex + (ey * ey + ez * ez));
  }
}

// p to row `to` and -p to row `from` (free vertices only) of the lanes in `on`: f = (q /
// len) κ, the reference's push.
inline void push_bend(const Rows& r, int to, int from, const float* q, const float* len, const float* kx,
                      const float* ky, const float* kz, const int* on) {
  const float *iwt = r.field(IW, to), *iwf = r.field(IW, from);
  const int ot = to * W, of = from * W;
  LANES {
    const float s = q[l] / len[l];
    const float fx = s * kx[l], fy = s * ky[l], fz = s * kz[l];
    // & rather than &&, as in own_space: so that the loop is vector code.
    const bool t = (on[l] != 0) & (iwt[l] != 0.0f), f = (on[l] != 0) & (iwf[l] != 0.0f);
    r.ax[ot + l] = t ? r.ax[ot + l] + fx : r.ax[ot + l];
    r.ay[ot + l] = t ? r.ay[ot + l] + fy : r.ay[ot + l];
    r.az[ot + l] = t ? r.az[ot + l] + fz : r.az[ot + l];
    r.ax[of + l] = f ? r.ax[of + l] - fx : r.ax[of + l];
    r.ay[of + l] = f ? r.ay[of + l] - fy : r.ay[of + l];
    r.az[of + l] = f ? r.az[of + l] - fz : r.az[of + l];
  }
}

// The springs' reaction through the spaces' twist (cascade_accelerations' twist_reactions),
// tip to root: each bend's load, the springs' loads on the twist of the spaces from it
// on, through the bend's two segments, j's and that of the space before it (almost always
// j - 1; a lane whose j - 1 keeps its parent's space looks further back on its own).
void twist_reactions(const Rows& r) {
  alignas(64) float load[W] = {}, len[W], len_p[W];
  alignas(64) int on[W], near[W], far[W];
  for (int j = r.n - 1; j >= 1; --j) {
    const int o = j * W;
    const float *bend = r.bend + o, *kx = r.kx + o, *ky = r.ky + o, *kz = r.kz + o;
    LANES {
      load[l] += r.tw[o + l];
      on[l] = static_cast<int>(bend[l] != 0.0f);
    }
    if (!any_lane(on)) continue;
    edge_lengths(r, j, len);
    push_bend(r, j, j - 1, load, len, kx, ky, kz, on);
    if (j < 2) continue;
    const float* bs = r.field(BS, j - 1);
    edge_lengths(r, j - 1, len_p);
    LANES {
      const bool own = bs[l] == 1.0f && len_p[l] > 0.0f;
      near[l] = static_cast<int>(on[l] != 0 && own);
      far[l] = static_cast<int>(on[l] != 0 && !own);
    }
    push_bend(r, j - 1, j - 2, load, len_p, kx, ky, kz, near);
    if (!any_lane(far)) continue;
    for (int l = 0; l < W; ++l) {
      if (!far[l]) continue;
      auto own_len = [&](int q) {
        const int a = q * W + l, b = a - W;
        const float ex = r.px[a] - r.px[b], ey = r.py[a] - r.py[b], ez = r.pz[a] - r.pz[b];
        return std::sqrt(ex * ex + (ey * ey + ez * ez));
      };
      int q = j - 1;
      while (q >= 1 && !(r.field(BS, q)[l] == 1.0f && own_len(q) > 0.0f)) --q;
      if (q < 1) continue;
      const float s = load[l] / own_len(q);
      const float fx = s * kx[l], fy = s * ky[l], fz = s * kz[l];
      const int t = q * W + l, f = t - W;
      if (r.field(IW, q)[l] != 0.0f) {
        r.ax[t] += fx;
        r.ay[t] += fy;
        r.az[t] += fz;
      }
      if (r.field(IW, q - 1)[l] != 0.0f) {
        r.ax[f] -= fx;
        r.ay[f] -= fy;
        r.az[f] -= fz;
      }
    }
  }
}

// §4.3's first two steps and the springs' forces (tangent_spaces, cascade_accelerations):
// every acceleration starts from gravity; then the tangent spaces from the root up, each
// used at once for the springs it carries, the upward one of the vertex above it and the
// downward one of the vertex two below it.
void cascade_forces(const Rows& r, const Substep& s, const BlockParams& p, const Frame& f) {
  const int n = r.n;
  const float* root_space = r.c + static_cast<std::size_t>(kCascadeFields) * n * W;
  const float gx = f.gravity[0], gy = f.gravity[1], gz = f.gravity[2];
  for (int i = 0; i < n * W; ++i) {
    r.ax[i] = gx;
    r.ay[i] = gy;
    r.az[i] = gz;
    r.tw[i] = 0.0f;
  }
  // Space 0, the given one at the root: head rotation · its rest space. Then row j's
  // parent is sp[(j - 1) & 1] and its space goes to sp[j & 1].
  Space sp[2];
  for (int col = 0; col < 3; ++col)
    for (int row = 0; row < 3; ++row) {
      const float h0 = s.m[3 * row], h1 = s.m[3 * row + 1], h2 = s.m[3 * row + 2];
      const float *s0 = root_space + (3 * col) * W, *s1 = s0 + W, *s2 = s1 + W;
      float* out = sp[0].v[3 * col + row];
      LANES { out[l] = h0 * s0[l] + (h1 * s1[l] + h2 * s2[l]); }
    }
  auto up = [&](const Space& m, int j) {  // vertex j+1 in space j
    reference_spring(r, m, j + 1, j, r.field(UX, j + 1), r.field(UY, j + 1), r.field(UZ, j + 1), r.field(KU, j + 1),
                     s, p.reactions);
  };
  auto down = [&](const Space& m, int j) {  // vertex j-2 in space j
    reference_spring(r, m, j - 2, j, r.field(DX, j - 2), r.field(DY, j - 2), r.field(DZ, j - 2), r.field(KD, j - 2),
                     s, p.reactions);
  };
  if (n > 1) up(sp[0], 0);
  for (int j = 1; j < n; ++j) {
    const Space& parent = sp[(j - 1) & 1];
    Space& cur = sp[j & 1];
    const int o = j * W;
    const float *ax = r.px + o - W, *ay = r.py + o - W, *az = r.pz + o - W;
    const float *bx = r.px + o, *by = r.py + o, *bz = r.pz + o;
    const float* bs = r.field(BS, j);
    // The segment's own B: B = N × T_{j-1} normalised (Cross) or the parent's B turned with
    // the segment (Transport); where that is undefined, B_{j-1} made perpendicular to N
    // instead. That case is rare: it is computed, for the lanes in it, only in rows that
    // have one. A segment with a base further back (or of zero length) keeps its
    // parent's space.
    alignas(64) int narrow[W];
    if (p.transport)
      own_space<true>(parent, cur, ax, ay, az, bx, by, bz, bs, narrow);
    else
      own_space<false>(parent, cur, ax, ay, az, bx, by, bz, bs, narrow);
    if (any_lane(narrow))
      LANES {
        const bool on = narrow[l] != 0;
        const float nx = cur.v[3][l], ny = cur.v[4][l], nz = cur.v[5][l];
        const float Bx = parent.v[0][l], By = parent.v[1][l], Bz = parent.v[2][l];
        const float dot = Bx * nx + (By * ny + Bz * nz);
        const float vx = Bx - dot * nx, vy = By - dot * ny, vz = Bz - dot * nz;
        const float vn2 = vx * vx + (vy * vy + vz * vz);
        const float vn = std::sqrt(vn2);
        const float b0 = vn2 > 0.0f ? vx / vn : vx, b1 = vn2 > 0.0f ? vy / vn : vy, b2 = vn2 > 0.0f ? vz / vn : vz;
        cur.v[0][l] = on ? b0 : cur.v[0][l];
        cur.v[1][l] = on ? b1 : cur.v[1][l];
        cur.v[2][l] = on ? b2 : cur.v[2][l];
        cur.v[6][l] = on ? ny * b2 - nz * b1 : cur.v[6][l];
        cur.v[7][l] = on ? nz * b0 - nx * b2 : cur.v[7][l];
        cur.v[8][l] = on ? nx * b1 - ny * b0 : cur.v[8][l];
      }
    // The bend between the parent's N and this space's, for the twist's part.
    float *kx = r.kx + o, *ky = r.ky + o, *kz = r.kz + o, *bend = r.bend + o;
    LANES {
      const float ex = bx[l] - ax[l], ey = by[l] - ay[l], ez = bz[l] - az[l];
      const float len = std::sqrt(ex * ex + (ey * ey + ez * ez));
      const float px = parent.v[3][l], py = parent.v[4][l], pz = parent.v[5][l];
      const float nx = cur.v[3][l], ny = cur.v[4][l], nz = cur.v[5][l];
      const float c = px * nx + (py * ny + pz * nz);
      kx[l] = (py * nz - pz * ny) / (1.0f + c);
      ky[l] = (pz * nx - px * nz) / (1.0f + c);
      kz[l] = (px * ny - py * nx) / (1.0f + c);
      bend[l] = bs[l] == 1.0f && len > 0.0f && c > -0.999f ? 1.0f : 0.0f;
    }
    if (j + 1 < n) up(cur, j);
    if (j >= 3) down(cur, j);
  }
  if (p.reactions && p.transport) twist_reactions(r);
}

// The block's positions to the groom-ordered float4 array, for the lanes asked for (w:
// the inverse mass, the groom's w unchanged).
void write_back(const Rows& r, const Block& b, float* out) {
  float* lane_out[W];
  for (int l = 0; l < W; ++l) lane_out[l] = b.write[l] ? out + 4 * static_cast<std::size_t>(b.offset[l]) : nullptr;
  soa::write_rows_float4(r.px, r.py, r.pz, r.field(IW, 0), r.n, lane_out);
}

template <Model kModel>
void frame_impl(const Block& b, const BlockParams& p, const Frame& f, float* out, float* scratch, soa::LineFeed& feed,
                std::int64_t* stage_ns) {
  const int n = b.n;
  const std::size_t rows = static_cast<std::size_t>(n) * W;
  Rows r{n,
         b.state + PX * rows,
         b.state + PY * rows,
         b.state + PZ * rows,
         b.state + QX * rows,
         b.state + QY * rows,
         b.state + QZ * rows,
         scratch,
         scratch + rows,
         scratch + 2 * rows,
         scratch + 3 * rows,
         scratch + 4 * rows,
         scratch + 5 * rows,
         scratch + 6 * rows,
         scratch + 7 * rows,
         b.data,
         b.rows};
  soa::StageClock clock(stage_ns);
  // Each finished stage (and length iteration) requests its share of the next block's lines.
  feed.pace(f.substep_count * ((kModel == Model::Cascade) + 1 + p.length_iterations +
                               (f.substep_count > 0 && f.substeps[0].sphere_count > 0)));
  for (int k = 0; k < f.substep_count; ++k) {
    const Substep& s = f.substeps[k];
    const soa::AffinePose h(s.m, s.t);
    if constexpr (kModel == Model::Cascade) {
      follow_head(r, h);
      cascade_forces(r, s, p, f);
      clock.lap(Stage::References);  // the spring model's references are computed in its integration
      feed.step();
    }
    // The cascade's gravity is in its accelerations (cascade_forces).
    constexpr bool kSpring = kModel == Model::Spring;
    const Integration in{h,
                         kSpring ? f.gravity[0] : 0.0f,
                         kSpring ? f.gravity[1] : 0.0f,
                         kSpring ? f.gravity[2] : 0.0f,
                         f.wind[0],
                         f.wind[1],
                         f.wind[2],
                         p.keep,
                         s.dt2,
                         kSpring ? p.spring_scale[k] : 1.0f};
    if (f.windy)
      integrate<kModel, true>(r, in);
    else
      integrate<kModel, false>(r, in);
    clock.lap(Stage::Integrate);
    feed.step();
    constexpr bool kSteps = kModel == Model::Cascade;  // the step form (strand_kernels.h)
    for (int it = 0; it < p.length_iterations; ++it) {
      edge_length<kSteps>(r);
      feed.step();
    }
    clock.lap(Stage::Length);
    if (s.sphere_count > 0) {
      collide<kSteps>(r, s);
      clock.lap(Stage::Collision);
      feed.step();
    }
  }
  write_back(r, b, out);
  clock.lap(Stage::Integrate);
  feed.finish();
}

void frame(Model model, const Block& b, const BlockParams& p, const Frame& f, float* out, float* scratch,
           soa::LineFeed& feed, std::int64_t* stage_ns) {
  if (model == Model::Spring)
    frame_impl<Model::Spring>(b, p, f, out, scratch, feed, stage_ns);
  else
    frame_impl<Model::Cascade>(b, p, f, out, scratch, feed, stage_ns);
}

}  // namespace

FrameFn frame_fn() { return &frame; }

}  // namespace hairbench::kernels::halen_soa::HAIRBENCH_ISA_VARIANT
