#include "kernels/plante2001/wisp_grid.h"

#include "kernels/plante2001/fused/wisp_soa.h"

#include <algorithm>
#include <cmath>

namespace hairbench::kernels {

namespace {

void set_mass(SegmentMasses& m, int q, const Vec3f& p) {
  m.x[q] = p.x();
  m.y[q] = p.y();
  m.z[q] = p.z();
}

}  // namespace

void grid_segments(SegmentGrid& g, const WispSystem& s) {
  g.seg.clear();
  for (std::size_t w = 0; w < s.wisp_count(); ++w) {
    const std::uint32_t b = s.node_begin[w], e = s.node_begin[w + 1];
    std::uint32_t first = b;
    while (first < e && s.pinned[first]) ++first;
    // Segment (first - 1, first) is the first one with a free mass.
    for (std::uint32_t k = first > b ? first - 1 : b; k + 1 < e; ++k) g.seg.push_back(k);
  }
  const std::size_t n = g.seg.size();
  g.wisp.resize(n);
  g.vol.resize(n);
  g.mass.resize(n);
  g.mass_free.resize(n);
  g.lo.resize(n);
  g.hi.resize(n);
  g.cell_lo.resize(n);
  g.cell_hi.resize(n);
  g.candidates.resize(n);
}

void grid_setup(SegmentGrid& g, const WispSystem& s, std::size_t begin, std::size_t end) {
  for (std::size_t i = begin; i < end; ++i) {
    Vec3f lo = Vec3f::Constant(INFINITY), hi = Vec3f::Constant(-INFINITY);
    for (std::uint32_t k = g.seg[i]; k <= g.seg[i] + 1; ++k) {
      lo = lo.cwiseMin(s.x[k]);
      hi = hi.cwiseMax(s.x[k]);
      for (int q = 0; q < kEnvelopePerSection; ++q) {
        const Vec3f p = envelope_point(s, k, q);
        lo = lo.cwiseMin(p);
        hi = hi.cwiseMax(p);
        if (k > g.seg[i]) set_mass(g.mass[i], 1 + q, p);
      }
    }
    const std::uint32_t k = g.seg[i] + 1;
    g.wisp[i] = s.node_wisp[k];
    g.vol[i] = SegmentVolume(s, g.seg[i]);
    for (int q : {0, kMassesPerSegment, kMassesPerSegment + 1, kMassesPerSegment + 2}) set_mass(g.mass[i], q, s.x[k]);
    g.mass_free[i] = !s.pinned[k];
    g.lo[i] = lo;
    g.hi[i] = hi;
  }
}

void grid_build(SegmentGrid& g, const WispSystem& s) {
  grid_segments(g, s);
  grid_setup(g, s, 0, g.size());
  grid_cells(g);
}

void grid_cells(SegmentGrid& g) {
  grid_frame(g, 1);
  grid_count(g, 0);
  grid_offsets(g);
  grid_fill(g, 0);
}

void grid_frame(SegmentGrid& g, std::size_t parts) {
  const std::size_t n = g.size();
  parts = std::max<std::size_t>(1, std::min(parts, n));
  g.part_begin.resize(parts + 1);
  for (std::size_t p = 0; p <= parts; ++p) g.part_begin[p] = n * p / parts;
  g.part_cells.resize(parts);
  g.part_items.assign(parts + 1, 0);
  if (n == 0) {
    g.dims = Eigen::Vector3i::Ones();
    g.cell_start.assign(2, 0);
    return;
  }
  // In segment order, whichever threads set the segments up (min and max keep a NaN or
  // drop it by their order of operands).
  Vec3f all_lo = Vec3f::Constant(INFINITY), all_hi = Vec3f::Constant(-INFINITY);
  float widest = 0.0f;
  for (std::size_t i = 0; i < n; ++i) {
    all_lo = all_lo.cwiseMin(g.lo[i]);
    all_hi = all_hi.cwiseMax(g.hi[i]);
    widest = std::max(widest, (g.hi[i] - g.lo[i]).maxCoeff());
  }
  const float extent = (all_hi - all_lo).maxCoeff();
  g.cell = std::max({widest, extent / static_cast<float>(kMaxGridCells), 1e-6f});
  g.origin = all_lo;
  for (int a = 0; a < 3; ++a)
    g.dims[a] = std::clamp(static_cast<int>((all_hi[a] - all_lo[a]) / g.cell) + 1, 1, kMaxGridCells + 1);
  const std::size_t cells = static_cast<std::size_t>(g.dims.x()) * g.dims.y() * g.dims.z();
  g.cell_start.resize(cells + 1);
  for (auto& counts : g.part_cells) counts.assign(cells, 0);
}

void grid_count(SegmentGrid& g, std::size_t part) {
  if (g.size() == 0) return;
  auto cell_of = [&](const Vec3f& p) {
    Eigen::Vector3i c;
    for (int a = 0; a < 3; ++a) c[a] = std::clamp(static_cast<int>((p[a] - g.origin[a]) / g.cell), 0, g.dims[a] - 1);
    return c;
  };
  std::vector<std::uint32_t>& counts = g.part_cells[part];
  std::uint32_t items = 0;
  for (std::size_t i = g.part_begin[part]; i < g.part_begin[part + 1]; ++i) {
    g.cell_lo[i] = cell_of(g.lo[i]);
    g.cell_hi[i] = cell_of(g.hi[i]);
    for (int z = g.cell_lo[i].z(); z <= g.cell_hi[i].z(); ++z)
      for (int y = g.cell_lo[i].y(); y <= g.cell_hi[i].y(); ++y)
        for (int x = g.cell_lo[i].x(); x <= g.cell_hi[i].x(); ++x) {
          ++counts[g.cell_at(x, y, z)];
          ++items;
        }
  }
  g.part_items[part + 1] = items;
}

void grid_offsets(SegmentGrid& g) {
  const std::size_t n = g.size(), cells = g.cell_start.size() - 1, parts = g.part_cells.size();
  if (n == 0) {
    g.cell_items.clear();
    return;
  }
  // Cell c's items: those of part 0, then part 1, ...; so each part's counts become the
  // slot of its first item in the cell, and the cell's items ascend.
  std::uint32_t slot = 0;
  for (std::size_t c = 0; c < cells; ++c) {
    g.cell_start[c] = slot;
    for (std::size_t p = 0; p < parts; ++p) {
      const std::uint32_t count = g.part_cells[p][c];
      g.part_cells[p][c] = slot;
      slot += count;
    }
  }
  g.cell_start[cells] = slot;
  for (std::size_t p = 0; p < parts; ++p) g.part_items[p + 1] += g.part_items[p];
  const std::size_t items = slot;
  g.cell_items.resize(items);
  for (int a = 0; a < 3; ++a) {
    g.item_lo[a].resize(items);
    g.item_hi[a].resize(items);
  }
  g.item_first.resize(items);
  g.self_begin.resize(n + 1);
  g.self_begin[n] = static_cast<std::uint32_t>(items);
  g.self_items.resize(items);
}

void grid_fill(SegmentGrid& g, std::size_t part) {
  if (g.size() == 0) return;
  std::vector<std::uint32_t>& fill = g.part_cells[part];
  std::uint32_t slot = g.part_items[part];
  for (std::size_t i = g.part_begin[part]; i < g.part_begin[part + 1]; ++i) {
    const Eigen::Vector3i& lo = g.cell_lo[i];
    g.self_begin[i] = slot;
    g.candidates[i] = 0;
    for (int z = lo.z(); z <= g.cell_hi[i].z(); ++z)
      for (int y = lo.y(); y <= g.cell_hi[i].y(); ++y)
        for (int x = lo.x(); x <= g.cell_hi[i].x(); ++x) {
          const std::size_t c = g.cell_at(x, y, z);
          const std::uint32_t it = fill[c]++;
          g.cell_items[it] = static_cast<std::uint32_t>(i);
          for (int a = 0; a < 3; ++a) {
            g.item_lo[a][it] = g.lo[i][a];
            g.item_hi[a][it] = g.hi[i][a];
          }
          g.item_first[it] = static_cast<std::uint8_t>((x == lo.x()) | (y == lo.y()) << 1 | (z == lo.z()) << 2);
          g.self_items[slot++] = it;
          // A cell's items ascend (filled in segment order): the rest after it are later.
          g.candidates[i] += g.cell_start[c + 1] - it - 1;
        }
  }
}

void grid_split(const SegmentGrid& g, std::size_t parts, std::vector<std::size_t>& bounds) {
  const std::size_t n = g.size();
  // Each segment also costs its own cell visits: one candidate's worth.
  std::uint64_t total = 0;
  for (std::uint32_t c : g.candidates) total += c + 1;
  bounds.assign(parts + 1, n);
  bounds[0] = 0;
  std::uint64_t done = 0;
  std::size_t p = 1;
  for (std::size_t i = 0; i < n && p < parts; ++i) {
    done += g.candidates[i] + 1;
    while (p < parts && done * parts >= total * p) bounds[p++] = i + 1;
  }
}

namespace {

// Segments i < j of one wisp within two segments of each other share a node or meet at
// one: the narrow phase never tests them.
bool neighbours(const SegmentGrid& g, std::size_t i, std::size_t j) {
  return g.wisp[j] == g.wisp[i] && g.seg[j] - g.seg[i] < 3;
}

bool boxes_overlap(const SegmentGrid& g, std::size_t i, std::size_t j) {
  return !((g.lo[i].array() > g.hi[j].array()).any() || (g.lo[j].array() > g.hi[i].array()).any());
}

// Node seg[i] + 1's masses (the node, then its envelope masses) in segment j's volume.
void masses_in(const SegmentGrid& g, const WispSystem& s, std::size_t i, std::size_t j, std::vector<WispContact>& out) {
  const std::uint32_t k = g.seg[i] + 1;
  if (s.pinned[k]) return;
  const SegmentVolume& vol = g.vol[j];
  const float u = vol.contains(s, s.x[k]);
  if (u >= 0.0f) out.push_back({k, vol.a, u, 0});
  for (int q = 0; q < kEnvelopePerSection; ++q) {
    const float uq = vol.contains(s, envelope_point(s, k, q));
    if (uq >= 0.0f) out.push_back({static_cast<std::uint32_t>(kEnvelopePerSection * k + q), vol.a, uq, 1});
  }
}

// Calls f(j) once for every segment j > i that shares a grid cell with segment i: the
// mailbox (mailbox[j] == i once j has been seen from i) keeps a pair met in several cells
// to one test (§4.1).
template <class F>
void for_each_later_candidate(const SegmentGrid& g, std::size_t i, std::vector<std::uint32_t>& mailbox, F&& f) {
  for (int z = g.cell_lo[i].z(); z <= g.cell_hi[i].z(); ++z)
    for (int y = g.cell_lo[i].y(); y <= g.cell_hi[i].y(); ++y)
      for (int x = g.cell_lo[i].x(); x <= g.cell_hi[i].x(); ++x) {
        const std::size_t c = g.cell_at(x, y, z);
        for (std::uint32_t it = g.cell_start[c]; it < g.cell_start[c + 1]; ++it) {
          const std::uint32_t j = g.cell_items[it];
          if (j <= i || mailbox[j] == i) continue;
          mailbox[j] = static_cast<std::uint32_t>(i);
          f(j);
        }
      }
}

}  // namespace

void grid_contacts_ref(const SegmentGrid& g, const WispSystem& s, std::size_t begin, std::size_t end,
                       std::vector<std::uint32_t>& mailbox, std::vector<WispContact>& out) {
  for (std::size_t i = begin; i < end; ++i)
    for_each_later_candidate(g, i, mailbox, [&](std::uint32_t j) {
      if (neighbours(g, i, j) || !boxes_overlap(g, i, j)) return;
      masses_in(g, s, i, j, out);
      masses_in(g, s, j, i, out);
    });
}

GridTestCounts grid_test_counts(const SegmentGrid& g, std::span<const WispContact> contacts) {
  GridTestCounts c;
  const std::size_t n = g.size();
  c.segments = n;
  std::vector<std::uint32_t> mailbox(n, ~0u);
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t j = i + 1; j < n && neighbours(g, i, j); ++j) ++c.neighbour_pairs;
    for_each_later_candidate(g, i, mailbox, [&](std::uint32_t j) {
      if (neighbours(g, i, j)) return;
      ++c.box_tests;
      if (!boxes_overlap(g, i, j)) return;
      ++c.box_overlaps;
      c.volume_tests += kMassesPerSegment * (g.mass_free[i] + g.mass_free[j]);
    });
  }
  // A contact is a mass of node k, owned by segment (k - 1, k), inside segment c.seg's
  // volume; the segments ascend by first node (grid_segments).
  auto index = [&](std::uint32_t first_node) {
    return static_cast<std::uint64_t>(std::lower_bound(g.seg.begin(), g.seg.end(), first_node) - g.seg.begin());
  };
  std::vector<std::uint64_t> pairs;
  pairs.reserve(contacts.size());
  for (const WispContact& k : contacts) {
    const std::uint32_t node = k.envelope ? k.point / kEnvelopePerSection : k.point;
    const std::uint64_t a = index(node - 1), b = index(k.seg);
    pairs.push_back(std::min(a, b) << 32 | std::max(a, b));
  }
  std::ranges::sort(pairs);
  pairs.erase(std::unique(pairs.begin(), pairs.end()), pairs.end());
  c.intersecting_pairs = pairs.size();
  std::vector<std::uint64_t> touched;
  for (const std::uint64_t p : pairs) {
    const std::uint64_t i = p >> 32, j = p & 0xffffffffu;
    if (g.wisp[i] == g.wisp[j]) {
      ++c.own_wisp_pairs;
      continue;
    }
    touched.push_back(i << 32 | g.wisp[j]);
    touched.push_back(j << 32 | g.wisp[i]);
  }
  std::ranges::sort(touched);
  c.wisp_contacts = static_cast<std::uint64_t>(std::unique(touched.begin(), touched.end()) - touched.begin());
  return c;
}

}  // namespace hairbench::kernels
