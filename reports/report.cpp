#include "reports/report.h"

#include "reports/animation.h"
#include "reports/packing.h"

#include "reports/metrics.h"

#include "git_sha.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <fstream>
#include <numeric>
#include <thread>
#include <unistd.h>

namespace hairbench {

namespace {

// NaN and Inf are never bare tokens in the report: they become null (docs/report-schema.md).
nlohmann::json num(double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr); }

// Per-frame series are for plotting, at 6 significant digits: the summaries beside them
// are computed from the full values. Printed in full, the series were half of a default
// comparison's report.
nlohmann::json series(const std::vector<double>& v) {
  nlohmann::json a = nlohmann::json::array();
  char b[32];
  for (double x : v) {
    std::snprintf(b, sizeof b, "%.6g", x);
    a.push_back(num(std::strtod(b, nullptr)));
  }
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

// A run's snapshot is written relative to the reference's at the same frame when the
// reference reached it with every strand finite and of the same length: most runs follow
// the reference to within millimetres, so the residuals shrink to a byte.
bool relative_to(const RunRecord::Snapshot& s, const RunRecord::Snapshot* ref) {
  if (!ref || ref->strands.size() != s.strands.size() || s.strands.empty()) return false;
  for (std::size_t i = 0; i < s.strands.size(); ++i)
    if (ref->strands[i].size() != s.strands[i].size() || !encode_snapshot_strand(ref->strands[i])) return false;
  return true;
}

nlohmann::json snapshot_json(const RunRecord::Snapshot& s, const RunRecord::Snapshot* ref = nullptr) {
  const bool relative = relative_to(s, ref);
  nlohmann::json strands = nlohmann::json::array();
  for (std::size_t i = 0; i < s.strands.size(); ++i) {
    const std::optional<std::string> code = encode_snapshot_strand(s.strands[i], relative ? &ref->strands[i] : nullptr);
    strands.push_back(code ? nlohmann::json(*code) : nlohmann::json(nullptr));
  }
  nlohmann::json out = {{"label", s.label}, {"frame", s.frame}, {"strands", std::move(strands)}};
  if (relative) out["relative_to_reference"] = true;
  return out;
}

nlohmann::json animation_json(const RunRecord::Animation& a) {
  nlohmann::json out = {{"frames", a.frames}, {"ended", a.ended}};
  if (a.same_as_reference) out["same_as_reference"] = true;
  else out["data"] = a.data;
  return out;
}

// Beyond this a position is a blown-up run, not hair: the strand is written as null.
constexpr double kSnapshotMaxMetres = 1e6;

std::string utc_now() {
  const std::time_t now = std::chrono::system_clock::to_time_t(std::chrono::system_clock::now());
  std::tm tm{};
  gmtime_r(&now, &tm);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%SZ", &tm);
  return buf;
}

}  // namespace

// Hair strands are smooth, so each vertex is close to the straight-line extrapolation of
// the two before it: the residuals of that prediction, in 10-micrometre units, are a few
// hundred at most and take one or two bytes as varints, where the decimal text took eight
// (the snapshots of a default compare are 1.8 million coordinates).
std::optional<std::string> encode_snapshot_strand(const std::vector<float>& xyz, const std::vector<float>* ref) {
  std::vector<std::int64_t> q(xyz.size());
  for (std::size_t i = 0; i < xyz.size(); ++i) {
    if (!std::isfinite(xyz[i]) || std::abs(double(xyz[i])) > kSnapshotMaxMetres) return std::nullopt;
    q[i] = std::llround(double(xyz[i]) / kSnapshotUnitMetres);
    if (ref) q[i] -= std::llround(double((*ref)[i]) / kSnapshotUnitMetres);
  }
  std::string bytes;
  for (std::size_t i = 0; i < q.size(); ++i) {
    const std::int64_t pred = i >= 6 ? 2 * q[i - 3] - q[i - 6] : i >= 3 ? q[i - 3] : 0;
    append_zigzag(bytes, q[i] - pred);
  }
  return base64_encode(bytes);
}

std::vector<double> decode_snapshot_strand(std::string_view code, const std::vector<double>* ref) {
  auto fail = [&](const char* why) {
    throw std::runtime_error("snapshot strand \"" + std::string(code.substr(0, 16)) + "\": " + why);
  };
  std::vector<std::int64_t> q;
  try {
    q = read_zigzag(base64_decode(code));
  } catch (const std::invalid_argument& e) {
    fail(e.what());
  }
  for (std::size_t n = 0; n < q.size(); ++n) q[n] += n >= 6 ? 2 * q[n - 3] - q[n - 6] : n >= 3 ? q[n - 3] : 0;
  if (q.size() % 3) fail("coordinate count is not a multiple of 3");
  if (ref && ref->size() != q.size()) fail("not as long as the reference's strand");
  std::vector<double> xyz(q.size());
  for (std::size_t i = 0; i < q.size(); ++i)
    xyz[i] = static_cast<double>(q[i] + (ref ? std::llround((*ref)[i] / kSnapshotUnitMetres) : 0)) * kSnapshotUnitMetres;
  return xyz;
}

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

namespace {

nlohmann::json opt_num(const std::optional<double>& v) { return v ? num(*v) : nlohmann::json(nullptr); }

nlohmann::json device_json(const DeviceRecord& d) {
  nlohmann::json clock = nullptr;
  if (d.clock_start_mhz || d.clock_end_mhz || d.clock_max_mhz)
    clock = {{"start", opt_num(d.clock_start_mhz)}, {"end", opt_num(d.clock_end_mhz)}, {"max", opt_num(d.clock_max_mhz)}};
  return {{"name", d.name},
          {"type", d.type.empty() ? nlohmann::json(nullptr) : nlohmann::json(d.type)},
          {"timestamp_period_ns", d.timestamp_period_ns > 0.0 ? num(d.timestamp_period_ns) : nlohmann::json(nullptr)},
          {"clock_mhz", clock},
          {"clock_source", d.clock_source}};
}

nlohmann::json summary(const std::vector<double>& v) {
  return {{"mean", num(finite_mean(v))},
          {"median", num(median(v))},
          {"min", num(*std::min_element(v.begin(), v.end()))},
          {"p95", num(percentile(v, 0.95))}};
}

}  // namespace

nlohmann::json context_json(const ReportContext& ctx) {
  nlohmann::json devices = nlohmann::json::array();
  for (const DeviceRecord& d : ctx.devices) devices.push_back(device_json(d));
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
          {"devices", devices},
          {"plugins", ctx.plugins.is_null() ? nlohmann::json{{"loaded", nlohmann::json::array()},
                                                              {"not_loaded", nlohmann::json::array()}}
                                            : ctx.plugins}};
}

namespace {

double summarise(const RunRecord& r, std::size_t done, const std::vector<double>& v, metrics::Stat stat) {
  switch (stat) {
    case metrics::Stat::rms: return rms(v);
    case metrics::Stat::mean: return finite_mean(v);
    case metrics::Stat::max: return finite_max(v);
    case metrics::Stat::final: return v.empty() ? NAN : v.back();
    case metrics::Stat::settled_mean: {
      // The frames that end at or after settle_from.
      std::vector<double> settled;
      for (std::size_t f = 0; f < done; ++f)
        if (r.t[f] >= r.settle_from - 1e-9) settled.push_back(v[f]);
      return finite_mean(settled);
    }
  }
  return NAN;
}

// runs[].metrics: each metric of the table (reports/frame_metrics.h), by its summaries;
// a follow-only column's summary only where follow hairs were rebuilt.
nlohmann::json frame_metrics_json(const RunRecord& r, std::size_t done) {
  nlohmann::json out = nlohmann::json::object();
  const auto table = metrics::frame_metrics();
  for (std::size_t m = 0; m < table.size(); ++m) {
    const metrics::FrameMetric& fm = table[m];
    nlohmann::json j = nlohmann::json::object();
    for (const metrics::Summary& s : fm.summaries) {
      const std::size_t c = metrics::first_column(m) + s.column;
      if (fm.columns[s.column].follow_only && r.frame_values[c].empty()) continue;
      const nlohmann::json value = num(summarise(r, done, r.frame_values[c], s.stat));
      if (s.key.empty())
        j = value;
      else
        j[std::string(s.key)] = value;
    }
    // A deviation is a measure of accuracy only against a reference that is ok.
    if (fm.against_reference) {
      j["reference"] = r.reference;
      j["reference_status"] = std::string(verdict::status_name(r.reference_status));
      if (!r.reference_overrides.empty()) j["reference_overrides"] = r.reference_overrides;
      if (!r.reference_reason.empty()) j["reference_reason"] = r.reference_reason;
    }
    out[std::string(fm.name)] = std::move(j);
  }
  return out;
}

}  // namespace

nlohmann::json run_json(const RunRecord& r, const ScenarioRecord* sc) {
  const std::size_t done = r.step_ms.size();
  // The headline times cover the frames where the model worked: a frame in which every
  // strand slept is skipping's saving, not the method's speed, and counting it would
  // compare one model's sleep with another's work. The sleep is reported beside them.
  std::vector<double> worked, asleep;
  for (std::size_t f = 0; f < done; ++f) {
    const bool work = f >= r.worked.size() || r.worked[f];
    (work ? worked : asleep).push_back(r.step_ms[f]);
  }
  nlohmann::json stage = nlohmann::json::object();
  const double per = worked.empty() ? 0.0 : 1.0 / static_cast<double>(worked.size());
  for (const auto& [name, total] : r.stage_ms_total) stage[name] = num(total * per);

  const double med = median(worked);
  double asleep_ms = 0.0, steps_s = 0.0;
  for (double ms : asleep) asleep_ms += ms;
  for (double ms : r.step_ms) steps_s += std::isfinite(ms) ? ms / 1e3 : 0.0;
  nlohmann::json timing = {
      {"step_ms",
       {{"frames", "worked"},
        {"count", worked.size()},
        {"mean", num(finite_mean(worked))},
        {"median", num(med)},
        {"min", num(worked.empty() ? NAN : *std::min_element(worked.begin(), worked.end()))},
        {"p95", num(percentile(worked, 0.95))}}},
      {"sleep",
       {{"frames_asleep", asleep.size()},
        {"ms_asleep", asleep_ms},
        {"ms_saved", num(static_cast<double>(asleep.size()) * med - asleep_ms)}}},
      {"stage_ms", stage},
      {"stage_skipped_steps", r.stage_skipped_steps},
      {"ns_per_vertex", num(med * 1e6 / static_cast<double>(r.vertices))},
      {"steps_s", steps_s},
      {"overhead_s",
       {{"probe", r.probe_s},
        {"twin", r.twin_s},
        {"setup", r.setup_s},
        {"settle_extra", r.settle_extra_s},
        {"metrics_cpu", r.metrics_s},
        {"animation", r.animation_s}}},
      {"shared_from",
       {{"probe", r.probe_from.empty() ? nlohmann::json() : nlohmann::json(r.probe_from)},
        {"twin", r.twin_from.empty() ? nlohmann::json() : nlohmann::json(r.twin_from)}}}};

  if (r.stream_ms > 0.0) {
    timing["state_bytes"] = r.state_bytes;
    timing["roofline_ratio"] = num(med / r.stream_ms);
  }
  if (!r.gpu_ms.empty()) {
    timing["gpu_ms"] = summary(r.gpu_ms);
    timing["gpu_clock_mhz"] = opt_num(r.gpu_clock_mhz);
  }
  if (!r.gpu_ms_lockstep.empty()) timing["gpu_ms_lockstep"] = summary(r.gpu_ms_lockstep);

  nlohmann::json metrics = frame_metrics_json(r, done);
  metrics["material"] = material::card_json(r.card, &r.reference_card);
  metrics["state_hash"] = metrics::hash_hex(r.state_hash);

  nlohmann::json failure = nullptr;
  if (r.failure) failure = {{"frame", r.failure->frame}, {"t", r.failure->t}, {"reason", r.failure->reason}};

  nlohmann::json snapshots = nlohmann::json::array();
  for (const auto& snap : r.snapshots) {
    const RunRecord::Snapshot* ref = nullptr;
    if (sc)
      for (const auto& rs : sc->reference_snapshots)
        if (rs.label == snap.label && rs.frame == snap.frame) ref = &rs;
    snapshots.push_back(snapshot_json(snap, ref));
  }

  nlohmann::json out = {{"scenario", r.scenario},
                       {"model", r.model},
                       {"origin", r.origin},
                       {"backend", r.backend},
                       {"metrics_on", r.metrics_on},
                       {"groom", {{"strands", r.strands}, {"vertices", r.vertices}, {"static_strands", r.static_strands}}},
                       {"frames", r.frames},
                       {"frames_run", done},
                       {"dt", r.dt},
                       {"settle_from", r.settle_from},
                       {"params", r.params},
                       {"status", verdict::status_name(r.verdict.status)},
                       {"verdict", verdict::verdict_json(r.verdict)},
                       {"failure", failure},
                       {"timing", timing},
                       {"metrics", metrics},
                       {"series",
                        {{"t", series(r.t)},
                         {"step_ms", series(r.step_ms)},
                         {"worked", r.worked}}},
                       {"snapshots", std::move(snapshots)}};
  if (r.knob) out["knob"] = {{"name", r.knob->name}, {"value", r.knob->value}};
  if (!r.substeps.is_null()) out["substeps"] = r.substeps;
  if (r.calibration) out["calibration"] = material::calibration_json(*r.calibration);
  if (r.truth)
    out["truth"] = r.truth->skipped_why.empty() ? nlohmann::json{{"modes", truth::result_json(r.truth->strands)}}
                                                : nlohmann::json{{"skipped", r.truth->skipped_why}};
  for (std::size_t c = 0; c < metrics::column_count(); ++c)
    if (const metrics::Column& col = metrics::column(c); col.reported && !(col.follow_only && r.frame_values[c].empty()))
      out["series"][std::string(col.name)] = series(r.frame_values[c]);
  if (!r.device.empty()) out["device"] = r.device;
  if (r.animation) out["animation"] = animation_json(*r.animation);
  if (!r.gpu_ms.empty()) out["series"]["gpu_ms"] = series(r.gpu_ms);
  if (!r.gpu_ms_lockstep.empty()) out["series"]["gpu_ms_lockstep"] = series(r.gpu_ms_lockstep);
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
  nlohmann::json out = {{"name", sc.name},
          {"frames", sc.frames},
          {"dt", sc.dt},
          {"duration", sc.frames * sc.dt},
          {"mean_strand_length", sc.mean_strand_length},
          {"head_radius", sc.head_radius},
          {"definition_hash", sc.definition_hash},
          {"phases", std::move(phases)},
          {"snapshots",
           {{"criterion", "most_violent: the frame where the reference's kinetic energy per unit mass relative to "
                          "the head, mean over vertices of |p(t) - H(t) H(t-dt)^-1 p(t-dt)|^2 / (2 dt^2), is "
                          "highest (hair moving rigidly with the head is still); final: the last frame"},
            {"strands", sc.snapshot_strands},
            {"frames", std::move(frames)},
            {"reference", {{"model", sc.reference}, {"snapshots", std::move(ref)}}}}},
          {"reference_state_hash", metrics::hash_hex(sc.reference_state_hash)}};
  if (!sc.groom.is_null()) out["groom"] = sc.groom;
  if (sc.animation) {
    const ScenarioRecord::Animation& a = *sc.animation;
    nlohmann::json frames = nlohmann::json::array(), heads = nlohmann::json::array(), named = nlohmann::json::array();
    for (std::size_t k = 0; k < a.heads.size(); ++k) {
      frames.push_back(static_cast<int>(k) * a.stride);
      // 1e-6 m and 1e-6 of a rotation: far below the player's millimetre.
      nlohmann::json h = nlohmann::json::array();
      const Affine3f& m = a.heads[k];
      for (int i = 0; i < 3; ++i) h.push_back(std::round(double(m.translation()[i]) * 1e6) / 1e6);
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) h.push_back(std::round(double(m.linear()(i, j)) * 1e6) / 1e6);
      heads.push_back(std::move(h));
    }
    for (const auto& n : a.named) named.push_back({{"strand", n.strand}, {"model", n.model}, {"why", n.why}});
    nlohmann::json reference = animation_json(a.reference);
    reference["model"] = sc.reference;
    out["animation"] = {{"stride", a.stride},
                        {"unit_metres", animation::kUnitMetres},
                        {"frames", std::move(frames)},
                        {"head", std::move(heads)},
                        {"strands", a.strands},
                        {"named", std::move(named)},
                        {"vertices", a.vertices},
                        {"reference", std::move(reference)}};
  }
  return out;
}

nlohmann::json make_report(const ReportContext& ctx, const std::vector<RunRecord>& runs,
                           const std::vector<ScenarioRecord>& scenarios) {
  nlohmann::json j = {{"schema", "hairbench-report"},
                      {"schema_version", 3},
                      {"context", context_json(ctx)},
                      {"snapshot_encoding", kSnapshotEncoding},
                      {"animation_encoding", animation::kEncoding},
                      {"metric_definitions", metrics::definitions_json()}};
  j["runs"] = nlohmann::json::array();
  for (const RunRecord& r : runs) {
    const auto sc = std::find_if(scenarios.begin(), scenarios.end(),
                                 [&](const ScenarioRecord& s) { return s.name == r.scenario; });
    j["runs"].push_back(run_json(r, sc == scenarios.end() ? nullptr : &*sc));
  }
  if (!scenarios.empty()) {
    j["scenarios"] = nlohmann::json::array();
    for (const ScenarioRecord& sc : scenarios) j["scenarios"].push_back(scenario_json(sc));
  }
  // A device the caller did not describe is still named.
  for (const RunRecord& r : runs) {
    nlohmann::json& devices = j["context"]["devices"];
    if (!r.device.empty() && std::none_of(devices.begin(), devices.end(),
                                          [&](const nlohmann::json& d) { return d["name"] == r.device; }))
      devices.push_back(device_json({r.device, "", 0.0, {}, {}, {}, "not recorded"}));
  }
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
