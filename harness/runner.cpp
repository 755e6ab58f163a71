#include "harness/runner.h"

#include "core/error.h"
#include "core/parallel.h"
#include "harness/follow_adapter.h"
#include "harness/gpu_clock.h"
#include "harness/calibrate.h"
#include "harness/probe.h"
#include "harness/at_rest_cache.h"
#include "harness/twin.h"
#include "harness/roofline.h"
#include "harness/shard.h"
#include "reports/animation.h"
#include "reports/device_metrics.h"
#include "reports/metrics.h"
#include "reports/verdict.h"
#include "scenarios/phases.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <memory>
#include <optional>

namespace hairbench {

namespace {

// Ascending strand indices as inclusive runs [first, last]: the fit's rejected roots are
// mostly whole runs of an asset's strands (a neck, a ponytail's tie).
nlohmann::json strand_ranges(const std::vector<std::uint32_t>& strands) {
  nlohmann::json out = nlohmann::json::array();
  for (std::size_t i = 0; i < strands.size();) {
    std::size_t j = i;
    while (j + 1 < strands.size() && strands[j + 1] == strands[j] + 1) ++j;
    out.push_back({strands[i], strands[j]});
    i = j + 1;
  }
  return out;
}

nlohmann::json params_json(const ParamSet& p, const Groom& g) {
  nlohmann::json j = nlohmann::json::object();
  for (const auto& [name, v] : p.base()) j[name] = v;
  nlohmann::json regions = nlohmann::json::object();
  for (std::size_t r = 0; r < p.regions().size(); ++r)
    if (!p.regions()[r].empty()) {
      nlohmann::json rj = nlohmann::json::object();
      for (const auto& [name, v] : p.regions()[r]) rj[name] = v;
      regions[g.region_names[r]] = rj;
    }
  if (!regions.empty()) j["regions"] = regions;
  return j;
}

bool same_params(const ParamSet& a, const ParamSet& b) { return a.base() == b.base() && a.regions() == b.regions(); }

std::vector<ParamOverride> concat(std::vector<ParamOverride> a, const std::vector<ParamOverride>& b) {
  a.insert(a.end(), b.begin(), b.end());
  return a;
}

// Adds the wall time of its scope to a counter (RunRecord::metrics_s, animation_s).
class LaneTimer {
 public:
  explicit LaneTimer(double& into) : into_(into), start_(std::chrono::steady_clock::now()) {}
  ~LaneTimer() { into_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count(); }
  LaneTimer(const LaneTimer&) = delete;
  LaneTimer& operator=(const LaneTimer&) = delete;

 private:
  double& into_;
  const std::chrono::steady_clock::time_point start_;
};

// Copies the snapshot strands' positions (xyz) out of a model's state.
void take_snapshot(const Groom& g, std::span<const std::uint32_t> strands, std::span<const Vec4f> p,
                   RunRecord::Snapshot& out, int frame) {
  out.frame = frame;
  out.strands.resize(strands.size());
  for (std::size_t i = 0; i < strands.size(); ++i) {
    auto& xyz = out.strands[i];
    xyz.clear();
    for (std::uint32_t v = g.strand_begin(strands[i]); v < g.strand_begin(strands[i]) + g.strand_size(strands[i]); ++v)
      xyz.insert(xyz.end(), {p[v].x(), p[v].y(), p[v].z()});
  }
}

// The positions of the strands a model simulates: its nodes' where it draws the groom
// from them (HairModel::simulated_groom), else the groom's.
std::span<const Vec4f> simulated_positions(const HairModel& m) {
  return m.simulated_groom() ? m.simulated_positions() : m.positions();
}

// One model stepping through the scenario, with its record and its detectors.
struct Lane {
  const ModelInfo* info;
  ParamSet params;
  std::unique_ptr<HairModel> model;
  RunRecord record;
  bool reported;
  bool running = true;
  std::vector<Vec4f> prev;  // positions at the end of the previous frame (host metrics)
  metrics::EnergyGrowthCheck energy;
  verdict::StretchTracker stretch;
  verdict::SettleCheck settle;
  verdict::Probe probe;
  // The rest twin's state in the head's frame (empty: no twin), and the distance from it
  // over the settle window.
  std::vector<Vec4f> twin;
  int twin_frames = 0;
  verdict::ReturnTracker back{};
  double kinetic = 0.0;  // this frame's kinetic energy relative to the head
  // Metrics on the device (docs/metrics.md, Where the metrics are computed): the model's
  // kernel, whether it reads the reference's positions on its device, this frame's
  // per-strand values, and the frame whose positions it keeps for the most violent
  // snapshot (-1: none).
  DeviceMetrics* device = nullptr;
  bool device_reference = false;
  std::span<const StrandMetrics> strands{};
  int kept_frame = -1;
  // The nodes a model draws the groom from (HairModel::simulated_groom), whose edges the
  // stretched verdict reads.
  std::optional<metrics::RestInfo> nodes = std::nullopt;
  // A truth scenario's modal amplitudes (reports/truth.h); unset elsewhere, or where the
  // model could not be kicked.
  std::optional<truth::Observer> truth = std::nullopt;
  // The player's frames (RunOptions::animation).
  animation::Recorder frames{};
};

// The lockstep run of one scenario, step by step: make the lanes (the reference first),
// then per frame step every lane, stop the lanes that diverged, measure the others and
// take the snapshots; at the end decide each lane's verdict.
class LockstepRun {
 public:
  LockstepRun(const Scenario& sc, const RunOptions& opt, ThreadPool& pool)
      : sc_(sc), opt_(opt), pool_(pool), frames_(opt.frames > 0 ? opt.frames : sc.frames), rest_(sc.groom, sc.follow ? sc.guides.strand_count() : sc.groom.strand_count()),
        snap_strands_(snapshot_strands(sc.groom)) {
    // Follow hairs are their guide plus a rigid offset, with unconstrained edges: their
    // stretch belongs to the follow layer, so the stretched verdict reads the guides'.
    if (sc.follow) guides_.emplace(sc.guides);
  }

  std::vector<RunRecord> run();

 private:
  void make_lanes();
  void use_device_metrics();
  void add_lane(const ModelInfo* info, const ParamSet& params, bool reported,
                const std::vector<ParamOverride>& overrides);
  void step_lanes(const FrameInput& in, bool driven);
  void stop_diverged(const FrameInput& in, int f, bool driven);
  void measure(const FrameInput& in);
  void track_return(const FrameInput& in);
  void kick(Lane& l) const;
  void observe_truth();
  void fit_truth();
  void snapshot(const FrameInput& in, int f, int frames);
  void record_animation(const FrameInput& in);
  void encode_animation();
  void record_scenario(int frames) const;
  void time_gpu_lanes();
  void extend_settle(int frames);
  // The lane's stretch, with whether its worst edge ends at a pinned vertex.
  verdict::Stretch stretch_of(const Lane& l) const;

  const Scenario& sc_;
  const RunOptions& opt_;
  // When the settle check and the return start. A truth scenario's undamped chain swings
  // on by design: it has neither (its decay is what the truth fit reads).
  const double settle_from_ = sc_.truth ? std::numeric_limits<double>::infinity() : sc_.settle_from;
  ThreadPool& pool_;
  const int frames_;
  const metrics::RestInfo rest_;
  std::optional<metrics::RestInfo> guides_;  // the simulated strands, where follow hairs are rebuilt
  const std::vector<std::uint32_t> snap_strands_;
  std::string reference_;
  std::map<std::string, double> ref_overrides_;
  std::vector<Lane> lanes_;
  std::vector<Vec4f> spheres_;
  StageTimes times_;
  double max_violence_ = -1.0;
  ScenarioRecord::SnapshotFrame violent_frame_, final_frame_;
  // The player's (RunOptions::animation): its frame stride, the strands it may draw (the
  // simulated ones: guides where follow hairs are rebuilt) and the head at each frame.
  const bool animate_ = opt_.animation && opt_.scenario_record;
  const int anim_stride_ = animation::stride(frames_);
  const std::size_t anim_candidates_ = sc_.follow ? sc_.guides.strand_count() : sc_.groom.strand_count();
  std::vector<Affine3f> anim_heads_;
};

}  // namespace

std::unique_ptr<HairModel> make_model(const ModelInfo& info, const Scenario& sc, const ParamSet& params,
                                      ThreadPool& pool, const std::string& device, bool skip_inert) {
  ModelContext ctx{&pool, device};
  ctx.skip_inert = skip_inert;
  std::unique_ptr<HairModel> m = info.make(ctx);
  // Follow hairs rebuilt from simulated guides (scenario groom.follow_hairs "follow"): by
  // the model where it can (on its device), else on the host around it.
  if (sc.follow) {
    const tfx::FollowHairs& f = *sc.follow;
    if (!m->set_follow_hairs({f.guide_offsets, f.guide, f.anchor, f.follow_offsets, f.offsets}))
      m = std::make_unique<FollowHairsAdapter>(std::move(m), sc.guides, f, &pool);
  }
  m->reset(sc.groom, params);
  return m;
}

std::vector<double> back_to_back_gpu_ms(HairModel& model, const Scenario& sc, int frames) {
  model.warm_up(frame_input(sc, 0), kGpuWarmUpSeconds);
  StageTimes times;
  std::vector<double> ms;
  for (int f = 0; f < frames; ++f) {
    model.step(frame_input(sc, f), times);
    model.positions();
    if (const auto gpu = model.last_gpu_ms()) ms.push_back(*gpu);
  }
  return ms;
}

FrameInput frame_input(const Scenario& sc, int f) {
  FrameInput in;
  in.frame = f;
  in.dt = sc.dt;
  in.t = (f + 1) * sc.dt;
  in.head_prev = sc.head.at(f * sc.dt);
  in.head = sc.head.at(in.t);
  in.gravity = sc.gravity;
  in.wind = sc.wind.at(in.t);
  in.colliders = sc.colliders;
  return in;
}

std::vector<ParamOverride> converged_overrides(const ModelInfo& model) {
  std::vector<ParamOverride> out;
  for (const ParamValue& v : model.converged) out.push_back({std::string(model.name), std::string(v.name), v.value});
  return out;
}

std::vector<std::uint32_t> snapshot_strands(const Groom& groom) {
  const std::size_t n = groom.strand_count();
  const std::size_t every = std::max<std::size_t>(1, (n + kMaxSnapshotStrands - 1) / kMaxSnapshotStrands);
  std::vector<std::uint32_t> out;
  for (std::size_t s = 0; s < n; s += every) out.push_back(static_cast<std::uint32_t>(s));
  return out;
}

void LockstepRun::add_lane(const ModelInfo* info, const ParamSet& params, bool reported,
                           const std::vector<ParamOverride>& overrides) {
  // The probe first: a model whose rest state is unstable must not sleep, or sleeping
  // would freeze the growth it is about to show (and change its metrics).
  using Clock = std::chrono::steady_clock;
  const auto start = Clock::now();
  AtRest at_rest;
  std::string probe_from, twin_from;
  const AtRestParts parts{true, opt_.material_card};
  if (opt_.probe)
    at_rest = opt_.at_rest ? opt_.at_rest->probe(*info, sc_, params, pool_, opt_.device, parts, probe_from)
                           : probe_at_rest(*info, sc_, params, pool_, opt_.device, parts);
  if (!opt_.probe || !opt_.material_card) at_rest.card = {};
  if (!opt_.probe) at_rest.card.skipped_why = "not measured (the probe at rest is off)";
  else if (!opt_.material_card) at_rest.card.skipped_why = "not measured (RunOptions::material_card off)";
  const verdict::Probe& probe = at_rest.probe;
  const auto probed = Clock::now();
  // Truth runs never sleep: a sleeping strand would stop the swing being measured.
  const bool skip = opt_.skip_inert && !(probe.run && probe.grows) && !sc_.truth;
  // The twin sleeps even under --no-skip: it is the yardstick, not the measured run, and
  // sleeping moves a state by less than 1e-4 L (docs/verdicts.md), a thousandth of the
  // deformed limit. A model whose rest state is unstable never sleeps.
  RestTwin twin;
  if (opt_.twin && !sc_.truth) {
    const bool sleeps = !(probe.run && probe.grows);
    twin = opt_.at_rest ? opt_.at_rest->twin(*info, sc_, params, pool_, opt_.device, sleeps, frames_, twin_from)
                        : rest_twin(*info, sc_, params, pool_, opt_.device, sleeps, frames_);
  }
  const auto twinned = Clock::now();
  Lane lane{info, params, make_model(*info, sc_, params, pool_, opt_.device, skip), {}, reported, true, {},
            metrics::EnergyGrowthCheck(rest_.mean_strand_length, sc_.gravity.norm()), {}, {}, probe, std::move(twin.positions), twin.frames};
  RunRecord& r = lane.record;
  r.card = at_rest.card;
  r.probe_s = std::chrono::duration<double>(probed - start).count();
  r.twin_s = std::chrono::duration<double>(twinned - probed).count();
  r.setup_s = std::chrono::duration<double>(Clock::now() - twinned).count();
  r.probe_from = std::move(probe_from);
  r.twin_from = std::move(twin_from);
  r.scenario = sc_.name;
  r.model = std::string(info->name);
  if (!info->origin.empty()) r.origin = std::string(info->origin);
  const Backend backend = lane.model->backend();
  r.backend = backend.name;
  r.device = backend.device;
  if (backend.name == "cpu") {
    r.state_bytes = lane.model->state_bytes();
    r.stream_ms = stream_seconds(r.state_bytes, pool_) * 1e3;
  }
  r.strands = sc_.groom.strand_count();
  r.vertices = sc_.groom.vertex_count();
  r.static_strands = lane.model->static_strands();
  if (const Groom* nodes = lane.model->simulated_groom()) lane.nodes.emplace(*nodes);
  r.dt = sc_.dt;
  r.settle_from = sc_.settle_from;
  r.params = params_json(lane.model->run_params() ? *lane.model->run_params() : params, sc_.groom);
  if (const auto c = choose_substeps(*info, sc_, params, overrides)) r.substeps = substeps_json(*c);
  r.reference = reference_;
  r.reference_overrides = ref_overrides_;
  if (reported) r.knob = opt_.knob;
  r.snapshots = {{"most_violent", -1, {}}, {"final", -1, {}}};
  // The hair at rest under the first frame's starting head transform.
  lane.prev = sc_.groom.positions;
  const Affine3f h0 = sc_.head.at(0.0);
  for (Vec4f& p : lane.prev) p.head<3>() = h0 * Vec3f(p.head<3>());
  if (sc_.truth) kick(lane);
  if (animate_) lane.frames = animation::Recorder(sc_.groom, anim_candidates_);
  lanes_.push_back(std::move(lane));
}

// A truth scenario starts the model from its simulated strands kicked into their modes
// (docs/truth.md), and takes the modal amplitudes at t = 0.
void LockstepRun::kick(Lane& l) const {
  RunRecord::Truth t;
  const Groom& simulated = l.model->simulated_groom() ? *l.model->simulated_groom() : sc_.groom;
  try {
    l.truth.emplace(simulated, truth::Kick{sc_.truth->modes, sc_.truth->amplitude, sc_.truth->direction},
                    sc_.gravity);
  } catch (const std::invalid_argument& e) {
    t.skipped_why = e.what();
  }
  if (l.truth && !l.model->start_from(l.truth->kicked())) {
    t.skipped_why = "the model cannot start from a given state (HairModel::start_from)";
    l.truth.reset();
  }
  if (l.truth) {
    l.truth->add(simulated_positions(*l.model));
    const auto p = l.model->positions();
    l.prev.assign(p.begin(), p.end());
  }
  l.record.truth = std::move(t);
}

void LockstepRun::observe_truth() {
  for (Lane& l : lanes_)
    if (l.running && l.truth) l.truth->add(simulated_positions(*l.model));
}

void LockstepRun::fit_truth() {
  for (Lane& l : lanes_) {
    if (!l.truth) continue;
    if (l.record.failure)
      l.record.truth->skipped_why = "the run diverged at frame " + std::to_string(l.record.failure->frame);
    else
      l.record.truth->strands = l.truth->result(sc_.dt);
  }
}

// The reference runs once per scenario: it is lane 0, and it is also the reported run of
// its model when that run's parameters are the same.
void LockstepRun::make_lanes() {
  reference_ = opt_.reference.empty() ? sc_.reference : opt_.reference;
  const ModelInfo* ref_info = find_model(reference_);
  if (!ref_info) throw InputError(sc_.source.string(), "reference", "unknown model '" + reference_ + "'");
  for (const ParamOverride& o : opt_.reference_overrides) ref_overrides_[o.name] = o.value;
  const ParamSet ref_params = resolve_params(*ref_info, sc_, concat(opt_.overrides, opt_.reference_overrides));
  // Every model's parameters are checked before any lane is made (and probed).
  std::vector<std::pair<const ModelInfo*, ParamSet>> reported;
  for (const std::string& m : opt_.models) {
    const ModelInfo* info = find_model(m);
    if (!info) throw InputError("--models", m, "unknown model");
    reported.emplace_back(info, resolve_params(*info, sc_, concat(opt_.overrides, opt_.model_overrides)));
  }
  add_lane(ref_info, ref_params, false, concat(opt_.overrides, opt_.reference_overrides));
  for (const auto& [info, params] : reported) {
    if (info == ref_info && same_params(params, ref_params)) {
      lanes_[0].reported = true;
      lanes_[0].record.knob = opt_.knob;
      continue;
    }
    const std::vector<ParamOverride> given = concat(opt_.overrides, opt_.model_overrides);
    if (!opt_.calibrate) {
      add_lane(info, params, true, given);
      continue;
    }
    // Fitted to the reference's card (lane 0's), keeping what the command line gave.
    material::Calibration cal;
    const material::Card& target = lanes_[0].record.card;
    ParamSet fitted = params;
    if (target.measured)
      fitted = calibrate(*info, sc_, params, target, given, pool_, opt_.device, cal);
    else
      cal.fits.push_back({"", "", "", 1.0, material::kNaN, material::kNaN, material::kNaN, material::kNaN, false, 0,
                          "the reference has no material card (" + target.skipped_why + ")"});
    add_lane(info, fitted, true, given);
    lanes_.back().record.calibration = std::move(cal);
  }
  use_device_metrics();
}

// A model with a metrics kernel (the Vulkan models) is measured on its device unless
// host metrics are asked for (RunOptions::host_metrics, HAIRBENCH_VK_HOST_METRICS=1). Its
// kernel reads the reference's positions where the reference lives on the same device;
// else they go up to it every frame (docs/vulkan.md, Data movement).
void LockstepRun::use_device_metrics() {
  const char* env = std::getenv("HAIRBENCH_VK_HOST_METRICS");
  if (opt_.host_metrics || (env && *env && std::string_view(env) != "0")) return;
  for (Lane& l : lanes_) {
    l.device = l.model->device_metrics();
    if (!l.device) continue;
    l.device->prepare(metrics::device_rest(rest_, l.prev));
    l.record.metrics_on = "device";
  }
  for (Lane& l : lanes_)
    if (l.device && lanes_[0].device) l.device_reference = l.device->read_reference(*lanes_[0].device);
}

// Steps every running lane, timing the step. A frame counts as worked unless the model
// skipped every stage (all its strands slept) while nothing drove the hair.
void LockstepRun::step_lanes(const FrameInput& in, bool driven) {
  for (Lane& l : lanes_) {
    if (!l.running) continue;
    times_.clear();
    const auto start = std::chrono::steady_clock::now();
    l.model->step(in, times_);
    const auto end = std::chrono::steady_clock::now();
    l.record.step_ms.push_back(std::chrono::duration<double, std::milli>(end - start).count());
    if (const auto gpu = l.model->last_gpu_ms()) l.record.gpu_ms.push_back(*gpu);
    bool ran = times_.entries().empty();
    for (const auto& e : times_.entries()) {
      l.record.stage_ms_total[std::string(e.name)] += e.ms;
      if (e.skipped) ++l.record.stage_skipped_steps[std::string(e.name)];
      ran |= !e.skipped;
    }
    l.record.worked.push_back(driven || ran);
  }
}

// Divergence first, so that a reference that diverged this frame is not used as one. One
// task per lane on the pool, each value computed whole by one thread, so no number
// depends on the thread count: the blow-up tests, the mechanical energy's growth with
// nothing driving the hair, and the kinetic energy relative to the head for the settle
// check and the snapshots.
void LockstepRun::stop_diverged(const FrameInput& in, int f, bool driven) {
  std::vector<std::string> why(lanes_.size());
  // The reference's positions, for the device lanes that cannot read them on their
  // device: fetched here, once, before the lanes' tasks share them.
  bool host_reference = false;
  for (const Lane& l : lanes_) host_reference |= l.running && l.device && !l.device_reference;
  const std::span<const Vec4f> reference =
      host_reference && lanes_[0].running ? lanes_[0].model->positions() : std::span<const Vec4f>();
  DeviceMetricsFrame frame{in.head, in.head * in.head_prev.inverse(), sc_.gravity, static_cast<float>(sc_.dt),
                           spheres_, {}};
  pool_.parallel_for(lanes_.size(), [&](std::size_t b, std::size_t e) {
    for (std::size_t i = b; i < e; ++i) {
      Lane& l = lanes_[i];
      if (!l.running) continue;
      const LaneTimer timer(l.record.metrics_s);
      if (l.device) {
        DeviceMetricsFrame lane_frame = frame;
        if (!l.device_reference) lane_frame.reference = reference;
        l.strands = l.device->measure(lane_frame);
        why[i] = metrics::blowup_reason(l.strands);
        if (why[i].empty()) why[i] = l.energy.add(metrics::mechanical_energy(rest_, l.strands), driven);
        l.kinetic = metrics::relative_kinetic_energy(rest_, l.strands, sc_.dt);
        l.settle.add(in.t, l.kinetic, driven, settle_from_);
        continue;
      }
      const auto p = l.model->positions();
      why[i] = l.model->failure();
      if (why[i].empty()) why[i] = metrics::blowup_reason(rest_, p, in.head.translation());
      if (why[i].empty()) why[i] = l.energy.add(metrics::mechanical_energy(p, l.prev, sc_.dt, sc_.gravity), driven);
      l.kinetic = verdict::relative_kinetic_energy(p, l.prev, in.head, in.head_prev, sc_.dt);
      l.settle.add(in.t, l.kinetic, driven, settle_from_);
      l.prev.assign(p.begin(), p.end());
    }
  });
  for (std::size_t i = 0; i < lanes_.size(); ++i) {
    Lane& l = lanes_[i];
    if (!l.running || why[i].empty()) continue;
    RunRecord& r = l.record;
    r.failure = RunRecord::Failure{f, in.t, why[i]};
    l.running = false;
    // Keep the series aligned with the frames that ran: null for the one that diverged.
    r.t.push_back(in.t);
    for (std::size_t c = 0; c < metrics::column_count(); ++c)
      if (guides_ || !metrics::column(c).follow_only) r.frame_values[c].push_back(std::numeric_limits<double>::quiet_NaN());
  }
}

// The per-frame metrics (reports/frame_metrics.h) cost as much as a fast model's step, so
// they run on the pool: one task per lane and metric, and one per lane for the edges the
// stretched verdict reads where they are not the whole groom's (a model's nodes, or the
// guides of rebuilt follow hairs). A device lane's strands were reduced by its kernel
// with the divergence tests (stop_diverged); its metrics add them up, but for a metric
// with no device half, which reads its positions.
void LockstepRun::measure(const FrameInput& in) {
  const auto table = metrics::frame_metrics();
  const std::size_t tasks = table.size() + 1;  // the last: the stretched verdict's edges
  const bool ref_ok = lanes_[0].running;
  std::vector<std::vector<double>> values(lanes_.size(), std::vector<double>(metrics::column_count()));
  std::vector<std::optional<metrics::LengthError>> stretch(lanes_.size());
  // The positions the host halves read, fetched once before the tasks share them (a
  // device model brings them back here): every host lane's, a device lane's where a
  // metric has no device half, and the reference's for any lane measured on the host.
  const bool host_only = std::any_of(table.begin(), table.end(), [](const auto& fm) { return !fm.device; });
  std::vector<std::span<const Vec4f>> p(lanes_.size());
  bool host_lanes = false;
  for (std::size_t i = 0; i < lanes_.size(); ++i)
    if (lanes_[i].running && (!lanes_[i].device || host_only)) {
      p[i] = lanes_[i].model->positions();
      host_lanes = true;
    }
  if (ref_ok && host_lanes && p[0].empty()) p[0] = lanes_[0].model->positions();
  std::vector<double> spent(lanes_.size() * tasks, 0.0);
  pool_.parallel_for(lanes_.size() * tasks, [&](std::size_t b, std::size_t e) {
    for (std::size_t task = b; task < e; ++task) {
      const std::size_t i = task / tasks, m = task % tasks;
      const Lane& l = lanes_[i];
      if (!l.running) continue;
      const LaneTimer timer(spent[task]);
      if (m == table.size()) {
        if (l.nodes)
          stretch[i] = metrics::length_error(*l.nodes, l.model->simulated_positions());
        else if (guides_ && l.device)
          stretch[i] = metrics::length_error(*guides_, l.strands.first(guides_->groom->strand_count()));
        else if (guides_)
          stretch[i] = metrics::length_error(*guides_, p[i].first(guides_->groom->vertex_count()));
        continue;
      }
      const metrics::FrameMetric& fm = table[m];
      const bool on_device = l.device && fm.device;
      metrics::FrameView view{rest_, guides_ ? &*guides_ : nullptr, {}, {}, {}, ref_ok, in.head, spheres_};
      if (on_device) {
        view.strands = l.strands;
      } else {
        view.p = p[i];
        if (ref_ok) view.reference = p[0];
      }
      (on_device ? fm.device : fm.host)(view, std::span(values[i]).subspan(metrics::first_column(m), fm.columns.size()));
    }
  });
  for (std::size_t task = 0; task < spent.size(); ++task) lanes_[task / tasks].record.metrics_s += spent[task];
  // Where no other groom holds the simulated edges, the stretched verdict reads the
  // whole groom's length error, worst edge included (its last columns).
  static const std::size_t length = metrics::column_index("length_error_rms");
  for (std::size_t i = 0; i < lanes_.size(); ++i) {
    Lane& l = lanes_[i];
    if (!l.running) continue;
    RunRecord& r = l.record;
    r.t.push_back(in.t);
    for (std::size_t c = 0; c < values[i].size(); ++c)
      if (guides_ || !metrics::column(c).follow_only) r.frame_values[c].push_back(values[i][c]);
    const auto& v = values[i];
    l.stretch.add(in.frame, stretch[i] ? *stretch[i]
                                       : metrics::LengthError{v[length], v[length + 1],
                                                              static_cast<std::uint32_t>(v[length + 2]),
                                                              static_cast<std::uint32_t>(v[length + 3])});
  }
}

// verdict::Return: each lane's RMS distance from its rest twin, in the head's frame, every
// frame of the settle window (the frames SettleCheck reads), and the farthest strand. One
// task per lane, each value computed whole by one thread.
void LockstepRun::track_return(const FrameInput& in) {
  std::vector<std::span<const Vec4f>> p(lanes_.size());
  for (std::size_t i = 0; i < lanes_.size(); ++i)
    if (lanes_[i].running && !lanes_[i].twin.empty()) p[i] = lanes_[i].model->positions();
  const Affine3f to_head = in.head.inverse();
  const Groom& g = sc_.groom;
  pool_.parallel_for(lanes_.size(), [&](std::size_t b, std::size_t e) {
    for (std::size_t i = b; i < e; ++i) {
      Lane& l = lanes_[i];
      if (p[i].empty()) continue;
      double sum = 0.0, worst = -1.0;
      std::uint32_t worst_strand = 0;
      for (std::size_t s = 0; s < g.strand_count(); ++s) {
        double strand = 0.0;
        for (std::uint32_t v = g.strand_begin(s); v < g.strand_offsets[s + 1]; ++v)
          strand += static_cast<double>((to_head * Vec3f(p[i][v].head<3>()) - l.twin[v].head<3>()).squaredNorm());
        sum += strand;
        const double rms = std::sqrt(strand / g.strand_size(s));
        if (!(rms <= worst)) {
          worst = rms;
          worst_strand = static_cast<std::uint32_t>(s);
        }
      }
      const double length = rest_.mean_strand_length;
      l.back.add(in.t, std::sqrt(sum / static_cast<double>(g.vertex_count())) / length);
      l.back.set_worst(worst_strand, worst / length);
    }
  });
}

// Snapshots: the most violent frame is the first one where the reference's kinetic
// energy relative to the head is highest; a new one replaces the previous one in every
// lane (a lane that has stopped has none there). The final frame is the last one each
// lane ran.
void LockstepRun::snapshot(const FrameInput& in, int f, int frames) {
  if (lanes_[0].running && lanes_[0].kinetic > max_violence_) {
    max_violence_ = lanes_[0].kinetic;
    violent_frame_ = {"most_violent", f, in.t, max_violence_, in.head};
    for (Lane& l : lanes_) {
      l.kept_frame = -1;
      if (!l.running) {
        l.record.snapshots[0] = {"most_violent", -1, {}};
      } else if (l.device) {
        // Kept on the device until the run ends: the most violent frame moves often
        // while the motion builds up.
        l.device->keep();
        l.kept_frame = f;
      } else {
        take_snapshot(sc_.groom, snap_strands_, l.model->positions(), l.record.snapshots[0], f);
      }
    }
  }
  if (f == frames - 1) {
    final_frame_ = {"final", f, in.t, 0.0, in.head};
    for (Lane& l : lanes_)
      if (l.running) take_snapshot(sc_.groom, snap_strands_, l.model->positions(), l.record.snapshots[1], f);
  }
}

// Every anim_stride_-th frame, every running lane's candidate strands; a device model's
// positions are read back here, outside its timed step.
void LockstepRun::record_animation(const FrameInput& in) {
  anim_heads_.push_back(in.head);
  for (Lane& l : lanes_)
    if (l.running) {
      const LaneTimer timer(l.record.animation_s);
      l.frames.add(l.model->positions(), in.head);
    }
}

// Once the verdicts are in: the strands drawn are the spread ones and each strand a
// verdict names (the worst stretched edge's, the one holding the most motion that does
// not settle, the one farthest from its rest twin), the same in every panel.
void LockstepRun::encode_animation() {
  ScenarioRecord::Animation a;
  a.stride = anim_stride_;
  a.heads = anim_heads_;
  for (const Lane& l : lanes_)
    for (animation::Named& n : animation::named_strands(l.record.verdict, l.record.model, anim_candidates_))
      a.named.push_back(std::move(n));
  a.strands = animation::drawn_strands(anim_candidates_, a.named);
  for (std::uint32_t s : a.strands) a.vertices.push_back(animation::picked_vertices(sc_.groom.strand_size(s)));
  for (Lane& l : lanes_) l.record.animation.emplace();
  pool_.parallel_for(lanes_.size(), [&](std::size_t b, std::size_t e) {
    for (std::size_t i = b; i < e; ++i) {
      const LaneTimer timer(lanes_[i].record.animation_s);
      const animation::Recorder& f = lanes_[i].frames;
      *lanes_[i].record.animation = {f.frames(), f.encode(a.strands), false, f.ended()};
    }
  });
  a.reference = *lanes_[0].record.animation;
  lanes_[0].record.animation->data.clear();
  lanes_[0].record.animation->same_as_reference = true;
  opt_.scenario_record->animation = std::move(a);
}

void LockstepRun::record_scenario(int frames) const {
  ScenarioRecord& out = *opt_.scenario_record;
  out.name = sc_.name;
  out.frames = frames;
  out.dt = sc_.dt;
  out.mean_strand_length = rest_.mean_strand_length;
  out.head_radius = sc_.groom.head_radius;
  if (sc_.import) {
    const GroomImport& im = *sc_.import;
    nlohmann::json repairs = nlohmann::json::array();
    for (const Repair& r : im.repairs)
      repairs.push_back({{"kind", r.kind}, {"strands", r.strands}, {"items", r.items}, {"action", r.action},
                         {"first", r.example}});
    out.groom = {{"file", im.file.string()},
                 {"unit", im.unit},
                 {"unit_from", im.unit_from},
                 {"pivot", {im.pivot.x(), im.pivot.y(), im.pivot.z()}},
                 {"pivot_from", im.pivot_from},
                 {"head_radius_fit", im.head_radius_fit},
                 {"degenerate", im.degenerate},
                 {"repairs", std::move(repairs)}};
    if (im.fitted)
      out.groom["fit"] = {{"sphere", im.fit.sphere},
                          {"scalp", im.fit.scalp},
                          {"cap", im.fit.cap},
                          {"center_m", {im.fit.center.x(), im.fit.center.y(), im.fit.center.z()}},
                          {"radius_m", im.fit.radius},
                          {"rms_residual_m", im.fit.rms_residual},
                          {"method", im.fit.method},
                          {"roots", im.fit.roots},
                          {"roots_rejected", im.fit.rejected.size()},
                          {"rejected_strands", strand_ranges(im.fit.rejected)},
                          {"note", im.fit.note}};
  }
  out.phases.clear();
  for (const Phase& p : scenario_phases(sc_, frames * sc_.dt)) out.phases.push_back({p.start, p.end, p.kind, p.label});
  out.snapshot_strands = snap_strands_;
  out.snapshot_frames.clear();
  for (const auto& fr : {violent_frame_, final_frame_})
    if (fr.frame >= 0) out.snapshot_frames.push_back(fr);
  out.reference = reference_;
  out.reference_snapshots = lanes_[0].record.snapshots;
  out.reference_state_hash = metrics::state_hash(lanes_[0].model->positions());
  // What the shards of one command must share: the scenario, and the command's
  // overrides and reference.
  Fnv64 h;
  h.text(scenario_hash(sc_, frames)).text(reference_);
  for (const auto& [name, v] : ref_overrides_) h.text(name).value(v);
  for (const ParamOverride& o : opt_.overrides) h.text(o.model).text(o.name).value(o.value);
  if (opt_.calibrate) h.text("calibrate");
  char b[17];
  std::snprintf(b, sizeof b, "%016llx", static_cast<unsigned long long>(h.digest()));
  out.definition_hash = b;
}

// In lockstep a GPU idles while the host steps the other models and measures, and may
// drop its clock in between: on an H100 the same kernel took 3x longer in the default
// compare than back to back (docs/vulkan.md, Timing). Each GPU lane's device time is therefore taken again on a
// fresh copy, stepped back to back through the frames the lane ran; the lockstep times
// are kept beside it.
void LockstepRun::time_gpu_lanes() {
  for (Lane& l : lanes_) {
    RunRecord& r = l.record;
    if (r.gpu_ms.empty()) continue;
    r.gpu_ms_lockstep = std::move(r.gpu_ms);
    const std::unique_ptr<HairModel> fresh = make_model(*l.info, sc_, l.params, pool_, opt_.device, opt_.skip_inert);
    r.gpu_ms = back_to_back_gpu_ms(*fresh, sc_, static_cast<int>(r.step_ms.size()));
    r.gpu_clock_mhz = read_gpu_clock(r.device).mhz;
  }
}

// verdict::SettleCheck::kExtraSeconds: a lane whose motion has not decayed by the
// scenario's end steps on alone, head still at its last pose and no wind, and its settle
// check reads the longer window. After the state hash, snapshots and series are taken, so
// nothing else in the report sees these frames; not timed.
void LockstepRun::extend_settle(int frames) {
  const FrameInput last = frame_input(sc_, frames - 1);
  const int extra = static_cast<int>(std::lround(verdict::SettleCheck::kExtraSeconds / sc_.dt));
  for (Lane& l : lanes_) {
    const verdict::Settle s = l.settle.result();
    if (!l.running || l.record.failure || s.decays || s.frames < verdict::SettleCheck::kMinFrames) continue;
    const auto start = std::chrono::steady_clock::now();
    StageTimes times;
    // verdict::EnergySpread: each strand's share over the last half of these frames.
    std::vector<double> per_strand(sc_.groom.strand_count(), 0.0);
    for (int k = 0; k < extra; ++k) {
      const bool spread = k >= extra / 2;
      FrameInput in = last;
      in.frame = frames + k;
      in.t = (frames + k + 1) * sc_.dt;
      in.head_prev = in.head = last.head;
      in.wind = {};
      l.model->step(in, times);
      times.clear();
      double kinetic = 0.0;
      if (l.device) {
        l.strands = l.device->measure({in.head, Affine3f::Identity(), sc_.gravity, static_cast<float>(sc_.dt),
                                       spheres_, {}});
        kinetic = metrics::relative_kinetic_energy(rest_, l.strands, sc_.dt);
        if (spread)
          for (std::size_t s = 0; s < per_strand.size(); ++s) per_strand[s] += l.strands[s].kinetic;
      } else {
        const auto p = l.model->positions();
        kinetic = verdict::relative_kinetic_energy(p, l.prev, in.head, in.head, sc_.dt);
        // The head holds still, so the energy relative to it is the plain |p - prev|^2.
        if (spread)
          for (std::size_t s = 0; s < per_strand.size(); ++s)
            for (std::uint32_t v = sc_.groom.strand_begin(s); v < sc_.groom.strand_offsets[s + 1]; ++v)
              per_strand[s] += static_cast<double>((p[v] - l.prev[v]).head<3>().squaredNorm());
        l.prev.assign(p.begin(), p.end());
      }
      l.settle.add_past_end(in.t, kinetic);
    }
    // Follow hairs are rebuilt from their guide: their motion is the guide's, so it counts
    // towards the guide, the strand a user would look at.
    if (sc_.follow) {
      const std::size_t guides = sc_.guides.strand_count();
      for (std::size_t f = 0; f < sc_.follow->strand_count(); ++f)
        per_strand[sc_.follow->guide[f]] += per_strand[guides + f];
      per_strand.resize(guides);
    }
    verdict::EnergySpread spread = verdict::energy_spread(per_strand);
    spread.guides = sc_.follow.has_value();
    l.settle.set_spread(spread);
    l.record.settle_extra_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  }
}

verdict::Stretch LockstepRun::stretch_of(const Lane& l) const {
  verdict::Stretch s = l.stretch.result();
  const Groom& simulated = l.nodes ? *l.nodes->groom : sc_.follow ? sc_.guides : sc_.groom;
  if (s.frames_above > 0 && s.worst_strand < simulated.strand_count() && s.worst_edge >= 2 &&
      s.worst_edge < simulated.strand_size(s.worst_strand)) {
    const Vec4f* p = simulated.positions.data() + simulated.strand_begin(s.worst_strand);
    s.pinned_end = (p[s.worst_edge].w() == 0.0f) != (p[s.worst_edge - 1].w() == 0.0f);
  }
  return s;
}

std::vector<RunRecord> LockstepRun::run() {
  make_lanes();
  // Once every lane is made (the CPU models' probes take a while): the GPU models' clock
  // is up as the first frame starts.
  for (Lane& l : lanes_) l.model->warm_up(frame_input(sc_, 0), kGpuWarmUpSeconds);
  const int frames = frames_;
  for (Lane& l : lanes_) l.record.frames = frames;
  for (int f = 0; f < frames; ++f) {
    const FrameInput in = frame_input(sc_, f);
    const bool driven = in.head.matrix() != in.head_prev.matrix() || in.wind.active();
    spheres_.clear();
    for (const Sphere& c : sc_.colliders) {
      const Vec3f center = collider_center(c, in.head);
      spheres_.emplace_back(center.x(), center.y(), center.z(), c.radius);
    }
    step_lanes(in, driven);
    stop_diverged(in, f, driven);
    measure(in);
    observe_truth();
    if (!driven && in.t >= settle_from_ - 1e-9) track_return(in);
    snapshot(in, f, frames);
    if (animate_ && f % anim_stride_ == 0) record_animation(in);
    if (opt_.on_frame) opt_.on_frame(f + 1, frames);
  }
  for (Lane& l : lanes_)
    if (l.kept_frame >= 0)
      take_snapshot(sc_.groom, snap_strands_, l.device->kept(), l.record.snapshots[0], l.kept_frame);
  if (opt_.scenario_record) record_scenario(frames);
  time_gpu_lanes();

  for (Lane& l : lanes_) l.record.state_hash = metrics::state_hash(l.model->positions());
  extend_settle(frames);
  fit_truth();

  for (Lane& l : lanes_) {
    RunRecord& r = l.record;
    std::optional<std::pair<int, double>> stop;
    if (r.failure) stop = std::make_pair(r.failure->frame, r.failure->t);
    verdict::Return back = l.back.result();
    back.twin_frames = l.twin_frames;
    if (sc_.truth) back.skipped_why = "a truth scenario has no settle window (its chain swings on)";
    else if (l.twin.empty()) back.skipped_why = "no rest twin was run (RunOptions::twin off)";
    r.verdict = verdict::decide(stop, r.failure ? r.failure->reason : "", stretch_of(l), l.settle.result(),
                                l.probe, back, sc_.dt);
  }
  if (animate_) encode_animation();
  // Lane 0 is the reference: every deviation carries its verdict.
  const verdict::Verdict reference = lanes_[0].record.verdict;
  const material::Card reference_card = lanes_[0].record.card;
  std::vector<RunRecord> out;
  for (Lane& l : lanes_) {
    RunRecord& r = l.record;
    r.reference_status = reference.status;
    r.reference_card = reference_card;
    if (reference.status != verdict::Status::ok) r.reference_reason = reference.reason;
    if (l.reported) out.push_back(std::move(r));
  }
  return out;
}

std::vector<RunRecord> run_scenario(const Scenario& sc, const RunOptions& opt, ThreadPool& pool) {
  return LockstepRun(sc, opt, pool).run();
}

}  // namespace hairbench
