// The fused Halén & Wester 2007 models (halen_spring §4.4, halen_cascade §4.3,
// halen_forest §4.2): the physics of models/halen2007/reference/ (spring, cascade and
// forest; registered as halen_*_ref), run as one structure-of-arrays pass per
// block of 16 strands through all substeps (kernels/halen2007/fused/halen_soa.h). Spring and cascade
// are bit-identical to their references, the forest agrees to rounding; all three give
// the same bits for any thread count. Blocks are partitioned statically over the threads
// at reset; a step allocates nothing and makes no virtual call.
#pragma once

#include "core/hair_model.h"
#include "core/sleep.h"
#include "kernels/halen2007/reference/halen_kernels.h"
#include "kernels/halen2007/fused/halen_soa.h"
#include "models/block_threads.h"
#include "models/halen2007/forest_settings.h"

#include <array>
#include <limits>
#include <memory>
#include <vector>

namespace hairbench::halen_fused {

using kernels::halen_soa::Model;

class HalenFusedModel final : public HairModel {
 public:
  HalenFusedModel(Model model, const ModelContext& ctx);
  void reset(const Groom& rest, const ParamSet& params) override;
  // The spring and cascade models' particles at the given positions, at rest; the
  // forest's joint angles that pose them (start_forest).
  bool start_from(std::span<const Vec4f> positions) override;
  void step(const FrameInput& in, StageTimes& out_times) override;
  std::span<const Vec4f> positions() const override { return pos_; }
  // The blocks' fields and state, and the positions written out.
  std::size_t state_bytes() const override;
  // Replaces the run-time chosen kernel variant (tests compare the variants).
  void use_kernel(kernels::halen_soa::FrameFn fn, kernels::halen_soa::ForestFrameFn forest) {
    kernel_ = fn;
    forest_kernel_ = forest;
  }

 private:
  static constexpr int W = kernels::halen_soa::kLanes;
  struct Region {
    float keep, tilt_min;
    int length_iterations;
    kernels::halen_soa::ForestParams forest;
  };
  struct BlockInfo {
    std::size_t offset = 0;     // into data_
    std::size_t state = 0;      // into state_
    std::size_t rows = 0;       // into row_kinds_
    int n = 0;
    std::uint16_t region = 0;
    bool sampled = false;       // times its stages
    std::array<std::uint32_t, W> offset_of{};  // per lane: first vertex of its strand
    std::array<std::uint32_t, W> strand{};     // per lane: the strand, or kNoStrand for a repeat
    std::array<std::uint32_t, W> source{};     // per lane: the strand it computes (repeats included)
  };
  using ThreadState = BlockThread;  // first/last: blocks
  static constexpr std::uint32_t kNoStrand = 0xffffffffu;
  std::size_t block_floats(int n) const;
  std::size_t state_floats(int n) const;
  // The model's settings (spring_settings.h, cascade_settings.h or forest_settings.h, read
  // there) in the one shape the blocks are set up from.
  struct Setup {
    struct RegionSetup {
      float stiffness, falloff_scale, down_fraction;  // the forest's joint stiffness as stiffness
      int falloff_exponent;
    };
    std::vector<RegionSetup> regions;
    halen_forest::Settings forest{};  // the forest's: its model-wide switches
    int frames = 0;
    bool reactions = false;
  };
  // region_ and substeps_ from the model's settings; what the blocks need returned.
  Setup read_settings(const ParamSet& params, std::size_t regions);
  void setup_blocks(const Groom& rest, const Setup& setup);
  void start_forest();
  void forest_substeps(const FrameInput& in, float dt);
  void feed_block(const BlockInfo& b, kernels::soa::LineFeed& feed) const;
  void run_thread(int t);
  void observe_sleep(int t, float dt);

  Model model_;
  ModelContext ctx_;
  kernels::halen_soa::FrameFn kernel_;
  kernels::halen_soa::ForestFrameFn forest_kernel_;
  std::vector<Region> region_;
  int substeps_ = 1;
  std::vector<BlockInfo> blocks_;
  std::vector<float> data_;
  std::vector<float> state_;  // positions and previous positions, block by block
  std::vector<kernels::halen_soa::RowKind> row_kinds_;
  std::vector<std::uint8_t> write_;  // per block and lane, refreshed every step
  std::vector<ThreadState> threads_;
  std::vector<float> scratch_;
  std::size_t scratch_stride_ = 0;
  std::vector<float> backup_;  // per thread: a block's state, for its sleeping lanes
  std::size_t backup_stride_ = 0;
  std::vector<Vec4f> prev_tmp_;  // per thread: one strand's previous positions (the cascade's steps)
  std::vector<kernels::halen_soa::Substep> substep_;
  std::vector<float> spheres_;        // per substep, x y z r per collider
  std::vector<float> spring_scale_;   // per region and substep: §4.4's tilt factor
  kernels::halen_soa::Frame frame_{};
  // The forest's substeps (and the final head pose), frame, axes and root motion history.
  std::vector<kernels::halen_soa::ForestSubstep> forest_substep_;
  kernels::halen_soa::ForestFrame forest_frame_{};
  bool forest_root_angular_ = false;  // the forest's root_angular_acceleration parameter
  Affine3f head_hist_[2];
  std::vector<float> inv_length_;  // forest: 1/ℓ per strand
  // forest: the rest polyline, segment lengths and joint stiffness, from which each
  // block's gain of the external torques (1/ℓ) is divided by
  // kernels::forest_rest_inertia_scale for the gravity of the frame (rest_hold).
  struct ForestRest {
    bool hold = false;
    std::vector<Vec4f> positions;
    std::vector<float> length, k;
    std::vector<std::uint32_t> strand_offsets;
    Vec3f gravity = Vec3f::Constant(std::numeric_limits<float>::quiet_NaN());
  };
  ForestRest forest_rest_;
  void hold_rest(const Vec3f& gravity);
  kernels::CascadeFrames cascade_frames_ = kernels::CascadeFrames::Transport;  // cascade: "frames"
  bool cascade_reactions_ = true;                                              // cascade: "reactions"
  bool calm_ = false;
  StrandSleep sleep_;
  std::vector<std::uint32_t> strand_begin_;
  std::vector<Vec4f> pos_;
};

std::unique_ptr<HairModel> make(Model model, const ModelContext& ctx);

}  // namespace hairbench::halen_fused
