#include "reports/metrics.h"

#include "reports/chunked.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <sstream>
#include <iomanip>

namespace hairbench::metrics {

namespace {
Eigen::Vector3d xyz(const Vec4f& v) { return v.head<3>().cast<double>(); }

// |a - b|^2 of two points in double: Eigen's (xyz(a) - xyz(b)).squaredNorm(), term by
// term in its order, written out so that loops over points vectorise.
METRIC_INLINE double distance2(const Vec4f& a, const Vec4f& b) {
  const double dx = double(a.x()) - double(b.x()), dy = double(a.y()) - double(b.y()),
               dz = double(a.z()) - double(b.z());
  return (dx * dx + dy * dy) + dz * dz;
}
// The lanes of the vector code below (LaneVec): strands side by side in jaggedness,
// vertices in penetration.
constexpr int kLanes = 8;

// The strands of each size >= 4 in groups of kLanes (in index order), and those left over.
void group_for_lanes(const Groom& g, std::vector<std::uint32_t>& grouped, std::vector<std::uint32_t>& alone) {
  std::vector<std::uint32_t> order(g.strand_count());
  for (std::uint32_t s = 0; s < order.size(); ++s) order[s] = s;
  std::stable_sort(order.begin(), order.end(),
                   [&](std::uint32_t a, std::uint32_t b) { return g.strand_size(a) < g.strand_size(b); });
  for (std::size_t i = 0; i < order.size();) {
    const std::size_t n = g.strand_size(order[i]);
    std::size_t j = i;
    while (j < order.size() && g.strand_size(order[j]) == n) ++j;
    const std::size_t lanes = n >= 4 ? (j - i) / kLanes * kLanes : 0;
    grouped.insert(grouped.end(), order.begin() + i, order.begin() + i + lanes);
    alone.insert(alone.end(), order.begin() + i + lanes, order.begin() + j);
    i = j;
  }
  std::sort(alone.begin(), alone.end());
}

// chunked over the edges (i - 1, i) of every strand, i in [1, end), as one run over the
// groom's vertices instead of one per strand (model 1's strands have about 11 vertices,
// too few for a loop per strand to vectorise): term(i) for every i, then 0 at the
// strands' roots, where no edge ends (their terms, computed with a rest length of 0, are
// not used). add(i, term) must leave its state as it was when given 0.
template <class Term, class Add>
METRIC_INLINE void edge_chunked(const Groom& g, std::size_t end, Term term, Add add) {
  decltype(term(1)) buf[kChunk];
  std::size_t s = 1;  // the next strand whose root is not yet behind (strand 0's is vertex 0)
  for (std::size_t c = 1; c < end; c += kChunk) {
    const std::size_t m = std::min(kChunk, end - c);
    for (std::size_t k = 0; k < m; ++k) buf[k] = term(c + k);
    for (; s < g.strand_count() && g.strand_begin(s) < c + m; ++s) buf[g.strand_begin(s) - c] = 0;
    for (std::size_t k = 0; k < m; ++k) add(c + k, buf[k]);
  }
}

// The median of a strand's rest edges (the mean of the middle two for an even count).
double median_edge(const float* first, std::size_t edges, std::vector<float>& buf) {
  buf.assign(first, first + edges);
  const std::size_t mid = edges / 2;
  std::nth_element(buf.begin(), buf.begin() + mid, buf.end());
  const double upper = buf[mid];
  if (edges % 2) return upper;
  const double lower = *std::max_element(buf.begin(), buf.begin() + mid);
  return 0.5 * (lower + upper);
}
}  // namespace

RestInfo::RestInfo(const Groom& rest, std::size_t simulated)
    : groom(&rest),
      rest_length(rest_edge_lengths(rest)),
      edge_count(0),
      mean_strand_length(hairbench::mean_strand_length(rest)),
      rest_kb_change(rest.vertex_count(), 0.0),
      kb_weight(rest.vertex_count(), 1.0),
      head_extent(0.0),
      simulated_strands(std::min(simulated, rest.strand_count())) {
  // The fallback scale: the mean rest edge of the simulated strands (of all strands if
  // those have no edges), which the models' constraints hold.
  double simulated_sum = 0.0, all_sum = 0.0;
  std::size_t simulated_edges = 0;
  for (std::size_t s = 0; s < rest.strand_count(); ++s) {
    const std::size_t b = rest.strand_begin(s), n = rest.strand_size(s);
    strand_kb_changes(std::span(rest.positions).subspan(b, n), std::span(rest_kb_change).subspan(b, n));
    head_extent = std::max(head_extent, xyz(rest.positions[b]).norm());
    const std::size_t edges = std::max<std::size_t>(n, 1) - 1;
    edge_count += edges;
    for (std::size_t i = b + 1; i < b + n; ++i) {
      all_sum += rest_length[i];
      if (s < simulated_strands) simulated_sum += rest_length[i];
    }
    if (s < simulated_strands) simulated_edges += edges;
  }
  const double mean_edge = simulated_edges ? simulated_sum / static_cast<double>(simulated_edges)
                           : edge_count    ? all_sum / static_cast<double>(edge_count)
                                           : 0.0;
  edge_scale.resize(rest.strand_count());
  vertex_edge_scale.resize(rest.vertex_count());
  std::vector<float> buf;
  for (std::size_t s = 0; s < rest.strand_count(); ++s) {
    const std::size_t b = rest.strand_begin(s), n = rest.strand_size(s);
    const double median = n > 1 ? median_edge(rest_length.data() + b + 1, n - 1, buf) : 0.0;
    edge_scale[s] = median > 1e-6 * mean_edge ? median : mean_edge;
    std::fill_n(vertex_edge_scale.begin() + static_cast<std::ptrdiff_t>(b), n, edge_scale[s]);
    // The pair at vertex b + i reads kb at i - 1 and i: the edges ending at i - 1, i, i + 1.
    const double shortest = kMinTurnEdge * edge_scale[s];
    for (std::size_t i = 2; i + 1 < n; ++i)
      if (rest_length[b + i - 1] < shortest || rest_length[b + i] < shortest || rest_length[b + i + 1] < shortest)
        kb_weight[b + i] = 0.0;
  }
  group_for_lanes(rest, jagged_grouped, jagged_alone);
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

// Each edge and its length are computed once and handed on to the next vertex: the
// metrics cost about as much as the models' steps in `compare`. f(i, d) is called with
// d = |kb_i - kb_{i-1}| for i = 2 .. n-2, n >= 4.
template <class F>
void for_kb_changes(std::span<const Vec4f> s, F f) {
  const std::size_t n = s.size();
  Eigen::Vector3d e0 = xyz(s[1]) - xyz(s[0]), e1 = xyz(s[2]) - xyz(s[1]);
  double l0 = e0.norm(), l1 = e1.norm();
  Eigen::Vector3d prev = curvature_binormal(e0, l0, e1, l1);
  for (std::size_t i = 2; i + 1 < n; ++i) {
    e0 = e1;
    l0 = l1;
    e1 = xyz(s[i + 1]) - xyz(s[i]);
    l1 = e1.norm();
    const Eigen::Vector3d kb = curvature_binormal(e0, l0, e1, l1);
    f(i, (kb - prev).norm());
    prev = kb;
  }
}
}  // namespace

void strand_kb_changes(std::span<const Vec4f> s, std::span<double> out) {
  if (s.size() < 4) return;
  for_kb_changes(s, [&](std::size_t i, double d) { out[i] = d; });
}

double strand_jaggedness(std::span<const Vec4f> s, std::span<const double> rest_kb_change,
                         std::span<const double> kb_weight) {
  const std::size_t n = s.size();
  if (n < 4) return 0.0;
  double sum = 0.0;
  for_kb_changes(s, [&](std::size_t i, double d) {
    const double diff = (d - rest_kb_change[i]) * kb_weight[i];
    sum += diff * diff;
  });
  return std::sqrt(sum / static_cast<double>(n - 3));
}

double strand_jaggedness(const RestInfo& rest, std::span<const Vec4f> p, std::size_t s) {
  const std::size_t b = rest.groom->strand_begin(s), n = rest.groom->strand_size(s);
  return strand_jaggedness(p.subspan(b, n), std::span(rest.rest_kb_change).subspan(b, n),
                           std::span(rest.kb_weight).subspan(b, n));
}

namespace {

// strand_jaggedness of kLanes strands of n >= 4 vertices each at once, one strand per
// lane: every lane repeats that function's operations in Eigen's order for 3-vectors
// (sums left to right, cross product by components, a norm as the square root of the
// squared norm), so each strand gets the same bits.
// The lanes are one GCC vector (LaneVec), whose operations are those IEEE operations lane
// by lane: written as loops over arrays, GCC keeps the running sums and the previous
// binormal in scalar registers and adds them one lane at a time (and the metrics cost
// about as much as a fast model's step in `compare`).
using LaneVec = double __attribute__((vector_size(kLanes * sizeof(double))));

// Lane by lane square root (a vector square root instruction where the target has one).
METRIC_INLINE void lane_sqrt(const LaneVec& v, LaneVec& out) {
  for (int l = 0; l < kLanes; ++l) out[l] = std::sqrt(v[l]);
}

// std::max(a, b) lane by lane: b where a < b, else a.
METRIC_INLINE void lane_max(const LaneVec& a, const LaneVec& b, LaneVec& out) { out = a < b ? b : a; }

struct LanePoints {
  LaneVec x, y, z;
};

// Vertex i of each lane's strand, in double.
METRIC_INLINE void lane_points(std::span<const Vec4f> p, const std::size_t* begin, std::size_t i, LanePoints& v) {
  for (int l = 0; l < kLanes; ++l) {
    const Vec4f& a = p[begin[l] + i];
    v.x[l] = double(a.x());
    v.y[l] = double(a.y());
    v.z[l] = double(a.z());
  }
}

struct LaneEdges {
  LaneVec x, y, z, len;
};

// Edge a -> b of each lane, and its length.
METRIC_INLINE void lane_edges(const LanePoints& a, const LanePoints& b, LaneEdges& e) {
  e.x = b.x - a.x;
  e.y = b.y - a.y;
  e.z = b.z - a.z;
  lane_sqrt((e.x * e.x + e.y * e.y) + e.z * e.z, e.len);
}

// curvature_binormal per lane.
METRIC_INLINE void lane_binormals(const LaneEdges& e0, const LaneEdges& e1, LaneVec (&kb)[3]) {
  const LaneVec lens = e0.len * e1.len;
  const LaneVec dot = (e0.x * e1.x + e0.y * e1.y) + e0.z * e1.z;
  LaneVec floored, denom;
  lane_max(lens, LaneVec{} + 1e-30, floored);
  lane_max(lens + dot, 1e-12 * floored, denom);
  kb[0] = 2.0 * (e0.y * e1.z - e0.z * e1.y) / denom;
  kb[1] = 2.0 * (e0.z * e1.x - e0.x * e1.z) / denom;
  kb[2] = 2.0 * (e0.x * e1.y - e0.y * e1.x) / denom;
}

METRIC_INLINE void lane_jaggedness(std::span<const Vec4f> p, const double* rest_kb_change, const double* kb_weight,
                                   const std::size_t* begin, std::size_t n, double* out) {
  LanePoints a, b;  // vertices i and i + 1
  LaneEdges e0, e1;
  LaneVec prev[3], kb[3], sum{}, d, d0{}, w{};
  lane_points(p, begin, 0, a);
  lane_points(p, begin, 1, b);
  lane_edges(a, b, e0);
  lane_points(p, begin, 2, a);
  lane_edges(b, a, e1);
  lane_binormals(e0, e1, prev);
  for (std::size_t i = 2; i + 1 < n; ++i) {
    b = a;
    lane_points(p, begin, i + 1, a);
    e0 = e1;
    lane_edges(b, a, e1);
    lane_binormals(e0, e1, kb);
    const LaneVec dx = kb[0] - prev[0], dy = kb[1] - prev[1], dz = kb[2] - prev[2];
    lane_sqrt((dx * dx + dy * dy) + dz * dz, d);
    for (int l = 0; l < kLanes; ++l) {
      d0[l] = rest_kb_change[begin[l] + i];
      w[l] = kb_weight[begin[l] + i];
    }
    const LaneVec diff = (d - d0) * w;
    sum += diff * diff;
    prev[0] = kb[0];
    prev[1] = kb[1];
    prev[2] = kb[2];
  }
  LaneVec root;
  lane_sqrt(sum / static_cast<double>(n - 3), root);
  for (int l = 0; l < kLanes; ++l) out[l] = root[l];
}

}  // namespace

// Strands are grouped by size at load (group_for_lanes): a ragged groom such as Table 1's
// model 1 rarely has kLanes consecutive strands of one size, and the strands left alone
// would take a large share of a fast model's comparison on it. Each strand's value is the
// same either way, and they are added in index order: the same bits.
METRIC_CLONES double jaggedness(const RestInfo& rest, std::span<const Vec4f> p) {
  const Groom& g = *rest.groom;
  const std::size_t strands = g.strand_count();
  thread_local std::vector<double> per_strand;  // the metrics of lanes run on several threads
  per_strand.resize(strands);
  const std::vector<std::uint32_t>& grouped = rest.jagged_grouped;
  for (std::size_t k = 0; k < grouped.size(); k += kLanes) {
    std::size_t begin[kLanes];
    double out[kLanes];
    for (int l = 0; l < kLanes; ++l) begin[l] = g.strand_begin(grouped[k + l]);
    lane_jaggedness(p, rest.rest_kb_change.data(), rest.kb_weight.data(), begin, g.strand_size(grouped[k]), out);
    for (int l = 0; l < kLanes; ++l) per_strand[grouped[k + l]] = out[l];
  }
  for (const std::uint32_t s : rest.jagged_alone) per_strand[s] = strand_jaggedness(rest, p, s);
  double sum = 0.0;
  for (std::size_t s = 0; s < strands; ++s) sum += per_strand[s];
  return sum / static_cast<double>(strands);
}

// The edges are added in the order of the strands and, within a strand, from the root:
// the terms of one run over the groom (edge_chunked), in which a root adds 0 to the sum
// of squares (x + 0 is x, for any x this sum can hold) and to the maximum (never above 0
// at a root, never NaN; a strictly larger term moves the worst edge, so the first of
// equal maxima stays). The same bits.
METRIC_CLONES LengthError length_error(const RestInfo& rest, std::span<const Vec4f> p) {
  const Groom& g = *rest.groom;
  const float* rl = rest.rest_length.data();
  const double* scale = rest.vertex_edge_scale.data();
  LengthError out;
  double sum = 0.0;
  std::size_t worst = 0;
  edge_chunked(
      g, p.size(),
      [&](std::size_t i) { return std::abs(std::sqrt(distance2(p[i], p[i - 1])) - double(rl[i])) / scale[i]; },
      [&](std::size_t i, double e) {
        sum += e * e;
        const bool above = out.max < e;
        worst = above ? i : worst;
        out.max = above ? e : out.max;
      });
  if (out.max > 0.0) {
    const auto& offsets = g.strand_offsets;
    const auto strand = std::upper_bound(offsets.begin(), offsets.end(), worst) - offsets.begin() - 1;
    out.worst_strand = static_cast<std::uint32_t>(strand);
    out.worst_edge = static_cast<std::uint32_t>(worst - g.strand_begin(out.worst_strand));
  }
  const std::size_t edges = rest.edge_count;
  out.rms = edges ? std::sqrt(sum / static_cast<double>(edges)) : 0.0;
  return out;
}

// T_H p^0 is Eigen's Affine3f product, written out in its order (as soa::AffinePose) so
// that the loop vectorises. Eigen sums the squared difference of a Vector3d and a cast
// Vector3f as x^2 + (y^2 + z^2), unlike distance2's two Vector3d.
METRIC_CLONES double rest_shape_error(const RestInfo& rest, std::span<const Vec4f> p, const Affine3f& head) {
  const Eigen::Matrix3f m = head.linear();
  const Vec3f t = head.translation();
  double sum = 0.0;
  const Vec4f* r = rest.groom->positions.data();
  chunked(
      0, p.size(),
      [&](std::size_t i) {
        const float a = r[i].x(), b = r[i].y(), c = r[i].z();
        const float gx = t.x() + ((m(0, 0) * a + m(0, 1) * b) + m(0, 2) * c);
        const float gy = t.y() + ((m(1, 0) * a + m(1, 1) * b) + m(1, 2) * c);
        const float gz = t.z() + ((m(2, 0) * a + m(2, 1) * b) + m(2, 2) * c);
        const double dx = double(p[i].x()) - double(gx), dy = double(p[i].y()) - double(gy),
                     dz = double(p[i].z()) - double(gz);
        return dx * dx + (dy * dy + dz * dz);
      },
      [&](double term) { sum += term; });
  return std::sqrt(sum / static_cast<double>(p.size())) / rest.mean_strand_length;
}

// The smallest squared distance (distance2) from the vertices to each of M spheres, in
// kLanes running minima per sphere: each vertex is loaded and widened once for all M.
template <int M>
METRIC_INLINE void nearest2(std::span<const Vec4f> p, const Vec4f* spheres, double* out) {
  const std::size_t whole = p.size() / kLanes * kLanes;
  LaneVec lane_min[M];
  for (int k = 0; k < M; ++k) lane_min[k] = LaneVec{} + std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < whole; i += kLanes) {
    std::size_t begin[kLanes];
    for (int l = 0; l < kLanes; ++l) begin[l] = i + static_cast<std::size_t>(l);
    LanePoints v;
    lane_points(p, begin, 0, v);
    for (int k = 0; k < M; ++k) {
      const LaneVec dx = v.x - double(spheres[k].x()), dy = v.y - double(spheres[k].y()),
                    dz = v.z - double(spheres[k].z());
      const LaneVec d = (dx * dx + dy * dy) + dz * dz;
      lane_min[k] = d < lane_min[k] ? d : lane_min[k];
    }
  }
  for (int k = 0; k < M; ++k) {
    double m = std::numeric_limits<double>::infinity();
    for (std::size_t i = whole; i < p.size(); ++i) {
      const double d = distance2(p[i], spheres[k]);
      m = d < m ? d : m;
    }
    for (int l = 0; l < kLanes; ++l) m = lane_min[k][l] < m ? lane_min[k][l] : m;
    out[k] = m;
  }
}

// Per sphere, the depth r - |v - c| is largest at the smallest squared distance: the
// rounded square root and subtraction are monotonic, so the depth of the nearest vertex
// is the bits of the largest depth (NaN distances are skipped, as std::max skipped
// them). A depth below 0 adds nothing. A minimum of squares (never -0) does not depend on
// the order in which it is taken. Up to four spheres share a pass over the vertices.
METRIC_CLONES double penetration(std::span<const Vec4f> p, std::span<const Vec4f> world_spheres) {
  double deepest = 0.0;
  if (p.empty()) return deepest;
  for (std::size_t c = 0; c < world_spheres.size(); c += 4) {
    const Vec4f* s = world_spheres.data() + c;
    double d2[4];
    switch (std::min<std::size_t>(4, world_spheres.size() - c)) {
      case 1: nearest2<1>(p, s, d2); break;
      case 2: nearest2<2>(p, s, d2); break;
      case 3: nearest2<3>(p, s, d2); break;
      default: nearest2<4>(p, s, d2); break;
    }
    for (std::size_t k = 0; k < 4 && c + k < world_spheres.size(); ++k)
      deepest = std::max(deepest, double(s[k].w()) - std::sqrt(d2[k]));
  }
  return deepest;
}

// "A vertex farther than 10 L-bar from the head" reads "from the head" as from the head
// body, which carries the roots: every root lies within head_extent of the head centre, so
// a vertex more than head_extent + 10 L-bar from the centre is farther than 10 L-bar from
// every point of the head. (A bare distance from the centre would call a groom diverged at
// rest whose roots span more than 10 strand lengths: TestHair1's 11 cm strands sit up to
// 1.06 m from its centre.) Stretched edges are not a blow-up: the `stretched` verdict
// measures them (reports/verdict.h) and the run goes on.
METRIC_CLONES std::string blowup_reason(const RestInfo& rest, std::span<const Vec4f> p, const Vec3f& head_center) {
  const Groom& g = *rest.groom;
  const double far = blowup_distance(rest);
  const Eigen::Vector3d c = head_center.cast<double>();
  // A screen first, without branches so that it vectorises: squared distances against a
  // bound a little inside the test's (0.98 far^2 against far^2), where NaN and Inf fail
  // every comparison. Only if it flags a vertex do the strands take the exact tests one by
  // one, in order, so the first failure reported is the same. The square roots and
  // branches per vertex would be most of this function's cost, which `compare` pays per
  // model and frame.
  constexpr double kNear = 0.98;
  const double near2 = kNear * far * far;
  const Vec4f centre(head_center.x(), head_center.y(), head_center.z(), 0.0f);
  int any = 0;
  chunked(
      0, p.size(),
      [&](std::size_t i) {
        return int{!(distance2(p[i], centre) <= near2)} | int{!(p[i].w() * 0.0f == 0.0f)};  // w: NaN, Inf
      },
      [&](int flag) { any |= flag; });
  if (!any) return {};
  for (std::size_t s = 0; s < g.strand_count(); ++s) {
    const std::size_t b = g.strand_begin(s), n = g.strand_size(s);
    for (std::size_t i = b; i < b + n; ++i) {
      if (!p[i].allFinite())
        return "non-finite position (strand " + std::to_string(s) + ", vertex " + std::to_string(i - b) + ")";
      if ((xyz(p[i]) - c).norm() > far)
        return "vertex farther than 10 mean strand lengths from the head (strand " + std::to_string(s) + ")";
    }
  }
  return {};
}

double blowup_distance(const RestInfo& rest) { return rest.head_extent + 10.0 * rest.mean_strand_length; }

// Each vertex's 0.5 |v|^2 - g.p as Eigen's Vector3d expressions compute it, written out
// in their order ((x^2 + y^2) + z^2, (gx px + gy py) + gz pz) so that the terms vectorise;
// added in vertex order: the same bits.
METRIC_CLONES double mechanical_energy(std::span<const Vec4f> p, std::span<const Vec4f> prev, double dt,
                                       const Vec3f& gravity) {
  if (p.empty()) return 0.0;
  const double gx = gravity.x(), gy = gravity.y(), gz = gravity.z();
  double e = 0.0;
  chunked(
      0, p.size(),
      [&](std::size_t i) {
        const double px = double(p[i].x()), py = double(p[i].y()), pz = double(p[i].z());
        const double vx = (px - double(prev[i].x())) / dt, vy = (py - double(prev[i].y())) / dt,
                     vz = (pz - double(prev[i].z())) / dt;
        return 0.5 * ((vx * vx + vy * vy) + vz * vz) - ((gx * px + gy * py) + gz * pz);
      },
      [&](double term) { e += term; });
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
