#include "models/halen2007/fused/halen_fused.h"

#include "core/parallel.h"
#include "kernels/halen2007/reference/halen_kernels.h"
#include "models/halen2007/cascade_settings.h"
#include "models/halen2007/spring_settings.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numeric>

namespace hairbench::halen_fused {

namespace soa = hairbench::kernels::halen_soa;
namespace k = hairbench::kernels;

// One block in this many (and the first of every region) times its stages.
constexpr std::size_t kSampleEvery = 16;

HalenFusedModel::HalenFusedModel(Model model, const ModelContext& ctx)
    : model_(model), ctx_(ctx), kernel_(soa::frame_kernel()), forest_kernel_(soa::forest_kernel()) {}

std::size_t HalenFusedModel::block_floats(int n) const {
  return model_ == Model::Forest ? soa::forest_block_floats(n) : soa::block_floats(model_, n);
}
std::size_t HalenFusedModel::state_floats(int n) const {
  return model_ == Model::Forest ? soa::forest_state_floats(n) : soa::state_floats(n);
}

HalenFusedModel::Setup HalenFusedModel::read_settings(const ParamSet& params, std::size_t regions) {
  Setup setup;
  region_.clear();
  if (model_ == Model::Spring) {
    const halen_spring::Settings s = halen_spring::read_settings(params, regions);
    for (const halen_spring::RegionSettings& r : s.regions) {
      region_.push_back({1.0f - r.damping, r.tilt_min, r.length_iterations, {}});
      setup.regions.push_back({r.stiffness, r.falloff_scale, 0.0f, r.falloff_exponent});
    }
    substeps_ = s.substeps;
  } else if (model_ == Model::Cascade) {
    const halen_cascade::Settings s = halen_cascade::read_settings(params, regions);
    for (const halen_cascade::RegionSettings& r : s.regions) {
      region_.push_back({1.0f - r.damping, 1.0f, r.length_iterations, {}});
      setup.regions.push_back({r.stiffness, r.falloff_scale, r.down_fraction, r.falloff_exponent});
    }
    substeps_ = s.substeps;
    setup.frames = s.frames;
    setup.reactions = s.reactions;
  } else {
    const halen_forest::Settings s = halen_forest::read_settings(params, regions);
    for (const halen_forest::RegionSettings& r : s.regions) {
      region_.push_back({1.0f, 1.0f, 0, {r.joint_damping, r.drag, r.collision_stiffness, r.collision_damping}});
      setup.regions.push_back({r.joint_stiffness, r.falloff_scale, 0.0f, r.falloff_exponent});
    }
    substeps_ = s.substeps;
    setup.forest = s;
  }
  return setup;
}

void HalenFusedModel::reset(const Groom& rest, const ParamSet& params) {
  const bool forest = model_ == Model::Forest;
  const Setup setup = read_settings(params, rest.region_names.size());

  // Threads: contiguous ranges of strands of about equal cost (vertices times passes over
  // them), fixed at reset, so that no two threads write the same cache line of the
  // positions. Blocks: within a thread's range, strands of one region and one vertex
  // count, W at a time (ragged grooms give one partly filled block per (region, count);
  // its idle lanes repeat a strand of the block and are never written back). Every lane's
  // result depends only on its own strand, so the state is the same for any thread count
  // and any grouping.
  const int threads = ctx_.pool ? ctx_.pool->threads() : 1;
  const std::size_t strands = rest.strand_count();
  auto cost = [&](std::size_t s) {
    return static_cast<double>(rest.strand_size(s)) * (4.0 + region_[rest.strand_region[s]].length_iterations);
  };
  double total = 0.0;
  for (std::size_t s = 0; s < strands; ++s) total += cost(s);
  threads_.assign(static_cast<std::size_t>(threads), ThreadState{});
  blocks_.clear();
  row_kinds_.clear();
  std::size_t floats = 0, state = 0;
  int max_n = 0;
  double acc = 0.0;
  std::size_t next = 0;
  for (int t = 0; t < threads; ++t) {
    const std::size_t first = next;
    const double end = total * (t + 1) / threads;
    while (next < strands && (t == threads - 1 || acc + 0.5 * cost(next) < end)) acc += cost(next++);
    std::vector<std::uint32_t> order(next - first);
    std::iota(order.begin(), order.end(), static_cast<std::uint32_t>(first));
    std::stable_sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) {
      if (rest.strand_region[a] != rest.strand_region[b]) return rest.strand_region[a] < rest.strand_region[b];
      return rest.strand_size(a) < rest.strand_size(b);
    });
    threads_[t].first = blocks_.size();
    for (std::size_t i = 0; i < order.size();) {
      const std::uint16_t region = rest.strand_region[order[i]];
      const int n = static_cast<int>(rest.strand_size(order[i]));
      std::size_t j = i;
      while (j < order.size() && j - i < static_cast<std::size_t>(W) && rest.strand_region[order[j]] == region &&
             static_cast<int>(rest.strand_size(order[j])) == n)
        ++j;
      BlockInfo b;
      b.offset = floats;
      b.state = state;
      b.rows = row_kinds_.size();
      b.n = n;
      b.region = region;
      b.sampled = blocks_.size() % kSampleEvery == 0 || blocks_.empty() || blocks_.back().region != region;
      for (int l = 0; l < W; ++l) {
        const bool used = i + static_cast<std::size_t>(l) < j;
        const std::uint32_t s = order[used ? i + l : j - 1];
        b.offset_of[l] = rest.strand_begin(s);
        b.strand[l] = used ? s : kNoStrand;
        b.source[l] = s;
      }
      for (int v = 0; v < n; ++v) {
        int pinned = 0;
        for (int l = 0; l < W; ++l) pinned += rest.positions[b.offset_of[l] + v].w() == 0.0f;
        row_kinds_.push_back(pinned == 0 ? soa::kRowFree : pinned == W ? soa::kRowPinned : soa::kRowMixed);
      }
      floats += block_floats(n);
      state += state_floats(n);
      max_n = std::max(max_n, n);
      blocks_.push_back(b);
      i = j;
    }
    threads_[t].last = blocks_.size();
  }
  data_.assign(floats, 0.0f);
  state_.assign(state, 0.0f);
  setup_blocks(rest, setup);

  scratch_stride_ = forest ? soa::forest_scratch_floats(max_n) : soa::scratch_floats(max_n);
  scratch_.assign(scratch_stride_ * static_cast<std::size_t>(threads), 0.0f);
  backup_stride_ = state_floats(max_n);
  backup_.assign(backup_stride_ * static_cast<std::size_t>(threads), 0.0f);
  prev_tmp_.assign(static_cast<std::size_t>(max_n) * static_cast<std::size_t>(threads), Vec4f::Zero());
  write_.assign(blocks_.size() * W, 0);
  substep_.assign(static_cast<std::size_t>(substeps_), soa::Substep{});
  forest_substep_.assign(static_cast<std::size_t>(substeps_) + 1, soa::ForestSubstep{});
  head_hist_[0] = head_hist_[1] = Affine3f::Identity();
  spheres_.reserve(static_cast<std::size_t>(substeps_) * 16 * 4);
  spring_scale_.assign(region_.size() * static_cast<std::size_t>(substeps_), 1.0f);
  strand_begin_.assign(rest.strand_offsets.begin(), rest.strand_offsets.end() - 1);
  pos_ = rest.positions;
  sleep_.reset(rest.strand_count());
}

bool HalenFusedModel::start_from(std::span<const Vec4f> positions) {
  start_positions(positions, pos_);
  if (model_ == Model::Forest) {
    start_forest();
    return true;
  }
  const bool cascade = model_ == Model::Cascade;
  for (const BlockInfo& b : blocks_) {
    float* st = state_.data() + b.state;
    const std::size_t rows = static_cast<std::size_t>(b.n) * W;
    for (int l = 0; l < W; ++l)
      for (int i = 0; i < b.n; ++i)
        for (int c = 0; c < 3; ++c) {
          const std::size_t at = static_cast<std::size_t>(i) * W + static_cast<std::size_t>(l);
          st[(soa::PX + c) * rows + at] = pos_[b.offset_of[l] + static_cast<std::size_t>(i)][c];
          st[(soa::QX + c) * rows + at] = cascade ? 0.0f : st[(soa::PX + c) * rows + at];  // at rest
        }
  }
  return true;
}

// The forest's joint angles that pose pos_ (forest_rest on it, as the reference does),
// their rates 0.
void HalenFusedModel::start_forest() {
  const auto axes = forest_frame_.parent_x ? k::ForestAxes::ParentX : k::ForestAxes::ParentZ;
  std::vector<k::Mat3f> frames(pos_.size());
  std::vector<float> theta(pos_.size()), phi(pos_.size()), lengths(pos_.size());
  for (std::size_t s = 0; s < strand_begin_.size(); ++s) {
    const std::size_t b = strand_begin_[s], e = s + 1 < strand_begin_.size() ? strand_begin_[s + 1] : pos_.size();
    k::forest_rest(std::span<const Vec4f>(pos_).subspan(b, e - b), axes, std::span(frames).subspan(b, e - b),
                   std::span(theta).subspan(b, e - b), std::span(phi).subspan(b, e - b),
                   std::span(lengths).subspan(b, e - b));
  }
  for (const BlockInfo& b : blocks_) {
    float* st = state_.data() + b.state;
    const std::size_t rows = static_cast<std::size_t>(b.n) * W;
    for (int l = 0; l < W; ++l)
      for (int i = 0; i < b.n; ++i) {
        const std::size_t at = static_cast<std::size_t>(i) * W + static_cast<std::size_t>(l);
        const std::size_t v = b.offset_of[l] + static_cast<std::size_t>(i);
        st[soa::TH * rows + at] = theta[v];
        st[soa::PH * rows + at] = phi[v];
        st[soa::DTH * rows + at] = st[soa::DPH * rows + at] = 0.0f;
      }
  }
}

// Fills every block's fields and initial state (the hair at rest), with the per-strand
// set-up the reference models use.
void HalenFusedModel::setup_blocks(const Groom& rest, const Setup& setup) {
  const std::size_t nv = rest.vertex_count();
  const bool spring = model_ == Model::Spring, forest = model_ == Model::Forest;
  const std::vector<float> rest_length = rest_edge_lengths(rest);
  std::vector<float> k_up(nv), k_down(nv), lift(nv), theta0(nv), phi0(nv), length(nv), inv_mass(nv), lever(nv);
  std::vector<int> base(nv);
  std::vector<k::Mat3f> space(spring ? 0 : nv);  // cascade: rest tangent spaces; forest: rest frames
  std::vector<Vec3f> up_local(spring ? 0 : nv), down_local(spring ? 0 : nv);
  const auto axes = forest && setup.forest.parent_z_axes ? k::ForestAxes::ParentZ : k::ForestAxes::ParentX;
  forest_frame_.parent_x = axes == k::ForestAxes::ParentX;
  forest_frame_.mass_inertia = forest && setup.forest.mass_inertia;
  forest_frame_.gravity_compensation = forest && setup.forest.gravity_compensation;
  forest_root_angular_ = forest && setup.forest.root_angular_acceleration;
  forest_rest_ = {};
  forest_rest_.hold = forest && !forest_frame_.mass_inertia && setup.forest.rest_hold;
  if (!spring && !forest) {
    cascade_frames_ = static_cast<k::CascadeFrames>(setup.frames);
    cascade_reactions_ = setup.reactions;
  }
  inv_length_.assign(rest.strand_count(), 0.0f);
  for (std::size_t s = 0; s < rest.strand_count(); ++s) {
    const std::size_t b = rest.strand_begin(s), n = rest.strand_size(s);
    const Setup::RegionSetup& r = setup.regions[rest.strand_region[s]];
    const auto strand_rest = std::span(rest.positions).subspan(b, n);
    const float c = r.falloff_scale;
    const int a = r.falloff_exponent;
    auto at = [&](auto& v) { return std::span(v).subspan(b, n); };
    if (spring)
      k::spring_setup(strand_rest, r.stiffness, c, a, at(k_up), at(lift));
    else if (!forest)
      k::cascade_setup(strand_rest, r.stiffness, c, a, r.down_fraction, cascade_frames_, at(inv_mass), at(k_up),
                       at(k_down), at(lift), at(base), at(lever), at(space), at(up_local), at(down_local));
    else
      inv_length_[s] = k::forest_setup(strand_rest, axes, r.stiffness, c, a,
                                       at(space), at(theta0), at(phi0), at(length), at(k_up));
  }
  const bool cascade = !spring && !forest;
  if (forest_rest_.hold) {
    forest_rest_.positions = rest.positions;
    forest_rest_.length = length;
    forest_rest_.k = k_up;
    forest_rest_.strand_offsets = rest.strand_offsets;
  }
  for (const BlockInfo& b : blocks_) {
    float* d = data_.data() + b.offset;
    float* st = state_.data() + b.state;
    const std::size_t rows = static_cast<std::size_t>(b.n) * W;
    auto row = [&](float* base, int field, int i, int l) -> float& {
      return base[field * rows + static_cast<std::size_t>(i) * W + static_cast<std::size_t>(l)];
    };
    for (int l = 0; l < W; ++l) {
      if (forest) d[static_cast<std::size_t>(soa::kForestFields) * rows + l] = inv_length_[b.source[l]];
      for (int i = 0; i < b.n; ++i) {
        const std::size_t v = b.offset_of[l] + static_cast<std::size_t>(i);
        const Vec4f& p0 = rest.positions[v];
        if (forest) {
          for (int c = 0; c < 3; ++c) row(d, soa::FRX + c, i, l) = p0[c];
          row(d, soa::FIW, i, l) = p0.w();
          row(d, soa::FLEN, i, l) = length[v];
          row(d, soa::FTH0, i, l) = theta0[v];
          row(d, soa::FPH0, i, l) = phi0[v];
          row(d, soa::FK, i, l) = k_up[v];
          for (int c = 0; c < 3; ++c)
            for (int e = 0; e < 3; ++e) row(d, soa::FR0 + 3 * c + e, i, l) = space[v](e, c);
          row(st, soa::TH, i, l) = theta0[v];
          row(st, soa::PH, i, l) = phi0[v];
          continue;
        }
        for (int c = 0; c < 3; ++c) {  // the hair starts at rest (the cascade's last steps: 0)
          row(st, soa::PX + c, i, l) = p0[c];
          row(st, soa::QX + c, i, l) = cascade ? 0.0f : p0[c];
        }
        row(d, soa::RX, i, l) = p0.x();
        row(d, soa::RY, i, l) = p0.y();
        row(d, soa::RZ, i, l) = p0.z();
        row(d, soa::IW, i, l) = p0.w();
        row(d, soa::RL, i, l) = rest_length[v];
        row(d, soa::LIFT, i, l) = lift[v];
        row(d, soa::KU, i, l) = k_up[v];
        if (spring) continue;
        row(d, soa::KD, i, l) = k_down[v];
        for (int c = 0; c < 3; ++c) {
          row(d, soa::UX + c, i, l) = up_local[v][c];
          row(d, soa::DX + c, i, l) = down_local[v][c];
        }
        row(d, soa::BS, i, l) = base[v] < 0 ? 0.0f : static_cast<float>(i - base[v]);
        row(d, soa::LV, i, l) = lever[v];
        if (i == 0) {  // the given space at the root, column by column
          float* root = d + static_cast<std::size_t>(soa::kCascadeFields) * rows;
          for (int c = 0; c < 3; ++c)
            for (int e = 0; e < 3; ++e) root[(3 * c + e) * W + l] = space[v](e, c);
        }
      }
    }
  }
}

std::size_t HalenFusedModel::state_bytes() const {
  return (data_.size() + state_.size()) * sizeof(float) + pos_.size() * sizeof(Vec4f);
}

// The next block's fields, state and output lines, for the kernel to request while this
// block computes (soa::LineFeed).
void HalenFusedModel::feed_block(const BlockInfo& b, k::soa::LineFeed& feed) const {
  feed.clear();
  feed.add(data_.data() + b.offset, block_floats(b.n) * sizeof(float));
  feed.add(state_.data() + b.state, state_floats(b.n) * sizeof(float));
  for (int l = 0; l < W; ++l)
    if (b.strand[l] != kNoStrand) feed.add(pos_.data() + b.offset_of[l], b.n * sizeof(Vec4f));
}

void HalenFusedModel::run_thread(int t) {
  ThreadState& ts = threads_[static_cast<std::size_t>(t)];
  float* scratch = scratch_.data() + scratch_stride_ * static_cast<std::size_t>(t);
  float* backup = backup_.data() + backup_stride_ * static_cast<std::size_t>(t);
  float* out = pos_.data()->data();
  k::soa::LineFeed feed;
  for (std::size_t i = ts.first; i < ts.last; ++i) {
    const BlockInfo& b = blocks_[i];
    std::uint8_t* write = write_.data() + i * W;
    int awake = 0, asleep = 0;
    for (int l = 0; l < W; ++l) {
      const bool real = b.strand[l] != kNoStrand;
      const bool sleeps = real && calm_ && sleep_.asleep(b.strand[l]);
      write[l] = real && !sleeps;
      awake += write[l];
      asleep += sleeps;
    }
    if (awake == 0) continue;  // every strand of the block sleeps
    if (i + 1 < ts.last)
      feed_block(blocks_[i + 1], feed);
    else
      feed.clear();
    float* state = state_.data() + b.state;
    const std::size_t floats = state_floats(b.n);
    if (asleep > 0) std::copy_n(state, floats, backup);
    const Region& r = region_[b.region];
    const soa::BlockParams p{r.keep, r.length_iterations,
                             spring_scale_.data() + static_cast<std::size_t>(b.region) * substep_.size(),
                             cascade_reactions_, cascade_frames_ == k::CascadeFrames::Transport};
    const soa::Block block{data_.data() + b.offset, state, b.n, b.offset_of.data(), row_kinds_.data() + b.rows, write};
    std::int64_t* stage_ns = b.sampled ? ts.stage_ns.data() : nullptr;
    const auto start = std::chrono::steady_clock::now();
    if (model_ == Model::Forest)
      forest_kernel_(block, r.forest, forest_frame_, out, scratch, feed, stage_ns);
    else
      kernel_(model_, block, p, frame_, out, scratch, feed, stage_ns);
    if (b.sampled)
      ts.sampled_ns +=
          std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now() - start).count();
    if (asleep == 0) continue;
    // A sleeping strand is not touched: its lane's state is put back.
    for (int l = 0; l < W; ++l)
      if (b.strand[l] != kNoStrand && !write[l])
        for (std::size_t k = static_cast<std::size_t>(l); k < floats; k += W) state[k] = backup[k];
  }
}

// StrandSleep::observe for every awake strand of this thread's blocks, with the previous
// positions gathered from the block (the last substep's, as the reference's prev; the
// cascade's last steps for observe_steps); the forest's angular speeds for observe_speed.
void HalenFusedModel::observe_sleep(int t, float dt) {
  const ThreadState& ts = threads_[static_cast<std::size_t>(t)];
  Vec4f* prev = prev_tmp_.data() + prev_tmp_.size() / threads_.size() * static_cast<std::size_t>(t);
  for (std::size_t i = ts.first; i < ts.last; ++i) {
    const BlockInfo& b = blocks_[i];
    const float* st = state_.data() + b.state;
    const std::size_t rows = static_cast<std::size_t>(b.n) * W;
    for (int l = 0; l < W; ++l) {
      const std::uint32_t s = b.strand[l];
      if (s == kNoStrand || sleep_.asleep(s)) continue;
      if (model_ == Model::Forest) {
        // A bound on the fastest vertex, as halen_forest_ref: every joint's angular speed
        // acting over the whole strand length.
        float omega = 0.0f;
        for (int v = 0; v < b.n; ++v) {
          const std::size_t k = static_cast<std::size_t>(v) * W + static_cast<std::size_t>(l);
          omega += std::abs(st[soa::DTH * rows + k]) + std::abs(st[soa::DPH * rows + k]);
        }
        sleep_.observe_speed(s, omega / inv_length_[s]);
        continue;
      }
      for (int v = 0; v < b.n; ++v) {
        const std::size_t k = static_cast<std::size_t>(v) * W + static_cast<std::size_t>(l);
        prev[v] = Vec4f(st[soa::QX * rows + k], st[soa::QY * rows + k], st[soa::QZ * rows + k], 0.0f);
      }
      const std::size_t n = static_cast<std::size_t>(b.n);
      if (model_ == Model::Cascade)
        sleep_.observe_steps(s, std::span<const Vec4f>(prev, n), dt);
      else
        sleep_.observe(s, std::span<const Vec4f>(pos_).subspan(strand_begin_[s], n), std::span<const Vec4f>(prev, n), dt);
    }
  }
}

// The forest's per-substep head poses, root inertia and colliders, and the final pose.
void HalenFusedModel::forest_substeps(const FrameInput& in, float dt) {
  const std::size_t nc = in.colliders.size();
  // Grows only when a scene has more colliders than any before (reserved for 16).
  if (spheres_.size() < nc * 4 * substep_.size()) spheres_.resize(nc * 4 * substep_.size());
  for (int i = 1; i <= substeps_ + 1; ++i) {
    const bool last = i > substeps_;
    const Affine3f head =
        last ? in.head : interpolate_head(in.head_prev, in.head, static_cast<float>(i) / static_cast<float>(substeps_));
    soa::ForestSubstep& s = forest_substep_[static_cast<std::size_t>(i - 1)];
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c) s.m[3 * r + c] = head.linear()(r, c);
      s.t[r] = head.translation()[r];
    }
    if (last) break;
    const k::Mat34f inertia = k::root_inertia(head, head_hist_[1], head_hist_[0], dt);
    const Vec3f angular =
        forest_root_angular_ ? k::head_angular_acceleration(head, head_hist_[1], head_hist_[0], dt) : Vec3f::Zero();
    head_hist_[0] = head_hist_[1];
    head_hist_[1] = head;
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 4; ++c) s.inertia[4 * r + c] = inertia(r, c);
    for (int r = 0; r < 3; ++r) s.root_angular[r] = angular[r];
    float* sp = spheres_.data() + static_cast<std::size_t>(i - 1) * nc * 4;
    write_spheres(in.colliders.first(nc), head, sp);
    s.spheres = sp;
    s.sphere_count = static_cast<int>(nc);
  }
  set_block_frame(forest_frame_, forest_substep_, substeps_, in, in.wind.active());
  forest_frame_.dt = dt;
}

// As halen_forest_ref: gravity reaches the model with the first frame, so the strands' J
// is raised there, and again only if it changes; each block's gain row is rewritten.
void HalenFusedModel::hold_rest(const Vec3f& gravity) {
  ForestRest& fr = forest_rest_;
  fr.gravity = gravity;
  if (!fr.hold) return;
  const std::size_t strands = fr.strand_offsets.size() - 1;
  std::vector<float> gain(strands);
  auto hold = [&](std::size_t begin, std::size_t end) {
    for (std::size_t s = begin; s < end; ++s) {
      const std::size_t b = fr.strand_offsets[s], n = fr.strand_offsets[s + 1] - b;
      gain[s] = inv_length_[s] / k::forest_rest_inertia_scale(std::span<const Vec4f>(fr.positions).subspan(b, n),
                                                              std::span<const float>(fr.length).subspan(b, n),
                                                              std::span<const float>(fr.k).subspan(b, n),
                                                              inv_length_[s], gravity, k::kForestRestMargin);
    }
  };
  if (ctx_.pool)
    ctx_.pool->parallel_for(strands, hold);
  else
    hold(0, strands);
  for (const BlockInfo& b : blocks_) {
    const std::size_t rows = static_cast<std::size_t>(b.n) * W;
    for (int l = 0; l < W; ++l) data_[b.offset + static_cast<std::size_t>(soa::kForestFields) * rows + l] = gain[b.source[l]];
  }
}

void HalenFusedModel::step(const FrameInput& in, StageTimes& times) {
  const bool forest = model_ == Model::Forest;
  if (forest && in.gravity != forest_rest_.gravity) hold_rest(in.gravity);
  calm_ = sleep_.begin_step(in, ctx_.skip_inert);
  if (calm_ && sleep_.all_asleep()) {
    // Every strand sleeps: nothing runs. The forest's head has been still for
    // kQuietFrames frames, so head_hist_ already holds it.
    if (forest)
      for (Stage stage : {Stage::Pose, Stage::Integrate}) times.skip(stage);
    else
      for (Stage stage : {Stage::References, Stage::Integrate, Stage::Length, Stage::Collision}) times.skip(stage);
    return;
  }
  const FramePlan plan = plan_frame(in, ctx_);
  const auto start = std::chrono::steady_clock::now();
  const float dt = static_cast<float>(in.dt) / static_cast<float>(substeps_);
  if (forest) forest_substeps(in, dt);
  const std::size_t nc = plan.collision ? in.colliders.size() : 0;
  // Grows only when a scene has more colliders than any before (reserved for 16).
  if (spheres_.size() < nc * 4 * substep_.size()) spheres_.resize(nc * 4 * substep_.size());
  // §4.4: "z is the up vector, z_h the up vector of the head" — up is against gravity.
  const Vec3f up = in.gravity.squaredNorm() > 0.0f ? Vec3f(-in.gravity.normalized()) : Vec3f::UnitY();
  // The head's up: the up of its rest orientation, turned by the head.
  const Vec3f rest_gravity = in.gravity_at_rest();
  const Vec3f rest_up = rest_gravity.squaredNorm() > 0.0f ? Vec3f(-rest_gravity.normalized()) : Vec3f::UnitY();
  for (int i = 1; i <= substeps_ && !forest; ++i) {
    const Affine3f head = interpolate_head(in.head_prev, in.head, static_cast<float>(i) / static_cast<float>(substeps_));
    soa::Substep& s = substep_[static_cast<std::size_t>(i - 1)];
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c) s.m[3 * r + c] = head.linear()(r, c);
      s.t[r] = head.translation()[r];
    }
    s.dt2 = dt * dt;
    if (model_ == Model::Cascade) {  // as halen_cascade_ref's substep
      const k::Mat3f head_rotation = head.linear();
      const Vec3f head_gravity = head_rotation * in.gravity_at_rest();
      for (int c = 0; c < 3; ++c) s.hg[c] = head_gravity[c];
    }
    float* sp = spheres_.data() + static_cast<std::size_t>(i - 1) * nc * 4;
    write_spheres(in.colliders.first(nc), head, sp);
    s.spheres = sp;
    s.sphere_count = static_cast<int>(nc);
    if (model_ == Model::Spring) {
      const Vec3f head_up = head.linear() * rest_up;
      for (std::size_t r = 0; r < region_.size(); ++r)
        spring_scale_[r * substep_.size() + static_cast<std::size_t>(i - 1)] =
            k::tilt_factor(up, head_up, region_[r].tilt_min);
    }
  }
  set_block_frame(frame_, substep_, substeps_, in, plan.wind);  // no wind, no wind term

  clear_stage_clocks(threads_);
  for_each_block_thread(ctx_.pool, threads_.size(), [this](int t) { run_thread(t); });

  // Per-stage times without a clock read per stage per block: the sampled blocks time
  // their stages; each stage's share of their time, times the step's wall time, is the
  // stage's time.
  const double wall_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  const SampledStageTimes stages(threads_, wall_ms);
  auto report = [&](Stage stage, bool ran) { stages.report(times, stage, ran); };

  if (forest) {
    report(Stage::Pose, true);
    report(Stage::Integrate, true);
  } else {
    report(Stage::References, true);
    report(Stage::Integrate, true);
    report(Stage::Length, true);
    report(Stage::Collision, plan.collision);
  }
  if (calm_) {
    StageTimer t(times, Stage::Sleep);
    for_each_block_thread(ctx_.pool, threads_.size(), [this, dt](int t) { observe_sleep(t, dt); });
    sleep_.end_observe();
  }
}

std::unique_ptr<HairModel> make(Model model, const ModelContext& ctx) {
  return std::make_unique<HalenFusedModel>(model, ctx);
}

}  // namespace hairbench::halen_fused
