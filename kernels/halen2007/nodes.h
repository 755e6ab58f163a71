// Halén & Wester 2007 simulate a few nodes per strand (Fig. 6.1.1: 4 and 8; §5.5: "anything
// above 64 strands and 8 nodes per strand should be considered extremely high") and draw
// more vertices by interpolating the simulated ones (§5.5: a drawn vertex is placed, at
// creation, at a height between two nodes A and B of its strand and follows them by
// linear interpolation). This file lays a groom's strands out as such nodes and draws the
// groom's vertices from them.
//
// Nodes sit on the rest polyline, spaced equally in arc length between anchors: the
// strand's first and last vertex and every pinned vertex are nodes themselves, so that a
// pin passes to the simulation unchanged; a pinned vertex is drawn exactly where the head
// carries it, whether or not the model holds a node there. A drawn vertex keeps its rest
// offset from the point of its node segment at its arc length, in that segment's frame:
// §5.5 stores a local coordinate system per vertex for its tangent and normal; here it
// carries the position too, so a curl finer than the nodes keeps its shape (the drawn
// groom at rest is the rest groom).
#pragma once

#include "core/groom.h"
#include "core/types.h"

#include <cstdint>
#include <span>
#include <vector>

namespace hairbench::kernels {

using Mat3f = Eigen::Matrix3f;

// Where one drawn vertex sits on its strand's nodes (indices within the strand):
//  - Segment: between node `a` and node a+1, at fraction t of that segment, plus `offset`,
//    its rest position less the segment's point at t;
//  - Head: rigid with the head, head · rest: a pinned vertex (a node too, which the
//    model moves with the head), and every vertex of a static strand.
struct NodeSpan {
  enum class Kind : std::uint8_t { Segment, Head };
  Kind kind = Kind::Head;
  std::int32_t a = 0;
  float t = 0.0f;
  Vec3f offset = Vec3f::Zero();
};

// A groom laid out as simulated nodes: `nodes` is the groom the model simulates (same
// strands and regions, `count` nodes a strand where the pins allow; a node's w is that
// of the drawn vertex it lies on or after, 0 where it is a pinned vertex), `span` one
// entry per drawn vertex.
struct NodeLayout {
  Groom nodes;
  std::vector<NodeSpan> span;
  std::size_t static_strands = 0;  // strands held static (layout_nodes' tied_static)
};

// Lays every strand of `drawn` out as `count` nodes (at least its anchors: first, last and
// pinned vertices). Free nodes go to the free stretches between anchors in proportion to
// their arc length (largest remainders, ties to the earlier stretch); a stretch between
// two adjacent pinned vertices is rigid and gets none. With `tied_static`, a strand with a
// pinned vertex after a free one (a tip tied to the head, a pin in the middle) is static:
// every node and vertex of it rigid with the head, as §6.3's constraints declare
// "individual strands and parts of strands" static, for a model that is a tree grown from
// the root and cannot honour a second pin (the forest, §4.2).
NodeLayout layout_nodes(const Groom& drawn, int count, bool tied_static = false);

// One strand's drawn vertices from its nodes (§5.5 with rest offsets). Each node segment
// j turns its rest frame by Q_j, the head's rotation carried down the strand by parallel
// transport: Q_j = T(Q_{j-1} e_j -> d_j) Q_{j-1}, Q_{-1} the head's rotation, e_j and d_j
// the segment's rest and current unit directions and T the smallest rotation between
// two directions, so the segments' twist follows the head and bends are turned, not
// spun. A node's frame is halfway between its two segments' and a drawn vertex's frame
// is interpolated (slerp) between its segment's two nodes', so drawn vertices on either
// side of a bent node turn alike. A drawn vertex is lerp(P_a, P_{a+1}, t) + R offset, R
// its frame; one rigid with the head is head · rest.
// `frame` is scratch of one entry per node.
void draw_from_nodes(std::span<const Vec4f> node_pos, std::span<const Vec4f> node_rest,
                     std::span<const NodeSpan> span, std::span<const Vec4f> drawn_rest, const Affine3f& head,
                     std::span<Quatf> frame, std::span<Vec4f> drawn);

}  // namespace hairbench::kernels
