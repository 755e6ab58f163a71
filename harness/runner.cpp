#include "harness/runner.h"

#include "core/error.h"
#include "core/parallel.h"
#include "harness/follow_adapter.h"
#include "reports/metrics.h"

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

}  // namespace

std::vector<RunRecord> run_scenario(const Scenario& sc, const RunOptions& opt, ThreadPool& pool) {
  const std::string reference = opt.reference.empty() ? sc.reference : opt.reference;
  const ModelInfo* ref_info = find_model(reference);
  if (!ref_info) throw InputError(sc.source.string(), "reference", "unknown model '" + reference + "'");

  // The reference runs once per scenario: it is lane 0, reported only if selected.
  std::vector<Lane> lanes;
  auto add_lane = [&](const ModelInfo* info, bool reported) {
    Lane lane{info, nullptr, {}, reported, true, {}, {}};
    const ParamSet params = resolve_params(*info, sc, opt.overrides);
    lane.model = info->make(ModelContext{&pool});
    // Follow hairs rebuilt from simulated guides (scenario groom.follow_hairs "follow").
    if (sc.follow) lane.model = std::make_unique<FollowHairsAdapter>(std::move(lane.model), sc.guides, *sc.follow);
    lane.model->reset(sc.groom, params);
    RunRecord& r = lane.record;
    r.scenario = sc.name;
    r.model = std::string(info->name);
    r.strands = sc.groom.strand_count();
    r.vertices = sc.groom.vertex_count();
    r.dt = sc.dt;
    r.settle_from = sc.settle_from;
    r.params = params_json(params, sc.groom);
    r.reference = reference;
    if (opt.energy_check) {
      const auto p = lane.model->positions();
      lane.prev.assign(p.begin(), p.end());
      lane.energy.emplace(mean_strand_length(sc.groom), sc.gravity.norm());
    }
    lanes.push_back(std::move(lane));
  };
  bool ref_selected = false;
  for (const std::string& m : opt.models) ref_selected |= (m == reference);
  add_lane(ref_info, ref_selected);
  for (const std::string& m : opt.models) {
    if (m == reference) continue;
    const ModelInfo* info = find_model(m);
    if (!info) throw InputError("--models", m, "unknown model");
    add_lane(info, true);
  }

  const int frames = opt.frames > 0 ? opt.frames : sc.frames;
  for (Lane& l : lanes) l.record.frames = frames;
  const metrics::RestInfo rest(sc.groom);
  StageTimes times;
  std::vector<Vec4f> spheres;

  for (int f = 0; f < frames; ++f) {
    FrameInput in;
    in.frame = f;
    in.dt = sc.dt;
    in.t = (f + 1) * sc.dt;
    in.head_prev = sc.head.at(f * sc.dt);
    in.head = sc.head.at(in.t);
    in.gravity = sc.gravity;
    in.wind = sc.wind.at(in.t);
    in.colliders = sc.colliders;
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
      for (const auto& e : times.entries()) l.record.stage_ms_total[std::string(e.name)] += e.ms;
    }

    // Stability first, so that a reference failing this frame is not used as one.
    const bool driven = in.head.matrix() != in.head_prev.matrix() || in.wind.active();
    for (Lane& l : lanes) {
      if (!l.running) continue;
      std::string why = metrics::blowup_reason(rest, l.model->positions(), in.head.translation());
      if (why.empty() && l.energy) {
        const auto p = l.model->positions();
        why = l.energy->add(metrics::mechanical_energy(p, l.prev, sc.dt, sc.gravity), driven);
        l.prev.assign(p.begin(), p.end());
      }
      if (why.empty()) continue;
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
    for (Lane& l : lanes) {
      if (!l.running) continue;
      const auto p = l.model->positions();
      RunRecord& r = l.record;
      r.t.push_back(in.t);
      r.deviation.push_back(ref_ok ? metrics::deviation(p, lanes[0].model->positions(), rest.mean_strand_length)
                                   : std::numeric_limits<double>::quiet_NaN());
      r.jaggedness.push_back(metrics::jaggedness(rest, p));
      const metrics::LengthError le = metrics::length_error(rest, p);
      r.length_rms.push_back(le.rms);
      r.length_max.push_back(le.max);
      r.rest_shape_error.push_back(metrics::rest_shape_error(rest, p, in.head));
      r.penetration.push_back(metrics::penetration(p, spheres));
    }
  }

  std::vector<RunRecord> out;
  for (Lane& l : lanes) {
    l.record.state_hash = metrics::state_hash(l.model->positions());
    if (l.reported) out.push_back(std::move(l.record));
  }
  return out;
}

}  // namespace hairbench
