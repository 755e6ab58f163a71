// Bring your own groom: the head sphere fitted through the shipped assets' roots agrees
// with the built-in scenarios' hand-fitted numbers, units are read from the groom's size
// (and refused when two fit), degenerate strands are repaired and listed or refused with
// the strand and edge, and substeps picked from the groom keep halen_spring's edges
// together on the mohawk, where the default count stretches them.
#include "core/error.h"
#include "core/groom_fit.h"
#include "core/parallel.h"
#include "harness/runner.h"
#include "models/registry.h"
#include "scenarios/groom_scenario.h"
#include "scenarios/scenario.h"
#include "scenarios/tfx/tfx.h"
#include "reports/verdict.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <limits>
#include <tuple>

namespace fs = std::filesystem;
using namespace hairbench;

namespace {

const fs::path kAssets = HAIRBENCH_ASSET_DIR;
const fs::path kMohawk = kAssets / "ratboy_mohawk_v4.0/Ratboy_mohawk.tfx";

// The message of the InputError f throws ("" when it throws none).
template <class F>
std::string error_of(F&& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

void expect_near(const Vec3f& got, const Vec3f& want, float tol) {
  EXPECT_LT((got - want).norm(), tol) << "got [" << got.transpose() << "], want [" << want.transpose() << "]";
}

TEST(HeadFit, AgreesWithTheBuiltInScenariosHandFits) {
  // tressfx_mohawk: "sphere fitted through the crown's roots, y > 75 cm", head radius 13 cm.
  const HeadFit mohawk = fit_head(tfx::read_tfx_strands(kMohawk), 75.0);
  ASSERT_TRUE(mohawk.sphere) << mohawk.note;
  expect_near(mohawk.center, Vec3f(-0.15f, 74.52f, 13.0f), 0.01f);
  EXPECT_NEAR(mohawk.radius, 13.0f, 13.0f * 0.2f);
  // tressfx_testhair1: "sphere fitted through the roots".
  const HeadFit testhair = fit_head(tfx::read_tfx_strands(kAssets / "testhair1/TestHair1.tfxproj"));
  ASSERT_TRUE(testhair.sphere) << testhair.note;
  expect_near(testhair.center, Vec3f(5.33f, 10.65f, -1.85f), 0.01f);
  // The ponytail's scenarios turn about the project's first collision sphere (26.5 cm),
  // a rough stand-in for the head: the scalp is the same head within a fifth of it.
  const HeadFit ponytail = fit_head(tfx::read_tfx_strands(kAssets / "ponytail/ponytail.tfxproj"));
  ASSERT_TRUE(ponytail.sphere) << ponytail.note;
  expect_near(ponytail.center, Vec3f(-0.095f, 92.0f, 9.899f), 26.5f * 0.25f);
  EXPECT_NEAR(ponytail.radius, 26.5f, 26.5f * 0.25f);
  // The consensus leaves out the tie: the tail section's 474 guides, rooted 45 cm behind
  // the head's centre on a ring of a few centimetres, are most of what it rejects.
  EXPECT_EQ(ponytail.method, "consensus");
  EXPECT_GT(ponytail.rejected.size(), 400u);
  EXPECT_LT(ponytail.rejected.size(), ponytail.roots / 4);
  // TestHair1's roots lie all round a ball: no scalp; the sphere through all of them.
  EXPECT_EQ(testhair.method, "all roots");
  EXPECT_TRUE(testhair.rejected.empty());
}

TEST(HeadFit, RootsOnALineFallBackWithANote) {
  Groom g;
  for (int s = 0; s < 20; ++s) {
    const std::vector<Vec3f> pts{{s * 5.0f, 0, 0}, {s * 5.0f, 15, 0}, {s * 5.0f, 30, 0}};
    g.add_strand(pts, 0);
  }
  const HeadFit fit = fit_head(g);
  EXPECT_FALSE(fit.sphere);
  EXPECT_NE(fit.note.find("bounding-box centre"), std::string::npos) << fit.note;
  EXPECT_GT(fit.radius, 0.0f);
  // 30-unit strands 5 units apart on a 95-unit line: hair on a body in cm (30 cm strands,
  // 0.95 m) and in mm (3 cm strands, 9.5 cm): no unit is guessed.
  EXPECT_EQ(error_of([&] { guess_unit(g, fit, "line.tfx"); }),
            "line.tfx: unit: cannot tell the unit: both cm and mm fit [file units: median strand 30 (0.02-2 m: cm or "
            "mm), roots' span 95 (0.05-3 m: cm or mm), root spacing 5 (0.0001-0.05 m: cm or mm)]; give it (--unit, "
            "or \"unit\" in the scenario file)");
}

TEST(HeadFit, UnitFollowsTheHeadsSize) {
  Groom cm = tfx::read_tfx_strands(kMohawk);
  EXPECT_EQ(guess_unit(cm, fit_head(cm, 75.0), "mohawk").unit, "cm");
  // The same groom written in metres.
  Groom m = cm;
  for (Vec4f& p : m.positions) p.head<3>() *= 0.01f;
  EXPECT_EQ(guess_unit(m, fit_head(m, 0.75), "mohawk_m").unit, "m");
}

// Every shipped asset gives its built-in scenarios' unit (cm), or a refusal that says
// --unit: never another unit.
TEST(HeadFit, ShippedAssetsGiveTheirBuiltInUnitOrARefusal) {
  const Groom ponytail = tfx::read_tfx_strands(kAssets / "ponytail/ponytail.tfxproj");
  const HeadFit pfit = fit_head(ponytail);
  EXPECT_TRUE(pfit.scalp) << pfit.note;  // 0.11 of its radius off, a cap (0.40)
  EXPECT_EQ(guess_unit(ponytail, pfit, "ponytail").unit, "cm");
  // TestHair1's roots lie all round a 64-unit ball, 0.15 of its radius off it: a pivot
  // (the built-in's), not a head. Its 11-unit strands are 1.1 cm in mm: too short.
  const Groom testhair = tfx::read_tfx_strands(kAssets / "testhair1/TestHair1.tfxproj");
  const HeadFit tfit = fit_head(testhair);
  EXPECT_TRUE(tfit.sphere);
  EXPECT_FALSE(tfit.scalp);
  EXPECT_NE(tfit.note.find("not a scalp"), std::string::npos) << tfit.note;
  EXPECT_EQ(guess_unit(testhair, tfit, "testhair").unit, "cm");
  // The mohawk's consensus is its crown, a 15-unit head: cm.
  const Groom mohawk = tfx::read_tfx_strands(kMohawk);
  EXPECT_EQ(guess_unit(mohawk, fit_head(mohawk), "mohawk").unit, "cm");
  // All its roots, down the neck, fit a 53-unit sphere: a head in mm, but its 8-unit
  // median strand is hair only in cm. The cues disagree: refused.
  const std::string why = error_of([&] { guess_unit(mohawk, fit_head(mohawk, -1e9), "mohawk"); });
  EXPECT_EQ(why.rfind("mohawk: unit: cannot tell the unit: no unit fits every cue [file units: head radius 52.86", 0),
            0u)
      << why;
  EXPECT_NE(why.find("--unit"), std::string::npos) << why;
  EXPECT_NE(why.find("--fit-above"), std::string::npos) << why;
}

// Roots on a 10 cm scalp cap (from 0.3 of the radius below the centre up) and down a
// neck under it (a column of 6 cm radius, its axis 2 cm behind the centre, from 9 to 30 cm
// below it): the fit is the scalp, and what it rejects is the neck. The neck's top few
// centimetres lie within the band of the scalp's sphere and join the consensus (nape
// hair), which pulls the sphere down and out a little: radius within 10%, centre within
// 1.5 cm; every root it rejects is the neck's, and most of the neck is rejected.
TEST(HeadFit, ConsensusRejectsANeckColumnUnderAScalp) {
  Groom g;
  const int scalp = 600, neck = 600;
  for (int i = 0; i < scalp + neck; ++i) {
    // Even spreads by the golden angle: deterministic, no generator.
    const bool on_scalp = i < scalp;
    const double u = ((on_scalp ? i : i - scalp) + 0.5) / (on_scalp ? scalp : neck), phi = 2.399963 * i;
    Vec3f root, out;
    if (on_scalp) {
      const double y = -0.3 + 1.3 * u, r = std::sqrt(1.0 - y * y);
      out = Vec3f(float(r * std::cos(phi)), float(y), float(r * std::sin(phi)));
      root = 0.1f * out;
    } else {
      out = Vec3f(float(std::cos(phi)), 0.0f, float(std::sin(phi)));
      root = 0.06f * out + Vec3f(0.0f, float(-0.09 - 0.21 * u), -0.02f);
    }
    const std::vector<Vec3f> pts{root, root + 0.05f * out, root + 0.1f * out};
    g.add_strand(pts, 0);
  }
  const HeadFit fit = fit_head(g, std::nullopt, {1.0f});
  EXPECT_EQ(fit.method, "consensus");
  EXPECT_NEAR(fit.radius, 0.1f, 0.01f);
  expect_near(fit.center, Vec3f::Zero(), 0.015f);
  EXPECT_GT(fit.rejected.size(), std::size_t(0.75 * neck));
  for (std::uint32_t s : fit.rejected) EXPECT_GE(s, std::uint32_t(scalp)) << "a scalp root rejected";
}

// The mohawk in metres with strand 100's edge 5 made zero and strand 200's edge 7 1e-7 m
// long (vertex i moved onto vertex i-1, or 1e-7 m from it along the edge).
Groom damaged_mohawk() {
  Groom g = tfx::load_tfx_asset(kMohawk, {0.01f}).groom;
  auto squeeze = [&](std::size_t s, std::uint32_t edge, float length) {
    Vec4f& b = g.positions[g.strand_begin(s) + edge + 1];
    const Vec4f& a = g.positions[g.strand_begin(s) + edge];
    const Vec3f d = (b - a).head<3>().normalized();
    b.head<3>() = a.head<3>() + length * d;
  };
  squeeze(100, 5, 0.0f);
  squeeze(200, 7, 1e-7f);
  return g;
}

TEST(Hygiene, NearZeroEdgesAreResampledAndListed) {
  Groom g = damaged_mohawk();
  const std::vector<Repair> repairs = repair_groom(g, DegeneratePolicy::Repair, "mohawk");
  ASSERT_FALSE(repairs.empty());
  EXPECT_EQ(repairs[0].kind, "near_zero_edges");
  EXPECT_EQ(repairs[0].strands, 2u);
  EXPECT_EQ(repairs[0].items, 2u);
  EXPECT_EQ(repairs[0].example, "strand 100 edge 5 (0 m)");
  validate_groom(g, "mohawk");  // no edge left at or under 1e-7 m
  const std::vector<float> len = rest_edge_lengths(g);
  // Resampled strands have equal edges (chords of equal arc-length steps).
  for (std::size_t s : {100u, 200u}) {
    const std::uint32_t b = g.strand_begin(s);
    EXPECT_GT(len[b + 6], 0.5f * len[b + 2]) << s;
  }
  EXPECT_EQ(repairs_text(repairs).rfind("repairs: 2 near-zero edges in 2 strands resampled (first: strand 100 edge 5", 0),
            0u);
}

// Short edges, authored but under kShortEdge of the strand's median (the ponytail's folded
// guide), are resampled and listed apart from near-zero ones; an edge above the limit is
// left as authored.
TEST(Hygiene, ShortEdgesAreResampledAndEdgesAboveTheLimitKept) {
  Groom g = tfx::load_tfx_asset(kMohawk, {0.01f}).groom;
  auto shorten = [&](std::size_t s, std::uint32_t edge, double fraction) {
    std::vector<float> e;
    for (std::uint32_t v = g.strand_begin(s); v + 1 < g.strand_begin(s + 1); ++v)
      e.push_back((g.positions[v + 1] - g.positions[v]).head<3>().norm());
    std::nth_element(e.begin(), e.begin() + e.size() / 2, e.end());
    Vec4f& b = g.positions[g.strand_begin(s) + edge + 1];
    const Vec4f& a = g.positions[g.strand_begin(s) + edge];
    b.head<3>() = a.head<3>() + static_cast<float>(fraction) * e[e.size() / 2] * (b - a).head<3>().normalized();
  };
  const Groom clean = g;
  shorten(300, 10, 0.9 * kShortEdge);
  shorten(400, 10, 1.2 * kShortEdge);
  const Groom authored = g;
  const std::vector<Repair> repairs = repair_groom(g, DegeneratePolicy::Repair, "mohawk");
  ASSERT_EQ(repairs.size(), 1u);
  EXPECT_EQ(repairs[0].kind, "short_edges");
  EXPECT_EQ(repairs[0].strands, 1u);
  EXPECT_EQ(repairs[0].items, 1u);
  EXPECT_EQ(repairs[0].example.rfind("strand 300 edge 10 (", 0), 0u) << repairs[0].example;
  EXPECT_EQ(repairs_text(repairs).rfind("repairs: 1 short edges in 1 strands resampled (first: strand 300 edge 10", 0), 0u)
      << repairs_text(repairs);
  const std::vector<float> len = rest_edge_lengths(g);
  const std::uint32_t b = g.strand_begin(300);
  EXPECT_GT(len[b + 10], 0.5f * len[b + 2]);
  for (std::uint32_t v = g.strand_begin(400); v < g.strand_begin(401); ++v)
    EXPECT_EQ(g.positions[v], authored.positions[v]) << "vertex " << v;
  EXPECT_EQ(error_of([&] { Groom r = authored; repair_groom(r, DegeneratePolicy::Refuse, "m.tfx"); })
                .rfind("m.tfx: strand 300 edge 10: short rest edge of ", 0),
            0u);
  Groom untouched = clean;
  for (const Repair& r : repair_groom(untouched, DegeneratePolicy::Repair, "mohawk")) EXPECT_NE(r.kind, "short_edges");
}

TEST(Hygiene, RefuseNamesTheStrandAndEdge) {
  Groom g = damaged_mohawk();
  EXPECT_EQ(error_of([&] { repair_groom(g, DegeneratePolicy::Refuse, "mohawk.tfx"); }),
            "mohawk.tfx: strand 100 edge 5: near-zero rest edge of 0 m (under 0.01 of the strand's median edge; "
            "\"degenerate\": \"repair\" resamples the strand)");
}

TEST(Hygiene, DuplicateStrandsAreRemovedAndShortOnesPinned) {
  Groom g;
  const std::vector<Vec3f> a{{0, 0, 0}, {0, 1, 0}, {0, 2, 0}}, b{{1, 0, 0}, {1, 1, 0}, {1, 2, 0}},
      tiny{{2, 0, 0}, {2, 0.01f, 0}, {2, 0.02f, 0}};
  for (const auto* s : {&a, &b, &a, &b, &tiny}) g.add_strand(*s, 0);
  const std::vector<Repair> repairs = repair_groom(g, DegeneratePolicy::Repair, "g");
  ASSERT_EQ(repairs.size(), 2u);
  EXPECT_EQ(repairs[0].kind, "coincident_roots");
  EXPECT_EQ(repairs[0].strands, 2u);
  EXPECT_EQ(g.strand_count(), 3u);
  EXPECT_EQ(repairs[1].kind, "short_strands");
  EXPECT_EQ(g.positions[g.strand_begin(2) + 2].w(), 0.0f);
}

// The built-in mohawk (strands under 2 cm rigid) without its hand-set substeps.
Scenario mohawk_without_substeps() {
  Scenario sc = load_scenario(builtin_scenario_dir() / "tressfx_mohawk.json");
  sc.models.erase("*");
  sc.frames = 10;
  return sc;
}

// At 32 nodes, the short strands' sub-millimetre edges are simulated (at the default 8 their
// nodes are centimetres apart and six substeps hold them).
TEST(AutoSubsteps, KeepHalenSpringsEdgesOnTheMohawk) {
  const Scenario sc = mohawk_without_substeps();
  const ModelInfo& spring = *find_model("halen_spring");
  const std::vector<ParamOverride> fine{{"halen_spring", "nodes", 32}};
  const auto chosen = choose_substeps(spring, sc, resolve_params(spring, sc, fine), fine);
  ASSERT_TRUE(chosen);
  EXPECT_EQ(chosen->source, "auto");
  EXPECT_GT(chosen->value, 6);
  EXPECT_FALSE(chosen->capped);
  // A number given anywhere wins.
  EXPECT_EQ(choose_substeps(spring, sc, resolve_params(spring, sc, {{"halen_spring", "substeps", 6}}),
                            {{"halen_spring", "substeps", 6}})
                ->source,
            "given");
  ThreadPool pool(2);
  RunOptions opt;
  opt.models = {"halen_spring"};
  opt.probe = false;
  opt.overrides = fine;
  EXPECT_EQ(run_scenario(sc, opt, pool).back().verdict.status, verdict::Status::ok);
  opt.overrides = {{"halen_spring", "nodes", 32}, {"halen_spring", "substeps", 6}};
  EXPECT_EQ(run_scenario(sc, opt, pool).back().verdict.status, verdict::Status::stretched);
}

TEST(GroomScenario, FitsEverythingFromTheGroomAlone) {
  const nlohmann::json doc = groom_scenario_json(kMohawk, kMohawk.string(), "shake", "auto", 75.0);
  const Scenario sc = load_scenario_text(doc.dump(), fs::temp_directory_path() / "mohawk_shake.json");
  ASSERT_TRUE(sc.import);
  EXPECT_EQ(sc.import->unit, "cm");
  EXPECT_EQ(sc.import->pivot_from, "fit");
  expect_near(sc.import->pivot, Vec3f(-0.15f, 74.52f, 13.0f), 0.01f);
  EXPECT_NEAR(sc.head_radius, 0.1515f, 1e-3f);
  // The collider is the head sphere shrunk until no rest vertex, pinned or free, is
  // inside it.
  ASSERT_EQ(sc.colliders.size(), 1u);
  EXPECT_LE(sc.colliders[0].radius, sc.head_radius);
  // The nearest rest vertex stays a clearance outside it, not on its surface, where
  // rounding would decide whether a model finds it inside.
  float nearest = std::numeric_limits<float>::infinity();
  for (const Vec4f& p : sc.groom.positions) nearest = std::min(nearest, (p.head<3>() - sc.colliders[0].center).norm());
  EXPECT_EQ(sc.colliders[0].radius, nearest * (1.0f - tfx::kColliderClearance));
  EXPECT_GT(nearest - sc.colliders[0].radius, 1e-4f);
  EXPECT_EQ(error_of([] { groom_scenario_json(kMohawk, "x", "moonwalk", "auto"); }).rfind(
                "--motion: moonwalk: not a built-in scenario (one of: ", 0),
            0u);
}

// A scalp-shaped sphere no head has is refused with the radius, the unit and the options:
// the mohawk's centimetres read as metres give no head of a head's size, and its roots a
// 53 m scalp.
TEST(GroomScenario, RefusesAScalpNoHeadHas) {
  const nlohmann::json doc = groom_scenario_json(kMohawk, kMohawk.string(), "shake", "m");
  const std::string why =
      error_of([&] { load_scenario_text(doc.dump(), fs::temp_directory_path() / "mohawk_shake.json"); });
  EXPECT_NE(why.find("head.radius: the roots fit a scalp-shaped sphere of radius 52.8"), std::string::npos) << why;
  EXPECT_NE(why.find("outside a head's [0.04, 0.4) m, with the unit m (given)"), std::string::npos) << why;
  EXPECT_NE(why.find("--unit"), std::string::npos) << why;
  EXPECT_NE(why.find("--fit-above"), std::string::npos) << why;
}

// Short strands: under 1/10 of the median pinned; under 2 cm and 1/4 of the median pinned;
// a strand under 2 cm in a groom of short hair (median 1.5 cm) left free.
TEST(Hygiene, ShortStrandsArePinnedByLengthAndByShareOfTheMedian) {
  auto strand = [](float x, float length) {
    return std::vector<Vec3f>{{x, 0, 0}, {x, length / 2, 0}, {x, length, 0}};
  };
  Groom g;
  for (int i = 0; i < 9; ++i) g.add_strand(strand(0.01f * i, 0.10f), 0);
  g.add_strand(strand(0.2f, 0.019f), 0);  // under 2 cm and under 1/4 of 10 cm
  g.add_strand(strand(0.3f, 0.03f), 0);   // over 2 cm, over 1/10
  repair_groom(g, DegeneratePolicy::Repair, "g");
  EXPECT_EQ(g.positions[g.strand_begin(9) + 2].w(), 0.0f);
  EXPECT_NE(g.positions[g.strand_begin(10) + 2].w(), 0.0f);
  Groom fur;
  for (int i = 0; i < 9; ++i) fur.add_strand(strand(0.01f * i, 0.015f), 0);
  fur.add_strand(strand(0.2f, 0.012f), 0);  // under 2 cm, but 0.8 of the median
  repair_groom(fur, DegeneratePolicy::Repair, "fur");
  EXPECT_NE(fur.positions[fur.strand_begin(9) + 2].w(), 0.0f);
}

}  // namespace
