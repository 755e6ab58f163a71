// The rounding bound between the metrics a device computes (kernels/vulkan/metrics.comp,
// added up by reports/device_metrics.cpp) and reports/metrics.cpp's on the same positions,
// derived from float rounding, and a lockstep run that compares the two frame by frame.
//
// The device works in float. Vulkan's precision rules make +, - and * correctly rounded
// (relative error at most u = 2^-24), division at most 2.5 ulp and sqrt that of
// 1 / inversesqrt (4.5 ulp); an ulp is at most 2u of the value, so every device operation
// errs by at most eps = 10u relatively, and a chain of k of them by at most
// gamma(k) = k eps / (1 - k eps); a fused multiply-add, which Vulkan allows, rounds less.
// Vulkan may flush subnormals to zero: no quantity here comes near 1e-38 (positions
// differ by a float step of about 1e-8 m or more, or not at all). The host works in
// double (rounding 2^-53) from the same float positions. Per metric, with the host's
// exact-in-double values (d, l, kb, ...):
//
// - A per-vertex or per-edge term t computed with absolute error a (below), added up
//   over a strand's n terms in float, errs by at most sum(a) + gamma(n) sum(|t| + a); the
//   strands and the host's own sum add in double, at most 2 N 2^-53 sum(|t| + a).
// - deviation: t = |p - q|^2, a = gamma(5) t (3 differences, 3 squares, 2 additions).
// - rest_shape_error: the device forms H p0 in float as the host does; either is within
//   eta_k = gamma(5) (|t_k| + sum_j |m_kj p0_j|) of the exact product, so the difference
//   d_k = p_k - H p0_k errs by e_k = eps |d_k| + 2 eta_k (1 + eps), and
//   a = sum_k (2 |d_k| e_k + e_k^2)(1 + gamma(2)) + gamma(3) t.
// - mechanical energy: t = |v|^2 / 2 - g.p, a = gamma(9) (|v|^2 / 2 + sum_k |g_k p_k|)
//   (v: a difference, a division by dt rounded to float, 3 squares and 2 additions).
// - relative kinetic energy: both sides form d = p - carry prev in float (e_k = 2 eps
//   |d_k| + 2 eta_k (1 + eps), eta_k as above for carry prev) and square it in float:
//   a = sum_k (2 |d_k| e_k + e_k^2)(1 + gamma(3)) + 2 gamma(3) t.
// - length_error: per edge e = | l - r | / s, a = (gamma(5) l + eps |l - r|)(1 + gamma(3)) / s
//   + gamma(3) e; max: the largest a; rms: t = e^2 with 2 e a + a^2 + gamma(2) (e + a)^2.
// - penetration: per vertex and sphere r - |p - c|, a = gamma(7) |p - c| + eps (r + |p - c|);
//   the maximum: the largest a.
// - jaggedness: kb = 2 c / D (c = e0 x e1, D = l0 l1 + e0.e1) with |c| erring by
//   dc = gamma(4) |(|e0y e1z| + |e0z e1y|, ...)| and D by dD = gamma(12) (l0 l1 + sum_k
//   |e0k e1k|): |kb| errs by 2 (dc + |c| dD / D) (1 + eps) / (D - dD) + eps |kb| (only where
//   D > 2 dD, which the check asserts). d = |kb_i - kb_{i-1}| adds the two and
//   gamma(5) of the result; d0 goes up rounded to float (u d0); diff = (d - d0) w one
//   more eps; J_s^2 sums diff^2 as above, J_s is its root, divided (eps) and rooted (eps).
// - A root: |sqrt(x) - sqrt(y)| <= min(|x - y| / sqrt(y), sqrt(|x - y|)).
#pragma once

#include "core/device_metrics.h"
#include "reports/device_metrics.h"
#include "reports/metrics.h"
#include "reports/verdict.h"
#include "vulkan_support.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

namespace hairbench::test {

inline constexpr double kU = 0x1p-24;
inline constexpr double kEps = 10.0 * kU;
inline constexpr double kDoubleU = 0x1p-53;
inline double gamma(double k) { return k * kEps / (1.0 - k * kEps); }
inline double root_bound(double y, double dxy) {
  return y > 0.0 ? std::min(dxy / std::sqrt(y), std::sqrt(dxy)) : std::sqrt(dxy);
}

// Terms added up per strand in float on the device, then over strands in double.
struct SumBound {
  double sum = 0.0, err = 0.0, mag = 0.0;
  double strand_mag = 0.0, strand_err = 0.0;
  std::size_t terms = 0, count = 0;
  void term(double t, double a) {
    sum += t;
    strand_mag += std::abs(t) + a;
    strand_err += a;
    ++terms;
    ++count;
  }
  void end_strand() {
    err += strand_err + gamma(static_cast<double>(terms)) * strand_mag;
    mag += strand_mag;
    strand_mag = strand_err = 0.0;
    terms = 0;
  }
  // The bound on |device sum - host sum|.
  double bound() const { return err + 2.0 * static_cast<double>(count + 1) * kDoubleU * mag; }
};

// The named metrics' values on both sides and their bound, for one frame.
struct MetricPair {
  double device = 0.0, host = 0.0, bound = 0.0;
};
using FrameMetrics = std::map<std::string, MetricPair>;

// Error of one coordinate of an affine product M x + t in float (5 operations), from exact.
inline double affine_eta(const Affine3f& a, const Vec4f& x, int k) {
  double mag = std::abs(double(a.translation()[k]));
  for (int j = 0; j < 3; ++j) mag += std::abs(double(a.linear()(k, j)) * double(x[j]));
  return gamma(5) * mag;
}

struct KbBound {
  Eigen::Vector3d kb = Eigen::Vector3d::Zero();
  double err = 0.0;
  bool resolved = true;  // D > 2 dD: the bound holds
};

inline KbBound kb_bound(const Eigen::Vector3d& e0, const Eigen::Vector3d& e1) {
  KbBound out;
  const double l0 = e0.norm(), l1 = e1.norm(), lens = l0 * l1;
  if (!(lens > 0.0)) return out;
  const Eigen::Vector3d c = e0.cross(e1);
  const Eigen::Vector3d cmag(std::abs(e0.y() * e1.z()) + std::abs(e0.z() * e1.y()),
                             std::abs(e0.z() * e1.x()) + std::abs(e0.x() * e1.z()),
                             std::abs(e0.x() * e1.y()) + std::abs(e0.y() * e1.x()));
  const double dc = gamma(4) * cmag.norm();
  const double d = std::max(lens + e0.dot(e1), 1e-12 * lens);
  const double dD = gamma(12) * (lens + e0.cwiseProduct(e1).cwiseAbs().sum());
  out.kb = 2.0 * c / d;
  out.resolved = d > 2.0 * dD;
  out.err = 2.0 * (dc + c.norm() * dD / d) * (1.0 + kEps) / (d - dD) + kEps * out.kb.norm();
  return out;
}

// J_s's bound for one strand of positions p (whole groom), beside the host's J_s.
inline double jaggedness_bound(const metrics::RestInfo& rest, std::span<const Vec4f> p, std::size_t s,
                               bool& resolved) {
  const Groom& g = *rest.groom;
  const std::size_t b = g.strand_begin(s), n = g.strand_size(s);
  if (n < 4) return 0.0;
  auto x = [&](std::size_t i) { return Eigen::Vector3d(p[b + i].head<3>().cast<double>()); };
  SumBound sq;
  KbBound prev = kb_bound(x(1) - x(0), x(2) - x(1));
  for (std::size_t i = 2; i + 1 < n; ++i) {
    const KbBound kb = kb_bound(x(i) - x(i - 1), x(i + 1) - x(i));
    const double w = rest.kb_weight[b + i];
    if (w != 0.0) {
      resolved = resolved && kb.resolved && prev.resolved;
      const double d = (kb.kb - prev.kb).norm(), d0 = rest.rest_kb_change[b + i];
      const double ad = kb.err + prev.err + gamma(5) * (d + kb.err + prev.err);
      const double diff = (d - d0) * w;
      const double adiff = w * (ad + kU * d0 + kEps * (std::abs(d - d0) + ad + kU * d0));
      sq.term(diff * diff, 2.0 * std::abs(diff) * adiff + adiff * adiff + gamma(2) * std::pow(std::abs(diff) + adiff, 2));
    } else {
      sq.term(0.0, 0.0);
    }
    prev = kb;
  }
  sq.end_strand();
  const double mean = sq.sum / static_cast<double>(n - 3), dmean = sq.bound() / static_cast<double>(n - 3);
  const double j = std::sqrt(mean);
  return root_bound(mean, dmean + kEps * (mean + dmean)) + kEps * j;
}

// The device's metrics of one frame against the host's on the positions read back,
// with their bounds. `prev`: the previous frame's positions (the host's `prev`).
inline FrameMetrics compare_frame(const metrics::RestInfo& rest, const metrics::RestInfo* guides,
                                  std::span<const StrandMetrics> m, std::span<const Vec4f> p,
                                  std::span<const Vec4f> prev, std::span<const Vec4f> ref, const FrameInput& in,
                                  std::span<const Vec4f> spheres, bool& resolved) {
  const Groom& g = *rest.groom;
  const std::size_t nv = g.vertex_count(), guide_strands = guides ? guides->groom->strand_count() : g.strand_count();
  const double lbar = rest.mean_strand_length;
  FrameMetrics out;
  SumBound dev, shape, energy, kinetic, len_all, len_guides;
  double jag_bound = 0.0, len_max_all = 0.0, len_max_guides = 0.0, pen_guides = 0.0, pen_follow = 0.0;
  const Affine3f carry = in.head * in.head_prev.inverse();
  const Eigen::Matrix3f m3 = in.head.linear();
  const Vec3f t3 = in.head.translation();
  for (std::size_t s = 0; s < g.strand_count(); ++s) {
    const bool guide = s < guide_strands;
    for (std::size_t i = g.strand_begin(s); i < g.strand_begin(s) + g.strand_size(s); ++i) {
      const Eigen::Vector3d x = p[i].head<3>().cast<double>();
      const double tdev = (x - ref[i].head<3>().cast<double>()).squaredNorm();
      dev.term(tdev, gamma(5) * tdev);

      const Vec4f& r = g.positions[i];
      const float a = r.x(), b = r.y(), c = r.z();
      const Eigen::Vector3d h(t3.x() + ((m3(0, 0) * a + m3(0, 1) * b) + m3(0, 2) * c),
                              t3.y() + ((m3(1, 0) * a + m3(1, 1) * b) + m3(1, 2) * c),
                              t3.z() + ((m3(2, 0) * a + m3(2, 1) * b) + m3(2, 2) * c));
      double ashape = 0.0;
      for (int k = 0; k < 3; ++k) {
        const double d = x[k] - h[k], e = kEps * std::abs(d) + 2.0 * affine_eta(in.head, r, k) * (1.0 + kEps);
        ashape += (2.0 * std::abs(d) * e + e * e) * (1.0 + gamma(2));
      }
      const double tshape = (x - h).squaredNorm();
      shape.term(tshape, ashape + gamma(3) * tshape);

      const Eigen::Vector3d pv = prev[i].head<3>().cast<double>(), grav = in.gravity.cast<double>();
      const Eigen::Vector3d v = (x - pv) / in.dt;
      energy.term(0.5 * v.squaredNorm() - grav.dot(x),
                  gamma(9) * (0.5 * v.squaredNorm() + grav.cwiseProduct(x).cwiseAbs().sum()));

      const Vec3f dk = p[i].head<3>() - carry * Vec3f(prev[i].head<3>());
      double akin = 0.0;
      for (int k = 0; k < 3; ++k) {
        const double e = 2.0 * kEps * std::abs(double(dk[k])) + 2.0 * affine_eta(carry, prev[i], k) * (1.0 + kEps);
        akin += (2.0 * std::abs(double(dk[k])) * e + e * e) * (1.0 + gamma(3));
      }
      const double tkin = static_cast<double>(dk.squaredNorm());
      kinetic.term(tkin, akin + 2.0 * gamma(3) * tkin);

      for (const Vec4f& sph : spheres) {
        const double dist = (x - sph.head<3>().cast<double>()).norm();
        const double apen = gamma(7) * dist + kEps * (double(sph.w()) + dist);
        (guide ? pen_guides : pen_follow) = std::max(guide ? pen_guides : pen_follow, apen);
      }

      if (i > g.strand_begin(s)) {
        const double l = (x - p[i - 1].head<3>().cast<double>()).norm(), rl = rest.rest_length[i];
        const double scale = rest.vertex_edge_scale[i], e = std::abs(l - rl) / scale;
        const double ae = (gamma(5) * l + kEps * std::abs(l - rl)) * (1.0 + gamma(3)) / scale + gamma(3) * e;
        const double a2 = 2.0 * e * ae + ae * ae + gamma(2) * std::pow(e + ae, 2);
        len_all.term(e * e, a2);
        len_max_all = std::max(len_max_all, ae);
        if (guide) {
          len_guides.term(e * e, a2);
          len_max_guides = std::max(len_max_guides, ae);
        }
      }
    }
    for (SumBound* b : {&dev, &shape, &energy, &kinetic, &len_all, &len_guides}) b->end_strand();
    jag_bound += jaggedness_bound(rest, p, s, resolved);
  }
  const double n = static_cast<double>(nv);
  auto root_metric = [&](const SumBound& b, double count, double scale) {
    return root_bound(b.sum / count, b.bound() / count) / scale + 4.0 * kDoubleU * std::sqrt(b.sum / count) / scale;
  };
  out["deviation_vs_reference"] = {metrics::deviation(rest, m), metrics::deviation(p, ref, lbar), root_metric(dev, n, lbar)};
  out["rest_shape_error"] = {metrics::rest_shape_error(rest, m), metrics::rest_shape_error(rest, p, in.head),
                             root_metric(shape, n, lbar)};
  out["mechanical_energy"] = {metrics::mechanical_energy(rest, m), metrics::mechanical_energy(p, prev, in.dt, in.gravity),
                              energy.bound() / n};
  out["kinetic_energy"] = {metrics::relative_kinetic_energy(rest, m, in.dt),
                           verdict::relative_kinetic_energy(p, prev, in.head, in.head_prev, in.dt),
                           kinetic.bound() / (2.0 * in.dt * in.dt * n)};
  const double strands = static_cast<double>(g.strand_count()), jag = metrics::jaggedness(rest, p);
  out["jaggedness"] = {metrics::jaggedness(rest, m), jag, jag_bound / strands + 2.0 * strands * kDoubleU * jag};
  const metrics::LengthError ld = metrics::length_error(rest, m), lh = metrics::length_error(rest, p);
  out["length_error_rms"] = {ld.rms, lh.rms, root_metric(len_all, static_cast<double>(rest.edge_count), 1.0)};
  out["length_error_max"] = {ld.max, lh.max, len_max_all};
  // The device's worst edge is a largest one within rounding: its host error is within
  // twice the bound of the host's largest.
  {
    const std::size_t i = g.strand_begin(ld.worst_strand) + ld.worst_edge;
    const double at = ld.max > 0.0 ? std::abs((p[i] - p[i - 1]).head<3>().cast<double>().norm() - rest.rest_length[i]) /
                                         rest.vertex_edge_scale[i]
                                   : 0.0;
    out["length_worst_edge"] = {at, lh.max, 2.0 * len_max_all};
  }
  if (guides) {
    const metrics::LengthError gd = metrics::length_error(*guides, m.first(guide_strands));
    const metrics::LengthError gh = metrics::length_error(*guides, p.first(guides->groom->vertex_count()));
    out["guide_length_rms"] = {gd.rms, gh.rms, root_metric(len_guides, static_cast<double>(guides->edge_count), 1.0)};
    out["guide_length_max"] = {gd.max, gh.max, len_max_guides};
    const std::size_t gv = guides->groom->vertex_count();
    out["penetration_guides"] = {metrics::penetration(m.first(guide_strands)),
                                 metrics::penetration(p.first(gv), spheres), pen_guides};
    out["penetration_follow"] = {metrics::penetration(m.subspan(guide_strands)),
                                 metrics::penetration(p.subspan(gv), spheres), pen_follow};
    // The groom's: the larger of the two layers'.
    const MetricPair &pg = out["penetration_guides"], &pf = out["penetration_follow"];
    out["penetration"] = {std::max(pg.device, pf.device), std::max(pg.host, pf.host), std::max(pg.bound, pf.bound)};
  } else {
    out["penetration"] = {metrics::penetration(m), metrics::penetration(p, spheres), pen_guides};
  }
  return out;
}

// The largest |device - host| / bound per metric over a run, and the largest host value.
struct MetricsAgreement {
  std::map<std::string, double> worst_ratio, largest;
  bool resolved = true;
  std::vector<FrameMetrics> frames;
  void add(const FrameMetrics& f) {
    for (const auto& [name, v] : f) {
      const double diff = std::abs(v.device - v.host);
      double& w = worst_ratio[name];
      w = std::max(w, v.bound > 0.0 ? diff / v.bound : (diff > 0.0 ? std::numeric_limits<double>::infinity() : 0.0));
      largest[name] = std::max(largest[name], v.host);
    }
    frames.push_back(f);
  }
  void print(const std::string& what) const {
    std::printf("%s: largest |device - host| / bound:", what.c_str());
    for (const auto& [name, w] : worst_ratio) std::printf(" %s %.3g (host max %.3g);", name.c_str(), w, largest.at(name));
    std::printf("\n");
  }
};

// Steps the Vulkan model `model` (registry name) through `frames` frames of sc beside the
// CPU model `reference`, and after each frame compares its device metrics with the
// host's on its positions read back. `extra_spheres` join the scenario's colliders in the
// metrics only (a sphere through the hair makes penetration > 0); `overrides` apply to
// both models, as RunOptions::overrides.
inline MetricsAgreement device_vs_host_metrics(const Scenario& sc, const std::string& model, const std::string& reference,
                                               int frames, const std::vector<Vec4f>& extra_spheres = {},
                                               const std::vector<ParamOverride>& overrides = {}) {
  ThreadPool pool(2);
  const ModelInfo* mi = find_model(model);
  const ModelInfo* ri = find_model(reference);
  const std::unique_ptr<HairModel> vkm = make_model(*mi, sc, resolve_params(*mi, sc, overrides), pool);
  const std::unique_ptr<HairModel> ref = make_model(*ri, sc, resolve_params(*ri, sc, overrides), pool);
  const metrics::RestInfo rest(sc.groom, sc.follow ? sc.guides.strand_count() : sc.groom.strand_count());
  std::optional<metrics::RestInfo> guides;
  if (sc.follow) guides.emplace(sc.guides);
  std::vector<Vec4f> prev = sc.groom.positions;
  const Affine3f h0 = sc.head.at(0.0);
  for (Vec4f& v : prev) v.head<3>() = h0 * Vec3f(v.head<3>());
  DeviceMetrics* dm = vkm->device_metrics();
  if (!dm) throw std::runtime_error(model + " has no device metrics");
  dm->prepare(metrics::device_rest(rest, prev));
  MetricsAgreement out;
  StageTimes times;
  for (int f = 0; f < frames; ++f) {
    const FrameInput in = frame_input(sc, f);
    vkm->step(in, times);
    ref->step(in, times);
    std::vector<Vec4f> spheres;
    for (const Sphere& c : sc.colliders) {
      const Vec3f centre = collider_center(c, in.head);
      spheres.emplace_back(centre.x(), centre.y(), centre.z(), c.radius);
    }
    spheres.insert(spheres.end(), extra_spheres.begin(), extra_spheres.end());
    const std::span<const Vec4f> q = ref->positions();
    const std::span<const StrandMetrics> m = dm->measure(
        {in.head, in.head * in.head_prev.inverse(), sc.gravity, static_cast<float>(sc.dt), spheres, q});
    const std::span<const Vec4f> p = vkm->positions();
    EXPECT_EQ(metrics::blowup_reason(m), metrics::blowup_reason(rest, p, in.head.translation())) << "frame " << f;
    out.add(compare_frame(rest, guides ? &*guides : nullptr, m, p, prev, q, in, spheres, out.resolved));
    prev.assign(p.begin(), p.end());
  }
  return out;
}

}  // namespace hairbench::test
