// Halén & Wester 2007's models at the thesis's resolution: the model simulates `nodes`
// nodes a strand (Fig. 6.1.1 times 4 and 8) and the groom's vertices are drawn from them
// (§5.5; kernels/halen2007/nodes.h). The harness, its metrics and the verdicts see every
// groom vertex; the inner model sees the nodes only.
//
// One material at any node count. A parameter that sets how stiff a strand is depends on
// how finely the strand is cut, so each model's stiffness and damping parameters are
// given at the thesis's 8 nodes and multiplied by ((nodes - 1) / 7)^p, with p from the
// model's equations so that its slowest mode (the strand turning about its root, the
// mode a reader sees) keeps its rate:
//  - spring (§4.4), p = 0: every node hangs on its own zero-rest-length spring, x'' = -k x
//    per unit mass, whatever the node count;
//  - cascade (§4.3), p = 3.6 on the stiffness: the reference springs are torsion springs
//    of stiffness k m ℓ² on nodes of mass m ∝ ℓ, and a continuous cantilever's slowest
//    mode goes as k (ℓ / L)⁴; the discrete rod's ends and the downward springs' reach
//    make it stiffer at more nodes than that, and 3.6 is measured: the settled bend of a
//    strand under a 30° head tilt at 4, 8, 16 and 32 nodes is 0.67, 0.49, 0.36, 0.28 L̄
//    with p = 4 and 0.62, 0.49, 0.43, 0.41 with 3.6 (docs/limitations.md, "The cascade");
//  - forest (§4.2), p = 2 on the joint stiffness and damping: the joints see a discrete
//    Laplacian of the spring torques whose slowest mode on n joints is about (π / 2n)² k,
//    damped at (π / 2n)² v.
// The fastest mode then rises with the node count (about as (nodes - 1)^1.8 in frequency
// for the cascade, (nodes - 1) for the forest), and `substeps: auto` follows it: the step
// bounds (step_bounds.h) are taken on the nodes at the scaled parameters.
#pragma once

#include "core/hair_model.h"
#include "kernels/halen2007/nodes.h"
#include "models/halen2007/step_bounds.h"

#include <array>
#include <memory>
#include <span>
#include <string_view>
#include <vector>

namespace hairbench::halen {

// The node count the models' stiffness and damping parameters are given at (Fig. 6.1.1).
inline constexpr int kReferenceNodes = 8;

// A parameter given at kReferenceNodes, multiplied by ((nodes - 1) / 7)^exponent.
struct NodeScaling {
  std::string_view param;
  double exponent;
};
inline constexpr std::array<NodeScaling, 0> kSpringScaling{};
inline constexpr std::array<NodeScaling, 1> kCascadeScaling{{{"stiffness", 3.6}}};
inline constexpr std::array<NodeScaling, 2> kForestScaling{{{"joint_stiffness", 2.0}, {"joint_damping", 2.0}}};

// How one model is laid out on nodes (kernels::layout_nodes): its scaled parameters, and
// whether strands pinned at both ends are held static (the forest, a tree grown from the
// root, cannot honour a second pin and holds such strands static, §6.3; the spring and
// cascade models, whose nodes are particles, honour every pin).
struct NodeTraits {
  std::span<const NodeScaling> scaling;
  bool tied_static;
};
inline constexpr NodeTraits kSpringNodes{kSpringScaling, false};
inline constexpr NodeTraits kCascadeNodes{kCascadeScaling, false};
inline constexpr NodeTraits kForestNodes{kForestScaling, true};

// Verlet's `damping` (spring and cascade) is given per sixth of a frame, a substep at the
// models' default six, and taken per substep as the same damping per frame: the substeps
// that `auto` raises with the node count and the strands' curvature change how often a
// strand is damped, not how much per second.
inline constexpr double kDampingSubsteps = 6.0;

// The parameters the inner model runs at: `p` with every scaled parameter multiplied for
// p's `nodes`, and the damping per substep.
ParamSet at_nodes(const ParamSet& p, std::span<const NodeScaling> scaling);

// `p` with `nodes` at most the most vertices any strand of `g` has: §5.5 draws a groom's
// vertices from fewer simulated nodes, and more nodes than a strand's vertices would only
// add short segments between them (8 nodes on TressFX TestHair1's 4-vertex strands: 1.2 cm
// segments, which an upright strand's edge corrections left stretched by 79% in its first
// frame).
ParamSet nodes_for_groom(const Groom& g, const ParamSet& p);

// A model's step bound (step_bounds.h) on the nodes it simulates the groom at, with the
// scaled parameters.
using BoundFn = StepBound (*)(const Groom&, const ParamSet&, const Vec3f&);
StepBound bound_at_nodes(BoundFn bound, const NodeTraits& traits, const Groom& g, const ParamSet& p,
                         const Vec3f& gravity);

class NodesModel final : public HairModel {
 public:
  NodesModel(std::unique_ptr<HairModel> inner, const NodeTraits& traits, const ModelContext& ctx);
  // Lays `rest` out as the parameter `nodes` asks and resets the inner model on the nodes.
  void reset(const Groom& rest, const ParamSet& params) override;
  // Starts the inner model from node positions (the simulated groom's layout) and draws
  // the groom's vertices from them.
  bool start_from(std::span<const Vec4f> positions) override;
  // Steps the inner model, then draws the groom's vertices (stage "interpolate").
  void step(const FrameInput& in, StageTimes& out_times) override;
  std::span<const Vec4f> positions() const override { return drawn_; }
  std::size_t state_bytes() const override;
  Backend backend() const override { return inner_->backend(); }
  std::size_t static_strands() const override { return layout_.static_strands; }
  const Groom* simulated_groom() const override { return &layout_.nodes; }
  std::span<const Vec4f> simulated_positions() const override { return inner_->positions(); }
  const ParamSet* run_params() const override { return &params_; }

 private:
  void draw(const Affine3f& head);

  ParamSet params_;  // as given, `nodes` at most the groom's (nodes_for_groom)
  std::unique_ptr<HairModel> inner_;
  NodeTraits traits_;
  ModelContext ctx_;
  Groom rest_;
  kernels::NodeLayout layout_;
  std::vector<Vec4f> drawn_;
  std::vector<Quatf> frame_;  // scratch, one per node
};

}  // namespace hairbench::halen
