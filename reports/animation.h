// The frames of report.html's motion player (docs/report-schema.md#animation): a few
// strands of every run at a fixed frame stride, in the head's frame, at 1 mm, each
// frame predicted from the one before it, as zigzag varints, deflated and base64'd.
//
// What is drawn, and why so little: a default comparison is 112 runs; at 200 strands,
// 16 vertices and every frame it would be hundreds of megabytes, against a budget of a
// few (the page carries the frames a second time). A 210-pixel panel shows the head and
// three strand lengths around it at about 2 mm a pixel, so 2 mm steps move a strand by
// a pixel; eight vertices draw a strand a few dozen pixels long; and 48 frames of a 4 s
// script, 12 a second, still show a swing (the slowest modes of the shipped grooms are
// around 1 Hz) though not a flutter near the frame rate, which the jaggedness series
// measures instead.
#pragma once

#include "core/groom.h"
#include "core/types.h"
#include "reports/verdict.h"

#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace hairbench::animation {

inline constexpr double kUnitMetres = 2e-3;
// The frame stride is the smallest that keeps at most this many frames a run.
inline constexpr int kMaxFrames = 48;
// Strands spread over the groom (every k-th of the candidates), before the ones the
// verdicts name.
inline constexpr std::size_t kSpreadStrands = 24;
// Vertices drawn per strand: the root, the tip and evenly spaced ones between.
inline constexpr std::uint32_t kVertices = 8;

int stride(int frames);
// Indices within a strand of `size` vertices of the ones drawn (all when size <= kVertices).
std::vector<std::uint32_t> picked_vertices(std::uint32_t size);
// Every k-th of the first `candidates` strands, at most kSpreadStrands.
std::vector<std::uint32_t> spread_strands(std::size_t candidates);

// A strand a run's verdict names, to be drawn in every panel: the worst stretched edge's
// (when some frame was over the limit), the one holding the most motion that does not
// settle, the one farthest from its rest twin (when it did not return).
struct Named {
  std::uint32_t strand;
  std::string model, why;
};
std::vector<Named> named_strands(const verdict::Verdict& v, const std::string& model, std::size_t candidates);
// The spread strands and the named ones, sorted, each once.
std::vector<std::uint32_t> drawn_strands(std::size_t candidates, const std::vector<Named>& named);

// One run's frames of the candidate strands (the groom's first `candidates`: the guides
// where follow hairs are rebuilt from them), quantised, until a frame has a coordinate
// it draws that is not finite or beyond kMaxMetres from the head: the run is drawn up to
// there.
class Recorder {
 public:
  static constexpr double kMaxMetres = 30.0;  // a blown-up strand, not hair
  Recorder() = default;
  Recorder(const Groom& groom, std::size_t candidates);
  void add(std::span<const Vec4f> positions, const Affine3f& head);
  int frames() const { return frames_; }
  bool ended() const { return ended_; }
  // The recorded frames of `strands` (candidate indices), encoded.
  std::string encode(std::span<const std::uint32_t> strands) const;

 private:
  std::vector<std::uint32_t> begin_, vertex_;  // per candidate: offset into a frame, and its groom vertices
  std::size_t per_frame_ = 0;                  // coordinates a frame holds
  std::vector<std::int16_t> q_;                // frame after frame
  std::vector<std::int16_t> scratch_;
  int frames_ = 0;
  bool ended_ = false;
};

// Frames of equal length (`per_frame` coordinates each, every one a list of strands of
// `sizes[s]` vertices) as the report's string, and back (throws std::runtime_error on a
// malformed code).
std::string encode(std::span<const std::int32_t> q, std::span<const std::uint32_t> sizes);
std::vector<std::int32_t> decode(std::string_view code, std::span<const std::uint32_t> sizes);

inline constexpr const char* kEncoding =
    "runs[].animation.data and scenarios[].animation.reference.data: padded base64 of a zlib (RFC 1950) "
    "stream of LEB128 varints; each varint is a zigzag-mapped residual r = q - p, q = round(coordinate in the "
    "head's frame / 2e-3 m), coordinates frame after frame, in each frame strand after strand "
    "(scenarios[].animation.strands), each strand's drawn vertices (scenarios[].animation.vertices) x y z; "
    "the prediction p of a coordinate at vertex v of a strand in frame f: in frame 0, 0 for v = 0 and the same "
    "axis of vertex v-1 after; in later frames, the same coordinate in frame f-1 plus (for v > 0) the change "
    "of vertex v-1 from frame f-1 to f";

}  // namespace hairbench::animation
