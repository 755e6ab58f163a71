// TressFX-style follow hairs: copies of a guide hair displaced by a random offset that
// grows towards the tip (the .tfxproj section's followHairsPerGuide, followRadius and
// tipSeparation). The offset lives in the guide's root frame, which turns with the head,
// so the follow hairs can be rebuilt from the simulated guides every frame.
#include "scenarios/tfx/tfx.h"

#include "core/error.h"
#include "core/parallel.h"
#include "core/rng.h"

#include <cmath>
#include <limits>
#include <stdexcept>

namespace hairbench::tfx {
namespace {

using Vec3d = Eigen::Vector3d;

// Uniform in the unit disk by rejection from the square: no sqrt/sin/cos whose last bit
// could differ between C libraries.
Eigen::Vector2d unit_disk(SplitMix64& rng) {
  for (;;) {
    const double x = rng.symmetric(), y = rng.symmetric();
    if (x * x + y * y <= 1.0) return {x, y};
  }
}

Vec3d xyz(const Vec4f& p) { return p.head<3>().cast<double>(); }

// sin of the angle between `a` and the unit vector `t` (0 when `a` is 0).
double off_axis(const Vec3d& a, const Vec3d& t) {
  const double n = a.norm();
  return n > 0.0 ? a.cross(t).norm() / n : 0.0;
}

// An anchor at a smaller angle than this to the root edge orients the frame too poorly.
constexpr double kMinAnchorSine = 0.05;
// Any anchor at least this far off the root edge is good enough to stop looking.
constexpr double kGoodAnchorSine = 0.5;

// The point whose direction from the guide root fixes the guide's root normal. The guide
// alone cannot fix it (a straight strand looks the same from every side), but the root of
// another guide can: both roots are pinned to the head, so the direction between them
// turns exactly with the head, like TressFX's per-strand root rotation, and not with the
// guide's own swinging. The first guide after `g` (cyclically) whose root is well off g's
// root edge is taken, else the best one; only a groom without any such guide falls back on
// the guide's own vertex farthest off its root edge, which turns with the strand.
std::uint32_t choose_anchor(const Groom& guides, std::size_t g) {
  const std::uint32_t root = guides.strand_begin(g);
  const Vec3d p0 = xyz(guides.positions[root]);
  const Vec3d t = (xyz(guides.positions[root + 1]) - p0).normalized();
  std::uint32_t best = root;
  double best_sine = kMinAnchorSine;
  const auto consider = [&](std::uint32_t candidate) {
    const double sine = off_axis(xyz(guides.positions[candidate]) - p0, t);
    if (sine >= best_sine) {
      best = candidate;
      best_sine = sine;
    }
    return sine >= kGoodAnchorSine;
  };
  const std::size_t strands = guides.strand_count();
  for (std::size_t k = 1; k < strands; ++k)
    if (consider(guides.strand_begin((g + k) % strands))) return best;
  if (best != root) return best;
  for (std::uint32_t i = 2; i < guides.strand_size(g); ++i) consider(root + i);
  if (best == root)
    throw InputError("follow hairs", "guide strand " + std::to_string(g),
                     "nothing orients its follow hairs: the strand is straight and no other "
                     "guide root lies off its root edge");
  return best;
}

Vec3d any_perpendicular(const Vec3d& t) {
  const Vec3d axis = std::abs(t.x()) < 0.5 ? Vec3d::UnitX() : Vec3d::UnitY();
  return t.cross(axis).normalized();
}

// `v` with its component along unit `t` removed, normalised; any perpendicular of `t`
// where nothing is left of `v`.
Vec3d perpendicular_part(const Vec3d& v, const Vec3d& t) {
  const Vec3d p = v - v.dot(t) * t;
  const double n = p.norm();
  return n > 1e-12 * (1.0 + v.norm()) ? Vec3d(p / n) : any_perpendicular(t);
}

struct Frame {
  Vec3d t, n, b;
};

// The guide's root frame: the tangent along the root edge, the normal towards the anchor
// (perpendicular to the tangent) and the binormal t x n. Root and anchor are pinned, so
// the frame turns exactly with the head. (A zero root edge cannot reach here: grooms are
// validated and the root edge is pinned.)
Frame root_frame(std::span<const Vec4f> strand, const Vec3d& anchor) {
  Frame f;
  const Vec3d edge = xyz(strand[1]) - xyz(strand[0]);
  f.t = edge.normalized();
  f.n = perpendicular_part(anchor - xyz(strand[0]), f.t);
  f.b = f.t.cross(f.n);
  return f;
}

void check_arguments(int per_guide, double radius, double tip_separation) {
  if (per_guide < 0) throw std::invalid_argument("follow hairs: negative count per guide");
  if (!std::isfinite(radius) || radius < 0.0)
    throw std::invalid_argument("follow hairs: radius must be finite and >= 0");
  if (!std::isfinite(tip_separation) || tip_separation < 0.0)
    throw std::invalid_argument("follow hairs: tip separation must be finite and >= 0");
  // The largest offset, at the tip, is stored as float.
  if (radius * (1.0 + tip_separation) > std::numeric_limits<float>::max())
    throw std::invalid_argument("follow hairs: offsets beyond float range");
}

// Follow strands and their vertices are indexed with 32 bits, like the groom's.
void check_capacity(const FollowHairs& out, const Groom& guides, std::size_t first,
                    std::size_t last, int per_guide) {
  const std::uint64_t added =
      std::uint64_t{guides.strand_offsets[last] - guides.strand_offsets[first]} *
      static_cast<std::uint64_t>(per_guide);
  if (out.vertex_count() + guides.vertex_count() + added >
      std::numeric_limits<std::uint32_t>::max())
    throw InputError("follow hairs", "count",
                     "guides and follow hairs together exceed 2^32 vertices");
}

// Checks everything apply_follow_hairs indexes with, so that a FollowHairs assembled by
// hand cannot make it read or write out of bounds.
void check_layout(const FollowHairs& f, std::size_t guide_vertices, std::size_t out_vertices) {
  const auto fail = [](const char* what) {
    throw std::invalid_argument(std::string("apply_follow_hairs: ") + what);
  };
  if (f.guide_offsets.empty() || f.guide_offsets.back() != guide_vertices)
    fail("guide positions do not match the guide layout");
  if (f.vertex_count() != out_vertices) fail("output size differs from the follow vertex count");
  if (f.anchor.size() != f.guide.size() || f.follow_offsets.size() != f.guide.size() + 1 ||
      f.follow_offsets.back() != f.vertex_count())
    fail("inconsistent follow strand arrays");
  for (std::size_t g = 1; g < f.guide_offsets.size(); ++g)
    if (f.guide_offsets[g] < f.guide_offsets[g - 1]) fail("guide offsets decrease");
  const std::size_t guides = f.guide_offsets.size() - 1;
  for (std::size_t s = 0; s < f.strand_count(); ++s) {
    if (f.guide[s] >= guides || f.anchor[s] >= guide_vertices) fail("guide or anchor out of range");
    const std::uint32_t n = f.guide_offsets[f.guide[s] + 1] - f.guide_offsets[f.guide[s]];
    if (f.follow_offsets[s] > f.follow_offsets[s + 1] ||
        f.follow_offsets[s + 1] - f.follow_offsets[s] != n)
      fail("a follow strand's vertex count differs from its guide's");
  }
}

}  // namespace

void append_follow_hairs(FollowHairs& out, const Groom& guides, std::size_t first, std::size_t last,
                         int per_guide, double radius, double tip_separation, std::uint64_t seed) {
  check_arguments(per_guide, radius, tip_separation);
  if (out.guide_offsets != guides.strand_offsets)
    throw std::invalid_argument("append_follow_hairs: FollowHairs made for another guide layout");
  if (first > last || last > guides.strand_count())
    throw std::invalid_argument("append_follow_hairs: strand range out of bounds");
  validate_groom(guides, "follow hair guides");
  check_capacity(out, guides, first, last, per_guide);
  if (per_guide == 0) return;
  SplitMix64 rng(seed);
  for (std::size_t g = first; g < last; ++g) {
    const std::uint32_t anchor = choose_anchor(guides, g);
    const std::uint32_t n = guides.strand_size(g);
    for (int k = 0; k < per_guide; ++k) {
      // The root offset, in the (normal, binormal) plane, i.e. perpendicular to the root
      // edge; vertex i keeps it, grown by the tip separation, in the guide's root frame.
      const Eigen::Vector2d d = radius * unit_disk(rng);
      out.guide.push_back(static_cast<std::uint32_t>(g));
      out.anchor.push_back(anchor);
      for (std::uint32_t i = 0; i < n; ++i) {
        const double grow =
            1.0 + tip_separation * static_cast<double>(i) / static_cast<double>(n - 1);
        out.offsets.emplace_back(0.0f, static_cast<float>(grow * d.x()),
                                 static_cast<float>(grow * d.y()));
      }
      out.follow_offsets.push_back(static_cast<std::uint32_t>(out.offsets.size()));
    }
  }
}

FollowHairs make_follow_hairs(const Groom& guides, int per_guide, double radius,
                              double tip_separation, std::uint64_t seed) {
  FollowHairs out;
  out.guide_offsets = guides.strand_offsets;
  append_follow_hairs(out, guides, 0, guides.strand_count(), per_guide, radius, tip_separation,
                      seed);
  return out;
}

namespace {

// Built for x86-64-v4 (AVX-512) and the baseline, chosen at load time; IEEE operations
// without FMA contraction (-ffp-contract=off) give the same bits in either.
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__)
#define FOLLOW_CLONES __attribute__((target_clones("arch=x86-64-v4", "default")))
#else
#define FOLLOW_CLONES
#endif

// Follow strands [first, last). A guide's follow strands are consecutive and share its
// anchor, so its root frame is computed once for all of them (the same bits as once per
// strand: the same inputs).
FOLLOW_CLONES void apply_range(const FollowHairs& follow, std::span<const Vec4f> guide_positions,
                 std::span<Vec4f> out_follow_positions, std::size_t first, std::size_t last) {
  std::uint32_t frame_guide = std::numeric_limits<std::uint32_t>::max(), frame_anchor = 0;
  Frame f{Vec3d::Zero(), Vec3d::Zero(), Vec3d::Zero()};
  for (std::size_t s = first; s < last; ++s) {
    const std::uint32_t g = follow.guide[s];
    const std::uint32_t b = follow.guide_offsets[g];
    const std::uint32_t n = follow.guide_offsets[g + 1] - b;
    const std::span<const Vec4f> guide = guide_positions.subspan(b, n);
    if (g != frame_guide || follow.anchor[s] != frame_anchor) {
      f = root_frame(guide, xyz(guide_positions[follow.anchor[s]]));
      frame_guide = g;
      frame_anchor = follow.anchor[s];
    }
    // guide + d.x t + d.y n + d.z b, component by component in Eigen's order for that
    // expression (((g + d.x t) + d.y n) + d.z b): the same bits as the Vec3d expression,
    // in a loop GCC vectorises (as Eigen expressions it runs one vertex at a time).
    const std::uint32_t o = follow.follow_offsets[s];
    const Vec3f* off = follow.offsets.data() + o;
    Vec4f* out = out_follow_positions.data() + o;
    const double tx = f.t.x(), ty = f.t.y(), tz = f.t.z(), nx = f.n.x(), ny = f.n.y(), nz = f.n.z(), bx = f.b.x(),
                 by = f.b.y(), bz = f.b.z();
    for (std::uint32_t i = 0; i < n; ++i) {
      const double dx = off[i].x(), dy = off[i].y(), dz = off[i].z();
      const double px = ((double(guide[i].x()) + dx * tx) + dy * nx) + dz * bx;
      const double py = ((double(guide[i].y()) + dx * ty) + dy * ny) + dz * by;
      const double pz = ((double(guide[i].z()) + dx * tz) + dy * nz) + dz * bz;
      out[i] = Vec4f(static_cast<float>(px), static_cast<float>(py), static_cast<float>(pz),
                     i < 2 ? 0.0f : guide[i].w());
    }
  }
}

}  // namespace

void apply_follow_hairs(const FollowHairs& follow, std::span<const Vec4f> guide_positions,
                        std::span<Vec4f> out_follow_positions, ThreadPool* pool) {
  check_layout(follow, guide_positions.size(), out_follow_positions.size());
  // Each strand is written from the guides alone: the same bits for any split.
  const auto range = [&](std::size_t first, std::size_t last) {
    apply_range(follow, guide_positions, out_follow_positions, first, last);
  };
  if (pool)
    pool->parallel_for(follow.strand_count(), range);
  else
    range(0, follow.strand_count());
}

Groom expand_follow_hairs(const Groom& guides, const FollowHairs& follow) {
  if (follow.guide_offsets != guides.strand_offsets)
    throw std::invalid_argument("expand_follow_hairs: FollowHairs made for another guide layout");
  Groom out = guides;
  const std::size_t base = guides.vertex_count();
  out.positions.resize(base + follow.vertex_count());
  apply_follow_hairs(follow, guides.positions, std::span<Vec4f>(out.positions).subspan(base));
  for (std::size_t s = 0; s < follow.strand_count(); ++s) {
    out.strand_offsets.push_back(static_cast<std::uint32_t>(base + follow.follow_offsets[s + 1]));
    out.strand_region.push_back(guides.strand_region[follow.guide[s]]);
  }
  return out;
}

}  // namespace hairbench::tfx
