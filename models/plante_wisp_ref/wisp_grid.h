// plante_wisp_ref: plante_wisp as it stood before the issue-10 speed work (one pass per
// stage over all wisps, a parallel_for per stage, the per-wisp kernels unchanged), kept
// as the reference that plante_wisp's speed-up and agreement are measured against
// (tests/plante_test.cpp, hairbench_bench BM_step). Physics: models/plante_wisp.
// Broad phase of the wisp-wisp interactions (Plante et al. 2001 §4.1): a uniform 3D grid
// over the bounding boxes of the wisp segments, and a mailbox per segment (Amanatides &
// Woo) so that each pair of segments is tested once per detection.
#pragma once

#include "models/plante_wisp_ref/wisp_kernels.h"

#include <cstdint>
#include <vector>

namespace hairbench::plante_ref {

struct SegmentGrid {
  // Segments that take part: (seg[i], seg[i] + 1), from each wisp's first free node on
  // (the pinned first segment is inside the head, §3.2).
  std::vector<std::uint32_t> seg;
  std::vector<Vec3f> lo, hi;                       // bounding box of skeleton + envelope masses
  std::vector<Eigen::Vector3i> cell_lo, cell_hi;   // cells each box covers
  Vec3f origin = Vec3f::Zero();
  float cell = 1.0f;
  Eigen::Vector3i dims = Eigen::Vector3i::Ones();
  std::vector<std::uint32_t> cell_start, cell_items;  // CSR: segments per cell, ascending

  std::size_t size() const { return seg.size(); }
};

// The cells are cubes as wide as the widest segment box, so a box covers at most 2x2x2
// cells; the grid has at most kMaxGridCells per axis (wider cells beyond that).
inline constexpr int kMaxGridCells = 64;

// Rebuilds the grid from the current state.
void grid_build(SegmentGrid& g, const WispSystem& s);

// Narrow phase for segments [begin, end) against every later segment sharing a cell
// with it: bounding boxes, then segment_pair_contacts. Segments of one wisp closer than
// three apart along it are never a pair (neighbours touch by construction). `mailbox`
// holds one entry per segment, all != any index in [begin, end) on entry. The contacts
// come in a fixed order (segment, then cell, then segment index), so splitting the range
// across threads and concatenating the outputs in range order gives the serial list.
void grid_contacts(const SegmentGrid& g, const WispSystem& s, std::size_t begin, std::size_t end,
                   std::vector<std::uint32_t>& mailbox, std::vector<WispContact>& out);

}  // namespace hairbench::plante_ref
