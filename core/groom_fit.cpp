#include "core/groom_fit.h"

#include "core/error.h"

#include <Eigen/Dense>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <iomanip>
#include <limits>
#include <optional>
#include <sstream>
#include <tuple>
#include <unordered_map>
#include <utility>

namespace hairbench {
namespace {

using Vec3d = Eigen::Vector3d;

Vec3d root_of(const Groom& g, std::size_t s) { return g.positions[g.strand_begin(s)].head<3>().cast<double>(); }

std::string text(double v, int digits = 3) {
  std::ostringstream os;
  os << std::setprecision(digits) << v;
  return os.str();
}

struct Sphere3 {
  Vec3d c = Vec3d::Zero();
  double r = 0.0;
  bool ok = false;
};

// The algebraic least-squares sphere through `pts` (relative to `origin`).
Sphere3 lsq_sphere(const std::vector<Vec3d>& pts, const std::vector<char>& use, const Vec3d& origin) {
  Eigen::Matrix4d a = Eigen::Matrix4d::Zero();
  Eigen::Vector4d b = Eigen::Vector4d::Zero();
  std::size_t n = 0;
  for (std::size_t i = 0; i < pts.size(); ++i) {
    if (!use[i]) continue;
    const Vec3d q = pts[i] - origin;
    const Eigen::Vector4d row(2.0 * q.x(), 2.0 * q.y(), 2.0 * q.z(), 1.0);
    a += row * row.transpose();
    b += row * q.squaredNorm();
    ++n;
  }
  Sphere3 s;
  if (n < 4) return s;
  const Eigen::ColPivHouseholderQR<Eigen::Matrix4d> qr(a);
  // Roots on a plane or a line leave the centre free along a direction: no sphere.
  if (qr.rank() < 4) return s;
  const Eigen::Vector4d x = qr.solve(b);
  const double r2 = x[3] + x.head<3>().squaredNorm();
  if (!(r2 > 0.0) || !x.allFinite()) return s;
  s.c = origin + x.head<3>();
  s.r = std::sqrt(r2);
  s.ok = true;
  return s;
}

double median(std::vector<double> v);

// The centre of the sphere of radius r nearest the used points in least squares (Gauss-
// Newton from c on sum (|p - c| - r)^2), for a consensus whose radius is held at a bound.
Vec3d centre_at_radius(const std::vector<Vec3d>& pts, const std::vector<char>& use, Vec3d c, double r) {
  for (int it = 0; it < 8; ++it) {
    Eigen::Matrix3d a = Eigen::Matrix3d::Zero();
    Vec3d b = Vec3d::Zero();
    for (std::size_t i = 0; i < pts.size(); ++i) {
      if (!use[i]) continue;
      const Vec3d v = pts[i] - c;
      const double d = v.norm();
      if (!(d > 0.0)) continue;
      const Vec3d u = v / d;
      a += u * u.transpose();
      b += u * (d - r);
    }
    const Vec3d step = a.ldlt().solve(b);
    if (!step.allFinite()) break;
    c += step;
    if (step.norm() <= 1e-9 * r) break;
  }
  return c;
}

// The RMS of |p - c| - r over the used points, and the length of their mean unit
// direction from c (HeadFit::cap).
std::pair<double, double> residual_and_cap(const std::vector<Vec3d>& pts, const std::vector<char>& use, const Vec3d& c,
                                           double r) {
  double sum = 0.0;
  Vec3d dir = Vec3d::Zero();
  std::size_t n = 0;
  for (std::size_t i = 0; i < pts.size(); ++i) {
    if (!use[i]) continue;
    const double d = (pts[i] - c).norm();
    sum += (d - r) * (d - r);
    if (d > 0.0) dir += (pts[i] - c) / d;
    ++n;
  }
  if (n == 0) return {0.0, 0.0};
  return {std::sqrt(sum / static_cast<double>(n)), (dir / static_cast<double>(n)).norm()};
}

// A consensus sphere with its radius held in [lo, hi] (fit_head, steps 1 and 2).
struct Consensus {
  Sphere3 s;
  std::vector<char> in;  // the roots within kFitBand r of it
  std::size_t count = 0;
  bool at_bound = false;  // its radius is held at lo or hi: the roots want another size
};

std::vector<char> within_band(const std::vector<Vec3d>& pts, const Vec3d& c, double r, std::size_t& count) {
  std::vector<char> in(pts.size(), 0);
  count = 0;
  for (std::size_t i = 0; i < pts.size(); ++i)
    if (std::abs((pts[i] - c).norm() - r) < kFitBand * r) {
      in[i] = 1;
      ++count;
    }
  return in;
}

Consensus consensus(const std::vector<Vec3d>& pts, const std::vector<std::size_t>& seeds, double lo, double hi) {
  Consensus best;
  const Vec3d origin = [&] {
    Vec3d m = Vec3d::Zero();
    for (const Vec3d& p : pts) m += p;
    return Vec3d(m / static_cast<double>(pts.size()));
  }();
  for (std::size_t seed : seeds) {
    std::vector<char> patch(pts.size(), 0);
    for (std::size_t i = 0; i < pts.size(); ++i) patch[i] = (pts[i] - pts[seed]).norm() < hi;
    Sphere3 s = lsq_sphere(pts, patch, origin);
    if (!s.ok) continue;
    Consensus c;
    c.s = s;
    c.s.r = std::clamp(s.r, lo, hi);
    if (c.s.r != s.r) c.s.c = centre_at_radius(pts, patch, s.c, c.s.r);
    for (int it = 0; it < 20; ++it) {
      std::size_t count = 0;
      std::vector<char> in = within_band(pts, c.s.c, c.s.r, count);
      if (in == c.in) break;
      c.in = std::move(in);
      c.count = count;
      if (count < 4) break;
      const Sphere3 next = lsq_sphere(pts, c.in, origin);
      if (!next.ok) break;
      c.at_bound = next.r > hi || next.r < lo;
      c.s = next;
      c.s.r = std::clamp(next.r, lo, hi);
      if (c.s.r != next.r) c.s.c = centre_at_radius(pts, c.in, c.s.c, c.s.r);
    }
    if (c.count >= 4 && c.count > best.count) best = std::move(c);
  }
  return best;
}

// The consensus sphere refitted on its core: the roots within 3 robust standard
// deviations (1.4826 times the median absolute residual) of it, until they no longer
// change, its radius held in [lo, hi]. The band of a consensus widens with its radius, so
// roots at its edge (where a neck leaves the scalp) pull the sphere towards them and are
// joined by more; the core's width comes from the residuals of the roots themselves.
void polish(const std::vector<Vec3d>& pts, Consensus& c, double lo, double hi) {
  const Vec3d origin = c.s.c;
  std::vector<char> core;
  std::vector<double> d;
  for (int it = 0; it < 20; ++it) {
    d.clear();
    for (std::size_t i = 0; i < pts.size(); ++i)
      if (c.in[i]) d.push_back(std::abs((pts[i] - c.s.c).norm() - c.s.r));
    const double sigma = 1.4826 * median(d);
    std::vector<char> next(pts.size(), 0);
    std::size_t n = 0;
    for (std::size_t i = 0; i < pts.size(); ++i)
      if (c.in[i] && std::abs((pts[i] - c.s.c).norm() - c.s.r) <= 3.0 * sigma) {
        next[i] = 1;
        ++n;
      }
    if (next == core || n < 4) break;
    core = std::move(next);
    const Sphere3 s = lsq_sphere(pts, core, origin);
    if (!s.ok) break;
    c.at_bound = s.r > hi || s.r < lo;
    c.s = s;
    c.s.r = std::clamp(s.r, lo, hi);
    if (c.s.r != s.r) c.s.c = centre_at_radius(pts, core, c.s.c, c.s.r);
    c.in = within_band(pts, c.s.c, c.s.r, c.count);
  }
}

// The consensus's seed roots.
constexpr std::size_t kFitSeeds = 32;

// `k` roots spread over the groom: root 0, then each the farthest from those taken.
std::vector<std::size_t> spread_seeds(const std::vector<Vec3d>& pts, std::size_t k) {
  std::vector<std::size_t> seeds;
  if (pts.empty()) return seeds;
  std::vector<double> d(pts.size(), std::numeric_limits<double>::infinity());
  std::size_t next = 0;
  for (std::size_t taken = 0; taken < std::min(k, pts.size()); ++taken) {
    seeds.push_back(next);
    std::size_t far = next;
    for (std::size_t i = 0; i < pts.size(); ++i) {
      d[i] = std::min(d[i], (pts[i] - pts[next]).norm());
      if (d[i] > d[far]) far = i;
    }
    next = far;
  }
  return seeds;
}

double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  const auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  return *mid;
}

// Strand s's edge lengths in double: e[i] is edge (i, i+1).
void edge_lengths(const Groom& g, std::size_t s, std::vector<double>& e) {
  const std::uint32_t b = g.strand_begin(s), n = g.strand_size(s);
  e.resize(n - 1);
  for (std::uint32_t i = 1; i < n; ++i)
    e[i - 1] = (g.positions[b + i] - g.positions[b + i - 1]).head<3>().cast<double>().norm();
}

// The strand resampled to its vertex count at equal arc-length steps along its polyline.
void resample(Groom& g, std::size_t s, const std::vector<double>& e) {
  const std::uint32_t b = g.strand_begin(s), n = g.strand_size(s);
  std::vector<Vec3d> old(n);
  for (std::uint32_t i = 0; i < n; ++i) old[i] = g.positions[b + i].head<3>().cast<double>();
  double total = 0.0;
  for (double l : e) total += l;
  std::uint32_t seg = 0;  // the segment (seg, seg + 1) the target lies on
  double seg_start = 0.0;  // arc length at old[seg]
  for (std::uint32_t k = 1; k + 1 < n; ++k) {
    const double target = total * k / (n - 1);
    while (seg + 1 < n - 1 && seg_start + e[seg] < target) seg_start += e[seg++];
    const double f = e[seg] > 0.0 ? std::clamp((target - seg_start) / e[seg], 0.0, 1.0) : 0.0;
    const Vec3d p = old[seg] + f * (old[seg + 1] - old[seg]);
    g.positions[b + k].head<3>() = p.cast<float>();
  }
  // The ends stay where they were.
}

std::string edge_example(std::size_t s, std::size_t edge, double length) {
  return "strand " + std::to_string(s) + " edge " + std::to_string(edge) + " (" + text(length) + " m)";
}

}  // namespace

HeadFit fit_head(const Groom& g, std::optional<double> above, std::vector<float> metres_per_unit) {
  HeadFit fit;
  const std::size_t n = g.strand_count();
  fit.roots = n;
  std::vector<Vec3d> roots(n);
  for (std::size_t s = 0; s < n; ++s) roots[s] = root_of(g, s);

  if (!above && n >= 4) {
    if (metres_per_unit.empty()) metres_per_unit = unit_cues(g);
    const std::vector<std::size_t> seeds = spread_seeds(roots, kFitSeeds);
    const auto scalp = [&](const Consensus& c) {
      if (c.count < 4 || static_cast<double>(c.count) < kScalpShare * static_cast<double>(n)) return false;
      const auto [rms, cap] = residual_and_cap(roots, c.in, c.s.c, c.s.r);
      return rms <= kScalpResidual * c.s.r && cap >= kScalpCap;
    };
    std::optional<Consensus> head;
    for (const float mpu : metres_per_unit) {
      Consensus c = consensus(roots, seeds, kHeadRadiusMin / mpu, kHeadRadiusMax / mpu);
      if (!c.at_bound && c.count >= 4) polish(roots, c, kHeadRadiusMin / mpu, kHeadRadiusMax / mpu);
      if (c.at_bound || !scalp(c)) {
        c = consensus(roots, seeds, kHeadPriorMin / mpu, kHeadPriorMax / mpu);
        if (c.count >= 4) polish(roots, c, kHeadPriorMin / mpu, kHeadPriorMax / mpu);
      }
      if (scalp(c) && (!head || c.count > head->count)) head = std::move(c);
    }
    if (head) {
      fit.sphere = fit.scalp = true;
      fit.method = "consensus";
      fit.center = head->s.c.cast<float>();
      fit.radius = static_cast<float>(head->s.r);
      std::tie(fit.rms_residual, fit.cap) = residual_and_cap(roots, head->in, head->s.c, head->s.r);
      for (std::size_t s = 0; s < n; ++s)
        if (!head->in[s]) fit.rejected.push_back(static_cast<std::uint32_t>(s));
      return fit;
    }
  }

  // No scalp, or the roots above a height: the least-squares sphere of those roots.
  fit.method = above ? "above" : "all roots";
  std::vector<char> use(n, 0);
  Vec3d lo = Vec3d::Constant(std::numeric_limits<double>::max()), hi = -lo, mean = Vec3d::Zero();
  std::size_t used = 0;
  for (std::size_t s = 0; s < n; ++s) {
    if (above && !(roots[s].y() > *above)) {
      fit.rejected.push_back(static_cast<std::uint32_t>(s));
      continue;
    }
    use[s] = 1;
    ++used;
    lo = lo.cwiseMin(roots[s]);
    hi = hi.cwiseMax(roots[s]);
    mean += roots[s];
  }
  if (used == 0) {
    fit.note = "no root lies above the fit height";
    fit.radius = static_cast<float>(std::max(mean_strand_length(g) / 2.0, 1e-6));
    return fit;
  }
  mean /= static_cast<double>(used);
  double spread = 0.0;
  for (std::size_t s = 0; s < n; ++s)
    if (use[s]) spread += (roots[s] - mean).squaredNorm();
  spread = std::sqrt(spread / static_cast<double>(used));

  const Sphere3 s = lsq_sphere(roots, use, mean);
  if (s.ok) {
    std::tie(fit.rms_residual, fit.cap) = residual_and_cap(roots, use, s.c, s.r);
    if (fit.rms_residual > kSphereResidual * s.r)
      fit.note = "the roots are " + text(fit.rms_residual / s.r) + " of its radius off the best sphere";
    else if (s.r > kSphereSpread * spread)
      fit.note = "the roots are nearly flat (the best sphere is " + text(s.r / spread) + " times their spread)";
    else fit.sphere = true;
    if (fit.sphere) {
      if (fit.rms_residual > kScalpResidual * s.r)
        fit.note = "not a scalp, so not used for the unit: the roots are " + text(fit.rms_residual / s.r) +
                   " of its radius off it (a scalp, above " + text(kScalpResidual) + ")";
      else if (fit.cap < kScalpCap)
        fit.note = "not a scalp, so not used for the unit: the roots lie all round it (mean direction " +
                   text(fit.cap, 2) + ", a scalp's cap " + text(kScalpCap) + " or more)";
      else fit.scalp = true;
    }
  } else {
    fit.note = used < 4 ? "fewer than 4 roots" : "the roots lie on a plane or a line";
  }
  if (fit.sphere) {
    fit.center = s.c.cast<float>();
    fit.radius = static_cast<float>(s.r);
    return fit;
  }
  // No head: the middle of the roots, and a sphere that fits inside their box.
  const Vec3d extent = hi - lo;
  fit.center = ((lo + hi) / 2.0).cast<float>();
  double radius = std::max(extent.minCoeff() / 2.0, extent.norm() / 8.0);
  if (!(radius > 0.0)) radius = mean_strand_length(g) / 2.0;
  fit.radius = static_cast<float>(radius);
  fit.note += "; pivot at the roots' bounding-box centre, radius " + text(radius);
  return fit;
}

float metres_per_unit(const std::string& unit) { return unit == "cm" ? 0.01f : unit == "mm" ? 0.001f : 1.0f; }

namespace {

// The median distance from a root to its nearest other root (coincident roots left
// out), over a uniform grid of cells about the roots' mean spacing on a surface; a root
// with no neighbour in the 27 cells about it counts as one cell away (a lower bound).
double median_root_spacing(const std::vector<Vec3d>& roots, double span) {
  const std::size_t n = roots.size();
  if (n < 2 || !(span > 0.0)) return 0.0;
  const double cell = span / std::sqrt(static_cast<double>(n));
  Vec3d lo = roots[0];
  for (const Vec3d& r : roots) lo = lo.cwiseMin(r);
  const auto key = [&](long x, long y, long z) {
    return (static_cast<std::uint64_t>(x) * 73856093ull) ^ (static_cast<std::uint64_t>(y) * 19349663ull) ^
           (static_cast<std::uint64_t>(z) * 83492791ull);
  };
  const auto coords = [&](const Vec3d& r) {
    const Vec3d c = ((r - lo) / cell).array().floor();
    return std::array<long, 3>{static_cast<long>(c.x()), static_cast<long>(c.y()), static_cast<long>(c.z())};
  };
  std::unordered_map<std::uint64_t, std::vector<std::uint32_t>> grid;
  grid.reserve(n);
  for (std::size_t i = 0; i < n; ++i) {
    const auto c = coords(roots[i]);
    grid[key(c[0], c[1], c[2])].push_back(static_cast<std::uint32_t>(i));
  }
  std::vector<double> nearest;
  nearest.reserve(n);
  for (std::size_t i = 0; i < n; ++i) {
    const auto c = coords(roots[i]);
    double best = std::numeric_limits<double>::infinity();
    for (long dx = -1; dx <= 1; ++dx)
      for (long dy = -1; dy <= 1; ++dy)
        for (long dz = -1; dz <= 1; ++dz) {
          const auto it = grid.find(key(c[0] + dx, c[1] + dy, c[2] + dz));
          if (it == grid.end()) continue;
          for (std::uint32_t j : it->second) {
            const double d = (roots[j] - roots[i]).norm();
            if (j != i && d > 0.0) best = std::min(best, d);
          }
        }
    nearest.push_back(std::min(best, cell));
  }
  return median(std::move(nearest));
}

// One cue of the unit: a size in file units and the range in metres that real hair on
// a real head gives it.
struct Cue {
  std::string what;
  double size;
  double lo, hi;
  std::vector<std::string> admits;
};

// The cues of a groom's size other than its head's, each with no unit admitted yet.
std::vector<Cue> size_cues(const Groom& g) {
  std::vector<Vec3d> roots(g.strand_count());
  Vec3d a = Vec3d::Constant(std::numeric_limits<double>::max()), b = -a;
  std::vector<double> lengths(g.strand_count()), e;
  for (std::size_t s = 0; s < g.strand_count(); ++s) {
    roots[s] = root_of(g, s);
    a = a.cwiseMin(roots[s]);
    b = b.cwiseMax(roots[s]);
    edge_lengths(g, s, e);
    for (double l : e) lengths[s] += l;
  }
  const double span = g.strand_count() ? (b - a).norm() : 0.0;
  return {{"median strand", median(lengths), kStrandLengthMin, kStrandLengthMax, {}},
          {"roots' span", span, kRootSpanMin, kRootSpanMax, {}},
          {"root spacing", median_root_spacing(roots, span), kRootSpacingMin, kRootSpacingMax, {}}};
}

// The units every cue admits, each cue's `admits` filled in.
std::vector<std::string> admitted_units(std::vector<Cue>& cues) {
  std::vector<std::string> fits;
  for (const char* unit : {"m", "cm", "mm"}) {
    bool all = true;
    for (Cue& c : cues) {
      const double m = c.size * metres_per_unit(unit);
      // Half-open, so that a range under 10x wide never admits two units at its ends.
      if (m >= c.lo && m < c.hi) c.admits.emplace_back(unit);
      else all = false;
    }
    if (all) fits.emplace_back(unit);
  }
  return fits;
}

}  // namespace

std::vector<float> unit_cues(const Groom& g) {
  std::vector<Cue> cues = size_cues(g);
  std::vector<float> out;
  for (const std::string& unit : admitted_units(cues)) out.push_back(metres_per_unit(unit));
  return out;
}

UnitGuess guess_unit(const Groom& g, const HeadFit& fit, const std::string& source) {
  std::vector<Cue> cues;
  if (fit.scalp) cues.push_back({"head radius", fit.radius, kHeadRadiusMin, kHeadRadiusMax, {}});
  for (Cue& c : size_cues(g)) cues.push_back(std::move(c));
  const std::vector<std::string> fits = admitted_units(cues);
  std::string sizes;
  for (const Cue& c : cues) {
    std::string admits;
    for (std::size_t i = 0; i < c.admits.size(); ++i)
      admits += (i == 0 ? "" : i + 1 == c.admits.size() ? " or " : ", ") + c.admits[i];
    sizes += (sizes.empty() ? "" : ", ") + c.what + " " + text(c.size, 4) + " (" + text(c.lo) + "-" + text(c.hi) +
             " m: " + (admits.empty() ? "no unit" : admits) + ")";
  }
  if (fits.size() != 1)
    throw InputError(source, "unit",
                     std::string("cannot tell the unit: ") +
                         (fits.empty() ? "no unit fits every cue" : "both " + fits[0] + " and " + fits[1] + " fit") +
                         " [file units: " + sizes + "]; give it (--unit, or \"unit\" in the scenario file)" +
                         (fits.empty() && fit.scalp && fit.note.empty()
                              ? ", or fit the head on the scalp's roots only (--fit-above, \"fit_above\")"
                              : ""));
  UnitGuess out;
  out.unit = fits[0];
  out.metres_per_unit = metres_per_unit(out.unit);
  out.why = cues.front().what + " " + text(cues.front().size, 4) + " file units = " +
            text(cues.front().size * out.metres_per_unit) + " m; every cue: " + sizes;
  return out;
}

std::vector<Repair> repair_groom(Groom& g, DegeneratePolicy policy, const std::string& source) {
  std::vector<Repair> out;
  const auto fail = [&](const std::string& field, const std::string& what) { throw InputError(source, field, what); };

  // Near-zero and short edges: relative to the strand's own median edge, and never under
  // 1e-7 m, validate_groom's floor. A strand with either is resampled once; the repair
  // that names it is the worse of its edges'.
  Repair edges{"near_zero_edges", 0, 0, "strand resampled at equal arc-length steps", ""};
  Repair shortened{"short_edges", 0, 0, "strand resampled at equal arc-length steps", ""};
  std::vector<double> e, sorted;
  for (std::size_t s = 0; s < g.strand_count(); ++s) {
    if (g.strand_size(s) < 2) continue;  // validate_groom names it
    edge_lengths(g, s, e);
    sorted = e;
    const double med = median(sorted);
    const double zero = std::max(kNearZeroEdge * med, 1e-7), short_limit = kShortEdge * med;
    std::size_t near_zero = 0, short_ones = 0;
    double total = 0.0;
    for (std::size_t i = 0; i < e.size(); ++i) {
      total += e[i];
      if (e[i] >= short_limit) continue;
      const bool is_zero = e[i] < zero;
      if (policy == DegeneratePolicy::Refuse)
        fail("strand " + std::to_string(s) + " edge " + std::to_string(i),
             std::string(is_zero ? "near-zero" : "short") + " rest edge of " + text(e[i]) + " m (under " +
                 text(is_zero ? kNearZeroEdge : kShortEdge) +
                 " of the strand's median edge; \"degenerate\": \"repair\" resamples the strand)");
      Repair& r = is_zero ? edges : shortened;
      if (r.example.empty()) r.example = edge_example(s, i, e[i]);
      ++(is_zero ? near_zero : short_ones);
    }
    if (near_zero + short_ones == 0) continue;
    // Resampling spreads the length over the edges; a strand with (almost) none cannot be.
    if (!(total > 1e-7 * static_cast<double>(e.size())))
      fail("strand " + std::to_string(s), "has zero length (every vertex at one point)");
    resample(g, s, e);
    edges.items += near_zero;
    shortened.items += short_ones;
    ++(near_zero > 0 ? edges : shortened).strands;
  }
  if (edges.strands > 0) out.push_back(edges);
  if (shortened.strands > 0) out.push_back(shortened);

  // Duplicate strands: the same vertices as an earlier strand (exporters that write a
  // strand twice). Grouped by the root's bits, then compared whole.
  Repair dups{"coincident_roots", 0, 0, "duplicate strand removed", ""};
  std::unordered_map<std::uint64_t, std::vector<std::size_t>> by_root;
  std::vector<char> keep(g.strand_count(), 1);
  for (std::size_t s = 0; s < g.strand_count(); ++s) {
    const Vec4f& r = g.positions[g.strand_begin(s)];
    std::array<std::uint32_t, 3> bits{};
    std::memcpy(bits.data(), r.data(), sizeof bits);
    const std::uint64_t key = (std::uint64_t{bits[0]} * 0x9e3779b97f4a7c15ull) ^
                              (std::uint64_t{bits[1]} * 0xc2b2ae3d27d4eb4full) ^ bits[2];
    auto& same = by_root[key];
    for (std::size_t t : same) {
      if (g.strand_size(t) != g.strand_size(s)) continue;
      bool equal = true;
      for (std::uint32_t i = 0; i < g.strand_size(s) && equal; ++i)
        equal = (g.positions[g.strand_begin(s) + i] - g.positions[g.strand_begin(t) + i]).head<3>().norm() <= 1e-7f;
      if (!equal) continue;
      if (policy == DegeneratePolicy::Refuse)
        fail("strand " + std::to_string(s),
             "repeats strand " + std::to_string(t) + " vertex for vertex (coincident roots; \"degenerate\": "
             "\"repair\" removes the copy)");
      if (dups.example.empty()) dups.example = "strand " + std::to_string(s) + " repeats strand " + std::to_string(t);
      keep[s] = 0;
      ++dups.strands;
      break;
    }
    if (keep[s]) same.push_back(s);
  }
  if (dups.strands > 0) {
    dups.items = dups.strands;
    Groom kept;
    kept.region_names = g.region_names;
    kept.head_radius = g.head_radius;
    for (std::size_t s = 0; s < g.strand_count(); ++s) {
      if (!keep[s]) continue;
      const auto b = g.positions.begin() + g.strand_begin(s);
      kept.positions.insert(kept.positions.end(), b, b + g.strand_size(s));
      kept.strand_offsets.push_back(static_cast<std::uint32_t>(kept.positions.size()));
      kept.strand_region.push_back(g.strand_region[s]);
    }
    g = std::move(kept);
    out.push_back(dups);
  }

  // Strands far shorter than the rest move rigidly with the head.
  std::vector<double> lengths(g.strand_count());
  for (std::size_t s = 0; s < g.strand_count(); ++s) {
    edge_lengths(g, s, e);
    for (double l : e) lengths[s] += l;
  }
  const double median_length = median(lengths);
  const double short_limit =
      std::max(kShortStrand * median_length, std::min(kStrandLengthMin, kShortFineStrand * median_length));
  Repair shorts{"short_strands", 0, 0, "every vertex pinned (moves rigidly with the head)", ""};
  for (std::size_t s = 0; s < g.strand_count(); ++s) {
    if (lengths[s] >= short_limit) continue;
    const std::uint32_t b = g.strand_begin(s), n = g.strand_size(s);
    bool free = false;
    for (std::uint32_t i = b; i < b + n; ++i) free = free || g.positions[i].w() != 0.0f;
    if (!free) continue;  // already rigid
    if (policy == DegeneratePolicy::Refuse)
      fail("strand " + std::to_string(s),
           "is " + text(lengths[s]) + " m long, under " + text(short_limit) + " m (" + text(kShortStrand) +
               " of the median strand, " + text(median_length) + " m, or under " + text(kStrandLengthMin) +
               " m and " + text(kShortFineStrand) + " of it; \"degenerate\": \"repair\" pins it)");
    if (shorts.example.empty()) shorts.example = "strand " + std::to_string(s) + " (" + text(lengths[s]) + " m)";
    for (std::uint32_t i = b; i < b + n; ++i) g.positions[i].w() = 0.0f;
    ++shorts.strands;
  }
  shorts.items = shorts.strands;
  if (shorts.strands > 0) out.push_back(shorts);
  return out;
}

std::string repairs_text(const std::vector<Repair>& repairs) {
  if (repairs.empty()) return "repairs: none";
  std::string out = "repairs:";
  for (std::size_t i = 0; i < repairs.size(); ++i) {
    const Repair& r = repairs[i];
    out += i == 0 ? " " : "; ";
    if (r.kind == "near_zero_edges")
      out += std::to_string(r.items) + " near-zero edges in " + std::to_string(r.strands) + " strands resampled";
    else if (r.kind == "short_edges")
      out += std::to_string(r.items) + " short edges in " + std::to_string(r.strands) + " strands resampled";
    else if (r.kind == "coincident_roots")
      out += std::to_string(r.strands) + " duplicate strands removed";
    else
      out += std::to_string(r.strands) + " short strands pinned";
    out += " (first: " + r.example + ")";
  }
  return out;
}

}  // namespace hairbench
