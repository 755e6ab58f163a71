// TressFX importer: the shipped AMD assets (counts, known positions, pinning, settings),
// the .tfx v4 writer's round trip, follow hairs, and every kind of malformed input.
#include "scenarios/tfx/tfx.h"

#include "core/error.h"
#include "core/parallel.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <ostream>
#include <stdexcept>
#include <string>
#include <vector>

namespace hairbench::tfx {
namespace {

namespace fs = std::filesystem;

const fs::path kAssets = HAIRBENCH_ASSET_DIR;
const fs::path kData = fs::path(HAIRBENCH_TEST_DATA_DIR) / "tfx";
const fs::path kCorpus = fs::path(HAIRBENCH_TEST_DATA_DIR).parent_path() / "fuzz" / "corpus";

// The assets and test data ship with the repository: a missing one fails the test.
// ASSERT returns from the test body, so this has to be a macro.
#define ASSERT_PRESENT(path) ASSERT_TRUE(fs::exists(path)) << "missing " << (path).string()

// Runs `f`, which must throw InputError, and returns its message.
template <class F>
std::string input_error(F&& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  ADD_FAILURE() << "no InputError thrown";
  return "";
}

// ---- hand-made .tfx images (written from the README layouts, not with the library) ----

void put_u32(std::vector<std::byte>& b, std::size_t at, std::uint32_t v) {
  for (std::size_t i = 0; i < 4; ++i) b[at + i] = static_cast<std::byte>((v >> (8 * i)) & 0xffu);
}
void put_f32(std::vector<std::byte>& b, std::size_t at, float v) {
  put_u32(b, at, std::bit_cast<std::uint32_t>(v));
}

// Strands whose vertex i is at (s, 1 + i, 0.5 i^2): no zero-length edge, all distinct.
Vec3f sample_vertex(std::size_t s, std::size_t i) {
  const float fi = static_cast<float>(i);
  return Vec3f(static_cast<float>(s), 1.0f + fi, 0.5f * fi * fi);
}

// .tfx 3.0: 296-byte header, vertex offset at byte 144, float3 positions.
std::vector<std::byte> v3_image(std::uint32_t strands, std::uint32_t n,
                                std::uint32_t both_ends = 0) {
  std::vector<std::byte> b(296 + std::size_t{strands} * n * 12);
  put_f32(b, 0, 3.0f);
  put_u32(b, 4, strands);
  put_u32(b, 8, n);
  put_u32(b, 16, both_ends);
  put_u32(b, 144, 296);
  for (std::size_t s = 0; s < strands; ++s)
    for (std::size_t i = 0; i < n; ++i)
      for (int c = 0; c < 3; ++c)
        put_f32(b, 296 + (s * n + i) * 12 + 4 * static_cast<std::size_t>(c),
                sample_vertex(s, i)[c]);
  return b;
}

// .tfx 4.0: 160-byte header, float4 positions at 160 with w = 0.5 (the file pins only
// vertex 0), then strand UVs (u, v) = (s, 0.25).
std::vector<std::byte> v4_image(std::uint32_t strands, std::uint32_t n) {
  const std::size_t uv_at = 160 + std::size_t{strands} * n * 16;
  std::vector<std::byte> b(uv_at + std::size_t{strands} * 8);
  put_f32(b, 0, 4.0f);
  put_u32(b, 4, strands);
  put_u32(b, 8, n);
  put_u32(b, 12, 160);
  put_u32(b, 16, static_cast<std::uint32_t>(uv_at));
  for (std::size_t s = 0; s < strands; ++s) {
    for (std::size_t i = 0; i < n; ++i) {
      const std::size_t at = 160 + (s * n + i) * 16;
      for (int c = 0; c < 3; ++c)
        put_f32(b, at + 4 * static_cast<std::size_t>(c), sample_vertex(s, i)[c]);
      put_f32(b, at + 12, i == 0 ? 0.0f : 0.5f);
    }
    put_f32(b, uv_at + s * 8, static_cast<float>(s));
    put_f32(b, uv_at + s * 8 + 4, 0.25f);
  }
  return b;
}

// A groom of `strands` strands rooted on a 10 cm sphere, bending downward and wiggling
// sideways, vertices 0 and 1 pinned.
Groom bent_groom(int strands, int n) {
  Groom g;
  for (int s = 0; s < strands; ++s) {
    const float a = 0.7f * static_cast<float>(s);
    const Vec3f out(std::cos(a), 0.3f, std::sin(a));
    const Vec3f root = 0.1f * out.normalized();
    std::vector<Vec3f> pts;
    for (int i = 0; i < n; ++i) {
      const float u = static_cast<float>(i) / static_cast<float>(n - 1);
      pts.push_back(root + 0.2f * u * out - Vec3f(0.0f, 0.15f * u * u, 0.0f) +
                    Vec3f(0.0f, 0.0f, 0.01f * std::sin(9.0f * u)));
    }
    g.add_strand(pts, 0);
  }
  return g;
}

// ---- shipped assets ---------------------------------------------------------------------

struct KnownVertex {
  std::uint32_t strand, vertex;
  float x, y, z;
};

struct ShippedTfx {
  const char* file;
  int version;
  std::uint32_t strands, vertices;
  bool both_ends;
  std::vector<KnownVertex> known;
};

// Expected floats read independently with Python:
//   struct.unpack_from('<3f', data, offset + (s * V + i) * stride)
// (offset = the vertex offset from the header: 296 for 3.0, 160 for 4.0; stride 12 or
// 16), printed with '%.9g' so that each literal is the exact float of the file.
const std::vector<ShippedTfx> kShipped = {
    {"ponytail/front_top.tfx",
     3,
     876,
     16,
     false,
     {{0, 0, 1.23569059f, 108.254196f, 29.6094055f},
      {0, 1, 1.26689041f, 108.422729f, 29.7617168f},
      {875, 15, -23.2450161f, 105.450836f, -5.69131565f}}},
    {"ponytail/side.tfx",
     3,
     3066,
     16,
     false,
     {{0, 0, 1.02043843f, 119.565033f, 2.11546326f},
      {1533, 8, 3.85888886f, 103.802902f, -29.8072643f},
      {3065, 15, -25.3127747f, 89.4561157f, 10.606369f}}},
    {"ponytail/back.tfx",
     3,
     517,
     16,
     true,
     {{0, 0, 4.55617952f, 67.1363297f, 30.7322388f},
      {258, 8, 2.89611983f, 83.4089127f, 41.7853966f},
      {516, 15, 8.50854206f, 79.7528152f, 36.3378944f}}},
    {"ponytail/tail.tfx",
     3,
     474,
     16,
     false,
     {{0, 1, -0.191404179f, 75.570961f, 48.7649193f},
      {237, 8, -1.20219696f, 50.8929977f, 60.5090942f},
      {473, 15, 4.90257215f, 3.2921524f, 76.5058899f}}},
    {"testhair1/TestHair1.tfx",
     3,
     10027,
     4,
     false,
     {{0, 0, 48.7915993f, 19.6662216f, 28.8274994f},
      {5013, 2, 13.5985403f, 85.4946747f, 16.0093746f},
      {10026, 3, 37.6600876f, 34.3651161f, 48.1223869f}}},
    {"ratboy_mohawk_v4.0/Ratboy_mohawk.tfx",
     4,
     2226,
     32,
     false,
     {{0, 1, 0.893056273f, 81.5450058f, 0.00950614177f},
      {1113, 16, -4.21494532f, 73.1135254f, -5.93146038f},
      {2225, 31, -3.05006599f, 32.4200287f, -16.2594414f}}},
};

// Names the file in test listings instead of dumping the struct's bytes.
void PrintTo(const ShippedTfx& a, std::ostream* os) { *os << a.file; }

class ShippedAsset : public testing::TestWithParam<ShippedTfx> {};

TEST_P(ShippedAsset, CountsPositionsAndPins) {
  const ShippedTfx& a = GetParam();
  const fs::path file = kAssets / a.file;
  ASSERT_PRESENT(file);
  const TfxStrands t = read_tfx(file);
  EXPECT_EQ(t.version_major, a.version);
  EXPECT_EQ(t.strand_count, a.strands);
  EXPECT_EQ(t.vertices_per_strand, a.vertices);
  ASSERT_EQ(t.positions.size(), std::size_t{a.strands} * a.vertices);
  for (const KnownVertex& k : a.known) {
    const Vec4f& p = t.positions[std::size_t{k.strand} * a.vertices + k.vertex];
    EXPECT_EQ(p.x(), k.x) << "strand " << k.strand << " vertex " << k.vertex;
    EXPECT_EQ(p.y(), k.y) << "strand " << k.strand << " vertex " << k.vertex;
    EXPECT_EQ(p.z(), k.z) << "strand " << k.strand << " vertex " << k.vertex;
  }
  // 3.x: vertices 0 and 1 pinned, the tip too with bothEndsImmovable (back.tfx), the rest
  // inverse mass 1. The 4.0 mohawk pins 0 and 1 itself and has w = 1 elsewhere.
  for (std::uint32_t s = 0; s < a.strands; ++s) {
    for (std::uint32_t i = 0; i < a.vertices; ++i) {
      const bool pinned = i < 2 || (a.both_ends && i == a.vertices - 1);
      ASSERT_EQ(t.positions[std::size_t{s} * a.vertices + i].w(), pinned ? 0.0f : 1.0f)
          << a.file << " strand " << s << " vertex " << i;
    }
  }
  EXPECT_EQ(t.strand_uv.size(), a.version == 4 ? a.strands : 0u);
}

INSTANTIATE_TEST_SUITE_P(Tfx, ShippedAsset, testing::ValuesIn(kShipped),
                         [](const testing::TestParamInfo<ShippedTfx>& info) {
                           return fs::path(info.param.file).stem().string();
                         });

TEST(ShippedAssets, MohawkStrandUv) {
  const fs::path file = kAssets / "ratboy_mohawk_v4.0/Ratboy_mohawk.tfx";
  ASSERT_PRESENT(file);
  // Python: struct.unpack_from('<2f', data, 1139872 + 8 * s), offsetStrandUV = 1139872.
  const TfxStrands t = read_tfx(file);
  EXPECT_EQ(t.strand_uv[0], Eigen::Vector2f(0.695898652f, 0.36622107f));
  EXPECT_EQ(t.strand_uv[2225], Eigen::Vector2f(0.0377973579f, 0.683560729f));
}

TEST(ShippedAssets, PonytailSimSettings) {
  struct Expected {
    const char* file;
    double local, global, range;
  };
  for (const Expected& e : {Expected{"front_top", 0.5, 0.2, 0.2}, Expected{"side", 0.5, 0.2, 0.2},
                            Expected{"back", 0.6, 0.2, 0.4}, Expected{"tail", 0.3, 0.1, 0.3}}) {
    const fs::path file = kAssets / "ponytail" / (std::string(e.file) + ".tfxsim");
    ASSERT_PRESENT(file);
    const SimSettings s = read_tfxsim(file);
    const std::map<std::string, double> expected{{"damping", 0.1},
                                                 {"local_stiffness", e.local},
                                                 {"global_stiffness", e.global},
                                                 {"global_range", e.range}};
    EXPECT_EQ(s.params, expected) << file;
  }
}

TEST(ShippedAssets, TestHair1SimSettings) {
  const fs::path file = kAssets / "testhair1/TestHair1.tfxsim";
  ASSERT_PRESENT(file);
  const std::map<std::string, double> expected{{"damping", 0.1},          {"local_stiffness", 0.5},
                                               {"global_stiffness", 0.1}, {"global_range", 0.2},
                                               {"length_iterations", 3},  {"local_iterations", 3}};
  EXPECT_EQ(read_tfxsim(file).params, expected);
}

TEST(ShippedAssets, PonytailProject) {
  const fs::path file = kAssets / "ponytail/ponytail.tfxproj";
  ASSERT_PRESENT(file);
  const TfxProject p = read_tfxproj(file);
  EXPECT_EQ(p.project_name, "Ponytail_model");
  ASSERT_EQ(p.sections.size(), 4u);
  const char* files[] = {"front_top", "side", "back", "tail"};
  const char* names[] = {"front-and-top", "side", "back", "tail"};
  for (std::size_t i = 0; i < 4; ++i) {
    const TfxProject::Section& s = p.sections[i];
    EXPECT_EQ(s.tfx_file, std::string(files[i]) + ".tfx");
    EXPECT_EQ(s.sim_file, std::string(files[i]) + ".tfxsim");
    EXPECT_EQ(s.name, names[i]);
    EXPECT_EQ(s.follow_per_guide, 4);
    EXPECT_EQ(s.follow_radius, 0.4);
    EXPECT_EQ(s.tip_separation, 5.0);
  }
  ASSERT_EQ(p.spheres.size(), 3u);
  EXPECT_EQ(p.spheres[0].center, Vec3f(-0.095f, 92.0f, 9.899f));
  EXPECT_EQ(p.spheres[0].radius, 26.5f);
  EXPECT_EQ(p.spheres[1].center, Vec3f(-0.405f, 93.707f, -5.111f));
  EXPECT_EQ(p.spheres[1].radius, 24.113f);
  EXPECT_EQ(p.spheres[2].center, Vec3f(-0.072f, 68.548f, -10.561f));
  EXPECT_EQ(p.spheres[2].radius, 25.5f);
  for (const Sphere& s : p.spheres) EXPECT_TRUE(s.head_attached);
  const std::map<std::string, double> iterations{{"length_iterations", 3}, {"local_iterations", 3}};
  EXPECT_EQ(p.params, iterations);
}

TEST(ShippedAssets, TestHair1Project) {
  const fs::path file = kAssets / "testhair1/TestHair1.tfxproj";
  ASSERT_PRESENT(file);
  const TfxProject p = read_tfxproj(file);
  EXPECT_EQ(p.project_name, "Test_model");
  ASSERT_EQ(p.sections.size(), 1u);
  EXPECT_EQ(p.sections[0].tfx_file, "TestHair1.tfx");
  EXPECT_EQ(p.sections[0].sim_file, "TestHair1.tfxsim");
  EXPECT_EQ(p.sections[0].name, "TestHair");
  EXPECT_EQ(p.sections[0].follow_per_guide, 4);
  EXPECT_EQ(p.sections[0].follow_radius, 1.3);
  EXPECT_EQ(p.sections[0].tip_separation, 1.0);
  EXPECT_TRUE(p.spheres.empty());
  EXPECT_TRUE(p.params.empty());
}

TEST(ShippedAssets, PonytailProjectLoadsInMetres) {
  const fs::path file = kAssets / "ponytail/ponytail.tfxproj";
  ASSERT_PRESENT(file);
  const TfxAsset a = load_tfx_project(file, {0.01f}, 7);
  const std::size_t guides = 876 + 3066 + 517 + 474;
  EXPECT_EQ(a.groom.region_names,
            (std::vector<std::string>{"front-and-top", "side", "back", "tail"}));
  ASSERT_EQ(a.groom.strand_count(), guides * 5);
  ASSERT_EQ(a.follow.strand_count(), guides * 4);
  // Guides in section order, then the follow hairs with their guide's region.
  EXPECT_EQ(a.groom.strand_region[875], 0);
  EXPECT_EQ(a.groom.strand_region[876], 1);
  EXPECT_EQ(a.groom.strand_region[guides - 1], 3);
  for (std::size_t f = 0; f < a.follow.strand_count(); ++f)
    ASSERT_EQ(a.groom.strand_region[guides + f], a.groom.strand_region[a.follow.guide[f]]);
  EXPECT_EQ(a.groom.positions[0],
            Vec4f(1.23569059f * 0.01f, 108.254196f * 0.01f, 29.6094055f * 0.01f, 0.0f));
  ASSERT_EQ(a.region_params.size(), 4u);
  const std::map<std::string, double> tail{{"damping", 0.1},          {"local_stiffness", 0.3},
                                           {"global_stiffness", 0.1}, {"global_range", 0.3},
                                           {"length_iterations", 3},  {"local_iterations", 3}};
  EXPECT_EQ(a.region_params[3], tail);
  // The project's three spheres (radius 26.5, 24.113, 25.5 cm) hold free rest vertices up
  // to 9.5 cm deep: each keeps its centre and shrinks to just short of its nearest free
  // rest vertex (kColliderClearance).
  ASSERT_EQ(a.colliders.size(), 3u);
  EXPECT_FLOAT_EQ(a.colliders[1].center.y(), 0.93707f);
  const float project_radius[3] = {0.265f, 0.24113f, 0.255f};
  for (std::size_t k = 0; k < 3; ++k) {
    const Sphere& c = a.colliders[k];
    EXPECT_TRUE(c.head_attached);
    float nearest = INFINITY;
    for (const Vec4f& p : a.groom.positions)
      if (p.w() != 0.0f) nearest = std::min(nearest, (p.head<3>() - c.center).norm());
    ASSERT_LT(nearest, project_radius[k]);
    EXPECT_EQ(c.radius, nearest * (1.0f - tfx::kColliderClearance));
    EXPECT_LT(c.radius, project_radius[k] - 0.04f);
  }
  // followRadius 0.4 cm: every follow root lies within 4 mm of its guide root.
  for (std::size_t f = 0; f < a.follow.strand_count(); ++f) {
    const Vec4f d = a.groom.positions[a.groom.strand_begin(guides + f)] -
                    a.groom.positions[a.groom.strand_begin(a.follow.guide[f])];
    ASSERT_LE(d.head<3>().norm(), 0.004f * (1.0f + 1e-5f));
  }
  validate_groom(a.groom, "ponytail");
}

TEST(ShippedAssets, TestHair1ProjectLoads) {
  const fs::path file = kAssets / "testhair1/TestHair1.tfxproj";
  ASSERT_PRESENT(file);
  const TfxAsset a = load_tfx_project(file, {0.01f}, 3);
  EXPECT_EQ(a.groom.region_names, std::vector<std::string>{"TestHair"});
  EXPECT_EQ(a.groom.strand_count(), 10027u * 5u);
  EXPECT_EQ(a.follow.strand_count(), 10027u * 4u);
  // The project sets no iteration counts: the .tfxsim's 3 and 3 stand.
  ASSERT_EQ(a.region_params.size(), 1u);
  EXPECT_EQ(a.region_params[0].at("length_iterations"), 3.0);
  EXPECT_EQ(a.region_params[0].at("local_iterations"), 3.0);
  EXPECT_TRUE(a.colliders.empty());
}

// The mohawk has stubble: 18 strands under 0.4 mm with 32 vertices each. With
// rigid_below, exactly the strands shorter than it are pinned whole, besides those the
// import's repairs pin (under 1/10 of the median strand); the others keep the file's pins
// (vertices 0 and 1).
TEST(ShippedAssets, RigidBelowPinsOnlyTheShortStrands) {
  const fs::path file = kAssets / "ratboy_mohawk_v4.0/Ratboy_mohawk.tfx";
  ASSERT_PRESENT(file);
  const TfxAsset plain = load_tfx_asset(file, {0.01f});
  const TfxAsset rigid = load_tfx_asset(file, {0.01f, DegeneratePolicy::Repair, 0.005});
  std::size_t pinned_whole = 0, short_strands = 0;
  for (std::size_t s = 0; s < plain.groom.strand_count(); ++s) {
    const std::uint32_t b = plain.groom.strand_begin(s), n = plain.groom.strand_size(s);
    double length = 0.0;
    for (std::uint32_t i = b + 1; i < b + n; ++i)
      length += (plain.groom.positions[i] - plain.groom.positions[i - 1]).head<3>().cast<double>().norm();
    bool repaired = true;
    for (std::uint32_t i = b; i < b + n; ++i) repaired &= plain.groom.positions[i].w() == 0.0f;
    const bool is_short = length < 0.005 || repaired;
    short_strands += is_short;
    bool all_pinned = true;
    for (std::uint32_t i = b; i < b + n; ++i) {
      all_pinned &= rigid.groom.positions[i].w() == 0.0f;
      ASSERT_EQ(rigid.groom.positions[i].head<3>(), plain.groom.positions[i].head<3>());
      if (!is_short) {
        ASSERT_EQ(rigid.groom.positions[i].w(), plain.groom.positions[i].w());
      }
    }
    pinned_whole += all_pinned;
    EXPECT_EQ(all_pinned, is_short) << "strand " << s;
  }
  EXPECT_EQ(pinned_whole, short_strands);
  EXPECT_GE(short_strands, 18u);
  EXPECT_LT(short_strands, 2226u / 10u);
}

TEST(ShippedAssets, SingleTfxAsset) {
  const fs::path file = kAssets / "ratboy_mohawk_v4.0/Ratboy_mohawk.tfx";
  ASSERT_PRESENT(file);
  const TfxAsset a = load_tfx_asset(file, {0.01f});
  EXPECT_EQ(a.groom.region_names, std::vector<std::string>{"Ratboy_mohawk"});
  EXPECT_EQ(a.groom.strand_count(), 2226u);
  EXPECT_EQ(a.groom.vertex_count(), 2226u * 32u);
  EXPECT_EQ(a.region_params.size(), 1u);
  EXPECT_TRUE(a.colliders.empty());
  EXPECT_TRUE(a.follow.empty());
  EXPECT_EQ(a.groom.positions[1].y(), 81.5450058f * 0.01f);
}

// ---- the small project in tests/data/tfx/mini (made by make_mini.py) -------------------

TEST(MiniProject, ReadsV3AndV4) {
  ASSERT_PRESENT(kData / "mini/a.tfx");
  ASSERT_PRESENT(kData / "mini/b.tfx");
  const TfxStrands a = read_tfx(kData / "mini/a.tfx");
  EXPECT_EQ(a.version_major, 3);
  EXPECT_EQ(a.strand_count, 3u);
  EXPECT_EQ(a.vertices_per_strand, 4u);
  EXPECT_EQ(a.positions[6], Vec4f(12.2861557f, 9.19999981f, 6.71195745f, 1.0f));
  const TfxStrands b = read_tfx(kData / "mini/b.tfx");
  EXPECT_EQ(b.version_major, 4);
  EXPECT_EQ(b.strand_count, 2u);
  // The file pins only vertex 0 (w = 1 at vertex 1): the reader pins vertex 1 too.
  EXPECT_EQ(b.positions[1], Vec4f(-4.99376202f, 9.68000031f, 10.9115696f, 0.0f));
  EXPECT_EQ(b.positions[2].w(), 1.0f);
  EXPECT_EQ(b.strand_uv, (std::vector<Eigen::Vector2f>{{0.25f, 0.5f}, {0.75f, 0.125f}}));
}

TEST(MiniProject, LoadsRegionsParamsCollidersAndFollowHairs) {
  const fs::path file = kData / "mini/mini.tfxproj";
  ASSERT_PRESENT(file);
  const TfxAsset a = load_tfx_project(file, {0.01f}, 1);
  EXPECT_EQ(a.groom.region_names, (std::vector<std::string>{"crown", "b"}));
  // Project iterations (4, 3) as defaults, each .tfxsim overriding what it sets.
  const std::map<std::string, double> crown{{"damping", 0.2},          {"local_stiffness", 0.7},
                                            {"global_stiffness", 0.3}, {"global_range", 0.25},
                                            {"length_iterations", 4},  {"local_iterations", 3}};
  const std::map<std::string, double> b{{"damping", 0.05},         {"local_stiffness", 0.4},
                                        {"global_stiffness", 0.1}, {"global_range", 0.5},
                                        {"length_iterations", 5},  {"local_iterations", 2}};
  ASSERT_EQ(a.region_params.size(), 2u);
  EXPECT_EQ(a.region_params[0], crown);
  EXPECT_EQ(a.region_params[1], b);
  // 3 + 2 guides, then 2 follow hairs for each guide of "crown" and none for "b".
  ASSERT_EQ(a.groom.strand_count(), 11u);
  EXPECT_EQ(a.follow.strand_count(), 6u);
  EXPECT_EQ(a.follow.guide, (std::vector<std::uint32_t>{0, 0, 1, 1, 2, 2}));
  EXPECT_EQ(a.groom.strand_region, (std::vector<std::uint16_t>{0, 0, 0, 1, 1, 0, 0, 0, 0, 0, 0}));
  EXPECT_EQ(a.groom.positions[0], Vec4f(10.0f * 0.01f, 10.0f * 0.01f, 0.0f, 0.0f));
  ASSERT_EQ(a.colliders.size(), 2u);
  EXPECT_EQ(a.colliders[1].center, Vec3f(1.5f, -2.0f, 3.0f) * 0.01f);
  EXPECT_EQ(a.colliders[1].radius, 4.5f * 0.01f);
  // Same seed, same groom; another seed moves the follow hairs.
  EXPECT_EQ(load_tfx_project(file, {0.01f}, 1).groom.positions, a.groom.positions);
  EXPECT_NE(load_tfx_project(file, {0.01f}, 2).groom.positions, a.groom.positions);
}

TEST(Loaders, ReportMissingFilesAndBadScale) {
  EXPECT_NE(input_error([] { read_tfx(kData / "no_such.tfx"); }).find("no_such.tfx: file:"),
            std::string::npos);
  EXPECT_NE(input_error([] { read_tfxsim(kData / "no_such.tfxsim"); }).find("no_such.tfxsim"),
            std::string::npos);
  ASSERT_PRESENT(kData / "mini/a.tfx");
  EXPECT_NE(input_error([] { load_tfx_asset(kData / "mini/a.tfx", {0.0f}); }).find("metres_per_unit"),
            std::string::npos);
  EXPECT_NE(input_error([] { load_tfx_asset(kData / "mini/a.tfx", {NAN}); }).find("metres_per_unit"),
            std::string::npos);
}

// ---- writer round trip ------------------------------------------------------------------

TEST(WriteTfxV4, RoundTripIsBitIdentical) {
  Groom g = bent_groom(7, 9);
  // Unusual inverse masses, a pinned tip and a negative zero exercise the w round trip.
  g.positions[5].w() = 0.25f;
  g.positions[8].w() = 0.0f;
  g.positions[12].w() = -0.0f;
  g.positions.back().w() = 3.0f;
  const std::vector<std::byte> bytes = tfx_v4_bytes(g, "generated");
  ASSERT_EQ(bytes.size(), 160u + 7u * 9u * 16u);
  const TfxStrands t = parse_tfx(bytes, "generated.tfx");
  EXPECT_EQ(t.version_major, 4);
  EXPECT_EQ(t.strand_count, 7u);
  EXPECT_EQ(t.vertices_per_strand, 9u);
  ASSERT_EQ(t.positions.size(), g.positions.size());
  EXPECT_EQ(std::memcmp(t.positions.data(), g.positions.data(), g.positions.size() * sizeof(Vec4f)),
            0);
  EXPECT_TRUE(t.strand_uv.empty());

  const fs::path file = fs::temp_directory_path() / "hairbench_tfx_roundtrip.tfx";
  write_tfx_v4(file, g);
  const TfxStrands back = read_tfx(file);
  fs::remove(file);
  EXPECT_EQ(
      std::memcmp(back.positions.data(), g.positions.data(), g.positions.size() * sizeof(Vec4f)),
      0);
}

TEST(WriteTfxV4, RejectsUnequalStrandsAndInvalidGrooms) {
  Groom g = bent_groom(2, 5);
  const std::vector<Vec3f> short_strand{{0, 0, 0}, {0, 1, 0}, {0, 2, 0}};
  g.add_strand(short_strand, 0);
  const std::string uneven = input_error([&] { tfx_v4_bytes(g, "uneven"); });
  EXPECT_NE(uneven.find("uneven: strand 2: has 3 vertices, strand 0 has 5"), std::string::npos)
      << uneven;
  Groom unpinned = bent_groom(1, 4);
  unpinned.positions[1].w() = 1.0f;
  EXPECT_NE(input_error([&] { tfx_v4_bytes(unpinned, "unpinned"); }).find("pinned"),
            std::string::npos);
}

// ---- follow hairs -----------------------------------------------------------------------

double max_distance(std::span<const Vec4f> a, std::span<const Vec4f> b) {
  double d = 0.0;
  for (std::size_t k = 0; k < a.size(); ++k)
    d = std::max(d, static_cast<double>((a[k] - b[k]).head<3>().norm()));
  return d;
}

TEST(FollowHairs, DeterministicBySeed) {
  const Groom g = bent_groom(6, 8);
  const FollowHairs a = make_follow_hairs(g, 4, 0.01, 2.0, 42);
  const FollowHairs b = make_follow_hairs(g, 4, 0.01, 2.0, 42);
  const FollowHairs c = make_follow_hairs(g, 4, 0.01, 2.0, 43);
  EXPECT_EQ(a.offsets, b.offsets);
  EXPECT_EQ(a.guide, b.guide);
  EXPECT_EQ(a.anchor, b.anchor);
  EXPECT_NE(a.offsets, c.offsets);
  EXPECT_EQ(a.strand_count(), 24u);
  EXPECT_EQ(a.vertex_count(), 24u * 8u);
}

TEST(FollowHairs, OffsetsArePerpendicularBoundedAndGrowTowardsTheTip) {
  const Groom g = bent_groom(5, 10);
  const double radius = 0.01, tip = 3.0;
  const FollowHairs f = make_follow_hairs(g, 6, radius, tip, 9);
  const Groom all = expand_follow_hairs(g, f);
  validate_groom(all, "expanded");
  for (std::size_t s = 0; s < f.strand_count(); ++s) {
    const std::uint32_t gb = g.strand_begin(f.guide[s]);
    const std::uint32_t fb = all.strand_begin(g.strand_count() + s);
    const Vec3f root_edge = (g.positions[gb + 1] - g.positions[gb]).head<3>().normalized();
    const Vec3f root_offset = (all.positions[fb] - g.positions[gb]).head<3>();
    EXPECT_LE(root_offset.norm(), radius * (1 + 1e-6));
    EXPECT_NEAR(root_offset.dot(root_edge), 0.0f, 1e-7f);
    const std::uint32_t n = g.strand_size(f.guide[s]);
    for (std::uint32_t i = 0; i < n; ++i) {
      const float grow =
          1.0f + static_cast<float>(tip) * static_cast<float>(i) / static_cast<float>(n - 1);
      const float d = (all.positions[fb + i] - g.positions[gb + i]).head<3>().norm();
      EXPECT_NEAR(d, grow * root_offset.norm(), 1e-6f);
      EXPECT_EQ(all.positions[fb + i].w(), i < 2 ? 0.0f : g.positions[gb + i].w());
    }
    EXPECT_EQ(all.strand_region[g.strand_count() + s], g.strand_region[f.guide[s]]);
  }
}

TEST(FollowHairs, ApplyOnRestGuidesReproducesRestFollows) {
  const Groom g = bent_groom(8, 12);
  const FollowHairs f = make_follow_hairs(g, 3, 0.008, 1.5, 5);
  const Groom all = expand_follow_hairs(g, f);
  std::vector<Vec4f> out(f.vertex_count());
  apply_follow_hairs(f, g.positions, out);
  const std::span<const Vec4f> rest =
      std::span<const Vec4f>(all.positions).subspan(g.vertex_count());
  EXPECT_LE(max_distance(out, rest), 1e-5 * mean_strand_length(g));
}

TEST(FollowHairs, RigidMotionOfGuidesMovesFollowsRigidly) {
  const Groom g = bent_groom(8, 12);
  const FollowHairs f = make_follow_hairs(g, 4, 0.01, 2.0, 11);
  const Groom rest = expand_follow_hairs(g, f);
  const Affine3f m = Eigen::Translation3f(0.3f, -1.2f, 0.7f) *
                     Eigen::AngleAxisf(1.1f, Vec3f(0.3f, 1.0f, -0.4f).normalized());
  std::vector<Vec4f> moved = g.positions;
  for (Vec4f& p : moved) p.head<3>() = m * Vec3f(p.head<3>());
  std::vector<Vec4f> out(f.vertex_count());
  apply_follow_hairs(f, moved, out);
  std::vector<Vec4f> expected(
      rest.positions.begin() + static_cast<std::ptrdiff_t>(g.vertex_count()), rest.positions.end());
  for (Vec4f& p : expected) p.head<3>() = m * Vec3f(p.head<3>());
  EXPECT_LE(max_distance(out, expected), 1e-5 * mean_strand_length(g));
}

// Over a pool the strands are split between threads; each is written from the guides
// alone, so the result is the serial one, bit for bit.
TEST(FollowHairs, ThreadsGiveTheSerialBits) {
  const Groom g = bent_groom(37, 12);
  const FollowHairs f = make_follow_hairs(g, 4, 0.01, 2.0, 17);
  std::vector<Vec4f> moved = g.positions;
  for (std::size_t k = 0; k < moved.size(); ++k)
    if (k % 12 >= 2) moved[k].x() += 0.003f * static_cast<float>(k % 12);
  std::vector<Vec4f> serial(f.vertex_count()), threaded(f.vertex_count(), Vec4f::Constant(-1.0f));
  apply_follow_hairs(f, moved, serial);
  ThreadPool pool(3);
  apply_follow_hairs(f, moved, threaded, &pool);
  EXPECT_EQ(0, std::memcmp(serial.data(), threaded.data(), serial.size() * sizeof(Vec4f)));
}

TEST(FollowHairs, FollowTheGuideWhenItBends) {
  // A bent guide: the follow hair stays at its offset distance from every guide vertex.
  const Groom g = bent_groom(3, 10);
  const FollowHairs f = make_follow_hairs(g, 1, 0.01, 0.0, 3);
  std::vector<Vec4f> bent = g.positions;
  for (std::size_t k = 0; k < bent.size(); ++k)
    if (k % 10 >= 2) bent[k].x() += 0.02f * static_cast<float>((k % 10) * (k % 10)) / 81.0f;
  std::vector<Vec4f> rest(f.vertex_count()), out(f.vertex_count());
  apply_follow_hairs(f, g.positions, rest);
  apply_follow_hairs(f, bent, out);
  for (std::size_t k = 0; k < out.size(); ++k) {
    const float d_rest = (rest[k] - g.positions[k]).head<3>().norm();
    EXPECT_NEAR((out[k] - bent[k]).head<3>().norm(), d_rest, 1e-6f);
  }
  EXPECT_GT(max_distance(out, rest), 0.01);
}

// TressFX rebuilds a follow hair as its guide plus a fixed root offset grown towards the
// tip; here the offset turns with the guide's root frame. However the free part of the
// guide swings, every follow vertex keeps its rest offset from its guide vertex: the
// follow hair's pinned vertices stay put, and follow edge i is guide edge i plus a fixed
// increment (per-vertex frames would swing that by |offset| times the bend instead).
TEST(FollowHairs, SwingingGuidesKeepEveryFollowOffset) {
  const Groom g = bent_groom(6, 10);
  const FollowHairs f = make_follow_hairs(g, 3, 0.02, 5.0, 17);
  std::vector<Vec4f> swung = g.positions;
  for (std::size_t s = 0; s < g.strand_count(); ++s)
    for (std::uint32_t i = 2; i < 10; ++i) {
      Vec4f& p = swung[g.strand_begin(s) + i];
      p.x() += 0.03f * static_cast<float>(i * i) / 81.0f;
      p.z() -= 0.05f * static_cast<float>(i) / 9.0f;
    }
  std::vector<Vec4f> rest(f.vertex_count()), out(f.vertex_count());
  apply_follow_hairs(f, g.positions, rest);
  apply_follow_hairs(f, swung, out);
  for (std::size_t s = 0; s < f.strand_count(); ++s) {
    const std::uint32_t gb = f.guide_offsets[f.guide[s]], fb = f.follow_offsets[s];
    for (std::uint32_t i = 0; i < 10; ++i) {
      const Vec3f rest_offset = (rest[fb + i] - g.positions[gb + i]).head<3>();
      const Vec3f offset = (out[fb + i] - swung[gb + i]).head<3>();
      EXPECT_LE((offset - rest_offset).norm(), 1e-7f);
      if (i < 2) {
        EXPECT_EQ(out[fb + i], rest[fb + i]);
      }
    }
  }
}

TEST(FollowHairs, OneStraightGuideHasNothingToOrientIt) {
  Groom g;
  const std::vector<Vec3f> straight{{0, 0, 0}, {0, 1, 0}, {0, 2, 0}, {0, 3, 0}};
  g.add_strand(straight, 0);
  EXPECT_NE(input_error([&] { make_follow_hairs(g, 2, 0.1, 0.0, 1); }).find("guide strand 0"),
            std::string::npos);
  // A second guide whose root is off the first one's axis is enough.
  const std::vector<Vec3f> beside{{1, 0, 0}, {1, 1, 0}, {1, 2, 0}, {1, 3, 0}};
  g.add_strand(beside, 0);
  EXPECT_EQ(make_follow_hairs(g, 2, 0.1, 0.0, 1).strand_count(), 4u);
  EXPECT_TRUE(make_follow_hairs(g, 0, 0.1, 0.0, 1).empty());
}

TEST(FollowHairs, RejectsBadArgumentsAndMismatchedSpans) {
  const Groom g = bent_groom(2, 4);
  EXPECT_THROW(make_follow_hairs(g, -1, 0.1, 0.0, 1), std::invalid_argument);
  EXPECT_THROW(make_follow_hairs(g, 1, -0.1, 0.0, 1), std::invalid_argument);
  EXPECT_THROW(make_follow_hairs(g, 1, 0.1, NAN, 1), std::invalid_argument);
  const FollowHairs f = make_follow_hairs(g, 2, 0.1, 0.0, 1);
  std::vector<Vec4f> out(f.vertex_count());
  EXPECT_THROW(apply_follow_hairs(f, std::span(g.positions).first(4), out), std::invalid_argument);
  EXPECT_THROW(apply_follow_hairs(f, g.positions, std::span(out).first(3)), std::invalid_argument);
  FollowHairs broken = f;
  broken.anchor[0] = 1000;
  EXPECT_THROW(apply_follow_hairs(broken, g.positions, out), std::invalid_argument);
  EXPECT_THROW(expand_follow_hairs(bent_groom(3, 4), f), std::invalid_argument);
}

// ---- malformed .tfx ---------------------------------------------------------------------

struct BadTfx {
  const char* what;
  std::vector<std::byte> bytes;
  const char* expected;  // substring of the message
};

std::vector<BadTfx> bad_tfx_cases() {
  std::vector<BadTfx> c;
  const auto v3 = [] { return v3_image(2, 4); };
  const auto v4 = [] { return v4_image(2, 4); };
  // Strand 1 vertex 2 of a 4-vertex file: vertex 6 of the block.
  const std::size_t v3_at = 296 + 6 * 12, v4_at = 160 + 6 * 16;

  c.push_back({"empty", {}, "bad.tfx: byte 0: truncated header"});
  std::vector<std::byte> b = v3();
  b.resize(100);
  c.push_back({"short v3 header", b,
               "bad.tfx: byte 100: truncated header: a .tfx 3.x header is 296 bytes"});
  b = v4();
  b.resize(150);
  c.push_back({"short v4 header", b, "byte 150: truncated header: a .tfx 4.x header is 160 bytes"});
  b = v3();
  put_f32(b, 0, 2.0f);
  c.push_back({"version 2", b, "byte 0: unknown version 2 (expected 3.x or 4.x)"});
  put_f32(b, 0, NAN);
  c.push_back({"NaN version", b, "byte 0: unknown version"});
  b = v3();
  put_u32(b, 4, 0);
  c.push_back({"zero strands", b, "byte 4: the file has zero strands"});
  b = v4();
  put_u32(b, 8, 1);
  c.push_back({"one vertex", b, "byte 8: 1 vertices per strand: a strand needs at least 2"});
  b = v3();
  put_u32(b, 4, 0xffffffffu);
  put_u32(b, 8, 0xffffffffu);
  c.push_back(
      {"overflowing counts", b, "byte 4: 4294967295 strands x 4294967295 vertices overflow"});
  // 2^28 - 1 strands x 16 vertices fits 32 bits but needs ~64 GiB of floats: rejected
  // before anything is allocated.
  b = v4();
  put_u32(b, 4, 0x0fffffffu);
  put_u32(b, 8, 16);
  c.push_back({"lying strand count", b, "byte 4: 4294967280 vertex position entries of 16 bytes"});
  b = v3();
  put_u32(b, 4, 3);
  c.push_back(
      {"one strand short", b,
       "byte 4: 12 vertex entries of 12 bytes at offset 296 need 440 bytes, the file has 392"});
  b = v3();
  put_u32(b, 144, 99999);
  c.push_back({"vertex offset past end", b,
               "byte 144: vertex offset 99999 is past the end of the file (392 bytes)"});
  put_u32(b, 144, 8);
  c.push_back(
      {"vertex offset in header", b, "byte 144: vertex offset 8 points into the 296-byte header"});
  b = v4();
  put_u32(b, 12, 0);
  c.push_back({"v4 vertex offset 0", b,
               "byte 12: vertex position offset 0 points into the 160-byte header"});
  b = v3();
  put_u32(b, 156, 5000);
  c.push_back(
      {"colour offset past end", b, "byte 156: perVertexColor offset 5000 is past the end"});
  b = v4();
  put_u32(b, 16, 100000);
  c.push_back({"UV offset past end", b, "byte 16: strand UV offset 100000 is past the end"});
  put_u32(b, 16, static_cast<std::uint32_t>(b.size() - 12));
  c.push_back({"UV block past end", b, "byte 16: 2 strand UV entries of 8 bytes"});
  b = v4();
  put_f32(b, b.size() - 4, INFINITY);
  c.push_back({"infinite UV", b, "strand 1: UV is NaN or infinite"});
  b = v3();
  put_u32(b, 16, 7);
  c.push_back({"bothEndsImmovable 7", b, "byte 16: bothEndsImmovable is 7 (expected 0 or 1)"});
  b = v3();
  put_f32(b, v3_at + 4, NAN);
  c.push_back({"NaN position", b, "byte 368: strand 1 vertex 2: position is NaN or infinite"});
  b = v4();
  put_f32(b, v4_at + 8, -INFINITY);
  c.push_back({"infinite position", b, "byte 256: strand 1 vertex 2: position is NaN or infinite"});
  b = v4();
  put_f32(b, v4_at + 12, NAN);
  c.push_back({"NaN inverse mass", b, "byte 268: inverse mass is NaN or infinite"});
  put_f32(b, v4_at + 12, -1.0f);
  c.push_back({"negative inverse mass", b, "byte 268: negative inverse mass -1"});
  return c;
}

TEST(MalformedTfx, EachKindIsOneInputErrorWithItsByte) {
  // The unmodified images parse: every failure below is the mutation's.
  EXPECT_EQ(parse_tfx(v3_image(2, 4), "good.tfx").positions.size(), 8u);
  EXPECT_EQ(parse_tfx(v4_image(2, 4), "good.tfx").strand_uv.size(), 2u);
  for (const BadTfx& c : bad_tfx_cases()) {
    const std::string message = input_error([&] { parse_tfx(c.bytes, "bad.tfx"); });
    EXPECT_NE(message.find(c.expected), std::string::npos)
        << c.what << "\n  message:  " << message << "\n  expected: " << c.expected;
    EXPECT_EQ(message.rfind("bad.tfx: byte ", 0), 0u) << c.what << ": " << message;
  }
}

TEST(MalformedTfx, V3BothEndsPinsTheTip) {
  const TfxStrands t = parse_tfx(v3_image(2, 4, 1), "tips.tfx");
  for (std::size_t k = 0; k < 8; ++k) EXPECT_EQ(t.positions[k].w(), k % 4 == 2 ? 1.0f : 0.0f) << k;
}

// ---- malformed text ---------------------------------------------------------------------

struct BadText {
  const char* text;
  const char* expected;
};

TEST(MalformedTfxsim, EachKindIsOneInputErrorWithItsLine) {
  const BadText cases[] = {
      {"version 3.0\nfoo 1", "bad.tfxsim: line 2: unknown key 'foo'"},
      // Unprintable bytes are escaped so that the message stays one readable line.
      {"da\x01mping 1", "line 1: unknown key 'da\\x01mping'"},
      {"damping", "line 1: damping: missing value (expected 1)"},
      {"# comment\n\ndamping 0.1 0.2", "line 3: damping: extra value '0.2'"},
      {"damping abc", "line 1: damping: 'abc' is not a number"},
      {"damping 0.1x", "line 1: damping: '0.1x' is not a number"},
      {"stiffnessForLocalShapeMatching inf",
       "line 1: stiffnessForLocalShapeMatching: 'inf' is not finite"},
      {"damping nan", "line 1: damping: 'nan' is not finite"},
      {"damping 1e999", "line 1: damping: '1e999' is out of range"},
      {"version 2.0", "line 1: version: '2.0' is not supported (expected 3.x or 4.x)"},
      {"version 5", "line 1: version: '5' is not supported"},
      {"damping 0.1\r\ndamping 0.2", "line 2: damping: given twice"},
      {"lengthConstraintIterations 2.5",
       "line 1: lengthConstraintIterations: '2.5' is not a whole number"},
      {"localShapeMatchingIterations -1",
       "line 1: localShapeMatchingIterations: '-1' is not a whole number"},
  };
  for (const BadText& c : cases) {
    const std::string message = input_error([&] { parse_tfxsim(c.text, "bad.tfxsim"); });
    EXPECT_NE(message.find(c.expected), std::string::npos) << c.text << "\n  message: " << message;
  }
}

TEST(MalformedTfxproj, EachKindIsOneInputErrorWithItsLine) {
  const BadText cases[] = {
      {"a.tfx 4 0.4 5.0 a.tfxsim top\nfoo 1", "bad.tfxproj: line 2: unknown key 'foo'"},
      {"a.tfx 4 0.4 5.0", "line 1: a.tfx: a section line is"},
      {"a.tfx 4 0.4 5.0 a.tfxsim top extra", "line 1: a.tfx: extra value 'extra'"},
      {"a.tfx -1 0.4 5.0 a.tfxsim", "line 1: a.tfx: '-1' is not a whole number in [0, 64]"},
      {"a.tfx 1000 0.4 5.0 a.tfxsim", "line 1: a.tfx: '1000' is not a whole number in [0, 64]"},
      {"a.tfx 4 -0.4 5.0 a.tfxsim", "line 1: a.tfx: negative follow radius"},
      {"a.tfx 4 0.4 -5 a.tfxsim", "line 1: a.tfx: negative tip separation"},
      {"a.tfx 4 0.4 nan a.tfxsim", "line 1: a.tfx: 'nan' is not finite"},
      {"a.tfx 4 0.4 5 a.txt", "line 1: a.tfx: 'a.txt' is not a .tfxsim file"},
      {"a.tfx 4 0.4 5 a.tfxsim x\nb.tfx 4 0.4 5 b.tfxsim x",
       "line 2: section name 'x' is used twice"},
      {"a.tfx 4 0.4 5 a.tfxsim\na.tfx 4 0.4 5 b.tfxsim", "line 2: section name 'a' is used twice"},
      {"a.tfx 4 0.4 5 a.tfxsim\ncollision_sphere 1 2 3",
       "line 2: collision_sphere: missing value (expected 4)"},
      {"a.tfx 4 0.4 5 a.tfxsim\ncollision_sphere 1 2 3 0",
       "line 2: collision_sphere: radius must be positive"},
      {"a.tfx 4 0.4 5 a.tfxsim\ncollision_sphere 1 2 3 1e39",
       "line 2: collision_sphere: value out of float range"},
      {"a.tfx 4 0.4 5 a.tfxsim\nlengthConstraintIterations x",
       "line 2: lengthConstraintIterations: 'x' is not a number"},
      {"a.tfx 4 0.4 5 a.tfxsim\ndamping 0.1", "line 2: unknown key 'damping'"},
      {"version 3.0\nversion 3.0", "line 2: version: given twice"},
      {"project_name", "line 1: project_name: missing value"},
      {"head.sdkmesh extra", "line 1: head.sdkmesh: extra value 'extra'"},
      {"version 3.0\n# no sections\n", "bad.tfxproj: sections: no hair section"},
  };
  for (const BadText& c : cases) {
    const std::string message = input_error([&] { parse_tfxproj(c.text, "bad.tfxproj"); });
    EXPECT_NE(message.find(c.expected), std::string::npos) << c.text << "\n  message: " << message;
  }
}

TEST(Tfxproj, AcceptsRenderingKeysCommentsAndMissingSectionName) {
  const TfxProject p = parse_tfxproj(
      "version 4.0\r\n  # comment\nhead.SDKMESH\nHair.TFX 0 0 0 Hair.tfxsim # trailing comment\n"
      "hairColor 1 2 3\nlightPos -421.25043f 606.7890949f -43.22232f\nKa 0\nKs1 1\nEx1 2\nKs2 "
      "3\nEx2 4",
      "ok.tfxproj");
  ASSERT_EQ(p.sections.size(), 1u);
  EXPECT_EQ(p.sections[0].name, "Hair");
  EXPECT_EQ(p.sections[0].follow_per_guide, 0);
}

// ---- fuzz corpus replay -----------------------------------------------------------------

std::string slurp(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

// Every file of the minimised libFuzzer corpus (tests/fuzz/corpus) goes through the
// parsers in the ordinary build: each parses or throws InputError, nothing else.
TEST(FuzzCorpus, ReplaysWithoutCrashing) {
  ASSERT_PRESENT(kCorpus / "tfx");
  ASSERT_PRESENT(kCorpus / "text");
  std::size_t files = 0;
  for (const auto& entry : fs::directory_iterator(kCorpus / "tfx")) {
    const std::string data = slurp(entry.path());
    try {
      parse_tfx(std::as_bytes(std::span(data.data(), data.size())), entry.path().string());
    } catch (const InputError&) {
    }
    ++files;
  }
  for (const auto& entry : fs::directory_iterator(kCorpus / "text")) {
    const std::string data = slurp(entry.path());
    try {
      parse_tfxsim(data, entry.path().string());
    } catch (const InputError&) {
    }
    try {
      parse_tfxproj(data, entry.path().string());
    } catch (const InputError&) {
    }
    ++files;
  }
  EXPECT_GT(files, 0u);
}

}  // namespace
}  // namespace hairbench::tfx
