// Grooms as a user brings them, with nothing but the file: `compare --groom` fits the head,
// pins the strands too short to simulate and picks the substeps, and the models hold
// together. The Ratboy mohawk, whose roots run down its neck, keeps the position-based
// models' edges within the stretched verdict's limit but for a few frames on idle, nod and
// shake; a fur derived from TestHair1, a tenth of its strands cut below a tenth of the
// median (so the import pins them whole), is ok in every model.
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

namespace fs = std::filesystem;

namespace hairbench {
namespace {

const fs::path kAssets = HAIRBENCH_ASSET_DIR;

Scenario from_groom(const fs::path& file, const std::string& motion, const std::string& unit) {
  const nlohmann::json doc = groom_scenario_json(file, file.string(), motion, unit);
  return load_scenario_text(doc.dump(), fs::temp_directory_path() / (file.stem().string() + "_" + motion + ".json"));
}

TEST(RealGrooms, TheMohawkFromTheFileAloneHoldsThePositionBasedModelsTogether) {
  ThreadPool pool(2);
  for (const std::string motion : {"idle", "nod", "shake"}) {
    const Scenario sc = from_groom(kAssets / "ratboy_mohawk_v4.0/Ratboy_mohawk.tfx", motion, "cm");
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
