#include "harness/merge.h"

#include "reports/animation.h"

#include "core/error.h"
#include "harness/reproduce.h"
#include "harness/shard.h"
#include "harness/stress.h"
#include "reports/report.h"

#include <algorithm>
#include <fstream>
#include <functional>
#include <map>
#include <optional>
#include <set>

namespace hairbench {

using nlohmann::json;

ShardReport read_shard_report(const std::string& file) {
  std::ifstream in(file);
  if (!in) throw InputError("merge", file, "cannot read the shard report");
  json j = json::parse(in, nullptr, false);
  if (j.is_discarded() || !j.is_object()) throw InputError("merge", file, "not a JSON object");
  if (j.value("schema", "") != "hairbench-report" && j.value("schema", "") != "hairbench-reproduce")
    throw InputError(file, "schema", "not a hairbench-report or hairbench-reproduce");
  const json& s = j.value("shard", json());
  if (!s.is_object())
    throw InputError(file, "shard",
                     "missing: not the report of a shard (run compare, sweep, stress or reproduce with --shard I/N)");
  auto bad = [&](const char* field, const char* what) { return InputError(file, std::string("shard.") + field, what); };
  if (!s.contains("index") || !s["index"].is_number_integer()) throw bad("index", "missing or not a whole number");
  if (!s.contains("count") || !s["count"].is_number_integer()) throw bad("count", "missing or not a whole number");
  if (!s.contains("plan_hash") || !s["plan_hash"].is_string()) throw bad("plan_hash", "missing or not a string");
  if (!s.contains("plan") || !s["plan"].is_array()) throw bad("plan", "missing or not an array");
  for (const json& p : s["plan"])
    if (!p.is_object() || !p.contains("key") || !p["key"].is_string() || !p.contains("shard") ||
        !p["shard"].is_number_integer())
      throw bad("plan", "an entry is not {\"key\": string, \"shard\": integer}");
  if (!j.contains("context") || !j["context"].is_object() || !j["context"].contains("git_sha"))
    throw InputError(file, "context.git_sha", "missing");
  return {file, std::move(j)};
}

std::string machine_label(const json& c) {
  std::string out = c.value("host", "?") + " (" + c.value("cpu", "?") + ", " +
                    std::to_string(c.value("threads", 0)) + " threads";
  for (const json& d : c.value("devices", json::array()))
    out += ", " + (d.is_object() ? d.value("name", "?") : d.is_string() ? d.get<std::string>() : "?");
  return out + ")";
}

namespace {

// A value in a message: a string as it is, anything else as JSON.
std::string text(const json& v) { return v.is_string() ? v.get<std::string>() : v.dump(); }

std::string shard_name(const json& report) {
  return std::to_string(report["shard"]["index"].get<int>()) + "/" + std::to_string(report["shard"]["count"].get<int>());
}

// The checks every merge makes: one build, one plan (the same command cut the same
// way), each shard once. `keys_of` lists the plan keys a shard's report holds; the
// result maps every plan key to the input that holds it, in plan order, after refusing
// duplicates and naming what is missing.
std::vector<std::pair<std::string, std::size_t>> check_shards(
    const std::vector<ShardReport>& in, const std::function<std::vector<std::string>(const json&)>& keys_of) {
  if (in.empty()) throw InputError("arguments", "merge", "name at least one shard report");
  const ShardReport& a = in.front();
  const json& sa = a.report["shard"];
  for (const ShardReport& b : in) {
    const std::string sha = b.report["context"]["git_sha"], sha_a = a.report["context"]["git_sha"];
    if (sha != sha_a)
      throw InputError(b.file, "context.git_sha",
                       sha + " differs from " + sha_a + " in " + a.file + ": shards of different builds cannot be merged");
  }
  for (std::size_t i = 0; i < in.size(); ++i) {
    const ShardReport& b = in[i];
    const json& sb = b.report["shard"];
    if (sb["count"] != sa["count"] || sb["plan_hash"] != sa["plan_hash"])
      throw InputError(b.file, "shard.plan_hash",
                       "shard " + shard_name(b.report) + " of plan " + sb["plan_hash"].get<std::string>() +
                           " is not of the plan of " + a.file + " (shard " + shard_name(a.report) + " of " +
                           sa["plan_hash"].get<std::string>() +
                           "): the shards come from different commands, --costs files or shard counts");
    for (std::size_t k = 0; k < i; ++k)
      if (in[k].report["shard"]["index"] == sb["index"])
        throw InputError(b.file, "shard.index", "shard " + shard_name(b.report) + " is also " + in[k].file);
  }
  std::map<std::string, std::size_t> plan_pos;
  const json& plan = sa["plan"];
  for (std::size_t p = 0; p < plan.size(); ++p) plan_pos.emplace(plan[p]["key"].get<std::string>(), p);
  std::vector<std::optional<std::size_t>> holder(plan.size());
  for (std::size_t i = 0; i < in.size(); ++i)
    for (const std::string& key : keys_of(in[i].report)) {
      const auto it = plan_pos.find(key);
      if (it == plan_pos.end()) throw InputError(in[i].file, "runs", key + " is not in the plan of the shards");
      if (holder[it->second])
        throw InputError(in[i].file, "runs", key + " is also in " + in[*holder[it->second]].file + ": a duplicate run");
      holder[it->second] = i;
    }
  std::vector<std::string> missing;
  std::set<int> absent_shards;
  for (std::size_t p = 0; p < plan.size(); ++p)
    if (!holder[p]) {
      missing.push_back(plan[p]["key"].get<std::string>());
      absent_shards.insert(plan[p]["shard"].get<int>());
    }
  if (!missing.empty()) {
    std::string names;
    constexpr std::size_t kNamed = 20;
    for (std::size_t m = 0; m < std::min(missing.size(), kNamed); ++m) names += (m ? ", " : "") + missing[m];
    if (missing.size() > kNamed) names += " and " + std::to_string(missing.size() - kNamed) + " more";
    std::string shards;
    for (int s : absent_shards) {
      const bool given = std::any_of(in.begin(), in.end(), [&](const ShardReport& r) { return r.report["shard"]["index"] == s; });
      shards += (shards.empty() ? "" : ", ") + std::to_string(s) + "/" + std::to_string(sa["count"].get<int>()) +
                (given ? " (given, without them)" : " (not given)");
    }
    throw InputError("merge", "runs",
                     std::to_string(missing.size()) + " of " + std::to_string(plan.size()) +
                         " runs of the plan are missing, from shard " + shards + ": " + names);
  }
  std::vector<std::pair<std::string, std::size_t>> out;
  for (std::size_t p = 0; p < plan.size(); ++p) out.emplace_back(plan[p]["key"].get<std::string>(), *holder[p]);
  return out;
}

// The shards' part of the merged report: per shard its file, context and machine; the
// machines; whether charts may mix them.
json merge_section(const std::vector<ShardReport>& in, bool mix_machines) {
  json shards = json::array(), machines = json::array();
  std::vector<std::string> labels;
  std::vector<std::size_t> order(in.size());
  for (std::size_t i = 0; i < in.size(); ++i) order[i] = i;
  std::sort(order.begin(), order.end(), [&](std::size_t x, std::size_t y) {
    return in[x].report["shard"]["index"].get<int>() < in[y].report["shard"]["index"].get<int>();
  });
  for (std::size_t i : order) {
    const json& r = in[i].report;
    const std::string label = machine_label(r["context"]);
    auto it = std::find(labels.begin(), labels.end(), label);
    if (it == labels.end()) {
      labels.push_back(label);
      machines.push_back(label);
      it = labels.end() - 1;
    }
    shards.push_back({{"index", r["shard"]["index"]},
                      {"file", in[i].file},
                      {"context", r["context"]},
                      {"machine", it - labels.begin()},
                      {"estimated_s", r["shard"].value("estimated_s", json())}});
  }
  return {{"count", in.front().report["shard"]["count"]},
          {"plan_hash", in.front().report["shard"]["plan_hash"]},
          {"mix_machines", mix_machines},
          {"machines", machines},
          {"shards", shards}};
}

// The merge's own context (where and when the merged report was made), with every GPU
// a shard used; threads where every shard used the same number, else null.
json merged_context(const std::vector<ShardReport>& in) {
  json ctx = context_json(ReportContext{1, {}});
  json devices = json::array();
  std::set<std::string> seen;
  std::set<json> threads;
  for (const ShardReport& s : in) {
    threads.insert(s.report["context"].value("threads", json()));
    for (const json& d : s.report["context"].value("devices", json::array())) {
      const std::string name = d.is_object() ? d.value("name", "") : d.dump();
      if (seen.insert(name).second) devices.push_back(d);
    }
  }
  ctx["devices"] = devices;
  ctx["threads"] = threads.size() == 1 ? *threads.begin() : json();
  return ctx;
}

}  // namespace

json merge_reports(const std::vector<ShardReport>& in, bool mix_machines) {
  // Scenario definitions and reference bits first: a tampered scenario may also move
  // the cut, and "a different scenario" says more than "a different plan".
  struct Seen {
    std::size_t shard;
    const json* scenario;
  };
  std::map<std::string, Seen> scenarios;
  for (std::size_t i = 0; i < in.size(); ++i) {
    if (!in[i].report.contains("scenarios")) continue;
    for (const json& sc : in[i].report["scenarios"]) {
      const std::string name = sc.value("name", "");
      const auto [it, fresh] = scenarios.emplace(name, Seen{i, &sc});
      if (fresh) continue;
      const json& first = *it->second.scenario;
      const std::string& other = in[it->second.shard].file;
      for (const auto& [field, why] :
           {std::pair<const char*, const char*>{"definition_hash",
                                                "a different scenario definition (its file, --frames, --set or "
                                                "--reference)"},
            {"reference_state_hash", "the reference runs ended in different states"}})
        if (sc.value(field, json()) != first.value(field, json()))
          throw InputError(in[i].file, "scenarios[" + name + "]." + field,
                           text(sc.value(field, json())) + " differs from " + text(first.value(field, json())) +
                               " in " + other + ": " + why);
    }
  }
  const auto held = check_shards(in, [](const json& r) {
    std::vector<std::string> keys;
    for (const json& run : r.value("runs", json::array())) keys.push_back(run_key(run));
    return keys;
  });
  std::vector<std::map<std::string, const json*>> by_key(in.size());
  for (std::size_t i = 0; i < in.size(); ++i)
    for (const json& run : in[i].report["runs"]) by_key[i][run_key(run)] = &run;

  // The shards' metric tables must be one table: a shard from another hairbench build
  // would put its numbers under the same names with other meanings.
  for (std::size_t i = 1; i < in.size(); ++i)
    if (in[i].report.value("metric_definitions", json()) != in.front().report.value("metric_definitions", json()))
      throw InputError(in[i].file, "metric_definitions",
                       "differs from " + in.front().file + "'s: the shards come from different hairbench builds");
  json report = {{"schema", "hairbench-report"},
                 {"schema_version", in.front().report.value("schema_version", 3)},
                 {"context", merged_context(in)},
                 {"snapshot_encoding", kSnapshotEncoding},
                 {"animation_encoding", animation::kEncoding},
                 {"metric_definitions", in.front().report.value("metric_definitions", json())}};
  json runs = json::array(), scenario_list = json::array();
  std::set<std::string> listed;
  for (const auto& [key, i] : held) {
    json run = *by_key[i].at(key);
    run["shard"] = in[i].report["shard"]["index"];
    const std::string sc = run["scenario"];
    if (listed.insert(sc).second && scenarios.count(sc)) scenario_list.push_back(*scenarios.at(sc).scenario);
    // The player draws the kept scenario's strands: a shard whose verdicts named others
    // recorded other strands, and its runs are left without frames.
    if (scenarios.count(sc) && run.contains("animation")) {
      const json& kept = scenarios.at(sc).scenario->value("animation", json());
      json mine;
      for (const json& s : in[i].report.value("scenarios", json::array()))
        if (s.value("name", "") == sc) mine = s.value("animation", json());
      if (kept.is_null() || mine.is_null() || kept.value("strands", json()) != mine.value("strands", json()))
        run.erase("animation");
    }
    runs.push_back(std::move(run));
  }
  report["runs"] = std::move(runs);
  if (!scenario_list.empty()) report["scenarios"] = std::move(scenario_list);
  if (in.front().report.contains("sweep")) report["sweep"] = in.front().report["sweep"];
  report["merge"] = merge_section(in, mix_machines);
  return report;
}

json merge_stress_reports(const std::vector<ShardReport>& in) {
  for (std::size_t i = 0; i < in.size(); ++i) {
    const json& st = in[i].report.value("stress", json());
    if (!st.is_object() || !st.contains("axes") || !st.contains("degenerate"))
      throw InputError(in[i].file, "stress", "missing: not the report of a stress shard (or mixed with one that is)");
    const json& first = in.front().report["stress"];
    for (const char* field : {"base", "groom", "base_hash"})
      if (st.value(field, json()) != first.value(field, json()))
        throw InputError(in[i].file, std::string("stress.") + field,
                         text(st.value(field, json())) + " differs from " + text(first.value(field, json())) +
                             " in " + in.front().file + ": a different base scenario (--base, --keep-every or its file)");
  }
  // A cell's key is its plan key (stress_cell_key); each axis's cells are merged in plan
  // order, which is escalation order.
  auto cells_of = [](const json& r) {
    std::vector<std::string> keys;
    for (const json& a : r["stress"]["axes"])
      for (const json& v : a["values"]) keys.push_back(stress_cell_key(a["model"], a["axis"], v.get<double>()));
    for (const json& d : r["stress"]["degenerate"]) keys.push_back(stress_groom_key(d["model"], d["groom"]));
    return keys;
  };
  const auto held = check_shards(in, cells_of);
  std::map<std::string, std::pair<std::size_t, json>> cell;  // key -> (input, {axis fields, value, stable, reason})
  for (std::size_t i = 0; i < in.size(); ++i) {
    for (const json& a : in[i].report["stress"]["axes"])
      for (std::size_t c = 0; c < a["values"].size(); ++c)
        cell[stress_cell_key(a["model"], a["axis"], a["values"][c].get<double>())] = {
            i, {{"model", a["model"]}, {"axis", a["axis"]}, {"unit", a["unit"]}, {"value", a["values"][c]},
                {"stable", a["stable"][c]}, {"reason", a["reasons"][c]}}};
    for (const json& d : in[i].report["stress"]["degenerate"]) cell[stress_groom_key(d["model"], d["groom"])] = {i, d};
  }
  StressResult result;
  const json& first = in.front().report["stress"];
  result.base = first["base"];
  result.base_hash = first.value("base_hash", "");
  result.strands = first["groom"]["strands"];
  result.vertices = first["groom"]["vertices"];
  for (const auto& [key, i] : held) {
    const json& c = cell.at(key).second;
    if (c.contains("groom")) {
      result.degenerate.push_back({c["model"], c["groom"], c["status"], c["reason"].is_null() ? "" : c["reason"]});
      continue;
    }
    if (result.axes.empty() || result.axes.back().model != c["model"] || result.axes.back().axis != c["axis"])
      result.axes.push_back({c["model"], c["axis"], c["unit"], {}, {}, {}, {}});
    result.axes.back().cells.push_back({c["value"], c["stable"], c["reason"]});
  }
  for (StressAxisResult& a : result.axes) decide_axis(a);
  json report = {{"schema", "hairbench-report"},
                 {"schema_version", in.front().report.value("schema_version", 3)},
                 {"context", merged_context(in)},
                 {"snapshot_encoding", kSnapshotEncoding},
                 {"runs", json::array()}};
  report["stress"] = stress_json(result);
  report["merge"] = merge_section(in, false);
  return report;
}

json merge_reproduce_reports(const std::vector<ShardReport>& in) {
  for (const ShardReport& s : in)
    if (s.report["schema"] != in.front().report["schema"])
      throw InputError(s.file, "schema", "a " + s.report["schema"].get<std::string>() + " among " +
                                             in.front().report["schema"].get<std::string>() + " shards");
  const auto keys_of = [](const json& r) {
    std::vector<std::string> keys;
    for (const json& p : r["papers"]) keys.push_back(reproduce_plan_key(p["id"], r["frames_cap"]));
    return keys;
  };
  json papers = json::array();
  double wall_s = 0.0;
  for (const auto& [key, i] : check_shards(in, keys_of))
    for (const json& p : in[i].report["papers"])
      if (reproduce_plan_key(p["id"], in[i].report["frames_cap"]) == key) papers.push_back(p);
  for (const ShardReport& s : in) wall_s += s.report.value("wall_s", 0.0);
  return {{"schema", "hairbench-reproduce"},
          {"schema_version", in.front().report["schema_version"]},
          {"context", merged_context(in)},
          {"papers", papers},
          {"frames_cap", in.front().report["frames_cap"]},
          {"load_average", {{"start", nullptr}, {"end", nullptr}}},
          {"wall_s", wall_s},
          {"summary", reproduce_summary(papers)},
          {"merge", merge_section(in, false)}};
}

}  // namespace hairbench
