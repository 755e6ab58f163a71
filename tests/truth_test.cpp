// The truth scenarios (docs/truth.md): the kick and the fit on their own, then every CPU
// model against the exact small oscillations of the chain it simulates.
#include "test_support.h"

#include "core/chain_modes.h"
#include "core/parallel.h"
#include "harness/precision.h"
#include "harness/runner.h"
#include "models/plugin/plugin_models.h"
#include "reports/truth.h"
#include "scenarios/groom_gen.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <string>
#include <vector>

namespace hairbench {
namespace {

using Result = truth::Observer::StrandResult;

Groom hanging(int strands, int vertices) {
  GroomSpec spec;
  spec.style = "hanging";
  spec.strands = strands;
  spec.vertices_per_strand = vertices;
  return generate_groom(spec, 0.1f, "test").groom;
}

const Vec3f kGravity(0.0f, -9.81f, 0.0f);

// The kick puts each mass a L shape_k across from where it hung, keeps every link's
// length, and holds its own mode alone: the M-weighted projection reads a L in it and
// nothing in the others (the modes are M-orthogonal).
TEST(Truth, TheKickStartsEachStrandInItsModeAlone) {
  for (int vertices : {8, 32}) {
    const Groom g = hanging(3, vertices);
    const truth::Kick kick{{1, 2, 3}, 1e-3, Vec3f::UnitX()};
    const truth::Observer obs(g, kick, kGravity);
    const std::vector<Vec4f>& p = obs.kicked();
    for (std::size_t s = 0; s < g.strand_count(); ++s) {
      SCOPED_TRACE("vertices " + std::to_string(vertices) + " strand " + std::to_string(s));
      const truth::StrandChain c = truth::strand_chain(g, s);
      const auto modes = chain::modes(c.masses, c.lengths, 9.81, 3);
      for (std::size_t k = 0; k < c.masses.size(); ++k) {
        const std::size_t v = c.first + k;
        const double link = (p[v] - p[v - 1]).head<3>().cast<double>().norm();
        EXPECT_NEAR(link, c.lengths[k], 2e-7) << "link " << k;
        EXPECT_NEAR(p[v].x() - g.positions[v].x(), 1e-3 * c.length * modes[s].shape[k], 2e-9) << "mass " << k;
        EXPECT_EQ(p[v].z(), g.positions[v].z());
      }
      std::vector<double> x(c.masses.size());
      for (std::size_t k = 0; k < x.size(); ++k) x[k] = p[c.first + k].x() - g.positions[c.first + k].x();
      for (std::size_t n = 0; n < 3; ++n)
        EXPECT_NEAR(chain::modal_amplitude(modes[n], c.masses, x), n == s ? 1e-3 * c.length : 0.0, 1e-8) << n;
    }
  }
}

// A damped swing written into the positions frame by frame is read back: the fit finds
// the frequency and decay it was made with, whatever the other modes hold.
TEST(Truth, TheFitReadsBackAKnownSwing) {
  const Groom g = hanging(2, 8);
  const truth::Kick kick{{2, 3}, 1e-3, Vec3f::UnitX()};
  truth::Observer obs(g, kick, kGravity);
  const double dt = 1.0 / 60.0, omega[2] = {17.0, 29.0}, sigma[2] = {0.3, 0.0};
  std::vector<std::vector<double>> shapes;
  for (std::size_t s = 0; s < 2; ++s) {
    const truth::StrandChain c = truth::strand_chain(g, s);
    shapes.push_back(chain::modes(c.masses, c.lengths, 9.81, 3)[s + 1].shape);
  }
  for (int f = 0; f <= 300; ++f) {
    std::vector<Vec4f> p = g.positions;
    const double t = f * dt;
    for (std::size_t s = 0; s < 2; ++s) {
      const truth::StrandChain c = truth::strand_chain(g, s);
      for (std::size_t k = 0; k < c.masses.size(); ++k)
        p[c.first + k].x() += static_cast<float>(2.5e-4 * std::exp(-sigma[s] * t) * std::cos(omega[s] * t) * shapes[s][k]);
    }
    obs.add(p);
  }
  const std::vector<Result> r = obs.result(dt);
  ASSERT_EQ(r.size(), 2u);
  for (std::size_t s = 0; s < 2; ++s) {
    EXPECT_NEAR(r[s].omega, omega[s], 1e-5 * omega[s]) << s;
    EXPECT_NEAR(r[s].sigma, sigma[s], 1e-4) << s;
    EXPECT_GT(r[s].share, 0.99) << s;
  }
}

TEST(Truth, StrandsThatAreNotChainsAreRefused) {
  Groom g = hanging(1, 8);
  EXPECT_THROW(truth::Observer(g, {{7}, 1e-3, Vec3f::UnitX()}, kGravity), std::invalid_argument) << "6 masses, mode 7";
  g.positions[5].w() = 0.0f;
  EXPECT_THROW(truth::strand_chain(g, 0), std::invalid_argument) << "a pin past the free vertices";
}

// One model on truth_chain_8 (three 8-vertex strands kicked in modes 1, 2 and 3) with
// `overrides`; its truth results, one per mode.
std::vector<Result> kicked(const std::string& model, std::vector<ParamOverride> overrides = {},
                           RunRecord* out = nullptr) {
  const Scenario sc = load_scenario(find_scenario("truth_chain_8"));
  ThreadPool pool(2);
  RunOptions opt;
  opt.models = {model};
  opt.overrides = std::move(overrides);
  opt.material_card = false;
  std::vector<RunRecord> runs = run_scenario(sc, opt, pool);
  const RunRecord& r = test::find(runs, model);
  EXPECT_FALSE(r.failure.has_value()) << model << ": " << (r.failure ? r.failure->reason : "");
  EXPECT_TRUE(r.truth.has_value());
  if (!r.truth) return {};
  EXPECT_EQ(r.truth->skipped_why, "") << model;
  if (out) *out = r;
  return r.truth->strands;
}

double order(double coarse, double fine) { return std::log2(std::abs(coarse) / std::abs(fine)); }

class TruthModels : public ::testing::Test {
 protected:
  static void SetUpTestSuite() { plugin::load(HAIRBENCH_FTL_PLUGIN); }
};

// Every CPU model can start from the kick, and each reference variant reads the same
// modes as the model it is the reference of (bit-identical pairs to the bit; the
// forest's, whose kernel reorders rounding, to 1e-6).
TEST_F(TruthModels, EveryModelStartsFromTheKick) {
  for (const std::string m : {"han_m1", "han_m2", "han_m3", "halen_spring", "halen_cascade", "halen_forest",
                               "plante_wisp", "muller_ftl"}) {
    SCOPED_TRACE(m);
    const std::vector<Result> r = kicked(m);
    ASSERT_EQ(r.size(), 3u);
    for (const Result& x : r) EXPECT_TRUE(std::isfinite(x.omega)) << "mode " << x.mode;
    if (m == "muller_ftl") continue;
    const std::vector<Result> ref = kicked(m + "_ref");
    ASSERT_EQ(ref.size(), 3u);
    for (std::size_t i = 0; i < 3; ++i) {
      if (m == "halen_forest") {
        EXPECT_NEAR(ref[i].omega, r[i].omega, 1e-6 * r[i].omega);
      } else {
        EXPECT_EQ(ref[i].omega, r[i].omega) << "mode " << r[i].mode;
        EXPECT_EQ(ref[i].sigma, r[i].sigma) << "mode " << r[i].mode;
      }
    }
  }
}

// The position-based chains (Han & Harada's methods with their shape terms off, Halén &
// Wester's spring and cascade with their springs off, follow-the-leader with its whole
// velocity correction) along a ladder of steps h, h/2, h/4 (h = dt / substeps; 1, 2, 4
// substeps, follow-the-leader 2, 4, 8, whose error reaches its asymptote later), the edge
// constraints iterated 64 times:
//  - the frequency error falls at second order in the step (measured 1.7-2.4), and
//    Richardson's extrapolation from the two finer steps, (4 w(h/4) - w(h/2)) / 3, lands on
//    the exact frequency within what it leaves: the amplitude's own softening at 1e-3 L
//    (below 1e-4, Chain.TheNonlinearChainSwingsAtItsModesFrequencies), the next term of
//    the error's series in (w h)^2 (the square of the error at h/2), and the constraints'
//    own error, read as twice the change at h/4 from 32 to 64 iterations;
//  - the decay falls at first order: the numerical damping is the integrator's, and
//    vanishes with the step (the undamped chain does not decay).
// Finer steps are not a convergence test for these models: their positions are floats,
// and below about h = dt / 12 a step's g h^2 is a few hundred ulp of a vertex's height
// and the rounding takes over (docs/truth.md, "The float floor").
TEST_F(TruthModels, PositionBasedChainsConvergeToTheChainAtSecondOrder) {
  for (const std::string m : {"han_m1", "han_m2", "han_m3", "halen_spring", "halen_cascade", "muller_ftl"}) {
    SCOPED_TRACE(m);
    const bool ftl = m == "muller_ftl";
    auto at = [&](int substeps, int iterations) {
      std::vector<ParamOverride> o = {{m, "substeps", static_cast<double>(substeps)}};
      if (!ftl) o.push_back({m, "length_iterations", static_cast<double>(iterations)});
      return kicked(m, o);
    };
    const int first = ftl ? 2 : 1;
    const std::vector<std::vector<Result>> ladder = {at(first, 64), at(2 * first, 64), at(4 * first, 64)};
    const std::vector<Result> fewer = ftl ? ladder[2] : at(4 * first, 32);
    for (const auto& rung : ladder) ASSERT_EQ(rung.size(), 3u);
    ASSERT_EQ(fewer.size(), 3u);
    for (std::size_t n = 0; n < 3; ++n) {
      SCOPED_TRACE("mode " + std::to_string(n + 1));
      const double e1 = ladder[0][n].frequency_error, e2 = ladder[1][n].frequency_error,
                   e4 = ladder[2][n].frequency_error;
      const double iterations = 2.0 * std::abs(e4 - fewer[n].frequency_error);
      RecordProperty(m + "_mode" + std::to_string(n + 1) + "_errors",
                     test::sci(e1) + " " + test::sci(e2) + " " + test::sci(e4));
      EXPECT_GT(order(e1, e2), 1.5);
      EXPECT_GT(order(e2, e4), 1.5);
      EXPECT_LT(std::abs((4.0 * e4 - e2) / 3.0), 1e-4 + e2 * e2 + iterations);
      EXPECT_NEAR(order(ladder[0][n].sigma, ladder[1][n].sigma), 1.0, 0.15);
      EXPECT_NEAR(order(ladder[1][n].sigma, ladder[2][n].sigma), 1.0, 0.15);
    }
  }
}

// The interactive forest in its chain limit (joints free, gravity compensation off) is not
// a chain: with k = v = 0 its joint torques vanish and, with J = m L l (inertia 1), every
// segment's absolute angle obeys a'' = -(g / l) sin a on its own, l the strand's length
// (kernels::forest_integrate). Every displacement is then a mode, at w = sqrt(g / l),
// and explicit Euler (Eq. 4.2.6) makes each grow at w^2 h / 2. docs/truth.md gives the
// derivation; the test holds the forest to its own answer, not the chain's.
TEST_F(TruthModels, TheForestSwingsAsIndependentPendula) {
  RunRecord run;
  const std::vector<Result> r = kicked("halen_forest", {}, &run);
  ASSERT_EQ(r.size(), 3u);
  const double w = std::sqrt(9.81 / 0.25), h = (1.0 / 60.0) / run.params["substeps"].get<double>();
  for (const Result& x : r) {
    SCOPED_TRACE("mode " + std::to_string(x.mode));
    EXPECT_NEAR(x.omega, w, 2e-3 * w);
    EXPECT_NEAR(x.sigma, -w * w * h / 2.0, 0.1 * w * w * h / 2.0);
  }
  EXPECT_LT(r[2].omega / r[2].exact_omega, 0.25) << "mode 3 of the chain is four times faster";
}

// The layered wisp's skeleton in its chain limit (bending and envelope springs off, one
// strand a wisp) is the chain of its nodes, whose masses are half the hair of each
// adjacent segment (the tip node half the others), on axial springs of stiffness K per
// unit hair length: under its weight each link stretches by g (the mass below it) / (K
// l_k). Symplectic Euler at 1 kHz leaves a phase error of (w h)^2 / 24, below 3e-5, and no
// decay. So the measured frequencies are the stretched chain's, within the amplitude's
// softening (1e-4) and the skeleton's axial ringing (the kick starts from the rest
// lengths; measured: 1e-4).
TEST_F(TruthModels, TheWispIsTheChainOfItsStretchedSkeleton) {
  RunRecord run;
  const std::vector<Result> r = kicked("plante_wisp", {}, &run);
  ASSERT_EQ(r.size(), 3u);
  const double K = run.params["axial_stiffness"].get<double>(), g = 9.81;
  const Scenario sc = load_scenario(find_scenario("truth_chain_8"));
  ThreadPool pool(1);
  const ModelInfo* info = find_model("plante_wisp");
  ParamSet p = resolve_params(*info, sc, {});
  const auto model = make_model(*info, sc, p, pool);
  for (std::size_t s = 0; s < 3; ++s) {
    SCOPED_TRACE("mode " + std::to_string(r[s].mode));
    const truth::StrandChain c = truth::strand_chain(*model->simulated_groom(), s);
    std::vector<double> stretched = c.lengths;
    double below = 0.0;
    for (std::size_t k = c.masses.size(); k-- > 0;) {
      below += c.masses[k];
      stretched[k] += g * below / (K * c.lengths[k]);
    }
    const double w = chain::modes(c.masses, stretched, g, 3)[s].omega;
    RecordProperty("wisp_mode" + std::to_string(s + 1) + "_vs_stretched", test::sci(r[s].omega / w - 1.0));
    EXPECT_NEAR(r[s].omega, w, 3e-4 * w);
    EXPECT_LT(std::abs(r[s].sigma), 2e-3 * w);
  }
}

// hairbench precision on truth_chain_8: the step ladder finds the second order the
// convergence test above finds (method 1 down to the float floor past 12 substeps,
// follow-the-leader over its three substep counts), the work line's points lie on a
// Pareto front that is not empty, and every point says how its error was read.
TEST_F(TruthModels, PrecisionFindsTheOrderOnTheExactChain) {
  const Scenario sc = load_scenario(find_scenario("truth_chain_8"));
  ThreadPool pool(2);
  PrecisionOptions opt;
  opt.models = {"han_m1", "muller_ftl"};
  const nlohmann::json pr = run_precision(sc, opt, pool);
  EXPECT_EQ(pr["reference"], "exact");
  ASSERT_EQ(pr["lines"].size(), 2u);
  const nlohmann::json& han = pr["lines"][0];
  EXPECT_NEAR(han["step"]["order"].get<double>(), 2.0, 0.2);
  EXPECT_EQ(han["step"]["falls_until"].get<double>(), 12.0) << "24 substeps are below the float floor";
  EXPECT_GT(pr["lines"][1]["step"]["order"].get<double>(), 1.5);
  int front = 0;
  for (const nlohmann::json& l : pr["lines"])
    for (const nlohmann::json& p : l["work"]) {
      front += p["pareto"].get<bool>();
      EXPECT_TRUE(p.contains("damping_ratio"));
      EXPECT_TRUE(p["error"].is_number() || p.contains("why")) << p.dump();
    }
  EXPECT_GT(front, 0);
}

// Against itself the model converges: at 4x its cost knobs it is closer to its 8x run
// than at 1x. An exact reference where there is none is refused.
TEST_F(TruthModels, PrecisionAgainstItselfConvergesAndExactNeedsATruthScenario) {
  Scenario sc = load_scenario(find_scenario("shake"));
  sc.groom = every_nth_strand(sc.groom, 50);
  ThreadPool pool(2);
  PrecisionOptions opt;
  opt.models = {"han_m3"};
  opt.frames = 60;
  const nlohmann::json pr = run_precision(sc, opt, pool);
  EXPECT_EQ(pr["reference"], "self");
  const nlohmann::json& work = pr["lines"][0]["work"];
  ASSERT_EQ(work.size(), 5u);
  EXPECT_LT(work[4]["error"].get<double>(), 0.5 * work[2]["error"].get<double>());
  opt.reference = PrecisionReference::exact;
  EXPECT_THROW(run_precision(sc, opt, pool), InputError);
}

}  // namespace
}  // namespace hairbench
