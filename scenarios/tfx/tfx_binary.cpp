// .tfx reader and writer, from the byte layouts of scenarios/assets/tressfx/README.md.
#include "scenarios/tfx/tfx.h"

#include "core/error.h"

#include <bit>
#include <cmath>
#include <fstream>
#include <iomanip>
#include <iterator>
#include <limits>
#include <sstream>

namespace hairbench::tfx {
namespace {

// .tfx 3.x header: f32 version, u32 numGuideHairStrands, u32 numVerticesPerStrand,
// u32 numFollowHairsPerGuideHair, u32 bothEndsImmovable, u32 reserved1[31], six u32
// offsets, u32 reserved2[32].
namespace v3 {
constexpr std::size_t kHeaderSize = 296;
constexpr std::size_t kBothEndsImmovable = 16;
constexpr std::size_t kVertexOffset = 20 + 31 * 4;  // the first of the six, after reserved1
constexpr std::size_t kStride = 12;                 // float3
}  // namespace v3

// .tfx 4.x header: f32 version, u32 numHairStrands, u32 numVerticesPerStrand, then u32
// offsets of vertex positions, strand UVs, vertex UVs, strand thickness, vertex colours,
// and u32 reserved[32].
namespace v4 {
constexpr std::size_t kHeaderSize = 160;
constexpr std::size_t kVertexOffset = 12;
constexpr std::size_t kStrandUvOffset = 16;
constexpr std::size_t kVertexUvOffset = 20;
constexpr std::size_t kStrandThicknessOffset = 24;
constexpr std::size_t kVertexColorOffset = 28;
constexpr std::size_t kStride = 16;         // float4
constexpr std::size_t kStrandUvStride = 8;  // float2
}  // namespace v4

constexpr std::size_t kStrandCount = 4;
constexpr std::size_t kVertexCount = 8;

// Reads the little-endian file bytes whatever the host byte order, and reports problems
// at a byte offset.
class Bytes {
 public:
  Bytes(std::span<const std::byte> bytes, const std::string& name) : b_(bytes), name_(name) {}

  std::uint32_t u32(std::size_t at) const {
    std::uint32_t v = 0;
    for (std::size_t i = 0; i < 4; ++i) v |= std::to_integer<std::uint32_t>(b_[at + i]) << (8 * i);
    return v;
  }
  float f32(std::size_t at) const { return std::bit_cast<float>(u32(at)); }

  [[noreturn]] void fail(std::size_t at, const std::string& what) const {
    throw InputError(name_, "byte " + std::to_string(at), what);
  }

  void require_header(std::size_t header_size, const char* format) const {
    if (b_.size() < header_size)
      fail(b_.size(), "truncated header: a " + std::string(format) + " header is " +
                          std::to_string(header_size) + " bytes, the file has " +
                          std::to_string(b_.size()));
  }

  // Checks that `count` elements of `stride` bytes fit at the offset stored at
  // `offset_field`; a block running past the end is reported at `blame`. The caller has
  // capped `count` at 2^32, so the 64-bit end below cannot overflow.
  std::size_t block(std::size_t offset_field, std::size_t header_size, std::uint64_t count,
                    std::size_t stride, const std::string& what, std::size_t blame) const {
    const std::uint32_t offset = u32(offset_field);
    if (offset < header_size)
      fail(offset_field, what + " offset " + std::to_string(offset) + " points into the " +
                             std::to_string(header_size) + "-byte header");
    if (offset >= b_.size())
      fail(offset_field, what + " offset " + std::to_string(offset) +
                             " is past the end of the file (" + std::to_string(b_.size()) +
                             " bytes)");
    const std::uint64_t end = offset + count * stride;
    if (end > b_.size())
      fail(blame, std::to_string(count) + " " + what + " entries of " + std::to_string(stride) +
                      " bytes at offset " + std::to_string(offset) + " need " +
                      std::to_string(end) + " bytes, the file has " + std::to_string(b_.size()));
    return offset;
  }

  // Blocks hairbench does not read: their sizes are not in the README, so only the start
  // of a present block (offset != 0) is checked.
  void optional_block_start(std::size_t offset_field, const std::string& what) const {
    const std::uint32_t offset = u32(offset_field);
    if (offset != 0 && offset >= b_.size())
      fail(offset_field, what + " offset " + std::to_string(offset) +
                             " is past the end of the file (" + std::to_string(b_.size()) +
                             " bytes)");
  }

 private:
  std::span<const std::byte> b_;
  const std::string& name_;
};

// A float for messages: "2", "-0.5", with the digits to tell any two floats apart.
std::string float_text(float v) {
  std::ostringstream os;
  os << std::setprecision(9) << v;
  return os.str();
}

std::string vertex_name(std::size_t s, std::size_t i) {
  return "strand " + std::to_string(s) + " vertex " + std::to_string(i);
}

// Strand and vertex counts, checked before anything is allocated: the vertex array can
// then never be larger than what the file's bytes hold (positions are at least 12 bytes
// per vertex in the file and 16 in memory).
void read_counts(const Bytes& in, TfxStrands& out) {
  out.strand_count = in.u32(kStrandCount);
  out.vertices_per_strand = in.u32(kVertexCount);
  if (out.strand_count == 0) in.fail(kStrandCount, "the file has zero strands");
  if (out.vertices_per_strand < 2)
    in.fail(kVertexCount, std::to_string(out.vertices_per_strand) +
                              " vertices per strand: a strand needs at least 2");
  const std::uint64_t vertices = std::uint64_t{out.strand_count} * out.vertices_per_strand;
  if (vertices > std::numeric_limits<std::uint32_t>::max())
    in.fail(kStrandCount, std::to_string(out.strand_count) + " strands x " +
                              std::to_string(out.vertices_per_strand) +
                              " vertices overflow the 32-bit vertex index");
}

// Reads the positions block (float3 or float4 per vertex, strand-major);
// `inverse_mass(at, i)` gives the w of vertex i of a strand stored at byte `at`. Every
// vertex is checked as it is read, each problem reported at the vertex's byte offset.
template <class InverseMass>
void read_positions(const Bytes& in, std::size_t offset, std::size_t stride, TfxStrands& out,
                    InverseMass inverse_mass) {
  const std::size_t n = out.vertices_per_strand;
  out.positions.resize(std::size_t{out.strand_count} * n);
  for (std::size_t s = 0; s < out.strand_count; ++s) {
    for (std::size_t i = 0; i < n; ++i) {
      const std::size_t k = s * n + i;
      const std::size_t at = offset + k * stride;
      const Vec3f p(in.f32(at), in.f32(at + 4), in.f32(at + 8));
      if (!p.allFinite()) in.fail(at, vertex_name(s, i) + ": position is NaN or infinite");
      // Coincident vertices (a zero-length edge) are read as they are: the asset loaders
      // repair or refuse them with the groom's other defects (repair_groom).
      out.positions[k] = Vec4f(p.x(), p.y(), p.z(), inverse_mass(at, i));
    }
  }
}

TfxStrands parse_v3(const Bytes& in) {
  in.require_header(v3::kHeaderSize, ".tfx 3.x");
  TfxStrands out;
  out.version_major = 3;
  read_counts(in, out);
  const std::uint32_t both_ends = in.u32(v3::kBothEndsImmovable);
  if (both_ends > 1)
    in.fail(v3::kBothEndsImmovable,
            "bothEndsImmovable is " + std::to_string(both_ends) + " (expected 0 or 1)");
  const std::uint64_t vertices = std::uint64_t{out.strand_count} * out.vertices_per_strand;
  const std::size_t offset =
      in.block(v3::kVertexOffset, v3::kHeaderSize, vertices, v3::kStride, "vertex", kStrandCount);
  static constexpr const char* kOtherBlocks[] = {"perStrandThickness", "perStrandTexCoord",
                                                 "perVertexColor", "guideHairStrand",
                                                 "perVertexTexCoord"};
  for (std::size_t b = 0; b < std::size(kOtherBlocks); ++b)
    in.optional_block_start(v3::kVertexOffset + 4 * (b + 1), kOtherBlocks[b]);
  // numFollowHairsPerGuideHair is not read: follow hairs come from the .tfxproj section
  // (followHairsPerGuide), which is what the TressFX sample projects configure.
  const std::size_t last = out.vertices_per_strand - 1;
  // 3.x stores no masses: vertices 0 and 1 are pinned (the root edge, which gives each
  // strand its root frame) and, with bothEndsImmovable, the last vertex as well.
  read_positions(in, offset, v3::kStride, out, [&](std::size_t, std::size_t i) {
    return i < 2 || (both_ends == 1 && i == last) ? 0.0f : 1.0f;
  });
  return out;
}

void read_strand_uv(const Bytes& in, TfxStrands& out) {
  const std::size_t uv = in.block(v4::kStrandUvOffset, v4::kHeaderSize, out.strand_count,
                                  v4::kStrandUvStride, "strand UV", v4::kStrandUvOffset);
  out.strand_uv.resize(out.strand_count);
  for (std::size_t s = 0; s < out.strand_count; ++s) {
    const std::size_t at = uv + s * v4::kStrandUvStride;
    out.strand_uv[s] = Eigen::Vector2f(in.f32(at), in.f32(at + 4));
    if (!out.strand_uv[s].allFinite())
      in.fail(at, "strand " + std::to_string(s) + ": UV is NaN or infinite");
  }
}

TfxStrands parse_v4(const Bytes& in) {
  in.require_header(v4::kHeaderSize, ".tfx 4.x");
  TfxStrands out;
  out.version_major = 4;
  read_counts(in, out);
  const std::uint64_t vertices = std::uint64_t{out.strand_count} * out.vertices_per_strand;
  const std::size_t offset = in.block(v4::kVertexOffset, v4::kHeaderSize, vertices, v4::kStride,
                                      "vertex position", kStrandCount);
  in.optional_block_start(v4::kVertexUvOffset, "vertex UV");
  in.optional_block_start(v4::kStrandThicknessOffset, "strand thickness");
  in.optional_block_start(v4::kVertexColorOffset, "vertex colour");
  // w is the file's inverse mass, but vertices 0 and 1 are pinned whatever it says: some
  // exporters pin only vertex 0, and every hairbench model (Han & Harada §3.2,
  // validate_groom) takes the strand's root frame from the pinned edge P_0 P_1.
  read_positions(in, offset, v4::kStride, out, [&](std::size_t at, std::size_t i) {
    const float w = in.f32(at + 12);
    if (!std::isfinite(w)) in.fail(at + 12, "inverse mass is NaN or infinite");
    if (w < 0.0f) in.fail(at + 12, "negative inverse mass " + float_text(w));
    return i < 2 ? 0.0f : w;
  });
  if (in.u32(v4::kStrandUvOffset) != 0) read_strand_uv(in, out);
  return out;
}

std::vector<std::byte> read_file(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary | std::ios::ate);
  if (!in) throw InputError(file.string(), "file", "cannot be opened");
  const std::streamoff size = in.tellg();
  if (size < 0) throw InputError(file.string(), "file", "cannot be read");
  in.seekg(0);
  std::vector<std::byte> bytes(static_cast<std::size_t>(size));
  in.read(reinterpret_cast<char*>(bytes.data()), size);
  if (!in) throw InputError(file.string(), "file", "read error");
  return bytes;
}

void put_u32(std::vector<std::byte>& out, std::size_t at, std::uint32_t v) {
  for (std::size_t i = 0; i < 4; ++i) out[at + i] = static_cast<std::byte>((v >> (8 * i)) & 0xffu);
}
void put_f32(std::vector<std::byte>& out, std::size_t at, float v) {
  put_u32(out, at, std::bit_cast<std::uint32_t>(v));
}

}  // namespace

TfxStrands parse_tfx(std::span<const std::byte> bytes, const std::string& name) {
  const Bytes in(bytes, name);
  in.require_header(4, ".tfx version");
  const float version = in.f32(0);
  if (version >= 3.0f && version < 4.0f) return parse_v3(in);
  if (version >= 4.0f && version < 5.0f) return parse_v4(in);
  in.fail(0, "unknown version " + float_text(version) + " (expected 3.x or 4.x)");
}

TfxStrands read_tfx(const std::filesystem::path& file) {
  const std::vector<std::byte> bytes = read_file(file);
  return parse_tfx(bytes, file.string());
}

std::vector<std::byte> tfx_v4_bytes(const Groom& groom, const std::string& name) {
  validate_groom(groom, name);
  const std::uint32_t n = groom.strand_size(0);
  for (std::size_t s = 1; s < groom.strand_count(); ++s)
    if (groom.strand_size(s) != n)
      throw InputError(name, "strand " + std::to_string(s),
                       "has " + std::to_string(groom.strand_size(s)) + " vertices, strand 0 has " +
                           std::to_string(n) +
                           ": a .tfx file has one vertex count for all strands");
  // validate_groom guarantees offsets that fit in 32 bits, so the size arithmetic below
  // cannot overflow a 64-bit size_t.
  std::vector<std::byte> out(v4::kHeaderSize + groom.vertex_count() * v4::kStride);
  put_f32(out, 0, 4.0f);
  put_u32(out, kStrandCount, static_cast<std::uint32_t>(groom.strand_count()));
  put_u32(out, kVertexCount, n);
  put_u32(out, v4::kVertexOffset, static_cast<std::uint32_t>(v4::kHeaderSize));
  // Strand UV, vertex UV, thickness and colour offsets and the reserved words stay 0.
  for (std::size_t k = 0; k < groom.vertex_count(); ++k)
    for (int c = 0; c < 4; ++c)
      put_f32(out, v4::kHeaderSize + k * v4::kStride + 4 * static_cast<std::size_t>(c),
              groom.positions[k][c]);
  return out;
}

void write_tfx_v4(const std::filesystem::path& file, const Groom& groom) {
  const std::vector<std::byte> bytes = tfx_v4_bytes(groom, file.string());
  std::ofstream out(file, std::ios::binary | std::ios::trunc);
  if (!out) throw InputError(file.string(), "file", "cannot be opened for writing");
  out.write(reinterpret_cast<const char*>(bytes.data()),
            static_cast<std::streamsize>(bytes.size()));
  if (!out) throw InputError(file.string(), "file", "write error");
}

}  // namespace hairbench::tfx
