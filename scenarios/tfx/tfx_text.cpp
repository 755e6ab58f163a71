// .tfxsim and .tfxproj readers. Both formats are one "key value..." per line with '#'
// comments (scenarios/assets/tressfx/README.md and the shipped files); the sample files
// have trailing blanks and no final newline, so tokens are split on any whitespace and
// a '\r' of Windows line ends is whitespace too.
#include "scenarios/tfx/tfx.h"

#include "core/error.h"

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <fstream>
#include <limits>
#include <sstream>
#include <utility>

namespace hairbench::tfx {
namespace {

// A token as it appears in a message: at most 40 characters, anything unprintable as
// \xNN, so that a binary or garbled file still gives one readable line.
std::string shown(std::string_view token) {
  constexpr std::size_t kMax = 40;
  static constexpr char kHex[] = "0123456789abcdef";
  std::string out;
  for (const char c : token.substr(0, kMax)) {
    const auto u = static_cast<unsigned char>(c);
    if (u >= 0x20 && u < 0x7f) {
      out += c;
    } else {
      out += "\\x";
      out += kHex[u >> 4];
      out += kHex[u & 0xf];
    }
  }
  if (token.size() > kMax) out += "...";
  return out;
}

struct Line {
  std::size_t number = 0;  // 1-based
  std::vector<std::string_view> tokens;
};

bool is_blank(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f'; }

// Tokens of one line; a token that starts with '#' comments out the rest of the line.
std::vector<std::string_view> split(std::string_view line) {
  std::vector<std::string_view> tokens;
  std::size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && is_blank(line[i])) ++i;
    if (i == line.size() || line[i] == '#') break;
    const std::size_t start = i;
    while (i < line.size() && !is_blank(line[i])) ++i;
    tokens.push_back(line.substr(start, i - start));
  }
  return tokens;
}

// The non-empty lines of `text`.
std::vector<Line> lines_of(std::string_view text) {
  std::vector<Line> lines;
  std::size_t number = 1;
  while (!text.empty()) {
    const std::size_t end = std::min(text.find('\n'), text.size());
    std::vector<std::string_view> tokens = split(text.substr(0, end));
    if (!tokens.empty()) lines.push_back({number, std::move(tokens)});
    text.remove_prefix(std::min(end + 1, text.size()));
    ++number;
  }
  return lines;
}

char ascii_lower(char c) { return c >= 'A' && c <= 'Z' ? static_cast<char>(c - 'A' + 'a') : c; }

// File names in the samples come from Windows tools: extensions compare case-blind.
bool ends_with_ci(std::string_view s, std::string_view suffix) {
  if (s.size() < suffix.size()) return false;
  const std::string_view tail = s.substr(s.size() - suffix.size());
  return std::equal(tail.begin(), tail.end(), suffix.begin(),
                    [](char a, char b) { return ascii_lower(a) == ascii_lower(b); });
}

// Reports problems as "FILE: line N: what" and reads the values of a line.
class Reader {
 public:
  explicit Reader(const std::string& name) : name_(name) {}

  [[noreturn]] void fail(const Line& line, const std::string& what) const {
    throw InputError(name_, "line " + std::to_string(line.number), what);
  }

  // Checks that the line is its key and exactly `values` values.
  void expect_values(const Line& line, std::size_t values) const {
    const std::string key = shown(line.tokens[0]);
    if (line.tokens.size() < values + 1)
      fail(line, key + ": missing value (expected " + std::to_string(values) + ")");
    if (line.tokens.size() > values + 1)
      fail(line, key + ": extra value '" + shown(line.tokens[values + 1]) + "'");
  }

  // Token `index` of the line as a finite number.
  double number(const Line& line, std::size_t index) const {
    const std::string key = shown(line.tokens[0]);
    const std::string_view token = line.tokens[index];
    double value = 0.0;
    const auto [end, ec] = std::from_chars(token.data(), token.data() + token.size(), value);
    if (ec == std::errc::result_out_of_range)
      fail(line, key + ": '" + shown(token) + "' is out of range");
    if (ec != std::errc() || end != token.data() + token.size())
      fail(line, key + ": '" + shown(token) + "' is not a number");
    if (!std::isfinite(value)) fail(line, key + ": '" + shown(token) + "' is not finite");
    return value;
  }

  // Token `index` as a whole number in [0, max].
  double count(const Line& line, std::size_t index, double max) const {
    const double value = number(line, index);
    if (value < 0.0 || value != std::floor(value) || value > max) {
      std::ostringstream os;
      os << shown(line.tokens[0]) << ": '" << shown(line.tokens[index])
         << "' is not a whole number in [0, " << max << "]";
      fail(line, os.str());
    }
    return value;
  }

  // A line "version V": TressFX 3.x and 4.x files are understood.
  void version(const Line& line, bool& seen) const {
    expect_values(line, 1);
    once(line, seen);
    const double v = number(line, 1);
    if (v < 3.0 || v >= 5.0)
      fail(line, "version: '" + shown(line.tokens[1]) + "' is not supported (expected 3.x or 4.x)");
  }

  void once(const Line& line, bool& seen) const {
    if (seen) fail(line, shown(line.tokens[0]) + ": given twice");
    seen = true;
  }

 private:
  const std::string& name_;
};

// Iteration counts are the only values that must be whole: the ranges of the others are
// each model's business (its settings.h, enforced by ParamSet). The bound keeps the
// counts far inside int.
constexpr double kMaxIterations = 1000.0;

// TressFX key -> hairbench parameter name (docs/scenarios.md).
struct KeyName {
  std::string_view tressfx;
  std::string_view hairbench;
  bool iterations;
};
constexpr std::array<KeyName, 6> kSimKeys{{
    {"damping", "damping", false},
    {"stiffnessForLocalShapeMatching", "local_stiffness", false},
    {"stiffnessForGlobalShapeMatching", "global_stiffness", false},
    {"globalShapeMatchingEffectiveRange", "global_range", false},
    {"lengthConstraintIterations", "length_iterations", true},
    {"localShapeMatchingIterations", "local_iterations", true},
}};

const KeyName* find_key(std::string_view key, std::span<const KeyName> keys) {
  const auto it =
      std::find_if(keys.begin(), keys.end(), [&](const KeyName& k) { return k.tressfx == key; });
  return it == keys.end() ? nullptr : &*it;
}

void set_param(const Reader& in, const Line& line, const KeyName& key,
               std::map<std::string, double>& params) {
  in.expect_values(line, 1);
  const double value = key.iterations ? in.count(line, 1, kMaxIterations) : in.number(line, 1);
  if (!params.emplace(std::string(key.hairbench), value).second)
    in.fail(line, shown(line.tokens[0]) + ": given twice");
}

// A .tfxproj sets only the iteration counts; the other settings are per section.
constexpr std::array<KeyName, 2> kProjectKeys{kSimKeys[4], kSimKeys[5]};

// TressFX viewer settings a .tfxproj may carry; they do not affect simulation.
constexpr std::array<std::string_view, 7> kRenderingKeys{"hairColor", "Ka",  "Ks1",     "Ex1",
                                                         "Ks2",       "Ex2", "lightPos"};

// More follow hairs than this per guide is certainly a broken file; the bound keeps the
// groom a project can ask for proportional to its guide data.
constexpr double kMaxFollowPerGuide = 64.0;

// "file.tfx followHairsPerGuide followRadius tipSeparation file.tfxsim [sectionName]"
TfxProject::Section parse_section(const Reader& in, const Line& line) {
  const auto& t = line.tokens;
  if (t.size() < 5)
    in.fail(line, shown(t[0]) +
                      ": a section line is 'file.tfx followHairsPerGuide followRadius "
                      "tipSeparation file.tfxsim [sectionName]'");
  if (t.size() > 6) in.fail(line, shown(t[0]) + ": extra value '" + shown(t[6]) + "'");
  TfxProject::Section s;
  s.tfx_file = t[0];
  s.follow_per_guide = static_cast<int>(in.count(line, 1, kMaxFollowPerGuide));
  s.follow_radius = in.number(line, 2);
  s.tip_separation = in.number(line, 3);
  if (s.follow_radius < 0.0) in.fail(line, shown(t[0]) + ": negative follow radius");
  if (s.tip_separation < 0.0) in.fail(line, shown(t[0]) + ": negative tip separation");
  if (!ends_with_ci(t[4], ".tfxsim"))
    in.fail(line, shown(t[0]) + ": '" + shown(t[4]) + "' is not a .tfxsim file");
  s.sim_file = t[4];
  s.name = t.size() == 6 ? std::string(t[5]) : std::filesystem::path(s.tfx_file).stem().string();
  return s;
}

// Sphere values are stored as float; a double beyond float range cannot be converted
// (the conversion is undefined behaviour), so it is an error here.
float float_value(const Reader& in, const Line& line, std::size_t index) {
  const double v = in.number(line, index);
  if (std::abs(v) > std::numeric_limits<float>::max())
    in.fail(line, shown(line.tokens[0]) + ": value out of float range");
  return static_cast<float>(v);
}

Sphere parse_sphere(const Reader& in, const Line& line) {
  in.expect_values(line, 4);
  Sphere sphere;
  sphere.center =
      Vec3f(float_value(in, line, 1), float_value(in, line, 2), float_value(in, line, 3));
  sphere.radius = float_value(in, line, 4);
  if (!(sphere.radius > 0.0f)) in.fail(line, "collision_sphere: radius must be positive");
  sphere.head_attached = true;
  return sphere;
}

void add_section(const Reader& in, const Line& line, TfxProject& p) {
  TfxProject::Section s = parse_section(in, line);
  for (const TfxProject::Section& other : p.sections)
    if (other.name == s.name)
      in.fail(line,
              "section name '" + shown(s.name) + "' is used twice (regions need distinct names)");
  p.sections.push_back(std::move(s));
}

// One project line; returns false for a key it does not know.
bool parse_project_line(const Reader& in, const Line& line, TfxProject& p, bool& version_seen,
                        bool& name_seen) {
  const std::string_view key = line.tokens[0];
  if (ends_with_ci(key, ".tfx")) {
    add_section(in, line, p);
  } else if (ends_with_ci(key, ".sdkmesh")) {
    in.expect_values(line, 0);  // the head mesh: not used by hairbench
  } else if (key == "version") {
    in.version(line, version_seen);
  } else if (key == "project_name") {
    if (line.tokens.size() < 2) in.fail(line, "project_name: missing value");
    in.once(line, name_seen);
    for (std::size_t i = 1; i < line.tokens.size(); ++i) {
      if (i > 1) p.project_name += ' ';
      p.project_name += line.tokens[i];
    }
  } else if (const KeyName* k = find_key(key, kProjectKeys)) {
    set_param(in, line, *k, p.params);
  } else if (key == "collision_sphere") {
    p.spheres.push_back(parse_sphere(in, line));
  } else {
    // Rendering keys are accepted without looking at their values: TressFX files carry
    // C-style literals there ("lightPos -421.25043f ..." in the ponytail sample).
    return std::find(kRenderingKeys.begin(), kRenderingKeys.end(), key) != kRenderingKeys.end();
  }
  return true;
}

std::string read_text(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw InputError(file.string(), "file", "cannot be opened");
  std::ostringstream os;
  os << in.rdbuf();
  if (in.bad()) throw InputError(file.string(), "file", "read error");
  return os.str();
}

}  // namespace

SimSettings parse_tfxsim(std::string_view text, const std::string& name) {
  const Reader in(name);
  SimSettings out;
  bool version_seen = false;
  for (const Line& line : lines_of(text)) {
    if (line.tokens[0] == "version") {
      in.version(line, version_seen);
    } else if (const KeyName* k = find_key(line.tokens[0], kSimKeys)) {
      set_param(in, line, *k, out.params);
    } else {
      in.fail(line, "unknown key '" + shown(line.tokens[0]) + "'");
    }
  }
  return out;
}

SimSettings read_tfxsim(const std::filesystem::path& file) {
  return parse_tfxsim(read_text(file), file.string());
}

TfxProject parse_tfxproj(std::string_view text, const std::string& name) {
  const Reader in(name);
  TfxProject out;
  bool version_seen = false, name_seen = false;
  for (const Line& line : lines_of(text))
    if (!parse_project_line(in, line, out, version_seen, name_seen))
      in.fail(line, "unknown key '" + shown(line.tokens[0]) + "'");
  if (out.sections.empty())
    throw InputError(name, "sections",
                     "no hair section (a line 'file.tfx followHairsPerGuide followRadius "
                     "tipSeparation file.tfxsim [sectionName]')");
  return out;
}

TfxProject read_tfxproj(const std::filesystem::path& file) {
  return parse_tfxproj(read_text(file), file.string());
}

}  // namespace hairbench::tfx
