#include "models/plante2001/wisp_model.h"

#include "core/parallel.h"
#include "models/plante2001/settings.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <map>
#include <numbers>

namespace hairbench::plante {

namespace k = hairbench::kernels;

WispModel::WispModel(const ModelContext& ctx) : ctx_(ctx) {}

namespace {

Vec3f xyz(const Vec4f& v) { return v.head<3>(); }

// Squared distance between a rest strand and a cluster centre of equal vertex count:
// the root weighs as much as the rest of the strand together, so wisps stay compact at
// the scalp, where the strands are pinned and the rebuild cannot bend them apart.
// The terms are never negative, so the partial sums only grow: once one exceeds `bound`
// the strand is farther than that, and the sum so far is returned.
float strand_distance2(const Groom& g, std::uint32_t s, const std::vector<Vec3f>& centre, std::size_t j, std::size_t n,
                       float bound) {
  const std::uint32_t b = g.strand_begin(s);
  float d = static_cast<float>(n) * (xyz(g.positions[b]) - centre[j * n]).squaredNorm();
  for (std::size_t i = 1; i < n && !(d > bound); ++i) d += (xyz(g.positions[b + i]) - centre[j * n + i]).squaredNorm();
  return d;
}

// The nearest centre to strand s: the first of equal distances in centre order, as a
// scan of all centres in order finds. `by_x` holds the centres sorted by their root's x
// (root_x ascending): the scan starts at the strand's own root x and walks outwards,
// and stops on each side where n dx^2 alone (a lower bound of the distance, less a
// margin far above rounding) exceeds the best found. `guess` (the last round's centre)
// sets the first bound.
std::uint32_t nearest_centre(const Groom& g, std::uint32_t s, const std::vector<Vec3f>& centre, std::size_t n,
                             const std::vector<std::uint32_t>& by_x, const std::vector<float>& root_x,
                             std::uint32_t guess) {
  std::uint32_t best_j = guess;
  float best = strand_distance2(g, s, centre, guess, n, std::numeric_limits<float>::infinity());
  auto visit = [&](std::uint32_t j) {
    const float d = strand_distance2(g, s, centre, j, n, best);
    if (d < best || (d == best && j < best_j)) {
      best = d;
      best_j = j;
    }
  };
  const float x = g.positions[g.strand_begin(s)].x();
  const float weight = 0.999f * static_cast<float>(n);
  auto far = [&](std::size_t at) {
    const float dx = root_x[at] - x;
    return weight * dx * dx > best;
  };
  const std::size_t mid = static_cast<std::size_t>(std::lower_bound(root_x.begin(), root_x.end(), x) - root_x.begin());
  for (std::size_t at = mid; at < by_x.size() && !far(at); ++at) visit(by_x[at]);
  for (std::size_t at = mid; at-- > 0 && !far(at);) visit(by_x[at]);
  return best_j;
}

// k-means with a fixed start (every (size/k)-th strand of the group) and a fixed number
// of rounds: the same groom always gives the same wisps. Strands are compared over all
// their rest vertices, not the root alone: near the crown, neighbouring roots comb
// apart in every direction, and a wisp must hold strands that stay together (§3.1:
// "neighboring hair strands of similar orientations"). Elsewhere the root dominates.
// Each strand's nearest centre is found on its own (over the threads, the same labels
// for any thread count); the centres are then summed in strand order.
std::vector<std::vector<std::uint32_t>> kmeans_strands(const Groom& g, const std::vector<std::uint32_t>& strands,
                                                       std::size_t k, ThreadPool* pool) {
  const std::size_t count = strands.size();
  const std::size_t n = g.strand_size(strands[0]);
  k = std::clamp<std::size_t>(k, 1, count);
  std::vector<Vec3f> centre(k * n);
  for (std::size_t j = 0; j < k; ++j) {
    const std::uint32_t b = g.strand_begin(strands[(2 * j + 1) * count / (2 * k)]);
    for (std::size_t i = 0; i < n; ++i) centre[j * n + i] = xyz(g.positions[b + i]);
  }
  std::vector<std::uint32_t> label(count, 0);
  std::vector<Vec3f> sum(k * n);
  std::vector<int> size(k);
  std::vector<std::uint32_t> by_x(k);
  std::vector<float> root_x(k);
  auto assign = [&](std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i) label[i] = nearest_centre(g, strands[i], centre, n, by_x, root_x, label[i]);
  };
  constexpr int kRounds = 12;
  constexpr std::size_t kThreadsMinStrands = 1024;  // fewer: a hand-off costs more than the work
  for (int round = 0; round < kRounds; ++round) {
    for (std::uint32_t j = 0; j < k; ++j) by_x[j] = j;
    std::sort(by_x.begin(), by_x.end(), [&](std::uint32_t a, std::uint32_t b) {
      return std::pair{centre[a * n].x(), a} < std::pair{centre[b * n].x(), b};
    });
    for (std::size_t at = 0; at < k; ++at) root_x[at] = centre[by_x[at] * n].x();
    if (pool && count >= kThreadsMinStrands)
      pool->parallel_for(count, assign);
    else
      assign(0, count);
    std::fill(sum.begin(), sum.end(), Vec3f::Zero());
    std::fill(size.begin(), size.end(), 0);
    for (std::size_t i = 0; i < count; ++i) {
      const std::uint32_t b = g.strand_begin(strands[i]);
      for (std::size_t v = 0; v < n; ++v) sum[label[i] * n + v] += xyz(g.positions[b + v]);
      ++size[label[i]];
    }
    for (std::size_t j = 0; j < k; ++j)
      if (size[j] > 0)
        for (std::size_t v = 0; v < n; ++v) centre[j * n + v] = sum[j * n + v] / static_cast<float>(size[j]);
  }
  std::vector<std::vector<std::uint32_t>> out(k);
  for (std::size_t i = 0; i < count; ++i) out[label[i]].push_back(strands[i]);
  std::erase_if(out, [](const auto& c) { return c.empty(); });
  return out;
}

// The widest rest bends a skeleton keeps (skeleton_of), radians: at its free nodes,
// and at a pinned node next to a free segment.
constexpr float kMaxRestBend = 0.7854f;    // 45 degrees
constexpr float kMaxAnchorBend = 2.3562f;  // 135 degrees

// The average of the polyline p (vertex i at parameter at[i]) over the parameters [a, b]
// within vertices [first, last]; the point at a where the interval is empty.
Vec3f average(const std::vector<Vec3f>& p, const std::vector<double>& at, std::uint32_t first, std::uint32_t last,
              double a, double b) {
  auto point = [&](std::uint32_t v, double t) {
    const double len = at[v + 1] - at[v];
    const double u = len > 0.0 ? (t - at[v]) / len : 0.0;
    return Eigen::Vector3d(p[v].cast<double>() + u * (p[v + 1] - p[v]).cast<double>());
  };
  if (!(b > a)) {
    std::uint32_t v = first;
    while (v + 1 < last && at[v + 1] < a) ++v;
    return point(v, a).cast<float>();
  }
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (std::uint32_t v = first; v < last; ++v) {
    const double x0 = std::max(a, at[v]), x1 = std::min(b, at[v + 1]);
    if (x1 > x0) sum += (x1 - x0) * point(v, 0.5 * (x0 + x1));
  }
  return (sum / (b - a)).cast<float>();
}

// A wisp's skeleton at rest (§3.2): point masses along the axis of its strands, with a
// resolution of its own. Every parameter below is an arc length along that axis, a curve
// with a point per strand vertex index (the wisp's strands share it by index).
struct Skeleton {
  std::vector<Vec3f> x;              // node rest positions
  std::vector<std::uint8_t> pinned;  // per node
  std::vector<double> at;            // per node, its parameter
  std::vector<double> vertex_at;     // per strand vertex index, its parameter
  // Per strand vertex index: the node whose section it lies in, and the fraction of the
  // way to the next node (kernels::strand_coord's sfrac, >= 0).
  std::vector<std::uint32_t> vertex_node;
  std::vector<float> vertex_u;
  // Per segment (node j, j + 1): its hair, the length of the wisp's strands whose
  // parameters fall in it, strand-metres.
  std::vector<double> hair;
  float widest = 0.0f;      // the strands' widest distance from the axis, metres
  double free_length = 0.0;  // length of the axis the free nodes span, metres
  int segments = 0;          // free segments
  // The widest rest bend at a free node, and at a pinned node next to a free segment,
  // radians.
  float bend = 0.0f, anchor_bend = 0.0f;
  // How far past its bounds the skeleton bends (<= 1: within them).
  float excess() const { return std::max(bend / kMaxRestBend, anchor_bend / kMaxAnchorBend); }
};

// The skeleton of cluster c (strands of one vertex count). Pinned vertices of the mean
// curve (all the strands pinned there) that start or end a pinned run become pinned
// nodes: the first segment lies inside the head (§3.2), and a run pinned whole moves
// with it. Each stretch of free vertices, from the pinned node before it to the pinned
// node after it or to the tip, is cut into segments of equal length along the wisp's
// axis: `segments` in all (0: the axis's free length over the wisp's width,
// 2 max(widest, r_min), rounded and clamped to 4-10, the paper's wisps having segments
// "mostly as wide as they are long" (§4.1, footnote 1) and 4.0-9.9 segments each
// (§5.3), finer where the style folds, below), never more than the strands' own free
// edges, shared between stretches by length.
//
// The skeleton keeps its rest bends within kMaxRestBend at its free nodes and
// kMaxAnchorBend at a pinned node next to a free segment. A skeleton laid along a curly
// groom's curls diverges at rest (PlanteWisp.CurlyGroomStaysOkAtRest without the
// bounds): near a half turn the frames carried by minimal rotation turn over, and the
// bending springs' twist loads grow as the curvature binormal, 2 tan(bend / 2)
// (kernels::bishop_bending; the skeleton is the same for either law, so that they
// compare on one skeleton); next to a pinned node the section frame bisects the
// head's segment and the first free one, and turns over as they fold back onto each
// other. Where the mean curve
// bends more at the nodes of the width's resolution, the skeleton is first made finer,
// up to the strands' own edges (a fold of the style); where that is not enough, its
// axis is the mean curve averaged over the shortest window, in whole mean edges, that
// is (curls and waves: the paper's skeleton carries a wisp's large-scale shape and its
// strands the waves, §5.2, which become their offsets in the sections). Failing both,
// the candidate that bends least past the bounds. Lengths along the axis, not along the
// mean curve, keep the segments equal where curls are averaged away; a segment's hair
// is then the more, the more the strands curl along it.
Skeleton skeleton_of(const Groom& g, const std::vector<std::uint32_t>& c, int segments, float r_min) {
  const std::uint32_t n = g.strand_size(c[0]);
  std::vector<Vec3f> mean(n, Vec3f::Zero());
  std::vector<std::uint8_t> pinned(n, 1);
  for (std::uint32_t i = 0; i < n; ++i) {
    for (std::uint32_t s : c) {
      const Vec4f& p = g.positions[g.strand_begin(s) + i];
      mean[i] += xyz(p);
      pinned[i] = pinned[i] && p.w() == 0.0f;
    }
    mean[i] /= static_cast<float>(c.size());
  }
  std::vector<double> at(n, 0.0);
  for (std::uint32_t i = 1; i < n; ++i) at[i] = at[i - 1] + static_cast<double>((mean[i] - mean[i - 1]).norm());
  // The free stretches [first, last] of vertex indices, their ends the pinned neighbours.
  std::vector<std::pair<std::uint32_t, std::uint32_t>> stretches;
  std::uint32_t free_edges = 0;
  double mean_length = 0.0, longest = 0.0;
  for (std::uint32_t i = 0; i < n;) {
    if (pinned[i]) {
      ++i;
      continue;
    }
    std::uint32_t j = i;
    while (j + 1 < n && !pinned[j + 1]) ++j;
    const std::uint32_t first = i > 0 ? i - 1 : i, last = j + 1 < n ? j + 1 : j;
    stretches.emplace_back(first, last);
    mean_length += at[last] - at[first];
    longest = std::max(longest, at[last] - at[first]);
    free_edges += last - first;
    i = j + 1;
  }
  // The mean curve averaged over `window` (twice, a triangle filter: a wave whose period
  // is about the window is gone), free vertices only, each stretch on its own, the
  // window cut off at the stretch's ends (narrowed to stay centred there, it would leave
  // the axis on the curls next to the root and the tip).
  auto smooth = [&](double window) {
    std::vector<Vec3f> axis = mean;
    for (int pass = 0; pass < 2; ++pass) {
      const std::vector<Vec3f> from = axis;
      for (const auto& [first, last] : stretches)
        for (std::uint32_t i = first; i <= last; ++i) {
          if (pinned[i]) continue;
          axis[i] = average(from, at, first, last, std::max(at[first], at[i] - 0.5 * window),
                            std::min(at[last], at[i] + 0.5 * window));
        }
    }
    return axis;
  };
  auto build = [&](const std::vector<Vec3f>& axis, int finer) {
    Skeleton sk;
    for (std::uint32_t i = 0; i < n; ++i)
      for (std::uint32_t s : c)
        sk.widest = std::max(sk.widest, (xyz(g.positions[g.strand_begin(s) + i]) - axis[i]).norm());
    std::vector<double>& along = sk.vertex_at;
    along.assign(n, 0.0);
    for (std::uint32_t i = 1; i < n; ++i) along[i] = along[i - 1] + static_cast<double>((axis[i] - axis[i - 1]).norm());
    for (const auto& [first, last] : stretches) sk.free_length += along[last] - along[first];
    if (free_edges > 0) {
      const double width = 2.0 * std::max(sk.widest, r_min);
      sk.segments = segments > 0 ? segments
                                 : std::clamp(static_cast<int>(std::lround(sk.free_length / width)), kMinSegments,
                                              kMaxSegments);
      sk.segments = std::min(sk.segments + finer, static_cast<int>(free_edges));
    }
    auto add = [&](double t, const Vec3f& p, bool pin) {
      sk.x.push_back(p);
      sk.pinned.push_back(pin ? 1 : 0);
      sk.at.push_back(t);
    };
    std::size_t next = 0;  // stretches, in order
    for (std::uint32_t i = 0; i < n; ++i) {
      if (pinned[i]) {
        if (i == 0 || !pinned[i - 1] || i + 1 == n || !pinned[i + 1]) add(along[i], axis[i], true);
        continue;
      }
      const auto [first, last] = stretches[next++];
      if (first == i) add(along[i], axis[i], false);  // no pinned node before it
      const double length = along[last] - along[first];
      const int parts = std::clamp(static_cast<int>(std::lround(sk.segments * length / sk.free_length)), 1,
                                   static_cast<int>(last - first));
      for (int j = 1; j < parts; ++j) {
        const double t = along[first] + length * j / parts;
        add(t, average(axis, along, first, last, t, t), false);
      }
      if (!pinned[last]) add(along[last], axis[last], false);  // the free tip
      i = pinned[last] ? last - 1 : last;
    }
    for (std::size_t j = 1; j + 1 < sk.x.size(); ++j) {
      if (sk.pinned[j - 1] && sk.pinned[j] && sk.pinned[j + 1]) continue;  // the head's own
      const Vec3f a = sk.x[j] - sk.x[j - 1], b = sk.x[j + 1] - sk.x[j];
      float& widest = sk.pinned[j] ? sk.anchor_bend : sk.bend;
      widest = std::max(widest, std::atan2(a.cross(b).norm(), a.dot(b)));
    }
    return sk;
  };
  const double edge = free_edges > 0 ? mean_length / free_edges : 0.0;
  Skeleton sk = build(mean, 0);
  auto consider = [&](Skeleton other) {
    if (other.excess() < sk.excess()) sk = std::move(other);
  };
  for (int finer = 1; sk.excess() > 1.0f && segments == 0 && finer < static_cast<int>(free_edges); ++finer)
    consider(build(mean, finer));
  for (std::uint32_t m = 1; sk.excess() > 1.0f && m * edge < longest; ++m) consider(build(smooth(m * edge), 0));

  // Each strand vertex in the section through the point of the skeleton nearest its
  // mean vertex, of the segments next to the one at its parameter along the axis: its
  // offset then lies about in that section's plane. (At its axis parameter itself, a
  // vertex near the root of a wisp whose axis was averaged lay up to half a window
  // behind its section, along the section's normal, an offset that the section's turns
  // swung into the strand's first edges.)
  const std::size_t nodes = sk.x.size();
  std::vector<double> param(n, 0.0);
  sk.vertex_node.assign(n, 0);
  sk.vertex_u.assign(n, 0.0f);
  for (std::uint32_t i = 0; i < n && nodes > 1; ++i) {
    const auto above = std::upper_bound(sk.at.begin(), sk.at.end(), sk.vertex_at[i]) - sk.at.begin();
    const std::size_t guess = std::min<std::size_t>(above > 0 ? static_cast<std::size_t>(above - 1) : 0, nodes - 2);
    const Eigen::Vector3d p = mean[i].cast<double>();
    std::size_t best_j = guess;
    double best_u = 0.0, best = std::numeric_limits<double>::infinity();
    for (std::size_t j = guess > 0 ? guess - 1 : 0; j <= guess + 1 && j + 1 < nodes; ++j) {
      const Eigen::Vector3d x0 = sk.x[j].cast<double>(), d = (sk.x[j + 1] - sk.x[j]).cast<double>();
      const double len2 = d.squaredNorm();
      const double u = len2 > 0.0 ? std::clamp((p - x0).dot(d) / len2, 0.0, 1.0) : 0.0;
      const double dist = (p - (x0 + u * d)).squaredNorm();
      if (dist < best) {
        best = dist;
        best_j = j;
        best_u = u;
      }
    }
    if (best_u >= 1.0) {  // node j + 1 itself
      ++best_j;
      best_u = 0.0;
    }
    param[i] = sk.at[best_j] + (best_j + 1 < nodes ? best_u * (sk.at[best_j + 1] - sk.at[best_j]) : 0.0);
    sk.vertex_node[i] = static_cast<std::uint32_t>(best_j);
    sk.vertex_u[i] = static_cast<float>(best_u);
  }
  // The strands' hair, edge by edge, shared between the segments by parameter.
  sk.hair.assign(nodes > 0 ? nodes - 1 : 0, 0.0);
  for (std::uint32_t i = 1; i < n && nodes > 1; ++i) {
    double hair = 0.0;
    for (std::uint32_t s : c) {
      const std::uint32_t b = g.strand_begin(s);
      hair += static_cast<double>((xyz(g.positions[b + i]) - xyz(g.positions[b + i - 1])).norm());
    }
    const double t0 = std::min(param[i - 1], param[i]), t1 = std::max(param[i - 1], param[i]);
    if (!(t1 > t0)) {
      sk.hair[std::min<std::size_t>(sk.vertex_node[i], sk.hair.size() - 1)] += hair;
      continue;
    }
    for (std::size_t j = 0; j < sk.hair.size(); ++j) {
      const double overlap = std::min(t1, sk.at[j + 1]) - std::max(t0, sk.at[j]);
      if (overlap > 0.0) sk.hair[j] += hair * overlap / (t1 - t0);
    }
  }
  return sk;
}

}  // namespace

void WispModel::cluster(const Groom& rest, int wisps, int strands_per_wisp, int segments, int root_blend,
                              float width_max, float r_min) {
  // Wisps only gather strands of one region (they share its parameters) and of one
  // vertex count (their vertices share the mean curve the skeleton is laid along).
  std::map<std::pair<std::uint16_t, std::uint32_t>, std::vector<std::uint32_t>> groups;
  for (std::size_t s = 0; s < rest.strand_count(); ++s)
    groups[{rest.strand_region[s], rest.strand_size(s)}].push_back(static_cast<std::uint32_t>(s));
  const double total = static_cast<double>(rest.strand_count());
  sys_ = {};
  strand_wisp_.assign(rest.strand_count(), 0);
  std::vector<Skeleton> skeletons;
  for (const auto& [key, strands] : groups) {
    const double share = static_cast<double>(strands.size());
    const double want = wisps > 0 ? wisps * share / total : share / strands_per_wisp;
    // A wisp's strands keep fixed offsets in its sections (§5.2), interpolated along each
    // segment, so a change of bend phi at a node turns the sections of the segments
    // beside it by up to phi/2 over a segment's length: a strand at radius r from the
    // skeleton stretches by about r phi / (2 segment length). Wisps wider than
    // `width_max` segments (the strands' widest distance from their axis) are split in
    // two until none is; the paper's wisps are "mostly as wide as they are
    // long" (§4.1, footnote 1), i.e. r up to half a segment.
    std::vector<std::vector<std::uint32_t>> todo =
        kmeans_strands(rest, strands, static_cast<std::size_t>(std::max(1.0, std::round(want))), ctx_.pool);
    std::vector<std::pair<std::vector<std::uint32_t>, Skeleton>> clusters;
    while (!todo.empty()) {
      std::vector<std::uint32_t> c = std::move(todo.back());
      todo.pop_back();
      Skeleton sk = skeleton_of(rest, c, segments, r_min);
      auto halves = c.size() > 1 && sk.segments > 0 && sk.widest > width_max * sk.free_length / sk.segments
                        ? kmeans_strands(rest, c, 2, ctx_.pool)
                        : std::vector<std::vector<std::uint32_t>>{};
      if (halves.size() == 2) {
        for (auto& half : halves) todo.push_back(std::move(half));
      } else {
        clusters.emplace_back(std::move(c), std::move(sk));  // narrow enough, or strands k-means cannot part
      }
    }
    // Wisps of one node count next to each other, so that the fused schedule's blocks
    // (one node count each) take as many of them as it can.
    std::sort(clusters.begin(), clusters.end(), [](const auto& a, const auto& b) {
      return std::pair{a.second.x.size(), a.first.front()} < std::pair{b.second.x.size(), b.first.front()};
    });
    for (auto& [c, sk] : clusters) {
      const auto w = static_cast<std::uint32_t>(skeletons.size());
      for (std::uint32_t s : c) strand_wisp_[s] = w;
      const auto first = static_cast<std::uint32_t>(sys_.rest_x.size());
      for (std::size_t j = 0; j < sk.x.size(); ++j) {
        sys_.rest_x.push_back(sk.x[j]);
        sys_.pinned.push_back(sk.pinned[j]);
        sys_.seg_mass.push_back(j > 0 ? static_cast<float>(sk.hair[j - 1]) : 0.0f);
      }
      sys_.node_begin.push_back(first + static_cast<std::uint32_t>(sk.x.size()));
      sys_.wisp_params.push_back(key.first);
      skeletons.push_back(std::move(sk));
    }
  }
  sys_.r_rest.assign(sys_.rest_x.size(), 0.0f);
  sys_.resize_state();
  for (std::size_t w = 0; w < sys_.wisp_count(); ++w) k::wisp_init_rest(sys_, w, root_blend);

  // §3.4/§5.2: each strand vertex gets fixed coordinates in its wisp's section through
  // its skeleton point (skeleton_of; kernels::strand_coord). A section's rest radius is
  // the circle holding every strand point interpolated from it (§5.2: points "in a
  // circle"), so strands start inside.
  coord_.assign(rest.vertex_count(), Vec4f::Zero());
  vertex_node_.assign(rest.vertex_count(), 0);
  for (std::size_t s = 0; s < rest.strand_count(); ++s) {
    const std::uint32_t w = strand_wisp_[s];
    const Skeleton& sk = skeletons[w];
    for (std::uint32_t i = 0; i < rest.strand_size(s); ++i) {
      const std::uint32_t v = rest.strand_begin(s) + i, node = sys_.node_begin[w] + sk.vertex_node[i];
      const Vec4f c = k::strand_coord(sys_, node, sk.vertex_u[i], xyz(rest.positions[v]), Eigen::Matrix3f::Identity());
      coord_[v] = c;
      vertex_node_[v] = node;
      const float radius = std::hypot(c.y(), c.z());
      sys_.r_rest[node] = std::max(sys_.r_rest[node], radius);
      if (c.x() != 0.0f) sys_.r_rest[node + 1] = std::max(sys_.r_rest[node + 1], radius);
    }
  }
}

void WispModel::reset(const Groom& rest, const ParamSet& params) {
  rest_ = rest;
  sleep_.reset(1);
  params_.clear();
  for (std::size_t r = 0; r < rest.region_names.size(); ++r) {
    k::WispParams p;
    auto f = [&](const char* name) { return static_cast<float>(params.get(name, r)); };
    p.air_drag = f("air_drag");
    p.axial_stiffness = f("axial_stiffness");
    p.axial_damping = f("axial_damping");
    p.bending_stiffness = f("bending_stiffness");
    p.bending_damping = f("bending_damping");
    p.bending = params.get_int("bending", r) == 0 ? k::BendingLaw::kPaper : k::BendingLaw::kBishop;
    p.envelope_mass = f("envelope_mass");
    p.radial_stiffness = f("radial_stiffness");
    p.radial_stretch = f("radial_stretch");
    p.radial_damping = f("radial_damping");
    p.ring_stiffness = f("ring_stiffness");
    p.ring_damping = f("ring_damping");
    params_.push_back(p);
  }
  const double deg = std::numbers::pi / 180.0;
  interaction_.contact_threshold = static_cast<float>(params.get("contact_threshold"));
  interaction_.body_friction = static_cast<float>(params.get("body_friction"));
  interaction_.hair_friction = static_cast<float>(params.get("hair_friction"));
  interaction_.parallel_cos = static_cast<float>(std::cos(params.get("parallel_angle") * deg));
  interaction_.in_plane_sin = static_cast<float>(std::sin(params.get("in_plane_angle") * deg));
  integration_hz_ = params.get("integration_hz");
  collision_hz_ = params.get("collision_hz");
  interaction_hz_ = params.get("interaction_hz");
  threads_min_wisps_ = params.get_int("threads_min_wisps");

  const float r_min = static_cast<float>(params.get("wisp_radius_min"));
  cluster(rest, params.get_int("wisps"), params.get_int("strands_per_wisp"), params.get_int("skeleton_segments"),
          params.get_int("root_blend"), static_cast<float>(params.get("wisp_width_max")), r_min);
  for (float& r : sys_.r_rest) r = std::max(r, r_min);
  for (std::size_t i = 0; i < sys_.r.size(); ++i) sys_.r[i] = sys_.r_rest[i / k::kEnvelopePerSection];
  const std::size_t threads = ctx_.pool ? static_cast<std::size_t>(ctx_.pool->threads()) : 1;
  chunk_contacts_.assign(threads == 1 ? 1 : kChunksPerThread * threads, {});
  threads_ = threads;
  contacts_.clear();
  contacts_known_ = false;
  pos_ = rest.positions;
  strand_points_.assign(pos_.size(), Vec3f::Zero());
  strand_weights_.assign(pos_.size(), 0.0f);
  prepare(threads);
  set_skeletons(rest);
  rebuild(Affine3f::Identity());
}

void WispModel::set_skeletons(const Groom& rest) {
  skeletons_ = Groom{};
  skeletons_.region_names = rest.region_names;
  skeletons_.head_radius = rest.head_radius;
  for (std::size_t w = 0; w < sys_.wisp_count(); ++w) {
    for (std::uint32_t i = sys_.node_begin[w]; i < sys_.node_begin[w + 1]; ++i) {
      const Vec3f& p = sys_.rest_x[i];
      skeletons_.positions.emplace_back(p.x(), p.y(), p.z(), sys_.pinned[i] ? 0.0f : 1.0f / sys_.mass[i]);
    }
    skeletons_.strand_offsets.push_back(static_cast<std::uint32_t>(skeletons_.positions.size()));
    skeletons_.strand_region.push_back(sys_.wisp_params[w]);
  }
  skeleton_pos_ = skeletons_.positions;
}

bool WispModel::start_from(std::span<const Vec4f> positions) {
  start_positions(positions, skeleton_pos_);
  for (std::size_t i = 0; i < sys_.x.size(); ++i) {
    if (!sys_.pinned[i]) sys_.x[i] = skeleton_pos_[i].head<3>();
    sys_.v[i].setZero();
  }
  for (std::size_t i = 0; i < sys_.r.size(); ++i) sys_.r[i] = sys_.r_rest[i / k::kEnvelopePerSection];
  std::fill(sys_.rdot.begin(), sys_.rdot.end(), 0.0f);
  for (std::size_t w = 0; w < sys_.wisp_count(); ++w) k::wisp_frames(sys_, w, sys_.rest_e1[w]);
  rebuild(Affine3f::Identity());
  return true;
}


std::size_t WispModel::state_bytes() const {
  auto bytes = [](const auto& v) { return v.size() * sizeof(v[0]); };
  return bytes(sys_.x) + bytes(sys_.v) + bytes(sys_.acc) + bytes(sys_.e1) + bytes(sys_.e2) + bytes(sys_.n) +
         bytes(sys_.r) + bytes(sys_.rdot) + bytes(sys_.racc) + bytes(pos_);
}

void WispModel::detect_self_interactions() {
  const std::size_t chunks = chunk_contacts_.size(), threads = threads_;
  k::grid_segments(grid_, sys_);
  const std::size_t n = grid_.size();
  for_each(n, [&](std::size_t begin, std::size_t end) { k::grid_setup(grid_, sys_, begin, end); });
  build_cells(threads);
  // Chunks of about equal candidates (grid_split), several per thread, claimed as the
  // threads come free: a chunk's cost also depends on how many of its candidates are
  // contacts, which no count ahead of the test knows (with one chunk of equal candidates
  // per thread, one thread would take markedly longer than the other on model 1).
  k::grid_split(grid_, chunks, chunk_bounds_);
  std::atomic<std::size_t> next{0};
  auto run = [&](std::size_t tb, std::size_t te) {
    for (std::size_t t = tb; t < te; ++t) {
      begin_narrow_phase(t, n);
      for (std::size_t c; (c = next.fetch_add(1, std::memory_order_relaxed)) < chunks;) {
        chunk_contacts_[c].clear();
        narrow_phase(t, chunk_bounds_[c], chunk_bounds_[c + 1], chunk_contacts_[c]);
      }
    }
  };
  for_each(threads, run);
  // Chunks are contiguous ranges of segments: concatenated in order they are the serial
  // list, whatever the thread count, the bounds and which thread ran which chunk. The
  // chunks are copied over the threads (model 1: 6.9 M contacts, 110 MB, per detection).
  chunk_offset_.assign(chunks + 1, 0);
  for (std::size_t c = 0; c < chunks; ++c) chunk_offset_[c + 1] = chunk_offset_[c] + chunk_contacts_[c].size();
  contacts_.resize(chunk_offset_[chunks]);
  auto copy = [&](std::size_t cb, std::size_t ce) {
    for (std::size_t c = cb; c < ce; ++c)
      std::copy(chunk_contacts_[c].begin(), chunk_contacts_[c].end(),
                contacts_.begin() + static_cast<std::ptrdiff_t>(chunk_offset_[c]));
  };
  for_each(chunks, copy);
}

// §5.1, once per integration step: (1) forces, (2) interaction detection at its rate,
// (3) velocities then their modifications, (4) positions then their modifications;
// skeleton before envelope, root to tip (inside the kernels).
void WispModel::step(const FrameInput& in, StageTimes& times) {
  const bool calm = sleep_.begin_step(in, ctx_.skip_inert);
  if (calm && sleep_.all_asleep()) {
    for (Stage stage : {Stage::Integrate, Stage::BodyCollision, Stage::SelfInteraction, Stage::Rebuild}) times.skip(stage);
    return;
  }
  // Without colliders there is no body pass at all, and the report says so;
  // --no-skip runs the pass over no spheres.
  const bool body_pass = !in.colliders.empty() || !ctx_.skip_inert;
  if (!body_pass) times.skip(Stage::BodyCollision);
  const int steps = std::max(1, static_cast<int>(std::ceil(in.dt * integration_hz_ - 1e-9)));
  const float h = static_cast<float>(in.dt / steps);
  const double t0 = in.t - in.dt;
  auto crosses = [&](double rate, int i) {
    // The epsilon keeps a period boundary that falls on a step's end (in exact
    // arithmetic) on that step despite rounding.
    constexpr double kEps = 1e-9;
    return rate > 0.0 && std::floor((t0 + i * (in.dt / steps)) * rate + kEps) >
                             std::floor((t0 + (i - 1) * (in.dt / steps)) * rate + kEps);
  };
  Affine3f head_before = in.head_prev;
  for (int i = 1; i <= steps; ++i) {
    const Affine3f head = interpolate_head(in.head_prev, in.head, static_cast<float>(i) / static_cast<float>(steps));
    const Eigen::Matrix3f head_rot = head.linear();
    // Bodies (§4.2): a mass the last detection found within the contact threshold is in
    // sliding contact until the next detection, so the modification (approach removed,
    // tangential slip dragged) applies on every integration step in between, not only on
    // the detecting one. Applied once per detection, the masses would sink into the body
    // again between detections under gravity and their springs, and the penetration
    // reaction throw them back out: on `idle` the position jumps would re-load the stiff
    // axial springs 120 times a second and hold the hair in a 0.4 m/s jitter that never
    // settles.
    const bool body_on = collision_hz_ > 0.0 && body_pass;
    // Also on the first step after reset: the sliding contacts above hold until the next
    // detection, and a groom that starts inside a body would otherwise sink into it for
    // a whole period before its first detection (the stress test's `inside_collider`:
    // the wisps would wrap round the sphere from 8 ms deep, rebuilt strands 55% long).
    const bool body_due = body_on && (crosses(collision_hz_, i) || i == steps || !contacts_known_);
    contacts_known_ = contacts_known_ || body_due;
    k::BodyStep body;
    if (body_on) {
      spheres_.clear();
      sphere_moves_.clear();
      for (const Sphere& c : in.colliders) {
        const Vec3f centre = collider_center(c, head);
        spheres_.emplace_back(centre.x(), centre.y(), centre.z(), c.radius);
        sphere_moves_.push_back(c.head_attached ? 1 : 0);
      }
      body.spheres = spheres_;
      body.moves = sphere_moves_;
      body.motion = head * head_before.inverse();
      body.h = h;
    }
    // Viscous friction over this step.
    const float drag = std::min(1.0f, interaction_.body_friction * h);
    // (2) + (3): wisp-wisp contacts are detected and responded to at the interaction
    // rate; the drag they apply stands for the whole period (§4.1 "proportional to ...
    // the time step"). After the bodies' modifications: a mass pressed against the head
    // carries, after the force update, the step's worth of velocity into it (a h) that
    // the sliding contact removes; seen by this response, it would be handed on to the
    // wisps touching that mass, and keep those on `idle` moving at up to 2 cm/s, 24 times
    // a second.
    const bool interact = crosses(interaction_hz_, i);
    const StepInput s{in, head, head_rot, h, body, drag, body_on, body_due, interact};
    integrate(s, times);
    head_before = head;
  }
  {
    StageTimer t(times, Stage::Rebuild);
    rebuild(in.head);
  }
  if (calm) {
    // The fastest skeleton mass or envelope mass (along its half-line) decides.
    float speed2 = 0.0f;
    for (const Vec3f& v : sys_.v) speed2 = std::max(speed2, v.squaredNorm());
    for (float rd : sys_.rdot) speed2 = std::max(speed2, rd * rd);
    sleep_.observe_speed(0, std::sqrt(speed2));
    sleep_.end_observe();
  }
}

// §5.2: the strands are drawn at fixed positions relative to the wisp envelope: the
// section's origin is the skeleton, its axes and scale factors come from the four
// envelope masses (kernels::strand_point).
//
// A strand's pinned vertices follow the head, but their section points need not: a
// vertex pinned where its wisp's skeleton is free (its wisp's other strands are not
// pinned there), or lying off its wisp's pinned segment, has its section point turn with
// the wisp's first free segment while the vertex does not, and, left alone, the first
// free edge would change length by up to the gap times that angle.
// The gap between the last pinned vertex and its section point (`anchor`) is carried
// by the free vertices, fading with the section weight that already blends the axes
// near the root (root_blend), so the strand stays attached to its root.
void WispModel::rebuild(const Affine3f& head) {
  for (std::size_t i = 0; i < sys_.x.size(); ++i) skeleton_pos_[i].head<3>() = sys_.x[i];
  const Eigen::Matrix3f head_rot = head.linear();
  prepare_sections(head_rot);
  auto body = [&](std::size_t begin, std::size_t end) {
    for (std::size_t s = begin; s < end; ++s) {
      const std::uint32_t vb = rest_.strand_begin(s);
      const std::uint32_t n = rest_.strand_size(s);
      auto pinned = [&](std::uint32_t i) { return rest_.positions[vb + i].w() == 0.0f; };
      section_points(s, head_rot);
      auto point = [&](std::uint32_t i) { return strand_points_[vb + i]; };
      auto weight = [&](std::uint32_t i) { return strand_weights_[vb + i]; };
      // Root to tip, each free vertex anchored to the last pinned one before it ...
      Vec3f anchor = Vec3f::Zero();
      int last = -1;
      bool pinned_after_free = false;
      for (std::uint32_t i = 0; i < n; ++i) {
        Vec4f& out = pos_[vb + i];
        if (pinned(i)) {
          out.head<3>() = head * xyz(rest_.positions[vb + i]);
          anchor = xyz(out) - point(i);
          pinned_after_free = pinned_after_free || (last >= 0 && static_cast<std::uint32_t>(last) + 1 < i) ||
                              (last < 0 && i > 0);
          last = static_cast<int>(i);
          continue;
        }
        out.head<3>() = point(i) + (1.0f - weight(i)) * anchor;
      }
      if (!pinned_after_free) continue;
      // ... or, where a pinned vertex follows nearer (a strand pinned at both ends), to it.
      int next = -1;
      for (std::uint32_t i = n; i-- > 0;) {
        if (pinned(i)) {
          anchor = xyz(pos_[vb + i]) - point(i);
          next = static_cast<int>(i);
          continue;
        }
        if (next < 0) continue;
        int prev = static_cast<int>(i) - 1;
        while (prev >= 0 && !pinned(static_cast<std::uint32_t>(prev))) --prev;
        if (prev >= 0 && static_cast<int>(i) - prev <= next - static_cast<int>(i)) continue;
        pos_[vb + i].head<3>() = point(i) + (1.0f - weight(i)) * anchor;
      }
    }
  };
  for_each(rest_.strand_count(), body);
}

}  // namespace hairbench::plante
