// AMD TressFX hair assets: .tfx strand files (binary, 3.x and 4.x), .tfxsim simulation
// settings and .tfxproj projects (text), and TressFX-style follow hairs. The layouts are
// the ones of scenarios/assets/tressfx/README.md; everything here is pure except the
// read_*/write_*/load_* functions, which only add file access.
//
// Every malformed input is one InputError whose message names the file and the place:
// "FILE: byte N: what" for .tfx, "FILE: line N: what" for the text formats.
#pragma once

#include "core/groom.h"
#include "core/groom_fit.h"
#include "core/types.h"

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <map>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace hairbench {
class ThreadPool;
}

namespace hairbench::tfx {

// ---- .tfx strands ---------------------------------------------------------------------

struct TfxStrands {
  int version_major = 0;  // 3 or 4
  std::uint32_t strand_count = 0;
  std::uint32_t vertices_per_strand = 0;
  // Strand-major, file units; w = inverse mass (0 = pinned). Vertices 0 and 1 of every
  // strand are always pinned (see parse_tfx).
  std::vector<Vec4f> positions;
  std::vector<Eigen::Vector2f> strand_uv;  // one per strand; empty if the file has none
};

// Parses a whole .tfx file held in memory; `name` is used in error messages.
TfxStrands parse_tfx(std::span<const std::byte> bytes, const std::string& name);
TfxStrands read_tfx(const std::filesystem::path& file);

// A .tfx 4.0 image of `groom` (positions float4, w = inverse mass, no UVs). The groom must
// pass validate_groom() and have the same vertex count in every strand (the format has
// one numVerticesPerStrand); otherwise InputError naming `name`. parse_tfx() of the result
// gives back the positions bit for bit.
std::vector<std::byte> tfx_v4_bytes(const Groom& groom, const std::string& name);
void write_tfx_v4(const std::filesystem::path& file, const Groom& groom);

// ---- .tfxsim / .tfxproj ---------------------------------------------------------------

// Simulation settings with hairbench parameter names (docs/scenarios.md):
// damping, local_stiffness, global_stiffness, global_range, length_iterations,
// local_iterations. Only the keys present in the file are set.
struct SimSettings {
  std::map<std::string, double> params;
};

// Unknown keys, keys given twice, missing, extra, non-numeric or non-finite values and
// iteration counts that are not whole numbers are errors ("FILE: line N: ...").
SimSettings parse_tfxsim(std::string_view text, const std::string& name);
SimSettings read_tfxsim(const std::filesystem::path& file);

struct TfxProject {
  struct Section {
    std::string tfx_file;  // as written, relative to the project file
    std::string sim_file;  // as written, relative to the project file
    std::string name;      // section name; the .tfx file's stem when the line has none
    int follow_per_guide = 0;
    double follow_radius = 0.0;   // file units
    double tip_separation = 0.0;  // dimensionless growth of the offset towards the tip
  };
  std::string project_name;  // "" when the file has no project_name line
  std::vector<Section> sections;
  std::vector<Sphere> spheres;  // file units, head_attached = true
  // Project-level iteration counts with hairbench names (length_iterations,
  // local_iterations).
  std::map<std::string, double> params;
};

// Lines: version (3.x/4.x), project_name, sections ("file.tfx followHairsPerGuide
// followRadius tipSeparation file.tfxsim [sectionName]", distinct names), the head mesh
// ("*.sdkmesh", ignored), lengthConstraintIterations, localShapeMatchingIterations,
// "collision_sphere x y z r", and the viewer's rendering keys (hairColor, Ka, Ks1, Ex1,
// Ks2, Ex2, lightPos: ignored). At least one section is required.
TfxProject parse_tfxproj(std::string_view text, const std::string& name);
TfxProject read_tfxproj(const std::filesystem::path& file);

// ---- follow hairs ---------------------------------------------------------------------

// TressFX renders several "follow" hairs around each simulated guide hair: a follow hair
// is its guide displaced by a fixed root offset that grows towards the tip (TressFX's
// UpdateFollowHairVertices: guide vertex + (1 + tipSeparation * i/n) * rootOffset). Here
// the offset is kept in the guide's root frame (root tangent, a normal fixed by a pinned
// anchor, binormal), so it turns with the head; a follow vertex moves exactly as its guide
// vertex plus that rigid offset, so the follow strand's pinned vertices move rigidly with
// the head like its guide's (whenever the anchor is another guide's root: see
// make_follow_hairs).
// (Offsets carried in per-vertex frames instead would swing by |offset| times the bend:
// with TressFX's tip separations that stretches follow edges many times faster than the
// guide bends.)
struct FollowHairs {
  // Strand layout of the guide positions this applies to (the guide groom's
  // strand_offsets).
  std::vector<std::uint32_t> guide_offsets{0};
  // Per follow strand: its guide strand, and the index (into the guide positions) of the
  // anchor point that orients the guide's root normal (see make_follow_hairs).
  std::vector<std::uint32_t> guide;
  std::vector<std::uint32_t> anchor;
  // Follow strand f owns offsets [follow_offsets[f], follow_offsets[f+1]); it has as many
  // vertices as its guide. Each offset is (tangent, normal, binormal) components in the
  // guide's root frame, already grown for its vertex.
  std::vector<std::uint32_t> follow_offsets{0};
  std::vector<Vec3f> offsets;

  std::size_t strand_count() const { return guide.size(); }
  std::size_t vertex_count() const { return offsets.size(); }
  bool empty() const { return guide.empty(); }
};

// `per_guide` follow hairs for every strand of `guides` (which must pass validate_groom),
// deterministic by `seed` on every machine (own integer RNG, rejection sampling, no
// transcendental functions). Each follow root is offset from its guide root by a uniform
// random vector in the disk of radius `radius` perpendicular to the root edge; at vertex
// i of n the offset is scaled by 1 + tip_separation * i / (n - 1). Follow hairs of one
// guide are consecutive, guides in order. Throws std::invalid_argument for a negative or
// non-finite argument (the project parser reports those with line numbers).
FollowHairs make_follow_hairs(const Groom& guides, int per_guide, double radius,
                              double tip_separation, std::uint64_t seed);

// Appends follow hairs for guide strands [first, last) of `guides` to `out`, whose
// guide_offsets must be guides.strand_offsets. make_follow_hairs() is this over all
// strands; project loading calls it once per section.
void append_follow_hairs(FollowHairs& out, const Groom& guides, std::size_t first, std::size_t last,
                         int per_guide, double radius, double tip_separation, std::uint64_t seed);

// The rest groom: the guides, then every follow strand (in FollowHairs order) with its
// guide's region and vertices 0 and 1 pinned.
Groom expand_follow_hairs(const Groom& guides, const FollowHairs& follow);

// Rebuilds the follow strands from the current guide positions (the root frames are
// recomputed from them on every call). out_follow_positions gets follow.vertex_count() vertices;
// w is the guide vertex's w, with vertices 0 and 1 pinned. Throws std::invalid_argument
// when a span does not match `follow`'s layout. With a pool, the strands are split over
// its threads (same result).
void apply_follow_hairs(const FollowHairs& follow, std::span<const Vec4f> guide_positions,
                        std::span<Vec4f> out_follow_positions, ThreadPool* pool = nullptr);

// ---- assets ---------------------------------------------------------------------------

struct TfxAsset {
  // Positions in metres, still in the asset's own frame. Guide strands first; when
  // `follow` is not empty, its strands follow in FollowHairs order.
  Groom groom;
  std::vector<std::map<std::string, double>> region_params;  // one per groom region
  std::vector<Sphere> colliders;                             // metres, head-attached, fitted to the rest hair
  FollowHairs follow;                                        // empty when there are no follow hairs
  std::vector<Repair> repairs;                               // what repair_groom did to the guides
};

// How an asset is read: its scale, what to do with degenerate strands (repair_groom,
// before any follow hair is made), and the strands to pin whole (pin_short_strands in
// tfx_asset.cpp).
struct ImportOptions {
  float metres_per_unit = 0.01f;
  DegeneratePolicy degenerate = DegeneratePolicy::Repair;
  double rigid_below = 0.0;
};

// The guide strands of an asset file or project in file units, as read (no repair, no
// scale): what a unit is guessed from (guess_unit). A project's strands are its
// sections' in order.
Groom read_tfx_strands(const std::filesystem::path& file);

// One .tfx file: one region named after the file stem, no parameters, no colliders.
TfxAsset load_tfx_asset(const std::filesystem::path& file, const ImportOptions& opt);

// A .tfxproj with its .tfx and .tfxsim files (paths relative to the project): one region
// per section, named by the section, with the project's parameters overridden by the
// section's .tfxsim; collision spheres as colliders; follow hairs per section (radius
// scaled to metres), seeded from `seed` and the section index. Each collision sphere keeps
// its centre and shrinks, where needed, until no free rest vertex (follow hairs included)
// lies inside it: TressFX's spheres overlap the hair they stand for the head under.
// Guides shorter than `rigid_below` metres, and their follow hairs, are pinned whole.
TfxAsset load_tfx_project(const std::filesystem::path& file, const ImportOptions& opt, std::uint64_t seed);

// Shrinks each sphere, keeping its centre, until no free vertex of `g` (with `pinned_too`,
// no vertex at all) lies inside it or on it: a shrunk sphere's radius is
// kColliderClearance short of the nearest such vertex's distance. A TressFX project's
// spheres keep the roots they are authored over; a sphere fitted to a groom
// (`"radius": "fit"`) clears the pinned vertices too, since a pinned vertex inside holds
// its free neighbour against the surface, and pushed out, that edge stretches from the
// first frame (TestHair1's fitted 0.54 m collider held 0.1 of its roots: the cascade's
// strand 1638 stretched 0.86 of its median edge). Exactly on the surface, rounding would decide whether a model finds
// that vertex inside (a sphere evaluated under the head transform, a distance computed in
// another order) and push it out at the first step: on TestHair1 tiled to 50,000 strands
// under `spin_fast`, `plante_wisp`'s two strands that touched the sphere kept bouncing
// off it with the head still (§4.2's reaction lifts a mass found inside 1.8 mm out).
inline constexpr float kColliderClearance = 1e-3f;  // of the distance
void fit_spheres_to_rest_hair(std::vector<Sphere>& spheres, const Groom& g, bool pinned_too = false);

}  // namespace hairbench::tfx
