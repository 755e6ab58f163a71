#include "models/han2012/fused/han_fused.h"

#include "core/parallel.h"
#include "kernels/han2012/reference/han_kernels.h"
#include "models/han2012/settings.h"

#include <algorithm>
#include <chrono>
#include <numeric>

namespace hairbench::han_fused {

namespace soa = hairbench::kernels::han_soa;
constexpr int W = soa::kLanes;

// One job in this many (and the first job of every region) times its stages.
constexpr std::size_t kSampleEvery = 16;

HanFusedModel::HanFusedModel(han::Method method, const ModelContext& ctx)
    : method_(method), ctx_(ctx), kernel_(soa::frame_kernel()) {}

void HanFusedModel::reset(const Groom& rest, const ParamSet& params) {
  const std::vector<float> rest_length = rest_edge_lengths(rest);
  const std::size_t regions = rest.region_names.size();

  // Per-region settings; a region's `method` (§6: a cheaper method as level of detail)
  // overrides the model's own.
  region_.clear();
  std::vector<int> region_method;
  bool any_frames = false;
  const han::Settings settings = han::read_settings(params, regions);
  for (const han::RegionSettings& given : settings.regions) {
    soa::BlockParams p{};
    p.keep = 1.0f - given.damping;
    p.global_stiffness = given.global_stiffness;
    p.global_ramp = given.global_ramp;
    // A pass whose stiffness or reach is 0 changes nothing and is not run (unless
    // ModelContext::skip_inert is off, the reference for that claim).
    p.global_on = !ctx_.skip_inert || (p.global_stiffness != 0.0f && given.global_range != 0.0f);
    p.local_stiffness = given.local_stiffness;
    p.local_iterations = !ctx_.skip_inert || p.local_stiffness != 0.0f ? given.local_iterations : 0;
    p.length_iterations = given.length_iterations;
    // global_reach depends on the strand's vertex count: set per block below.
    p.global_reach = given.global_range;
    region_.push_back(p);
    region_method.push_back(given.method != 0 ? given.method : static_cast<int>(method_));
    any_frames = any_frames || region_method.back() != 3;
  }
  substeps_ = settings.substeps;

  // Rest frames (Algorithm 2) with the per-strand kernel, for methods 1 and 2, and
  // method 2's frames across rounding-sized rest edges.
  std::vector<Quatf> rest_rotation, rest_relative;
  std::vector<Vec3f> rest_local;
  std::vector<std::uint8_t> rounding_sized;
  if (any_frames) {
    rest_rotation.assign(rest.vertex_count(), Quatf::Identity());
    rest_local.assign(rest.vertex_count(), Vec3f::Zero());
    rest_relative.assign(rest.vertex_count(), Quatf::Identity());
    rounding_sized.assign(rest.vertex_count(), 0);
    for (std::size_t s = 0; s < rest.strand_count(); ++s) {
      const std::size_t b = rest.strand_begin(s), n = rest.strand_size(s);
      kernels::init_rest_frames(std::span(rest.positions).subspan(b, n), std::span(rest_rotation).subspan(b, n),
                                std::span(rest_local).subspan(b, n));
      kernels::init_rounding_sized_frames(std::span(rest_length).subspan(b, n),
                                          std::span<const Vec3f>(rest_local).subspan(b, n),
                                          std::span(rounding_sized).subspan(b, n),
                                          std::span(rest_relative).subspan(b, n));
    }
  }

  // Blocks: strands of one region and one vertex count, kLanes at a time (ragged grooms
  // give one partly filled block per (region, count); its idle lanes repeat a strand of
  // the block and are never written back).
  std::vector<std::uint32_t> order(rest.strand_count());
  std::iota(order.begin(), order.end(), 0u);
  std::stable_sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) {
    if (rest.strand_region[a] != rest.strand_region[b]) return rest.strand_region[a] < rest.strand_region[b];
    return rest.strand_size(a) < rest.strand_size(b);
  });
  blocks_.clear();
  std::vector<std::array<std::uint32_t, W>> lanes;
  std::size_t floats = 0;
  for (std::size_t i = 0; i < order.size();) {
    const std::uint16_t region = rest.strand_region[order[i]];
    const int n = static_cast<int>(rest.strand_size(order[i]));
    std::size_t j = i;
    while (j < order.size() && j - i < static_cast<std::size_t>(W) && rest.strand_region[order[j]] == region &&
           static_cast<int>(rest.strand_size(order[j])) == n)
      ++j;
    BlockInfo b{};
    b.offset = floats;
    b.n = n;
    b.method = region_method[region];
    b.region = region;
    std::array<std::uint32_t, W> strands{};
    for (int l = 0; l < W; ++l) {
      const bool used = i + static_cast<std::size_t>(l) < j;
      strands[l] = order[used ? i + l : j - 1];
      b.out_offset[l] = used ? rest.strand_begin(strands[l]) : soa::kNoStrand;
      b.in_offset[l] = rest.strand_begin(strands[l]);
      b.strand[l] = used ? strands[l] : soa::kNoStrand;
    }
    floats += soa::block_floats(b.method, n);
    blocks_.push_back(b);
    lanes.push_back(strands);
    i = j;
  }

  data_.assign(floats, 0.0f);
  row_kinds_.clear();
  rounding_rows_.clear();
  int max_n = 0;
  any_global_ = any_local_ = any_length_ = false;
  for (std::size_t k = 0; k < blocks_.size(); ++k) {
    const BlockInfo& b = blocks_[k];
    const soa::BlockParams& p = region_[b.region];
    any_global_ = any_global_ || p.global_on;
    any_local_ = any_local_ || p.local_iterations > 0;
    any_length_ = any_length_ || p.length_iterations > 0;
    max_n = std::max(max_n, b.n);
    const std::size_t rows = static_cast<std::size_t>(b.n) * W;
    float* d = data_.data() + b.offset;
    auto at = [&](int field, int i, int l) -> float& { return d[field * rows + static_cast<std::size_t>(i) * W + l]; };
    blocks_[k].row_kinds = row_kinds_.size();
    for (int i = 0; i < b.n; ++i) {
      int pinned = 0;
      for (int l = 0; l < W; ++l) pinned += rest.positions[rest.strand_begin(lanes[k][l]) + i].w() == 0.0f;
      row_kinds_.push_back(pinned == 0 ? soa::kRowFree : pinned == W ? soa::kRowPinned : soa::kRowMixed);
    }
    // Method 2's rows with a rounding-sized rest edge in some lane (local_shape_m2 reads
    // vertices 2 and up).
    blocks_[k].rounding_first = rounding_rows_.size();
    for (int i = 2; b.method == 2 && i < b.n; ++i) {
      soa::RoundingRow e{};
      e.row = i;
      bool any = false;
      for (int l = 0; l < W; ++l) {
        const std::size_t v = rest.strand_begin(lanes[k][l]) + static_cast<std::size_t>(i);
        const Quatf& q = rest_relative[v];
        any = any || rounding_sized[v] != 0;
        e.on[l] = rounding_sized[v] != 0 ? 1.0f : 0.0f;
        e.qx[l] = q.x();
        e.qy[l] = q.y();
        e.qz[l] = q.z();
        e.qw[l] = q.w();
      }
      if (any) rounding_rows_.push_back(e);
    }
    blocks_[k].rounding_count = static_cast<int>(rounding_rows_.size() - b.rounding_first);
    for (int l = 0; l < W; ++l) {
      const std::size_t v0 = rest.strand_begin(lanes[k][l]);
      for (int i = 0; i < b.n; ++i) {
        const Vec4f& p0 = rest.positions[v0 + i];
        for (int c = 0; c < 3; ++c) {
          at(soa::QX + c, i, l) = p0[c];
          at(soa::RX + c, i, l) = p0[c];
        }
        at(soa::RL, i, l) = rest_length[v0 + i];
        if (b.method == 3) continue;
        for (int c = 0; c < 3; ++c) at(soa::LX + c, i, l) = rest_local[v0 + i][c];
        if (b.method == 2) {  // method 2's frames start at the rest frames
          const Quatf& q = rest_rotation[v0 + i];
          at(soa::OW, i, l) = q.w();
          at(soa::OX, i, l) = q.x();
          at(soa::OY, i, l) = q.y();
          at(soa::OZ, i, l) = q.z();
        }
      }
      if (b.method == 1) {
        float* frames = d + static_cast<std::size_t>(soa::field_count(b.method)) * rows;
        for (int v = 0; v < 2; ++v) {
          const Quatf& q = rest_rotation[v0 + static_cast<std::size_t>(v)];
          frames[(4 * v + 0) * W + l] = q.w();
          frames[(4 * v + 1) * W + l] = q.x();
          frames[(4 * v + 2) * W + l] = q.y();
          frames[(4 * v + 3) * W + l] = q.z();
        }
      }
    }
  }
  pos_ = rest.positions;

  // Jobs: blocks in pairs where two consecutive ones share region and vertex count.
  jobs_.clear();
  for (std::size_t k = 0; k < blocks_.size();) {
    const bool pair = k + 1 < blocks_.size() && blocks_[k + 1].region == blocks_[k].region &&
                      blocks_[k + 1].n == blocks_[k].n;
    const bool first_of_region = jobs_.empty() || blocks_[jobs_.back().first].region != blocks_[k].region;
    jobs_.push_back({k, pair ? 2 : 1, jobs_.size() % kSampleEvery == 0 || first_of_region});
    k += pair ? 2 : 1;
  }

  // Static partition of the jobs over the threads by estimated cost (vertices times
  // passes over them), fixed at reset: which thread runs a block never changes a bit of
  // its result, so any thread count gives the same state.
  const int threads = ctx_.pool ? ctx_.pool->threads() : 1;
  std::vector<double> cost(jobs_.size());
  double total = 0.0;
  for (std::size_t j = 0; j < jobs_.size(); ++j) {
    const BlockInfo& b = blocks_[jobs_[j].first];
    const soa::BlockParams& p = region_[b.region];
    const double local_cost = b.method == 1 ? 4.0 : b.method == 2 ? 4.0 : 1.0;
    cost[j] = jobs_[j].count * b.n * (3.0 + local_cost * p.local_iterations + p.length_iterations);
    total += cost[j];
  }
  threads_.assign(static_cast<std::size_t>(threads), ThreadState{});
  double acc = 0.0;
  std::size_t k = 0;
  for (int t = 0; t < threads; ++t) {
    threads_[t].first = k;
    const double end = total * (t + 1) / threads;
    while (k < jobs_.size() && (t == threads - 1 || acc + 0.5 * cost[k] < end)) acc += cost[k++];
    threads_[t].last = k;
  }
  scratch_stride_ = soa::kMaxBlocks * soa::scratch_floats(max_n);
  std::size_t max_block = 0;
  for (const BlockInfo& b : blocks_) max_block = std::max(max_block, soa::block_floats(b.method, b.n));
  backup_stride_ = soa::kMaxBlocks * max_block;
  backup_.assign(backup_stride_ * static_cast<std::size_t>(threads), 0.0f);
  pos_backup_stride_ = soa::kMaxBlocks * W * static_cast<std::size_t>(max_n);
  pos_backup_.assign(pos_backup_stride_ * static_cast<std::size_t>(threads), Vec4f::Zero());
  prev_tmp_.assign(static_cast<std::size_t>(max_n) * static_cast<std::size_t>(threads), Vec4f::Zero());
  sleep_.reset(rest.strand_count());
  scratch_.assign(scratch_stride_ * static_cast<std::size_t>(threads), 0.0f);
  substep_.assign(static_cast<std::size_t>(substeps_), soa::Substep{});
  spheres_.reserve(static_cast<std::size_t>(substeps_) * 16 * 4);
}

bool HanFusedModel::start_from(std::span<const Vec4f> positions) {
  start_positions(positions, pos_);
  for (const BlockInfo& b : blocks_) {
    const std::size_t rows = static_cast<std::size_t>(b.n) * W;
    float* d = data_.data() + b.offset;
    for (int l = 0; l < W; ++l)
      for (int i = 0; i < b.n; ++i)
        for (int c = 0; c < 3; ++c)
          d[(soa::QX + c) * rows + static_cast<std::size_t>(i) * W + l] = pos_[b.in_offset[l] + i][c];
  }
  return true;
}

std::size_t HanFusedModel::state_bytes() const {
  return data_.size() * sizeof(float) + pos_.size() * sizeof(Vec4f) + rounding_rows_.size() * sizeof(soa::RoundingRow);
}

// The next job's blocks and output lines, for the kernel to request while this job
// computes (soa::LineFeed).
void HanFusedModel::feed_job(const Job& job, kernels::soa::LineFeed& feed) const {
  feed.clear();
  for (int i = 0; i < job.count; ++i) {
    const BlockInfo& b = blocks_[job.first + static_cast<std::size_t>(i)];
    feed.add(data_.data() + b.offset, soa::block_floats(b.method, b.n) * sizeof(float));
    for (int l = 0; l < W; ++l)
      if (b.out_offset[l] != soa::kNoStrand) feed.add(pos_.data() + b.out_offset[l], b.n * sizeof(Vec4f));
  }
}

void HanFusedModel::run_thread(int t) {
  ThreadState& ts = threads_[static_cast<std::size_t>(t)];
  float* pos = pos_.data()->data();
  float* scratch = scratch_.data() + scratch_stride_ * static_cast<std::size_t>(t);
  float* backup = backup_.data() + backup_stride_ * static_cast<std::size_t>(t);
  Vec4f* pos_backup = pos_backup_.data() + pos_backup_stride_ * static_cast<std::size_t>(t);
  // Where sleeper lane l of the job's block i keeps its positions, which the kernel
  // writes back with the rest of the block.
  auto saved_pos = [pos_backup](int i, int l, int n) {
    return pos_backup + (static_cast<std::size_t>(i) * W + static_cast<std::size_t>(l)) * static_cast<std::size_t>(n);
  };
  kernels::soa::LineFeed feed;
  for (std::size_t j = ts.first; j < ts.last; ++j) {
    const Job& job = jobs_[j];
    const BlockInfo& first = blocks_[job.first];
    soa::BlockParams p = region_[first.region];
    p.global_reach = p.global_reach * static_cast<float>(first.n);  // range · n, as global_shape
    soa::Block blocks[soa::kMaxBlocks];
    int asleep = 0, strands = 0;
    for (int i = 0; i < job.count; ++i) {
      const BlockInfo& b = blocks_[job.first + static_cast<std::size_t>(i)];
      blocks[i] = {data_.data() + b.offset, b.n, b.method, b.out_offset.data(), b.in_offset.data(),
                   row_kinds_.data() + b.row_kinds, rounding_rows_.data() + b.rounding_first, b.rounding_count};
      if (!calm_) continue;
      for (std::uint32_t s : b.strand)
        if (s != soa::kNoStrand) {
          ++strands;
          asleep += sleep_.asleep(s);
        }
    }
    if (calm_ && asleep == strands) continue;  // every strand of the job sleeps
    if (asleep > 0)
      for (int i = 0; i < job.count; ++i) {
        const BlockInfo& b = blocks_[job.first + static_cast<std::size_t>(i)];
        std::copy_n(blocks[i].data, soa::block_floats(b.method, b.n), backup + i * backup_stride_ / soa::kMaxBlocks);
        for (int l = 0; l < W; ++l)
          if (b.strand[l] != soa::kNoStrand && sleep_.asleep(b.strand[l]))
            std::copy_n(pos_.data() + b.out_offset[l], b.n, saved_pos(i, l, b.n));
      }
    if (j + 1 < ts.last)
      feed_job(jobs_[j + 1], feed);
    else
      feed.clear();
    if (!job.sampled) {
      kernel_(blocks, job.count, p, frame_, pos, scratch, feed, nullptr);
    } else {
      const auto start = std::chrono::steady_clock::now();
      kernel_(blocks, job.count, p, frame_, pos, scratch, feed, ts.stage_ns.data());
      ts.sampled_ns +=
          std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now() - start).count();
    }
    if (asleep == 0) continue;
    // Put the sleepers' lanes back, every row of every field, and their positions.
    for (int i = 0; i < job.count; ++i) {
      const BlockInfo& b = blocks_[job.first + static_cast<std::size_t>(i)];
      const float* saved = backup + i * backup_stride_ / soa::kMaxBlocks;
      const std::size_t rows = soa::block_floats(b.method, b.n) / W;
      for (int l = 0; l < W; ++l) {
        if (b.strand[l] == soa::kNoStrand || !sleep_.asleep(b.strand[l])) continue;
        for (std::size_t r = 0; r < rows; ++r) blocks[i].data[r * W + l] = saved[r * W + l];
        std::copy_n(saved_pos(i, l, b.n), b.n, pos_.data() + b.out_offset[l]);
      }
    }
  }
}

// StrandSleep::observe for every awake strand of this thread's jobs, with the previous
// positions gathered from the blocks (the last substep's, as the reference's prev).
void HanFusedModel::observe_sleep(int t, float dt) {
  const ThreadState& ts = threads_[static_cast<std::size_t>(t)];
  Vec4f* prev = prev_tmp_.data() + prev_tmp_.size() / threads_.size() * static_cast<std::size_t>(t);
  for (std::size_t j = ts.first; j < ts.last; ++j)
    for (int i = 0; i < jobs_[j].count; ++i) {
      const BlockInfo& b = blocks_[jobs_[j].first + static_cast<std::size_t>(i)];
      const float* d = data_.data() + b.offset;
      const std::size_t nw = static_cast<std::size_t>(b.n) * W;
      for (int l = 0; l < W; ++l) {
        const std::uint32_t s = b.strand[l];
        if (s == soa::kNoStrand || sleep_.asleep(s)) continue;
        for (int v = 0; v < b.n; ++v) {
          const std::size_t k = static_cast<std::size_t>(v) * W + l;
          const float iw = pos_[b.out_offset[l] + static_cast<std::size_t>(v)].w();
          prev[v] = Vec4f(d[soa::QX * nw + k], d[soa::QY * nw + k], d[soa::QZ * nw + k], iw);
        }
        const std::size_t n = static_cast<std::size_t>(b.n);
        sleep_.observe(s, std::span<const Vec4f>(pos_).subspan(b.out_offset[l], n), std::span<const Vec4f>(prev, n), dt);
      }
    }
}

void HanFusedModel::step(const FrameInput& in, StageTimes& times) {
  calm_ = sleep_.begin_step(in, ctx_.skip_inert);
  if (calm_ && sleep_.all_asleep()) {
    // Every strand sleeps: nothing runs.
    for (Stage stage : {Stage::Integrate, Stage::GlobalShape, Stage::LocalShape, Stage::Length, Stage::Collision}) times.skip(stage);
    return;
  }
  const FramePlan plan = plan_frame(in, ctx_);
  const auto start = std::chrono::steady_clock::now();
  const float dt = static_cast<float>(in.dt) / static_cast<float>(substeps_);
  const std::size_t nc = in.colliders.size();
  // Grows only when a scene has more colliders than any before (reserved for 16).
  if (spheres_.size() < nc * 4 * substep_.size()) spheres_.resize(nc * 4 * substep_.size());
  for (int k = 1; k <= substeps_; ++k) {
    const Affine3f head = interpolate_head(in.head_prev, in.head, static_cast<float>(k) / static_cast<float>(substeps_));
    const Quatf q(head.rotation());
    soa::Substep& s = substep_[static_cast<std::size_t>(k - 1)];
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c) s.m[3 * r + c] = head.linear()(r, c);
      s.t[r] = head.translation()[r];
    }
    s.q[0] = q.x();
    s.q[1] = q.y();
    s.q[2] = q.z();
    s.q[3] = q.w();
    s.dt2 = dt * dt;
    const Vec3f gdt2 = in.gravity * s.dt2;
    for (int c = 0; c < 3; ++c) s.gravity_dt2[c] = gdt2[c];
    float* sp = spheres_.data() + static_cast<std::size_t>(k - 1) * nc * 4;
    write_spheres(in.colliders.first(nc), head, sp);
    s.spheres = sp;
    s.sphere_count = static_cast<int>(nc);
  }
  set_block_frame(frame_, substep_, substeps_, in, plan.wind);  // no wind, no wind term

  clear_stage_clocks(threads_);
  for_each_block_thread(ctx_.pool, threads_.size(), [this](int t) { run_thread(t); });

  // Per-stage times without a clock read per stage per block: the sampled blocks (one in
  // kSampleEvery, and each region's first) time their stages; each stage's share of
  // their time, times the step's wall time, is the stage's time. What the shares leave
  // (write-back of the positions, waiting for the other thread) stays untimed.
  const double wall_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  const SampledStageTimes stages(threads_, wall_ms);
  auto report = [&](Stage stage, bool ran) { stages.report(times, stage, ran); };
  report(Stage::Integrate, true);
  report(Stage::GlobalShape, any_global_);
  report(Stage::LocalShape, any_local_);
  report(Stage::Length, any_length_);
  report(Stage::Collision, plan.collision);
  if (calm_) {
    StageTimer t(times, Stage::Sleep);
    for_each_block_thread(ctx_.pool, threads_.size(), [this, dt](int t) { observe_sleep(t, dt); });
    sleep_.end_observe();
  }
}

std::unique_ptr<HairModel> make(han::Method method, const ModelContext& ctx) {
  return std::make_unique<HanFusedModel>(method, ctx);
}

}  // namespace hairbench::han_fused
