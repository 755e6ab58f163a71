// The phases of a scenario's script, for charts that shade them: when the head moves
// between keys, when an oscillator shakes it, when wind blows. Derived from the script
// alone, so every report of the same scenario shades the same intervals.
#pragma once

#include "scenarios/scenario.h"

#include <string>
#include <vector>

namespace hairbench {

struct Phase {
  double start = 0.0, end = 0.0;  // seconds
  std::string kind;               // "move" (between head keys), "oscillate", "wind"
  std::string label;              // e.g. "rotate ±60° about y at 2 Hz"
};

// Phases in order of start time, clipped to [0, duration] (a run may be shorter or longer
// than the scenario's own frame count); intervals of zero length are left out. A key segment is a "move" when its two keys differ in translation or rotation; a
// wind phase spans the time the wind strength is non-zero.
std::vector<Phase> scenario_phases(const Scenario& sc, double duration);

}  // namespace hairbench
