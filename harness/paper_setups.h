// The papers' timing set-ups that both `hairbench reproduce` and `hairbench_bench` run:
// Plante et al. 2001 §5.3's three hair styles, and Halén & Wester 2007 Figure 6.1.1's
// small grooms under a repeating head shake.
#pragma once

#include "core/hair_model.h"
#include "scenarios/scenario.h"

#include <functional>
#include <map>
#include <span>
#include <string>

namespace hairbench {

namespace plante {
class WispModel;
}

// §5.3: short (199 wisps, ~4.0 segments), medium (73, ~9.9), long (56, ~7.7). Nodes per
// wisp rounded to the paper's averages; lengths chosen so that segments are about as
// long as the wisps are wide (§4.1, footnote 1).
struct PlanteStyle {
  const char* name;
  int wisps;
  int vertices;  // per strand = wisp nodes: segments + 1
  double length;
};
std::span<const PlanteStyle> plante_styles();

struct PlanteStyleTiming {
  double wisps = 0.0, segments_per_wisp = 0.0;  // segments as the paper counts them, the pinned first one included
  double step_ms = 0.0;                         // all frames' steps
  double sim_s = 0.0;                           // simulated time
  std::map<std::string, double> stage_ms;       // per stage, all frames
};
// One style at the paper's rates (plante_wisp's defaults) and wisp counts (no splitting
// of wide wisps), on one thread like the paper's single R12000, under the head script of
// `shake` in `frames` frames of 1/24 s (the paper's frame rate). `after_frame`, when
// set, is shown the model after each frame, outside the timed steps.
PlanteStyleTiming time_plante_style(const PlanteStyle& style, int frames,
                                    const std::function<void(const plante::WispModel&)>& after_frame = {});

// Figure 6.1.1: `strands` strands of `nodes` vertices generated on `shake`'s head.
Scenario fig611_scenario(int strands, int nodes);
// Frame `frame` of `shake`'s head script repeated every 2 s (the head is back at rest
// at the end of each period), so a benchmark can run any number of frames.
FrameInput fig611_frame_input(const Scenario& sc, int frame);

}  // namespace hairbench
