#include "scenarios/groom_gen.h"

#include "core/error.h"
#include "core/rng.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <iomanip>
#include <limits>
#include <numbers>
#include <optional>
#include <sstream>

namespace hairbench {

namespace {

using Vec3d = Eigen::Vector3d;
constexpr double kPi = std::numbers::pi;

// In the order of enum Style.
constexpr std::array<std::string_view, 5> kStyles{"straight", "wavy", "curly", "ponytail", "hanging"};
enum class Style { Straight, Wavy, Curly, Ponytail, Hanging };

constexpr double kMaxLength = 100.0;  // metres

// Geometry of the generated hair, in units of the head radius r unless said otherwise.
constexpr double kLowestRoot = 0.1;   // roots cover the scalp cap y >= 0.1 r
constexpr double kRootJitter = 0.35;  // root jitter, as a fraction of the mean root spacing
constexpr double kMargin = 0.02;      // strands stay at least 2% of r above the scalp
constexpr double kFallOutward = 0.2;  // hair falls slightly away from the head, not flat on it
// Metres of strand over which a strand turns towards its comb direction: hair leaves
// the scalp along the normal and lies down within a centimetre or two.
constexpr double kCombLength = 0.012;
// Ponytail tail strands turn more tightly still: into the tie and down from it.
constexpr double kTieLength = 0.005;

// libm's sin and cos may differ in the last bit between library versions and between
// the FMA and non-FMA code paths glibc picks at run time. The groom must be
// bit-identical on every machine, so the generator uses its own: reduction to
// [-pi/2, pi/2] and a Taylor polynomial, built from +, -, * only (and the project
// compiles with -ffp-contract=off, so no fused multiply-adds change the rounding).
double det_sin(double x) {
  x -= 2.0 * kPi * std::nearbyint(x / (2.0 * kPi));
  if (x > kPi / 2) x = kPi - x;
  if (x < -kPi / 2) x = -kPi - x;
  const double x2 = x * x;
  // Terms up to x^19/19! leave an error below 1e-13 on [-pi/2, pi/2].
  double sum = -1.0 / 121645100408832000.0;
  for (double d : {355687428096000.0, -1307674368000.0, 6227020800.0, -39916800.0, 362880.0,
                   -5040.0, 120.0, -6.0, 1.0})
    sum = sum * x2 + 1.0 / d;
  return x * sum;
}

double det_cos(double x) { return det_sin(x + kPi / 2); }

// The unit vector perpendicular to `axis` closest to `ref` (some perpendicular when ref
// is parallel to axis).
Vec3d perpendicular(const Vec3d& ref, const Vec3d& axis) {
  const Vec3d p = ref - ref.dot(axis) * axis;
  return p.norm() > 1e-9 ? Vec3d(p.normalized()) : Vec3d(axis.unitOrthogonal());
}

struct Root {
  Vec3d normal;  // unit outward scalp normal; the root sits at r * normal
  Vec3d east;    // unit scalp tangent: the plane of a wave, the reference of a curl
};

// A Fibonacci lattice over the cap y >= kLowestRoot r: every root owns about the same
// scalp area, without the rows a latitude/longitude grid would show. A small jitter
// then breaks the lattice's visible spirals.
std::vector<Root> scalp_roots(int count, SplitMix64& rng) {
  const double golden_angle = kPi * (3.0 - std::sqrt(5.0));
  const double spacing = std::sqrt(2.0 * kPi * (1.0 - kLowestRoot) / count);  // unit sphere
  std::vector<Root> roots;
  roots.reserve(static_cast<std::size_t>(count));
  for (int i = 0; i < count; ++i) {
    const double y = 1.0 - (i + 0.5) / count * (1.0 - kLowestRoot);
    const double ring = std::sqrt(1.0 - y * y);
    const double phi = golden_angle * i;
    const Vec3d n(ring * det_cos(phi), y, ring * det_sin(phi));
    const Vec3d east(-det_sin(phi), 0.0, det_cos(phi));
    const Vec3d north = n.cross(east);
    const double du = rng.centered(), dv = rng.centered();
    Vec3d jittered = (n + kRootJitter * spacing * (du * east + dv * north)).normalized();
    if (jittered.y() < kLowestRoot) jittered = n;
    roots.push_back({jittered, perpendicular(east, jittered)});
  }
  return roots;
}

// How a strand is combed: the direction it turns to, how quickly, and for ponytail
// tail strands the tie point it is gathered to first.
struct Comb {
  std::uint16_t region = 0;
  Vec3d direction = -Vec3d::UnitY();  // unit
  double turn_length = kCombLength;
  std::optional<Vec3d> tie;
};

// Loose hair: down, and a little away from the head.
Comb loose_comb(const Root& root) {
  const Vec3d away = perpendicular(root.normal, Vec3d::UnitY());
  return {0, (kFallOutward * away - Vec3d::UnitY()).normalized(), kCombLength, std::nullopt};
}

// The three regions of Han & Harada Figure 1a/b (y up, +z towards the face): front
// strands, rooted near the forehead, fall forward; top strands are combed back over the
// crown; tail strands, rooted on the back of the head, are gathered into a tie point
// behind the head and hang from it.
enum PonytailRegion : std::uint16_t { kFront, kTop, kTail };

Comb ponytail_comb(const Root& root, double r, SplitMix64& rng) {
  if (root.normal.z() > 0.5) return {kFront, Vec3d(0.0, -1.0, 0.35).normalized(), kCombLength, {}};
  if (root.normal.z() > -0.35) return {kTop, Vec3d(0.0, -1.0, -0.8).normalized(), kCombLength, {}};
  // A tie 15% of r off the scalp at the back of the head; strands meet it within a
  // bundle of about r/10 across rather than in one point.
  const Vec3d tie = 1.15 * r * Vec3d(0.0, 0.2, -1.0).normalized();
  const Vec3d spread = 0.1 * r * Vec3d(rng.centered(), rng.centered(), 0.0);
  return {kTail, Vec3d(0.0, -1.0, -0.15).normalized(), kTieLength, tie + spread};
}

// The unmodulated growth direction after one more edge: h turned towards `target` by
// about edge/turn_length radians, the Euler step of dh/ds = (target - h) / turn_length,
// so the shape barely depends on the vertex count.
Vec3d turn_towards(const Vec3d& h, const Vec3d& target, double rate) {
  const Vec3d v = h + rate * target;
  return v.norm() > 1e-9 ? Vec3d(v.normalized()) : perpendicular(target, h);
}

// Where the strand heads next: to its tie point until it reaches it, then its comb.
Vec3d comb_target(const Comb& comb, const Vec3d& p, double edge, bool& tied) {
  if (comb.tie && !tied) {
    const Vec3d to_tie = *comb.tie - p;
    if (to_tie.norm() > edge) return to_tie.normalized();
    tied = true;
  }
  return comb.direction;
}

// The step direction of a strand whose unmodulated growth direction is h, at distance
// `axial` along h from the root: straight hair follows h; wavy hair is the derivative
// of a planar sine A sin(2 pi a / lambda + phase) in the plane of h and the root's east
// tangent; curly hair the derivative of a helix of radius R and pitch P about h, which
// gives the strand its rest curvature.
Vec3d step_direction(const GroomSpec& spec, Style style, const Vec3d& h, const Vec3d& east,
                     double axial, double phase) {
  if (style == Style::Wavy) {
    const double k = 2.0 * kPi / spec.wave_length;
    const double slope = spec.wave_amplitude * k * det_cos(k * axial + phase);
    return (h + slope * perpendicular(east, h)).normalized();
  }
  if (style == Style::Curly) {
    const double k = 2.0 * kPi / spec.curl_pitch;
    const double theta = k * axial + phase;
    const Vec3d u = perpendicular(east, h);
    const Vec3d v = h.cross(u);
    return (h + spec.curl_radius * k * (det_cos(theta) * v - det_sin(theta) * u)).normalized();
  }
  return h;
}

// A step that would end inside the keep-out sphere (scalp + margin) is turned into the
// scalp's tangent plane at p: then |p + e w|^2 = |p|^2 + e^2, so the strand slides over
// the head instead of entering it, and the edge keeps its exact rest length. The growth
// direction is flattened too, so that the comb goes on turning from where the strand
// really goes.
void keep_outside(const Vec3d& p, double edge, double keep_out, Vec3d& w, Vec3d& h) {
  if ((p + edge * w).norm() >= keep_out) return;
  const Vec3d out = p.normalized();
  // Moving outward already: only near the root, when edges are shorter than the margin.
  if (w.dot(out) >= 0.0) return;
  w = perpendicular(w, out);
  if (h.dot(out) < 0.0) h = perpendicular(h, out);
}

std::vector<Vec3f> grow_strand(const GroomSpec& spec, Style style, double r, const Root& root,
                               const Comb& comb, double phase, int n) {
  const double edge = spec.length / (n - 1);
  const double keep_out = r * (1.0 + kMargin);
  std::vector<Vec3f> points;
  points.reserve(static_cast<std::size_t>(n));
  Vec3d p = r * root.normal;
  points.push_back(p.cast<float>());
  // Vertex 1 straight out of the scalp: vertices 0 and 1 are pinned and define the
  // strand's root frame, x_0 = P_1 - P_0 (Han & Harada §3.1, §3.2).
  p += edge * root.normal;
  points.push_back(p.cast<float>());
  Vec3d h = root.normal;
  double axial = 0.0;
  bool tied = false;
  for (int i = 2; i < n; ++i) {
    h = turn_towards(h, comb_target(comb, p, edge, tied), edge / comb.turn_length);
    Vec3d w = step_direction(spec, style, h, root.east, axial, phase);
    axial += edge * w.dot(h);
    keep_outside(p, edge, keep_out, w, h);
    p += edge * w;
    points.push_back(p.cast<float>());
  }
  return points;
}

// The hanging chains of the truth scenarios (docs/truth.md): strand s rooted under the
// head at r (0, -cos a_s, sin a_s), its roots 3 cm apart along z (closer when that would
// not fit under the head), and straight down (-y) in equal edges, so that under gravity
// along -y it hangs at rest with its free vertices a chain below the pinned vertex 1.
std::vector<Vec3f> hanging_strand(const GroomSpec& spec, double r, int s, int n) {
  const double spacing = std::min(0.03, 1.6 * r / spec.strands);
  const double z = (s - 0.5 * (spec.strands - 1)) * spacing;
  const double edge = spec.length / (n - 1);
  std::vector<Vec3f> points;
  for (int i = 0; i < n; ++i) points.emplace_back(0.0f, static_cast<float>(-std::sqrt(r * r - z * z) - i * edge),
                                                  static_cast<float>(z));
  return points;
}

// Per-region defaults from the TressFX ponytail sample's .tfxsim files (damping, local
// and global stiffness, global range): front takes the stiffest set (back.tfxsim), top
// front_top.tfxsim's, tail tail.tfxsim's - a stiff front, a softer top, a loose tail.
std::vector<std::map<std::string, double>> ponytail_region_params() {
  return {
      {{"damping", 0.1}, {"local_stiffness", 0.6}, {"global_stiffness", 0.2}, {"global_range", 0.4}},
      {{"damping", 0.1}, {"local_stiffness", 0.5}, {"global_stiffness", 0.2}, {"global_range", 0.2}},
      {{"damping", 0.1}, {"local_stiffness", 0.3}, {"global_stiffness", 0.1}, {"global_range", 0.3}},
  };
}

std::string range_text(double lo, double hi, double got, bool lo_open) {
  std::ostringstream os;
  os << std::setprecision(10) << "must be in " << (lo_open ? "(" : "[") << lo << ", " << hi << "], got " << got;
  return os.str();
}

void check_range(double v, double lo, double hi, bool lo_open, const std::string& source,
                 const std::string& field) {
  if (!std::isfinite(v)) throw InputError(source, field, "value is NaN or infinite");
  if ((lo_open ? v <= lo : v < lo) || v > hi)
    throw InputError(source, field, range_text(lo, hi, v, lo_open));
}

void check_positive(double v, const std::string& source, const std::string& field,
                    double hi = kMaxLength) {
  check_range(v, 0.0, hi, true, source, field);
}

Style parse_style(const std::string& name, const std::string& source) {
  const auto it = std::find(kStyles.begin(), kStyles.end(), name);
  if (it != kStyles.end()) return static_cast<Style>(it - kStyles.begin());
  std::string known;
  for (std::string_view s : kStyles) known += (known.empty() ? "" : ", ") + std::string(s);
  throw InputError(source, "groom.style", "unknown style '" + name + "' (known: " + known + ")");
}

Style check_spec(const GroomSpec& spec, float head_radius, const std::string& source) {
  const Style style = parse_style(spec.style, source);
  check_range(spec.strands, 1, kMaxGroomStrands, false, source, "groom.strands");
  check_range(spec.vertices_per_strand, 2, kMaxStrandVertices, false, source, "groom.vertices_per_strand");
  if (spec.total_vertices != 0)
    check_range(static_cast<double>(spec.total_vertices), 2.0 * spec.strands,
                static_cast<double>(kMaxStrandVertices) * spec.strands, false, source, "groom.vertices");
  check_positive(spec.length, source, "groom.length");
  check_positive(spec.wave_amplitude, source, "groom.wave_amplitude");
  check_positive(spec.wave_length, source, "groom.wave_length");
  check_positive(spec.curl_radius, source, "groom.curl_radius");
  check_positive(spec.curl_pitch, source, "groom.curl_pitch");
  check_positive(head_radius, source, "head.radius", std::numeric_limits<double>::max());
  return style;
}

}  // namespace

std::span<const std::string_view> groom_styles() { return kStyles; }

GeneratedGroom generate_groom(const GroomSpec& spec, float head_radius, const std::string& source) {
  const Style style = check_spec(spec, head_radius, source);
  const bool ponytail = style == Style::Ponytail;
  const double r = head_radius;
  SplitMix64 rng(spec.seed);
  // Roots first, from the start of the stream: the same seed and strand count give the
  // same roots in every style, so styles compare strand for strand.
  const std::vector<Root> roots = scalp_roots(spec.strands, rng);
  GeneratedGroom out;
  out.groom.head_radius = head_radius;
  if (ponytail) {
    out.groom.region_names = {"front", "top", "tail"};
    out.region_params = ponytail_region_params();
  } else {
    out.region_params.resize(1);
  }
  const std::int64_t strands = spec.strands;
  const std::int64_t total = spec.total_vertices > 0 ? spec.total_vertices : strands * spec.vertices_per_strand;
  out.groom.positions.reserve(static_cast<std::size_t>(total));
  for (std::int64_t s = 0; s < strands; ++s) {
    const Root& root = roots[static_cast<std::size_t>(s)];
    const Comb comb = ponytail ? ponytail_comb(root, r, rng) : loose_comb(root);
    const double phase = 2.0 * kPi * rng.uniform();
    const int n = static_cast<int>((s + 1) * total / strands - s * total / strands);
    if (style == Style::Hanging)
      out.groom.add_strand(hanging_strand(spec, r, static_cast<int>(s), n), 0);
    else
      out.groom.add_strand(grow_strand(spec, style, r, root, comb, phase, n), comb.region);
  }
  validate_groom(out.groom, source);
  return out;
}

}  // namespace hairbench
