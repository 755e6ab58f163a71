// Errors that reach the user as one line and exit code 2 (bad arguments, bad files).
#pragma once

#include <stdexcept>
#include <string>

namespace hairbench {

class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
  // "FILE: FIELD: what is wrong" - the shape every loader uses.
  InputError(const std::string& file, const std::string& field, const std::string& what)
      : std::runtime_error(file + ": " + field + ": " + what) {}
};

}  // namespace hairbench
