// The host's half of the metrics computed on a device (core/device_metrics.h): the rest
// data the kernel takes, and the per-strand values added up into the numbers
// reports/metrics.h computes from positions. Strands are added in index order in double,
// so a result does not depend on how the device scheduled them (docs/metrics.md, Where
// the metrics are computed).
#pragma once

#include "core/device_metrics.h"
#include "reports/metrics.h"

#include <span>
#include <string>

namespace hairbench::metrics {

// The kernel's rest data for `rest`'s groom; `start` is where the first frame's
// velocities start (the runner's `prev` before frame 0).
DeviceMetricsRest device_rest(const RestInfo& rest, std::span<const Vec4f> start);

// Each is its metrics.h namesake over the per-strand values `m` of rest's groom.
double deviation(const RestInfo& rest, std::span<const StrandMetrics> m);
double jaggedness(const RestInfo& rest, std::span<const StrandMetrics> m);
// `m` may be the leading strands of a larger groom (a TressFX scenario's guides), one per
// strand of rest's groom.
LengthError length_error(const RestInfo& rest, std::span<const StrandMetrics> m);
double rest_shape_error(const RestInfo& rest, std::span<const StrandMetrics> m);
// The deepest of the strands m.
double penetration(std::span<const StrandMetrics> m);
std::string blowup_reason(std::span<const StrandMetrics> m);
double mechanical_energy(const RestInfo& rest, std::span<const StrandMetrics> m);
// verdict::relative_kinetic_energy.
double relative_kinetic_energy(const RestInfo& rest, std::span<const StrandMetrics> m, double dt);

}  // namespace hairbench::metrics
