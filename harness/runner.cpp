#include "harness/runner.h"

#include "core/error.h"
#include "core/parallel.h"
#include "harness/follow_adapter.h"
#include "harness/roofline.h"
#include "reports/metrics.h"
#include "scenarios/phases.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <limits>
#include <cmath>
#include <memory>
#include <optional>

namespace hairbench {

ParamOverride parse_param_override(const std::string& arg) {
  const auto dot = arg.find('.');
  const auto eq = arg.find('=');
  if (dot == std::string::npos || eq == std::string::npos || dot > eq || dot == 0 || eq == dot + 1)
    throw InputError("--set", arg, "expected MODEL.NAME=VALUE (MODEL may be *)");
  const std::string value = arg.substr(eq + 1);
  std::size_t used = 0;
  double v = 0.0;
  try {
    v = std::stod(value, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used == 0 || used != value.size()) throw InputError("--set", arg, "'" + value + "' is not a number");
  if (!std::isfinite(v)) throw InputError("--set", arg, "value is NaN or infinite");
  return {arg.substr(0, dot), arg.substr(dot + 1, eq - dot - 1), v};
}

void check_param_override(const ParamOverride& o) {
  const std::string key = o.model + "." + o.name;
  if (o.model == "*") {
    for (const ModelInfo& m : model_registry())
      for (const ParamSpec& p : m.params)
        if (p.name == o.name) return;
    throw InputError("--set", key, "no model has a parameter named '" + o.name + "'");
  }
  const ModelInfo* m = find_model(o.model);
  if (!m) throw InputError("--set", key, "unknown model '" + o.model + "' (see `hairbench list models`)");
  ParamSet probe(m->params, 0);
  probe.set(o.name, o.value, {"--set", o.model + "."});
}

namespace {

std::size_t region_index(const Scenario& sc, const std::string& name, const std::string& key) {
  const auto& names = sc.groom.region_names;
  for (std::size_t r = 0; r < names.size(); ++r)
    if (names[r] == name) return r;
  throw InputError(sc.source.string(), key, "no region named '" + name + "' in the groom");
}

void apply_overrides(ParamSet& set, const Scenario& sc, const std::string& key, const ParamOverrides& o,
                     bool only_known) {
  const std::string file = sc.source.string();
  for (const auto& [name, v] : o.base)
    if (!only_known || set.has(name)) set.set(name, v, {file, "models." + key + "."});
  for (const auto& [region, values] : o.regions) {
    const std::string rkey = "models." + key + ".regions." + region;
    const std::size_t r = region_index(sc, region, rkey);
    for (const auto& [name, v] : values)
      if (!only_known || set.has(name)) set.set_region(r, name, v, {file, rkey + "."});
  }
}

// Names in a scenario's "*" entry must belong to at least one model: a typo there would
// otherwise be ignored by every model.
void check_star_names(const Scenario& sc, const ParamOverrides& star) {
  auto known = [](const std::string& name) {
    for (const ModelInfo& m : model_registry())
      for (const ParamSpec& p : m.params)
        if (p.name == name) return true;
    return false;
  };
  for (const auto& [name, v] : star.base)
    if (!known(name)) throw InputError(sc.source.string(), "models.*." + name, "no model has this parameter");
  for (const auto& [region, values] : star.regions)
    for (const auto& [name, v] : values)
      if (!known(name))
        throw InputError(sc.source.string(), "models.*.regions." + region + "." + name, "no model has this parameter");
}

}  // namespace

ParamSet resolve_params(const ModelInfo& model, const Scenario& sc, const std::vector<ParamOverride>& overrides) {
  ParamSet set(model.params, sc.groom.region_names.size());
  for (const auto& [key, o] : sc.models)
    if (key != "*" && !find_model(key))
      throw InputError(sc.source.string(), "models." + key, "unknown model (see `hairbench list models`)");

  // Region defaults that come with the groom (asset .tfxsim, procedural styles) apply
  // to every model that has the parameter.
  for (std::size_t r = 0; r < sc.region_params.size(); ++r)
    for (const auto& [name, v] : sc.region_params[r])
      if (set.has(name)) set.set_region(r, name, v, {sc.source.string(), "groom.regions." + sc.groom.region_names[r] + "."});

  ParamOverrides base_star, base_model;
  if (auto it = sc.models.find("*"); it != sc.models.end()) {
    check_star_names(sc, it->second);
    apply_overrides(set, sc, "*", {it->second.base, {}}, true);
    base_star.regions = it->second.regions;
  }
  if (auto it = sc.models.find(std::string(model.name)); it != sc.models.end()) {
    apply_overrides(set, sc, it->first, {it->second.base, {}}, false);
    base_model.regions = it->second.regions;
  }
  apply_overrides(set, sc, "*", base_star, true);
  apply_overrides(set, sc, std::string(model.name), base_model, false);

  for (const ParamOverride& o : overrides)
    if (o.model == "*" && set.has(o.name)) set.set_everywhere(o.name, o.value, {"--set", "*."});
  for (const ParamOverride& o : overrides)
    if (o.model == model.name) set.set_everywhere(o.name, o.value, {"--set", o.model + "."});
  return set;
}

namespace {

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

struct Lane {
  const ModelInfo* info;
  std::unique_ptr<HairModel> model;
  RunRecord record;
  bool reported;
  bool running = true;
  // With RunOptions::energy_check: last frame's positions and the growth check.
  std::vector<Vec4f> prev;
  std::optional<metrics::EnergyGrowthCheck> energy;
};

bool same_params(const ParamSet& a, const ParamSet& b) { return a.base() == b.base() && a.regions() == b.regions(); }

std::vector<ParamOverride> concat(std::vector<ParamOverride> a, const std::vector<ParamOverride>& b) {
  a.insert(a.end(), b.begin(), b.end());
  return a;
}

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

// Kinetic energy per unit mass of the hair relative to the head between two frames:
// mean over vertices of |p - H H_prev^-1 p_prev|^2 / (2 dt^2). Hair carried rigidly by
// the head scores 0, so a walk's steady translation is not "violent"; a whip is.
double relative_kinetic_energy(std::span<const Vec4f> p, std::span<const Vec4f> prev, const Affine3f& head,
                               const Affine3f& head_prev, double dt) {
  const Affine3f carry = head * head_prev.inverse();
  double sum = 0.0;
  for (std::size_t v = 0; v < p.size(); ++v) {
    const Vec3f d = p[v].head<3>() - carry * Vec3f(prev[v].head<3>());
    sum += static_cast<double>(d.squaredNorm());
  }
  return p.empty() ? 0.0 : sum / (2.0 * dt * dt * static_cast<double>(p.size()));
}

}  // namespace

std::unique_ptr<HairModel> make_model(const ModelInfo& info, const Scenario& sc, const ParamSet& params,
                                      ThreadPool& pool, const std::string& device, bool skip_inert) {
  ModelContext ctx{&pool, device};
  ctx.skip_inert = skip_inert;
  std::unique_ptr<HairModel> m = info.make(ctx);
  // Follow hairs rebuilt from simulated guides (scenario groom.follow_hairs "follow").
  if (sc.follow) m = std::make_unique<FollowHairsAdapter>(std::move(m), sc.guides, *sc.follow, &pool);
  m->reset(sc.groom, params);
  return m;
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

std::vector<ParamOverride> converged_reference_overrides() {
  return {{"han_m1", "local_iterations", 32}, {"han_m1", "length_iterations", 32}, {"han_m1", "substeps", 4}};
}

std::vector<std::uint32_t> snapshot_strands(const Groom& groom) {
  const std::size_t n = groom.strand_count();
  const std::size_t every = std::max<std::size_t>(1, (n + kMaxSnapshotStrands - 1) / kMaxSnapshotStrands);
  std::vector<std::uint32_t> out;
  for (std::size_t s = 0; s < n; s += every) out.push_back(static_cast<std::uint32_t>(s));
  return out;
}

std::vector<RunRecord> run_scenario(const Scenario& sc, const RunOptions& opt, ThreadPool& pool) {
  const std::string reference = opt.reference.empty() ? sc.reference : opt.reference;
  const ModelInfo* ref_info = find_model(reference);
  if (!ref_info) throw InputError(sc.source.string(), "reference", "unknown model '" + reference + "'");
  std::map<std::string, double> ref_overrides;
  for (const ParamOverride& o : opt.reference_overrides) ref_overrides[o.name] = o.value;

  // The reference runs once per scenario: it is lane 0, and it is also the reported run
  // of its model when that run's parameters are the same.
  std::vector<Lane> lanes;
  auto add_lane = [&](const ModelInfo* info, const ParamSet& params, bool reported) {
    Lane lane{info, make_model(*info, sc, params, pool, opt.device, opt.skip_inert), {}, reported, true, {}, {}};
    RunRecord& r = lane.record;
    r.scenario = sc.name;
    r.model = std::string(info->name);
    const Backend backend = lane.model->backend();
    r.backend = backend.name;
    r.device = backend.device;
    if (backend.name == "cpu") {
      r.state_bytes = lane.model->state_bytes();
      r.stream_ms = stream_seconds(r.state_bytes, pool) * 1e3;
    }
    r.strands = sc.groom.strand_count();
    r.vertices = sc.groom.vertex_count();
    r.dt = sc.dt;
    r.settle_from = sc.settle_from;
    r.params = params_json(params, sc.groom);
    r.reference = reference;
    r.reference_overrides = ref_overrides;
    if (reported) r.knob = opt.knob;
    r.snapshots = {{"most_violent", -1, {}}, {"final", -1, {}}};
    if (opt.energy_check) {
      const auto p = lane.model->positions();
      lane.prev.assign(p.begin(), p.end());
      lane.energy.emplace(mean_strand_length(sc.groom), sc.gravity.norm());
    }
    lanes.push_back(std::move(lane));
  };
  const ParamSet ref_params = resolve_params(*ref_info, sc, concat(opt.overrides, opt.reference_overrides));
  add_lane(ref_info, ref_params, false);
  for (const std::string& m : opt.models) {
    const ModelInfo* info = find_model(m);
    if (!info) throw InputError("--models", m, "unknown model");
    const ParamSet params = resolve_params(*info, sc, concat(opt.overrides, opt.model_overrides));
    if (info == ref_info && same_params(params, ref_params)) {
      lanes[0].reported = true;
      lanes[0].record.knob = opt.knob;
      continue;
    }
    add_lane(info, params, true);
  }

  const int frames = opt.frames > 0 ? opt.frames : sc.frames;
  for (Lane& l : lanes) l.record.frames = frames;
  const metrics::RestInfo rest(sc.groom, sc.follow ? sc.guides.strand_count() : sc.groom.strand_count());
  const std::vector<std::uint32_t> snap_strands = snapshot_strands(sc.groom);
  StageTimes times;
  std::vector<Vec4f> spheres;
  // The reference's positions at the end of the previous frame (at rest under the first
  // frame's starting head transform before frame 0), for the violence criterion.
  std::vector<Vec4f> ref_prev(sc.groom.positions);
  {
    const Affine3f h0 = sc.head.at(0.0);
    for (Vec4f& p : ref_prev) p.head<3>() = h0 * Vec3f(p.head<3>());
  }
  double max_violence = -1.0;
  ScenarioRecord::SnapshotFrame violent_frame, final_frame;

  for (int f = 0; f < frames; ++f) {
    const FrameInput in = frame_input(sc, f);
    spheres.clear();
    for (const Sphere& c : sc.colliders) {
      const Vec3f center = collider_center(c, in.head);
      spheres.emplace_back(center.x(), center.y(), center.z(), c.radius);
    }

    for (Lane& l : lanes) {
      if (!l.running) continue;
      times.clear();
      const auto start = std::chrono::steady_clock::now();
      l.model->step(in, times);
      const auto end = std::chrono::steady_clock::now();
      l.record.step_ms.push_back(std::chrono::duration<double, std::milli>(end - start).count());
      if (const auto gpu = l.model->last_gpu_ms()) l.record.gpu_ms.push_back(*gpu);
      for (const auto& e : times.entries()) {
        l.record.stage_ms_total[std::string(e.name)] += e.ms;
        if (e.skipped) ++l.record.stage_skipped_steps[std::string(e.name)];
      }
    }

    // Stability first, so that a reference failing this frame is not used as one.
    const bool driven = in.head.matrix() != in.head_prev.matrix() || in.wind.active();
    // The metrics cost as much as a fast model's step, so they run on the pool: one task
    // per lane (and below, per lane and metric), each value computed whole by one thread,
    // so no number depends on the thread count.
    std::vector<std::string> blowup(lanes.size());
    pool.parallel_for(lanes.size(), [&](std::size_t b, std::size_t e) {
      for (std::size_t i = b; i < e; ++i) {
        Lane& l = lanes[i];
        if (!l.running) continue;
        std::string why = metrics::blowup_reason(rest, l.model->positions(), in.head.translation());
        if (why.empty() && l.energy) {
          const auto p = l.model->positions();
          why = l.energy->add(metrics::mechanical_energy(p, l.prev, sc.dt, sc.gravity), driven);
          l.prev.assign(p.begin(), p.end());
        }
        blowup[i] = std::move(why);
      }
    });
    for (std::size_t i = 0; i < lanes.size(); ++i) {
      Lane& l = lanes[i];
      const std::string& why = blowup[i];
      if (!l.running || why.empty()) continue;
      RunRecord& r = l.record;
      r.failure = RunRecord::Failure{f, in.t, why};
      l.running = false;
      // Keep the series aligned with the frames that ran: null for the failed one.
      r.t.push_back(in.t);
      const double nan = std::numeric_limits<double>::quiet_NaN();
      for (auto* v : {&r.deviation, &r.jaggedness, &r.length_rms, &r.length_max, &r.rest_shape_error,
                      &r.penetration})
        v->push_back(nan);
    }
    const bool ref_ok = lanes[0].running;
    enum FrameMetric { kDeviation, kJaggedness, kLength, kRestShape, kPenetration, kFrameMetrics };
    std::vector<std::array<double, kFrameMetrics + 1>> values(lanes.size());  // length: rms, max
    // One more task: the reference's violence for the snapshots (below), which would
    // otherwise run alone on this thread while the pool waits.
    const std::size_t metric_tasks = lanes.size() * kFrameMetrics;
    double violence = 0.0;
    pool.parallel_for(metric_tasks + 1, [&](std::size_t b, std::size_t e) {
      for (std::size_t task = b; task < e; ++task) {
        if (task == metric_tasks) {
          if (ref_ok)
            violence = relative_kinetic_energy(lanes[0].model->positions(), ref_prev, in.head, in.head_prev, sc.dt);
          continue;
        }
        const std::size_t i = task / kFrameMetrics;
        if (!lanes[i].running) continue;
        const auto p = lanes[i].model->positions();
        auto& v = values[i];
        switch (static_cast<FrameMetric>(task % kFrameMetrics)) {
          case kDeviation:
            v[kDeviation] = ref_ok ? metrics::deviation(p, lanes[0].model->positions(), rest.mean_strand_length)
                                   : std::numeric_limits<double>::quiet_NaN();
            break;
          case kJaggedness: v[kJaggedness] = metrics::jaggedness(rest, p); break;
          case kLength: {
            const metrics::LengthError le = metrics::length_error(rest, p);
            v[kLength] = le.rms;
            v[kFrameMetrics] = le.max;
            break;
          }
          case kRestShape: v[kRestShape] = metrics::rest_shape_error(rest, p, in.head); break;
          case kPenetration: v[kPenetration] = metrics::penetration(p, spheres); break;
          case kFrameMetrics: break;
        }
      }
    });
    for (std::size_t i = 0; i < lanes.size(); ++i) {
      if (!lanes[i].running) continue;
      RunRecord& r = lanes[i].record;
      const auto& v = values[i];
      r.t.push_back(in.t);
      r.deviation.push_back(v[kDeviation]);
      r.jaggedness.push_back(v[kJaggedness]);
      r.length_rms.push_back(v[kLength]);
      r.length_max.push_back(v[kFrameMetrics]);
      r.rest_shape_error.push_back(v[kRestShape]);
      r.penetration.push_back(v[kPenetration]);
    }

    // Snapshots: a new most violent frame replaces the previous one in every lane (a lane
    // that has stopped has none there); the final frame is the last one each lane ran.
    if (ref_ok) {
      const auto ref_p = lanes[0].model->positions();
      std::copy(ref_p.begin(), ref_p.end(), ref_prev.begin());
      if (violence > max_violence) {
        max_violence = violence;
        violent_frame = {"most_violent", f, in.t, violence, in.head};
        for (Lane& l : lanes) {
          if (l.running) take_snapshot(sc.groom, snap_strands, l.model->positions(), l.record.snapshots[0], f);
          else l.record.snapshots[0] = {"most_violent", -1, {}};
        }
      }
    }
    if (f == frames - 1) {
      final_frame = {"final", f, in.t, 0.0, in.head};
      for (Lane& l : lanes)
        if (l.running) take_snapshot(sc.groom, snap_strands, l.model->positions(), l.record.snapshots[1], f);
    }
    if (opt.on_frame) opt.on_frame(f + 1, frames);
  }

  if (opt.scenario_record) {
    ScenarioRecord& out = *opt.scenario_record;
    out.name = sc.name;
    out.frames = frames;
    out.dt = sc.dt;
    out.mean_strand_length = rest.mean_strand_length;
    out.head_radius = sc.groom.head_radius;
    out.phases.clear();
    for (const Phase& p : scenario_phases(sc, frames * sc.dt)) out.phases.push_back({p.start, p.end, p.kind, p.label});
    out.snapshot_strands = snap_strands;
    out.snapshot_frames.clear();
    for (const auto& fr : {violent_frame, final_frame})
      if (fr.frame >= 0) out.snapshot_frames.push_back(fr);
    out.reference = reference;
    out.reference_snapshots = lanes[0].record.snapshots;
  }

  std::vector<RunRecord> out;
  for (Lane& l : lanes) {
    l.record.state_hash = metrics::state_hash(l.model->positions());
    if (l.reported) out.push_back(std::move(l.record));
  }
  return out;
}

}  // namespace hairbench
