// The hairbench-report JSON (DESIGN.md, "Report (contract)", schema_version 1).
#pragma once

#include <nlohmann/json.hpp>

#include <cstdint>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace hairbench {

// Everything measured for one model on one scenario, frame by frame.
struct RunRecord {
  std::string scenario;
  std::string model;
  std::string backend = "cpu";
  std::string device;  // the GPU a GPU model ran on (run "device"; context "devices")
  std::size_t strands = 0, vertices = 0;
  int frames = 0;  // frames requested
  double dt = 0.0;
  double settle_from = 0.0;
  nlohmann::json params = nlohmann::json::object();

  struct Failure {
    int frame;
    double t;
    std::string reason;
  };
  std::optional<Failure> failure;  // set when the model became unstable

  std::string reference;  // model the deviation is measured against
  // Per frame actually run (a failed run stops early).
  std::vector<double> step_ms;
  std::vector<double> gpu_ms;  // device time per step, GPU models with timestamps only
  std::vector<double> deviation;  // NaN where the reference had already failed
  std::vector<double> jaggedness;
  std::vector<double> length_rms, length_max;
  std::vector<double> rest_shape_error;
  std::vector<double> penetration;
  std::vector<double> t;  // time at the end of each frame
  std::map<std::string, double> stage_ms_total;  // summed over the run
  std::uint64_t state_hash = 0;
};

struct ReportContext {
  int threads = 1;
};

nlohmann::json context_json(const ReportContext& ctx);
nlohmann::json run_json(const RunRecord& run);
nlohmann::json make_report(const ReportContext& ctx, const std::vector<RunRecord>& runs);
// Writes pretty JSON, creating the folder; throws std::runtime_error on I/O failure.
void write_json(const std::filesystem::path& file, const nlohmann::json& j);

// Summary statistics used by the report (exposed for tests).
double median(std::vector<double> v);
double percentile(std::vector<double> v, double q);

}  // namespace hairbench
