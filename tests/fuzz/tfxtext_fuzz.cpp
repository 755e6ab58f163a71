// libFuzzer target for the text formats: the same input goes to parse_tfxsim and to
// parse_tfxproj; each either parses or throws InputError, anything else is a finding.
#include "core/error.h"
#include "scenarios/tfx/tfx.h"

#include <cstddef>
#include <cstdint>
#include <string_view>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  try {
    hairbench::tfx::parse_tfxsim(text, "fuzz.tfxsim");
  } catch (const hairbench::InputError&) {
  }
  try {
    hairbench::tfx::parse_tfxproj(text, "fuzz.tfxproj");
  } catch (const hairbench::InputError&) {
  }
  return 0;
}
