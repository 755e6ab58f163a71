#include "harness/probe.h"

#include "core/groom.h"
#include "core/parallel.h"
#include "reports/metrics.h"

#include <cmath>

namespace hairbench {

verdict::Probe perturbation_probe(const ModelInfo& info, const Scenario& sc, const ParamSet& params,
                                  ThreadPool& pool, const std::string& device) {
  using S = ProbeSettings;
  verdict::Probe out;
  const Groom& full = sc.follow ? sc.guides : sc.groom;
  const std::size_t every = std::max<std::size_t>(1, (full.strand_count() + S::kMaxStrands - 1) / S::kMaxStrands);
  const Groom groom = every > 1 ? every_nth_strand(full, every) : full;

  ModelContext ctx{&pool, device};
  ctx.skip_inert = false;
  std::unique_ptr<HairModel> still = info.make(ctx);
  if (still->backend().name != "cpu") {
    out.skipped_why = "runs on a GPU: its CPU implementation of the same method carries the probe";
    return out;
  }
  std::unique_ptr<HairModel> kicked = info.make(ctx);
  still->reset(groom, params);
  kicked->reset(groom, params);

  // The pulse: a rotation about a fixed, oblique axis through the head centre, of the
  // angle that moves a point at the farthest root plus one strand length by kAmplitude
  // strand lengths.
  const double mean_length = mean_strand_length(groom);
  double reach = 0.0;
  for (std::size_t s = 0; s < groom.strand_count(); ++s)
    reach = std::max(reach, static_cast<double>(groom.positions[groom.strand_begin(s)].head<3>().norm()));
  reach += mean_length;
  const float angle = static_cast<float>(S::kAmplitude * mean_length / reach);
  const Affine3f pulse(Eigen::AngleAxisf(angle, Vec3f(1.0f, 2.0f, 3.0f).normalized()));

  FrameInput in;
  in.dt = sc.dt;
  in.gravity = sc.gravity;
  in.colliders = sc.colliders;
  StageTimes times;
  std::vector<double> d;
  for (int f = 0; f < S::kSettleFrames + S::kFrames; ++f) {
    in.frame = f;
    in.t = (f + 1) * sc.dt;
    in.head_prev = in.head = Affine3f::Identity();
    still->step(in, times);
    times.clear();
    const int k = f - S::kSettleFrames;  // frames since the kick began
    if (k == 0) in.head = pulse;
    if (k == 1) in.head_prev = pulse;
    kicked->step(in, times);
    times.clear();
    if (k >= 1) d.push_back(metrics::deviation(kicked->positions(), still->positions(), mean_length));
  }
  auto mean = [](const double* v, int n) {
    double s = 0.0;
    for (int i = 0; i < n; ++i) s += v[i];
    return s / n;
  };
  out.run = true;
  out.kick = d.front();
  out.first = mean(d.data() + 1, S::kWindow);
  out.last = mean(d.data() + d.size() - S::kWindow, S::kWindow);
  // From the kick itself, not the first window: where a rest edge is rounding-sized, the
  // kick turns it at once and the first frames after it already hold most of the growth.
  const double span = (static_cast<double>(d.size()) - 0.5 * (S::kWindow + 1)) * sc.dt;
  out.rate = std::log(out.last / out.kick) / span;
  // NaN (a kicked copy that blew up) counts as growth.
  out.grows = !(out.rate <= S::kMinGrowthRate) && !(out.last <= S::kMinGrowth * S::kAmplitude);
  return out;
}

}  // namespace hairbench
