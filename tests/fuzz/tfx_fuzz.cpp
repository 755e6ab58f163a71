// libFuzzer target: any byte string fed to parse_tfx either parses or throws InputError;
// any other exception, crash, sanitizer report or leak is a finding.
#include "core/error.h"
#include "scenarios/tfx/tfx.h"

#include <cstddef>
#include <cstdint>
#include <span>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    const hairbench::tfx::TfxStrands s =
        hairbench::tfx::parse_tfx(std::as_bytes(std::span(data, size)), "fuzz.tfx");
    // A successful parse promises what the groom needs: the counts match the vertices.
    if (s.positions.size() != std::size_t{s.strand_count} * s.vertices_per_strand) __builtin_trap();
  } catch (const hairbench::InputError&) {
  }
  return 0;
}
