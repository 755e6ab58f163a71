// A scenario: groom + scripted head motion + colliders + wind + per-model parameters
// (the scenario file contract, docs/scenarios.md).
#pragma once

#include "core/error.h"
#include "core/groom.h"
#include "core/groom_fit.h"
#include "scenarios/groom_gen.h"
#include "scenarios/head_motion.h"
#include "scenarios/tfx/tfx.h"

#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace hairbench {

// Wind over time: a direction and a strength, optionally keyed (piecewise linear in t).
struct WindScript {
  Vec3f direction = Vec3f::UnitX();
  double strength = 0.0;
  struct Key {
    double t;
    double strength;
  };
  std::vector<Key> keys;  // sorted by t; when present they replace `strength`
  Wind at(double t) const;
  bool ever_active() const;
};

// Parameter overrides from a scenario file for one model key ("*" or a model name).
struct ParamOverrides {
  std::map<std::string, double> base;
  std::map<std::string, std::map<std::string, double>> regions;  // region name -> values
  bool substeps_auto = false;  // "substeps": "auto" (harness/substeps.h)
};

// How an imported groom was placed and cleaned, for the terminal and the report's
// scenarios[].groom (docs/report-schema.md).
struct GroomImport {
  std::filesystem::path file;
  std::string unit;
  std::string unit_from;   // "given", or how it was guessed (guess_unit)
  Vec3f pivot = Vec3f::Zero();  // file units
  std::string pivot_from;  // "given", "collision sphere" or "fit"
  HeadFit fit;             // the sphere through the guides' roots, metres; set when anything was fitted
  bool fitted = false;
  bool head_radius_fit = false;
  std::string degenerate = "repair";
  std::vector<Repair> repairs;
  double seconds_fit = 0.0;  // guessing the unit, fitting the head sphere and the collider
};

// A truth scenario (docs/truth.md): strands hanging still under gravity, each started in
// a small multiple of one of its chain's modes, every model in its chain limit
// (ParamSet::set_chain_limit), never sleeping, the frequency and decay of each mode read
// from the run (reports/truth.h).
struct TruthKick {
  std::vector<int> modes;  // strand s starts in mode modes[s % size()], 1 the slowest
  // The kick's largest displacement as a fraction of the chain's length (its tip's, in the
  // slowest mode): small enough that the chain stays linear (docs/truth.md).
  double amplitude = 1e-3;
  Vec3f direction = Vec3f::UnitX();  // horizontal, unit
};

// The model every other is measured against unless a scenario or --reference names
// another: Han & Harada's method 1, the exact serial transforms (docs/metrics.md).
inline constexpr const char* kDefaultReference = "han_m1";

struct Scenario {
  std::string name;
  std::string description;
  std::filesystem::path source;  // the file it was loaded from ("" if built in code)
  int frames = 240;
  double dt = 1.0 / 60.0;
  Vec3f gravity{0.0f, -9.81f, 0.0f};
  // The full groom: every strand the metrics cover, follow hairs of an imported asset
  // included.
  Groom groom;
  // With an imported asset whose follow hairs are rebuilt from their guides
  // (groom.follow_hairs "follow"): the follow layout and the guide groom the models
  // simulate. groom is then `guides` expanded by `follow` (tfx::expand_follow_hairs), and
  // guides has groom's regions. Unset when models simulate every strand of `groom`.
  std::optional<tfx::FollowHairs> follow;
  Groom guides;
  std::vector<std::map<std::string, double>> region_params;  // per groom region defaults
  float head_radius = 0.1f;
  HeadMotion head;
  std::vector<Sphere> colliders;
  WindScript wind;
  double settle_from = 0.0;
  std::string reference = kDefaultReference;
  std::map<std::string, ParamOverrides> models;  // "*" and model names, as in the file
  std::optional<GroomImport> import;              // set for an imported TressFX groom
  std::optional<TruthKick> truth;
  // Explicit models pick their substeps from the groom when nobody gives a number
  // (harness/substeps.h); stress runs turn that off to escalate a model as it is.
  bool auto_substeps = true;

  double duration() const { return frames * dt; }
};

// Loads and validates a scenario file. Every problem is an InputError with the message
// "FILE: KEY: what is wrong" (unknown keys, wrong types, missing or non-finite numbers,
// out-of-range values, missing referenced files).
Scenario load_scenario(const std::filesystem::path& file);
// The same for a scenario held as JSON text; `file` names it in messages, and paths in
// it are relative to file's folder.
Scenario load_scenario_text(const std::string& text, const std::filesystem::path& file);

// The folder of built-in scenarios (scenarios/builtin in the source tree, or
// $HAIRBENCH_SCENARIO_DIR), and its scenario files sorted by name.
std::filesystem::path builtin_scenario_dir();
std::vector<std::filesystem::path> builtin_scenarios();

// Loads every built-in scenario. The built-in scenarios' assets ship with them
// (scenarios/assets), so any error, a missing asset file included, is thrown.
std::vector<Scenario> load_builtin_scenarios();

// A name ("shake") or a path to a JSON file -> the file; InputError if neither exists.
std::filesystem::path find_scenario(const std::string& name_or_path);

// The resolved scenario as a hash (16 hex digits): the loaded groom's bits, the head
// script's keys and oscillators, the colliders, wind, gravity, time step, the first
// `frames` frames, the settle time, the reference and every parameter override the file
// gives. Shards of one sweep must agree on it (hairbench merge); the script is hashed as
// written, not evaluated, so that the hash does not depend on a machine's libm.
std::string scenario_hash(const Scenario& sc, int frames);

}  // namespace hairbench
