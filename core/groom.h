// The rest shape of a head of hair: strands as polylines, strand-major, in the head's
// rest frame (metres, y up, head centre at the origin).
#pragma once

#include "core/types.h"

#include <cstdint>
#include <span>
#include <string>
#include <vector>

namespace hairbench {

struct Groom {
  // Rest positions; w is the inverse mass (0 = pinned to the head). Strand s owns
  // vertices [strand_offsets[s], strand_offsets[s+1]).
  std::vector<Vec4f> positions;
  std::vector<std::uint32_t> strand_offsets{0};
  // Region of each strand (index into region_names); regions carry their own
  // parameters (Han & Harada §5, Figure 1).
  std::vector<std::uint16_t> strand_region;
  std::vector<std::string> region_names{"all"};
  float head_radius = 0.1f;  // the scalp sphere the strands are rooted on, metres

  std::size_t strand_count() const { return strand_offsets.size() - 1; }
  std::size_t vertex_count() const { return positions.size(); }
  std::uint32_t strand_begin(std::size_t s) const { return strand_offsets[s]; }
  std::uint32_t strand_size(std::size_t s) const { return strand_offsets[s + 1] - strand_offsets[s]; }

  // Appends one strand; `pinned` leading vertices get inverse mass 0.
  void add_strand(std::span<const Vec3f> points, std::uint16_t region, int pinned = 2);
};

// Per-edge rest lengths, indexed by the edge's second vertex (entry at a strand's first
// vertex is 0), so kernels address edges and vertices with one index.
std::vector<float> rest_edge_lengths(const Groom& g);
// Mean rest strand length L-bar (docs/metrics.md).
double mean_strand_length(const Groom& g);

// Every `keep_every`-th strand of g (strands 0, n, 2n, ...), with its region: a thinner
// groom for tests and stress runs whose properties are per strand.
Groom every_nth_strand(const Groom& g, std::size_t keep_every);
// The given strands of g, in the order given, each with its region.
Groom select_strands(const Groom& g, std::span<const std::uint32_t> strands);

// Checks the invariants every model relies on and throws InputError naming `source` and
// the first offending strand: >= 2 vertices, finite positions, no zero-length edge,
// vertices 0 and 1 pinned, offsets consistent.
void validate_groom(const Groom& g, const std::string& source);

}  // namespace hairbench
