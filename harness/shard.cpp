#include "harness/shard.h"

#include "core/error.h"
#include "harness/runner.h"
#include "reports/report.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <numeric>

namespace hairbench {

ShardSpec parse_shard(const std::string& arg) {
  const auto slash = arg.find('/');
  auto whole = [](std::string_view s, int& out) {
    const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), out);
    return !s.empty() && ec == std::errc() && end == s.data() + s.size();
  };
  ShardSpec s;
  if (slash == std::string::npos || !whole(std::string_view(arg).substr(0, slash), s.index) ||
      !whole(std::string_view(arg).substr(slash + 1), s.count) || s.count < 1 || s.count > kMaxShards ||
      s.index < 1 || s.index > s.count)
    throw InputError("--shard", arg,
                     "expected I/N, whole numbers with 1 <= I <= N <= " + std::to_string(kMaxShards) + " (e.g. 2/4)");
  return s;
}

namespace {

// The lane's share of the lockstep that is not its step: the per-frame metrics
// (deviation, jaggedness, length, rest shape, penetration, the verdicts' detectors), ns
// of wall time per vertex and frame on the worker threads; measured as the unsharded
// sweep's wall time less its steps and process over its vertex-frames (the idle/shake
// sweep of docs/sharding.md: 1.9 s over 276 million).
constexpr double kMetricsNsPerVertex = 7.0;
// A frame in which every strand sleeps costs this share of a worked one (the sleep
// bookkeeping).
constexpr double kSleepShare = 0.05;


// How much more a step costs at `params` than at the model's defaults (StepCost's
// multiplier and linear terms).
double param_scale(const ModelInfo& model, const ParamSet& params) {
  const StepCost* e = &model.cost;
  auto def = [&](std::string_view name) {
    for (const ParamSpec& p : model.params)
      if (p.name == name) return p.default_value;
    return 0.0;
  };
  double linear = 1.0;
  for (const auto& [name, share] : e->linear)
    if (!name.empty() && params.has(name)) linear += share * (params.get(name) - def(name));
  double mult = 1.0;
  if (params.has(e->multiplier) && def(e->multiplier) > 0.0) mult = params.get(e->multiplier) / def(e->multiplier);
  return std::max(linear, 0.05) * mult;
}

// A model without a measured cost (a plugin that gives none) is costed as the slowest
// model that has one, so that no shard is starved; the estimate's source says so.
double slowest_known_ns() {
  double ns = 0.0;
  for (const ModelInfo& m : model_registry()) ns = std::max(ns, m.cost.ns_per_vertex);
  return ns;
}

// The perturbation probe steps two copies of the model for 210 frames on at most 64
// strands of the groom (harness/probe.h).
double probe_vertex_steps(std::size_t vertices, std::size_t strands) {
  const double per_strand = strands ? static_cast<double>(vertices) / static_cast<double>(strands) : 0.0;
  return 2.0 * 210.0 * std::min<double>(static_cast<double>(vertices), 64.0 * per_strand);
}

std::string fmt(const char* f, double v) {
  char b[64];
  std::snprintf(b, sizeof b, f, v);
  return b;
}

}  // namespace

CostModel CostModel::from_report(const std::filesystem::path& file) {
  const std::string f = file.string();
  std::ifstream in(file);
  if (!in) throw InputError("--costs", f, "cannot read the report");
  const nlohmann::json j = nlohmann::json::parse(in, nullptr, false);
  if (j.is_discarded()) throw InputError("--costs", f, "not JSON");
  if (j.value("schema", "") != "hairbench-report") throw InputError(f, "schema", "not a hairbench-report");
  if (!j.contains("runs") || !j["runs"].is_array() || j["runs"].empty())
    throw InputError(f, "runs", "missing or empty: --costs needs a report with runs");
  CostModel c;
  c.file_ = f;
  std::map<std::string, std::vector<double>> per_model;
  for (std::size_t i = 0; i < j["runs"].size(); ++i) {
    const nlohmann::json& r = j["runs"][i];
    const std::string at = "runs[" + std::to_string(i) + "]";
    try {
      const nlohmann::json& steps = r.at("series").at("step_ms");
      double ms = 0.0;
      for (const nlohmann::json& s : steps)
        if (s.is_number()) ms += s.get<double>();
      if (!steps.empty()) c.run_frame_seconds_[run_key(r)] = ms * 1e-3 / static_cast<double>(steps.size());
      // The mean step of the worked frames per vertex: what a run's total follows.
      const nlohmann::json& worked = r.at("series").at("worked");
      double worked_ms = 0.0;
      std::size_t n = 0;
      for (std::size_t k = 0; k < steps.size() && k < worked.size(); ++k)
        if (steps[k].is_number() && worked[k].get<int>() != 0) {
          worked_ms += steps[k].get<double>();
          ++n;
        }
      const double vertices = r.at("groom").at("vertices").get<double>();
      const ModelInfo* m = find_model(r.at("model").get<std::string>());
      if (n > 0 && vertices > 0 && m) {
        // Back to the model's defaults, so that another parameter value scales from it.
        ParamSet p(m->params, 0);
        for (const auto& [name, v] : r.at("params").items())
          if (v.is_number() && p.has(name)) p.set(name, v.get<double>(), {f, at + ".params."});
        per_model[std::string(m->name)].push_back(worked_ms * 1e6 / (n * vertices) / param_scale(*m, p));
      }
    } catch (const nlohmann::json::exception& e) {
      throw InputError(f, at, std::string("not a run of a hairbench-report (") + e.what() + ")");
    }
  }
  for (auto& [model, v] : per_model) c.model_ns_[model] = median(v);
  return c;
}

CostEstimate CostModel::run(const ModelInfo& model, const ParamSet& params, const std::string& key,
                            std::size_t strands, std::size_t vertices, int frames, double work_fraction) const {
  const double vf = static_cast<double>(vertices) * frames;
  const double metrics = vf * kMetricsNsPerVertex * 1e-9;
  double ns = model.cost.ns_per_vertex;
  std::string source = "table";
  if (ns <= 0.0) {
    ns = slowest_known_ns();
    source = "unknown (" + std::string(model.name) + " gives no cost: the slowest model's)";
  }
  if (const auto it = model_ns_.find(std::string(model.name)); it != model_ns_.end()) {
    ns = it->second;
    source = "costs: model";
  }
  ns *= param_scale(model, params);
  const double probe = probe_vertex_steps(vertices, strands) * ns * 1e-9;
  // The same run measured before: its steps as they were, sleep included.
  if (const auto it = run_frame_seconds_.find(key); it != run_frame_seconds_.end())
    return {it->second * frames + metrics + probe, "costs: run"};
  const double work = model.cost.sleeps ? work_fraction : 1.0;
  const double steps = vf * (work + (1.0 - work) * kSleepShare);
  return {steps * ns * 1e-9 + probe + metrics, source};
}

std::string run_key(const std::string& scenario, const std::string& model, const std::string& knob_name,
                    std::optional<double> knob_value) {
  std::string k = scenario + "/" + model;
  if (knob_value) k += "/" + knob_name + "=" + fmt("%.17g", *knob_value);
  return k;
}

std::string run_key(const nlohmann::json& run) {
  std::optional<double> v;
  std::string name;
  if (run.contains("knob") && run["knob"].is_object()) {
    name = run["knob"].at("name").get<std::string>();
    v = run["knob"].at("value").get<double>();
  }
  return run_key(run.at("scenario").get<std::string>(), run.at("model").get<std::string>(), name, v);
}

double work_fraction(const Scenario& sc, int frames) {
  if (frames <= 0) return 0.0;
  double last_driven = 0.0;  // the start counts as a drive: the rest shape sags
  int awake = 0;
  for (int f = 0; f < frames; ++f) {
    const FrameInput in = frame_input(sc, f);
    if (in.head.matrix() != in.head_prev.matrix() || in.wind.active()) last_driven = in.t;
    if (in.t - last_driven <= kSettleSeconds) ++awake;
  }
  return static_cast<double>(awake) / frames;
}

Plan plan_runs(const std::vector<Scenario>& scenarios, const RunOptions& run, const std::string& knob_name,
               const std::vector<double>& knob_values, const CostModel& costs, int count) {
  Plan plan;
  plan.count = count;
  plan.cost_source = costs.from_file() ? costs.file() : "the built-in table";
  plan.process_seconds = kProcessSeconds;
  std::vector<std::optional<double>> values;
  for (double v : knob_values) values.emplace_back(v);
  if (values.empty()) values.emplace_back();
  auto same = [](const ParamSet& a, const ParamSet& b) { return a.base() == b.base() && a.regions() == b.regions(); };
  for (const Scenario& sc : scenarios) {
    const int frames = run.frames > 0 ? run.frames : sc.frames;
    const double work = work_fraction(sc, frames);
    const std::string ref = run.reference.empty() ? sc.reference : run.reference;
    const ModelInfo* ref_info = find_model(ref);
    if (!ref_info) throw InputError(sc.source.string(), "reference", "unknown model '" + ref + "'");
    std::vector<ParamOverride> ref_overrides = run.overrides;
    ref_overrides.insert(ref_overrides.end(), run.reference_overrides.begin(), run.reference_overrides.end());
    const ParamSet ref_params = resolve_params(*ref_info, sc, ref_overrides);
    const std::size_t strands = sc.groom.strand_count(), vertices = sc.groom.vertex_count();
    for (const std::optional<double>& value : values) {
      const std::size_t group = plan.group_cost.size();
      const std::string knob = value ? " " + knob_name + "=" + fmt("%g", *value) : "";
      plan.group_label.push_back(sc.name + knob);
      plan.group_cost.push_back(
          costs.run(*ref_info, ref_params, run_key(sc.name, ref, "", {}), strands, vertices, frames, work).seconds);
      for (const std::string& m : run.models) {
        const ModelInfo* info = find_model(m);
        if (!info) throw InputError("--models", m, "unknown model");
        std::vector<ParamOverride> o = run.overrides;
        if (value) o.push_back({m, knob_name, *value});
        const ParamSet params = resolve_params(*info, sc, o);
        PlanItem it{run_key(sc.name, m, knob_name, value), sc.name + " " + m + knob, group, {}, 0};
        it.cost = info == ref_info && same(params, ref_params)
                      ? CostEstimate{0.0, "reference lane"}
                      : costs.run(*info, params, it.key, strands, vertices, frames, work);
        plan.items.push_back(std::move(it));
      }
    }
  }
  partition(plan);
  return plan;
}

void partition(Plan& plan) {
  std::vector<std::size_t> order(plan.items.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return plan.items[a].cost.seconds > plan.items[b].cost.seconds;
  });
  const auto n = static_cast<std::size_t>(plan.count);
  plan.shard_seconds.assign(n, plan.process_seconds);
  std::vector<std::vector<bool>> has(n, std::vector<bool>(plan.group_cost.size(), false));
  for (std::size_t i : order) {
    PlanItem& it = plan.items[i];
    std::size_t best = 0;
    double best_load = 0.0;
    for (std::size_t s = 0; s < n; ++s) {
      const double load = plan.shard_seconds[s] + it.cost.seconds + (has[s][it.group] ? 0.0 : plan.group_cost[it.group]);
      if (s == 0 || load < best_load) {
        best = s;
        best_load = load;
      }
    }
    plan.shard_seconds[best] = best_load;
    has[best][it.group] = true;
    it.shard = static_cast<int>(best) + 1;
  }
}

std::string plan_text(const Plan& plan, const std::string& what) {
  // Stress runs each model alone: no batch shares a reference lane there.
  const bool batches = plan.group_cost.size() > 1 || (!plan.group_cost.empty() && plan.group_cost.front() > 0.0);
  std::string out = what + ": " + std::to_string(plan.items.size()) + " runs" +
                    (batches ? " in " + std::to_string(plan.group_cost.size()) + " batches" : "") + ", " +
                    std::to_string(plan.count) + " shard" + (plan.count == 1 ? "" : "s") + "; costs from " +
                    plan.cost_source + "\n";
  std::size_t width = 3;
  for (const PlanItem& it : plan.items) width = std::max(width, it.label.size());
  char line[512];
  std::snprintf(line, sizeof line, "  %-6s %-*s %10s  %s\n", "shard", static_cast<int>(width), "run", "est. s", "from");
  out += line;
  for (const PlanItem& it : plan.items) {
    std::snprintf(line, sizeof line, "  %-6s %-*s %10.3f  %s\n", (std::to_string(it.shard) + "/" + std::to_string(plan.count)).c_str(),
                  static_cast<int>(width), it.label.c_str(), it.cost.seconds, it.cost.source.c_str());
    out += line;
  }
  if (batches) {
    std::snprintf(line, sizeof line, "  (each batch's reference lane is paid by every shard that runs part of the batch)\n");
    out += line;
  }
  for (int s = 1; s <= plan.count; ++s) {
    std::size_t runs = 0;
    std::vector<bool> groups(plan.group_cost.size(), false);
    for (const PlanItem& it : plan.items)
      if (it.shard == s) {
        ++runs;
        groups[it.group] = true;
      }
    const std::string in = batches ? ", " + std::to_string(std::count(groups.begin(), groups.end(), true)) + " batches" : "";
    std::snprintf(line, sizeof line, "shard %d/%d: %zu runs%s, estimated %.2f s (%.2f s of it the process)\n", s,
                  plan.count, runs, in.c_str(), plan.shard_seconds[static_cast<std::size_t>(s - 1)],
                  plan.process_seconds);
    out += line;
  }
  return out;
}

nlohmann::json shard_json(const Plan& plan, const ShardSpec& shard) {
  nlohmann::json runs = nlohmann::json::array();
  for (const PlanItem& it : plan.items) runs.push_back({{"key", it.key}, {"shard", it.shard}});
  return {{"index", shard.index},
          {"count", shard.count},
          {"plan_hash", plan_hash(plan)},
          {"estimated_s", plan.shard_seconds[static_cast<std::size_t>(shard.index - 1)]},
          {"cost_source", plan.cost_source},
          {"plan", std::move(runs)}};
}

std::string plan_hash(const Plan& plan) {
  Fnv64 h;
  h.value(plan.count);
  for (const PlanItem& it : plan.items) h.text(it.key).value(it.shard);
  char b[17];
  std::snprintf(b, sizeof b, "%016llx", static_cast<unsigned long long>(h.digest()));
  return b;
}

}  // namespace hairbench
