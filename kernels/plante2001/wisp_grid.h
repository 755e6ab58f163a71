// Broad phase of the wisp-wisp interactions (Plante et al. 2001 §4.1): a uniform 3D grid
// over the bounding boxes of the wisp segments. Each pair of segments is tested once per
// detection: in the first cell they share (SegmentGrid::item_first), or, in the
// reference narrow phase, by a mailbox per segment (Amanatides & Woo).
#pragma once

#include "kernels/plante2001/reference/wisp_kernels.h"

#include <array>
#include <cstdint>
#include <span>
#include <vector>

namespace hairbench::kernels {

// The masses a segment (k-1, k) owns: node k and its envelope masses 4k..4k+3, in the
// order they are tested (§4.1).
inline constexpr int kMassesPerSegment = 1 + kEnvelopePerSection;

// Those masses coordinate by coordinate, padded to a vector's width with copies of the
// first: the volume tests (wisp_grid_kernel.cpp) run on all of them at once.
struct SegmentMasses {
  static constexpr int kWidth = 8;
  alignas(32) float x[kWidth], y[kWidth], z[kWidth];
  Vec3f operator[](int q) const { return {x[q], y[q], z[q]}; }
};

struct SegmentGrid {
  // Segments that take part: (seg[i], seg[i] + 1), from each wisp's first free node on
  // (the pinned first segment is inside the head, §3.2).
  std::vector<std::uint32_t> seg;
  std::vector<std::uint32_t> wisp;                 // wisp of segment i
  std::vector<Vec3f> lo, hi;                       // bounding box of skeleton + envelope masses
  std::vector<Eigen::Vector3i> cell_lo, cell_hi;   // cells each box covers
  // Per segment, set up once per detection for its tests against every other one: its
  // volume, the positions of the masses it owns, and whether they are free
  // (node seg[i] + 1 is not pinned).
  std::vector<SegmentVolume> vol;
  std::vector<SegmentMasses> mass;
  std::vector<std::uint8_t> mass_free;
  Vec3f origin = Vec3f::Zero();
  float cell = 1.0f;
  Eigen::Vector3i dims = Eigen::Vector3i::Ones();
  std::vector<std::uint32_t> cell_start, cell_items;  // CSR: segments per cell, ascending
  // The bounding box of each entry of cell_items, coordinate by coordinate, so that a
  // cell's candidates are tested in one sequential sweep.
  std::array<std::vector<float>, 3> item_lo, item_hi;
  // Per entry of cell_items, bit a (x, y, z) set where its segment's box starts in this
  // cell along axis a (the cell's coordinate is its cell_lo[a]). A pair of segments is
  // first met in the lowest cell they share in z, y, x order: per axis the larger of
  // their cell_lo. So a segment i meets item j there first iff, on every axis where the
  // cell lies past i's cell_lo, j's box starts in it; the narrow phase tests this with
  // the boxes, and needs no mailbox (a mailbox's branch, taken by about one duplicate
  // per new pair on model 1, would be the hottest of the candidate loop).
  std::vector<std::uint8_t> item_first;
  // CSR: per segment, its own entry in each of its cells, in z, y, x order (the later
  // segments of a cell follow it there).
  std::vector<std::uint32_t> self_begin, self_items;
  // Scratch of the grid's parts (grid_frame): part p is segments [part_begin[p],
  // part_begin[p + 1]); its items per cell (grid_count), then the slot of its next one in
  // each cell (grid_offsets, grid_fill); part_items[p]: its first entry of self_items.
  std::vector<std::size_t> part_begin;
  std::vector<std::vector<std::uint32_t>> part_cells;
  std::vector<std::uint32_t> part_items;
  // Per segment, its candidates: the later segments in its cells, summed over the cells.
  // The narrow phase of segment i costs about that much, and it falls the more the later
  // i is, so equal ranges of segments are far from equal work (see grid_split).
  std::vector<std::uint32_t> candidates;

  std::size_t size() const { return seg.size(); }
  // The index of cell (x, y, z) in cell_start.
  std::size_t cell_at(int x, int y, int z) const { return (static_cast<std::size_t>(z) * dims.y() + y) * dims.x() + x; }
};

// The cells are cubes as wide as the widest segment box, so a box covers at most 2x2x2
// cells; the grid has at most kMaxGridCells per axis (wider cells beyond that).
inline constexpr int kMaxGridCells = 64;

// Rebuilds the grid from the current state: grid_segments, grid_setup of every segment,
// then grid_cells. In parts, so that grid_setup can run over ranges of segments on
// several threads; any split gives the same grid.
void grid_build(SegmentGrid& g, const WispSystem& s);
// The segments that take part, and every per-segment array sized for them.
void grid_segments(SegmentGrid& g, const WispSystem& s);
// Segments [begin, end): their boxes, volumes and masses.
void grid_setup(SegmentGrid& g, const WispSystem& s, std::size_t begin, std::size_t end);
// The cells, from the segments' boxes, and each segment's candidates.
void grid_cells(SegmentGrid& g);
// grid_cells in steps, so that its loops over the segments can run on several threads:
// grid_frame (the cells from the boxes' bounds, and `parts` equal ranges of segments),
// grid_count of every part, grid_offsets, then grid_fill of every part. Any number of
// parts gives the same grid.
void grid_frame(SegmentGrid& g, std::size_t parts);
void grid_count(SegmentGrid& g, std::size_t part);
void grid_offsets(SegmentGrid& g);
void grid_fill(SegmentGrid& g, std::size_t part);

// The plain narrow phase (plante_wisp_ref's, and the reference of wisp_soa's ContactsFn,
// which finds the same contacts in the same order): for each segment in [begin, end),
// every later segment of its cells, one pair at a time (box test, then each of the five
// masses of either segment in the other's volume by SegmentVolume::contains). `mailbox`
// holds one entry per segment, all != any index in [begin, end) on entry; a pair is
// tested where it is first met.
void grid_contacts_ref(const SegmentGrid& g, const WispSystem& s, std::size_t begin, std::size_t end,
                       std::vector<std::uint32_t>& mailbox, std::vector<WispContact>& out);

// What a detection's narrow phase tests, counted as §4.1 describes it (grid_contacts_ref's
// order): each pair of segments met in a shared cell is tested once (the mailbox),
// neighbours within two segments of one wisp excepted; its bounding boxes are compared;
// where they overlap, each mass of a free node of either segment is tested in the other's
// volume. A pair intersects when at least one of those masses is inside (§4.1's
// collision), read from the detection's contacts.
struct GridTestCounts {
  std::uint64_t segments = 0;            // that take part (SegmentGrid::size)
  std::uint64_t box_tests = 0;           // pairs whose bounding boxes are compared
  std::uint64_t box_overlaps = 0;        // of those, pairs whose boxes overlap
  std::uint64_t volume_tests = 0;        // mass-in-volume tests of the overlapping pairs
  std::uint64_t intersecting_pairs = 0;  // pairs with a mass of either inside the other
  std::uint64_t own_wisp_pairs = 0;      // of those, pairs of one wisp's segments
  std::uint64_t wisp_contacts = 0;       // (segment, other wisp) with an intersecting pair
  std::uint64_t neighbour_pairs = 0;     // neighbours within two segments of one wisp, never tested
};
// The counts of the detection that built `g` and found `contacts` (WispModel::grid() and
// contacts() after it, or grid_build and grid_contacts_ref).
GridTestCounts grid_test_counts(const SegmentGrid& g, std::span<const WispContact> contacts);

// Bounds of `parts` contiguous ranges of segments with about equal candidates each:
// range p is [bounds[p], bounds[p + 1]).
void grid_split(const SegmentGrid& g, std::size_t parts, std::vector<std::size_t>& bounds);

}  // namespace hairbench::kernels
