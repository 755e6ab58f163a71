// Grooms as a user brings them, with nothing but the file: `compare --groom` fits the head,
// pins the strands too short to simulate and picks the substeps, and the models hold
// together. The Ratboy mohawk's roots run down its neck: the head is fitted on its crown
// whatever its unit, without --fit-above, and the mohawk keeps the position-based
// models' edges within the stretched verdict's limit but for a few frames on idle, nod and
// shake; a fur derived from TestHair1, a tenth of its strands cut below a tenth of the
// median (so the import pins them whole), is ok in every model.
#include "core/groom_fit.h"
#include "harness/runner.h"
#include "models/registry.h"
#include "reports/verdict.h"
#include "scenarios/groom_scenario.h"
#include "scenarios/scenario.h"
#include "scenarios/tfx/tfx.h"
#include "test_support.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <string>
#include <tuple>
#include <vector>

namespace fs = std::filesystem;

namespace hairbench {
namespace {

const fs::path kAssets = HAIRBENCH_ASSET_DIR;
const fs::path kMohawk = kAssets / "ratboy_mohawk_v4.0/Ratboy_mohawk.tfx";

void expect_near(const Vec3f& got, const Vec3f& want, float tol) {
  EXPECT_LT((got - want).norm(), tol) << "got [" << got.transpose() << "], want [" << want.transpose() << "]";
}

Scenario from_groom(const fs::path& file, const std::string& motion, const std::string& unit) {
  const nlohmann::json doc = groom_scenario_json(file, file.string(), motion, unit);
  return load_scenario_text(doc.dump(), fs::temp_directory_path() / (file.stem().string() + "_" + motion + ".json"));
}

// The robust fit: the mohawk's roots run from its crown down its neck and back, and all of
// them fit a 53 cm sphere (RMS residual 0.05 of it, a cap: shaped like a scalp). The
// consensus finds the crown: a sphere of a head's size, 8-15 cm, near the built-in
// scenario's hand fit, through under half the roots, in cm and in metres alike, with the
// unit given or not. Its crown alone (the roots above 75 cm) fits the same head.
TEST(HeadFit, ConsensusFindsTheMohawksCrownNotItsNeck) {
  Groom cm = tfx::read_tfx_strands(kMohawk);
  Groom m = cm;
  for (Vec4f& p : m.positions) p.head<3>() *= 0.01f;
  for (const auto& [groom, mpu, units] :
       {std::tuple{&cm, 0.01f, std::vector<float>{}}, std::tuple{&cm, 0.01f, std::vector<float>{0.01f}},
        std::tuple{&m, 1.0f, std::vector<float>{}}, std::tuple{&m, 1.0f, std::vector<float>{1.0f}}}) {
    const HeadFit fit = fit_head(*groom, std::nullopt, units);
    SCOPED_TRACE("metres per unit " + std::to_string(mpu) + (units.empty() ? ", unit guessed" : ", unit given"));
    EXPECT_EQ(fit.method, "consensus");
    EXPECT_TRUE(fit.scalp) << fit.note;
    EXPECT_GE(fit.radius * mpu, kHeadPriorMin);
    EXPECT_LE(fit.radius * mpu, kHeadPriorMax * (1 + 1e-6));
    expect_near(fit.center * (mpu / 0.01f), Vec3f(-0.15f, 74.52f, 13.0f), 3.0f);
    EXPECT_EQ(fit.roots, 2226u);
    EXPECT_GT(fit.rejected.size(), 1000u);  // the neck and back
    EXPECT_LT(fit.rejected.size(), 1500u);
    // The rejected roots are the low ones: none of the crown's above 80 cm.
    for (std::uint32_t s : fit.rejected) EXPECT_LT(groom->positions[groom->strand_begin(s)].y() / (mpu / 0.01f), 80.0f);
  }
  std::vector<std::uint32_t> crown;
  for (std::uint32_t s = 0; s < cm.strand_count(); ++s)
    if (cm.positions[cm.strand_begin(s)].y() > 75.0f) crown.push_back(s);
  const HeadFit top = fit_head(select_strands(cm, crown));
  EXPECT_EQ(top.method, "consensus");
  EXPECT_NEAR(top.radius, 15.15f, 1.0f);
  expect_near(top.center, Vec3f(-0.15f, 74.52f, 13.0f), 1.0f);
  EXPECT_LT(top.rejected.size(), crown.size() / 10);
}

// Without --fit-above: the mohawk with its unit given, guessed, and as a metres copy with
// "m" fits a head of 8-15 cm through its crown's roots; the import says how many roots it
// rejected.
TEST(GroomScenario, FitsTheMohawksHeadWithoutBeingToldWhere) {
  Groom metres = tfx::read_tfx_strands(kMohawk);
  for (Vec4f& p : metres.positions) p.head<3>() *= 0.01f;
  const fs::path copy = fs::temp_directory_path() / "hairbench_mohawk_in_metres.tfx";
  tfx::write_tfx_v4(copy, metres);
  for (const auto& [file, unit, mpu] :
       {std::tuple{kMohawk, "cm", 0.01f}, std::tuple{kMohawk, "auto", 0.01f}, std::tuple{copy, "m", 1.0f}}) {
    SCOPED_TRACE(file.string() + " " + unit);
    const nlohmann::json doc = groom_scenario_json(file, file.string(), "shake", unit);
    const Scenario sc = load_scenario_text(doc.dump(), fs::temp_directory_path() / "mohawk_shake.json");
    ASSERT_TRUE(sc.import);
    EXPECT_EQ(sc.import->fit.method, "consensus");
    EXPECT_GE(sc.head_radius, kHeadPriorMin);
    EXPECT_LE(sc.head_radius, kHeadPriorMax * (1 + 1e-6));
    expect_near(sc.import->pivot * (mpu / 0.01f), Vec3f(-0.15f, 74.52f, 13.0f), 3.0f);
    EXPECT_GT(sc.import->fit.rejected.size(), 1000u);
    const std::string summary = import_summary(sc);
    EXPECT_NE(summary.find("head fit on " + std::to_string(2226 - sc.import->fit.rejected.size()) + " of 2226 roots (" +
                           std::to_string(sc.import->fit.rejected.size()) + " rejected"),
              std::string::npos)
        << summary;
  }
}

TEST(RealGrooms, TheMohawkFromTheFileAloneHoldsThePositionBasedModelsTogether) {
  ThreadPool pool(2);
  for (const std::string motion : {"idle", "nod", "shake"}) {
    const Scenario sc = from_groom(kMohawk, motion, "cm");
    RunOptions opt;
    opt.models = {"han_m1", "han_m2", "han_m3"};
    opt.probe = false;  // the stretch is what is checked
    opt.twin = false;
    opt.material_card = false;
    for (const RunRecord& r : run_scenario(sc, opt, pool)) {
      SCOPED_TRACE(motion + " " + r.model);
      RecordProperty(motion + "_" + r.model + "_frames_stretched", std::to_string(r.verdict.stretch.frames_above));
      EXPECT_LE(r.verdict.stretch.frames_above, 5) << r.verdict.reason;
    }
  }
}

TEST(RealGrooms, AFurWithPinnedShortStrandsIsOkInEveryModel) {
  tfx::TfxStrands t = tfx::read_tfx(kAssets / "testhair1/TestHair1.tfx");
  Groom fur;
  fur.region_names = {"fur"};
  const std::uint32_t n = t.vertices_per_strand;
  for (std::uint32_t s = 0; s < t.strand_count; s += 2) {  // every other strand, for time
    std::vector<Vec3f> pts;
    for (std::uint32_t i = 0; i < n; ++i) pts.push_back(t.positions[s * n + i].head<3>());
    if (s % 20 == 0)  // a tenth, cut to 1/20 of their length
      for (std::uint32_t i = 1; i < n; ++i) pts[i] = pts[0] + 0.05f * (pts[i] - pts[0]);
    fur.add_strand(pts, 0);
  }
  const fs::path file = fs::temp_directory_path() / "hairbench_fur.tfx";
  tfx::write_tfx_v4(file, fur);
  ThreadPool pool(2);
  for (const std::string motion : {"idle", "shake"}) {
    const Scenario sc = from_groom(file, motion, "auto");
    ASSERT_TRUE(sc.import);
    ASSERT_FALSE(sc.import->repairs.empty());
    EXPECT_EQ(sc.import->repairs.back().kind, "short_strands");
    EXPECT_EQ(sc.import->repairs.back().strands, (t.strand_count + 19) / 20);
    RunOptions opt;
    opt.models = test::kCpuModels;
    for (const RunRecord& r : run_scenario(sc, opt, pool)) {
      SCOPED_TRACE(motion + " " + r.model);
      EXPECT_EQ(verdict::status_name(r.verdict.status), "ok") << r.verdict.reason;
    }
  }
}

}  // namespace
}  // namespace hairbench
