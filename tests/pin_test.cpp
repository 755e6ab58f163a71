// Every model honours every pin (docs/groom-import.md, "Pins"): a vertex of inverse mass
// 0, from the file or from an import repair, moves rigidly with the head, whatever the
// model does with the free vertices around it. A model whose paper cannot represent a
// strand's pins holds that strand static, and counts it (HairModel::static_strands).
#include "test_support.h"

#include "core/parallel.h"
#include "harness/runner.h"
#include "models/plugin/plugin_models.h"
#include "models/registry.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>

namespace hairbench {
namespace {

// The shake groom, thinned, with three kinds of pins beside the usual roots: every
// fifth strand pinned whole (a short strand the import pins), every fifth from the
// second pinned at its tip too, every fifth from the third pinned at its middle vertex.
struct PinnedGroom {
  Scenario sc;
  std::size_t strands_pinned_twice = 0;
};

PinnedGroom pinned_groom() {
  PinnedGroom out{test::builtin("shake", 24)};
  Groom& g = out.sc.groom;
  for (std::size_t s = 0; s < g.strand_count(); ++s) {
    const std::uint32_t b = g.strand_begin(s), n = g.strand_size(s);
    switch (s % 5) {
      case 0:
        for (std::uint32_t i = 0; i < n; ++i) g.positions[b + i].w() = 0.0f;
        break;
      case 1:
        g.positions[b + n - 1].w() = 0.0f;
        ++out.strands_pinned_twice;
        break;
      case 2:
        g.positions[b + n / 2].w() = 0.0f;
        ++out.strands_pinned_twice;
        break;
      default:
        break;
    }
  }
  out.sc.frames = 90;  // the shake's first swings: the head at full speed
  return out;
}

class Pins : public ::testing::TestWithParam<std::string> {};

TEST_P(Pins, EveryPinnedVertexMovesRigidlyWithTheHead) {
  const ModelInfo* info = find_model(GetParam());
  ThreadPool pool(2);
  const ModelContext ctx{&pool};
  if (info->unavailable) {
    const std::string why = info->unavailable(ctx);
    if (!why.empty()) GTEST_SKIP() << why;
  }
  const PinnedGroom pg = pinned_groom();
  const Scenario& sc = pg.sc;
  const Groom& rest = sc.groom;
  auto model = make_model(*info, sc, resolve_params(*info, sc, {}), pool);
  // Float rounding of p' = R p + t: each coordinate is a sum of three products and t,
  // each term rounded once, so 2 ulp of the largest term bounds it.
  const double ulp = std::numeric_limits<float>::epsilon();
  double worst = 0.0;  // in ulp
  double moved = 0.0;  // the farthest a pinned vertex went from its rest position, metres
  std::string where;
  for (int f = 0; f < sc.frames; ++f) {
    const FrameInput in = frame_input(sc, f);
    StageTimes t;
    model->step(in, t);
    const auto p = model->positions();
    ASSERT_EQ(p.size(), rest.positions.size());
    const Eigen::Matrix3d r = in.head.linear().cast<double>();
    const Eigen::Vector3d tr = in.head.translation().cast<double>();
    for (std::size_t i = 0; i < p.size(); ++i) {
      if (rest.positions[i].w() != 0.0f) continue;
      const Eigen::Vector3d q = rest.positions[i].head<3>().cast<double>();
      const Eigen::Vector3d want = r * q + tr;
      moved = std::max(moved, (want - q).norm());
      const double scale = r.cwiseAbs().rowwise().maxCoeff().maxCoeff() * q.cwiseAbs().maxCoeff() + tr.cwiseAbs().maxCoeff();
      const double err = (p[i].head<3>().cast<double>() - want).cwiseAbs().maxCoeff() / (ulp * std::max(scale, 1e-30));
      if (err > worst) {
        worst = err;
        where = "frame " + std::to_string(f) + " vertex " + std::to_string(i);
      }
    }
  }
  EXPECT_LE(worst, 2.0) << GetParam() << ": a pinned vertex is " << worst << " ulp from its head-transformed rest position at " << where;
  EXPECT_GT(moved, 0.05) << "the head carried the pins";
  // The forest, a tree grown from the root, holds the strands pinned past a free vertex
  // static and counts them; the other models honour those pins.
  const bool forest = GetParam().rfind("halen_forest", 0) == 0;
  EXPECT_EQ(model->static_strands(), forest ? pg.strands_pinned_twice : 0u);
}

// The built-in models and the default plugin's (muller_ftl, through the plugin ABI).
std::vector<std::string> every_model() {
  plugin::load(HAIRBENCH_FTL_PLUGIN);
  std::vector<std::string> names;
  for (const ModelInfo& m : model_registry()) names.emplace_back(m.name);
  return names;
}

INSTANTIATE_TEST_SUITE_P(EveryModel, Pins, ::testing::ValuesIn(every_model()),
                         [](const auto& p) { return std::string(p.param); });

}  // namespace
}  // namespace hairbench
