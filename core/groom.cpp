#include "core/groom.h"

#include "core/error.h"

#include <algorithm>
#include <cmath>

namespace hairbench {

void Groom::add_strand(std::span<const Vec3f> points, std::uint16_t region, int pinned) {
  for (std::size_t i = 0; i < points.size(); ++i) {
    const float inv_mass = static_cast<int>(i) < pinned ? 0.0f : 1.0f;
    positions.emplace_back(points[i].x(), points[i].y(), points[i].z(), inv_mass);
  }
  strand_offsets.push_back(static_cast<std::uint32_t>(positions.size()));
  strand_region.push_back(region);
}

Groom every_nth_strand(const Groom& g, std::size_t keep_every) {
  std::vector<std::uint32_t> kept;
  for (std::size_t s = 0; s < g.strand_count(); s += std::max<std::size_t>(keep_every, 1))
    kept.push_back(static_cast<std::uint32_t>(s));
  return select_strands(g, kept);
}

Groom select_strands(const Groom& g, std::span<const std::uint32_t> strands) {
  Groom out;
  out.region_names = g.region_names;
  out.head_radius = g.head_radius;
  for (const std::uint32_t s : strands) {
    const auto b = g.positions.begin() + g.strand_begin(s);
    out.positions.insert(out.positions.end(), b, b + g.strand_size(s));
    out.strand_offsets.push_back(static_cast<std::uint32_t>(out.positions.size()));
    out.strand_region.push_back(g.strand_region[s]);
  }
  return out;
}

std::vector<float> rest_edge_lengths(const Groom& g) {
  std::vector<float> len(g.vertex_count(), 0.0f);
  for (std::size_t s = 0; s < g.strand_count(); ++s) {
    const std::uint32_t b = g.strand_begin(s), n = g.strand_size(s);
    for (std::uint32_t i = 1; i < n; ++i)
      len[b + i] = (g.positions[b + i] - g.positions[b + i - 1]).head<3>().norm();
  }
  return len;
}

double mean_strand_length(const Groom& g) {
  if (g.strand_count() == 0) return 0.0;
  double total = 0.0;
  for (float l : rest_edge_lengths(g)) total += l;
  return total / static_cast<double>(g.strand_count());
}

void validate_groom(const Groom& g, const std::string& source) {
  const auto strand_field = [](std::size_t s) { return "strand " + std::to_string(s); };
  if (g.strand_count() == 0) throw InputError(source, "strands", "the groom has no strands");
  if (g.strand_offsets.front() != 0 || g.strand_offsets.back() != g.positions.size())
    throw InputError(source, "strands", "strand offsets do not cover the vertex array");
  if (g.strand_region.size() != g.strand_count())
    throw InputError(source, "regions", "one region index per strand expected");
  for (std::size_t s = 0; s < g.strand_count(); ++s) {
    if (g.strand_offsets[s + 1] < g.strand_offsets[s])
      throw InputError(source, strand_field(s), "strand offsets decrease");
    const std::uint32_t b = g.strand_begin(s), n = g.strand_size(s);
    if (n < 2) throw InputError(source, strand_field(s), "a strand needs at least 2 vertices");
    if (g.strand_region[s] >= g.region_names.size())
      throw InputError(source, strand_field(s), "region index out of range");
    for (std::uint32_t i = 0; i < n; ++i) {
      const Vec4f& p = g.positions[b + i];
      if (!p.allFinite())
        throw InputError(source, strand_field(s) + " vertex " + std::to_string(i),
                         "position is NaN or infinite");
      if (p.w() < 0.0f)
        throw InputError(source, strand_field(s) + " vertex " + std::to_string(i),
                         "negative inverse mass");
      if (i > 0 && (p - g.positions[b + i - 1]).head<3>().norm() <= 1e-7f)
        throw InputError(source, strand_field(s) + " vertex " + std::to_string(i),
                         "zero-length edge");
    }
    // Han & Harada §3.2: vertices 0 and 1 are pinned so that every strand has a root
    // frame (x_0 = P_1 - P_0) that follows the head.
    if (g.positions[b].w() != 0.0f || g.positions[b + 1].w() != 0.0f)
      throw InputError(source, strand_field(s), "vertices 0 and 1 must be pinned (inverse mass 0)");
  }
}

}  // namespace hairbench
