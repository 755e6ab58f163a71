// `hairbench stress`: where does each model break? Escalates one axis at a
// time from a stable base scenario and runs degenerate grooms; failures are results.
#pragma once

#include "scenarios/scenario.h"

#include <nlohmann/json.hpp>

#include <functional>
#include <optional>
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
};

struct StressResult {
  std::string base;
  std::size_t strands = 0, vertices = 0;
  std::vector<StressAxisResult> axes;
  std::vector<DegenerateResult> degenerate;
};

// progress(done, total) after each run.
StressResult run_stress(const StressOptions& options, ThreadPool& pool,
                        const std::function<void(int, int)>& progress = {});

// The report's `stress` section (model x axis -> last stable, first failing, reason).
nlohmann::json stress_json(const StressResult& result);
// Plain-text table for the terminal.
std::string stress_table(const StressResult& result);

}  // namespace hairbench
