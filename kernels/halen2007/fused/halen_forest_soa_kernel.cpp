// The forest block kernel of halen_soa.h (§4.2, §5.9: forest_pose and forest_integrate of
// halen_kernels.cpp, kLanes strands at a time). Compiled once per ISA variant, like
// halen_soa_kernel.cpp.
#include "kernels/halen2007/fused/halen_soa.h"
#include "kernels/simd/soa_common.h"
#include "kernels/simd/soa_rows.h"
#include "kernels/simd/vec_math.h"

#include <algorithm>
#include <cmath>

#ifndef HAIRBENCH_ISA_VARIANT
#error "HAIRBENCH_ISA_VARIANT must name the ISA variant"
#endif

namespace hairbench::kernels::halen_soa::HAIRBENCH_ISA_VARIANT {

namespace {

constexpr int W = kLanes;
static_assert(W == soa::kRowLanes, "soa_rows.h takes rows of 16 lanes");

#define LANES _Pragma("GCC ivdep") for (int l = 0; l < W; ++l)

struct Rows {
  int n;
  const float* c;        // fields
  float* st;             // state
  float* f;              // frames: 9 rows per vertex, column by column
  float *px, *py, *pz;   // positions
  float *tx, *ty, *tz;   // joint torques
  const RowKind* kind;
  const float* field(int k, int i) const { return c + (static_cast<std::size_t>(k) * n + i) * W; }
  float* state(int k, int i) const { return st + (static_cast<std::size_t>(k) * n + i) * W; }
  float* frame(int i, int e) const { return f + (static_cast<std::size_t>(i) * 9 + e) * W; }
};

// forest_pose: segments ending at a pinned vertex follow the head rigidly; the others are
// rebuilt from the angles, F_i = F_{i-1} R_primary(θ_i) R_y(φ_i), P_i = P_{i-1} + L_i z_i.
template <bool kParentX>
void pose(const Rows& r, const ForestSubstep& h) {
  const float m0 = h.m[0], m1 = h.m[1], m2 = h.m[2], m3 = h.m[3], m4 = h.m[4], m5 = h.m[5], m6 = h.m[6],
              m7 = h.m[7], m8 = h.m[8], t0 = h.t[0], t1 = h.t[1], t2 = h.t[2];
  for (int i = 0; i < r.n; ++i) {
    const int o = i * W;
    const float *iw = r.field(FIW, i), *rx = r.field(FRX, i), *ry = r.field(FRY, i), *rz = r.field(FRZ, i);
    float* F = r.frame(i, 0);
    float *px = r.px + o, *py = r.py + o, *pz = r.pz + o;
    if (r.kind[i] != kRowFree || i == 0) {
      const float* R = r.field(FR0, i);
      const std::size_t fs = static_cast<std::size_t>(r.n) * W;  // field stride
      // The root row is rigid with the head in every lane.
      LANES {
        const bool rigid = iw[l] == 0.0f || i == 0;
        for (int col = 0; col < 3; ++col) {
          const float a = R[(3 * col) * fs + l], b = R[(3 * col + 1) * fs + l], c = R[(3 * col + 2) * fs + l];
          F[(3 * col) * W + l] = rigid ? m0 * a + m1 * b + m2 * c : F[(3 * col) * W + l];
          F[(3 * col + 1) * W + l] = rigid ? m3 * a + m4 * b + m5 * c : F[(3 * col + 1) * W + l];
          F[(3 * col + 2) * W + l] = rigid ? m6 * a + m7 * b + m8 * c : F[(3 * col + 2) * W + l];
        }
        px[l] = rigid ? t0 + (m0 * rx[l] + m1 * ry[l] + m2 * rz[l]) : px[l];
        py[l] = rigid ? t1 + (m3 * rx[l] + m4 * ry[l] + m5 * rz[l]) : py[l];
        pz[l] = rigid ? t2 + (m6 * rx[l] + m7 * ry[l] + m8 * rz[l]) : pz[l];
      }
      if (r.kind[i] == kRowPinned || i == 0) continue;
    }
    const float *th = r.state(TH, i), *ph = r.state(PH, i), *len = r.field(FLEN, i);
    const float* P = r.frame(i - 1, 0);
    const float *qx = r.px + o - W, *qy = r.py + o - W, *qz = r.pz + o - W;
    alignas(64) float st[W], ct[W], sp[W], cp[W];
    LANES {
      sincos_poly(th[l], st[l], ct[l]);
      sincos_poly(ph[l], sp[l], cp[l]);
    }
    const float *P0 = P, *P1 = P + W, *P2 = P + 2 * W, *P3 = P + 3 * W, *P4 = P + 4 * W, *P5 = P + 5 * W,
                *P6 = P + 6 * W, *P7 = P + 7 * W, *P8 = P + 8 * W;
    float *F0 = F, *F1 = F + W, *F2 = F + 2 * W, *F3 = F + 3 * W, *F4 = F + 4 * W, *F5 = F + 5 * W, *F6 = F + 6 * W,
          *F7 = F + 7 * W, *F8 = F + 8 * W;
    LANES {
      const bool free = iw[l] != 0.0f;
      // R = R_primary(θ) R_y(φ): R(row, col) = r<row><col>.
      const float r00 = kParentX ? cp[l] : ct[l] * cp[l], r01 = kParentX ? 0.0f : -st[l],
                  r02 = kParentX ? sp[l] : ct[l] * sp[l];
      const float r10 = kParentX ? st[l] * sp[l] : st[l] * cp[l], r11 = ct[l],
                  r12 = kParentX ? -st[l] * cp[l] : st[l] * sp[l];
      const float r20 = kParentX ? -ct[l] * sp[l] : -sp[l], r21 = kParentX ? st[l] : 0.0f,
                  r22 = kParentX ? ct[l] * cp[l] : cp[l];
      // F = P R, column by column (P0..P2 the parent's x axis, P3..P5 y, P6..P8 z).
      const float f0 = P0[l] * r00 + P3[l] * r10 + P6[l] * r20, f1 = P1[l] * r00 + P4[l] * r10 + P7[l] * r20,
                  f2 = P2[l] * r00 + P5[l] * r10 + P8[l] * r20;
      const float f3 = P0[l] * r01 + P3[l] * r11 + P6[l] * r21, f4 = P1[l] * r01 + P4[l] * r11 + P7[l] * r21,
                  f5 = P2[l] * r01 + P5[l] * r11 + P8[l] * r21;
      const float f6 = P0[l] * r02 + P3[l] * r12 + P6[l] * r22, f7 = P1[l] * r02 + P4[l] * r12 + P7[l] * r22,
                  f8 = P2[l] * r02 + P5[l] * r12 + P8[l] * r22;
      F0[l] = free ? f0 : F0[l];
      F1[l] = free ? f1 : F1[l];
      F2[l] = free ? f2 : F2[l];
      F3[l] = free ? f3 : F3[l];
      F4[l] = free ? f4 : F4[l];
      F5[l] = free ? f5 : F5[l];
      F6[l] = free ? f6 : F6[l];
      F7[l] = free ? f7 : F7[l];
      F8[l] = free ? f8 : F8[l];
      px[l] = free ? qx[l] + len[l] * f6 : px[l];
      py[l] = free ? qy[l] + len[l] * f7 : py[l];
      pz[l] = free ? qz[l] + len[l] * f8 : pz[l];
    }
  }
}

// forest_integrate: one explicit Euler step of the joint angles (Eq. 4.2.1-4.2.6).
void integrate(const Rows& r, const ForestSubstep& h, const ForestFrame& f, const ForestParams& p) {
  const int n = r.n;
  const int prim = f.parent_x ? 0 : 2;  // the parent's primary axis: column 0 (x) or 2 (z)
  const float v = p.joint_damping, dt = f.dt;
  const float keep = std::exp(-p.drag * dt);
  const float push = p.collision_stiffness / (dt * dt);
  const float damp = 2.0f * p.collision_damping * std::sqrt(p.collision_stiffness) / dt;
  const float gx = f.gravity[0], gy = f.gravity[1], gz = f.gravity[2];
  const float wx = f.wind[0], wy = f.wind[1], wz = f.wind[2];
  const float* in = h.inertia;
  const float m0 = h.m[0], m1 = h.m[1], m2 = h.m[2], m3 = h.m[3], m4 = h.m[4], m5 = h.m[5], m6 = h.m[6],
              m7 = h.m[7], m8 = h.m[8];
  const std::size_t fs = static_cast<std::size_t>(n) * W;
  // Eq. 4.2.2: each joint's spring torque (kθ + vθ')a_p + (kφ + vφ')y.
  for (int i = 1; i < n; ++i) {
    const int o = i * W;
    const float *iw = r.field(FIW, i), *k = r.field(FK, i), *th0 = r.field(FTH0, i), *ph0 = r.field(FPH0, i);
    const float *th = r.state(TH, i), *ph = r.state(PH, i), *dth = r.state(DTH, i), *dph = r.state(DPH, i);
    const float *A = r.frame(i - 1, 3 * prim), *Y = r.frame(i, 3);
    LANES {
      const bool free = iw[l] != 0.0f;
      const float a = k[l] * (th[l] - th0[l]) + v * dth[l], b = k[l] * (ph[l] - ph0[l]) + v * dph[l];
      r.tx[o + l] = free ? a * A[l] + b * Y[l] : 0.0f;
      r.ty[o + l] = free ? a * A[W + l] + b * Y[W + l] : 0.0f;
      r.tz[o + l] = free ? a * A[2 * W + l] + b * Y[2 * W + l] : 0.0f;
    }
  }
  // The parent's absolute acceleration, the head's (or zero) until the first free segment.
  alignas(64) float pax[W], pay[W], paz[W];
  LANES {
    pax[l] = h.root_angular[0];
    pay[l] = h.root_angular[1];
    paz[l] = h.root_angular[2];
  }
  const bool compensate = f.gravity_compensation;
  // What turns a torque per unit mass into an angular acceleration (ForestInertia): 1/ℓ
  // (one row after the fields) or the segment's length.
  const float* inv_len = r.c + static_cast<std::size_t>(kForestFields) * fs;
  // The segment's angular velocity and its end's velocity relative to the head, summed
  // from the root; a pinned segment is rigid with the head.
  alignas(64) float spx[W] = {}, spy[W] = {}, spz[W] = {}, ux[W] = {}, uy[W] = {}, uz[W] = {};
  for (int i = 1; i < n; ++i) {
    if (r.kind[i] == kRowPinned) {
      for (float* q : {spx, spy, spz, ux, uy, uz}) std::fill_n(q, W, 0.0f);
      continue;
    }
    const int o = i * W;
    const float *iw = r.field(FIW, i), *gain = f.mass_inertia ? r.field(FLEN, i) : inv_len;
    const float* R2 = r.field(FR6, i);  // rest frame's z column
    const float *A = r.frame(i - 1, 3 * prim), *Y = r.frame(i, 3), *Z = r.frame(i, 6);
    const bool child = i + 1 < n;
    const float *ntx = r.tx + (child ? o + W : o), *nty = r.ty + (child ? o + W : o),
                *ntz = r.tz + (child ? o + W : o);
    float *th = r.state(TH, i), *ph = r.state(PH, i), *dth = r.state(DTH, i), *dph = r.state(DPH, i);
    const float *px = r.px + o, *py = r.py + o, *pz = r.pz + o;
    const float* len = r.field(FLEN, i);
    LANES {
      const bool free = iw[l] != 0.0f;
      const float sx = spx[l] + dth[l] * A[l] + dph[l] * Y[l];
      const float sy = spy[l] + dth[l] * A[W + l] + dph[l] * Y[W + l];
      const float sz = spz[l] + dth[l] * A[2 * W + l] + dph[l] * Y[2 * W + l];
      const float ex = len[l] * Z[l], ey = len[l] * Z[W + l], ez = len[l] * Z[2 * W + l];
      spx[l] = free ? sx : 0.0f;
      spy[l] = free ? sy : 0.0f;
      spz[l] = free ? sz : 0.0f;
      ux[l] = free ? ux[l] + (sy * ez - sz * ey) : 0.0f;
      uy[l] = free ? uy[l] + (sz * ex - sx * ez) : 0.0f;
      uz[l] = free ? uz[l] + (sx * ey - sy * ex) : 0.0f;
    }
    // External acceleration: gravity less the root's inertia, the wind's part normal to
    // the segment, damped penalty forces of the spheres the end is inside.
    alignas(64) float ax[W], ay[W], az[W];
    LANES {
      const float x = px[l], y = py[l], z = pz[l];
      ax[l] = gx - (in[0] * x + in[1] * y + in[2] * z + in[3]);
      ay[l] = gy - (in[4] * x + in[5] * y + in[6] * z + in[7]);
      az[l] = gz - (in[8] * x + in[9] * y + in[10] * z + in[11]);
    }
    if (f.windy)
      LANES {
        const float zx = Z[l], zy = Z[W + l], zz = Z[2 * W + l];
        const float d = wx * zx + wy * zy + wz * zz;
        ax[l] += wx - d * zx;
        ay[l] += wy - d * zy;
        az[l] += wz - d * zz;
      }
    for (int c = 0; c < h.sphere_count; ++c) {
      const float sx = h.spheres[4 * c], sy = h.spheres[4 * c + 1], sz = h.spheres[4 * c + 2],
                  rad = h.spheres[4 * c + 3];
      LANES {
        const float dx = px[l] - sx, dy = py[l] - sy, dz = pz[l] - sz;
        const float dist2 = dx * dx + dy * dy + dz * dz;
        const bool inside = dist2 < rad * rad;
        const float dist = std::sqrt(dist2);
        const bool off = dist > 0.0f;
        const float nx = off ? dx / dist : 0.0f, ny = off ? dy / dist : 1.0f, nz = off ? dz / dist : 0.0f;
        const float depth = rad - dist, limit = damp * depth / dt;
        const float d = damp * (ux[l] * nx + uy[l] * ny + uz[l] * nz);
        const float g = inside ? push * depth - (d < -limit ? -limit : limit < d ? limit : d) : 0.0f;
        ax[l] += g * nx;
        ay[l] += g * ny;
        az[l] += g * nz;
      }
    }
    LANES {
      const float zx = Z[l], zy = Z[W + l], zz = Z[2 * W + l];
      // Where compensating, z × g_n is subtracted: g_n the part of gravity normal to the
      // head-transformed rest segment z0 (forest_integrate).
      const float rzx = m0 * R2[l] + m1 * R2[fs + l] + m2 * R2[2 * fs + l];
      const float rzy = m3 * R2[l] + m4 * R2[fs + l] + m5 * R2[2 * fs + l];
      const float rzz = m6 * R2[l] + m7 * R2[fs + l] + m8 * R2[2 * fs + l];
      const float along = gx * rzx + gy * rzy + gz * rzz;
      const float nx = gx - along * rzx, ny = gy - along * rzy, nz = gz - along * rzz;
      const float il = gain[l];
      const float tx = zy * az[l] - zz * ay[l], ty = zz * ax[l] - zx * az[l], tz = zx * ay[l] - zy * ax[l];
      const float cx = compensate ? tx - (zy * nz - zz * ny) : tx;
      const float cy = compensate ? ty - (zz * nx - zx * nz) : ty;
      const float cz = compensate ? tz - (zx * ny - zy * nx) : tz;
      float accx = il * cx - r.tx[o + l], accy = il * cy - r.ty[o + l], accz = il * cz - r.tz[o + l];
      if (child) {
        accx += ntx[l];
        accy += nty[l];
        accz += ntz[l];
      }
      // Eq. 4.2.5: relative to the parent, projected on the joint axes; Eq. 4.2.6: Euler.
      const float relx = accx - pax[l], rely = accy - pay[l], relz = accz - paz[l];
      const float ddth = A[l] * relx + A[W + l] * rely + A[2 * W + l] * relz;
      const float ddph = Y[l] * relx + Y[W + l] * rely + Y[2 * W + l] * relz;
      const bool free = iw[l] != 0.0f;
      pax[l] = free ? accx : pax[l];
      pay[l] = free ? accy : pay[l];
      paz[l] = free ? accz : paz[l];
      th[l] = free ? th[l] + dth[l] * dt : th[l];
      ph[l] = free ? ph[l] + dph[l] * dt : ph[l];
      dth[l] = free ? (dth[l] + ddth * dt) * keep : dth[l];
      dph[l] = free ? (dph[l] + ddph * dt) * keep : dph[l];
    }
  }
}

void forest_frame(const Block& b, const ForestParams& p, const ForestFrame& f, float* out, float* scratch,
                  soa::LineFeed& feed, std::int64_t* stage_ns) {
  const int n = b.n;
  const std::size_t rows = static_cast<std::size_t>(n) * W;
  Rows r{n,          b.data,           b.state,          scratch,          scratch + 9 * rows,
         scratch + 10 * rows, scratch + 11 * rows, scratch + 12 * rows, scratch + 13 * rows, scratch + 14 * rows,
         b.rows};
  soa::StageClock clock(stage_ns);
  feed.pace(2 * f.substep_count);  // each pose and integration requests a share of the next block
  for (int k = 0; k < f.substep_count; ++k) {
    if (f.parent_x)
      pose<true>(r, f.substeps[k]);
    else
      pose<false>(r, f.substeps[k]);
    clock.lap(Stage::Pose);
    feed.step();
    integrate(r, f.substeps[k], f, p);
    clock.lap(Stage::Integrate);
    feed.step();
  }
  if (f.parent_x)
    pose<true>(r, f.substeps[f.substep_count]);
  else
    pose<false>(r, f.substeps[f.substep_count]);
  float* lane_out[W];
  for (int l = 0; l < W; ++l) lane_out[l] = b.write[l] ? out + 4 * static_cast<std::size_t>(b.offset[l]) : nullptr;
  soa::write_rows_float4(r.px, r.py, r.pz, r.field(FIW, 0), n, lane_out);  // w: the groom's, unchanged
  clock.lap(Stage::Pose);
  feed.finish();
}

}  // namespace

ForestFrameFn forest_frame_fn() { return &forest_frame; }

}  // namespace hairbench::kernels::halen_soa::HAIRBENCH_ISA_VARIANT
