// Test helper shared by the scenario-loading suites.
#pragma once

#include "core/error.h"
#include "scenarios/scenario.h"

#include <filesystem>
#include <string>

namespace hairbench::test {

// The one-line message a scenario file is refused with, or "" if it loads.
inline std::string error_of(const std::filesystem::path& file) {
  try {
    load_scenario(file);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

}  // namespace hairbench::test
