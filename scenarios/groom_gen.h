// Procedural grooms, deterministic by seed (same spec -> bit-identical groom on every
// machine: the generator uses its own integer RNG, not <random>'s distributions).
#pragma once

#include "core/groom.h"

#include <cstdint>
#include <map>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace hairbench {

// The largest groom generate_groom builds (and a scenario file may ask for).
inline constexpr int kMaxGroomStrands = 1'000'000;
inline constexpr int kMaxStrandVertices = 256;

struct GroomSpec {
  std::string style = "straight";  // straight | wavy | curly | ponytail | hanging
  int strands = 2000;
  int vertices_per_strand = 16;
  // > 0: the groom's total vertex count instead of vertices_per_strand; strands get
  // floor or ceil of the mean, spread evenly, so a published groom size (Han & Harada
  // Table 1: 19,776 strands, 221,078 vertices) is met exactly.
  std::int64_t total_vertices = 0;
  double length = 0.25;  // metres, rest strand length
  std::uint64_t seed = 1;
  // Style shape knobs (metres). wavy: planar sine wave; curly: helix around the
  // strand's growth direction, giving rest curvature.
  double wave_amplitude = 0.015, wave_length = 0.08;
  double curl_radius = 0.012, curl_pitch = 0.04;
};

struct GeneratedGroom {
  Groom groom;
  // Per-region default parameters (name -> value) that the style implies, e.g. the
  // ponytail's stiff front and soft tail (Han & Harada Figure 1). Same length as
  // groom.region_names.
  std::vector<std::map<std::string, double>> region_params;
};

// The styles generate_groom builds, for loaders and error messages.
std::span<const std::string_view> groom_styles();

// Strands rooted on the upper half of the head sphere (radius head_radius, centre at
// the origin), growing outward and combed downward, never inside the sphere; vertices 0
// and 1 pinned (Han & Harada §3.2). "hanging": straight strands hanging down (-y) from
// under the head, the truth scenarios' chains. Throws InputError(source, "groom.<field>", ...) on
// a spec it cannot build.
GeneratedGroom generate_groom(const GroomSpec& spec, float head_radius, const std::string& source);

}  // namespace hairbench
