// Command-line argument parsing shared by the hairbench subcommands.
#pragma once

#include "core/error.h"

#include <exception>
#include <string>

namespace hairbench {

// A whole number in [lo, hi], or an InputError naming the flag ("arguments: FLAG: ...").
inline int parse_int(const std::string& flag, const std::string& v, int lo, int hi) {
  std::size_t used = 0;
  long long x = 0;
  try {
    x = std::stoll(v, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used == 0 || used != v.size() || x < lo || x > hi)
    throw InputError("arguments", flag, "'" + v + "' is not a whole number in [" + std::to_string(lo) + ", " +
                                            std::to_string(hi) + "]");
  return static_cast<int>(x);
}

}  // namespace hairbench
