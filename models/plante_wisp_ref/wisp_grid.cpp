#include "models/plante_wisp_ref/wisp_grid.h"

#include <algorithm>
#include <cmath>

namespace hairbench::plante_ref {

void grid_build(SegmentGrid& g, const WispSystem& s) {
  g.seg.clear();
  for (std::size_t w = 0; w < s.wisp_count(); ++w) {
    const std::uint32_t b = s.node_begin[w], e = s.node_begin[w + 1];
    std::uint32_t first = b;
    while (first < e && s.pinned[first]) ++first;
    // Segment (first - 1, first) is the first one with a free mass.
    for (std::uint32_t k = first > b ? first - 1 : b; k + 1 < e; ++k) g.seg.push_back(k);
  }
  const std::size_t n = g.seg.size();
  g.lo.resize(n);
  g.hi.resize(n);
  g.cell_lo.resize(n);
  g.cell_hi.resize(n);
  if (n == 0) {
    g.cell_start.assign(2, 0);
    g.cell_items.clear();
    g.dims = Eigen::Vector3i::Ones();
    return;
  }
  Vec3f all_lo = Vec3f::Constant(INFINITY), all_hi = Vec3f::Constant(-INFINITY);
  float widest = 0.0f;
  for (std::size_t i = 0; i < n; ++i) {
    Vec3f lo = Vec3f::Constant(INFINITY), hi = Vec3f::Constant(-INFINITY);
    for (std::uint32_t k = g.seg[i]; k <= g.seg[i] + 1; ++k) {
      lo = lo.cwiseMin(s.x[k]);
      hi = hi.cwiseMax(s.x[k]);
      for (int q = 0; q < kEnvelopePerSection; ++q) {
        const Vec3f p = envelope_point(s, k, q);
        lo = lo.cwiseMin(p);
        hi = hi.cwiseMax(p);
      }
    }
    g.lo[i] = lo;
    g.hi[i] = hi;
    all_lo = all_lo.cwiseMin(lo);
    all_hi = all_hi.cwiseMax(hi);
    widest = std::max(widest, (hi - lo).maxCoeff());
  }
  const float extent = (all_hi - all_lo).maxCoeff();
  g.cell = std::max({widest, extent / static_cast<float>(kMaxGridCells), 1e-6f});
  g.origin = all_lo;
  for (int a = 0; a < 3; ++a)
    g.dims[a] = std::clamp(static_cast<int>((all_hi[a] - all_lo[a]) / g.cell) + 1, 1, kMaxGridCells + 1);
  auto cell_of = [&](const Vec3f& p) {
    Eigen::Vector3i c;
    for (int a = 0; a < 3; ++a) c[a] = std::clamp(static_cast<int>((p[a] - g.origin[a]) / g.cell), 0, g.dims[a] - 1);
    return c;
  };
  const std::size_t cells = static_cast<std::size_t>(g.dims.x()) * g.dims.y() * g.dims.z();
  g.cell_start.assign(cells + 1, 0);
  auto index = [&](int x, int y, int z) { return (static_cast<std::size_t>(z) * g.dims.y() + y) * g.dims.x() + x; };
  for (std::size_t i = 0; i < n; ++i) {
    g.cell_lo[i] = cell_of(g.lo[i]);
    g.cell_hi[i] = cell_of(g.hi[i]);
    for (int z = g.cell_lo[i].z(); z <= g.cell_hi[i].z(); ++z)
      for (int y = g.cell_lo[i].y(); y <= g.cell_hi[i].y(); ++y)
        for (int x = g.cell_lo[i].x(); x <= g.cell_hi[i].x(); ++x) ++g.cell_start[index(x, y, z) + 1];
  }
  for (std::size_t c = 0; c < cells; ++c) g.cell_start[c + 1] += g.cell_start[c];
  g.cell_items.resize(g.cell_start[cells]);
  std::vector<std::uint32_t> fill(g.cell_start.begin(), g.cell_start.end() - 1);
  for (std::size_t i = 0; i < n; ++i)
    for (int z = g.cell_lo[i].z(); z <= g.cell_hi[i].z(); ++z)
      for (int y = g.cell_lo[i].y(); y <= g.cell_hi[i].y(); ++y)
        for (int x = g.cell_lo[i].x(); x <= g.cell_hi[i].x(); ++x)
          g.cell_items[fill[index(x, y, z)]++] = static_cast<std::uint32_t>(i);
}

void grid_contacts(const SegmentGrid& g, const WispSystem& s, std::size_t begin, std::size_t end,
                   std::vector<std::uint32_t>& mailbox, std::vector<WispContact>& out) {
  auto index = [&](int x, int y, int z) { return (static_cast<std::size_t>(z) * g.dims.y() + y) * g.dims.x() + x; };
  for (std::size_t i = begin; i < end; ++i) {
    const std::uint32_t a = g.seg[i];
    const std::uint32_t wa = s.node_wisp[a];
    for (int z = g.cell_lo[i].z(); z <= g.cell_hi[i].z(); ++z)
      for (int y = g.cell_lo[i].y(); y <= g.cell_hi[i].y(); ++y)
        for (int x = g.cell_lo[i].x(); x <= g.cell_hi[i].x(); ++x) {
          const std::size_t c = index(x, y, z);
          for (std::uint32_t it = g.cell_start[c]; it < g.cell_start[c + 1]; ++it) {
            const std::uint32_t j = g.cell_items[it];
            if (j <= i || mailbox[j] == i) continue;
            mailbox[j] = static_cast<std::uint32_t>(i);
            const std::uint32_t b = g.seg[j];
            if (s.node_wisp[b] == wa && b - a < 3) continue;  // b > a within a wisp
            if ((g.lo[i].array() > g.hi[j].array()).any() || (g.lo[j].array() > g.hi[i].array()).any()) continue;
            segment_pair_contacts(s, a, b, out);
          }
        }
  }
}

}  // namespace hairbench::plante_ref
