// The lockstep runner: every selected model steps through the same scenario frame by
// frame with the identical FrameInput; metrics are taken after each step against the
// reference model's positions of the same frame (docs/architecture.md).
#pragma once

#include "core/params.h"
#include "harness/param_resolution.h"
#include "models/registry.h"
#include "reports/report.h"
#include "scenarios/scenario.h"

#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace hairbench {

class ThreadPool;
class AtRestCache;

struct RunOptions {
  std::vector<std::string> models;  // to report, in order
  std::string reference = "";       // empty: the scenario's reference
  int frames = 0;                   // > 0 overrides the scenario's frame count
  std::vector<ParamOverride> overrides;
  // Applied after `overrides` to the reference only (--reference converged) ...
  std::vector<ParamOverride> reference_overrides;
  // ... and to the reported models only (a sweep's knob value, recorded as `knob`). A
  // reported model shares the reference's lane only when its parameters come out equal.
  std::vector<ParamOverride> model_overrides;
  std::optional<RunRecord::Knob> knob;
  // Called after every frame with (frames done, frames), for progress displays.
  std::function<void(int, int)> on_frame;
  // When set, filled with what the runs share: phases, snapshot frames and strands, and
  // the reference's snapshots.
  ScenarioRecord* scenario_record = nullptr;
  // With scenario_record: record the frames of report.html's player (reports/animation.h).
  bool animation = false;
  std::string device;  // GPU models' --device (empty: the default device)
  // Each lane's perturbation probe at rest (harness/probe.h), for the `unstable`
  // verdict; a model whose probe grows never sleeps. Off only where a test or benchmark
  // needs bare steps.
  bool probe = true;
  // Each lane's rest twin (harness/twin.h), for the `deformed` verdict. Off only where a
  // test or benchmark needs bare steps, or a caller reads no verdict but the
  // self-excited classes.
  bool twin = true;
  // Where set, the probes and twins come from it (harness/at_rest_cache.h): scenarios
  // that ask for the same copies at rest step them once. The cache must outlive the run
  // and not the scenarios.
  AtRestCache* at_rest = nullptr;
  // Each lane's material card (reports/material.h: the probe's third, harder-kicked copy
  // for the mode; sag and stretch cost nothing extra). Off where no report shows it
  // (stress cells), and then `--calibrate` has no target.
  bool material_card = true;
  // --calibrate (harness/calibrate.h): each reported model but the reference runs with its
  // stiffness and damping fitted so that its material card matches the reference's.
  // Parameters given in `overrides` or `model_overrides` are not fitted.
  bool calibrate = false;
  // false (--no-skip): models run every stage even where it is inert and no strand
  // sleeps (ModelContext::skip_inert), to show what skipping saves and that it changes
  // nothing else.
  bool skip_inert = true;
  // true: every model's metrics are computed on the host from its positions, as they are
  // for the CPU models, also where a model could compute them on its device
  // (HairModel::device_metrics); so does HAIRBENCH_VK_HOST_METRICS=1. Report runs[].metrics_on.
  bool host_metrics = false;
};

// A model ready to step the scenario: made, given the follow hairs to rebuild from the
// guides when the scenario asks for it (a Vulkan model builds them on the device; any
// other is wrapped in a FollowHairsAdapter), and reset to the groom with `params`.
std::unique_ptr<HairModel> make_model(const ModelInfo& info, const Scenario& sc, const ParamSet& params,
                                      ThreadPool& pool, const std::string& device = "", bool skip_inert = true);
// The input of frame f: the head script evaluated at both ends of the step.
FrameInput frame_input(const Scenario& sc, int f);

// How long a GPU model steps back to back before its steps are timed (HairModel::warm_up):
// long enough for a GPU's clock to come up from idle (docs/vulkan.md, Timing).
inline constexpr double kGpuWarmUpSeconds = 0.2;
// Device time of each of the scenario's first `frames` steps of a freshly reset GPU model,
// stepped back to back after a warm-up, each followed by positions() (as BM_HanVk does):
// the device time that does not depend on what runs beside the model.
std::vector<double> back_to_back_gpu_ms(HairModel& model, const Scenario& sc, int frames);

// The reference setting `--reference converged`: the default reference at the settings
// at which it is its own converged solution (ModelInfo::converged), so that every model's
// deviation from it is an absolute error (the reference's own included).
inline constexpr const char* kConvergedReference = "converged";
std::vector<ParamOverride> converged_overrides(const ModelInfo& model);


// The groom strands the strand pictures show: every k-th strand, at most
// kMaxSnapshotStrands of them.
std::vector<std::uint32_t> snapshot_strands(const Groom& groom);

// Runs one scenario; a model that diverges stops there (RunRecord::failure) and the
// others go on; every run ends with its verdict (reports/verdict.h). A GPU model is warmed
// up before its first step, and after the lockstep run a fresh copy steps the same frames
// back to back for its device time (RunRecord::gpu_ms). Every run records
// the scenario's two snapshot frames:
// the most violent one, where the reference's kinetic energy per unit mass relative to
// the head, mean |p(t) - H(t) H(t-dt)^-1 p(t-dt)|^2 / (2 dt^2), is highest (the first such
// frame), and the final one. Throws InputError for bad parameters.
std::vector<RunRecord> run_scenario(const Scenario& scenario, const RunOptions& options, ThreadPool& pool);

}  // namespace hairbench
