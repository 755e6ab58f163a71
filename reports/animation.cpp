#include "reports/animation.h"

#include "reports/packing.h"

#include <zlib.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <stdexcept>

namespace hairbench::animation {

namespace {

[[noreturn]] void fail(std::string_view code, const std::string& why) {
  throw std::runtime_error("animation data \"" + std::string(code.substr(0, 16)) + "\": " + why);
}

// The prediction of coordinate i of frame f from frame f-1 (`prev`, null in frame 0) and
// the coordinates of frame f before it: where vertex v's parent moved, v moves too, so a
// strand swinging rigidly or holding still costs one byte a coordinate, most of them 0.
std::int64_t predict(std::span<const std::int32_t> cur, const std::int32_t* prev, std::size_t i, bool root) {
  if (!prev) return root ? 0 : cur[i - 3];
  return root ? prev[i] : std::int64_t(prev[i]) + cur[i - 3] - prev[i - 3];
}

// Per coordinate of a frame: whether it belongs to a strand's first vertex.
std::vector<bool> roots(std::span<const std::uint32_t> sizes) {
  std::vector<bool> out;
  for (std::uint32_t n : sizes)
    for (std::uint32_t v = 0; v < n; ++v) out.insert(out.end(), 3, v == 0);
  return out;
}

}  // namespace

int stride(int frames) { return std::max(1, (frames + kMaxFrames - 1) / kMaxFrames); }

std::vector<std::uint32_t> picked_vertices(std::uint32_t size) {
  std::vector<std::uint32_t> out;
  if (size <= kVertices) {
    for (std::uint32_t v = 0; v < size; ++v) out.push_back(v);
    return out;
  }
  for (std::uint32_t k = 0; k < kVertices; ++k)
    out.push_back(static_cast<std::uint32_t>((std::uint64_t(k) * (size - 1) + (kVertices - 1) / 2) / (kVertices - 1)));
  return out;
}

std::vector<std::uint32_t> spread_strands(std::size_t candidates) {
  const std::size_t every = std::max<std::size_t>(1, (candidates + kSpreadStrands - 1) / kSpreadStrands);
  std::vector<std::uint32_t> out;
  for (std::size_t s = 0; s < candidates; s += every) out.push_back(static_cast<std::uint32_t>(s));
  return out;
}

std::vector<Named> named_strands(const verdict::Verdict& v, const std::string& model, std::size_t candidates) {
  std::vector<Named> out;
  auto name = [&](std::uint32_t s, const char* why) {
    if (s < candidates) out.push_back({s, model, why});
  };
  if (v.stretch.frames_above > 0) name(v.stretch.worst_strand, "the worst stretched edge");
  if (!v.settle.decays && v.settle.spread.strands > 0)
    name(v.settle.spread.strand, "the most motion that does not settle");
  if (v.back.deformed) name(v.back.worst_strand, "the farthest from its rest twin");
  return out;
}

std::vector<std::uint32_t> drawn_strands(std::size_t candidates, const std::vector<Named>& named) {
  std::vector<std::uint32_t> out = spread_strands(candidates);
  for (const Named& n : named) out.push_back(n.strand);
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

Recorder::Recorder(const Groom& groom, std::size_t candidates) {
  for (std::size_t s = 0; s < candidates; ++s) {
    begin_.push_back(static_cast<std::uint32_t>(per_frame_));
    for (std::uint32_t v : picked_vertices(groom.strand_size(s))) {
      vertex_.push_back(groom.strand_begin(s) + v);
      per_frame_ += 3;
    }
  }
  begin_.push_back(static_cast<std::uint32_t>(per_frame_));
}

void Recorder::add(std::span<const Vec4f> positions, const Affine3f& head) {
  if (ended_) return;
  const Affine3f to_head = head.inverse();
  scratch_.resize(per_frame_);
  for (std::size_t i = 0; i < vertex_.size(); ++i) {
    const Vec3f p = to_head * Vec3f(positions[vertex_[i]].head<3>());
    for (int a = 0; a < 3; ++a) {
      const double x = p[a];
      if (!(std::abs(x) <= kMaxMetres)) {
        ended_ = true;
        return;
      }
      scratch_[3 * i + a] = static_cast<std::int16_t>(std::lround(x / kUnitMetres));
    }
  }
  q_.insert(q_.end(), scratch_.begin(), scratch_.end());
  ++frames_;
}

std::string Recorder::encode(std::span<const std::uint32_t> strands) const {
  std::vector<std::uint32_t> sizes;
  for (std::uint32_t s : strands) sizes.push_back((begin_[s + 1] - begin_[s]) / 3);
  std::vector<std::int32_t> q;
  for (int f = 0; f < frames_; ++f)
    for (std::uint32_t s : strands)
      q.insert(q.end(), q_.begin() + f * per_frame_ + begin_[s], q_.begin() + f * per_frame_ + begin_[s + 1]);
  return animation::encode(q, sizes);
}

std::string encode(std::span<const std::int32_t> q, std::span<const std::uint32_t> sizes) {
  const std::vector<bool> root = roots(sizes);
  const std::size_t n = root.size();
  if (n == 0 || q.size() % n) throw std::invalid_argument("animation::encode: frames of unequal length");
  std::string bytes;
  for (std::size_t f = 0; f * n < q.size(); ++f) {
    const std::span<const std::int32_t> cur = q.subspan(f * n, n);
    const std::int32_t* prev = f ? q.data() + (f - 1) * n : nullptr;
    for (std::size_t i = 0; i < n; ++i) append_zigzag(bytes, cur[i] - predict(cur, prev, i, root[i]));
  }
  uLongf packed_size = compressBound(bytes.size());
  std::string packed(packed_size, '\0');
  if (compress2(reinterpret_cast<Bytef*>(packed.data()), &packed_size, reinterpret_cast<const Bytef*>(bytes.data()),
                bytes.size(), Z_BEST_COMPRESSION) != Z_OK)
    throw std::runtime_error("animation::encode: zlib failed");
  packed.resize(packed_size);
  return base64_encode(packed);
}

std::vector<std::int32_t> decode(std::string_view code, std::span<const std::uint32_t> sizes) {
  std::string packed;
  try {
    packed = base64_decode(code);
  } catch (const std::invalid_argument& e) {
    fail(code, e.what());
  }
  z_stream zs{};
  if (inflateInit(&zs) != Z_OK) fail(code, "zlib failed");
  zs.next_in = reinterpret_cast<Bytef*>(packed.data());
  zs.avail_in = static_cast<uInt>(packed.size());
  std::string bytes;
  int rc = Z_OK;
  char buf[1 << 14];
  while (rc == Z_OK) {
    zs.next_out = reinterpret_cast<Bytef*>(buf);
    zs.avail_out = sizeof buf;
    rc = inflate(&zs, Z_NO_FLUSH);
    bytes.append(buf, sizeof buf - zs.avail_out);
  }
  inflateEnd(&zs);
  if (rc != Z_STREAM_END) fail(code, "not a complete zlib stream");
  const std::vector<bool> root = roots(sizes);
  const std::size_t n = root.size();
  if (n == 0) fail(code, "no strands to decode into");
  std::vector<std::int64_t> r;
  try {
    r = read_zigzag(bytes);
  } catch (const std::invalid_argument& e) {
    fail(code, e.what());
  }
  if (r.size() % n) fail(code, "not a whole number of frames");
  std::vector<std::int32_t> q(r.size());
  for (std::size_t f = 0; f * n < q.size(); ++f) {
    const std::span<const std::int32_t> cur(q.data() + f * n, n);
    const std::int32_t* prev = f ? q.data() + (f - 1) * n : nullptr;
    for (std::size_t i = 0; i < n; ++i)
      q[f * n + i] = static_cast<std::int32_t>(r[f * n + i] + predict(cur, prev, i, root[i]));
  }
  return q;
}

}  // namespace hairbench::animation
