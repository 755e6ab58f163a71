#include "reports/metrics.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <sstream>
#include <iomanip>

namespace hairbench::metrics {

namespace {
Eigen::Vector3d xyz(const Vec4f& v) { return v.head<3>().cast<double>(); }

// The per-frame metrics cost about as much as a fast model's step in `compare`, which
// computes them per model and frame (issue 10). Their hot loops are built twice, for
// x86-64-v4 (AVX-512) and the baseline, and chosen at load time; the IEEE operations
// give the same bits in either (no FMA contraction, -ffp-contract=off).
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__)
#define METRIC_CLONES __attribute__((target_clones("arch=x86-64-v4", "default")))
#else
#define METRIC_CLONES
#endif
// Their helpers are inlined into each build (a call would run the baseline build).
#define METRIC_INLINE [[gnu::always_inline]] inline

// A sum's terms are computed kChunk at a time into a buffer, by a loop that vectorises,
// and added in order after it: the same additions in the same order as in one loop, so
// the same bits, without each term's arithmetic waiting on the running sum.
constexpr std::size_t kChunk = 256;

// |a - b|^2 of two points in double: Eigen's (xyz(a) - xyz(b)).squaredNorm(), term by
// term in its order, written out so that loops over points vectorise.
METRIC_INLINE double distance2(const Vec4f& a, const Vec4f& b) {
  const double dx = double(a.x()) - double(b.x()), dy = double(a.y()) - double(b.y()),
               dz = double(a.z()) - double(b.z());
  return (dx * dx + dy * dy) + dz * dz;
}
template <class Term, class Add>
METRIC_INLINE void chunked(std::size_t begin, std::size_t end, Term term, Add add) {
  double buf[kChunk];
  for (std::size_t c = begin; c < end; c += kChunk) {
    const std::size_t m = std::min(kChunk, end - c);
    for (std::size_t k = 0; k < m; ++k) buf[k] = term(c + k);
    for (std::size_t k = 0; k < m; ++k) add(buf[k]);
  }
}
}  // namespace

RestInfo::RestInfo(const Groom& rest, std::size_t simulated)
    : groom(&rest),
      rest_length(rest_edge_lengths(rest)),
      mean_strand_length(hairbench::mean_strand_length(rest)),
      head_extent(0.0),
      simulated_strands(std::min(simulated, rest.strand_count())) {
  rest_jaggedness.resize(rest.strand_count());
  for (std::size_t s = 0; s < rest.strand_count(); ++s) {
    rest_jaggedness[s] = strand_jaggedness_raw(
        std::span(rest.positions).subspan(rest.strand_begin(s), rest.strand_size(s)));
    head_extent = std::max(head_extent, xyz(rest.positions[rest.strand_begin(s)]).norm());
  }
}

METRIC_CLONES double deviation(std::span<const Vec4f> p, std::span<const Vec4f> ref, double mean_length) {
  double sum = 0.0;
  chunked(
      0, p.size(), [&](std::size_t i) { return distance2(p[i], ref[i]); }, [&](double t) { sum += t; });
  return std::sqrt(sum / static_cast<double>(p.size())) / mean_length;
}

namespace {
// Curvature binormal at vertex i (between edges e0: i-1 -> i and e1: i -> i+1, of lengths
// l0 and l1). An exact hairpin (antiparallel edges) has unbounded curvature; the
// denominator is floored so the metric stays finite and large there.
Eigen::Vector3d curvature_binormal(const Eigen::Vector3d& e0, double l0, const Eigen::Vector3d& e1, double l1) {
  const double lens = l0 * l1;
  const double denom = std::max(lens + e0.dot(e1), 1e-12 * std::max(lens, 1e-30));
  return 2.0 * e0.cross(e1) / denom;
}
}  // namespace

// Each edge and its length are computed once and handed on to the next vertex: the
// metrics cost about as much as the models' steps in `compare` (issue 10).
double strand_jaggedness_raw(std::span<const Vec4f> s) {
  const std::size_t n = s.size();
  if (n < 4) return 0.0;
  double sum = 0.0;
  Eigen::Vector3d e0 = xyz(s[1]) - xyz(s[0]), e1 = xyz(s[2]) - xyz(s[1]);
  double l0 = e0.norm(), l1 = e1.norm();
  Eigen::Vector3d prev = curvature_binormal(e0, l0, e1, l1);
  for (std::size_t i = 2; i + 1 < n; ++i) {
    e0 = e1;
    l0 = l1;
    e1 = xyz(s[i + 1]) - xyz(s[i]);
    l1 = e1.norm();
    const Eigen::Vector3d kb = curvature_binormal(e0, l0, e1, l1);
    sum += (kb - prev).squaredNorm();
    prev = kb;
  }
  return std::sqrt(sum / static_cast<double>(n - 3));
}

namespace {

// strand_jaggedness_raw of kLanes strands of n >= 4 vertices each at once, one strand per
// lane: every lane repeats that function's operations in Eigen's order for 3-vectors
// (sums left to right, cross product by components), so each strand gets the same bits,
// and the loops over lanes vectorise, the divisions and square roots with them
// (issue 10: the metrics cost about as much as a fast model's step in `compare`).
constexpr int kLanes = 8;
#define METRIC_LANES _Pragma("GCC ivdep") for (int l = 0; l < kLanes; ++l)

struct Edges {
  double x[kLanes], y[kLanes], z[kLanes], len[kLanes];
};

// Edge i -> i + 1 of each lane's strand, and its length.
METRIC_INLINE void lane_edges(std::span<const Vec4f> p, const std::size_t* begin, std::size_t i, Edges& e) {
  METRIC_LANES {
    const Vec4f& a = p[begin[l] + i];
    const Vec4f& b = p[begin[l] + i + 1];
    e.x[l] = double(b.x()) - double(a.x());
    e.y[l] = double(b.y()) - double(a.y());
    e.z[l] = double(b.z()) - double(a.z());
    e.len[l] = std::sqrt((e.x[l] * e.x[l] + e.y[l] * e.y[l]) + e.z[l] * e.z[l]);
  }
}

// curvature_binormal per lane.
METRIC_INLINE void lane_binormals(const Edges& e0, const Edges& e1, double (&kb)[3][kLanes]) {
  METRIC_LANES {
    const double lens = e0.len[l] * e1.len[l];
    const double dot = (e0.x[l] * e1.x[l] + e0.y[l] * e1.y[l]) + e0.z[l] * e1.z[l];
    const double denom = std::max(lens + dot, 1e-12 * std::max(lens, 1e-30));
    kb[0][l] = 2.0 * (e0.y[l] * e1.z[l] - e0.z[l] * e1.y[l]) / denom;
    kb[1][l] = 2.0 * (e0.z[l] * e1.x[l] - e0.x[l] * e1.z[l]) / denom;
    kb[2][l] = 2.0 * (e0.x[l] * e1.y[l] - e0.y[l] * e1.x[l]) / denom;
  }
}

METRIC_INLINE void lane_jaggedness(std::span<const Vec4f> p, const std::size_t* begin, std::size_t n, double* out) {
  Edges e0, e1;
  double prev[3][kLanes], kb[3][kLanes], sum[kLanes];
  lane_edges(p, begin, 0, e0);
  lane_edges(p, begin, 1, e1);
  lane_binormals(e0, e1, prev);
  METRIC_LANES sum[l] = 0.0;
  for (std::size_t i = 2; i + 1 < n; ++i) {
    e0 = e1;
    lane_edges(p, begin, i, e1);
    lane_binormals(e0, e1, kb);
    METRIC_LANES {
      const double dx = kb[0][l] - prev[0][l], dy = kb[1][l] - prev[1][l], dz = kb[2][l] - prev[2][l];
      sum[l] += (dx * dx + dy * dy) + dz * dz;
      prev[0][l] = kb[0][l];
      prev[1][l] = kb[1][l];
      prev[2][l] = kb[2][l];
    }
  }
  METRIC_LANES out[l] = std::sqrt(sum[l] / static_cast<double>(n - 3));
}

}  // namespace

METRIC_CLONES double jaggedness(const RestInfo& rest, std::span<const Vec4f> p) {
  const Groom& g = *rest.groom;
  const std::size_t strands = g.strand_count();
  double sum = 0.0;
  std::size_t begin[kLanes];
  double raw[kLanes];
  for (std::size_t s = 0; s < strands;) {
    // kLanes strands of one size >= 4 together; the strands are added in order either way.
    const std::size_t n = g.strand_size(s);
    bool together = n >= 4 && s + kLanes <= strands;
    for (int l = 0; l < kLanes && together; ++l) {
      together = g.strand_size(s + l) == n;
      begin[l] = g.strand_begin(s + l);
    }
    if (together) {
      lane_jaggedness(p, begin, n, raw);
      for (int l = 0; l < kLanes; ++l) sum += raw[l] - rest.rest_jaggedness[s + l];
      s += kLanes;
    } else {
      sum += strand_jaggedness_raw(p.subspan(g.strand_begin(s), n)) - rest.rest_jaggedness[s];
      ++s;
    }
  }
  return sum / static_cast<double>(strands);
}

METRIC_CLONES LengthError length_error(const RestInfo& rest, std::span<const Vec4f> p) {
  const Groom& g = *rest.groom;
  LengthError out;
  double sum = 0.0;
  std::size_t edges = 0;
  for (std::size_t s = 0; s < g.strand_count(); ++s) {
    const std::size_t b = g.strand_begin(s), n = g.strand_size(s);
    chunked(
        b + 1, b + n,
        [&](std::size_t i) {
          return std::abs((xyz(p[i]) - xyz(p[i - 1])).norm() - rest.rest_length[i]) / rest.rest_length[i];
        },
        [&](double e) {
          sum += e * e;
          out.max = std::max(out.max, e);
          ++edges;
        });
  }
  out.rms = edges ? std::sqrt(sum / static_cast<double>(edges)) : 0.0;
  return out;
}

METRIC_CLONES double rest_shape_error(const RestInfo& rest, std::span<const Vec4f> p, const Affine3f& head) {
  const Affine3f& h = head;
  double sum = 0.0;
  const auto& r = rest.groom->positions;
  chunked(
      0, p.size(),
      [&](std::size_t i) {
        const Vec3f goal = h * Vec3f(r[i].head<3>());
        return (xyz(p[i]) - goal.cast<double>()).squaredNorm();
      },
      [&](double t) { sum += t; });
  return std::sqrt(sum / static_cast<double>(p.size())) / rest.mean_strand_length;
}

// Per sphere, the depth r - |v - c| is largest at the smallest squared distance: the
// rounded square root and subtraction are monotonic, so the depth of the nearest vertex
// is the bits of the largest depth (NaN distances are skipped, as std::max skipped
// them). A depth below 0 adds nothing. The minimum is taken in kLanes running minima,
// combined at the end: a minimum of squares (never -0) does not depend on the order.
METRIC_CLONES double penetration(std::span<const Vec4f> p, std::span<const Vec4f> world_spheres) {
  double deepest = 0.0;
  for (const Vec4f& s : world_spheres) {
    double lane_min[kLanes];
    METRIC_LANES lane_min[l] = std::numeric_limits<double>::infinity();
    const std::size_t whole = p.size() / kLanes * kLanes;
    for (std::size_t i = 0; i < whole; i += kLanes) METRIC_LANES {
        const double d = distance2(p[i + l], s);
        lane_min[l] = d < lane_min[l] ? d : lane_min[l];
      }
    double nearest2 = std::numeric_limits<double>::infinity();
    for (std::size_t i = whole; i < p.size(); ++i) {
      const double d = distance2(p[i], s);
      nearest2 = d < nearest2 ? d : nearest2;
    }
    for (int l = 0; l < kLanes; ++l) nearest2 = lane_min[l] < nearest2 ? lane_min[l] : nearest2;
    if (p.size() > 0) deepest = std::max(deepest, double(s.w()) - std::sqrt(nearest2));
  }
  return deepest;
}

// DESIGN.md's "a vertex farther than 10 L-bar from the head" reads "from the head" as from
// the head body, which carries the roots: every root lies within head_extent of the head
// centre, so a vertex more than head_extent + 10 L-bar from the centre is farther than
// 10 L-bar from every point of the head. (A bare distance from the centre would call a
// groom unstable at rest whose roots span more than 10 strand lengths: TestHair1's 11 cm
// strands sit up to 1.06 m from its centre.)
// The edge test covers the strands the models simulate. Follow strands rebuilt from a guide
// are that guide plus a rigid offset (tfx::FollowHairs): their edges are not constrained
// and change length whenever the guide turns against the offset, so their stretch is the
// follow layer's, reported by length_error, not a blow-up of the model; NaN/Inf and the
// distance test still cover them.
METRIC_CLONES std::string blowup_reason(const RestInfo& rest, std::span<const Vec4f> p, const Vec3f& head_center) {
  const Groom& g = *rest.groom;
  const double far = rest.head_extent + 10.0 * rest.mean_strand_length;
  const Eigen::Vector3d c = head_center.cast<double>();
  // A screen per strand first, without branches so that it vectorises: squared lengths
  // against bounds a little inside the tests' (0.98 far^2 against far^2; 0.26 r^2 and
  // 2.2 r^2 against (0.5 r)^2 and (1.5 r)^2), where NaN and Inf fail every comparison.
  // Only a strand the screen flags takes the exact tests, in order, so the first failure
  // reported is the same; the square roots and branches per vertex were most of this
  // function's cost, which `compare` pays per model and frame (issue 10).
  constexpr double kNear = 0.98, kShort = 0.26, kLong = 2.2;
  const double near2 = kNear * far * far;
  for (std::size_t s = 0; s < g.strand_count(); ++s) {
    const std::size_t b = g.strand_begin(s), n = g.strand_size(s);
    const bool simulated = s < rest.simulated_strands;
    int flagged = 0;
    for (std::size_t i = b; i < b + n; ++i)
      flagged |= static_cast<int>(!((xyz(p[i]) - c).squaredNorm() <= near2)) |
                 static_cast<int>(!(p[i].w() * 0.0f == 0.0f));  // w: NaN or Inf
    if (simulated)
      for (std::size_t i = b + 1; i < b + n; ++i) {
        const double l2 = (xyz(p[i]) - xyz(p[i - 1])).squaredNorm(), r2 = rest.rest_length[i] * rest.rest_length[i];
        flagged |= static_cast<int>(!(l2 > kShort * r2)) | static_cast<int>(!(l2 < kLong * r2));
      }
    if (!flagged) continue;
    for (std::size_t i = b; i < b + n; ++i) {
      if (!p[i].allFinite())
        return "non-finite position (strand " + std::to_string(s) + ", vertex " + std::to_string(i - b) + ")";
      if ((xyz(p[i]) - c).norm() > far)
        return "vertex farther than 10 mean strand lengths from the head (strand " + std::to_string(s) + ")";
      if (simulated && i > b) {
        const double e = std::abs((xyz(p[i]) - xyz(p[i - 1])).norm() - rest.rest_length[i]) / rest.rest_length[i];
        if (e > 0.5)
          return "edge length error above 50% (strand " + std::to_string(s) + ", edge " + std::to_string(i - b) + ")";
      }
    }
  }
  return {};
}

double mechanical_energy(std::span<const Vec4f> p, std::span<const Vec4f> prev, double dt, const Vec3f& gravity) {
  if (p.empty()) return 0.0;
  const Eigen::Vector3d g = gravity.cast<double>();
  double e = 0.0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    const Eigen::Vector3d v = (xyz(p[i]) - xyz(prev[i])) / dt;
    e += 0.5 * v.squaredNorm() - g.dot(xyz(p[i]));
  }
  return e / static_cast<double>(p.size());
}

std::string EnergyGrowthCheck::add(double energy, bool driven) {
  if (driven) {  // energy may rise while the head or the wind works on the hair
    sum_ = 0.0;
    in_window_ = 0;
    have_last_ = false;
    rising_ = 0;
    return {};
  }
  sum_ += energy;
  if (++in_window_ < kWindow) return {};
  const double mean = sum_ / kWindow;
  sum_ = 0.0;
  in_window_ = 0;
  rising_ = (have_last_ && mean - last_mean_ > min_rise_) ? rising_ + 1 : 0;
  last_mean_ = mean;
  have_last_ = true;
  if (rising_ < kWindows) return {};
  return "mechanical energy grew for " + std::to_string(kWindow * kWindows) + " frames with the head still and no wind";
}

std::uint64_t state_hash(std::span<const Vec4f> p) {
  std::uint64_t h = 1469598103934665603ull;
  for (const Vec4f& v : p)
    for (int k = 0; k < 4; ++k) {
      std::uint32_t bits;
      const float f = v[k];
      std::memcpy(&bits, &f, sizeof bits);
      for (int byte = 0; byte < 4; ++byte) {
        h ^= (bits >> (8 * byte)) & 0xffu;
        h *= 1099511628211ull;
      }
    }
  return h;
}

std::string hash_hex(std::uint64_t h) {
  std::ostringstream os;
  os << std::hex << std::setw(16) << std::setfill('0') << h;
  return os.str();
}

}  // namespace hairbench::metrics
