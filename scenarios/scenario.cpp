#include "scenarios/scenario.h"

#include "core/error.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <fstream>
#include <functional>
#include <iomanip>
#include <limits>
#include <numbers>
#include <optional>
#include <set>
#include <sstream>
#include <string_view>

namespace hairbench {

namespace {

using nlohmann::json;
namespace fs = std::filesystem;

constexpr std::int64_t kMaxFrames = 1'000'000;

// ---------------------------------------------------------------------------------------
// Messages

std::string num_text(double v) {
  std::ostringstream os;
  os << std::setprecision(10) << v;
  return os.str();
}

// Key names and string values come from the user's file and go into a one-line message;
// control characters are shown escaped, as JSON writes them.
std::string printable(const std::string& s) {
  const bool plain = std::none_of(s.begin(), s.end(), [](char c) {
    return static_cast<unsigned char>(c) < 0x20 || c == 0x7f;
  });
  return plain ? s : json(s).dump();
}

std::string join_key(const std::string& path, const std::string& key) {
  return path.empty() ? printable(key) : path + "." + printable(key);
}

std::string join_index(const std::string& path, std::size_t i) {
  return path + "[" + std::to_string(i) + "]";
}

template <typename Names>
std::string list_text(const Names& names) {
  std::string out;
  for (std::string_view n : names) out += (out.empty() ? "" : ", ") + std::string(n);
  return out;
}

std::string describe(const json& j) {
  switch (j.type()) {
    case json::value_t::object: return "an object";
    case json::value_t::array: return "an array";
    case json::value_t::string: return "a string";
    case json::value_t::boolean: return "a boolean";
    case json::value_t::null: return "null";
    default: return "a number";
  }
}

// Reports problems as "FILE: KEY: what is wrong", KEY the dotted path of the value.
class Reader {
 public:
  explicit Reader(std::string file) : file_(std::move(file)) {}
  [[noreturn]] void fail(const std::string& path, const std::string& what) const {
    throw InputError(file_, path.empty() ? "(top level)" : path, what);
  }
  const std::string& file() const { return file_; }

 private:
  std::string file_;
};

// ---------------------------------------------------------------------------------------
// Typed values

double as_number(const Reader& r, const json& j, const std::string& path) {
  if (!j.is_number()) r.fail(path, "expected a number, got " + describe(j));
  const double v = j.get<double>();
  // Parsing already rejects literals that overflow a double (1e999). Positions, gravity
  // and wind end up in floats, where a larger magnitude would turn infinite.
  if (std::abs(v) > std::numeric_limits<float>::max())
    r.fail(path, "value is too large (the limit is " + num_text(std::numeric_limits<float>::max()) + ")");
  return v;
}

std::int64_t as_integer(const Reader& r, const json& j, const std::string& path) {
  if (j.is_number_float())
    r.fail(path, "expected an integer, got the floating-point number " + num_text(j.get<double>()));
  if (!j.is_number_integer()) r.fail(path, "expected an integer, got " + describe(j));
  if (j.is_number_unsigned() && j.get<std::uint64_t>() > std::numeric_limits<std::int64_t>::max())
    r.fail(path, "integer out of range");
  return j.get<std::int64_t>();
}

std::string as_string(const Reader& r, const json& j, const std::string& path) {
  if (!j.is_string()) r.fail(path, "expected a string, got " + describe(j));
  return j.get<std::string>();
}

Vec3f as_vec3(const Reader& r, const json& j, const std::string& path) {
  if (!j.is_array() || j.size() != 3)
    r.fail(path, "expected an array of 3 numbers, got " +
                     (j.is_array() ? "an array of " + std::to_string(j.size()) : describe(j)));
  Vec3f v;
  for (std::size_t i = 0; i < 3; ++i)
    v[static_cast<int>(i)] = static_cast<float>(as_number(r, j[i], join_index(path, i)));
  return v;
}

// Axes are given as any non-zero vector and used as unit vectors.
Vec3f as_axis(const Reader& r, const json& j, const std::string& path) {
  const Vec3f v = as_vec3(r, j, path);
  if (!(v.norm() > 1e-6f)) r.fail(path, "must be a non-zero vector");
  return v.normalized();
}

void check_min(const Reader& r, const std::string& path, double v, double lo) {
  if (v < lo) r.fail(path, "must be >= " + num_text(lo) + ", got " + num_text(v));
}

void check_range(const Reader& r, const std::string& path, double v, double lo, double hi) {
  if (v < lo || v > hi)
    r.fail(path, "must be in [" + num_text(lo) + ", " + num_text(hi) + "], got " + num_text(v));
}

void check_positive(const Reader& r, const std::string& path, double v,
                    double hi = std::numeric_limits<double>::max()) {
  if (v <= 0.0 || v > hi)
    r.fail(path, hi == std::numeric_limits<double>::max()
                     ? "must be > 0, got " + num_text(v)
                     : "must be in (0, " + num_text(hi) + "], got " + num_text(v));
}

const json& as_array(const Reader& r, const json& j, const std::string& path) {
  if (!j.is_array()) r.fail(path, "expected an array, got " + describe(j));
  return j;
}

const json& as_object(const Reader& r, const json& j, const std::string& path) {
  if (!j.is_object()) r.fail(path, "expected an object, got " + describe(j));
  return j;
}

// One JSON object of the file with the keys it may hold. Construction rejects any other
// key (docs/scenarios.md: unknown keys are an error that names the key and the file), so a typo
// such as "frequency" for "frequency_hz" never silently falls back to a default.
class Obj {
 public:
  using Keys = std::vector<std::string_view>;
  Obj(const Reader& r, const json& j, std::string path, const Keys& allowed)
      : r_(r), j_(as_object(r, j, path)), path_(std::move(path)) {
    for (const auto& [key, value] : j_.items())
      if (std::find(allowed.begin(), allowed.end(), key) == allowed.end())
        r_.fail(join_key(path_, key), "unknown key (allowed here: " + list_text(allowed) + ")");
  }

  const Reader& reader() const { return r_; }
  std::string key(std::string_view k) const { return join_key(path_, std::string(k)); }
  bool has(std::string_view k) const { return j_.contains(k); }
  const json& at(std::string_view k) const {
    if (!has(k)) r_.fail(key(k), "missing required key");
    return j_.at(std::string(k));
  }

  double number(std::string_view k) const { return as_number(r_, at(k), key(k)); }
  double number_or(std::string_view k, double fallback) const { return has(k) ? number(k) : fallback; }
  std::int64_t integer(std::string_view k, std::int64_t lo, std::int64_t hi) const {
    const std::int64_t v = as_integer(r_, at(k), key(k));
    if (v < lo || v > hi)
      r_.fail(key(k), "must be in [" + std::to_string(lo) + ", " + std::to_string(hi) +
                          "], got " + std::to_string(v));
    return v;
  }
  std::string string(std::string_view k) const { return as_string(r_, at(k), key(k)); }
  std::string string_or(std::string_view k, const std::string& fallback) const {
    return has(k) ? string(k) : fallback;
  }
  // A string that must be one of `choices`.
  std::string one_of(std::string_view k, const Keys& choices) const {
    const std::string v = string(k);
    if (std::find(choices.begin(), choices.end(), v) == choices.end())
      r_.fail(key(k), "unknown value '" + printable(v) + "' (expected one of: " + list_text(choices) + ")");
    return v;
  }
  // The same, optional: the first choice is the default.
  std::string one_of_or_first(std::string_view k, const Keys& choices) const {
    return has(k) ? one_of(k, choices) : std::string(choices.front());
  }
  // Keys this object holds although `allowed` lists them: they belong to another
  // variant of the object (another style, another kind); `why` says which.
  void reject(const Keys& keys, const std::string& why) const {
    for (std::string_view k : keys)
      if (has(k)) r_.fail(key(k), why);
  }
  Vec3f vec3(std::string_view k) const { return as_vec3(r_, at(k), key(k)); }
  Vec3f vec3_or(std::string_view k, const Vec3f& fallback) const { return has(k) ? vec3(k) : fallback; }
  Vec3f axis(std::string_view k) const { return as_axis(r_, at(k), key(k)); }

 private:
  const Reader& r_;
  const json& j_;
  std::string path_;
};

// Calls f(element, path) for each element of the array at `k` (if present).
template <typename F>
void for_each_element(const Obj& o, std::string_view k, F&& f) {
  if (!o.has(k)) return;
  const json& arr = as_array(o.reader(), o.at(k), o.key(k));
  for (std::size_t i = 0; i < arr.size(); ++i) f(arr[i], join_index(o.key(k), i));
}

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

double radians(double degrees) { return degrees * std::numbers::pi / 180.0; }

// ---------------------------------------------------------------------------------------
// Parsing: JSON syntax errors as "FILE: line L, column C: message"

// Follows the parser through the file as a key path (a parse callback), for two jobs
// nlohmann::json does not do: it reports duplicate keys (the library keeps the last of
// two without a word, and a file that says "dt" twice is almost surely a mistake), and
// it names the value a number overflow stopped the parser in.
class KeyPathTracker {
 public:
  explicit KeyPathTracker(const Reader& r) : r_(r) {}

  bool operator()(int /*depth*/, json::parse_event_t event, json& parsed) {
    switch (event) {
      case json::parse_event_t::object_start: enter(false); break;
      case json::parse_event_t::array_start: enter(true); break;
      case json::parse_event_t::object_end:
      case json::parse_event_t::array_end: levels_.pop_back(); break;
      case json::parse_event_t::key: on_key(parsed.get<std::string>()); break;
      case json::parse_event_t::value: count_element(); break;
    }
    return true;
  }

  // The value the parser is reading when it stops inside one.
  std::string unfinished_value_path() const { return path(true); }

 private:
  struct Level {
    bool array = false;
    std::size_t elements = 0;  // arrays: elements begun so far
    std::string key;           // objects: the key being read
    std::set<std::string> keys;
  };

  void count_element() {
    if (!levels_.empty() && levels_.back().array) ++levels_.back().elements;
  }
  void enter(bool array) {
    count_element();
    levels_.push_back({array, 0, {}, {}});
  }
  void on_key(const std::string& key) {
    Level& top = levels_.back();
    top.key = key;
    if (!top.keys.insert(key).second) r_.fail(path(), "duplicate key");
  }
  // Arrays contribute the element being read: the last one begun, or with
  // `next_element` for the innermost array, the one the parser has not yet reported.
  std::string path(bool next_element = false) const {
    std::string p;
    for (std::size_t i = 0; i < levels_.size(); ++i) {
      const Level& l = levels_[i];
      const bool unfinished = next_element && i + 1 == levels_.size();
      p = l.array ? join_index(p, l.elements - (unfinished ? 0 : 1)) : join_key(p, l.key);
    }
    return p;
  }

  const Reader& r_;
  std::vector<Level> levels_;
};

std::string read_text(const Reader& r, const fs::path& file) {
  std::error_code ec;
  if (!fs::exists(file, ec)) r.fail("scenario", "no such file");
  std::ifstream in(file, std::ios::binary);
  if (!in || fs::is_directory(file, ec)) r.fail("scenario", "cannot read the file");
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

// nlohmann's message without its "[json.exception...] parse error at line L, column C: "
// prefix; the position is recomputed from the byte offset, in the project's own shape.
std::string parser_message(const json::parse_error& e) {
  const std::string what = e.what();
  const std::size_t column = what.find("column ");
  const std::size_t colon = column == std::string::npos ? column : what.find(": ", column);
  return colon == std::string::npos ? what : what.substr(colon + 2);
}

// Line and column (1-based, in bytes) of the offending character; `byte` counts the
// characters the parser read, that one (or the end of the input) included.
std::string position_text(const std::string& text, std::size_t byte) {
  const std::string_view before(text.data(), std::min(byte > 0 ? byte - 1 : 0, text.size()));
  const auto line = 1 + std::count(before.begin(), before.end(), '\n');
  const std::size_t newline = before.rfind('\n');
  const std::size_t column = before.size() - (newline == std::string_view::npos ? 0 : newline + 1) + 1;
  return "line " + std::to_string(line) + ", column " + std::to_string(column);
}

json parse_file(const Reader& r, const std::string& text) {
  KeyPathTracker tracker(r);
  try {
    return json::parse(text, std::ref(tracker));
  } catch (const json::parse_error& e) {
    throw InputError(r.file() + ": " + position_text(text, e.byte) + ": " + parser_message(e));
  } catch (const json::out_of_range&) {
    // The one range error of parsing: a literal such as 1e999 that overflows a double.
    r.fail(tracker.unfinished_value_path(), "value is NaN or infinite (the number overflows a double)");
  }
}

// ---------------------------------------------------------------------------------------
// Sections

HeadKey read_head_key(const Reader& r, const json& j, const std::string& path) {
  const Obj o(r, j, path, {"t", "translate", "rotate", "ease"});
  HeadKey k;
  k.t = o.number("t");
  check_min(r, o.key("t"), k.t, 0.0);
  k.translate = o.vec3_or("translate", Vec3f::Zero());
  if (o.has("rotate")) {
    const Obj rot(r, o.at("rotate"), o.key("rotate"), {"axis", "deg"});
    k.axis = rot.axis("axis");
    k.angle = radians(rot.number("deg"));
  }
  k.linear = o.one_of_or_first("ease", {"smooth", "linear"}) == "linear";
  return k;
}

Oscillator read_oscillator(const Reader& r, const json& j, const std::string& path) {
  const Obj o(r, j, path,
              {"kind", "axis", "amplitude_deg", "amplitude", "frequency_hz", "start", "end", "phase_deg"});
  Oscillator osc;
  const bool rotate = o.one_of("kind", {"rotate", "translate"}) == "rotate";
  osc.kind = rotate ? Oscillator::Kind::Rotate : Oscillator::Kind::Translate;
  // The amplitude's key carries its unit, so that a file cannot say one and mean the other.
  if (rotate) o.reject({"amplitude"}, "a rotate oscillator takes amplitude_deg (degrees)");
  else o.reject({"amplitude_deg"}, "a translate oscillator takes amplitude (metres)");
  osc.axis = o.axis("axis");
  osc.amplitude = rotate ? radians(o.number("amplitude_deg")) : o.number("amplitude");
  osc.frequency_hz = o.number("frequency_hz");
  check_positive(r, o.key("frequency_hz"), osc.frequency_hz);
  osc.start = o.number("start");
  check_min(r, o.key("start"), osc.start, 0.0);
  osc.end = o.number("end");
  if (osc.end < osc.start)
    r.fail(o.key("end"), "must be >= start (" + num_text(osc.start) + "), got " + num_text(osc.end));
  osc.phase = radians(o.number_or("phase_deg", 0.0));
  return osc;
}

// Keyframe times must increase strictly: equal times would make a segment of zero length.
template <typename Key>
void check_increasing(const Reader& r, const std::vector<Key>& keys, const std::string& path) {
  for (std::size_t i = 1; i < keys.size(); ++i)
    if (!(keys[i].t > keys[i - 1].t))
      r.fail(join_index(path, i) + ".t", "key times must increase strictly (previous key has t = " +
                                             num_text(keys[i - 1].t) + ")");
}

void read_head(const Obj& top, Scenario& sc, bool& head_radius_fit) {
  if (!top.has("head")) return;
  const Reader& r = top.reader();
  const Obj o(r, top.at("head"), top.key("head"), {"radius", "keys", "oscillators"});
  // "fit": the sphere through an imported groom's roots (read_imported_groom sets it).
  head_radius_fit = o.has("radius") && o.at("radius").is_string();
  if (head_radius_fit) {
    o.one_of("radius", {"fit"});
  } else {
    const double radius = o.number_or("radius", sc.head_radius);
    // Anything over a metre is surely a unit mistake (centimetres for metres).
    check_positive(r, o.key("radius"), radius, 1.0);
    sc.head_radius = static_cast<float>(radius);
  }
  for_each_element(o, "keys", [&](const json& j, const std::string& path) {
    sc.head.keys.push_back(read_head_key(r, j, path));
  });
  check_increasing(r, sc.head.keys, o.key("keys"));
  for_each_element(o, "oscillators", [&](const json& j, const std::string& path) {
    sc.head.oscillators.push_back(read_oscillator(r, j, path));
  });
}

// Seeds are any unsigned 64-bit integer.
std::uint64_t as_seed(const Reader& r, const json& j, const std::string& path) {
  if (j.is_number_unsigned()) return j.get<std::uint64_t>();
  r.fail(path, "must be a non-negative integer, got " + std::to_string(as_integer(r, j, path)));
}

// An imported TressFX asset in the head rest frame (metres, the pivot at the origin).
struct ImportedGroom {
  Groom groom;  // the full groom
  std::vector<std::map<std::string, double>> region_params;
  std::vector<Sphere> colliders;  // the project's collision spheres, head-attached
  std::optional<tfx::FollowHairs> follow;  // set when follow hairs are rebuilt from guides
  Groom guides;                            // the simulated guides when `follow` is set
  GroomImport info;
};

// The guide strands of an asset groom: its first follow.guide_offsets.size() - 1 strands
// (load_tfx_project puts the follow strands after them), with the asset's regions.
Groom guide_groom(const Groom& full, const tfx::FollowHairs& follow) {
  Groom g;
  g.strand_offsets = follow.guide_offsets;
  g.positions.assign(full.positions.begin(), full.positions.begin() + follow.guide_offsets.back());
  g.strand_region.assign(full.strand_region.begin(),
                         full.strand_region.begin() + static_cast<std::ptrdiff_t>(g.strand_count()));
  g.region_names = full.region_names;
  g.head_radius = full.head_radius;
  return g;
}

void translate(Groom& g, const Vec3f& by) {
  for (Vec4f& p : g.positions) p.head<3>() += by;
}

// groom: { "tfx": ... } / { "tfx_project": ... }: an imported TressFX asset instead of a
// generated groom (paths relative to the scenario file).
ImportedGroom read_imported_groom(const Obj& g, float head_radius, bool head_radius_fit) {
  const Reader& r = g.reader();
  const bool project = g.has("tfx_project");
  if (project && g.has("tfx")) r.fail(g.key("tfx"), "give either tfx or tfx_project, not both");
  const std::string_view key = project ? "tfx_project" : "tfx";
  // A bare .tfx file has no follow hairs: their keys would silently do nothing.
  if (!project) g.reject({"follow_hairs", "seed"}, "applies to tfx_project only (a .tfx file has no follow hairs)");

  GroomImport info;
  // TressFX's sample assets are authored in centimetres; "auto" reads the unit from the
  // groom's size (guess_unit).
  info.unit = g.one_of_or_first("unit", {"cm", "mm", "m", "auto"});
  info.degenerate = g.one_of_or_first("degenerate", {"repair", "refuse"});
  const bool simulate_follow = g.one_of_or_first("follow_hairs", {"follow", "simulate"}) == "simulate";
  const std::uint64_t seed = g.has("seed") ? as_seed(r, g.at("seed"), g.key("seed")) : 1;
  // Strands shorter than this (metres) move rigidly with the head (tfx::load_tfx_asset).
  const double rigid_below = g.number_or("rigid_strands_below", 0.0);
  check_range(r, g.key("rigid_strands_below"), rigid_below, 0.0, 1.0);
  // The pivot is the head centre: the head rest frame's origin, about which it turns;
  // "fit": the centre of the sphere through the roots.
  const bool pivot_fit = g.has("pivot") && g.at("pivot").is_string();
  if (pivot_fit) g.one_of("pivot", {"fit"});
  // Only the roots higher than this (file units) are fitted.
  std::optional<double> fit_above;
  if (g.has("fit_above")) fit_above = g.number("fit_above");

  const fs::path file = (fs::path(r.file()).parent_path() / g.string(key)).lexically_normal();
  std::error_code ec;
  if (!fs::is_regular_file(file, ec)) throw InputError(r.file(), g.key(key), "no such file: " + file.string());
  info.file = file;

  tfx::TfxAsset asset;
  try {
    if (info.unit == "auto") {
      const Groom raw = tfx::read_tfx_strands(file);
      const auto start = std::chrono::steady_clock::now();
      const UnitGuess guess = guess_unit(raw, fit_head(raw, fit_above), file.string());
      info.seconds_fit += seconds_since(start);
      info.unit = guess.unit;
      info.unit_from = guess.why;
    } else {
      info.unit_from = "given";
    }
    const tfx::ImportOptions opt{metres_per_unit(info.unit),
                                 info.degenerate == "refuse" ? DegeneratePolicy::Refuse : DegeneratePolicy::Repair,
                                 rigid_below};
    asset = project ? tfx::load_tfx_project(file, opt, seed) : tfx::load_tfx_asset(file, opt);
  } catch (const InputError& e) {
    // The asset loader names the asset file and the place; say which scenario asked.
    throw InputError(r.file() + ": " + g.key(key) + ": " + e.what());
  }
  const float mpu = metres_per_unit(info.unit);
  info.repairs = std::move(asset.repairs);

  // The sphere through the guides' roots, in metres (follow hairs are offset from them).
  if (pivot_fit || head_radius_fit) {
    const auto start = std::chrono::steady_clock::now();
    info.fit = fit_head(asset.follow.empty() ? asset.groom : guide_groom(asset.groom, asset.follow),
                        fit_above ? std::optional<double>(*fit_above * mpu) : std::nullopt, {1.0f});
    info.fitted = true;
    info.seconds_fit += seconds_since(start);
  }
  info.head_radius_fit = head_radius_fit;
  Vec3f pivot = Vec3f::Zero();
  if (pivot_fit) {
    pivot = info.fit.center;
    info.pivot_from = "fit";
  } else if (g.has("pivot")) {
    pivot = g.vec3("pivot") * mpu;
    info.pivot_from = "given";
  } else {
    // Without one, a project's first collision sphere (TressFX's head sphere) is the centre.
    if (asset.colliders.empty())
      r.fail(g.key("pivot"), std::string("missing required key (the head centre in asset units, or \"fit\"; ") +
                                 (project ? "the project has no collision sphere" : "a .tfx file has no head") + ")");
    pivot = asset.colliders.front().center;
    info.pivot_from = "collision sphere";
  }
  info.pivot = pivot / mpu;
  translate(asset.groom, -pivot);
  for (Sphere& s : asset.colliders) s.center -= pivot;
  if (head_radius_fit) {
    // A scalp-shaped sphere no head has: the unit is wrong, or the fit found another surface.
    if (info.fit.scalp && !(info.fit.radius >= kHeadRadiusMin && info.fit.radius < kHeadRadiusMax))
      r.fail("head.radius",
             "the roots fit a scalp-shaped sphere of radius " + num_text(info.fit.radius) + " m, outside a head's [" +
                 num_text(kHeadRadiusMin) + ", " + num_text(kHeadRadiusMax) + ") m, with the unit " + info.unit + " (" +
                 (info.unit_from == "given" ? "given" : "guessed") +
                 "); give the unit (--unit, \"unit\"), fit on the scalp's roots (--fit-above, \"fit_above\") or give "
                 "head.radius and the pivot");
    if (!(info.fit.radius > 0.0f && info.fit.radius <= 1.0f))
      r.fail("head.radius", "the fitted head radius is " + num_text(info.fit.radius) +
                                " m, outside (0, 1] (check the groom's unit)");
    head_radius = info.fit.radius;
  }
  asset.groom.head_radius = head_radius;

  ImportedGroom out;
  out.region_params = std::move(asset.region_params);
  out.colliders = std::move(asset.colliders);
  if (!asset.follow.empty() && !simulate_follow) {
    out.guides = guide_groom(asset.groom, asset.follow);
    out.follow = std::move(asset.follow);
  }
  out.groom = std::move(asset.groom);
  out.info = std::move(info);
  return out;
}

GroomSpec read_groom_spec(const Reader& r, const json& j, const std::string& path) {
  const Obj o(r, j, path,
              {"style", "strands", "vertices_per_strand", "vertices", "length", "seed", "wave_amplitude", "wave_length",
               "curl_radius", "curl_pitch"});
  const auto styles = groom_styles();
  GroomSpec spec;
  spec.style = o.one_of("style", Obj::Keys(styles.begin(), styles.end()));
  // Shape knobs are accepted only for the style they shape: a wave_length on a curly
  // groom is a mistake, not something to ignore.
  if (spec.style != "wavy") o.reject({"wave_amplitude", "wave_length"}, "applies to style wavy only");
  if (spec.style != "curly") o.reject({"curl_radius", "curl_pitch"}, "applies to style curly only");
  spec.strands = static_cast<int>(o.integer("strands", 1, kMaxGroomStrands));
  // Either vertices per strand or the groom's total (strands then differ by at most one).
  if (o.has("vertices") == o.has("vertices_per_strand"))
    r.fail(o.key("vertices_per_strand"), "give exactly one of vertices_per_strand and vertices");
  if (o.has("vertices"))
    spec.total_vertices = o.integer("vertices", 2 * std::int64_t{spec.strands},
                                    std::int64_t{kMaxStrandVertices} * spec.strands);
  else
    spec.vertices_per_strand = static_cast<int>(o.integer("vertices_per_strand", 2, kMaxStrandVertices));
  spec.length = o.number("length");
  spec.seed = as_seed(r, o.at("seed"), o.key("seed"));
  spec.wave_amplitude = o.number_or("wave_amplitude", spec.wave_amplitude);
  spec.wave_length = o.number_or("wave_length", spec.wave_length);
  spec.curl_radius = o.number_or("curl_radius", spec.curl_radius);
  spec.curl_pitch = o.number_or("curl_pitch", spec.curl_pitch);
  return spec;
}

// Returns the colliders that come with an imported groom (the caller appends them to
// the file's own).
std::vector<Sphere> read_groom(const Obj& top, Scenario& sc, bool head_radius_fit) {
  const Reader& r = top.reader();
  const json& j = top.at("groom");
  const std::string path = top.key("groom");
  if (as_object(r, j, path).contains("tfx") || j.contains("tfx_project")) {
    ImportedGroom imported = read_imported_groom(Obj(r, j, path,
                                                     {"tfx", "tfx_project", "unit", "pivot", "follow_hairs", "seed",
                                                      "rigid_strands_below", "degenerate", "fit_above"}),
                                                 sc.head_radius, head_radius_fit);
    sc.groom = std::move(imported.groom);
    sc.head_radius = sc.groom.head_radius;
    sc.region_params = std::move(imported.region_params);
    sc.follow = std::move(imported.follow);
    sc.guides = std::move(imported.guides);
    sc.import = std::move(imported.info);
    return std::move(imported.colliders);
  }
  if (head_radius_fit) r.fail("head.radius", "\"fit\" applies to an imported groom (tfx or tfx_project) only");
  GeneratedGroom generated = generate_groom(read_groom_spec(r, j, path), sc.head_radius, r.file());
  sc.groom = std::move(generated.groom);
  sc.region_params = std::move(generated.region_params);
  return {};
}

// "radius": "fit" is the head radius, shrunk until no rest vertex of the groom, pinned or
// free, lies inside (the sphere the fitted head stands for, without flinging hair out or
// stretching a root's edge at frame 0; tfx::fit_spheres_to_rest_hair).
Sphere read_collider(const Reader& r, const json& j, const std::string& path, Scenario& sc) {
  const Obj o(r, j, path, {"type", "center", "radius", "attached"});
  o.one_of("type", {"sphere"});
  Sphere s;
  s.center = o.vec3("center");
  if (o.has("radius") && o.at("radius").is_string()) {
    o.one_of("radius", {"fit"});
    std::vector<Sphere> one{{s.center, sc.head_radius, true}};
    const auto start = std::chrono::steady_clock::now();
    tfx::fit_spheres_to_rest_hair(one, sc.groom, true);
    if (sc.import) sc.import->seconds_fit += seconds_since(start);
    if (!(one[0].radius > 0.0f)) r.fail(o.key("radius"), "a rest vertex lies at the centre: no sphere fits");
    s.radius = one[0].radius;
  } else {
    const double radius = o.number("radius");
    check_positive(r, o.key("radius"), radius);
    s.radius = static_cast<float>(radius);
  }
  s.head_attached = o.one_of_or_first("attached", {"head", "world"}) == "head";
  return s;
}

WindScript::Key read_wind_key(const Reader& r, const json& j, const std::string& path) {
  const Obj o(r, j, path, {"t", "strength"});
  return {o.number("t"), o.number("strength")};
}

void read_wind(const Obj& top, Scenario& sc) {
  if (!top.has("wind")) return;
  const Reader& r = top.reader();
  const Obj o(r, top.at("wind"), top.key("wind"), {"direction", "strength", "keys"});
  if (o.has("direction")) sc.wind.direction = o.axis("direction");
  // Keys replace the constant strength; both at once would leave one of them unused.
  if (o.has("strength") && o.has("keys"))
    r.fail(o.key("keys"), "give either a constant strength or keys, not both");
  sc.wind.strength = o.number_or("strength", 0.0);
  for_each_element(o, "keys", [&](const json& j, const std::string& path) {
    sc.wind.keys.push_back(read_wind_key(r, j, path));
  });
  check_increasing(r, sc.wind.keys, o.key("keys"));
}

// "truth": the kick of a truth scenario, checked against what the chain's exact answer
// assumes (docs/truth.md): a still head, nothing but gravity acting, and strands that
// hang straight along gravity with every vertex past the pinned ones free.
void read_truth(const Obj& top, Scenario& sc) {
  if (!top.has("truth")) return;
  const Reader& r = top.reader();
  const Obj o(r, top.at("truth"), top.key("truth"), {"modes", "amplitude", "direction"});
  TruthKick t;
  for_each_element(o, "modes", [&](const json& j, const std::string& path) {
    const std::int64_t m = as_integer(r, j, path);
    if (m < 1 || m > 64) r.fail(path, "must be in [1, 64], got " + std::to_string(m));
    t.modes.push_back(static_cast<int>(m));
  });
  if (t.modes.empty()) r.fail(o.key("modes"), "must list at least one mode");
  t.amplitude = o.number_or("amplitude", t.amplitude);
  if (!(t.amplitude > 0.0 && t.amplitude <= 0.05)) r.fail(o.key("amplitude"), "must be in (0, 0.05], got " + num_text(t.amplitude));
  if (o.has("direction")) t.direction = o.axis("direction");
  const Vec3f down = sc.gravity.normalized();
  if (!(sc.gravity.norm() > 0.0f)) r.fail(top.key("gravity"), "a truth scenario needs gravity");
  if (std::abs(t.direction.dot(down)) > 1e-6f) r.fail(o.key("direction"), "must be horizontal (perpendicular to gravity)");
  if (!sc.head.keys.empty() || !sc.head.oscillators.empty())
    r.fail(top.key("head"), "a truth scenario's head holds still (no keys or oscillators)");
  if (!sc.colliders.empty()) r.fail(top.key("colliders"), "a truth scenario has no colliders");
  if (sc.wind.ever_active()) r.fail(top.key("wind"), "a truth scenario has no wind");
  if (sc.follow) r.fail(top.key("groom"), "a truth scenario's strands are simulated whole (no follow hairs)");
  const Groom& g = sc.groom;
  for (std::size_t s = 0; s < g.strand_count(); ++s) {
    const std::string field = "groom: strand " + std::to_string(s);
    const Vec4f* p = g.positions.data() + g.strand_begin(s);
    const std::size_t n = g.strand_size(s);
    std::size_t pinned = 0;
    while (pinned < n && p[pinned].w() == 0.0f) ++pinned;
    const std::size_t mode = static_cast<std::size_t>(t.modes[s % t.modes.size()]);
    if (n - pinned < mode)
      r.fail(field, "has " + std::to_string(n - pinned) + " free vertices, too few for mode " + std::to_string(mode));
    const Vec3f pivot = p[pinned - 1].head<3>();
    for (std::size_t i = pinned; i < n; ++i) {
      const Vec3f d = p[i].head<3>() - pivot;
      if (p[i].w() == 0.0f) r.fail(field, "vertex " + std::to_string(i) + " is pinned past the root: not a hanging chain");
      if ((d - d.dot(down) * down).norm() > 1e-5f * (d.norm() + 1e-6f) || d.dot(down) <= 0.0f)
        r.fail(field, "vertex " + std::to_string(i) + " is not straight below the last pinned vertex along gravity");
    }
  }
  sc.truth = std::move(t);
}

// "regions": { region: { name: number } }, for regions the groom has.
std::map<std::string, std::map<std::string, double>> read_region_overrides(
    const Reader& r, const json& j, const std::string& path, const Groom& groom) {
  std::map<std::string, std::map<std::string, double>> out;
  const auto& names = groom.region_names;
  for (const auto& [region, params] : as_object(r, j, path).items()) {
    const std::string region_key = join_key(path, region);
    if (std::find(names.begin(), names.end(), region) == names.end())
      r.fail(region_key, "no region '" + printable(region) + "' in the groom (it has: " + list_text(names) + ")");
    for (const auto& [name, value] : as_object(r, params, region_key).items())
      out[region][name] = as_number(r, value, join_key(region_key, name));
  }
  return out;
}

// { name: number, ... } with an optional "regions" object. Model and parameter names are
// checked by the harness, which knows the model registry.
ParamOverrides read_overrides(const Reader& r, const json& j, const std::string& path,
                              const Groom& groom) {
  ParamOverrides out;
  for (const auto& [name, value] : as_object(r, j, path).items()) {
    if (name == "regions")
      out.regions = read_region_overrides(r, value, join_key(path, name), groom);
    else if (name == "substeps" && value.is_string())
      out.substeps_auto = value == "auto" || (r.fail(join_key(path, name), "expected a number or \"auto\""), false);
    else
      out.base[name] = as_number(r, value, join_key(path, name));
  }
  return out;
}

void read_models(const Obj& top, Scenario& sc) {
  if (!top.has("models")) return;
  const Reader& r = top.reader();
  for (const auto& [model, overrides] : as_object(r, top.at("models"), top.key("models")).items())
    sc.models[model] = read_overrides(r, overrides, join_key(top.key("models"), model), sc.groom);
}

}  // namespace

// ---------------------------------------------------------------------------------------

Wind WindScript::at(double t) const {
  Wind w;
  w.direction = direction;
  if (keys.empty()) {
    w.strength = static_cast<float>(strength);
    return w;
  }
  // Piecewise linear between keys, held before the first and after the last.
  double s = keys.front().strength;
  if (t >= keys.back().t) {
    s = keys.back().strength;
  } else if (t > keys.front().t) {
    const auto b = std::upper_bound(keys.begin(), keys.end(), t,
                                    [](double v, const Key& k) { return v < k.t; });
    const Key& a = *(b - 1);
    s = a.strength + (t - a.t) / (b->t - a.t) * (b->strength - a.strength);
  }
  w.strength = static_cast<float>(s);
  return w;
}

bool WindScript::ever_active() const {
  if (keys.empty()) return strength != 0.0;
  return std::any_of(keys.begin(), keys.end(), [](const Key& k) { return k.strength != 0.0; });
}

namespace {

Scenario load_scenario_doc(const Reader& r, const json& doc, const fs::path& file) {
  const Obj top(r, doc, "",
                {"name", "description", "frames", "dt", "gravity", "groom", "head", "colliders", "wind",
                 "settle_from", "reference", "models", "truth"});
  Scenario sc;
  sc.source = file;
  sc.name = top.string_or("name", file.stem().string());
  if (sc.name.empty()) r.fail(top.key("name"), "must not be empty");
  sc.description = top.string_or("description", "");
  sc.frames = static_cast<int>(top.integer("frames", 1, kMaxFrames));
  sc.dt = top.number("dt");
  check_positive(r, top.key("dt"), sc.dt, 1.0);
  sc.gravity = top.vec3_or("gravity", sc.gravity);
  bool head_radius_fit = false;
  read_head(top, sc, head_radius_fit);  // before the groom: the head radius is the scalp radius
  const std::vector<Sphere> asset_colliders = read_groom(top, sc, head_radius_fit);
  for_each_element(top, "colliders", [&](const json& j, const std::string& path) {
    sc.colliders.push_back(read_collider(r, j, path, sc));
  });
  sc.colliders.insert(sc.colliders.end(), asset_colliders.begin(), asset_colliders.end());
  read_wind(top, sc);
  sc.settle_from = top.number_or("settle_from", sc.settle_from);
  check_range(r, top.key("settle_from"), sc.settle_from, 0.0, sc.duration());
  sc.reference = top.string_or("reference", sc.reference);
  if (sc.reference.empty()) r.fail(top.key("reference"), "must not be empty");
  read_models(top, sc);
  read_truth(top, sc);
  return sc;
}

}  // namespace

Scenario load_scenario(const fs::path& file) {
  const Reader r(file.string());
  return load_scenario_doc(r, parse_file(r, read_text(r, file)), file);
}

Scenario load_scenario_text(const std::string& text, const fs::path& file) {
  const Reader r(file.string());
  return load_scenario_doc(r, parse_file(r, text), file);
}

fs::path builtin_scenario_dir() {
  const char* env = std::getenv("HAIRBENCH_SCENARIO_DIR");
  return env != nullptr && *env != '\0' ? fs::path(env) : fs::path(HAIRBENCH_BUILTIN_SCENARIO_DIR);
}

std::vector<fs::path> builtin_scenarios() {
  const fs::path dir = builtin_scenario_dir();
  std::error_code ec;
  if (!fs::is_directory(dir, ec))
    throw InputError(dir.string(), "HAIRBENCH_SCENARIO_DIR", "not a directory of scenario files");
  std::vector<fs::path> files;
  for (const fs::directory_entry& e : fs::directory_iterator(dir))
    if (e.is_regular_file() && e.path().extension() == ".json") files.push_back(e.path());
  std::sort(files.begin(), files.end());
  return files;
}

std::vector<Scenario> load_builtin_scenarios() {
  std::vector<Scenario> out;
  for (const fs::path& file : builtin_scenarios()) out.push_back(load_scenario(file));
  return out;
}

fs::path find_scenario(const std::string& name_or_path) {
  std::error_code ec;
  if (fs::is_regular_file(name_or_path, ec)) return name_or_path;
  const fs::path builtin = builtin_scenario_dir() / (name_or_path + ".json");
  if (fs::is_regular_file(builtin, ec)) return builtin;
  throw InputError(name_or_path, "scenario",
                   "no such scenario file or built-in scenario (see `hairbench list scenarios`)");
}

}  // namespace hairbench
