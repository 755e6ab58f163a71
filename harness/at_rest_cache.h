// The copies at rest that one comparison's scenarios share: the probe at rest
// (harness/probe.h) and the rest twin (harness/twin.h) of a model depend only on the
// model, its parameters, the strands it simulates, the step, and gravity and colliders
// as the copies see them, not on the head's script. Most built-in scenarios share one
// groom; every one of them asks for the same probe, and those whose head ends at the
// same pose for the same twin. Each is stepped once and handed to the others.
//
// The inputs are hashed bit for bit (every value a copy reads): a run gets
// exactly the bits it would have computed itself, whatever else ran before it, so a
// report does not depend on which scenarios were run with it or in which order.
#pragma once

#include "harness/probe.h"
#include "harness/twin.h"

#include <cstdint>
#include <mutex>
#include <string>
#include <unordered_map>
#include <vector>

namespace hairbench {

class AtRestCache {
 public:
  // probe_at_rest's result for these inputs; `from` is set to the scenario that computed
  // it when an earlier one did, and left empty when this call computed it.
  AtRest probe(const ModelInfo& info, const Scenario& sc, const ParamSet& params, ThreadPool& pool,
               const std::string& device, AtRestParts parts, std::string& from);
  // rest_twin's result for these inputs, as probe. A twin that stopped at rest after F
  // frames serves every request of F frames or more (the later frames would not have
  // run); one that ran out of frames serves its own count only.
  RestTwin twin(const ModelInfo& info, const Scenario& sc, const ParamSet& params, ThreadPool& pool,
                const std::string& device, bool skip_inert, int frames, std::string& from);

  // Kept twins' positions at most, bytes (a twin of a TressFX groom with its follow
  // hairs is 6 MB). Over it, the twins that took least time to step per byte they hold go
  // first: a slow model's twin on a small groom is worth more than a fast one's on a big
  // groom.
  static constexpr std::size_t kMaxTwinBytes = std::size_t{64} << 20;

 private:
  struct ProbeEntry {
    AtRest at_rest;
    std::string scenario;
  };
  struct TwinEntry {
    std::uint64_t key;
    RestTwin twin;
    int asked;       // frames asked for
    double seconds;  // it took to step
    std::string scenario;
  };
  std::mutex mutex_;
  std::unordered_map<std::uint64_t, ProbeEntry> probes_;
  std::vector<TwinEntry> twins_;
  std::size_t twin_bytes_ = 0;
};

}  // namespace hairbench
