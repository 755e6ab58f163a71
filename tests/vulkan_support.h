// Shared by the Vulkan test suites: skip when there is no Vulkan device at all, and step
// a CPU model and its Vulkan twin in lockstep.
#pragma once

#include "core/parallel.h"
#include "harness/runner.h"
#include "models/han2012/vulkan/han_vulkan.h"
#include "test_support.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <memory>
#include <string>

// GTEST_SKIP only for "no Vulkan loader or device" (the one-line reason is printed);
// every other failure of the backend fails the test.
#define HAIRBENCH_REQUIRE_VULKAN()                                              \
  do {                                                                          \
    const std::string why = hairbench::han_vk::unavailable(hairbench::ModelContext{}); \
    if (!why.empty()) GTEST_SKIP() << why;                                      \
  } while (0)

namespace hairbench::test {

struct Agreement {
  double max_diff = 0.0;          // max over vertices and frames of |p_cpu - p_vk|, metres
  double mean_length = 0.0;       // L-bar of the groom
  double max_displacement = 0.0;  // max over vertices and frames of |p_cpu - p_rest|: the hair moved
  bool gpu_timed = false;        // the Vulkan model reported a device time for its steps
};

// Runs `cpu` and `vk` (registry names) on the scenario for `frames` frames with the same
// resolved parameters and compares positions vertex by vertex after every frame (the
// bound is stated for the last frame; every frame is the stronger check).
// `groom_b`, when given, replaces the scenario's groom for the second model.
inline Agreement agreement(const Scenario& sc, const std::string& cpu, const std::string& vk, int frames,
                           const std::vector<ParamOverride>& overrides = {}, const Groom* groom_b = nullptr) {
  ThreadPool pool(2);
  const ModelInfo* a = find_model(cpu);
  const ModelInfo* b = find_model(vk);
  if (!a || !b) throw std::runtime_error("unknown model " + cpu + " or " + vk);
  std::unique_ptr<HairModel> ma = a->make(ModelContext{&pool});
  std::unique_ptr<HairModel> mb = b->make(ModelContext{&pool});
  ma->reset(sc.groom, resolve_params(*a, sc, overrides));
  mb->reset(groom_b ? *groom_b : sc.groom, resolve_params(*b, sc, overrides));
  StageTimes times;
  Agreement out;
  out.gpu_timed = true;
  for (int f = 0; f < frames; ++f) {
    const FrameInput in = frame_input(sc, f);
    ma->step(in, times);
    mb->step(in, times);
    out.gpu_timed = out.gpu_timed && mb->last_gpu_ms().has_value() && *mb->last_gpu_ms() > 0.0;
    const auto pa = ma->positions(), pb = mb->positions();
    for (std::size_t i = 0; i < pa.size(); ++i) {
      out.max_diff = std::max(out.max_diff, static_cast<double>((pa[i] - pb[i]).head<3>().norm()));
      out.max_displacement =
          std::max(out.max_displacement, static_cast<double>((pa[i] - sc.groom.positions[i]).head<3>().norm()));
    }
  }
  out.mean_length = mean_strand_length(sc.groom);
  return out;
}

}  // namespace hairbench::test
