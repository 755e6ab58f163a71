// The per-frame metrics of a model whose positions live on a device, computed there
// (docs/metrics.md, Where the metrics are computed): a kernel reduces each strand to the
// few numbers of StrandMetrics, in float, and the harness adds the strands in strand
// order in double (reports/device_metrics.h), so that positions need not come back to the
// host every frame.
#pragma once

#include "core/types.h"

#include <cstdint>
#include <span>
#include <vector>

namespace hairbench {

// What the kernel needs of the rest groom, uploaded once (reports/device_metrics.h
// device_rest builds it from metrics::RestInfo).
struct DeviceMetricsRest {
  std::vector<Vec4f> rest;  // per vertex: rest position (head rest frame), xyz
  // Per vertex: x the rest length of the edge ending there (length_error), y its strand's
  // edge scale, z the rest shape's kb change d0 and w its jaggedness weight (0 or 1).
  std::vector<Vec4f> edge;
  std::vector<std::uint32_t> strand_offsets;
  // The positions the first frame's velocities start from: the rest groom under the
  // first frame's starting head transform.
  std::vector<Vec4f> start;
  float far = 0.0f;  // blowup_reason's distance from the head centre
};

// One frame's inputs besides the positions.
struct DeviceMetricsFrame {
  Affine3f head;   // rest -> world at the end of the frame (rest_shape_error)
  Affine3f carry;  // head * head_prev^-1 (relative kinetic energy)
  Vec3f gravity;
  float dt = 0.0f;
  std::span<const Vec4f> spheres;  // world xyz, w radius (penetration)
  // The reference's positions where they are on the host (a CPU reference, or one on
  // another device); empty where the kernel reads them on its device (read_reference).
  std::span<const Vec4f> reference;
};

// One strand's share of every metric (docs/metrics.md), in float. The layout is the
// kernel's (kernels/vulkan/metrics_layout.h, checked there).
struct StrandMetrics {
  float deviation2;   // sum |p - q|^2 over the strand's vertices (deviation_vs_reference)
  float jaggedness;   // J_s
  float length2;      // sum of e^2 over its edges (length_error)
  float length_max;   // its largest e
  std::uint32_t length_worst;  // that edge, by its second vertex's index in the strand; 0 when length_max is 0
  float rest2;        // sum |p - H p0|^2 (rest_shape_error)
  float penetration;  // max(0, max over spheres and vertices of r - |p - c|)
  float energy;       // sum of 1/2 |v|^2 - g.p (mechanical_energy)
  float kinetic;      // sum |p - carry prev|^2 (verdict::relative_kinetic_energy)
  // blowup_reason: the first vertex of the strand (its index in the strand) that is not
  // finite (kNonFinite) or farther than `far` from the head centre (kFar); kSane if none.
  std::uint32_t bad_vertex;
  std::uint32_t bad_kind;
  std::uint32_t pad;
  static constexpr std::uint32_t kSane = 0, kNonFinite = 1, kFar = 2;
};

// A model's metrics kernel (HairModel::device_metrics). After measure(), the kernel's
// copy of the previous frame's positions is this frame's.
class DeviceMetrics {
 public:
  virtual ~DeviceMetrics() = default;
  // Once per run, before the first measure().
  virtual void prepare(const DeviceMetricsRest& rest) = 0;
  // Reads the reference's positions on the device where `reference` lives on the same
  // device (true), so that measure() takes no reference positions; false otherwise.
  virtual bool read_reference(const DeviceMetrics& reference) = 0;
  // The frame's metrics per strand, valid until the next call.
  virtual std::span<const StrandMetrics> measure(const DeviceMetricsFrame& frame) = 0;
  // Keeps the current positions on the device (the most violent frame's snapshot), and
  // brings what was kept to the host.
  virtual void keep() = 0;
  virtual std::span<const Vec4f> kept() = 0;
};

}  // namespace hairbench
