// `muller_ftl`: Müller, Kim & Chentanez 2012, Dynamic Follow-The-Leader (§3-4,
// Algorithm 1), as a hairbench plugin. It talks to the harness only through
// core/include/hairbench/plugin.h; the numerical work is the per-strand kernels of
// kernels/muller2012/ftl_kernels.h. Each substep runs Algorithm 1's three loops as three
// passes over all strands, split by strand through the host's parallel_for (a static
// partition, and strands never read each other, so the bits do not depend on the thread
// count): the prediction and the velocity update are timed as `integrate`, the FTL pass
// with its collisions as `length`.
#include "hairbench/plugin.h"

#include "kernels/muller2012/ftl_kernels.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <exception>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

namespace {

namespace muller = hairbench::kernels::muller;
using hairbench::Affine3f;
using hairbench::Vec3f;
using hairbench::Vec4f;

enum Param : std::size_t { kFtlDamping, kDamping, kSubsteps, kParamCount };

const hb_param_spec kParams[kParamCount] = {
    {"ftl_damping", 0.9, 0.0, 1.0, 0,
     "s_damping (§4, Algorithm 1): the share of the child's FTL correction taken off a vertex's velocity, "
     "dimensionless; the paper reports 0.9. 1 takes the whole correction off, and the strand then swings as "
     "a chain of its masses (docs/truth.md): below 1 the correction is a damping of its own and shifts the "
     "frequencies",
     HB_ROLE_CHAIN_LIMIT, 1.0},
    {"damping", 0.0, 0.0, 1.0, 0,
     "plain velocity damping per substep, v *= 1 - damping, dimensionless (ours, not the paper's)", HB_ROLE_DAMPING,
     0.0},
    {"substeps", 1.0, 1.0, 64.0, 1,
     "DFTL steps per frame, the head interpolated between the frame's ends, count (the base value; regions ignored)",
     HB_ROLE_COST_KNOB, 0.0},
};

// The per-region parameters one strand steps with.
struct RegionParams {
  float s_damping;
  float damping;
};

void write_error(char* err, std::size_t err_size, const char* message) {
  if (err != nullptr && err_size > 0) std::snprintf(err, err_size, "%s", message);
}

[[noreturn]] void fail(const std::string& message) { throw std::invalid_argument(message); }

std::string number(double value) {
  char text[32];
  std::snprintf(text, sizeof text, "%g", value);
  return text;
}

bool all_finite(const float* values, std::size_t count) {
  for (std::size_t i = 0; i < count; ++i)
    if (!std::isfinite(values[i])) return false;
  return true;
}

void check_groom(const hb_groom& g) {
  if (g.strand_count == 0 || g.vertex_count == 0) fail("the groom has no strands or no vertices");
  if (g.strand_offsets == nullptr || g.positions == nullptr) fail("the groom has no strand offsets or no positions");
  if (g.strand_offsets[0] != 0) fail("the groom's first strand offset is not 0");
  for (std::size_t s = 0; s < g.strand_count; ++s)
    if (g.strand_offsets[s + 1] <= g.strand_offsets[s]) fail("strand " + std::to_string(s) + " has no vertices");
  if (g.strand_offsets[g.strand_count] != g.vertex_count)
    fail("the last strand offset is " + std::to_string(g.strand_offsets[g.strand_count]) + ", not vertex_count " +
         std::to_string(g.vertex_count));
  if (!all_finite(g.positions, 4 * g.vertex_count)) fail("the groom has a position that is not finite");
}

void check_value(std::size_t k, double value, const std::string& where) {
  const hb_param_spec& spec = kParams[k];
  const bool whole = spec.integer == 0 || value == std::floor(value);
  if (!(value >= spec.min && value <= spec.max) || !whole)
    fail(std::string(spec.name) + where + " is " + number(value) + ", outside [" + number(spec.min) + ", " +
         number(spec.max) + "]" + (spec.integer != 0 ? " or not whole" : ""));
}

void check_params(const hb_params& p) {
  if (p.count != kParamCount)
    fail("expected " + std::to_string(kParamCount) + " parameters, got " + std::to_string(p.count));
  if (p.base == nullptr || (p.region_count > 0 && p.region_values == nullptr)) fail("the parameter values are missing");
  for (std::size_t k = 0; k < kParamCount; ++k) check_value(k, p.base[k], "");
  for (std::size_t r = 0; r < p.region_count; ++r)
    for (std::size_t k = 0; k < kParamCount; ++k)
      check_value(k, p.region_values[r * kParamCount + k], " of region " + std::to_string(r));
}

// Every strand's region must have a row of parameters (none: all take the base values).
void check_regions(const hb_groom& g, const hb_params& p) {
  if (p.region_count == 0) return;
  if (g.strand_region == nullptr) fail("the parameters have regions but the groom has no strand_region");
  for (std::size_t s = 0; s < g.strand_count; ++s)
    if (g.strand_region[s] >= p.region_count)
      fail("strand " + std::to_string(s) + " is in region " + std::to_string(g.strand_region[s]) + " of " +
           std::to_string(p.region_count));
}

void check_initial(const hb_initial_state* initial, std::size_t vertex_count) {
  if (initial == nullptr) return;
  if (initial->positions != nullptr && !all_finite(initial->positions, 4 * vertex_count))
    fail("the initial state has a position that is not finite");
  if (initial->velocities != nullptr && !all_finite(initial->velocities, 4 * vertex_count))
    fail("the initial state has a velocity that is not finite");
}

void check_frame(const hb_frame& f) {
  if (!(f.dt > 0.0) || !std::isfinite(f.dt)) fail("the frame's dt is not a positive number");
  if (f.sphere_count > 0 && f.spheres == nullptr) fail("the frame has sphere_count > 0 and no spheres");
}

// `count` float x, y, z, w quadruples into `out` as Vec4f (its storage is kept and grows
// only when needed).
void read_quadruples(const float* values, std::size_t count, std::vector<Vec4f>& out) {
  out.resize(count);
  for (std::size_t i = 0; i < count; ++i)
    out[i] = Vec4f(values[4 * i], values[4 * i + 1], values[4 * i + 2], values[4 * i + 3]);
}

class FtlModel {
 public:
  explicit FtlModel(const hb_host& host) : host_(host) {}

  void reset(const hb_groom& rest, const hb_params& params, const hb_initial_state* initial);
  void step(const hb_frame& frame);
  const float* positions(std::size_t* vertex_count) const;

 private:
  void load_groom(const hb_groom& rest);
  void load_params(const hb_groom& rest, const hb_params& params);
  void load_initial(const hb_initial_state* initial);
  void load_spheres(const hb_frame& frame);
  void substep(const Affine3f& head, const hb_frame& frame, float dt);
  void set_inputs(const Affine3f& head, const hb_frame& frame, float dt);
  std::span<Vec4f> strand(std::vector<Vec4f>& a, std::size_t s) const;
  std::span<const float> strand(const std::vector<float>& a, std::size_t s) const;
  template <class Fn>
  void for_each_strand(int stage, const Fn& fn) { for_each(stage, offsets_.size() - 1, fn); }
  template <class Fn>
  void for_each(int stage, std::size_t count, const Fn& fn);

  hb_host host_;
  std::vector<std::uint32_t> offsets_;
  std::vector<std::uint16_t> region_;  // per strand: a row of regions_
  std::vector<RegionParams> regions_;  // the base values alone where there are no regions
  std::vector<Vec4f> rest_, x_, v_, p_, d_;
  std::vector<float> rest_length_;
  std::vector<Vec4f> spheres_;
  std::vector<muller::StepInput> inputs_;  // per region, for the current substep
  int substeps_ = 1;
};

void FtlModel::reset(const hb_groom& rest, const hb_params& params, const hb_initial_state* initial) {
  check_groom(rest);
  check_params(params);
  check_regions(rest, params);
  check_initial(initial, rest.vertex_count);
  load_groom(rest);
  load_params(rest, params);
  load_initial(initial);
}

void FtlModel::load_groom(const hb_groom& rest) {
  offsets_.assign(rest.strand_offsets, rest.strand_offsets + rest.strand_count + 1);
  read_quadruples(rest.positions, rest.vertex_count, rest_);
  rest_length_.assign(rest.vertex_count, 0.0f);
  for (std::size_t s = 0; s + 1 < offsets_.size(); ++s)
    muller::rest_lengths(strand(rest_, s), {rest_length_.data() + offsets_[s], offsets_[s + 1] - offsets_[s]});
  p_.assign(rest.vertex_count, Vec4f::Zero());
  d_.assign(rest.vertex_count, Vec4f::Zero());
}

void FtlModel::load_params(const hb_groom& rest, const hb_params& params) {
  substeps_ = static_cast<int>(params.base[kSubsteps]);
  const auto row = [](const double* values) {
    return RegionParams{static_cast<float>(values[kFtlDamping]), static_cast<float>(values[kDamping])};
  };
  if (params.region_count == 0) {
    regions_.assign(1, row(params.base));
    region_.assign(rest.strand_count, 0);
    return;
  }
  regions_.clear();
  for (std::size_t r = 0; r < params.region_count; ++r) regions_.push_back(row(params.region_values + r * kParamCount));
  region_.assign(rest.strand_region, rest.strand_region + rest.strand_count);
}

// The hair starts at rest under the identity head, or where `initial` puts it; w is
// always the groom's inverse mass.
void FtlModel::load_initial(const hb_initial_state* initial) {
  x_ = rest_;
  v_.assign(rest_.size(), Vec4f::Zero());
  if (initial == nullptr) return;
  for (std::size_t i = 0; i < x_.size(); ++i) {
    if (initial->positions != nullptr) x_[i].head<3>() = Vec3f(initial->positions + 4 * i);
    if (initial->velocities != nullptr) v_[i].head<3>() = Vec3f(initial->velocities + 4 * i);
  }
}

void FtlModel::step(const hb_frame& frame) {
  if (x_.empty()) fail("step before reset");
  check_frame(frame);
  load_spheres(frame);
  const Affine3f head_prev = muller::head_transform(frame.head_prev);
  const Affine3f head = muller::head_transform(frame.head);
  const float dt = static_cast<float>(frame.dt) / static_cast<float>(substeps_);
  for (int k = 1; k <= substeps_; ++k)
    substep(hairbench::interpolate_head(head_prev, head, static_cast<float>(k) / static_cast<float>(substeps_)), frame, dt);
}

// Copied so that the kernels read aligned Vec4f. The ABI gives the spheres at the end of
// the step only: every substep collides with them there.
void FtlModel::load_spheres(const hb_frame& frame) { read_quadruples(frame.spheres, frame.sphere_count, spheres_); }

// Algorithm 1's three loops, each over every strand before the next begins.
void FtlModel::substep(const Affine3f& head, const hb_frame& frame, float dt) {
  set_inputs(head, frame, dt);
  const std::vector<muller::StepInput>& in = inputs_;
  for_each_strand(HB_STAGE_INTEGRATE, [&](std::size_t s) {
    muller::predict(strand(x_, s), strand(v_, s), strand(rest_, s), in[region_[s]], strand(p_, s));
  });
  // Groups of consecutive strands, side by side through the FTL pass (follow_the_leader
  // over strands: a strand alone is one chain of dependent steps).
  constexpr std::size_t kGroup = 8;
  const std::size_t strands = offsets_.size() - 1;
  for_each(HB_STAGE_LENGTH, (strands + kGroup - 1) / kGroup, [&](std::size_t g) {
    std::array<muller::FtlStrand, kGroup> group;
    const std::size_t first = g * kGroup, count = std::min(kGroup, strands - first);
    for (std::size_t k = 0; k < count; ++k) {
      const std::size_t s = first + k;
      group[k] = {strand(p_, s), strand(d_, s), strand(rest_, s), strand(rest_length_, s), &in[region_[s]]};
    }
    muller::follow_the_leader(std::span<const muller::FtlStrand>(group.data(), count));
  });
  for_each_strand(HB_STAGE_INTEGRATE, [&](std::size_t s) {
    muller::update_velocity(strand(x_, s), strand(v_, s), strand(p_, s), strand(d_, s), in[region_[s]]);
  });
}

// One kernel input per region: the same head, forces and spheres, the region's dampings.
void FtlModel::set_inputs(const Affine3f& head, const hb_frame& frame, float dt) {
  inputs_.resize(regions_.size());
  for (std::size_t r = 0; r < regions_.size(); ++r) {
    muller::StepInput& in = inputs_[r];
    in.head = head;
    in.gravity = Vec3f(frame.gravity);
    in.wind = Vec3f(frame.wind);
    in.spheres = spheres_;
    in.dt = dt;
    in.s_damping = regions_[r].s_damping;
    in.damping = regions_[r].damping;
  }
}

std::span<Vec4f> FtlModel::strand(std::vector<Vec4f>& a, std::size_t s) const {
  return {a.data() + offsets_[s], offsets_[s + 1] - offsets_[s]};
}

std::span<const float> FtlModel::strand(const std::vector<float>& a, std::size_t s) const {
  return {a.data() + offsets_[s], offsets_[s + 1] - offsets_[s]};
}

// fn(i) for every i < count through the host's parallel_for, its wall time added to
// `stage`. The kernels neither throw nor allocate, so nothing leaves the callback.
template <class Fn>
void FtlModel::for_each(int stage, std::size_t count, const Fn& fn) {
  const auto start = std::chrono::steady_clock::now();
  const auto run = [](void* user, std::size_t begin, std::size_t end) noexcept {
    const Fn& f = *static_cast<const Fn*>(user);
    for (std::size_t s = begin; s < end; ++s) f(s);
  };
  host_.parallel_for(host_.ctx, count, run, const_cast<Fn*>(&fn));
  if (host_.stage_time == nullptr) return;
  const std::chrono::duration<double, std::milli> ms = std::chrono::steady_clock::now() - start;
  host_.stage_time(host_.ctx, stage, ms.count());
}

const float* FtlModel::positions(std::size_t* vertex_count) const {
  if (vertex_count != nullptr) *vertex_count = x_.size();
  return x_.empty() ? nullptr : x_.front().data();
}

// ---- the C entry points: every exception becomes HB_ERROR with its message -------------

template <class Fn>
int guarded(char* err, std::size_t err_size, const Fn& fn) {
  try {
    fn();
    return HB_OK;
  } catch (const std::exception& e) {
    write_error(err, err_size, e.what());
  } catch (...) {
    write_error(err, err_size, "muller_ftl: unknown error");
  }
  return HB_ERROR;
}

void* create(const hb_host* host, char* err, std::size_t err_size) {
  FtlModel* model = nullptr;
  const int status = guarded(err, err_size, [&] {
    if (host == nullptr || host->parallel_for == nullptr) fail("the host has no parallel_for");
    model = new FtlModel(*host);
  });
  return status == HB_OK ? model : nullptr;
}

int reset(void* model, const hb_groom* rest, const hb_params* params, const hb_initial_state* initial, char* err,
          std::size_t err_size) {
  return guarded(err, err_size, [&] {
    if (model == nullptr || rest == nullptr || params == nullptr) fail("reset without a model, groom or parameters");
    static_cast<FtlModel*>(model)->reset(*rest, *params, initial);
  });
}

int step(void* model, const hb_frame* frame, char* err, std::size_t err_size) {
  return guarded(err, err_size, [&] {
    if (model == nullptr || frame == nullptr) fail("step without a model or frame");
    static_cast<FtlModel*>(model)->step(*frame);
  });
}

const float* positions(void* model, std::size_t* vertex_count) {
  if (model == nullptr) {
    if (vertex_count != nullptr) *vertex_count = 0;
    return nullptr;
  }
  return static_cast<const FtlModel*>(model)->positions(vertex_count);
}

void destroy(void* model) { delete static_cast<FtlModel*>(model); }

const hb_model_desc kModels[] = {{
    "muller_ftl",
    "Müller, Kim & Chentanez 2012: dynamic follow-the-leader, one root-to-tip pass and the velocity correction (§3-4)",
    kParams,
    kParamCount,
    // Median step per vertex on `shake` at the defaults in the default comparison, 2
    // threads on the 2-core development VM (the built-in models' costs are measured so).
    29.1,
    "substeps",
    create,
    reset,
    step,
    positions,
    destroy,
}};

const hb_plugin kPlugin = {HAIRBENCH_PLUGIN_ABI_VERSION, "muller2012", kModels, 1};

}  // namespace

extern "C" HB_EXPORT const hb_plugin* hairbench_plugin(void) { return &kPlugin; }
