// Shared by the stress tests: the models `hairbench stress` runs, and those the verdicts
// find unstable on some of its grooms.
#pragma once

#include "models/registry.h"

#include <string>
#include <vector>

namespace hairbench::test {

// The models the verdicts find unstable on some of the stress grooms (docs/verdicts.md): the
// forest (explicit joint integration where strands crowd or start inside a collider).
inline bool known_unstable(const std::string& model) {
  for (const char* m : {"halen_forest"})
    if (model.rfind(m, 0) == 0) return true;
  return false;
}

inline std::vector<std::string> stress_models() {
  std::vector<std::string> names;
  for (const ModelInfo& m : model_registry())
    if (m.platform == Platform::Cpu) names.emplace_back(m.name);  // the CPU models, as hairbench stress
  return names;
}

}  // namespace hairbench::test
