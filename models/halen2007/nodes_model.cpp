#include "models/halen2007/nodes_model.h"

#include "core/parallel.h"

#include <algorithm>
#include <cmath>

namespace hairbench::halen {

ParamSet at_nodes(const ParamSet& p, std::span<const NodeScaling> scaling) {
  ParamSet out = p;
  const double ratio = (p.get_int("nodes") - 1.0) / (kReferenceNodes - 1.0);
  for (const NodeScaling& s : scaling) out.scale(s.param, std::pow(ratio, s.exponent));
  if (p.has("damping") && p.has("substeps")) {
    // Verlet's damping per substep (Eq. 4.1's k = 1 - damping), given per sixth of a frame:
    // kept (1 - d)^(6 / substeps) a substep, the same per frame at any substep count.
    const double share = kDampingSubsteps / p.get("substeps");
    auto per_substep = [&](double d) { return 1.0 - std::pow(1.0 - d, share); };
    const ParamSet::Origin from{"", "damping per substep."};
    out.set("damping", per_substep(p.get("damping")), from);
    for (std::size_t r = 0; r < p.regions().size(); ++r)
      if (p.regions()[r].contains("damping")) out.set_region(r, "damping", per_substep(p.get("damping", r)), from);
  }
  return out;
}

ParamSet nodes_for_groom(const Groom& g, const ParamSet& p) {
  std::size_t most = 0;
  for (std::size_t s = 0; s < g.strand_count(); ++s) most = std::max<std::size_t>(most, g.strand_size(s));
  ParamSet out = p;
  if (most > 0 && static_cast<std::size_t>(p.get_int("nodes")) > most)
    out.set("nodes", static_cast<double>(most), {"", "the groom's vertices per strand."});
  return out;
}

StepBound bound_at_nodes(BoundFn bound, const NodeTraits& traits, const Groom& g, const ParamSet& given,
                         const Vec3f& gravity) {
  const ParamSet p = nodes_for_groom(g, given);
  const kernels::NodeLayout layout = kernels::layout_nodes(g, p.get_int("nodes"), traits.tied_static);
  StepBound b = bound(layout.nodes, at_nodes(p, traits.scaling), gravity);
  b.why += " (at " + std::to_string(p.get_int("nodes")) + " nodes)";
  return b;
}

NodesModel::NodesModel(std::unique_ptr<HairModel> inner, const NodeTraits& traits, const ModelContext& ctx)
    : inner_(std::move(inner)), traits_(traits), ctx_(ctx) {}

void NodesModel::reset(const Groom& rest, const ParamSet& given) {
  rest_ = rest;
  params_ = nodes_for_groom(rest, given);
  layout_ = kernels::layout_nodes(rest, params_.get_int("nodes"), traits_.tied_static);
  inner_->reset(layout_.nodes, at_nodes(params_, traits_.scaling));
  drawn_ = rest.positions;
  frame_.resize(layout_.nodes.vertex_count());
  draw(Affine3f::Identity());
}

bool NodesModel::start_from(std::span<const Vec4f> positions) {
  if (!inner_->start_from(positions)) return false;
  draw(Affine3f::Identity());
  return true;
}

void NodesModel::step(const FrameInput& in, StageTimes& out_times) {
  inner_->step(in, out_times);
  const StageTimer timer(out_times, Stage::Interpolate);
  draw(in.head);
}

void NodesModel::draw(const Affine3f& head) {
  const std::span<const Vec4f> nodes = inner_->positions();
  auto body = [&](std::size_t begin, std::size_t end) {
    for (std::size_t s = begin; s < end; ++s) {
      const std::size_t nb = layout_.nodes.strand_begin(s), nn = layout_.nodes.strand_size(s);
      const std::size_t db = rest_.strand_begin(s), dn = rest_.strand_size(s);
      kernels::draw_from_nodes(nodes.subspan(nb, nn), std::span<const Vec4f>(layout_.nodes.positions).subspan(nb, nn),
                               std::span<const kernels::NodeSpan>(layout_.span).subspan(db, dn),
                               std::span<const Vec4f>(rest_.positions).subspan(db, dn), head,
                               std::span(frame_).subspan(nb, nn), std::span(drawn_).subspan(db, dn));
    }
  };
  if (ctx_.pool != nullptr)
    ctx_.pool->parallel_for(rest_.strand_count(), body);
  else
    body(0, rest_.strand_count());
}

std::size_t NodesModel::state_bytes() const {
  return inner_->state_bytes() + (rest_.positions.size() + drawn_.size()) * sizeof(Vec4f) +
         layout_.span.size() * sizeof(kernels::NodeSpan) + layout_.nodes.positions.size() * sizeof(Vec4f) +
         frame_.size() * sizeof(Quatf);
}

}  // namespace hairbench::halen
