// A scenario made from nothing but a TressFX groom and a built-in motion: `hairbench
// compare --groom` runs it, `hairbench scenario new` writes it (docs/cli.md). Everything
// the groom does not say is fitted: the unit (unless given), the pivot and the head
// sphere through the roots, and a head collider of that sphere shrunk to the rest hair.
#pragma once

#include "scenarios/scenario.h"

#include <nlohmann/json.hpp>

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace hairbench {

// The built-in scenarios whose head scripts `compare --groom` runs by default.
std::vector<std::string> default_motions();

// The scenario file for `groom` (written in the file as `groom_as_written`, relative to
// the file's folder or absolute) under the head script, wind, frames, time step, gravity
// and settle time of the built-in scenario `motion`; `unit` is cm, mm, m or auto. Throws
// InputError naming --motion for a motion that is not a built-in scenario, and naming
// --groom for a file that is neither .tfx nor .tfxproj.
// `fit_above`, when given, fits the head on the roots higher than it (file units).
nlohmann::json groom_scenario_json(const std::filesystem::path& groom, const std::string& groom_as_written,
                                   const std::string& motion, const std::string& unit,
                                   std::optional<double> fit_above = std::nullopt);

// `base` (a groom scenario) under another built-in motion: its head script, wind, frames,
// time step, gravity and settle time, and the name GROOM_MOTION. The groom, its fit and
// its colliders are kept, so a groom is loaded and fitted once for every motion.
Scenario with_motion(const Scenario& base, const std::string& motion);

// The name of a groom scenario: the groom file's stem and the motion.
std::string groom_scenario_name(const std::filesystem::path& groom, const std::string& motion);

// Lines for the terminal: what was read, guessed, fitted and repaired.
std::string import_summary(const Scenario& sc);

}  // namespace hairbench
