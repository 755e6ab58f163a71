#include "reports/device_metrics.h"

#include <algorithm>
#include <cmath>

namespace hairbench::metrics {

DeviceMetricsRest device_rest(const RestInfo& rest, std::span<const Vec4f> start) {
  const Groom& g = *rest.groom;
  DeviceMetricsRest out;
  out.rest.assign(g.positions.begin(), g.positions.end());
  out.edge.resize(g.vertex_count());
  for (std::size_t i = 0; i < g.vertex_count(); ++i)
    out.edge[i] = Vec4f(rest.rest_length[i], static_cast<float>(rest.vertex_edge_scale[i]),
                        static_cast<float>(rest.rest_kb_change[i]), static_cast<float>(rest.kb_weight[i]));
  out.strand_offsets.assign(g.strand_offsets.begin(), g.strand_offsets.end());
  out.start.assign(start.begin(), start.end());
  out.far = static_cast<float>(blowup_distance(rest));
  return out;
}

// The sums below run over the strands in index order, each strand's float value widened
// to double: one order whatever order the device worked in.

double deviation(const RestInfo& rest, std::span<const StrandMetrics> m) {
  double sum = 0.0;
  for (const StrandMetrics& s : m) sum += s.deviation2;
  return std::sqrt(sum / static_cast<double>(rest.groom->vertex_count())) / rest.mean_strand_length;
}

double jaggedness(const RestInfo& rest, std::span<const StrandMetrics> m) {
  double sum = 0.0;
  for (const StrandMetrics& s : m) sum += s.jaggedness;
  return sum / static_cast<double>(rest.groom->strand_count());
}

// The first strand of the largest error holds it, as in one pass over the groom.
LengthError length_error(const RestInfo& rest, std::span<const StrandMetrics> m) {
  LengthError out;
  double sum = 0.0;
  for (std::size_t s = 0; s < rest.groom->strand_count(); ++s) {
    sum += m[s].length2;
    if (out.max < m[s].length_max) {
      out.max = m[s].length_max;
      out.worst_strand = static_cast<std::uint32_t>(s);
      out.worst_edge = m[s].length_worst;
    }
  }
  const std::size_t edges = rest.edge_count;
  out.rms = edges ? std::sqrt(sum / static_cast<double>(edges)) : 0.0;
  return out;
}

double rest_shape_error(const RestInfo& rest, std::span<const StrandMetrics> m) {
  double sum = 0.0;
  for (const StrandMetrics& s : m) sum += s.rest2;
  return std::sqrt(sum / static_cast<double>(rest.groom->vertex_count())) / rest.mean_strand_length;
}

double penetration(std::span<const StrandMetrics> m) {
  double deepest = 0.0;
  for (const StrandMetrics& s : m) deepest = std::max(deepest, double(s.penetration));
  return deepest;
}

// The messages are blowup_reason's: the first bad vertex in strand order.
std::string blowup_reason(std::span<const StrandMetrics> m) {
  for (std::size_t s = 0; s < m.size(); ++s) {
    if (m[s].bad_kind == StrandMetrics::kNonFinite)
      return "non-finite position (strand " + std::to_string(s) + ", vertex " + std::to_string(m[s].bad_vertex) + ")";
    if (m[s].bad_kind == StrandMetrics::kFar)
      return "vertex farther than 10 mean strand lengths from the head (strand " + std::to_string(s) + ")";
  }
  return {};
}

double mechanical_energy(const RestInfo& rest, std::span<const StrandMetrics> m) {
  const std::size_t n = rest.groom->vertex_count();
  if (n == 0) return 0.0;
  double e = 0.0;
  for (const StrandMetrics& s : m) e += s.energy;
  return e / static_cast<double>(n);
}

double relative_kinetic_energy(const RestInfo& rest, std::span<const StrandMetrics> m, double dt) {
  const std::size_t n = rest.groom->vertex_count();
  if (n == 0) return 0.0;
  double sum = 0.0;
  for (const StrandMetrics& s : m) sum += s.kinetic;
  return sum / (2.0 * dt * dt * static_cast<double>(n));
}

}  // namespace hairbench::metrics
