#include "reports/report.h"

#include "reports/metrics.h"

#include "git_sha.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <ctime>
#include <fstream>
#include <numeric>
#include <thread>
#include <unistd.h>

namespace hairbench {

namespace {

// NaN and Inf are never bare tokens in the report: they become null (DESIGN.md).
nlohmann::json num(double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr); }

nlohmann::json series(const std::vector<double>& v) {
  nlohmann::json a = nlohmann::json::array();
  for (double x : v) a.push_back(num(x));
  return a;
}

double finite_max(const std::vector<double>& v) {
  double m = std::numeric_limits<double>::quiet_NaN();
  for (double x : v)
    if (std::isfinite(x)) m = std::isnan(m) ? x : std::max(m, x);
  return m;
}

double finite_mean(const std::vector<double>& v) {
  double sum = 0.0;
  std::size_t n = 0;
  for (double x : v)
    if (std::isfinite(x)) {
      sum += x;
      ++n;
    }
  return n ? sum / static_cast<double>(n) : std::numeric_limits<double>::quiet_NaN();
}

double rms(const std::vector<double>& v) {
  double sum = 0.0;
  std::size_t n = 0;
  for (double x : v)
    if (std::isfinite(x)) {
      sum += x * x;
      ++n;
    }
  return n ? std::sqrt(sum / static_cast<double>(n)) : std::numeric_limits<double>::quiet_NaN();
}

std::string cpu_name() {
  std::ifstream in("/proc/cpuinfo");
  std::string line;
  while (std::getline(in, line))
    if (line.rfind("model name", 0) == 0) {
      const auto colon = line.find(':');
      if (colon != std::string::npos) return line.substr(line.find_first_not_of(' ', colon + 1));
    }
  return "unknown";
}

// The commit being measured: the one the binary was built from (git_sha.h, written at
// every build by git_sha.cmake), not the checkout's HEAD at run time, which differs
// wherever binaries outlive or travel without their checkout (on the device machine the
// tree's copy answered 252324f for binaries built from a4fe085).
std::string git_sha() { return HAIRBENCH_GIT_SHA; }

// Snapshot coordinates to 10 micrometres: enough for a picture and for per-vertex
// deviation (L-bar is centimetres), and it keeps the numbers short in the JSON.
nlohmann::json snapshot_json(const RunRecord::Snapshot& s) {
  nlohmann::json strands = nlohmann::json::array();
  for (const auto& xyz : s.strands) {
    nlohmann::json a = nlohmann::json::array();
    for (float x : xyz) a.push_back(std::isfinite(x) ? nlohmann::json(std::round(double(x) * 1e5) / 1e5) : nlohmann::json(nullptr));
    strands.push_back(std::move(a));
  }
  return {{"label", s.label}, {"frame", s.frame}, {"strands", std::move(strands)}};
}

std::string utc_now() {
  const std::time_t now = std::chrono::system_clock::to_time_t(std::chrono::system_clock::now());
  std::tm tm{};
  gmtime_r(&now, &tm);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%SZ", &tm);
  return buf;
}

}  // namespace

double median(std::vector<double> v) { return percentile(std::move(v), 0.5); }

double percentile(std::vector<double> v, double q) {
  if (v.empty()) return std::numeric_limits<double>::quiet_NaN();
  std::sort(v.begin(), v.end());
  // Linear interpolation between closest ranks.
  const double pos = q * static_cast<double>(v.size() - 1);
  const std::size_t lo = static_cast<std::size_t>(std::floor(pos));
  const std::size_t hi = std::min(lo + 1, v.size() - 1);
  return v[lo] + (pos - static_cast<double>(lo)) * (v[hi] - v[lo]);
}

nlohmann::json context_json(const ReportContext& ctx) {
  char host[256] = {};
  gethostname(host, sizeof host - 1);
  return {{"date", utc_now()},
          {"git_sha", git_sha()},
          {"host", host},
          {"cpu", cpu_name()},
          {"hardware_threads", std::thread::hardware_concurrency()},
          {"threads", ctx.threads},
          {"build_type", HAIRBENCH_BUILD_TYPE},
          {"compiler", std::string("gcc-compatible ") + __VERSION__},
          {"devices", nlohmann::json::array()}};
}

nlohmann::json run_json(const RunRecord& r) {
  const std::size_t done = r.step_ms.size();
  nlohmann::json stage = nlohmann::json::object();
  for (const auto& [name, total] : r.stage_ms_total) stage[name] = num(done ? total / static_cast<double>(done) : 0.0);

  const double med = median(r.step_ms);
  nlohmann::json timing = {
      {"step_ms",
       {{"mean", num(finite_mean(r.step_ms))},
        {"median", num(med)},
        {"min", num(r.step_ms.empty() ? NAN : *std::min_element(r.step_ms.begin(), r.step_ms.end()))},
        {"p95", num(percentile(r.step_ms, 0.95))}}},
      {"stage_ms", stage},
      {"stage_skipped_steps", r.stage_skipped_steps},
      {"ns_per_vertex", num(med * 1e6 / static_cast<double>(r.vertices))}};

  if (r.stream_ms > 0.0) {
    timing["state_bytes"] = r.state_bytes;
    timing["roofline_ratio"] = num(med / r.stream_ms);
  }
  if (!r.gpu_ms.empty())
    timing["gpu_ms"] = {{"mean", num(finite_mean(r.gpu_ms))},
                        {"median", num(median(r.gpu_ms))},
                        {"min", num(*std::min_element(r.gpu_ms.begin(), r.gpu_ms.end()))},
                        {"p95", num(percentile(r.gpu_ms, 0.95))}};

  // rest_shape_error averages the frames that end at or after settle_from.
  std::vector<double> settled;
  for (std::size_t f = 0; f < done; ++f)
    if (r.t[f] >= r.settle_from - 1e-9) settled.push_back(r.rest_shape_error[f]);

  nlohmann::json deviation = {{"reference", r.reference},
                               {"rms", num(rms(r.deviation))},
                               {"max", num(finite_max(r.deviation))},
                               {"final", num(r.deviation.empty() ? NAN : r.deviation.back())}};
  if (!r.reference_overrides.empty()) deviation["reference_overrides"] = r.reference_overrides;
  nlohmann::json metrics = {
      {"deviation_vs_reference", std::move(deviation)},
      {"jaggedness", {{"mean", num(finite_mean(r.jaggedness))}, {"max", num(finite_max(r.jaggedness))}}},
      {"length_error", {{"rms", num(rms(r.length_rms))}, {"max", num(finite_max(r.length_max))}}},
      {"rest_shape_error", num(finite_mean(settled))},
      {"penetration", {{"max", num(finite_max(r.penetration))}}},
      {"state_hash", metrics::hash_hex(r.state_hash)}};

  nlohmann::json failure = nullptr;
  if (r.failure) failure = {{"frame", r.failure->frame}, {"t", r.failure->t}, {"reason", r.failure->reason}};

  nlohmann::json snapshots = nlohmann::json::array();
  for (const auto& snap : r.snapshots) snapshots.push_back(snapshot_json(snap));

  nlohmann::json out = {{"scenario", r.scenario},
                       {"model", r.model},
                       {"backend", r.backend},
                       {"groom", {{"strands", r.strands}, {"vertices", r.vertices}}},
                       {"frames", r.frames},
                       {"frames_run", done},
                       {"dt", r.dt},
                       {"settle_from", r.settle_from},
                       {"params", r.params},
                       {"status", r.failure ? "unstable" : "ok"},
                       {"failure", failure},
                       {"timing", timing},
                       {"metrics", metrics},
                       {"series",
                        {{"t", series(r.t)},
                         {"step_ms", series(r.step_ms)},
                         {"deviation_vs_reference", series(r.deviation)},
                         {"jaggedness", series(r.jaggedness)},
                         {"length_error_rms", series(r.length_rms)},
                         {"rest_shape_error", series(r.rest_shape_error)},
                         {"penetration", series(r.penetration)}}},
                       {"snapshots", std::move(snapshots)}};
  if (r.knob) out["knob"] = {{"name", r.knob->name}, {"value", r.knob->value}};
  if (!r.device.empty()) out["device"] = r.device;
  if (!r.gpu_ms.empty()) out["series"]["gpu_ms"] = series(r.gpu_ms);
  return out;
}

nlohmann::json scenario_json(const ScenarioRecord& sc) {
  nlohmann::json phases = nlohmann::json::array();
  for (const auto& p : sc.phases)
    phases.push_back({{"start", p.start}, {"end", p.end}, {"kind", p.kind}, {"label", p.label}});
  nlohmann::json frames = nlohmann::json::array();
  for (const auto& f : sc.snapshot_frames) {
    nlohmann::json rot = nlohmann::json::array();
    for (int i = 0; i < 3; ++i)
      rot.push_back({f.head.linear()(i, 0), f.head.linear()(i, 1), f.head.linear()(i, 2)});
    const Vec3f c = f.head.translation();
    frames.push_back({{"label", f.label},
                      {"frame", f.frame},
                      {"t", f.t},
                      {"violence", num(f.violence)},
                      {"head", {{"translation", {c.x(), c.y(), c.z()}}, {"rotation", rot}}}});
  }
  nlohmann::json ref = nlohmann::json::array();
  for (const auto& snap : sc.reference_snapshots) ref.push_back(snapshot_json(snap));
  return {{"name", sc.name},
          {"frames", sc.frames},
          {"dt", sc.dt},
          {"duration", sc.frames * sc.dt},
          {"mean_strand_length", sc.mean_strand_length},
          {"head_radius", sc.head_radius},
          {"phases", std::move(phases)},
          {"snapshots",
           {{"criterion", "most_violent: the frame where the reference's kinetic energy per unit mass relative to "
                          "the head, mean over vertices of |p(t) - H(t) H(t-dt)^-1 p(t-dt)|^2 / (2 dt^2), is "
                          "highest (hair moving rigidly with the head is still); final: the last frame"},
            {"strands", sc.snapshot_strands},
            {"frames", std::move(frames)},
            {"reference", {{"model", sc.reference}, {"snapshots", std::move(ref)}}}}}};
}

nlohmann::json make_report(const ReportContext& ctx, const std::vector<RunRecord>& runs,
                           const std::vector<ScenarioRecord>& scenarios) {
  nlohmann::json j = {{"schema", "hairbench-report"}, {"schema_version", 1}, {"context", context_json(ctx)}};
  j["runs"] = nlohmann::json::array();
  for (const RunRecord& r : runs) j["runs"].push_back(run_json(r));
  if (!scenarios.empty()) {
    j["scenarios"] = nlohmann::json::array();
    for (const ScenarioRecord& sc : scenarios) j["scenarios"].push_back(scenario_json(sc));
  }
  for (const RunRecord& r : runs)
    if (!r.device.empty() && std::find(j["context"]["devices"].begin(), j["context"]["devices"].end(), r.device) ==
                                 j["context"]["devices"].end())
      j["context"]["devices"].push_back(r.device);
  return j;
}

namespace {

// Indented like dump(1), except that an array of numbers (a series, a snapshot strand)
// stays on one line: the report stays readable and a tenth of the size.
void write_pretty(std::ostream& o, const nlohmann::json& j, int depth) {
  const bool flat_array =
      j.is_array() && std::none_of(j.begin(), j.end(), [](const nlohmann::json& e) { return e.is_structured(); });
  if (!j.is_structured() || j.empty() || flat_array) {
    o << j.dump();
    return;
  }
  const std::string pad(depth + 1, ' ');
  o << (j.is_object() ? "{\n" : "[\n");
  for (auto it = j.begin(); it != j.end(); ++it) {
    if (it != j.begin()) o << ",\n";
    o << pad;
    if (j.is_object()) o << nlohmann::json(it.key()).dump() << ": ";
    write_pretty(o, *it, depth + 1);
  }
  o << '\n' << std::string(depth, ' ') << (j.is_object() ? '}' : ']');
}

}  // namespace

void write_json(const std::filesystem::path& file, const nlohmann::json& j) {
  if (file.has_parent_path()) std::filesystem::create_directories(file.parent_path());
  std::ofstream out(file);
  write_pretty(out, j, 0);
  out << '\n';
  if (!out) throw std::runtime_error("cannot write " + file.string());
}

}  // namespace hairbench
