// The solver stages every model times, one enum with one name table: a report's
// `timing.stages` keys are these names (docs/report-schema.md), and the fused kernels'
// sampled clocks are indexed by the same enum.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <string_view>

namespace hairbench {

enum class Stage : std::uint8_t {
  Upload,           // host to device copies (GPU models)
  Dispatch,         // the device's work for the frame, waited on (GPU models)
  References,       // reference nodes of Halén's spring and cascade models (§4.3, §4.4)
  Pose,             // positions from the forest's joint angles (Halén §4.2)
  Integrate,        // the explicit integration of every model
  GlobalShape,      // Han & Harada's global shape constraint
  LocalShape,       // Han & Harada's local shape constraint (methods 1-3)
  Length,           // edge length constraints
  Collision,        // strand-sphere collisions
  BodyCollision,    // Plante's wisp-body collisions (§4.2)
  SelfInteraction,  // Plante's wisp-wisp interactions (§4.1)
  Rebuild,          // Plante's strands from their wisps (§3.4)
  Interpolate,      // groom vertices drawn from Halén's simulated nodes (§5.5)
  FollowHairs,      // follow hairs generated from the guides (TressFX grooms)
  Sleep,            // the sleep checks of a calm scene
};
inline constexpr std::size_t kStageCount = static_cast<std::size_t>(Stage::Sleep) + 1;

inline constexpr std::array<std::string_view, kStageCount> kStageNames = {
    "upload", "dispatch",       "references",       "pose",    "integrate",    "global_shape", "local_shape",
    "length", "collision",      "body_collision",   "self_interaction", "rebuild", "interpolate", "follow_hairs",
    "sleep"};

constexpr std::size_t stage_index(Stage s) { return static_cast<std::size_t>(s); }
constexpr std::string_view stage_name(Stage s) { return kStageNames[stage_index(s)]; }

}  // namespace hairbench
