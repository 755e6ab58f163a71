// `hairbench stress`: where does each model break? Escalates one axis at a
// time from a stable base scenario and runs degenerate grooms; failures are results.
#pragma once

#include "scenarios/scenario.h"

#include <nlohmann/json.hpp>

#include <functional>
#include <optional>
#include <set>
#include <string>
#include <vector>

namespace hairbench {

class ThreadPool;

// One value tried on one axis.
struct StressCell {
  double value = 0.0;
  bool stable = true;
  std::string reason;  // why it failed ("" when stable)
};

struct StressAxisResult {
  std::string model, axis, unit;
  std::vector<StressCell> cells;  // in escalation order
  // The last stable value before the first failure, and that failure (unset when the
  // axis never failed, or failed at its first value).
  std::optional<double> last_stable, first_failing;
  std::string reason;
};

struct DegenerateResult {
  std::string model, name;
  std::string status;  // "ok", "unstable" or "refused" (refused at load, with reason)
  std::string reason;
};

struct StressOptions {
  std::vector<std::string> models;
  std::string base = "shake";  // built-in scenario or path: the stable starting point
  std::size_t keep_every = 10;  // thin the base groom: every n-th strand
  int value_stride = 1;         // > 1 keeps every n-th value of each axis (quick runs)
  std::string axes = ".*";      // regex over axis names
  bool degenerate = true;
  // When set, only the cells and degenerate grooms with these keys run (a shard's part,
  // stress_cell_key and stress_groom_key); the result holds only them.
  std::optional<std::set<std::string>> only;
};

struct StressResult {
  std::string base;
  std::string base_hash;  // the thinned base scenario (scenario_hash): shards must share it
  std::size_t strands = 0, vertices = 0;
  std::vector<StressAxisResult> axes;
  std::vector<DegenerateResult> degenerate;
};

// The keys of one stress run in a plan and a shard report: "MODEL/AXIS=VALUE" (the value
// as %.17g) and "MODEL/groom:NAME".
std::string stress_cell_key(const std::string& model, const std::string& axis, double value);
std::string stress_groom_key(const std::string& model, const std::string& groom);

// Sets an axis's last_stable, first_failing and reason from its cells, in escalation
// order.
void decide_axis(StressAxisResult& axis);

struct Plan;
class CostModel;
// Every run of the stress command, in the order it runs them, with its estimated cost
// (each runs the model alone, as its own reference), cut into `count` shards.
Plan plan_stress(const StressOptions& options, const CostModel& costs, int count);

// progress(done, total) after each run.
StressResult run_stress(const StressOptions& options, ThreadPool& pool,
                        const std::function<void(int, int)>& progress = {});

// The report's `stress` section (model x axis -> last stable, first failing, reason).
nlohmann::json stress_json(const StressResult& result);
// Plain-text table for the terminal.
std::string stress_table(const StressResult& result);

}  // namespace hairbench
