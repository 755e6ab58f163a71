#include "reports/verdict.h"

#include "reports/chunked.h"

#include <algorithm>
#include <cmath>

namespace hairbench::verdict {

std::string_view status_name(Status s) {
  switch (s) {
    case Status::ok: return "ok";
    case Status::stretched: return "stretched";
    case Status::deformed: return "deformed";
    case Status::unstable: return "unstable";
    case Status::diverged: return "diverged";
  }
  return "ok";
}

void StretchTracker::add(int frame, const metrics::LengthError& e) {
  if (!(e.max <= kStretchLimit)) {  // NaN counts: the edge is not within the limit
    if (!s_.frames_above++) s_.first_above = frame;
  }
  if (e.max > s_.peak || (s_.peak_frame < 0 && std::isfinite(e.max))) {
    s_.peak = e.max;
    s_.peak_frame = frame;
    s_.worst_strand = e.worst_strand;
    s_.worst_edge = e.worst_edge;
  }
}

void SettleCheck::add(double t, double energy, bool driven, double settle_from) {
  if (driven || t < settle_from - 1e-9) return;
  t_.push_back(t);
  e_.push_back(energy);
}

void SettleCheck::add_past_end(double t, double energy) {
  t_.push_back(t);
  e_.push_back(energy);
  ++extra_;
}

EnergySpread energy_spread(std::span<const double> per_strand) {
  EnergySpread out;
  double total = 0.0;
  for (double e : per_strand) total += e;
  if (!(total > 0.0) || !std::isfinite(total)) return out;
  std::vector<std::uint32_t> order(per_strand.size());
  for (std::uint32_t s = 0; s < order.size(); ++s) order[s] = s;
  // Largest first; ties by index, so the answer does not depend on the sort.
  std::sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) {
    return per_strand[a] != per_strand[b] ? per_strand[a] > per_strand[b] : a < b;
  });
  out.strands = per_strand.size();
  out.strand = order[0];
  out.share = per_strand[order[0]] / total;
  double held = 0.0;
  for (std::uint32_t s : order) {
    held += per_strand[s];
    ++out.strands_for_90;
    if (held >= 0.9 * total) break;
  }
  return out;
}

Settle SettleCheck::result() const {
  Settle s;
  s.frames = static_cast<int>(e_.size());
  s.extra_frames = extra_;
  s.spread = spread_;
  if (s.frames < kMinFrames) return s;
  const std::size_t half = e_.size() / 2;
  auto mean = [](const std::vector<double>& v, std::size_t b, std::size_t e) {
    double sum = 0.0;
    for (std::size_t i = b; i < e; ++i) sum += v[i];
    return sum / static_cast<double>(e - b);
  };
  s.energy_first = mean(e_, 0, half);
  s.energy_second = mean(e_, e_.size() - half, e_.size());
  const double span = mean(t_, e_.size() - half, e_.size()) - mean(t_, 0, half);
  s.rate = std::log(s.energy_second / s.energy_first) / span;
  const double peak_first = *std::max_element(e_.begin(), e_.begin() + static_cast<std::ptrdiff_t>(half));
  const double peak_second = *std::max_element(e_.end() - static_cast<std::ptrdiff_t>(half), e_.end());
  s.peak_rate = std::log(peak_second / peak_first) / span;
  const double floor = 0.5 * kRestSpeed * kRestSpeed;
  // NaN energy (a non-finite state) fails the comparisons and so counts as not decaying.
  s.decays = s.energy_second < floor || (s.rate <= -kMinDecayRate && s.peak_rate <= -kMinDecayRate);
  return s;
}

void ReturnTracker::add(double t, double distance) {
  t_.push_back(t);
  d_.push_back(distance);
}

void ReturnTracker::set_worst(std::uint32_t strand, double distance) {
  worst_strand_ = strand;
  worst_ = distance;
}

Return ReturnTracker::result() const {
  Return r;
  r.frames = static_cast<int>(d_.size());
  if (d_.empty()) {
    r.skipped_why = "no settle window (the head moves or wind blows to the end)";
    return r;
  }
  r.measured = true;
  r.first = d_.front();
  r.last = d_.back();
  r.worst_strand = worst_strand_;
  r.worst = worst_;
  // Least squares slope of ln(distance); a zero distance (a model that sleeps into its
  // twin's state) has no logarithm and leaves the rate at 0.
  double st = 0, sl = 0, stt = 0, stl = 0;
  int n = 0;
  for (std::size_t i = 0; i < d_.size(); ++i) {
    if (!(d_[i] > 0.0) || !std::isfinite(d_[i])) continue;
    const double l = std::log(d_[i]);
    st += t_[i];
    sl += l;
    stt += t_[i] * t_[i];
    stl += t_[i] * l;
    ++n;
  }
  const double den = n * stt - st * st;
  if (n >= 2 && den > 0.0) r.rate = (n * stl - st * sl) / den;
  // NaN (a state that is not finite) is not within the limit.
  r.deformed = !(r.last <= Return::kLimit);
  return r;
}

METRIC_CLONES double relative_kinetic_energy(std::span<const Vec4f> p, std::span<const Vec4f> prev,
                                             const Affine3f& head, const Affine3f& head_prev, double dt) {
  // Hair carried rigidly by the head scores 0, so a walk's steady translation is not
  // motion of the hair; a whip is. Each vertex's |p - carry prev|^2 in float as Eigen's
  // Affine3f product and Vector3f squaredNorm compute it, written out in their order
  // (t + ((m0 a + m1 b) + m2 c), x^2 + (y^2 + z^2)) so that the terms vectorise; added in
  // vertex order: the same bits.
  const Affine3f carry = head * head_prev.inverse();
  const Eigen::Matrix3f m = carry.linear();
  const Vec3f t = carry.translation();
  double sum = 0.0;
  metrics::chunked(
      0, p.size(),
      [&](std::size_t i) {
        const float a = prev[i].x(), b = prev[i].y(), c = prev[i].z();
        const float qx = t.x() + ((m(0, 0) * a + m(0, 1) * b) + m(0, 2) * c);
        const float qy = t.y() + ((m(1, 0) * a + m(1, 1) * b) + m(1, 2) * c);
        const float qz = t.z() + ((m(2, 0) * a + m(2, 1) * b) + m(2, 2) * c);
        const float dx = p[i].x() - qx, dy = p[i].y() - qy, dz = p[i].z() - qz;
        return static_cast<double>(dx * dx + (dy * dy + dz * dz));
      },
      [&](double term) { sum += term; });
  return p.empty() ? 0.0 : sum / (2.0 * dt * dt * static_cast<double>(p.size()));
}

Verdict decide(const std::optional<std::pair<int, double>>& stop, const std::string& diverged, const Stretch& stretch,
               const Settle& settle, const Probe& probe, const Return& back, double dt) {
  Verdict v;
  v.stretch = stretch;
  v.settle = settle;
  v.probe = probe;
  v.back = back;
  char buf[200];
  if (stop) {
    v.status = Status::diverged;
    v.reason = diverged;
    v.frame = stop->first;
    v.t = stop->second;
  } else if (probe.run && probe.grows) {
    v.status = Status::unstable;
    std::snprintf(buf, sizeof buf, "a perturbation at rest grows at %.3g/s (%.2g -> %.2g mean strand lengths)",
                  probe.rate, probe.kick, probe.last);
    v.reason = buf;
  } else if (!settle.decays) {
    v.status = Status::unstable;
    std::snprintf(buf, sizeof buf,
                  "motion does not decay with the head still: kinetic energy %.3g -> %.3g m^2/s^2 (%.3g/s)",
                  settle.energy_first, settle.energy_second, settle.rate);
    v.reason = buf;
    if (settle.extra_frames > 0) {
      std::snprintf(buf, sizeof buf, " over %.3g s, %.3g s of them past the scenario's end", settle.frames * dt,
                    settle.extra_frames * dt);
      v.reason += buf;
    }
  } else if (back.measured && back.deformed) {
    v.status = Status::deformed;
    std::snprintf(buf, sizeof buf,
                  "does not return: %.3g mean strand lengths (RMS) from where it rests with the head held still at "
                  "this pose, strand %u %.3g; ",
                  back.last, back.worst_strand, back.worst);
    v.reason = buf;
    if (back.rate < 0.0)
      std::snprintf(buf, sizeof buf, "coming back at %.3g/s (e-folding time %.3g s) over the last %.3g s", back.rate,
                    -1.0 / back.rate, back.frames * dt);
    else
      std::snprintf(buf, sizeof buf, "not coming back (%.3g/s over the last %.3g s)", back.rate, back.frames * dt);
    v.reason += buf;
  } else if (stretch.frames_above > 0) {
    v.status = Status::stretched;
    std::snprintf(buf, sizeof buf, "edge length error %.3g (strand %u, edge %u%s) above %.2g in %d frames",
                  stretch.peak, stretch.worst_strand, stretch.worst_edge,
                  stretch.pinned_end ? ", between a free and a pinned vertex" : "", kStretchLimit,
                  stretch.frames_above);
    v.reason = buf;
    v.frame = stretch.peak_frame;
    v.t = (stretch.peak_frame + 1) * dt;
  }
  // Where the motion that outlasted the scenario is, whichever detector found it.
  if (v.status == Status::unstable && settle.spread.strands > 0) {
    const char* what = settle.spread.guides ? "guide" : "strand";
    std::snprintf(buf, sizeof buf, "; %s in %zu of %zu %ss%s, %.3g%% in %s %u",
                  settle.decays ? "past the scenario's end, 90% of the motion" : "90% of it",
                  settle.spread.strands_for_90, settle.spread.strands, what,
                  settle.spread.guides ? " (with their follow hairs)" : "", 100.0 * settle.spread.share, what,
                  settle.spread.strand);
    v.reason += buf;
  }
  return v;
}

namespace {
nlohmann::json num(double x) { return std::isfinite(x) ? nlohmann::json(x) : nlohmann::json(nullptr); }
}  // namespace

nlohmann::json verdict_json(const Verdict& v) {
  nlohmann::json j = {{"class", status_name(v.status)},
                      {"reason", v.reason},
                      {"frame", v.frame >= 0 ? nlohmann::json(v.frame) : nlohmann::json(nullptr)},
                      {"t", v.frame >= 0 ? num(v.t) : nlohmann::json(nullptr)},
                      {"stretch",
                       {{"limit", kStretchLimit},
                        {"peak", num(v.stretch.peak)},
                        {"peak_frame", v.stretch.peak_frame},
                        {"worst_strand", v.stretch.worst_strand},
                        {"worst_edge", v.stretch.worst_edge},
                        {"frames_above", v.stretch.frames_above},
                        {"first_above",
                         v.stretch.first_above >= 0 ? nlohmann::json(v.stretch.first_above) : nlohmann::json(nullptr)},
                        {"pinned_end", v.stretch.pinned_end}}},
                      {"settle",
                       {{"frames", v.settle.frames},
                        {"extra_frames", v.settle.extra_frames},
                        {"energy_first", num(v.settle.energy_first)},
                        {"energy_second", num(v.settle.energy_second)},
                        {"rate", num(v.settle.rate)},
                        {"peak_rate", num(v.settle.peak_rate)},
                        {"decays", v.settle.decays},
                        {"spread", v.settle.spread.strands == 0
                                       ? nlohmann::json(nullptr)
                                       : nlohmann::json{{"strands", v.settle.spread.strands},
                                                        {"strands_for_90", v.settle.spread.strands_for_90},
                                                        {"strand", v.settle.spread.strand},
                                                        {"guides", v.settle.spread.guides},
                                                        {"share", num(v.settle.spread.share)}}}}}};
  if (v.back.measured)
    j["return"] = {{"limit", Return::kLimit},
                   {"frames", v.back.frames},
                   {"twin_frames", v.back.twin_frames},
                   {"first", num(v.back.first)},
                   {"last", num(v.back.last)},
                   {"rate", num(v.back.rate)},
                   {"worst_strand", v.back.worst_strand},
                   {"worst", num(v.back.worst)},
                   {"deformed", v.back.deformed}};
  else
    j["return"] = {{"skipped", v.back.skipped_why}};
  if (v.probe.run)
    j["probe"] = {{"kick", num(v.probe.kick)},
                  {"first", num(v.probe.first)},
                  {"last", num(v.probe.last)},
                  {"growth_rate", num(v.probe.rate)},
                  {"grows", v.probe.grows}};
  else
    j["probe"] = {{"skipped", v.probe.skipped_why}};
  return j;
}

}  // namespace hairbench::verdict
