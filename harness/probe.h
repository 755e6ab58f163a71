// The perturbation probe at rest: is a model's rest state stable? (docs/verdicts.md)
//
// Two copies of the model start from the rest groom with the head still and settle under
// gravity for kSettleFrames (the rest shape is not an equilibrium: the hair sags, and the
// sensitivity of that swing is not the rest state's). Then one gets a tiny kick, a head
// rotation pulse that displaces the strand tips by about kAmplitude mean strand lengths
// for one frame and returns. Both run kFrames more frames with nothing driving them and
// every stage run (no skipping, no sleeping). A stable rest
// state damps the difference between the two away; an unstable one amplifies it. The
// growth rate is that of the RMS distance between them, from the frame after the pulse
// to the mean over the last kWindow frames.
#pragma once

#include "core/params.h"
#include "models/registry.h"
#include "reports/material.h"
#include "reports/verdict.h"
#include "scenarios/scenario.h"

namespace hairbench {

class ThreadPool;

struct ProbeSettings {
  static constexpr double kAmplitude = 1e-6;
  static constexpr int kSettleFrames = 90;
  static constexpr int kFrames = 120;
  static constexpr int kWindow = 10;
  // An unstable rest state: the difference grows faster than e-fold per second and ends
  // above kMinGrowth times the kick's size (2e-4 L, 50 um on 25 cm strands), so that
  // neither rounding (which keeps a damped model's difference at a floor, rate ~0, near
  // 1e-7 L) nor a rounding-sized rest edge that the kick turns at once (up to 4e-5 L on
  // the TressFX mohawk) counts as growth.
  static constexpr double kMinGrowthRate = 1.0;
  static constexpr double kMinGrowth = 200.0;
  // The probe runs on at most this many strands, spread over the groom: the rest-state
  // dynamics of a strand do not depend on how many others there are.
  static constexpr std::size_t kMaxStrands = 64;
  // The material card's kick (reports/material.h): the same pulse, a thousand times the
  // probe's, so that its decay stays far above the rounding floor (about 1e-7 L) for the
  // fit while the response stays linear (a tip moved 1/1000 of its strand).
  static constexpr double kCardAmplitude = 1e-3;
  // The card's mode fit skips the frames right after the pulse, where the faster modes it
  // also excites have not died out, and reads down to 1/1000 of the largest sample.
  static constexpr int kCardSkipFrames = 3;
};

// The probe's copies at rest, and what they measure: the probe's verdict and the run's
// material card (a third copy, kicked by kCardAmplitude; sag and stretch read from the
// unkicked copy at the end of its settling).
struct AtRest {
  verdict::Probe probe;
  material::Card card;
};

// Runs the probe for `info` with `params` on the scenario's groom (its guides where
// follow hairs are rebuilt from them), gravity and colliders. Models that run on a GPU
// are not probed (their CPU twins implement the same method; the result says so) but
// get their card.
// Which of the copies run: the probe's kicked copy (the verdict), the card's kicked copy
// (its mode); with neither, only the unkicked copy settles, for the card's sag and
// stretch (what harness/calibrate.h fits stiffness on).
struct AtRestParts {
  bool probe = true;
  bool mode = true;
};
AtRest probe_at_rest(const ModelInfo& info, const Scenario& sc, const ParamSet& params, ThreadPool& pool,
                     const std::string& device = "", AtRestParts parts = {});
inline verdict::Probe perturbation_probe(const ModelInfo& info, const Scenario& sc, const ParamSet& params,
                                         ThreadPool& pool, const std::string& device = "") {
  return probe_at_rest(info, sc, params, pool, device).probe;
}

}  // namespace hairbench
