#include "scenarios/phases.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>

namespace hairbench {

namespace {

std::string fmt(const char* f, double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, f, v);
  return buf;
}

// "x", "y", "z" for a coordinate axis, else the vector.
std::string axis_name(const Vec3f& a) {
  static constexpr const char* kPositive[] = {"x", "y", "z"};
  static constexpr const char* kNegative[] = {"-x", "-y", "-z"};
  for (int i = 0; i < 3; ++i)
    if (std::abs(std::abs(a[i]) - 1.0f) < 1e-6f) return a[i] < 0 ? kNegative[i] : kPositive[i];
  return "(" + fmt("%.2g", a.x()) + ", " + fmt("%.2g", a.y()) + ", " + fmt("%.2g", a.z()) + ")";
}

double deg(double rad) { return rad * 180.0 / std::numbers::pi; }

void add(std::vector<Phase>& out, double start, double end, double duration, std::string kind, std::string label) {
  start = std::max(start, 0.0);
  end = std::min(end, duration);
  if (end > start) out.push_back({start, end, std::move(kind), std::move(label)});
}

std::string move_label(const HeadKey& a, const HeadKey& b) {
  std::string label;
  const double dist = (b.translate - a.translate).norm();
  if (dist > 0.0) label = "move " + fmt("%.3g", dist) + " m";
  if (a.axis == b.axis && a.angle != b.angle) {
    if (!label.empty()) label += ", ";
    label += "turn " + fmt("%.4g", deg(b.angle - a.angle)) + "° about " + axis_name(a.axis);
  } else if (a.axis != b.axis) {
    if (!label.empty()) label += ", ";
    label += "turn to " + fmt("%.4g", deg(b.angle)) + "° about " + axis_name(b.axis);
  }
  return label;
}

}  // namespace

std::vector<Phase> scenario_phases(const Scenario& sc, double duration) {
  std::vector<Phase> out;
  const auto& keys = sc.head.keys;
  for (std::size_t k = 1; k < keys.size(); ++k) {
    const std::string label = move_label(keys[k - 1], keys[k]);
    if (!label.empty()) add(out, keys[k - 1].t, keys[k].t, duration, "move", label);
  }
  for (const Oscillator& o : sc.head.oscillators) {
    const std::string what = o.kind == Oscillator::Kind::Rotate
                                 ? "rotate ±" + fmt("%.3g", deg(o.amplitude)) + "° about " + axis_name(o.axis)
                                 : "translate ±" + fmt("%.3g", o.amplitude) + " m along " + axis_name(o.axis);
    add(out, o.start, o.end, duration, "oscillate", what + " at " + fmt("%.3g", o.frequency_hz) + " Hz");
  }
  // Wind: the spans where the (piecewise linear) strength is non-zero.
  const WindScript& w = sc.wind;
  if (w.keys.empty()) {
    if (w.strength != 0.0) add(out, 0.0, duration, duration, "wind", "wind " + fmt("%.3g", w.strength) + " m/s²");
  } else {
    double peak = 0.0;
    double start = w.keys.front().strength != 0.0 ? 0.0 : NAN;
    for (std::size_t k = 0; k < w.keys.size(); ++k) {
      const auto& key = w.keys[k];
      peak = std::max(peak, std::abs(key.strength));
      const bool on_after = key.strength != 0.0 || (k + 1 < w.keys.size() && w.keys[k + 1].strength != 0.0);
      if (on_after && std::isnan(start)) start = key.t;
      if (!on_after && !std::isnan(start)) {
        add(out, start, key.t, duration, "wind", "wind gust up to " + fmt("%.3g", peak) + " m/s²");
        start = NAN;
        peak = 0.0;
      }
    }
    if (!std::isnan(start)) add(out, start, duration, duration, "wind", "wind up to " + fmt("%.3g", peak) + " m/s²");
  }
  std::stable_sort(out.begin(), out.end(), [](const Phase& a, const Phase& b) { return a.start < b.start; });
  return out;
}

}  // namespace hairbench
