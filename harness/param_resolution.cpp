#include "harness/param_resolution.h"

#include "core/error.h"

#include <algorithm>
#include <cmath>
#include <exception>

namespace hairbench {

double parse_finite(const std::string& text, const std::string& option, const std::string& arg) {
  std::size_t used = 0;
  double v = 0.0;
  try {
    v = std::stod(text, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used == 0 || used != text.size()) throw InputError(option, arg, "'" + text + "' is not a number");
  if (!std::isfinite(v)) throw InputError(option, arg, "value is NaN or infinite");
  return v;
}

ParamOverride parse_param_override(const std::string& arg) {
  const auto dot = arg.find('.');
  const auto eq = arg.find('=');
  if (dot == std::string::npos || eq == std::string::npos || dot > eq || dot == 0 || eq == dot + 1)
    throw InputError("--set", arg, "expected MODEL.NAME=VALUE (MODEL may be *)");
  return {arg.substr(0, dot), arg.substr(dot + 1, eq - dot - 1), parse_finite(arg.substr(eq + 1), "--set", arg)};
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

  // A truth scenario runs every model in its chain limit (docs/truth.md), over the
  // defaults and under what the scenario file and the command line give.
  if (sc.truth) set.set_chain_limit({sc.source.string(), "truth (chain limit)."});

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
  apply_auto_substeps(model, sc, set, overrides);
  return set;
}

void apply_auto_substeps(const ModelInfo& model, const Scenario& sc, ParamSet& params,
                         const std::vector<ParamOverride>& overrides) {
  if (const auto c = choose_substeps(model, sc, params, overrides); c && c->source == "auto")
    params.set_everywhere("substeps", c->value, {sc.source.string(), "substeps (auto)."});
}

std::optional<SubstepsChoice> choose_substeps(const ModelInfo& model, const Scenario& sc, const ParamSet& resolved,
                                              const std::vector<ParamOverride>& overrides) {
  if (!model.step_bound || !resolved.has("substeps")) return std::nullopt;
  bool given = false, asked = false;
  for (const ParamOverride& o : overrides) given |= o.name == "substeps" && (o.model == "*" || o.model == model.name);
  for (const std::string& key : {std::string("*"), std::string(model.name)}) {
    const auto it = sc.models.find(key);
    if (it == sc.models.end()) continue;
    given |= it->second.base.contains("substeps");
    asked |= it->second.substeps_auto;
    for (const auto& [region, values] : it->second.regions) given |= values.contains("substeps");
  }
  SubstepsChoice c;
  const ParamSpec* spec = nullptr;
  for (const ParamSpec& p : model.params)
    if (p.name == "substeps") spec = &p;
  if (given || !(sc.auto_substeps || asked)) {
    c.value = resolved.get_int("substeps");
    c.source = given ? "given" : "default";
    return c;
  }
  const Groom& simulated = sc.follow ? sc.guides : sc.groom;
  const StepBound bound = model.step_bound(simulated, resolved, sc.gravity);
  c.source = "auto";
  c.max_step = bound.max_step;
  c.why = bound.why;
  const double needed = bound.max_step > 0.0 ? std::ceil(sc.dt / bound.max_step) : spec->max + 1;
  c.needed = static_cast<int>(std::min(needed, spec->max + 1));
  c.value = std::max(static_cast<int>(spec->default_value), c.needed);
  c.capped = c.value > spec->max;
  if (c.capped) c.value = static_cast<int>(spec->max);
  return c;
}

nlohmann::json substeps_json(const SubstepsChoice& c) {
  nlohmann::json j = {{"value", c.value}, {"source", c.source}};
  if (c.source == "auto") {
    j["needed"] = c.needed;
    j["max_step_s"] = c.max_step;
    j["bound"] = c.why;
    j["capped"] = c.capped;
  }
  return j;
}

}  // namespace hairbench
