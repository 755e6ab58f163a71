// The per-frame metrics as one table (docs/metrics.md): each entry names a metric, says
// how one frame's values are computed from a run's positions on the host and, where a
// device kernel reduced the frame to per-strand shares (core/device_metrics.h), from
// those; how the report summarises the frames; and where the CLI, the charts and the
// perf gate show it. The runner records, and the report writer, `hairbench compare`'s
// table, charts.py and ci/perf-gate show, whatever the table holds (the report carries
// the table as metric_definitions), so a new metric is one entry here, its functions and
// its test.
#pragma once

#include "core/device_metrics.h"
#include "core/types.h"
#include "reports/metrics.h"

#include <nlohmann/json.hpp>

#include <cstddef>
#include <span>
#include <string_view>
#include <vector>

namespace hairbench::metrics {

// What a metric reads of one frame of one run.
struct FrameView {
  const RestInfo& rest;     // the groom the run's positions are of
  const RestInfo* guides;   // with follow hairs rebuilt from guides: the guides' (leading strands); else null
  // A host run: its positions. A device run: its strands' shares, one per groom strand.
  std::span<const Vec4f> p;
  std::span<const StrandMetrics> strands;
  // The reference's positions at this frame (host runs), and whether the reference is
  // still running (false: the metrics against it are NaN).
  std::span<const Vec4f> reference;
  bool reference_ok = true;
  Affine3f head = Affine3f::Identity();  // rest -> world at the end of the frame
  std::span<const Vec4f> spheres;        // the head's collision spheres, world xyz, w radius
};

// One number a metric records every frame (RunRecord::series(name)).
struct Column {
  std::string_view name;
  bool reported;     // written to the report's runs[].series under `name`
  bool follow_only;  // recorded only where follow hairs are rebuilt from guides
};

// How the report reduces a column over the frames a run ran. NaN and Inf frames are left
// out of each; `final` is the last frame's value (NaN: none).
enum class Stat { rms, mean, max, final, settled_mean };

struct Summary {
  std::string_view key;  // runs[].metrics.NAME.KEY; "" : runs[].metrics.NAME is this number
  std::size_t column;    // of the metric's columns
  Stat stat;
  std::string_view label;   // a column of the charts' tables; "" : not shown there
  std::string_view format;  // printf-style precision of that column and the CLI ("%.3g")
  // ci/perf-gate's accuracy check: the candidate may exceed the baseline by
  // max(gate_rel * baseline, gate_abs); gate_rel 0: not gated.
  double gate_rel = 0.0, gate_abs = 0.0;
};

// Fills `out` (one value per column, in order) for one frame.
using FrameFn = void (*)(const FrameView&, std::span<double> out);

struct FrameMetric {
  std::string_view name;     // runs[].metrics.NAME
  std::string_view unit;     // of its values: "L-bar" (a fraction of the mean strand length), "1" or "m"
  std::string_view meaning;  // one line for the report's metric_definitions
  std::span<const Column> columns;
  std::span<const Summary> summaries;  // the first is the metric's headline (CLI, perf gate order)
  FrameFn host;
  FrameFn device;  // null: a device run's positions come back to the host for this metric
  std::string_view cli;       // its abbreviation in `hairbench compare`'s run lines; "" : not printed
  std::string_view timeseries_label;  // y axis of its panel in STEM_timeseries.png; "" : no panel
  // Measured against the reference: the report adds the reference's name and status.
  bool against_reference = false;
};

std::span<const FrameMetric> frame_metrics();

// The columns of every metric, numbered in table order: RunRecord's storage.
std::size_t column_count();
// Of the first column of metric m (index into frame_metrics()).
std::size_t first_column(std::size_t m);
// Throws std::out_of_range naming `name` when no metric records it.
std::size_t column_index(std::string_view name);
const Column& column(std::size_t c);

// The report's metric_definitions: the table, less the functions.
nlohmann::json definitions_json();

}  // namespace hairbench::metrics
