// The rest twin of a run: where the same model, at the same settings, rests with the head
// held still at the run's final pose (reports/verdict.h, Return; docs/verdicts.md).
//
// A copy of the model starts from the rest groom and steps as many frames as the run with
// the head still. It steps in the head's frame: the head at the identity, gravity turned
// into the head's frame by the final pose's rotation, and every collider where the final
// pose puts it, seen from the head. A model's physics does not depend on the frame it is
// written in, so this is the equilibrium the run's hair would reach at that pose if it
// came back, sag, a tilted head and a legitimately fallen state included; and it needs no
// first step that carries the roots from the rest pose to the final one.
#pragma once

#include "core/params.h"
#include "models/registry.h"
#include "scenarios/scenario.h"

#include <string>
#include <vector>

namespace hairbench {

class ThreadPool;

struct RestTwin {
  Affine3f head = Affine3f::Identity();  // the final pose (head rest -> world)
  std::vector<Vec4f> positions;          // the twin's state at the end, in the head's frame
  int frames = 0;                        // frames it stepped
  bool at_rest = false;                  // it stopped at rest (kTwinRestSpeed) before running out of frames
};

// Once every vertex of the twin has moved slower than this, RMS, for kRestFrames frames
// in a row, it has stopped: 0.1 mm/s, so that a twin still creeping below it would move
// less than 0.5 mm in the rest of a 5 s run, 1/200 of a 10 cm strand and 1/20 of the
// `deformed` limit (reports/verdict.h, Return::kLimit). kRestFrames is 1/6 s at 60 Hz,
// longer than a swing spends that slow at its turning points.
inline constexpr double kTwinRestSpeed = 1e-4;
inline constexpr int kTwinRestFrames = 10;

// Steps the twin `frames` frames, or until it has stopped (kTwinRestSpeed), the model
// made as the run's is (make_model, with its follow hairs); `skip_inert` lets its strands
// sleep once they rest.
RestTwin rest_twin(const ModelInfo& info, const Scenario& sc, const ParamSet& params, ThreadPool& pool,
                   const std::string& device, bool skip_inert, int frames);

}  // namespace hairbench
