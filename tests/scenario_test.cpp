// Scenario layer: the loader's contract (docs/scenarios.md), the shipped
// scenarios, the procedural grooms and the head-motion script.
#include "scenario_support.h"
#include "scenarios/scenario.h"

#include "core/error.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <numbers>
#include <set>
#include <sstream>

namespace hairbench {
namespace {

namespace fs = std::filesystem;
constexpr double kPi = std::numbers::pi;

const fs::path kBadDir = fs::path(HAIRBENCH_TEST_DATA_DIR) / "bad";

// Writes `text` to a fresh file in the test's temporary folder and returns its path.
fs::path write_temp(const std::string& name, const std::string& text) {
  const fs::path dir = fs::path(testing::TempDir()) / "hairbench_scenario_test";
  fs::create_directories(dir);
  const fs::path file = dir / name;
  std::ofstream(file, std::ios::binary) << text;
  return file;
}

using test::error_of;

// A valid scenario around a caller-supplied fragment, for loader tests.
std::string scenario_with(const std::string& extra) {
  return R"({ "frames": 120, "dt": 0.025,
    "groom": { "style": "straight", "strands": 30, "vertices_per_strand": 6, "length": 0.2, "seed": 3 })" +
         (extra.empty() ? "" : ", " + extra) + " }";
}

// Last time at which the head script or the wind changes.
double motion_end(const Scenario& sc) {
  double end = 0.0;
  if (!sc.head.keys.empty()) end = sc.head.keys.back().t;
  for (const Oscillator& o : sc.head.oscillators) end = std::max(end, o.end);
  if (!sc.wind.keys.empty()) end = std::max(end, sc.wind.keys.back().t);
  return end;
}

bool transforms_equal(const Affine3f& a, const Affine3f& b) { return a.matrix() == b.matrix(); }

float rotation_angle(const Affine3f& a) { return Eigen::AngleAxisf(a.rotation()).angle(); }

// ---------------------------------------------------------------------------------------
// Shipped scenarios

TEST(BuiltinScenarios, AreTheDocumentedSetSortedByName) {
  std::vector<std::string> names;
  for (const fs::path& p : builtin_scenarios()) names.push_back(p.stem().string());
  const std::vector<std::string> expected{"idle",
                                          "nod",
                                          "ponytail",
                                          "shake",
                                          "spin_fast",
                                          "tilt_upside_down",
                                          "tressfx_mohawk",
                                          "tressfx_ponytail_shake",
                                          "tressfx_ponytail_spin",
                                          "tressfx_testhair1",
                                          "truth_chain_32",
                                          "truth_chain_8",
                                          "walk",
                                          "wind_gust"};
  EXPECT_EQ(names, expected);
}

TEST(BuiltinScenarios, LoadEndStillAndSettleAfterTheMotion) {
  for (const Scenario& sc : load_builtin_scenarios()) {
    SCOPED_TRACE(sc.source.string());
    EXPECT_EQ(sc.name, sc.source.stem().string());
    EXPECT_FALSE(sc.description.empty());
    EXPECT_NEAR(sc.dt, 1.0 / 60.0, 1e-12);
    EXPECT_FLOAT_EQ(sc.gravity.y(), -9.81f);
    // The truth scenarios hold the head still and have neither colliders nor a settle
    // window (docs/truth.md): their checks are the loader's (read_truth).
    if (sc.truth) {
      EXPECT_TRUE(sc.head.keys.empty() && sc.head.oscillators.empty());
      EXPECT_TRUE(sc.colliders.empty());
      continue;
    }
    const double t_end = sc.duration();
    EXPECT_TRUE(transforms_equal(sc.head.at(t_end), sc.head.at(t_end - sc.dt)));
    EXPECT_EQ(sc.wind.at(t_end).strength, 0.0f);
    EXPECT_GE(sc.settle_from, motion_end(sc) + 1.0);
    EXPECT_LT(sc.settle_from, t_end);
    EXPECT_FLOAT_EQ(sc.gravity.y(), -9.81f);
    // The TressFX scenarios bring their own grooms and colliders (tressfx_scenario_test).
    if (sc.name.rfind("tressfx_", 0) == 0) continue;
    ASSERT_EQ(sc.colliders.size(), 1u);
    EXPECT_TRUE(sc.colliders[0].head_attached);
    EXPECT_FLOAT_EQ(sc.colliders[0].radius, 0.1f);
    EXPECT_FLOAT_EQ(sc.head_radius, 0.1f);
    EXPECT_EQ(sc.groom.vertex_count(), sc.groom.strand_count() * 16);
  }
}

TEST(BuiltinScenarios, MoveAsDescribed) {
  const Scenario spin = load_scenario(find_scenario("spin_fast"));
  // 720 degrees per second: a quarter turn after 0.125 s.
  EXPECT_NEAR(rotation_angle(spin.head.at(0.125)), kPi / 2, 1e-5);
  const Scenario tilt = load_scenario(find_scenario("tilt_upside_down"));
  EXPECT_NEAR(tilt.head.at(3.0).linear()(1, 1), -1.0f, 1e-6f);  // y axis points down
  const Scenario walk = load_scenario(find_scenario("walk"));
  EXPECT_NEAR(walk.head.at(3.0).translation().z(), 1.5f, 1e-6f);
  const Scenario gust = load_scenario(find_scenario("wind_gust"));
  EXPECT_FLOAT_EQ(gust.wind.at(1.0).strength, 12.0f);
  EXPECT_TRUE(gust.wind.ever_active());
  const Scenario pony = load_scenario(find_scenario("ponytail"));
  EXPECT_EQ(pony.groom.region_names.size(), 3u);
  EXPECT_EQ(pony.groom.strand_count(), 1500u);
}

TEST(FindScenario, ByNameByPathAndUnknown) {
  const fs::path by_name = find_scenario("shake");
  EXPECT_EQ(by_name.filename(), "shake.json");
  EXPECT_EQ(find_scenario(by_name.string()), by_name);
  try {
    find_scenario("no_such_scenario");
    FAIL() << "expected an InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("no_such_scenario"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("hairbench list scenarios"), std::string::npos);
  }
}

TEST(FindScenario, EnvironmentOverridesTheBuiltinFolder) {
  ASSERT_EQ(setenv("HAIRBENCH_SCENARIO_DIR", kBadDir.c_str(), 1), 0);
  EXPECT_EQ(builtin_scenario_dir(), kBadDir);
  EXPECT_EQ(find_scenario("malformed"), kBadDir / "malformed.json");
  ASSERT_EQ(setenv("HAIRBENCH_SCENARIO_DIR", "/nonexistent/scenarios", 1), 0);
  EXPECT_THROW(builtin_scenarios(), InputError);
  ASSERT_EQ(unsetenv("HAIRBENCH_SCENARIO_DIR"), 0);
  EXPECT_NE(builtin_scenario_dir(), kBadDir);
}

// ---------------------------------------------------------------------------------------
// Bad files: one-line InputError naming the file and the key path

struct BadCase {
  std::string file, expected;
};

std::vector<BadCase> bad_manifest() {
  std::vector<BadCase> cases;
  std::ifstream in(kBadDir / "expected.txt");
  for (std::string line; std::getline(in, line);) {
    const std::size_t space = line.find(' ');
    if (space != std::string::npos) cases.push_back({line.substr(0, space), line.substr(space + 1)});
  }
  return cases;
}

TEST(BadFiles, ManifestCoversEveryBadFile) {
  std::set<std::string> listed, present;
  for (const BadCase& c : bad_manifest()) listed.insert(c.file);
  for (const auto& e : fs::directory_iterator(kBadDir))
    if (e.path().extension() == ".json") present.insert(e.path().filename().string());
  EXPECT_EQ(listed, present);
  EXPECT_GE(listed.size(), 12u);
}

TEST(BadFiles, EachGivesOneLineNamingFileAndKey) {
  for (const BadCase& c : bad_manifest()) {
    SCOPED_TRACE(c.file);
    const std::string msg = error_of(kBadDir / c.file);
    ASSERT_FALSE(msg.empty()) << "loaded without an error";
    EXPECT_NE(msg.find(c.expected), std::string::npos) << msg;
    EXPECT_NE(msg.find(c.file), std::string::npos) << msg;
    EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
  }
}

TEST(Loader, SyntaxErrorPositionIsLineAndColumn) {
  const fs::path file = write_temp("syntax.json", "{\n  \"frames\": 10,\n  \"dt\": tru\n}\n");
  const std::string msg = error_of(file);
  EXPECT_EQ(msg.rfind(file.string() + ": line 3, column ", 0), 0u) << msg;
  EXPECT_EQ(msg.find("json.exception"), std::string::npos) << msg;
}

TEST(Loader, MissingFileIsAnInputError) {
  EXPECT_NE(error_of("/nonexistent/x.json").find("/nonexistent/x.json"), std::string::npos);
}

TEST(Loader, TheDesignDocExampleLoads) {
  const std::string text = R"({
  "name": "shake",
  "description": "Head shakes ±60° at 2 Hz for 2 s, then holds still",
  "frames": 240, "dt": 0.0166667,
  "gravity": [0, -9.81, 0],
  "groom": { "style": "straight", "strands": 2000, "vertices_per_strand": 16,
             "length": 0.25, "seed": 1 },
  "head": {
    "radius": 0.1,
    "keys": [ { "t": 0.0, "translate": [0,0,0], "rotate": { "axis": [0,1,0], "deg": 0 } } ],
    "oscillators": [ { "kind": "rotate", "axis": [0,1,0], "amplitude_deg": 60,
                       "frequency_hz": 2.0, "start": 0.0, "end": 2.0 } ]
  },
  "colliders": [ { "type": "sphere", "center": [0,0,0], "radius": 0.1, "attached": "head" } ],
  "wind": { "direction": [1,0,0], "strength": 0.0 },
  "settle_from": 3.0,
  "models": { "*": { "local_iterations": 3 }, "han_m2": { "local_iterations": 3 } }
})";
  const Scenario sc = load_scenario(write_temp("design_example.json", text));
  EXPECT_EQ(sc.name, "shake");
  EXPECT_EQ(sc.frames, 240);
  EXPECT_EQ(sc.groom.vertex_count(), 32000u);
  EXPECT_EQ(sc.head.oscillators.size(), 1u);
  EXPECT_EQ(sc.models.at("han_m2").base.at("local_iterations"), 3.0);
  EXPECT_FALSE(sc.wind.ever_active());
}

TEST(Loader, DefaultsAndUnitConversions) {
  const fs::path file = write_temp("my_scene.json", scenario_with(R"(
    "head": { "radius": 0.12,
      "keys": [ { "t": 0.5, "rotate": { "axis": [0, 0, 2], "deg": 90 } } ],
      "oscillators": [ { "kind": "rotate", "axis": [0, 3, 0], "amplitude_deg": 45, "frequency_hz": 1,
                         "start": 0, "end": 1, "phase_deg": 180 } ] },
    "wind": { "direction": [0, 0, -5], "strength": 2 },
    "settle_from": 3 )"));
  const Scenario sc = load_scenario(file);
  EXPECT_EQ(sc.name, "my_scene");
  EXPECT_EQ(sc.source, file);
  EXPECT_EQ(sc.reference, "han_m1");
  EXPECT_FLOAT_EQ(sc.head_radius, 0.12f);
  EXPECT_FLOAT_EQ(sc.groom.head_radius, 0.12f);
  EXPECT_DOUBLE_EQ(sc.head.keys[0].angle, kPi / 2);
  EXPECT_TRUE(sc.head.keys[0].axis.isApprox(Vec3f::UnitZ()));
  EXPECT_DOUBLE_EQ(sc.head.oscillators[0].amplitude, kPi / 4);
  EXPECT_DOUBLE_EQ(sc.head.oscillators[0].phase, kPi);
  EXPECT_TRUE(sc.head.oscillators[0].axis.isApprox(Vec3f::UnitY()));
  EXPECT_TRUE(sc.wind.direction.isApprox(-Vec3f::UnitZ()));
  EXPECT_FLOAT_EQ(sc.wind.at(1.0).strength, 2.0f);
  EXPECT_TRUE(sc.colliders.empty());
  EXPECT_EQ(sc.groom.region_names, std::vector<std::string>{"all"});
  ASSERT_EQ(sc.region_params.size(), 1u);
  EXPECT_TRUE(sc.region_params[0].empty());
}

TEST(Loader, ModelOverridesKeepTheFileShape) {
  const std::string text = R"({ "frames": 60, "dt": 0.02, "reference": "han_m3",
    "groom": { "style": "ponytail", "strands": 200, "vertices_per_strand": 8, "length": 0.25, "seed": 9 },
    "models": { "*": { "local_iterations": 3 },
                "han_m2": { "damping": 0.05, "regions": { "tail": { "local_stiffness": 0.25 } } } } })";
  const Scenario sc = load_scenario(write_temp("models.json", text));
  EXPECT_EQ(sc.reference, "han_m3");
  ASSERT_EQ(sc.models.size(), 2u);
  EXPECT_EQ(sc.models.at("*").base.at("local_iterations"), 3.0);
  EXPECT_TRUE(sc.models.at("*").regions.empty());
  EXPECT_EQ(sc.models.at("han_m2").base.at("damping"), 0.05);
  EXPECT_EQ(sc.models.at("han_m2").regions.at("tail").at("local_stiffness"), 0.25);
}

TEST(Loader, StyleKnobsReachTheGenerator) {
  const std::string text = R"({ "frames": 60, "dt": 0.02,
    "groom": { "style": "curly", "strands": 10, "vertices_per_strand": 30, "length": 0.3, "seed": 1,
               "curl_radius": 0.02, "curl_pitch": 0.05 } })";
  const Scenario sc = load_scenario(write_temp("curly.json", text));
  GroomSpec spec;
  spec.style = "curly";
  spec.strands = 10;
  spec.vertices_per_strand = 30;
  spec.length = 0.3;
  spec.curl_radius = 0.02;
  spec.curl_pitch = 0.05;
  EXPECT_EQ(sc.groom.positions, generate_groom(spec, 0.1f, "x").groom.positions);
}

TEST(Loader, LargeSeedsAreAccepted) {
  const std::string text = R"({ "frames": 1, "dt": 0.02,
    "groom": { "style": "straight", "strands": 3, "vertices_per_strand": 4, "length": 0.1,
               "seed": 18446744073709551615 } })";
  EXPECT_NO_THROW(load_scenario(write_temp("seed.json", text)));
}

// ---------------------------------------------------------------------------------------
// Wind

TEST(Wind, KeysArePiecewiseLinearAndHeldOutside) {
  WindScript w;
  w.direction = Vec3f::UnitZ();
  w.keys = {{1.0, 0.0}, {2.0, 10.0}, {4.0, 0.0}};
  EXPECT_EQ(w.at(0.0).strength, 0.0f);
  EXPECT_FLOAT_EQ(w.at(1.5).strength, 5.0f);
  EXPECT_FLOAT_EQ(w.at(2.0).strength, 10.0f);
  EXPECT_FLOAT_EQ(w.at(3.5).strength, 2.5f);
  EXPECT_EQ(w.at(9.0).strength, 0.0f);
  EXPECT_TRUE(w.at(1.5).direction.isApprox(Vec3f::UnitZ()));
  EXPECT_TRUE(w.ever_active());
  WindScript calm;
  EXPECT_FALSE(calm.ever_active());
  calm.strength = 1.0;
  EXPECT_TRUE(calm.ever_active());
  EXPECT_EQ(calm.at(100.0).strength, 1.0f);
}

// ---------------------------------------------------------------------------------------
// Grooms

GroomSpec spec_of(const std::string& style, std::uint64_t seed = 1) {
  GroomSpec s;
  s.style = style;
  s.strands = 400;
  s.vertices_per_strand = 16;
  s.length = 0.25;
  s.seed = seed;
  return s;
}

Vec3f pos(const Groom& g, std::size_t s, std::uint32_t i) {
  return g.positions[g.strand_begin(s) + i].head<3>();
}

// Mean turning angle per unit length over all interior vertices.
double mean_rest_curvature(const Groom& g) {
  double sum = 0.0;
  std::size_t n = 0;
  for (std::size_t s = 0; s < g.strand_count(); ++s)
    for (std::uint32_t i = 1; i + 1 < g.strand_size(s); ++i) {
      const Vec3f a = pos(g, s, i) - pos(g, s, i - 1), b = pos(g, s, i + 1) - pos(g, s, i);
      const double c = std::clamp(a.normalized().dot(b.normalized()), -1.0f, 1.0f);
      sum += std::acos(c) / b.norm();
      ++n;
    }
  return sum / static_cast<double>(n);
}

TEST(Groom, SameSeedIsBitIdenticalOtherSeedDiffers) {
  for (const std::string_view style : groom_styles()) {
    SCOPED_TRACE(std::string(style));
    const Groom a = generate_groom(spec_of(std::string(style), 7), 0.1f, "t").groom;
    const Groom b = generate_groom(spec_of(std::string(style), 7), 0.1f, "t").groom;
    const Groom c = generate_groom(spec_of(std::string(style), 8), 0.1f, "t").groom;
    ASSERT_EQ(a.positions.size(), b.positions.size());
    EXPECT_EQ(std::memcmp(a.positions.data(), b.positions.data(), a.positions.size() * sizeof(Vec4f)), 0);
    EXPECT_EQ(a.strand_region, b.strand_region);
    // The truth scenarios' hanging chains are placed, not grown: no seed moves them.
    if (style == "hanging")
      EXPECT_EQ(a.positions, c.positions);
    else
      EXPECT_NE(a.positions, c.positions);
  }
}

TEST(Groom, EveryStyleStaysOutsideTheHeadWithExactEdgesAndPinnedRoots) {
  const float r = 0.1f;
  for (const std::string_view style : groom_styles()) {
    SCOPED_TRACE(std::string(style));
    const GroomSpec spec = spec_of(std::string(style));
    const Groom g = generate_groom(spec, r, "t").groom;
    ASSERT_EQ(g.strand_count(), 400u);
    EXPECT_FLOAT_EQ(g.head_radius, r);
    const double edge = spec.length / (spec.vertices_per_strand - 1);
    for (std::size_t s = 0; s < g.strand_count(); ++s) {
      ASSERT_EQ(g.strand_size(s), 16u);
      const Vec3f root = pos(g, s, 0);
      EXPECT_NEAR(root.norm(), r, 1e-6f);
      if (style == "hanging") {
        // Under the head, and straight down from the root.
        EXPECT_LT(root.y(), 0.0f);
        EXPECT_GT((pos(g, s, g.strand_size(s) - 1) - root).normalized().dot(-Vec3f::UnitY()), 1.0f - 1e-6f);
      } else {
        EXPECT_GE(root.y(), 0.1f * r * (1 - 1e-5f));
        // Vertex 1 straight out along the scalp normal.
        EXPECT_GT((pos(g, s, 1) - root).normalized().dot(root.normalized()), 1.0f - 1e-5f);
      }
      for (std::uint32_t i = 0; i < g.strand_size(s); ++i) {
        const Vec4f& p = g.positions[g.strand_begin(s) + i];
        EXPECT_EQ(p.w(), i < 2 ? 0.0f : 1.0f);
        EXPECT_GE(p.head<3>().norm(), (i < 2 ? r : 1.02f * r) * (1 - 1e-6f)) << "strand " << s << " vertex " << i;
        if (i > 0) {
          EXPECT_NEAR((pos(g, s, i) - pos(g, s, i - 1)).norm() / edge, 1.0, 1e-5);
        }
      }
    }
    EXPECT_NO_THROW(validate_groom(g, "t"));
  }
}

TEST(Groom, CurlsAndWavesBendTheRestShape) {
  const double straight = mean_rest_curvature(generate_groom(spec_of("straight"), 0.1f, "t").groom);
  const double wavy = mean_rest_curvature(generate_groom(spec_of("wavy"), 0.1f, "t").groom);
  GroomSpec curly_spec = spec_of("curly");
  curly_spec.vertices_per_strand = 48;  // several vertices per curl turn
  const double curly = mean_rest_curvature(generate_groom(curly_spec, 0.1f, "t").groom);
  EXPECT_GT(wavy, 1.5 * straight);
  EXPECT_GT(curly, 3.0 * straight);
  // A helix of radius R and pitch P has curvature R / (R^2 + (P/2pi)^2).
  const double helix = 0.012 / (0.012 * 0.012 + std::pow(0.04 / (2 * kPi), 2));
  EXPECT_GT(curly, 0.5 * helix);
}

TEST(Groom, StylesShareRootsForTheSameSeed) {
  const Groom a = generate_groom(spec_of("straight"), 0.1f, "t").groom;
  const Groom b = generate_groom(spec_of("curly"), 0.1f, "t").groom;
  for (std::size_t s = 0; s < a.strand_count(); ++s) EXPECT_EQ(pos(a, s, 0), pos(b, s, 0));
}

TEST(Groom, PonytailHasThreeRegionsLikeHanHaradaFigure1) {
  const GeneratedGroom gen = generate_groom(spec_of("ponytail"), 0.1f, "t");
  const Groom& g = gen.groom;
  ASSERT_EQ(g.region_names, (std::vector<std::string>{"front", "top", "tail"}));
  ASSERT_EQ(gen.region_params.size(), 3u);
  EXPECT_EQ(gen.region_params[0].at("local_stiffness"), 0.6);
  EXPECT_EQ(gen.region_params[2].at("global_stiffness"), 0.1);
  std::array<int, 3> count{};
  std::array<double, 3> root_z{}, tip_z{};
  for (std::size_t s = 0; s < g.strand_count(); ++s) {
    const int region = g.strand_region[s];
    ++count[region];
    root_z[region] += pos(g, s, 0).z();
    tip_z[region] += pos(g, s, g.strand_size(s) - 1).z();
  }
  for (int r = 0; r < 3; ++r) {
    EXPECT_GT(count[r], 0) << g.region_names[r];
    root_z[r] /= count[r];
    tip_z[r] /= count[r];
  }
  EXPECT_GT(root_z[0], 0.0);  // front: rooted at the forehead
  EXPECT_GT(tip_z[0], 0.0);   // and falls forward
  EXPECT_LT(tip_z[1], 0.0);   // top: combed back
  EXPECT_LT(root_z[2], 0.0);  // tail: rooted at the back
  // Tail tips hang together in one bundle behind and below the head.
  for (std::size_t s = 0; s < g.strand_count(); ++s) {
    if (g.strand_region[s] != 2) continue;
    const Vec3f tip = pos(g, s, g.strand_size(s) - 1);
    EXPECT_LT(tip.z(), -0.1f);
    EXPECT_LT(std::abs(tip.x()), 0.03f);
    EXPECT_LT(tip.y(), 0.0f);
  }
}

TEST(Groom, OtherStylesHaveOneRegionWithoutDefaults) {
  const GeneratedGroom gen = generate_groom(spec_of("wavy"), 0.1f, "t");
  EXPECT_EQ(gen.groom.region_names, std::vector<std::string>{"all"});
  ASSERT_EQ(gen.region_params.size(), 1u);
  EXPECT_TRUE(gen.region_params[0].empty());
}

TEST(Groom, ExtremeSpecsStillHoldTheInvariants) {
  GroomSpec tiny = spec_of("curly");
  tiny.strands = 1;
  tiny.vertices_per_strand = 2;
  tiny.length = 0.0001;
  EXPECT_NO_THROW(generate_groom(tiny, 0.1f, "t"));
  GroomSpec fine = spec_of("ponytail");
  fine.strands = 50;
  fine.vertices_per_strand = 256;
  fine.length = 0.02;  // edges far shorter than the 2% margin
  const Groom g = generate_groom(fine, 0.1f, "t").groom;
  for (const Vec4f& p : g.positions) EXPECT_GE(p.head<3>().norm(), 0.1f * (1 - 1e-6f));
}

TEST(Groom, BadSpecNamesTheField) {
  GroomSpec s = spec_of("straight");
  s.strands = 0;
  try {
    generate_groom(s, 0.1f, "file.json");
    FAIL() << "expected an InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("file.json: groom.strands:"), std::string::npos) << e.what();
  }
  s = spec_of("dreadlocks");
  EXPECT_THROW(generate_groom(s, 0.1f, "f"), InputError);
  s = spec_of("wavy");
  s.wave_length = 0.0;
  EXPECT_THROW(generate_groom(s, 0.1f, "f"), InputError);
  EXPECT_THROW(generate_groom(spec_of("straight"), 0.0f, "f"), InputError);
}

// ---------------------------------------------------------------------------------------
// Head motion

Affine3f pose(const Vec3f& translate, const Vec3f& axis, double deg) {
  Affine3f a = Affine3f::Identity();
  a.linear() = Eigen::AngleAxisf(static_cast<float>(deg * kPi / 180.0), axis).toRotationMatrix();
  a.translation() = translate;
  return a;
}

HeadKey key(double t, const Vec3f& translate, const Vec3f& axis, double deg, bool linear = false) {
  HeadKey k;
  k.t = t;
  k.translate = translate;
  k.axis = axis;
  k.angle = deg * kPi / 180.0;
  k.linear = linear;
  return k;
}

HeadMotion three_keys() {
  HeadMotion m;
  m.keys = {key(0.5, {0, 0, 0}, Vec3f::UnitY(), 0), key(1.5, {0.1f, 0.2f, 0}, Vec3f::UnitX(), 40),
            key(2.0, {0, 0, 0.3f}, Vec3f(0, 0.6f, 0.8f), -70)};
  return m;
}

TEST(HeadMotion, KeysAreHitAndHeldOutside) {
  const HeadMotion m = three_keys();
  for (const HeadKey& k : m.keys)
    EXPECT_TRUE(m.at(k.t).isApprox(pose(k.translate, k.axis, k.angle * 180.0 / kPi), 1e-6f)) << k.t;
  EXPECT_TRUE(transforms_equal(m.at(-1.0), m.at(0.5)));
  EXPECT_TRUE(transforms_equal(m.at(0.2), m.at(0.5)));
  EXPECT_TRUE(transforms_equal(m.at(2.0), m.at(7.0)));
  EXPECT_TRUE(HeadMotion().at(3.0).isApprox(Affine3f::Identity()));
}

TEST(HeadMotion, IsAPureFunctionOfTime) {
  const HeadMotion m = three_keys();
  const Affine3f first = m.at(1.234);
  m.at(0.1);
  m.at(1.9);
  EXPECT_TRUE(transforms_equal(first, m.at(1.234)));
}

// Largest change of any transform entry per second, from t to t + h.
float speed(const HeadMotion& m, double t, double h) {
  return (m.at(t + h).matrix() - m.at(t).matrix()).cwiseAbs().maxCoeff() / static_cast<float>(h);
}

TEST(HeadMotion, SmoothEaseStopsAtKeysLinearDoesNot) {
  const HeadMotion m = three_keys();
  const double h = 1e-3;
  const float mid = speed(m, 1.0, h);
  ASSERT_GT(mid, 0.1f);
  for (const double t : {0.5, 1.5}) {
    EXPECT_LT(speed(m, t, h), 0.02f * mid) << "leaving key at " << t;
    EXPECT_LT(speed(m, t - h, h), 0.02f * mid) << "arriving at key at " << t;
  }
  HeadMotion lin;
  lin.keys = {key(0.0, {0, 0, 0}, Vec3f::UnitY(), 0), key(1.0, {0, 0, 1}, Vec3f::UnitY(), 0, true)};
  EXPECT_NEAR(lin.at(0.25).translation().z(), 0.25f, 1e-6f);
  EXPECT_NEAR(speed(lin, 0.0, h), 1.0f, 1e-3f);
  EXPECT_NEAR(speed(lin, 1.0 - h, h), 1.0f, 1e-3f);
}

TEST(HeadMotion, SameAxisKeysSpinThroughTheWholeAngle) {
  HeadMotion m;
  m.keys = {key(0.0, {0, 0, 0}, Vec3f::UnitY(), 0), key(1.0, {0, 0, 0}, Vec3f::UnitY(), 720, true)};
  // Accumulate the frame-to-frame rotation about y: two full turns.
  double turned = 0.0;
  const int steps = 1000;
  for (int i = 0; i < steps; ++i) {
    const Affine3f a = m.at(i / double(steps)), b = m.at((i + 1) / double(steps));
    const Eigen::AngleAxisf d(b.rotation() * a.rotation().transpose());
    turned += d.angle() * d.axis().y();
  }
  EXPECT_NEAR(turned, 4 * kPi, 1e-3);
  EXPECT_TRUE(m.at(0.375).isApprox(pose({0, 0, 0}, Vec3f::UnitY(), 270), 1e-5f));
}

TEST(HeadMotion, DifferentAxesSlerp) {
  HeadMotion m;
  m.keys = {key(0.0, {0, 0, 0}, Vec3f::UnitX(), 0), key(1.0, {0, 0, 0}, Vec3f::UnitZ(), 90, true)};
  const Quatf q0 = Quatf::Identity();
  const Quatf q1(Eigen::AngleAxisf(static_cast<float>(kPi / 2), Vec3f::UnitZ()));
  EXPECT_TRUE(Quatf(m.at(0.3).rotation()).isApprox(q0.slerp(0.3f, q1), 1e-5f));
}

TEST(HeadMotion, OscillatorsReachTheirAmplitudeOnlyInsideTheirWindow) {
  HeadMotion m;
  Oscillator rot;
  rot.kind = Oscillator::Kind::Rotate;
  rot.axis = Vec3f::UnitX();
  rot.amplitude = kPi / 6;
  rot.frequency_hz = 2.0;
  rot.start = 1.0;
  rot.end = 2.0;
  Oscillator bob;
  bob.kind = Oscillator::Kind::Translate;
  bob.axis = Vec3f::UnitY();
  bob.amplitude = 0.02;
  bob.frequency_hz = 1.0;
  bob.phase = kPi / 2;
  bob.start = 0.0;
  bob.end = 3.0;
  m.oscillators = {rot, bob};
  // Quarter period after start: the peak.
  EXPECT_NEAR(rotation_angle(m.at(1.125)), kPi / 6, 1e-5);
  EXPECT_NEAR(m.at(1.125).rotation()(2, 1), std::sin(kPi / 6), 1e-5);  // about +x
  EXPECT_NEAR(m.at(0.0).translation().y(), 0.02f, 1e-7f);                // phase 90 degrees
  EXPECT_NEAR(m.at(3.0).translation().y(), 0.02f, 1e-7f);
  EXPECT_TRUE(m.at(0.99).linear().isIdentity());
  EXPECT_TRUE(m.at(2.01).linear().isIdentity());
  EXPECT_TRUE(transforms_equal(m.at(3.01), Affine3f::Identity()));
}

TEST(HeadMotion, OscillatorsRotateAboutTheHeadCentre) {
  HeadMotion m;
  m.keys = {key(0.0, {0, 0, 1}, Vec3f::UnitY(), 90)};
  Oscillator nod;
  nod.axis = Vec3f::UnitX();
  nod.amplitude = kPi / 4;
  nod.frequency_hz = 1.0;
  nod.start = 0.0;
  nod.end = 1.0;
  m.oscillators = {nod};
  const Affine3f a = m.at(0.25);
  // The head centre stays where the keys put it; the nod is about world x, after the key turn.
  EXPECT_TRUE(a.translation().isApprox(Vec3f(0, 0, 1)));
  const Eigen::Matrix3f expected =
      (Eigen::AngleAxisf(static_cast<float>(kPi / 4), Vec3f::UnitX()) *
       Eigen::AngleAxisf(static_cast<float>(kPi / 2), Vec3f::UnitY())).toRotationMatrix();
  EXPECT_TRUE(a.linear().isApprox(expected, 1e-5f));
}

// groom.vertices meets a published groom size exactly (Han & Harada Table 1, model 1:
// 19,776 strands, 221,078 vertices), strands differing by at most one vertex.
TEST(GroomVertices, ExactTotalForTheTable1Sizes) {
  const Scenario sc = load_scenario(std::filesystem::path(HAIRBENCH_TEST_DATA_DIR) / "../../scenarios/paper/han2012_model1.json");
  EXPECT_EQ(sc.groom.strand_count(), 19776u);
  EXPECT_EQ(sc.groom.vertex_count(), 221078u);
  std::uint32_t lo = UINT32_MAX, hi = 0;
  for (std::size_t s = 0; s < sc.groom.strand_count(); ++s) {
    lo = std::min(lo, sc.groom.strand_size(s));
    hi = std::max(hi, sc.groom.strand_size(s));
  }
  EXPECT_EQ(lo, 11u);
  EXPECT_EQ(hi, 12u);
}

}  // namespace
}  // namespace hairbench
