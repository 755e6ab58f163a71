#include "harness/twin.h"

#include "core/parallel.h"
#include "harness/runner.h"

namespace hairbench {

RestTwin rest_twin(const ModelInfo& info, const Scenario& sc, const ParamSet& params, ThreadPool& pool,
                   const std::string& device, bool skip_inert, int frames) {
  RestTwin out;
  out.head = sc.head.at(frames * sc.dt);
  const Affine3f to_head = out.head.inverse();
  std::vector<Sphere> colliders;
  for (const Sphere& c : sc.colliders) colliders.push_back({to_head * collider_center(c, out.head), c.radius, false});
  const std::unique_ptr<HairModel> model = make_model(info, sc, params, pool, device, skip_inert);
  FrameInput in;
  in.dt = sc.dt;
  in.gravity = to_head.linear() * sc.gravity;
  in.rest_gravity = sc.gravity;
  in.colliders = colliders;
  StageTimes times;
  out.positions = sc.groom.positions;
  const double still = kTwinRestSpeed * kTwinRestSpeed * sc.dt * sc.dt * static_cast<double>(out.positions.size());
  int at_rest = 0;
  for (int f = 0; f < frames && at_rest < kTwinRestFrames; ++f) {
    in.frame = f;
    in.t = (f + 1) * sc.dt;
    model->step(in, times);
    times.clear();
    const auto p = model->positions();
    double moved = 0.0;
    for (std::size_t v = 0; v < p.size(); ++v) {
      moved += static_cast<double>((p[v] - out.positions[v]).head<3>().squaredNorm());
      out.positions[v] = p[v];
    }
    at_rest = moved < still ? at_rest + 1 : 0;
    out.frames = f + 1;
  }
  out.at_rest = at_rest >= kTwinRestFrames;
  return out;
}

}  // namespace hairbench
