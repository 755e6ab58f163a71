#include "models/plante2001/fused/wisp_fused.h"

#include <algorithm>

namespace hairbench::plante {

namespace k = hairbench::kernels;

void PlanteWispModel::prepare(std::size_t threads) {
  // Blocks of the fused schedule: consecutive wisps of one node count and params set
  // (k-means clusters of one region and strand size are consecutive, cluster()). A block
  // costs about as much as 7 wisps through the per-wisp kernels whatever its lanes in
  // use, so it takes runs of at least half its lanes.
  runs_.clear();
  constexpr std::uint32_t lanes = k::wisp_soa::kLanes, kMinBlockLanes = lanes / 2;
  const auto wisps = static_cast<std::uint32_t>(sys_.wisp_count());
  auto size = [&](std::uint32_t w) { return sys_.node_begin[w + 1] - sys_.node_begin[w]; };
  for (std::uint32_t w = 0; w < wisps;) {
    std::uint32_t n = 0;
    while (n < lanes && w + n < wisps && k::wisp_soa::block_eligible(sys_, w + n) && size(w + n) == size(w) &&
           sys_.wisp_params[w + n] == sys_.wisp_params[w])
      ++n;
    if (n < kMinBlockLanes) n = 1;
    runs_.push_back({w, n});
    w += n;
  }

  // The threads' shares of the runs, of about equal cost rather than equal counts: a
  // wisp through the per-wisp kernels costs about a seventh of a block (above), and such
  // wisps gather where the groom has them (where they lie mostly at the end of the list,
  // equal counts of runs would leave most of the integration to one thread).
  constexpr std::uint64_t kBlockCost = 7;
  std::vector<std::uint64_t> cost_before(runs_.size() + 1, 0);
  for (std::size_t i = 0; i < runs_.size(); ++i)
    cost_before[i + 1] = cost_before[i] + (runs_[i].count > 1 ? kBlockCost : 1) * size(runs_[i].first);
  run_bounds_.assign(threads + 1, runs_.size());
  run_ranges_ = std::vector<RunRange>(threads);
  for (std::size_t t = 0; t < threads; ++t)
    run_bounds_[t] = static_cast<std::size_t>(
        std::lower_bound(cost_before.begin(), cost_before.end() - 1, cost_before.back() * t / threads) -
        cost_before.begin());
  node_sections_.assign(sys_.node_count(), k::NodeSection{});
}

// Stage times inside a fused pass: every kTimingSample-th wisp is timed stage
// by stage, and the pass's measured time is split between the stages in those
// proportions (as the fused Han kernel samples its blocks).
constexpr std::size_t kTimingSample = 8;

void PlanteWispModel::WispClock::lap(int stage) {
  if (!on) return;
  const auto now = std::chrono::steady_clock::now();
  sampled_ns[stage]->fetch_add(std::chrono::duration_cast<std::chrono::nanoseconds>(now - last).count(),
                               std::memory_order_relaxed);
  last = now;
}

namespace {

// A range of runs [front, back) packed as front << 32 | back, taken from either end.
bool take_front(std::atomic<std::uint64_t>& range, std::size_t& i) {
  std::uint64_t cur = range.load(std::memory_order_relaxed);
  for (;;) {
    const std::uint64_t front = cur >> 32, back = cur & 0xffffffffu;
    if (front >= back) return false;
    if (range.compare_exchange_weak(cur, (front + 1) << 32 | back, std::memory_order_relaxed)) {
      i = static_cast<std::size_t>(front);
      return true;
    }
  }
}
bool take_back(std::atomic<std::uint64_t>& range, std::size_t& i) {
  std::uint64_t cur = range.load(std::memory_order_relaxed);
  for (;;) {
    const std::uint64_t front = cur >> 32, back = cur & 0xffffffffu;
    if (front >= back) return false;
    if (range.compare_exchange_weak(cur, front << 32 | (back - 1), std::memory_order_relaxed)) {
      i = static_cast<std::size_t>(back - 1);
      return true;
    }
  }
}

}  // namespace

template <class F>
void PlanteWispModel::wisp_pass(StageTimes& times, F&& f) {
  for (auto& ns : sampled_ns_) ns.store(0, std::memory_order_relaxed);
  const auto start = std::chrono::steady_clock::now();
  // Each thread takes the runs of its range (run_bounds_, of about equal estimated
  // cost) from the front; one that runs out takes the other ranges' runs from their back
  // (the body contacts gather on some wisps, so equal estimated costs can still leave one
  // thread far busier than the other). A thread keeps nearly the same wisps
  // from step to step, in its cache, and which thread steps a wisp changes no bits.
  const std::size_t parts = run_bounds_.size() - 1;
  for (std::size_t p = 0; p < parts; ++p)
    run_ranges_[p].range.store(static_cast<std::uint64_t>(run_bounds_[p]) << 32 | run_bounds_[p + 1],
                               std::memory_order_relaxed);
  for_each(parts, [&](std::size_t part_begin, std::size_t part_end) {
    WispClock clock;
    clock.sampled_ns = {&sampled_ns_[0], &sampled_ns_[1]};
    auto run = [&](std::size_t i) {
      clock.on = i % kTimingSample == 0;
      if (clock.on) clock.last = std::chrono::steady_clock::now();
      f(runs_[i], clock);
    };
    for (std::size_t p = part_begin; p < part_end; ++p) {
      std::size_t i;
      while (take_front(run_ranges_[p].range, i)) run(i);
      for (std::size_t other = 1; other < parts; ++other)
        while (take_back(run_ranges_[(p + other) % parts].range, i)) run(i);
    }
  });
  const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  const double integration = static_cast<double>(sampled_ns_[kIntegration].load(std::memory_order_relaxed));
  const double bodies = static_cast<double>(sampled_ns_[kBody].load(std::memory_order_relaxed));
  const double share = integration + bodies > 0.0 ? bodies / (integration + bodies) : 0.0;
  times.add(Stage::Integrate, ms * (1.0 - share));
  if (bodies > 0.0) times.add(Stage::BodyCollision, ms * share);
}

std::size_t PlanteWispModel::block_wisps() const {
  std::size_t n = 0;
  for (const WispRun& run : runs_) n += run.count > 1 ? run.count : 0;
  return n;
}

// §5.1 per wisp, root to tip inside the kernels: (1) forces and (3) velocities, the
// bodies' velocity modifications, then (4) positions and the bodies' position
// modifications. A wisp's stages touch only its own masses, so each wisp goes through
// them in one pass while it is in cache; the wisp-wisp response, which reads every wisp,
// splits the pass in two on the steps that detect. Same operations in the same order per
// wisp as the per-stage schedule (plante_wisp_ref): bit-identical.
void PlanteWispModel::integrate(const StepInput& s, StageTimes& times) {
  const k::wisp_soa::BodyLanes body_lanes(s.body);
  auto velocities = [&](const WispRun& run, WispClock& clock) {
    const k::WispParams& p = params_[sys_.wisp_params[run.first]];
    for (std::uint32_t w = run.first; w < run.first + run.count; ++w) k::wisp_pin(sys_, w, s.head, s.h);
    if (run.count == 1) {
      k::wisp_forces_and_velocities(sys_, run.first, p, s.head_rot, s.in.gravity, s.in.wind, s.h);
    } else {
      std::array<std::uint32_t, k::wisp_soa::kLanes> ids;
      for (std::uint32_t l = 0; l < run.count; ++l) ids[l] = run.first + l;
      block_.velocities(sys_, ids.data(), static_cast<int>(run.count), p, s.head_rot, s.in.gravity, s.in.wind, s.h);
    }
    clock.lap(kIntegration);
    if (s.body_on) {
      block_.body_slide(sys_, run.first, run.count, body_lanes, s.drag);
      clock.lap(kBody);
    }
  };
  auto positions = [&](const WispRun& run, WispClock& clock) {
    std::array<Vec3f, k::wisp_soa::kLanes> root_e1;
    for (std::uint32_t l = 0; l < run.count; ++l) root_e1[l] = s.head_rot * sys_.rest_e1[run.first + l];
    if (run.count == 1) {
      k::wisp_positions(sys_, run.first, root_e1[0], s.h);
    } else {
      std::array<std::uint32_t, k::wisp_soa::kLanes> ids;
      for (std::uint32_t l = 0; l < run.count; ++l) ids[l] = run.first + l;
      block_.positions(sys_, ids.data(), static_cast<int>(run.count), root_e1.data(), s.h);
    }
    clock.lap(kIntegration);
    if (s.body_on) {
      block_.body_hold(sys_, run.first, run.count, body_lanes);
      if (s.body_due) {
        // The block kernel records the contacts of the wisps with no mass inside a body
        // (nearly all); the per-wisp kernel moves the others' masses out.
        std::uint32_t inside = ~0u;
        if (run.count > 1) {
          std::array<std::uint32_t, k::wisp_soa::kLanes> ids;
          for (std::uint32_t l = 0; l < run.count; ++l) ids[l] = run.first + l;
          inside = block_.body_detect(sys_, ids.data(), static_cast<int>(run.count), body_lanes,
                                      interaction_.contact_threshold);
        }
        for (std::uint32_t l = 0; l < run.count; ++l) {
          if (inside >> l & 1u)
            k::wisp_body_detect(sys_, run.first + l, s.body, root_e1[l], interaction_.contact_threshold);
          k::wisp_body_list(sys_, run.first + l);
        }
      }
      clock.lap(kBody);
    }
  };
  if (s.interact) {
    wisp_pass(times, velocities);
    {
      StageTimer t(times, Stage::SelfInteraction);
      detect_self_interactions();
      respond_to_contacts(static_cast<float>(1.0 / interaction_hz_));
    }
    wisp_pass(times, positions);
  } else {
    wisp_pass(times, [&](const WispRun& run, WispClock& clock) {
      velocities(run, clock);
      positions(run, clock);
    });
  }
}

void PlanteWispModel::build_cells(std::size_t threads) {
  // The cells' loops over the segments on the threads (serial, they would take about an
  // eighth of a detection's time on shake at 2 threads).
  k::grid_frame(grid_, threads);
  const std::size_t parts = grid_.part_begin.size() - 1;
  auto over_parts = [&](auto step) {
    for_each(parts, [&](std::size_t pb, std::size_t pe) {
      for (std::size_t p = pb; p < pe; ++p) step(grid_, p);
    });
  };
  over_parts(k::grid_count);
  k::grid_offsets(grid_);
  over_parts(k::grid_fill);
}

void PlanteWispModel::narrow_phase(std::size_t, std::size_t begin, std::size_t end, std::vector<k::WispContact>& out) {
  block_.contacts(grid_, sys_, begin, end, out);
}

void PlanteWispModel::respond_to_contacts(float h) {
  // k::wisp_contacts_respond in its two parts (ContactImpulse): the impulses over ranges
  // of contacts (by the lane kernel, from the nodes' rows), then each thread sums them, in
  // list order, on its own nodes' masses.
  const std::size_t count = contacts_.size();
  if (count == 0) return;
  impulses_.resize(count);
  const auto nodes = static_cast<std::uint32_t>(sys_.x.size());
  contact_nodes_.resize(nodes);
  for_each(nodes, [&](std::size_t begin, std::size_t end) {
    k::wisp_soa::contact_nodes(sys_, params_, begin, end, contact_nodes_.data());
  });
  for_each(count, [&](std::size_t begin, std::size_t end) {
    block_.impulses(sys_, contact_nodes_.data(), contacts_, begin, end, interaction_, params_, h, impulses_.data());
  });
  // The threads' node ranges hold about equal contacts, not equal nodes: contacts gather
  // where the hair is dense (on model 1, equal nodes would give one thread about 5 times
  // as many contacts to sum as the other). A chunk's
  // contacts each touch a node of its own segments (the tested mass's or the volume's),
  // so the ranges are cut at the chunks that split the list evenly. Any cut gives the
  // same sums.
  const std::size_t parts = threads_, chunks = chunk_offset_.size() - 1;
  node_bounds_.assign(parts + 1, nodes);
  node_bounds_[0] = 0;
  for (std::size_t c = 0, p = 1; c < chunks && p < parts; ++c)
    while (p < parts && chunk_offset_[c + 1] * parts >= count * p)
      node_bounds_[p++] = chunk_bounds_[c + 1] < grid_.size() ? grid_.seg[chunk_bounds_[c + 1]] : nodes;
  for_each(parts, [&](std::size_t pb, std::size_t pe) {
    for (std::size_t p = pb; p < pe; ++p)
      k::wisp_contacts_apply(sys_, contacts_, impulses_, node_bounds_[p], node_bounds_[p + 1]);
  });
}

// Each node's part of the section frames once, then a strand's points 16 vertices at a
// time (§5.2); the same bits as plante_wisp_ref's point by point.
void PlanteWispModel::prepare_sections(const Eigen::Matrix3f& head_rot) {
  for_each(sys_.node_count(), [&](std::size_t begin, std::size_t end) {
    for (std::size_t n = begin; n < end; ++n)
      node_sections_[n] = k::node_section(sys_, static_cast<std::uint32_t>(n), head_rot);
  });
}

void PlanteWispModel::section_points(std::size_t strand, const Eigen::Matrix3f&) {
  const std::uint32_t vb = rest_.strand_begin(strand), n = rest_.strand_size(strand);
  if (n > 0)
    block_.strand_points(sys_, node_sections_.data(), &vertex_node_[vb], &coord_[vb], n, &strand_points_[vb],
                         &strand_weights_[vb]);
}

std::unique_ptr<HairModel> make_fused(const ModelContext& ctx) { return std::make_unique<PlanteWispModel>(ctx); }

}  // namespace hairbench::plante
