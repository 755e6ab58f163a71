// Cutting a run list into N shards that separate processes (a CI matrix, a Slurm job
// array) run apart, and estimating what each costs (docs/sharding.md). A shard is told
// only I/N; it recomputes the whole plan from the same inputs and keeps its part, so
// every shard of one command agrees on the cut without talking to the others.
#pragma once

#include "core/fnv64.h"

#include "core/params.h"
#include "models/registry.h"
#include "scenarios/scenario.h"

#include <nlohmann/json.hpp>

#include <cstdint>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace hairbench {

struct RunOptions;

// --shard I/N: part I (1-based) of N. count 0: the whole run list in one process.
struct ShardSpec {
  int index = 0;
  int count = 0;
  bool active() const { return count > 0; }
};
// Parses "I/N" (1 <= I <= N <= kMaxShards); throws InputError naming --shard.
ShardSpec parse_shard(const std::string& arg);
inline constexpr int kMaxShards = 10000;
// What a shard process pays besides its runs (start, loading the scenarios, writing the
// report), s, on the development machine.
inline constexpr double kProcessSeconds = 0.4;

// What a run costs on one machine, in seconds, and where the estimate came from.
struct CostEstimate {
  double seconds = 0.0;
  std::string source;  // "table", "costs: run", "costs: model"
};

// The estimate of a run's wall time: vertices x frames x the model's ns per vertex and
// step (scaled by its iteration and substep parameters), plus the per-frame metrics
// and the perturbation probe every lane pays. The built-in table was measured on the
// development machine (docs/sharding.md); --costs REPORT.json replaces it with the step
// times a previous report measured, per run where the report has the same run, else per
// model.
class CostModel {
 public:
  CostModel() = default;
  // Reads a hairbench-report (compare, sweep or merged); throws InputError naming the
  // file and the field.
  static CostModel from_report(const std::filesystem::path& file);

  // `key` identifies the run as in a report (run_key); `work_fraction` is the share of
  // frames in which the scenario drives the hair or it is still settling (the rest
  // cost a sleeping model almost nothing).
  CostEstimate run(const ModelInfo& model, const ParamSet& params, const std::string& key, std::size_t strands,
                   std::size_t vertices, int frames, double work_fraction) const;
  bool from_file() const { return !file_.empty(); }
  const std::string& file() const { return file_; }

 private:
  std::string file_;
  std::map<std::string, double> run_frame_seconds_;  // run key -> mean step time, s
  std::map<std::string, double> model_ns_;       // model -> median ns per vertex and step
};

// A run's identity in a plan and a report: "SCENARIO/MODEL", with "/KNOB=VALUE" in a
// sweep (the value as %.17g, so that every double has one spelling).
std::string run_key(const std::string& scenario, const std::string& model, const std::string& knob_name,
                    std::optional<double> knob_value);
// The same from a report's run (its "scenario", "model" and "knob").
std::string run_key(const nlohmann::json& run);

// One unit of the partition: its own cost, and the group whose shared cost a shard pays
// once when it holds any unit of the group (a lockstep batch's reference lane, a stress
// axis's base scenario).
struct PlanItem {
  std::string key;    // run_key, or a stress cell's name
  std::string label;  // how --plan prints it
  std::size_t group = 0;
  CostEstimate cost;
  int shard = 0;  // 1-based, set by partition
};

struct Plan {
  int count = 1;
  std::vector<PlanItem> items;       // in the order of the unsharded command
  std::vector<double> group_cost;    // per group, seconds
  std::vector<std::string> group_label;
  double process_seconds = 0.0;      // what every shard process pays once (start, load, report)
  std::vector<double> shard_seconds; // per shard: process + its groups + its items
  std::string cost_source;           // "built-in table" or the --costs file
};

// Assigns every item to a shard: heaviest first (ties in plan order) to the shard where
// it adds the least, its group's shared cost counted where the shard lacks the group
// yet (ties: the lower shard). Deterministic for the same plan; fills shard_seconds.
void partition(Plan& plan);

// The share of a scenario's first `frames` frames in which the hair is driven (the head
// moves, the wind blows) or may still be settling (within kSettleSeconds of being
// driven, or of the start, when the rest shape sags under gravity); in the other frames
// the models' strands sleep.
double work_fraction(const Scenario& sc, int frames);
inline constexpr double kSettleSeconds = 1.0;

// compare's and sweep's run list: per scenario, per knob value (one batch each, sharing
// the reference lane), every model of `run.models`, estimated by `costs`, cut into
// `count` shards. A reported model that is the reference at the reference's parameters
// shares its lane and costs nothing of its own.
Plan plan_runs(const std::vector<Scenario>& scenarios, const RunOptions& run, const std::string& knob_name,
               const std::vector<double>& knob_values, const CostModel& costs, int count);

// The plan as --plan prints it: every item with its shard and estimate, then per shard
// its runs, groups and estimated seconds.
std::string plan_text(const Plan& plan, const std::string& what);
// The report's `shard` object: this shard, the count and the whole plan's keys with
// their shards, so that merge can name a missing run.
nlohmann::json shard_json(const Plan& plan, const ShardSpec& shard);
// "0123456789abcdef": a hash of the plan's keys and their shards; shards of one command
// carry the same.
std::string plan_hash(const Plan& plan);

}  // namespace hairbench
