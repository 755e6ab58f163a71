// The hairbench-report JSON (docs/report-schema.md; schema_version 3: context.devices
// are objects with the GPU clock; 2: snapshot strands encoded, see encode_snapshot_strand).
#pragma once

#include "core/types.h"
#include "reports/animation.h"
#include "reports/frame_metrics.h"
#include "reports/material.h"
#include "reports/truth.h"
#include "reports/verdict.h"

#include <nlohmann/json.hpp>

#include <cstdint>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace hairbench {

// Everything measured for one model on one scenario, frame by frame.
struct RunRecord {
  std::string scenario;
  std::string model;
  std::string origin = "built-in";  // or the plugin library's path (ModelInfo::origin)
  std::string backend = "cpu";
  std::string device;  // the GPU a GPU model ran on (run "device"; context "devices")
  std::string metrics_on = "host";  // where the per-frame metrics were computed: "host" or "device"
  std::size_t strands = 0, vertices = 0;
  std::size_t static_strands = 0;  // held rigid with the head (HairModel::static_strands)
  int frames = 0;  // frames requested
  double dt = 0.0;
  double settle_from = 0.0;
  nlohmann::json params = nlohmann::json::object();
  nlohmann::json substeps;  // how substeps were chosen (harness/runner.h SubstepsChoice); null: no bound

  struct Failure {
    int frame;
    double t;
    std::string reason;
  };
  std::optional<Failure> failure;  // set when the model diverged and the run stopped
  verdict::Verdict verdict;         // the run's stability class (reports/verdict.h)

  std::string reference;  // model the deviation is measured against
  // The reference's own verdict on this scenario (its run at the reference's settings):
  // a deviation is a measure of accuracy only against a reference that is `ok`.
  verdict::Status reference_status = verdict::Status::ok;
  std::string reference_reason;  // the reference's verdict reason when it is not ok
  // The run's material card and the reference's on this scenario (reports/material.h).
  material::Card card, reference_card;
  std::optional<material::Calibration> calibration;  // what --calibrate fitted
  // On a truth scenario (reports/truth.h): each kicked strand's measured mode, or why the
  // model could not be kicked (skipped_why).
  struct Truth {
    std::string skipped_why;
    std::vector<truth::Observer::StrandResult> strands;
  };
  std::optional<Truth> truth;
  // Per frame actually run (a failed run stops early).
  std::vector<double> step_ms;
  // Per frame run: 1 where the model worked (the head moved, wind blew, or some strand was
  // awake), 0 where it skipped every stage because all its strands slept.
  std::vector<std::uint8_t> worked;
  // Device time per step, GPU models with timestamps only: the steps run again back to
  // back after a warm-up (timing.gpu_ms, what BM_HanVk measures), and as they ran in
  // lockstep, between the other models' steps and the metrics (timing.gpu_ms_lockstep).
  std::vector<double> gpu_ms, gpu_ms_lockstep;
  std::optional<double> gpu_clock_mhz;  // the GPU's clock right after the back-to-back steps, where known
  // The per-frame metrics (reports/frame_metrics.h), one series per column of the table,
  // in its order: a value per frame run (NaN where the reference had already failed, for
  // the metrics against it; NaN at the frame the run diverged). A follow-only column is
  // empty where no follow hairs are rebuilt.
  std::vector<std::vector<double>> frame_values = std::vector<std::vector<double>>(metrics::column_count());
  // The series of the column `name` (metrics::column_index; throws std::out_of_range).
  const std::vector<double>& series(std::string_view name) const { return frame_values[metrics::column_index(name)]; }
  std::vector<double>& series(std::string_view name) { return frame_values[metrics::column_index(name)]; }
  std::vector<double> t;  // time at the end of each frame
  std::map<std::string, double> stage_ms_total;  // summed over the run
  // Steps in which a stage was not needed and not run; absent when never.
  std::map<std::string, std::size_t> stage_skipped_steps;
  std::uint64_t state_hash = 0;
  // The model's state_bytes() and the time to stream them once on the run's threads
  // (harness/roofline.h), CPU models only: timing.roofline_ratio.
  std::size_t state_bytes = 0;
  double stream_ms = 0.0;
  // Wall time outside the timed steps that is the model's own work: its perturbation probe
  // at rest, making and resetting it, and the frames stepped past the scenario's end for
  // the settle check (timing.overhead_s).
  double probe_s = 0.0, twin_s = 0.0, setup_s = 0.0, settle_extra_s = 0.0;
  // The scenario whose identical probe or twin this run was handed (harness/at_rest_cache.h;
  // its time is counted there), or empty: computed for this run.
  std::string probe_from, twin_from;
  // The harness's per-frame work on this run, also timing.overhead_s: its divergence
  // checks and metric tasks, summed over the pool's tasks (CPU seconds: on two threads the
  // wall time is about half), and recording and encoding its player frames (wall).
  double metrics_s = 0.0, animation_s = 0.0;

  // Parameters given to the reference on top of the scenario's (--reference converged);
  // empty when the reference runs at the scenario's parameters.
  std::map<std::string, double> reference_overrides;
  // The swept parameter and its value for this run (hairbench sweep); unset for compare.
  struct Knob {
    std::string name;
    double value;
  };
  std::optional<Knob> knob;
  // Positions of the scenario's snapshot strands at its snapshot frames (see
  // ScenarioRecord), for strand pictures. A snapshot the run did not reach (it became
  // unstable first) has no strands.
  struct Snapshot {
    std::string label;  // "most_violent" or "final"
    int frame = -1;
    std::vector<std::vector<float>> strands;  // per snapshot strand: x0 y0 z0 x1 y1 z1 ...
  };
  std::vector<Snapshot> snapshots;
  // The run's frames for report.html's player (reports/animation.h; ScenarioRecord's
  // animation says which strands and frames): `frames` recorded, `data` encoded. The
  // reference's own run has no data of its own (`same_as_reference`): it is the scenario's.
  struct Animation {
    int frames = 0;
    std::string data;
    bool same_as_reference = false;
    bool ended = false;  // stopped by a blown-up coordinate, not by the run's end
  };
  std::optional<Animation> animation;
};

// What the runs of one scenario share: its script phases, and the frames and strands
// the strand pictures show, with the reference's positions there.
struct ScenarioRecord {
  std::string name;
  int frames = 0;
  double dt = 0.0;
  double mean_strand_length = 0.0;  // L-bar, metres: per-vertex deviation is |p - p_ref| / L-bar
  double head_radius = 0.0;
  // An imported groom: its file, unit, pivot, fitted head and repairs (null otherwise).
  nlohmann::json groom;
  struct PhaseSpan {
    double start, end;
    std::string kind, label;
  };
  std::vector<PhaseSpan> phases;
  std::vector<std::uint32_t> snapshot_strands;  // groom strand indices, at most kMaxSnapshotStrands
  struct SnapshotFrame {
    std::string label;
    int frame = -1;
    double t = 0.0;
    double violence = 0.0;  // the criterion's value at that frame (see runner.h)
    Affine3f head = Affine3f::Identity();
  };
  std::vector<SnapshotFrame> snapshot_frames;
  std::string reference;
  std::vector<RunRecord::Snapshot> reference_snapshots;
  // The player's frames (reports/animation.h): every `stride`-th frame, the strands drawn
  // (groom indices; `named` says which a verdict picked and why), each one's drawn
  // vertices, the head pose at each recorded frame and the reference's frames.
  struct Animation {
    int stride = 1;
    std::vector<std::uint32_t> strands;
    std::vector<animation::Named> named;
    std::vector<std::vector<std::uint32_t>> vertices;
    std::vector<Affine3f> heads;
    RunRecord::Animation reference;
  };
  std::optional<Animation> animation;
  // The reference's final positions (metrics::state_hash): every shard of a sweep runs
  // the reference itself, and hairbench merge checks that they all got the same bits.
  std::uint64_t reference_state_hash = 0;
  // The resolved scenario with the command's --set, --frames and reference
  // (scenarios/scenario.h, scenario_hash), 16 hex digits.
  std::string definition_hash;
};

inline constexpr std::size_t kMaxSnapshotStrands = 200;

// A GPU the runs used (context.devices), with its clock at the start and end of the
// command where it can be read (harness/gpu_clock.h).
struct DeviceRecord {
  std::string name, type;
  double timestamp_period_ns = 0.0;  // 0: no timestamps
  std::optional<double> clock_start_mhz, clock_end_mhz, clock_max_mhz;
  std::string clock_source;
};

struct ReportContext {
  int threads = 1;
  std::vector<DeviceRecord> devices;
  // The plugin libraries loaded and the default ones left out (harness/plugin_loading.h);
  // null: the caller loads none.
  nlohmann::json plugins = nullptr;
};

nlohmann::json context_json(const ReportContext& ctx);
// With `sc`, the run's snapshots are written relative to the scenario's reference's.
nlohmann::json run_json(const RunRecord& run, const ScenarioRecord* sc = nullptr);
nlohmann::json scenario_json(const ScenarioRecord& sc);
// `scenarios` adds the report's "scenarios" list (phases, snapshot frames); a report
// without it is still a complete report.
nlohmann::json make_report(const ReportContext& ctx, const std::vector<RunRecord>& runs,
                           const std::vector<ScenarioRecord>& scenarios = {});
// Writes pretty JSON, creating the folder; throws std::runtime_error on I/O failure.
void write_json(const std::filesystem::path& file, const nlohmann::json& j);

// Snapshot strands in the report: positions rounded to 10 micrometres (a drawn pixel
// of a strand picture is millimetres; the deviations the pictures colour are fractions
// of L-bar, centimetres), as integers q = round(x / 1e-5 m) in the order x0 y0 z0 x1 ...;
// with `ref` (a run's snapshot marked "relative_to_reference"), q minus the reference
// strand's q. Each value is predicted from the same axis of the two vertices before it
// (2 q[v-1] - q[v-2]; q[v-1] for the second vertex, 0 for the first) and the residual
// r = q - prediction is zigzag-mapped ((r << 1) ^ (r >> 63)), written as a LEB128 varint
// (7 bits a byte, low bits first, high bit set while more follow), and the bytes as padded
// base64 (RFC 4648). A strand with a non-finite or absurd (beyond 1e6 m) position has no
// code (null).
inline constexpr double kSnapshotUnitMetres = 1e-5;
inline constexpr const char* kSnapshotEncoding =
    "runs[].snapshots[].strands and scenarios[].snapshots.reference.snapshots[].strands: one string per strand "
    "(null: a non-finite position or one beyond 1e6 m), padded base64 of LEB128 varints; each varint is a "
    "zigzag-mapped residual r = q - p, q = round(coordinate / 1e-5 m) (minus the reference strand's q at the same "
    "frame where the snapshot has relative_to_reference: true), coordinates in the order x0 y0 z0 x1 ..., the "
    "prediction p of a value from the same axis of the vertices before it: 0 for the first vertex, q[v-1] for the "
    "second, 2 q[v-1] - q[v-2] after";
std::optional<std::string> encode_snapshot_strand(const std::vector<float>& xyz, const std::vector<float>* ref = nullptr);
// The inverse, in metres (multiples of 1e-5; `ref` decoded first); throws
// std::runtime_error on a malformed code.
std::vector<double> decode_snapshot_strand(std::string_view code, const std::vector<double>* ref = nullptr);

// Summary statistics used by the report (exposed for tests).
double median(std::vector<double> v);
double percentile(std::vector<double> v, double q);

}  // namespace hairbench
