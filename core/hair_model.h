// The interface every hair model implements (docs/architecture.md).
#pragma once

#include "core/groom.h"
#include "core/params.h"
#include "core/stage.h"
#include "core/types.h"

#include <array>
#include <chrono>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>

namespace hairbench {

class ThreadPool;
class DeviceMetrics;

// Wall time per solver stage within one step, in the order the stages were first timed.
// Fixed capacity and no allocation: it is filled inside the timed step.
//
// A stage the scene does not need is not run and is reported through skip(), so the
// report shows it as 0 ms and skipped rather than leaving it out. A stage that ran in
// any substep of the step counts as run.
class StageTimes {
 public:
  struct Entry {
    Stage stage{};
    std::string_view name;  // stage_name(stage)
    double ms = 0.0;
    bool skipped = false;
  };
  void add(Stage stage, double ms) {
    if (Entry* e = find(stage)) {
      e->ms += ms;
      e->skipped = false;
      return;
    }
    entries_[count_++] = {stage, stage_name(stage), ms, false};
  }
  void skip(Stage stage) {
    if (find(stage) == nullptr) entries_[count_++] = {stage, stage_name(stage), 0.0, true};
  }
  void clear() { count_ = 0; }
  std::span<const Entry> entries() const { return {entries_.data(), count_}; }

 private:
  Entry* find(Stage stage) {
    for (std::size_t i = 0; i < count_; ++i)
      if (entries_[i].stage == stage) return &entries_[i];
    return nullptr;
  }
  std::array<Entry, kStageCount> entries_{};  // each stage at most once
  std::size_t count_ = 0;
};

// Times the scope it lives in and adds it to a stage.
class StageTimer {
 public:
  StageTimer(StageTimes& times, Stage stage)
      : times_(times), stage_(stage), start_(std::chrono::steady_clock::now()) {}
  ~StageTimer() {
    const auto end = std::chrono::steady_clock::now();
    times_.add(stage_, std::chrono::duration<double, std::milli>(end - start_).count());
  }
  StageTimer(const StageTimer&) = delete;
  StageTimer& operator=(const StageTimer&) = delete;

 private:
  StageTimes& times_;
  Stage stage_;
  std::chrono::steady_clock::time_point start_;
};

// What a model may use besides its input: the harness's worker threads.
struct ModelContext {
  // A constructor rather than an aggregate, so ModelContext{&pool} stays warning-free.
  ModelContext(ThreadPool* p = nullptr, std::string d = {}) : pool(p), device(std::move(d)) {}
  ThreadPool* pool = nullptr;
  std::string device;  // GPU models: --device NAME|INDEX, empty for the default device
  // false runs every stage and term even where it is inert (no colliders, zero wind,
  // zero stiffness) and never lets a strand sleep: the reference that shows skipping
  // does not change the physics, and the "off" side of the skip benchmarks.
  bool skip_inert = true;
};

// Which per-frame stages and terms a step needs, decided once per step from
// its input rather than by multiplying by zero inside the kernels: no colliders -> no
// collision pass; zero wind -> no wind term.
struct FramePlan {
  bool collision = true;
  bool wind = true;
};
inline FramePlan plan_frame(const FrameInput& in, const ModelContext& ctx) {
  return {!ctx.skip_inert || !in.colliders.empty(), !ctx.skip_inert || in.wind.active()};
}

// Where a model runs, for the report (run "backend" and "device").
struct Backend {
  std::string name = "cpu";
  std::string device;  // e.g. the Vulkan device's name; empty on the CPU
};

// TressFX follow hairs laid out on the guides, as scenarios/tfx's FollowHairs holds them
// (tfx.h; the same fields, viewed).
struct FollowHairsView {
  std::span<const std::uint32_t> guide_offsets;   // the guides' strand offsets
  std::span<const std::uint32_t> guide;           // per follow strand: its guide strand
  std::span<const std::uint32_t> anchor;          // per follow strand: the guide vertex orienting its root frame
  std::span<const std::uint32_t> follow_offsets;  // follow strand f: offsets [follow_offsets[f], [f + 1])
  std::span<const Vec3f> offsets;                 // per follow vertex: (tangent, normal, binormal) offset
};

// start_from()'s positions over a model's own: x, y and z from `from`, w kept. Throws
// std::invalid_argument when the counts differ (the caller gave the wrong layout).
void start_positions(std::span<const Vec4f> from, std::span<Vec4f> to);

class HairModel {
 public:
  virtual ~HairModel() = default;
  // Takes the rest groom (head rest frame) and the resolved parameters; the hair starts
  // at rest under the identity head transform.
  virtual void reset(const Groom& rest, const ParamSet& params) = 0;
  // After reset(): the hair starts from `positions` instead, at zero velocity, under the
  // identity head (a strand kicked into a mode shape, docs/truth.md). They are in the
  // simulated groom's layout where simulated_groom() is set, else the groom's; their w is
  // ignored (the rest groom's inverse masses stay). false: the model cannot start from a
  // given state, and the harness reports so; its state is then as reset() left it.
  virtual bool start_from(std::span<const Vec4f> /*positions*/) { return false; }
  // Advances by in.dt. Adds per-stage wall times to out_times.
  virtual void step(const FrameInput& in, StageTimes& out_times) = 0;
  // Same topology as the groom given to reset(): strand s, vertex i, world space.
  virtual std::span<const Vec4f> positions() const = 0;
  virtual Backend backend() const { return {}; }
  // Bytes of state one step reads and writes (positions and every per-vertex array the
  // solver keeps), for the roofline probe of hairbench_bench: a model's step time over
  // the time to stream this many bytes is its roofline_ratio. The default counts the
  // positions twice (current and previous), the least a Verlet model touches.
  virtual std::size_t state_bytes() const { return 2 * positions().size_bytes(); }
  // Device time of the last step() from GPU timestamps (report timing.gpu_ms); nullopt
  // for models that do not run on a GPU.
  virtual std::optional<double> last_gpu_ms() const { return std::nullopt; }
  // Before timing: GPU models run their step with `in` back to back for `seconds` (the
  // pipeline compiled, the clock up) and leave their state as it was; nothing elsewhere.
  virtual void warm_up(const FrameInput& /*in*/, double /*seconds*/) {}
  // Models whose positions live on a device compute the per-frame metrics there
  // (core/device_metrics.h), valid until the next reset(); nullptr: the harness computes
  // them from positions().
  virtual DeviceMetrics* device_metrics() { return nullptr; }
  // Strands the model holds rigid with the head because it cannot represent their pins
  // (a tree grown from the root whose tip is pinned too), counted in the report
  // (runs[].static_strands).
  virtual std::size_t static_strands() const { return 0; }
  // A model that simulates fewer nodes than the groom has vertices and draws the groom
  // from them (Halén & Wester's, §5.5): the groom it simulates and its nodes' positions,
  // whose edges its constraints hold (the stretched verdict reads them; the metrics read
  // positions()). nullptr and empty: the model simulates every groom vertex.
  virtual const Groom* simulated_groom() const { return nullptr; }
  virtual std::span<const Vec4f> simulated_positions() const { return {}; }
  // The parameters the model runs at, after reset(), where the groom changed one it was
  // given (Halén & Wester's nodes, at most a strand's vertices); the report shows these.
  // nullptr: the ones given.
  virtual const ParamSet* run_params() const { return nullptr; }
  // A model that builds TressFX follow hairs from its guides itself (on its device, so
  // that the guides need not come back to the host) takes their layout here, before
  // reset(), and returns true; reset() then takes the guides expanded by the follow hairs.
  // false: the harness rebuilds them on the host (harness/follow_adapter.h).
  virtual bool set_follow_hairs(const FollowHairsView& /*follow*/) { return false; }
  // Why the model cannot go on, once it cannot (a plugin that returned an error or threw
  // across its boundary, or gave positions of the wrong size): the run stops there as
  // diverged with this reason. Empty while the model runs.
  virtual std::string failure() const { return {}; }
};

}  // namespace hairbench
