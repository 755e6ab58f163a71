// The fused Han & Harada models (han_m1..3, models/han2012/fused/) beyond the scene matrix
// of fused_reference_test.cpp: the paper's setting, stages switched off by parameters,
// the method parameter, per-region methods, and a state that depends on neither the
// thread count nor the ISA variant of the kernel.
#include "agreement_support.h"

#include "core/parallel.h"
#include "kernels/simd/isa.h"
#include "kernels/han2012/fused/han_soa.h"
#include "models/han2012/reference/han_reference.h"
#include "models/han2012/fused/han_fused.h"
#include "models/registry.h"
#include "reports/metrics.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <map>
#include <set>

namespace hairbench {
namespace {

using test::first_difference;
using test::paper_model1;
using test::state_hash_after;

const std::vector<std::string> kMethods = {"han_m1", "han_m2", "han_m3"};

TEST(HanFused, BitIdenticalToReferenceOnPonytailWithPaperSetting) {
  const Scenario sc = test::builtin("ponytail", 8);
  for (const std::string& m : kMethods) {
    double diff = 0.0;
    EXPECT_EQ(first_difference(sc, m, m + "_ref", sc.frames, test::paper_setting(), &diff), -1)
        << m << " max diff " << diff;
  }
}

// Stages switched off by parameters give the same bits as running them with no effect.
TEST(HanFused, BitIdenticalWithStagesOff) {
  const Scenario sc = test::builtin("shake", 16);
  const std::vector<std::vector<ParamOverride>> settings = {
      {{"*", "global_stiffness", 0.0}},
      {{"*", "global_range", 0.0}},
      {{"*", "local_iterations", 0}},
      {{"*", "length_iterations", 0}, {"*", "local_iterations", 4}},
  };
  for (const auto& ov : settings)
    for (const std::string& m : kMethods)
      EXPECT_EQ(first_difference(sc, m, m + "_ref", 60, ov), -1) << m << " " << ov[0].name;
}

// method = 1..3 in every region runs that method whatever the model's own (§6 LOD).
TEST(HanFused, MethodParameterSelectsTheMethod) {
  const Scenario sc = test::builtin("shake", 16);
  EXPECT_GE(first_difference(sc, "han_m3", "han_m1_ref", 60, {}), 0) << "the methods should differ";
  EXPECT_EQ(first_difference(sc, "han_m3", "han_m1_ref", 60, {{"han_m3", "method", 1}}), -1);
  EXPECT_EQ(first_difference(sc, "han_m1", "han_m2_ref", 60, {{"han_m1", "method", 2}}), -1);
  EXPECT_EQ(first_difference(sc, "han_m2", "han_m3_ref", 60, {{"han_m2", "method", 3}}), -1);
}

// Per-region methods: each region's strands follow their own method, as if the whole
// groom ran it (strands are independent).
TEST(HanFused, PerRegionMethod) {
  const Scenario sc = paper_model1(16);
  ASSERT_GE(sc.groom.region_names.size(), 2u);
  ThreadPool pool(2);
  const ModelInfo* info = find_model("han_m1");
  ParamSet mixed = resolve_params(*info, sc, {});
  mixed.set_region(1, "method", 3, {"test", ""});
  han_fused::HanFusedModel fast(han::Method::Serial, ModelContext{&pool});
  fast.reset(sc.groom, mixed);
  auto m1 = test::make_named("han_m1_ref", sc, {}, pool);
  auto m3 = test::make_named("han_m3_ref", sc, {}, pool);
  for (int f = 0; f < 30; ++f) {
    const FrameInput in = frame_input(sc, f);
    StageTimes t;
    fast.step(in, t);
    m1->step(in, t);
    m3->step(in, t);
  }
  std::size_t checked[2] = {0, 0};
  for (std::size_t s = 0; s < sc.groom.strand_count(); ++s) {
    const bool tail = sc.groom.strand_region[s] == 1;
    const auto expect = tail ? m3->positions() : m1->positions();
    for (std::size_t v = sc.groom.strand_begin(s); v < sc.groom.strand_offsets[s + 1]; ++v)
      ASSERT_EQ(std::memcmp(&fast.positions()[v], &expect[v], sizeof(Vec4f)), 0) << "strand " << s;
    ++checked[tail ? 1 : 0];
  }
  EXPECT_GT(checked[0], 0u);
  EXPECT_GT(checked[1], 0u);
}

TEST(HanFused, StateHashIndependentOfThreadCount) {
  const Scenario sc = paper_model1(8);
  for (const std::string& m : kMethods) {
    const auto one = state_hash_after(sc, m, 1, 20);
    EXPECT_EQ(one, state_hash_after(sc, m, 2, 20)) << m;
    EXPECT_EQ(one, state_hash_after(sc, m, 3, 20)) << m;
  }
}

TEST(HanFused, IsaVariantsGiveTheSameBits) {
  const Scenario sc = paper_model1(16);
  ThreadPool pool(2);
  for (han::Method method : {han::Method::Serial, han::Method::Jacobi, han::Method::RestFrames}) {
    const ParamSet params = resolve_params(*find_model("han_m1"), sc, {});
    han_fused::HanFusedModel best(method, ModelContext{&pool}), base(method, ModelContext{&pool});
    base.use_kernel(kernels::han_soa::frame_kernel_baseline());
    best.reset(sc.groom, params);
    base.reset(sc.groom, params);
    for (int f = 0; f < 30; ++f) {
      StageTimes t;
      best.step(frame_input(sc, f), t);
      base.step(frame_input(sc, f), t);
    }
    EXPECT_EQ(metrics::state_hash(best.positions()), metrics::state_hash(base.positions()))
        << kernels::simd::isa_name(kernels::simd::runtime_isa());
  }
}

// Stages the scene does not need are reported skipped, the others with a time.
TEST(HanFused, SkippedStagesAreReported) {
  Scenario sc = test::builtin("shake", 16);
  ThreadPool pool(2);
  auto m = test::make_named("han_m3", sc, {{"*", "global_stiffness", 0.0}}, pool);
  FrameInput in = frame_input(sc, 0);
  in.colliders = {};
  StageTimes t;
  m->step(in, t);
  std::map<std::string, bool> skipped;
  for (const auto& e : t.entries()) skipped[std::string(e.name)] = e.skipped;
  EXPECT_EQ(skipped, (std::map<std::string, bool>{{"integrate", false},
                                                   {"global_shape", true},
                                                   {"local_shape", false},
                                                   {"length", false},
                                                   {"collision", true}}));
}

}  // namespace
}  // namespace hairbench
