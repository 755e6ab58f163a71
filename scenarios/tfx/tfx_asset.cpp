// TressFX files -> a hairbench groom in metres with regions, parameters, colliders and
// follow hairs.
#include "scenarios/tfx/tfx.h"

#include "core/error.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace hairbench::tfx {
namespace {

void check_scale(const std::filesystem::path& file, float metres_per_unit) {
  if (!std::isfinite(metres_per_unit) || !(metres_per_unit > 0.0f))
    throw InputError(file.string(), "metres_per_unit",
                     std::to_string(metres_per_unit) + " is not a positive finite scale");
}

// Appends the strands of one .tfx file to `groom`, positions scaled to metres (w, the
// inverse mass, is unit-free), all in region `region`.
void append_strands(Groom& groom, const TfxStrands& strands, float metres_per_unit,
                    std::uint16_t region, const std::string& source) {
  if (groom.positions.size() + strands.positions.size() > std::numeric_limits<std::uint32_t>::max())
    throw InputError(source, "sections", "more than 2^32 vertices in all");
  for (const Vec4f& p : strands.positions)
    groom.positions.emplace_back(p.x() * metres_per_unit, p.y() * metres_per_unit,
                                 p.z() * metres_per_unit, p.w());
  const std::uint32_t n = strands.vertices_per_strand;
  for (std::uint32_t s = 0; s < strands.strand_count; ++s) {
    groom.strand_offsets.push_back(groom.strand_offsets.back() + n);
    groom.strand_region.push_back(region);
  }
}

// Independent follow-hair streams per section: the murmur3 64-bit finaliser of seed and
// index (splitmix64 streams from seeds one gamma apart would be shifted copies).
std::uint64_t section_seed(std::uint64_t seed, std::size_t section) {
  std::uint64_t h = seed ^ (0x9e3779b97f4a7c15ull * (section + 1));
  h ^= h >> 33;
  h *= 0xff51afd7ed558ccdull;
  h ^= h >> 33;
  h *= 0xc4ceb9fe1a85ec53ull;
  return h ^ (h >> 33);
}

// Pins every vertex of the strands shorter than `min_length` (metres). PBD cannot move a
// strand whose edges are far shorter than the distance gravity and the head carry a vertex
// in one substep (gravity alone: 9.81 m/s^2 at 360 Hz is 76 um; the Ratboy mohawk has 18
// strands under 4 mm with 32 vertices, edges down to 3 um): its edge constraints tear it
// apart. Real hair that short barely bends: a cantilever's tip deflection w L^4 / (8 E I)
// for an 80 um fibre (E ~ 4 GPa, 1.3 g/cm^3) is 0.16 mm at L = 2 cm under gravity, so it
// moves rigidly with the scalp, which is what pinned vertices do.
void pin_short_strands(Groom& g, double min_length) {
  if (!(min_length > 0.0)) return;
  for (std::size_t s = 0; s < g.strand_count(); ++s) {
    const std::uint32_t b = g.strand_begin(s), n = g.strand_size(s);
    double length = 0.0;
    for (std::uint32_t i = b + 1; i < b + n; ++i)
      length += (g.positions[i] - g.positions[i - 1]).head<3>().cast<double>().norm();
    if (length < min_length)
      for (std::uint32_t i = b; i < b + n; ++i) g.positions[i].w() = 0.0f;
  }
}

// TressFX's collision spheres are a coarse stand-in for the head mesh, and the ponytail's
// hold thousands of free rest vertices, up to 9.5 cm deep: the collision pass would fling
// them out on the first frame. The hair is the ground truth of where the head is not, so
// each sphere keeps its centre and shrinks to the largest radius that no free rest vertex
// lies inside (pinned vertices are never collided). Then no vertex is inside a collider at
// rest, and the penetration metric measures what the motion adds.
// The path of a project's section file, for the strands' reader.
std::filesystem::path section_path(const std::filesystem::path& project, const std::string& file) {
  return project.parent_path() / file;
}

Sphere to_metres(const Sphere& s, float metres_per_unit, const std::string& source) {
  Sphere out = s;
  out.center *= metres_per_unit;
  out.radius *= metres_per_unit;
  if (!out.center.allFinite() || !std::isfinite(out.radius))
    throw InputError(source, "collision_sphere", "out of float range in metres");
  return out;
}

}  // namespace

void fit_spheres_to_rest_hair(std::vector<Sphere>& spheres, const Groom& g, bool pinned_too) {
  for (Sphere& s : spheres) {
    float nearest = std::numeric_limits<float>::infinity();
    for (const Vec4f& p : g.positions)
      if (pinned_too || p.w() != 0.0f) nearest = std::min(nearest, (p.head<3>() - s.center).norm());
    if (nearest <= s.radius) s.radius = nearest * (1.0f - kColliderClearance);
  }
}

Groom read_tfx_strands(const std::filesystem::path& file) {
  Groom g;
  if (file.extension() != ".tfxproj") {
    append_strands(g, read_tfx(file), 1.0f, 0, file.string());
    return g;
  }
  for (const TfxProject::Section& section : read_tfxproj(file).sections)
    append_strands(g, read_tfx(section_path(file, section.tfx_file)), 1.0f, 0, file.string());
  return g;
}

TfxAsset load_tfx_asset(const std::filesystem::path& file, const ImportOptions& opt) {
  check_scale(file, opt.metres_per_unit);
  const TfxStrands strands = read_tfx(file);
  TfxAsset asset;
  asset.groom.region_names = {file.stem().string()};
  append_strands(asset.groom, strands, opt.metres_per_unit, 0, file.string());
  asset.region_params.resize(1);
  asset.repairs = repair_groom(asset.groom, opt.degenerate, file.string());
  validate_groom(asset.groom, file.string());
  pin_short_strands(asset.groom, opt.rigid_below);
  return asset;
}

TfxAsset load_tfx_project(const std::filesystem::path& file, const ImportOptions& opt, std::uint64_t seed) {
  check_scale(file, opt.metres_per_unit);
  const float metres_per_unit = opt.metres_per_unit;
  const TfxProject project = read_tfxproj(file);
  const std::string source = file.string();
  if (project.sections.size() > std::numeric_limits<std::uint16_t>::max() + std::size_t{1})
    throw InputError(source, "sections", "more sections than 16-bit region indices hold");

  TfxAsset asset;
  Groom guides;
  guides.region_names.clear();
  for (std::size_t i = 0; i < project.sections.size(); ++i) {
    const TfxProject::Section& section = project.sections[i];
    const TfxStrands strands = read_tfx(section_path(file, section.tfx_file));
    // A section's .tfxsim overrides the project-level values (TressFX reads the project
    // iteration counts as defaults).
    std::map<std::string, double> params = project.params;
    for (const auto& [key, value] : read_tfxsim(section_path(file, section.sim_file)).params) params[key] = value;
    append_strands(guides, strands, metres_per_unit, static_cast<std::uint16_t>(i), source);
    guides.region_names.push_back(section.name);
    asset.region_params.push_back(std::move(params));
  }
  // Repairs may remove strands: the sections' first strands are counted after them.
  asset.repairs = repair_groom(guides, opt.degenerate, source);
  std::vector<std::size_t> first_strand(project.sections.size() + 1, guides.strand_count());
  for (std::size_t s = guides.strand_count(); s-- > 0;) first_strand[guides.strand_region[s]] = s;
  for (std::size_t i = project.sections.size(); i-- > 0;)
    first_strand[i] = std::min(first_strand[i], first_strand[i + 1]);
  validate_groom(guides, source);
  // Before the follow hairs, which take their guide's inverse masses.
  pin_short_strands(guides, opt.rigid_below);

  FollowHairs follow;
  follow.guide_offsets = guides.strand_offsets;
  for (std::size_t i = 0; i < project.sections.size(); ++i) {
    const TfxProject::Section& section = project.sections[i];
    try {
      append_follow_hairs(follow, guides, first_strand[i], first_strand[i + 1],
                          section.follow_per_guide, section.follow_radius * metres_per_unit,
                          section.tip_separation, section_seed(seed, i));
    } catch (const InputError& e) {
      throw InputError(source + ": section " + section.name + ": " + e.what());
    }
  }
  if (follow.empty()) {
    asset.groom = std::move(guides);
  } else {
    asset.groom = expand_follow_hairs(guides, follow);
    asset.follow = std::move(follow);
  }
  for (const Sphere& s : project.spheres)
    asset.colliders.push_back(to_metres(s, metres_per_unit, source));
  fit_spheres_to_rest_hair(asset.colliders, asset.groom);
  validate_groom(asset.groom, source);
  return asset;
}

}  // namespace hairbench::tfx
