#include "scenarios/groom_scenario.h"

#include "core/error.h"

#include <cstdio>
#include <fstream>
#include <sstream>

namespace hairbench {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

std::string text(double v, const char* fmt = "%.4g") {
  char buf[64];
  std::snprintf(buf, sizeof buf, fmt, v);
  return buf;
}

// The built-in scenario file of a motion, parsed.
json motion_doc(const std::string& motion) {
  const fs::path file = builtin_scenario_dir() / (motion + ".json");
  std::error_code ec;
  if (motion.empty() || motion.find('/') != std::string::npos || !fs::is_regular_file(file, ec)) {
    std::string names;
    for (const fs::path& p : builtin_scenarios()) names += (names.empty() ? "" : ", ") + p.stem().string();
    throw InputError("--motion", motion, "not a built-in scenario (one of: " + names + ")");
  }
  std::ifstream in(file);
  return json::parse(in);
}

}  // namespace

std::vector<std::string> default_motions() { return {"idle", "nod", "shake", "spin_fast", "walk", "wind_gust"}; }

std::string groom_scenario_name(const fs::path& groom, const std::string& motion) {
  return groom.stem().string() + "_" + motion;
}

json groom_scenario_json(const fs::path& groom, const std::string& groom_as_written, const std::string& motion,
                         const std::string& unit, std::optional<double> fit_above) {
  const std::string ext = groom.extension().string();
  if (ext != ".tfx" && ext != ".tfxproj")
    throw InputError("--groom", groom.string(), "expected a TressFX .tfx or .tfxproj file");
  const json m = motion_doc(motion);
  json head = {{"radius", "fit"}};
  if (m.contains("head")) {
    for (const char* k : {"keys", "oscillators"})
      if (m["head"].contains(k)) head[k] = m["head"][k];
  }
  json doc = {
      {"name", groom_scenario_name(groom, motion)},
      {"description", groom.filename().string() + " under the built-in " + motion +
                          " motion; pivot, head sphere and collider fitted through the roots"},
      {"frames", m.at("frames")},
      {"dt", m.at("dt")},
      {"groom", {{ext == ".tfx" ? "tfx" : "tfx_project", groom_as_written}, {"unit", unit}, {"pivot", "fit"}}},
      {"head", head},
      {"colliders", json::array({{{"type", "sphere"}, {"center", {0, 0, 0}}, {"radius", "fit"}, {"attached", "head"}}})}};
  if (fit_above) doc["groom"]["fit_above"] = *fit_above;
  for (const char* k : {"gravity", "wind", "settle_from"})
    if (m.contains(k)) doc[k] = m[k];
  return doc;
}

Scenario with_motion(const Scenario& base, const std::string& motion) {
  motion_doc(motion);  // the same message as groom_scenario_json for a bad name
  const Scenario m = load_scenario(builtin_scenario_dir() / (motion + ".json"));
  Scenario sc = base;
  sc.name = groom_scenario_name(base.import ? base.import->file : fs::path(base.name), motion);
  sc.description = base.description.substr(0, base.description.find(" under the built-in ")) +
                   " under the built-in " + motion + " motion; pivot, head sphere and collider fitted through the roots";
  sc.frames = m.frames;
  sc.dt = m.dt;
  sc.gravity = m.gravity;
  sc.head = m.head;
  sc.wind = m.wind;
  sc.settle_from = m.settle_from;
  return sc;
}

std::string import_summary(const Scenario& sc) {
  if (!sc.import) return "";
  const GroomImport& im = *sc.import;
  std::ostringstream os;
  const std::size_t follow = sc.follow ? sc.follow->strand_count() : 0;
  os << "groom " << im.file.string() << ": " << sc.groom.strand_count() - follow << " strands";
  if (follow) os << " (+" << follow << " follow hairs)";
  os << ", " << sc.groom.vertex_count() << " vertices\n";
  // The unit, the head and the repairs on one line: a wrong fit shows before any metric.
  os << "  unit " << im.unit << (im.unit_from == "given" ? " (given)" : " (guessed: " + im.unit_from + ")");
  if (im.fitted) {
    const HeadFit& f = im.fit;
    const float mpu = metres_per_unit(im.unit);
    const Vec3f c = f.center / mpu;  // fitted in metres, before the pivot moved the groom
    const std::size_t used = f.roots - f.rejected.size();
    os << "; head ";
    if (!f.sphere) {
      os << "not fitted: " << f.note;
    } else {
      os << "fit on " << used << " of " << f.roots << " roots";
      if (f.method == "consensus") os << " (" << f.rejected.size() << " rejected: off the scalp's sphere)";
      else if (f.method == "above") os << " (" << f.rejected.size() << " rejected: at or below --fit-above)";
      os << ": centre [" << text(c.x()) << ", " << text(c.y()) << ", " << text(c.z()) << "] file units, radius "
         << text(f.radius, "%.4f") << " m, RMS residual " << text(f.rms_residual * 1e3, "%.3g") << " mm"
         << (f.scalp ? "" : "; " + f.note);
    }
  }
  os << "; " << repairs_text(im.repairs) << "\n";
  os << "  pivot [" << text(im.pivot.x()) << ", " << text(im.pivot.y()) << ", " << text(im.pivot.z())
     << "] file units (" << im.pivot_from << ")";
  os << "; head radius " << text(sc.head_radius, "%.4f") << " m" << (im.head_radius_fit ? " (fit)" : "") << "; colliders:";
  for (const Sphere& s : sc.colliders)
    os << " r " << text(s.radius, "%.4f") << " m at [" << text(s.center.x(), "%.3f") << ", "
       << text(s.center.y(), "%.3f") << ", " << text(s.center.z(), "%.3f") << "]";
  if (sc.colliders.empty()) os << " none";
  os << "\n";
  return os.str();
}

}  // namespace hairbench
