#include "reports/frame_metrics.h"

#include "reports/device_metrics.h"

#include <algorithm>
#include <limits>
#include <stdexcept>
#include <string>

namespace hairbench::metrics {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// The accuracy metrics gate a change that moves them by 10%, above a floor well over
// float reordering noise (~1e-6 of L-bar) and below the differences between methods
// (~1e-3).
constexpr double kGateRel = 0.10, kGateAbs = 1e-4;

// --- deviation_vs_reference: deviation (metrics.h) from the reference's same frame.

void deviation_host(const FrameView& v, std::span<double> out) {
  out[0] = v.reference_ok ? deviation(v.p, v.reference, v.rest.mean_strand_length) : kNaN;
}
void deviation_device(const FrameView& v, std::span<double> out) {
  out[0] = v.reference_ok ? deviation(v.rest, v.strands) : kNaN;
}
constexpr Column kDeviationColumns[] = {{"deviation_vs_reference", true, false}};
constexpr Summary kDeviationSummaries[] = {
    {"rms", 0, Stat::rms, "deviation RMS", "%.3g", kGateRel, kGateAbs},
    {"max", 0, Stat::max, "deviation max", "%.3g"},
    {"final", 0, Stat::final, "", "%.3g"}};

// --- jaggedness (metrics.h).

void jaggedness_host(const FrameView& v, std::span<double> out) { out[0] = jaggedness(v.rest, v.p); }
void jaggedness_device(const FrameView& v, std::span<double> out) { out[0] = jaggedness(v.rest, v.strands); }
constexpr Column kJaggednessColumns[] = {{"jaggedness", true, false}};
constexpr Summary kJaggednessSummaries[] = {
    {"mean", 0, Stat::mean, "jaggedness mean", "%.3g", kGateRel, kGateAbs},
    {"max", 0, Stat::max, "", "%.3g"}};

// --- length_error (metrics.h), with where its largest edge error is: the stretched
// verdict reads the whole groom's where no other groom holds the simulated edges.

void put_length(const LengthError& e, std::span<double> out) {
  out[0] = e.rms;
  out[1] = e.max;
  out[2] = e.worst_strand;
  out[3] = e.worst_edge;
}
void length_host(const FrameView& v, std::span<double> out) { put_length(length_error(v.rest, v.p), out); }
void length_device(const FrameView& v, std::span<double> out) { put_length(length_error(v.rest, v.strands), out); }
constexpr Column kLengthColumns[] = {{"length_error_rms", true, false},
                                     {"length_error_max", false, false},
                                     {"length_error_worst_strand", false, false},
                                     {"length_error_worst_edge", false, false}};
constexpr Summary kLengthSummaries[] = {
    {"rms", 0, Stat::rms, "length error RMS", "%.2g", kGateRel, kGateAbs},
    {"max", 1, Stat::max, "", "%.2g"}};

// --- rest_shape_error (metrics.h), summarised over the settled frames.

void rest_shape_host(const FrameView& v, std::span<double> out) { out[0] = rest_shape_error(v.rest, v.p, v.head); }
void rest_shape_device(const FrameView& v, std::span<double> out) { out[0] = rest_shape_error(v.rest, v.strands); }
constexpr Column kRestShapeColumns[] = {{"rest_shape_error", true, false}};
constexpr Summary kRestShapeSummaries[] = {
    {"", 0, Stat::settled_mean, "rest shape error", "%.3g", kGateRel, kGateAbs}};

// --- penetration (metrics.h). Follow hairs are rebuilt from their guides and not
// collided (as TressFX does not): the guides' and the follow layer's apart, and the
// larger, the same number as one pass over every vertex.

void penetration_host(const FrameView& v, std::span<double> out) {
  if (!v.guides) {
    out[0] = penetration(v.p, v.spheres);
    return;
  }
  const std::size_t guide_vertices = v.guides->groom->vertex_count();
  out[1] = penetration(v.p.first(guide_vertices), v.spheres);
  out[2] = penetration(v.p.subspan(guide_vertices), v.spheres);
  out[0] = std::max(out[1], out[2]);
}
void penetration_device(const FrameView& v, std::span<double> out) {
  if (!v.guides) {
    out[0] = penetration(v.strands);
    return;
  }
  const std::size_t guide_strands = v.guides->groom->strand_count();
  out[1] = penetration(v.strands.first(guide_strands));
  out[2] = penetration(v.strands.subspan(guide_strands));
  out[0] = std::max(out[1], out[2]);
}
constexpr Column kPenetrationColumns[] = {
    {"penetration", true, false}, {"penetration_guides", true, true}, {"penetration_follow", true, true}};
constexpr Summary kPenetrationSummaries[] = {{"max", 0, Stat::max, "penetration max (m)", "%.2g"},
                                             {"guides_max", 1, Stat::max, "", "%.2g"},
                                             {"follow_max", 2, Stat::max, "", "%.2g"}};

constexpr FrameMetric kMetrics[] = {
    {"deviation_vs_reference", "L-bar",
     "RMS distance of every vertex from the reference's same vertex at the same frame, over the mean strand length",
     kDeviationColumns, kDeviationSummaries, deviation_host, deviation_device, "dev", "deviation vs reference (/ L̄)",
     true},
    {"jaggedness", "1",
     "mean over strands of the RMS change of the curvature binormal between neighbour vertices, less the rest "
     "shape's",
     kJaggednessColumns, kJaggednessSummaries, jaggedness_host, jaggedness_device, "jag", "jaggedness"},
    {"length_error", "1", "each edge's |length - rest length| over its strand's edge scale: RMS and largest",
     kLengthColumns, kLengthSummaries, length_host, length_device, "len", ""},
    {"rest_shape_error", "L-bar",
     "RMS distance from the head-transformed rest shape over the mean strand length, mean over the settled frames",
     kRestShapeColumns, kRestShapeSummaries, rest_shape_host, rest_shape_device, "rest", ""},
    {"penetration", "m", "depth of the deepest vertex inside a head collision sphere", kPenetrationColumns,
     kPenetrationSummaries, penetration_host, penetration_device, "", ""},
};

struct ColumnRef {
  std::size_t metric, column;
};

const std::vector<ColumnRef>& all_columns() {
  static const std::vector<ColumnRef> columns = [] {
    std::vector<ColumnRef> out;
    for (std::size_t m = 0; m < std::size(kMetrics); ++m)
      for (std::size_t c = 0; c < kMetrics[m].columns.size(); ++c) out.push_back({m, c});
    return out;
  }();
  return columns;
}

const char* stat_name(Stat s) {
  switch (s) {
    case Stat::rms: return "rms";
    case Stat::mean: return "mean";
    case Stat::max: return "max";
    case Stat::final: return "final";
    case Stat::settled_mean: return "settled_mean";
  }
  return "";
}

}  // namespace

std::span<const FrameMetric> frame_metrics() { return kMetrics; }

std::size_t column_count() { return all_columns().size(); }

std::size_t first_column(std::size_t m) {
  std::size_t c = 0;
  for (std::size_t i = 0; i < m; ++i) c += kMetrics[i].columns.size();
  return c;
}

std::size_t column_index(std::string_view name) {
  const auto& columns = all_columns();
  for (std::size_t i = 0; i < columns.size(); ++i)
    if (column(i).name == name) return i;
  throw std::out_of_range("no per-frame metric records a column named '" + std::string(name) +
                          "' (reports/frame_metrics.cpp)");
}

const Column& column(std::size_t c) {
  const ColumnRef r = all_columns().at(c);
  return kMetrics[r.metric].columns[r.column];
}

nlohmann::json definitions_json() {
  nlohmann::json out = nlohmann::json::array();
  for (const FrameMetric& m : kMetrics) {
    nlohmann::json columns = nlohmann::json::array(), summaries = nlohmann::json::array();
    for (const Column& c : m.columns)
      columns.push_back({{"name", c.name}, {"reported", c.reported}, {"follow_only", c.follow_only}});
    for (const Summary& s : m.summaries) {
      nlohmann::json j = {{"key", s.key},
                          {"column", m.columns[s.column].name},
                          {"stat", stat_name(s.stat)},
                          {"label", s.label},
                          {"format", s.format}};
      j["gate"] = s.gate_rel > 0.0 ? nlohmann::json{{"rel", s.gate_rel}, {"abs", s.gate_abs}} : nlohmann::json();
      summaries.push_back(std::move(j));
    }
    out.push_back({{"name", m.name},
                   {"unit", m.unit},
                   {"meaning", m.meaning},
                   {"columns", std::move(columns)},
                   {"summaries", std::move(summaries)},
                   {"on_device", m.device != nullptr},
                   {"cli", m.cli},
                   {"timeseries_label", m.timeseries_label},
                   {"against_reference", m.against_reference}});
  }
  return out;
}

}  // namespace hairbench::metrics
