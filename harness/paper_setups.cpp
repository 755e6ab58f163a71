#include "harness/paper_setups.h"

#include "core/parallel.h"
#include "harness/runner.h"
#include "models/plante2001/fused/wisp_fused.h"
#include "models/plante2001/settings.h"
#include "scenarios/groom_gen.h"

#include <chrono>
#include <cmath>

namespace hairbench {

namespace {
constexpr PlanteStyle kPlanteStyles[] = {{"short", 199, 5, 0.08}, {"medium", 73, 11, 0.25}, {"long", 56, 9, 0.45}};
constexpr int kStrandsPerWisp = 6;
constexpr double kPlanteFrameDt = 1.0 / 24.0;
constexpr double kFig611Period = 2.0;  // shake's oscillation
}  // namespace

std::span<const PlanteStyle> plante_styles() { return kPlanteStyles; }

PlanteStyleTiming time_plante_style(const PlanteStyle& style, int frames,
                                    const std::function<void(const plante::WispModel&)>& after_frame) {
  GroomSpec spec;
  spec.strands = style.wisps * kStrandsPerWisp;
  spec.vertices_per_strand = style.vertices;
  spec.length = style.length;
  const Groom groom = generate_groom(spec, 0.1f, "plante2001").groom;
  Scenario shake = load_scenario(find_scenario("shake"));
  shake.dt = kPlanteFrameDt;
  ParamSet params(plante::kParams, groom.region_names.size());
  params.set("wisps", style.wisps, {"plante2001", ""});
  // The paper's segments per wisp (§5.3), the pinned first one included, rather than the
  // wisp width's resolution.
  params.set("skeleton_segments", style.vertices - 2, {"plante2001", ""});
  // The paper's wisp counts, unsplit: the width cap (settings.h) bounds the rebuilt
  // strands' edge error, which this timing does not measure.
  params.set("wisp_width_max", 1000, {"plante2001", ""});
  ThreadPool pool(1);
  plante::PlanteWispModel model(ModelContext{&pool});
  model.reset(groom, params);
  PlanteStyleTiming r;
  StageTimes times;
  for (int f = 0; f < frames; ++f) {
    const FrameInput in = frame_input(shake, f);
    times.clear();
    const auto start = std::chrono::steady_clock::now();
    model.step(in, times);
    r.step_ms += std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    for (const auto& e : times.entries()) r.stage_ms[std::string(e.name)] += e.ms;
    if (after_frame) after_frame(model);
  }
  const auto& s = model.wisps();
  r.wisps = static_cast<double>(s.wisp_count());
  r.segments_per_wisp = static_cast<double>(s.node_count() - s.wisp_count()) / r.wisps;
  r.sim_s = frames * kPlanteFrameDt;
  return r;
}

Scenario fig611_scenario(int strands, int nodes) {
  Scenario sc = load_scenario(find_scenario("shake"));
  // Figure 6.1.1 times each model at its own substeps, whatever the groom.
  sc.auto_substeps = false;
  GroomSpec spec;
  spec.strands = strands;
  spec.vertices_per_strand = nodes;
  sc.groom = generate_groom(spec, sc.head_radius, "fig611").groom;
  // The Halén models simulate `nodes` nodes a strand of their own: the groom's.
  sc.models["*"].base["nodes"] = nodes;
  return sc;
}

FrameInput fig611_frame_input(const Scenario& sc, int frame) {
  const double t0 = std::fmod(frame * sc.dt, kFig611Period);
  FrameInput in;
  in.frame = frame;
  in.dt = sc.dt;
  in.t = t0 + sc.dt;
  in.head_prev = sc.head.at(t0);
  in.head = sc.head.at(in.t);
  in.gravity = sc.gravity;
  in.wind = sc.wind.at(in.t);
  in.colliders = sc.colliders;
  return in;
}

}  // namespace hairbench
