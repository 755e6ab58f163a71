#include "harness/stress.h"

#include "core/error.h"
#include "core/parallel.h"
#include "harness/runner.h"
#include "harness/shard.h"
#include "reports/verdict.h"
#include "models/registry.h"
#include "scenarios/groom_gen.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <regex>

namespace hairbench {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

// One axis: its values in escalation order and how a value changes the base scenario
// (or the model's parameters).
struct Axis {
  std::string name, unit;
  std::vector<double> values;
  std::function<void(Scenario&, std::vector<ParamOverride>&, double)> apply;
};

void set_frames_for(Scenario& sc, double seconds) { sc.frames = static_cast<int>(std::lround(seconds / sc.dt)); }

// A straight groom with the base's strand count, regenerated for the axes that change
// the strands themselves; the base's region parameters no longer apply to it.
void regenerate_groom(Scenario& sc, int vertices, double length) {
  GroomSpec spec;
  spec.strands = static_cast<int>(sc.groom.strand_count());
  spec.vertices_per_strand = vertices;
  spec.length = length;
  GeneratedGroom g = generate_groom(spec, sc.head_radius, "stress");
  sc.groom = std::move(g.groom);
  sc.region_params = std::move(g.region_params);
  for (auto& [model, o] : sc.models) o.regions.clear();
}

// A still start, then constant angular velocity about y for 1 s, then a 1.5 s hold in
// which the energy check watches the hair settle.
void spin(Scenario& sc, double deg_per_s) {
  sc.head.oscillators.clear();
  sc.head.keys = {HeadKey{0.0, Vec3f::Zero(), Vec3f::UnitY(), 0.0, false},
                  HeadKey{1.0, Vec3f::Zero(), Vec3f::UnitY(), deg_per_s * kDeg, true}};
  set_frames_for(sc, 2.5);
}

// ±20° shaking whose peak angular acceleration A (2 pi f)^2 is the axis value, over a
// whole number of half periods near 1.5 s (so the head ends where it started, with no
// jump), then a 1.5 s hold.
void shake_with_acceleration(Scenario& sc, double deg_per_s2) {
  const double amplitude = 20.0;
  const double f = std::sqrt(deg_per_s2 / amplitude) / (2.0 * std::numbers::pi);
  const double end = std::ceil(1.5 * 2.0 * f) / (2.0 * f);
  sc.head.keys.clear();
  sc.head.oscillators = {Oscillator{Oscillator::Kind::Rotate, Vec3f::UnitY(), amplitude * kDeg, f, 0.0, 0.0, end}};
  set_frames_for(sc, end + 1.5);
}

// The head jumps by `metres` along x within one frame at t = 0.5 s and stays there.
void teleport(Scenario& sc, double metres) {
  sc.head.oscillators.clear();
  sc.head.keys = {HeadKey{0.5, Vec3f::Zero(), Vec3f::UnitY(), 0.0, false},
                  HeadKey{0.5 + sc.dt, Vec3f(static_cast<float>(metres), 0.0f, 0.0f), Vec3f::UnitY(), 0.0, true}};
  set_frames_for(sc, 2.5);
}

// Values clamped into the parameter's declared range, duplicates dropped.
std::vector<double> within(const ParamSpec& p, std::initializer_list<double> values) {
  std::vector<double> out;
  for (double v : values) {
    const double c = std::clamp(v, p.min, p.max);
    if (out.empty() || out.back() != c) out.push_back(c);
  }
  return out;
}

std::vector<Axis> axes_for(const ModelInfo& model) {
  std::vector<Axis> axes = {
      {"time_step", "s", {1.0 / 240, 1.0 / 120, 1.0 / 60, 1.0 / 30, 1.0 / 20, 1.0 / 10},
       [](Scenario& sc, auto&, double v) {
         const double seconds = sc.duration();
         sc.dt = v;
         set_frames_for(sc, seconds);
       }},
      {"angular_velocity", "deg/s", {90, 250, 500, 1000, 2000, 3500, 5000},
       [](Scenario& sc, auto&, double v) { spin(sc, v); }},
      {"angular_acceleration", "deg/s^2", {1e3, 3e3, 1e4, 3e4, 1e5, 3e5},
       [](Scenario& sc, auto&, double v) { shake_with_acceleration(sc, v); }},
      {"teleport", "m", {0.1, 0.3, 1, 3, 10}, [](Scenario& sc, auto&, double v) { teleport(sc, v); }},
      // The Halén models simulate as many nodes as the groom has vertices, up to their
      // parameter's 64: the axis stresses their simulation, not their drawing.
      {"vertices_per_strand", "", {2, 4, 8, 16, 32, 64, 128},
       [](Scenario& sc, auto&, double v) {
         regenerate_groom(sc, static_cast<int>(v), 0.25);
         sc.models["*"].base["nodes"] = std::min(v, 64.0);
       }},
      {"strand_length", "m", {0.001, 0.01, 0.1, 1, 10},
       [](Scenario& sc, auto&, double v) { regenerate_groom(sc, 16, v); }},
  };
  // Parameter extremes: every stiffness at 0 and 1, every iteration count from 1 to 64,
  // damping at 0 and 1, each within what the model accepts.
  const std::string name(model.name);
  for (const ParamSpec& p : model.params) {
    const std::string pn(p.name);
    std::vector<double> values;
    if (pn.find("stiffness") != std::string::npos || pn == "damping") values = within(p, {0.0, 1.0});
    else if (pn.find("iterations") != std::string::npos) values = within(p, {1, 2, 4, 8, 16, 32, 64});
    else continue;
    axes.push_back({pn, "", values, [name, pn](Scenario&, std::vector<ParamOverride>& o, double v) {
                      o.push_back({name, pn, v});
                    }});
  }
  return axes;
}

// --- Degenerate grooms: each runs (never diverges) or is refused at load. ---

struct Degenerate {
  std::string name;
  Groom groom;
  std::vector<Sphere> colliders;  // replaces the base's when not empty
};

std::vector<Vec3f> line(const Vec3f& root, const Vec3f& dir, int n, float length) {
  std::vector<Vec3f> p;
  for (int i = 0; i < n; ++i) p.push_back(root + dir * (length * static_cast<float>(i) / static_cast<float>(n - 1)));
  return p;
}

Vec3f on_head(float r, float azimuth, float elevation) {
  return r * Vec3f(std::cos(elevation) * std::cos(azimuth), std::sin(elevation), std::cos(elevation) * std::sin(azimuth));
}

std::vector<Degenerate> degenerate_grooms(float r) {
  std::vector<Degenerate> out;
  auto groom = [] { Groom g; g.strand_offsets = {0}; return g; };
  {  // Two vertices of one strand coincide: an edge of length zero has no direction.
    Degenerate d{"zero_length_edge", groom(), {}};
    for (int s = 0; s < 8; ++s) {
      const Vec3f root = on_head(r, 0.8f * s, 0.6f);
      std::vector<Vec3f> p = line(root, root.normalized(), 16, 0.25f);
      p[6] = p[5];
      d.groom.add_strand(p, 0);
    }
    out.push_back(std::move(d));
  }
  {  // Exactly vertical, collinear strands (Han & Harada §4.1: the frame of a strand
     // parallel to the reference axis needs an arbitrary perpendicular vector).
    Degenerate d{"vertical_collinear", groom(), {}};
    for (int s = 0; s < 8; ++s) {
      const float a = 0.8f * s;
      d.groom.add_strand(line(on_head(r, a, 0.0f), -Vec3f::UnitY(), 16, 0.25f), 0);
    }
    d.groom.add_strand(line(Vec3f(0, r, 0), Vec3f::UnitY(), 16, 0.25f), 0);
    out.push_back(std::move(d));
  }
  {  // Strands of only two vertices: both pinned, nothing free to simulate.
    Degenerate d{"two_vertex_strands", groom(), {}};
    for (int s = 0; s < 8; ++s) {
      const Vec3f root = on_head(r, 0.8f * s, 0.5f);
      d.groom.add_strand(line(root, root.normalized(), 2, 0.02f), 0);
    }
    out.push_back(std::move(d));
  }
  {  // Many strands on one root with one direction: identical, overlapping strands.
    Degenerate d{"coincident_roots", groom(), {}};
    const Vec3f root = on_head(r, 0.3f, 0.4f);
    for (int s = 0; s < 16; ++s) d.groom.add_strand(line(root, root.normalized(), 16, 0.25f), 0);
    out.push_back(std::move(d));
  }
  {  // Hanging strands whose lower half starts inside a head-attached collider.
    Degenerate d{"inside_collider", groom(), {}};
    for (int s = 0; s < 8; ++s) {
      const Vec3f root = on_head(r, 0.1f * s - 0.35f, 0.0f);
      d.groom.add_strand(line(root, -Vec3f::UnitY(), 16, 0.25f), 0);
    }
    d.colliders = {Sphere{Vec3f::Zero(), r, true}, Sphere{Vec3f(r, -0.18f, 0.0f), 0.06f, true}};
    out.push_back(std::move(d));
  }
  return out;
}

// Runs `model` alone on sc: its verdict class and why, ok with "" when it held.
// Any class but ok fails a stress value: a stretched strand, or hair that does not return,
// is as much a limit of the configuration as a diverged one.
std::pair<verdict::Status, std::string> run_one(const Scenario& sc, const std::string& model,
                                                const std::vector<ParamOverride>& overrides, ThreadPool& pool) {
  RunOptions opt;
  opt.models = {model};
  opt.reference = model;
  opt.overrides = overrides;
  opt.material_card = false;  // stress.json shows verdicts only
  const std::vector<RunRecord> runs = run_scenario(sc, opt, pool);
  const verdict::Verdict& v = runs.front().verdict;
  if (v.status == verdict::Status::ok) return {v.status, {}};
  std::string why = std::string(verdict::status_name(v.status)) + ": " + v.reason;
  if (v.frame >= 0) {
    char at[48];
    std::snprintf(at, sizeof at, " (t = %.3g s)", v.t);
    why += at;
  }
  return {v.status, why};
}

}  // namespace

std::string stress_cell_key(const std::string& model, const std::string& axis, double value) {
  char v[32];
  std::snprintf(v, sizeof v, "%.17g", value);
  return model + "/" + axis + "=" + v;
}

std::string stress_groom_key(const std::string& model, const std::string& groom) { return model + "/groom:" + groom; }

void decide_axis(StressAxisResult& a) {
  a.last_stable.reset();
  a.first_failing.reset();
  a.reason.clear();
  for (const StressCell& c : a.cells) {
    if (!c.stable && !a.first_failing) {
      a.first_failing = c.value;
      a.reason = c.reason;
    }
    if (c.stable && !a.first_failing) a.last_stable = c.value;
  }
  if (!a.first_failing) a.last_stable.reset();  // "never failed" reads better than a value
}

namespace {

// What a stress command runs: the thinned base, each model's selected axes with their
// values, and the degenerate grooms.
struct StressWork {
  Scenario base;
  struct Planned {
    std::string model;
    Axis axis;
  };
  std::vector<Planned> plan;
  std::vector<Degenerate> degenerate;
};

StressWork prepare(const StressOptions& opt) {
  StressWork w;
  w.base = load_scenario(find_scenario(opt.base));
  Scenario& base = w.base;
  // Each axis escalates a model at its own substeps: picked from the groom, they would
  // follow the time step and strand axes instead of meeting them.
  base.auto_substeps = false;
  if (base.follow)
    throw InputError(base.source.string(), "groom.follow_hairs",
                     "stress needs a base whose strands are all simulated (\"simulate\")");
  base.groom = every_nth_strand(base.groom, opt.keep_every);
  std::regex axis_re;
  try {
    axis_re = std::regex(opt.axes);
  } catch (const std::regex_error& e) {
    throw InputError("arguments", "--axes", std::string("bad regular expression: ") + e.what());
  }
  for (const std::string& m : opt.models) {
    const ModelInfo* info = find_model(m);
    if (!info) throw InputError("--models", m, "unknown model");
    for (Axis& a : axes_for(*info)) {
      if (!std::regex_match(a.name, axis_re)) continue;
      if (opt.value_stride > 1) {
        std::vector<double> kept;
        for (std::size_t i = 0; i < a.values.size(); i += static_cast<std::size_t>(opt.value_stride))
          kept.push_back(a.values[i]);
        if (kept.back() != a.values.back()) kept.push_back(a.values.back());  // keep the extreme
        a.values = std::move(kept);
      }
      w.plan.push_back({m, std::move(a)});
    }
  }
  if (opt.degenerate) w.degenerate = degenerate_grooms(base.head_radius);
  return w;
}

// The base with a degenerate groom in place of its own.
Scenario with_groom(const Scenario& base, const Degenerate& d) {
  Scenario sc = base;
  sc.groom = d.groom;
  sc.groom.head_radius = base.head_radius;
  sc.region_params.assign(1, {});
  for (auto& [model, o] : sc.models) o.regions.clear();
  if (!d.colliders.empty()) sc.colliders = d.colliders;
  return sc;
}

}  // namespace

Plan plan_stress(const StressOptions& opt, const CostModel& costs, int count) {
  const StressWork w = prepare(opt);
  Plan plan;
  plan.count = count;
  plan.cost_source = costs.from_file() ? costs.file() : "the built-in table";
  plan.process_seconds = kProcessSeconds;
  // Each run is its own lockstep batch (the model is its own reference): no shared cost.
  plan.group_cost = {0.0};
  plan.group_label = {"each run alone"};
  auto estimate = [&](const Scenario& sc, const std::string& model, const std::vector<ParamOverride>& o,
                      const std::string& key) {
    const ModelInfo& info = *find_model(model);
    try {
      return costs.run(info, resolve_params(info, sc, o), key, sc.groom.strand_count(), sc.groom.vertex_count(),
                       sc.frames, work_fraction(sc, sc.frames));
    } catch (const InputError&) {  // refused at load: it costs nothing
      return CostEstimate{0.0, "refused"};
    }
  };
  for (const StressWork::Planned& p : w.plan)
    for (double v : p.axis.values) {
      Scenario sc = w.base;
      std::vector<ParamOverride> overrides;
      p.axis.apply(sc, overrides, v);
      const std::string key = stress_cell_key(p.model, p.axis.name, v);
      char label[160];
      std::snprintf(label, sizeof label, "%s %s=%g", p.model.c_str(), p.axis.name.c_str(), v);
      plan.items.push_back({key, label, 0, estimate(sc, p.model, overrides, key), 0});
    }
  for (const std::string& m : opt.models)
    for (const Degenerate& d : w.degenerate) {
      const std::string key = stress_groom_key(m, d.name);
      plan.items.push_back({key, m + " groom:" + d.name, 0, estimate(with_groom(w.base, d), m, {}, key), 0});
    }
  partition(plan);
  return plan;
}

StressResult run_stress(const StressOptions& opt, ThreadPool& pool, const std::function<void(int, int)>& progress) {
  const StressWork w = prepare(opt);
  const Scenario& base = w.base;
  StressResult result;
  result.base = base.name;
  result.base_hash = scenario_hash(base, base.frames);
  result.strands = base.groom.strand_count();
  result.vertices = base.groom.vertex_count();

  auto wanted = [&](const std::string& key) { return !opt.only || opt.only->count(key); };
  int total = 0, done = 0;
  for (const StressWork::Planned& p : w.plan)
    for (double v : p.axis.values) total += wanted(stress_cell_key(p.model, p.axis.name, v));
  for (const std::string& m : opt.models)
    for (const Degenerate& d : w.degenerate) total += wanted(stress_groom_key(m, d.name));
  auto tick = [&] {
    if (progress) progress(++done, total);
  };

  for (const StressWork::Planned& p : w.plan) {
    StressAxisResult ar{p.model, p.axis.name, p.axis.unit, {}, {}, {}, {}};
    for (double v : p.axis.values) {
      if (!wanted(stress_cell_key(p.model, p.axis.name, v))) continue;
      Scenario sc = base;
      std::vector<ParamOverride> overrides;
      p.axis.apply(sc, overrides, v);
      StressCell cell{v, true, {}};
      try {
        cell.reason = run_one(sc, p.model, overrides, pool).second;
      } catch (const InputError& e) {  // the model refuses this configuration
        cell.reason = std::string("refused: ") + e.what();
      }
      cell.stable = cell.reason.empty();
      ar.cells.push_back(std::move(cell));
      tick();
    }
    if (ar.cells.empty()) continue;
    decide_axis(ar);
    result.axes.push_back(std::move(ar));
  }

  for (const std::string& m : opt.models)
    for (const Degenerate& d : w.degenerate) {
      if (!wanted(stress_groom_key(m, d.name))) continue;
      DegenerateResult dr{m, d.name, "ok", {}};
      const Scenario sc = with_groom(base, d);
      try {
        validate_groom(sc.groom, "stress: degenerate groom '" + d.name + "'");
        const auto [status, why] = run_one(sc, m, {}, pool);
        dr.status = std::string(verdict::status_name(status));
        dr.reason = why;
      } catch (const InputError& e) {
        dr.status = "refused";
        dr.reason = e.what();
      }
      result.degenerate.push_back(std::move(dr));
      tick();
    }
  return result;
}

nlohmann::json stress_json(const StressResult& r) {
  auto opt_num = [](const std::optional<double>& v) { return v ? nlohmann::json(*v) : nlohmann::json(nullptr); };
  nlohmann::json axes = nlohmann::json::array();
  for (const StressAxisResult& a : r.axes) {
    nlohmann::json values = nlohmann::json::array(), stable = nlohmann::json::array(),
                   reasons = nlohmann::json::array();
    for (const StressCell& c : a.cells) {
      values.push_back(c.value);
      stable.push_back(c.stable);
      reasons.push_back(c.reason);
    }
    axes.push_back({{"model", a.model},
                    {"axis", a.axis},
                    {"unit", a.unit},
                    {"values", values},
                    {"stable", stable},
                    {"reasons", reasons},
                    {"last_stable", opt_num(a.last_stable)},
                    {"first_failing", opt_num(a.first_failing)},
                    {"reason", a.reason.empty() ? nlohmann::json(nullptr) : nlohmann::json(a.reason)}});
  }
  nlohmann::json degenerate = nlohmann::json::array();
  for (const DegenerateResult& d : r.degenerate)
    degenerate.push_back({{"model", d.model},
                          {"groom", d.name},
                          {"status", d.status},
                          {"reason", d.reason.empty() ? nlohmann::json(nullptr) : nlohmann::json(d.reason)}});
  return {{"base", r.base},
          {"base_hash", r.base_hash},
          {"groom", {{"strands", r.strands}, {"vertices", r.vertices}}},
          {"failure_criteria",
           "any verdict but ok (docs/verdicts.md): diverged (NaN/Inf; a vertex farther than 10 mean strand "
           "lengths from the head; mechanical energy rising by > 5% g L-bar per 10-frame window for 60 frames with "
           "the head still), unstable (a perturbation at rest growing faster than 1/s, or motion not decaying with "
           "the head still), deformed (at the end more than 0.1 mean strand lengths RMS from where the model rests with the "
           "head held still at the final pose), stretched (an edge more than 50% of its strand's median rest edge off "
           "its rest length)"},
          {"axes", axes},
          {"degenerate", degenerate}};
}

std::string stress_table(const StressResult& r) {
  std::string out;
  char line[512];
  std::snprintf(line, sizeof line, "%-14s %-32s %-12s %-12s %s\n", "model", "axis", "last stable", "first fail",
                "reason");
  out += line;
  auto num = [](const std::optional<double>& v) {
    if (!v) return std::string("-");
    char b[32];
    std::snprintf(b, sizeof b, "%.4g", *v);
    return std::string(b);
  };
  for (const StressAxisResult& a : r.axes) {
    const std::string last = a.first_failing ? num(a.last_stable) : "all stable";
    std::snprintf(line, sizeof line, "%-14s %-32s %-12s %-12s %s\n", a.model.c_str(),
                  (a.axis + (a.unit.empty() ? "" : " [" + a.unit + "]")).c_str(), last.c_str(),
                  num(a.first_failing).c_str(), a.reason.c_str());
    out += line;
  }
  for (const DegenerateResult& d : r.degenerate) {
    std::snprintf(line, sizeof line, "%-14s %-32s %-25s %s\n", d.model.c_str(), ("groom:" + d.name).c_str(),
                  d.status.c_str(), d.reason.c_str());
    out += line;
  }
  return out;
}

}  // namespace hairbench
