#include "kernels/halen2007/nodes.h"

#include <algorithm>
#include <cmath>

namespace hairbench::kernels {

namespace {

Vec3f xyz(const Vec4f& v) { return v.head<3>(); }

// The smallest rotation taking the unit vector a to the unit vector b (Rodrigues, about
// a × b); where b is (almost) opposite a the turn is about any axis normal to a.
Mat3f smallest_rotation(const Vec3f& a, const Vec3f& b) {
  const float c = a.dot(b);
  if (c > -0.999f) {
    const Vec3f v = a.cross(b);
    Mat3f k;
    k << 0.0f, -v.z(), v.y(), v.z(), 0.0f, -v.x(), -v.y(), v.x(), 0.0f;
    return Mat3f::Identity() + k + k * k / (1.0f + c);
  }
  Vec3f axis = a.cross(Vec3f::UnitX());
  if (axis.squaredNorm() < 1e-6f) axis = a.cross(Vec3f::UnitY());
  axis.normalize();
  return 2.0f * axis * axis.transpose() - Mat3f::Identity();
}

// One strand's layout: node arc lengths and which drawn vertex each node lies on or after.
struct StrandNodes {
  std::vector<double> arc;        // arc length of each node
  std::vector<std::uint32_t> at;  // the drawn vertex each node lies on or after
  std::vector<bool> pinned;
};

// `s`: the arc length of every vertex of `rest`.
StrandNodes strand_nodes(std::span<const Vec4f> rest, std::span<const double> s, int count) {
  const std::size_t n = rest.size();
  std::vector<std::uint32_t> anchors;
  for (std::size_t i = 0; i < n; ++i)
    if (i == 0 || i + 1 == n || rest[i].w() == 0.0f) anchors.push_back(static_cast<std::uint32_t>(i));

  // Free stretches between consecutive anchors and their share of the free nodes.
  const std::size_t stretches = anchors.size() - 1;
  std::vector<double> length(stretches, 0.0);
  double free_length = 0.0;
  for (std::size_t k = 0; k < stretches; ++k) {
    const std::uint32_t a = anchors[k], b = anchors[k + 1];
    const bool rigid = b == a + 1 && rest[a].w() == 0.0f && rest[b].w() == 0.0f;
    if (!rigid) length[k] = s[b] - s[a];
    free_length += length[k];
  }
  const int free_nodes = std::max(0, count - static_cast<int>(anchors.size()));
  std::vector<int> share(stretches, 0);
  if (free_length > 0.0) {
    std::vector<double> remainder(stretches, 0.0);
    int given = 0;
    for (std::size_t k = 0; k < stretches; ++k) {
      const double exact = free_nodes * length[k] / free_length;
      share[k] = static_cast<int>(std::floor(exact));
      remainder[k] = exact - share[k];
      given += share[k];
    }
    for (; given < free_nodes; ++given) {
      std::size_t best = 0;
      for (std::size_t k = 1; k < stretches; ++k)
        if (remainder[k] > remainder[best]) best = k;
      ++share[best];
      remainder[best] = -1.0;
    }
  }

  StrandNodes out;
  auto add = [&](double arc, bool pinned) {
    std::uint32_t i = 0;
    while (i + 1 < n && s[i + 1] <= arc) ++i;
    out.arc.push_back(arc);
    out.at.push_back(i);
    out.pinned.push_back(pinned);
  };
  for (std::size_t k = 0; k < stretches; ++k) {
    const std::uint32_t a = anchors[k];
    add(s[a], rest[a].w() == 0.0f);
    for (int j = 1; j <= share[k]; ++j)
      add(s[a] + (s[anchors[k + 1]] - s[a]) * j / (share[k] + 1), false);
  }
  add(s[n - 1], rest[n - 1].w() == 0.0f);
  return out;
}

// The point of the rest polyline at arc length `arc`, within edge (i, i+1).
Vec3f point_at(std::span<const Vec4f> rest, std::span<const double> s, std::uint32_t i, double arc) {
  if (i + 1 >= rest.size() || s[i + 1] <= s[i]) return xyz(rest[i]);
  const float t = static_cast<float>((arc - s[i]) / (s[i + 1] - s[i]));
  return xyz(rest[i]) + t * (xyz(rest[i + 1]) - xyz(rest[i]));
}

}  // namespace

NodeLayout layout_nodes(const Groom& drawn, int count, bool tied_static) {
  NodeLayout out;
  out.nodes.region_names = drawn.region_names;
  out.nodes.head_radius = drawn.head_radius;
  out.nodes.strand_region = drawn.strand_region;
  out.span.resize(drawn.vertex_count());
  for (std::size_t strand = 0; strand < drawn.strand_count(); ++strand) {
    const auto rest = std::span(drawn.positions).subspan(drawn.strand_begin(strand), drawn.strand_size(strand));
    const std::size_t n = rest.size();
    std::vector<double> s(n, 0.0);
    for (std::size_t i = 1; i < n; ++i) s[i] = s[i - 1] + (xyz(rest[i]) - xyz(rest[i - 1])).cast<double>().norm();
    // Held: a pinned vertex after a free one, at the tip or in the middle (a strand pinned
    // whole is the groom's rigid strand already, not one the model holds).
    const auto first_free = std::find_if(rest.begin(), rest.end(), [](const Vec4f& v) { return v.w() != 0.0f; });
    const bool held = tied_static && first_free != rest.end() &&
                      std::any_of(first_free, rest.end(), [](const Vec4f& v) { return v.w() == 0.0f; });
    out.static_strands += held;
    const StrandNodes sn = strand_nodes(rest, s, count);
    const std::size_t first = out.nodes.positions.size();
    for (std::size_t j = 0; j < sn.arc.size(); ++j) {
      // A node on a vertex is that vertex, bit for bit; a node inside an edge takes the
      // inverse mass of the edge's free end.
      const std::uint32_t i = sn.at[j];
      const bool on_vertex = sn.arc[j] == s[i];
      const Vec3f p = on_vertex ? xyz(rest[i]) : point_at(rest, s, i, sn.arc[j]);
      const float w = sn.pinned[j] || held ? 0.0f : (rest[i].w() != 0.0f || i + 1 >= n ? rest[i].w() : rest[i + 1].w());
      out.nodes.positions.emplace_back(p.x(), p.y(), p.z(), w);
    }
    out.nodes.strand_offsets.push_back(static_cast<std::uint32_t>(out.nodes.positions.size()));
    const auto nodes = std::span(out.nodes.positions).subspan(first, sn.arc.size());

    // Each pinned vertex rigid with the head (it is a node, which the model moves with
    // the head too, but the drawing does not depend on that), each other one on the node
    // segment that holds its arc length.
    std::size_t j = 0;
    for (std::size_t i = 0; i < n; ++i) {
      NodeSpan& sp = out.span[drawn.strand_begin(strand) + i];
      while (j + 2 < sn.arc.size() && sn.arc[j + 1] <= s[i]) ++j;
      if (held || rest[i].w() == 0.0f) continue;  // Kind::Head
      const double len = sn.arc[j + 1] - sn.arc[j];
      sp.kind = NodeSpan::Kind::Segment;
      sp.a = static_cast<std::int32_t>(j);
      sp.t = len > 0.0 ? static_cast<float>(std::clamp((s[i] - sn.arc[j]) / len, 0.0, 1.0)) : 0.0f;
      const Vec3f on_segment = xyz(nodes[j]) + sp.t * (xyz(nodes[j + 1]) - xyz(nodes[j]));
      sp.offset = xyz(rest[i]) - on_segment;
    }
  }
  return out;
}

void draw_from_nodes(std::span<const Vec4f> node_pos, std::span<const Vec4f> node_rest,
                     std::span<const NodeSpan> span, std::span<const Vec4f> drawn_rest, const Affine3f& head,
                     std::span<Quatf> frame, std::span<Vec4f> drawn) {
  const std::size_t n = node_pos.size();
  const Mat3f head_rotation = head.linear();
  // Segment frames into frame[1..n-1] (segment j at j + 1), then node frames in place.
  Mat3f q = head_rotation;
  for (std::size_t j = 0; j + 1 < n; ++j) {
    const Vec3f e = xyz(node_rest[j + 1]) - xyz(node_rest[j]);
    const Vec3f d = xyz(node_pos[j + 1]) - xyz(node_pos[j]);
    const bool rigid = node_rest[j].w() == 0.0f && node_rest[j + 1].w() == 0.0f;
    if (rigid) {
      q = head_rotation;  // rigid with the head
    } else if (e.norm() > 0.0f && d.norm() > 0.0f) {
      q = smallest_rotation((q * e).normalized(), d.normalized()) * q;
    }  // a degenerate segment keeps its parent's frame
    frame[j + 1] = Quatf(q);
  }
  // A node's frame halves the turn between its two segments' (the first and last take
  // their one segment's), so that a drawn vertex's frame, interpolated between its
  // segment's nodes, turns continuously along the strand.
  frame[0] = n > 1 ? frame[1] : Quatf(head_rotation);
  for (std::size_t j = 1; j + 1 < n; ++j) frame[j] = frame[j].slerp(0.5f, frame[j + 1]);
  for (std::size_t i = 0; i < drawn.size(); ++i) {
    const NodeSpan& sp = span[i];
    switch (sp.kind) {
      case NodeSpan::Kind::Segment: {
        const Vec3f pa = xyz(node_pos[sp.a]), pb = xyz(node_pos[sp.a + 1]);
        drawn[i].head<3>() = pa + sp.t * (pb - pa) + frame[sp.a].slerp(sp.t, frame[sp.a + 1]) * sp.offset;
        break;
      }
      case NodeSpan::Kind::Head: drawn[i].head<3>() = head * xyz(drawn_rest[i]); break;
    }
    drawn[i].w() = drawn_rest[i].w();
  }
}

}  // namespace hairbench::kernels
