#include "harness/probe.h"

#include "core/groom.h"
#include "core/parallel.h"
#include "reports/metrics.h"

#include <algorithm>
#include <cmath>

namespace hairbench {

namespace {

// The card's static part from the settled copy: each strand's tip drop along gravity from
// its rest position (strands pinned whole left out), averaged, over the mean strand
// length; and the RMS edge length error.
material::Card material_at_rest(const Groom& groom, std::span<const Vec4f> p, const Vec3f& gravity, double settled) {
  material::Card card;
  card.measured = true;
  card.settle_s = settled;
  const metrics::RestInfo rest(groom);
  card.stretch = metrics::length_error(rest, p).rms;
  const Vec3f down = gravity.squaredNorm() > 0.0f ? Vec3f(gravity.normalized()) : Vec3f::Zero();
  double drop = 0.0;
  for (std::size_t s = 0; s < groom.strand_count(); ++s) {
    const std::uint32_t tip = groom.strand_begin(s + 1) - 1;
    bool free = false;
    for (std::uint32_t v = groom.strand_begin(s); v <= tip; ++v) free = free || groom.positions[v].w() != 0.0f;
    if (!free) continue;
    drop += static_cast<double>((p[tip] - groom.positions[tip]).head<3>().dot(down));
    ++card.strands;
  }
  card.sag = card.strands > 0 ? drop / static_cast<double>(card.strands) / rest.mean_strand_length : material::kNaN;
  return card;
}

double median(std::vector<double> v) {
  if (v.empty()) return material::kNaN;
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2), v.end());
  return v[v.size() / 2];
}

// The pulse: a rotation about a fixed, oblique axis through the head centre, of the angle
// that moves a point at the farthest root plus one strand length by `amplitude` strand
// lengths.
Affine3f pulse_of(const Groom& groom, double mean_length, double amplitude) {
  double reach = 0.0;
  for (std::size_t s = 0; s < groom.strand_count(); ++s)
    reach = std::max(reach, static_cast<double>(groom.positions[groom.strand_begin(s)].head<3>().norm()));
  reach += mean_length;
  const Vec3f axis = Vec3f(1.0f, 2.0f, 3.0f).normalized();
  return Affine3f(Eigen::AngleAxisf(static_cast<float>(amplitude * mean_length / reach), axis));
}

// Each strand's displacement projected on its first one after the pulse: a signed signal
// per strand that holds every mode the pulse excited in it.
void project_on_first(const Groom& groom, std::span<const Vec4f> p, std::span<const Vec4f> q,
                      std::vector<Vec4f>& first, std::vector<std::vector<double>>& x) {
  if (first.empty())
    for (std::size_t v = 0; v < p.size(); ++v) first.push_back(p[v] - q[v]);
  for (std::size_t s = 0; s < groom.strand_count(); ++s) {
    double dot = 0.0;
    for (std::uint32_t v = groom.strand_begin(s); v < groom.strand_begin(s + 1); ++v)
      dot += static_cast<double>((p[v] - q[v]).head<3>().dot(first[v].head<3>()));
    x[s].push_back(dot);
  }
}

// Each strand's slowest mode (strands of different lengths and regions swing at their own
// rates), and the median over the strands of each of sigma and omega.
void card_mode(const std::vector<std::vector<double>>& x, double dt, material::Card& card) {
  std::vector<double> sigma, omega;
  for (const std::vector<double>& xs : x) {
    const material::Mode mode = material::slowest_mode(xs, dt, ProbeSettings::kCardSkipFrames);
    if (!std::isfinite(mode.sigma)) continue;
    sigma.push_back(mode.sigma);
    omega.push_back(mode.omega);
  }
  card.sigma = median(sigma);
  card.omega = median(omega);
}

// The probe's verdict from the kicked copy's distances from the still one, frame by frame.
verdict::Probe probe_of(const std::vector<double>& d, double dt) {
  using S = ProbeSettings;
  auto mean = [](const double* v, int n) {
    double s = 0.0;
    for (int i = 0; i < n; ++i) s += v[i];
    return s / n;
  };
  verdict::Probe probe;
  probe.run = true;
  probe.kick = d.front();
  probe.first = mean(d.data() + 1, S::kWindow);
  probe.last = mean(d.data() + d.size() - S::kWindow, S::kWindow);
  // From the kick itself, not the first window: where a rest edge is rounding-sized, the
  // kick turns it at once and the first frames after it already hold most of the growth.
  const double span = (static_cast<double>(d.size()) - 0.5 * (S::kWindow + 1)) * dt;
  probe.rate = std::log(probe.last / probe.kick) / span;
  // NaN (a kicked copy that blew up) counts as growth.
  probe.grows = !(probe.rate <= S::kMinGrowthRate) && !(probe.last <= S::kMinGrowth * S::kAmplitude);
  return probe;
}

}  // namespace

AtRest probe_at_rest(const ModelInfo& info, const Scenario& sc, const ParamSet& params, ThreadPool& pool,
                     const std::string& device, AtRestParts parts) {
  using S = ProbeSettings;
  AtRest out;
  const Groom& full = sc.follow ? sc.guides : sc.groom;
  const std::size_t every = std::max<std::size_t>(1, (full.strand_count() + S::kMaxStrands - 1) / S::kMaxStrands);
  const Groom groom = every > 1 ? every_nth_strand(full, every) : full;

  ModelContext ctx{&pool, device};
  ctx.skip_inert = false;
  std::unique_ptr<HairModel> still = info.make(ctx);
  const bool gpu = still->backend().name != "cpu";
  if (gpu) out.probe.skipped_why = "runs on a GPU: its CPU implementation of the same method carries the probe";
  else if (!parts.probe) out.probe.skipped_why = "not asked for";
  std::unique_ptr<HairModel> kicked = gpu || !parts.probe ? nullptr : info.make(ctx);
  std::unique_ptr<HairModel> carded = parts.mode ? info.make(ctx) : nullptr;
  still->reset(groom, params);
  if (kicked) kicked->reset(groom, params);
  if (carded) carded->reset(groom, params);

  const double mean_length = mean_strand_length(groom);
  const Affine3f pulse = pulse_of(groom, mean_length, S::kAmplitude);
  const Affine3f card_pulse = pulse_of(groom, mean_length, S::kCardAmplitude);

  FrameInput in;
  in.dt = sc.dt;
  in.gravity = sc.gravity;
  in.colliders = sc.colliders;
  StageTimes times;
  std::vector<double> d;
  std::vector<std::vector<double>> x(groom.strand_count());  // per strand
  std::vector<Vec4f> first;  // the card's displacement right after its pulse
  const int frames = kicked || carded ? S::kSettleFrames + S::kFrames : S::kSettleFrames;
  for (int f = 0; f < frames; ++f) {
    in.frame = f;
    in.t = (f + 1) * sc.dt;
    in.head_prev = in.head = Affine3f::Identity();
    still->step(in, times);
    times.clear();
    const int k = f - S::kSettleFrames;  // frames since the kick began
    if (k == -1) out.card = material_at_rest(groom, still->positions(), sc.gravity, (f + 1) * sc.dt);
    FrameInput kick = in;
    if (k == 0) kick.head = pulse;
    if (k == 1) kick.head_prev = pulse;
    if (kicked) {
      kicked->step(kick, times);
      times.clear();
      if (k >= 1) d.push_back(metrics::deviation(kicked->positions(), still->positions(), mean_length));
    }
    if (!carded) continue;
    if (k == 0) kick.head = card_pulse;
    if (k == 1) kick.head_prev = card_pulse;
    carded->step(kick, times);
    times.clear();
    if (k >= 1) project_on_first(groom, carded->positions(), still->positions(), first, x);
  }
  if (carded) card_mode(x, sc.dt, out.card);
  if (kicked) out.probe = probe_of(d, sc.dt);
  return out;
}

}  // namespace hairbench
