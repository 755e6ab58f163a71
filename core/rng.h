// The project's one random number generator: splitmix64 (Steele, Lea & Flood 2014).
// Integer-only, so a seed gives the same stream on every platform and standard
// library, unlike <random>'s distributions whose algorithms the standard leaves open:
// procedural grooms and follow hairs must be bit-identical everywhere.
#pragma once

#include <cstdint>

namespace hairbench {

class SplitMix64 {
 public:
  explicit SplitMix64(std::uint64_t seed) : state_(seed) {}
  std::uint64_t next() {
    std::uint64_t z = (state_ += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
  }
  // Uniform in [0, 1): the top 53 bits scaled by 2^-53, exact in a double.
  double uniform() { return static_cast<double>(next() >> 11) * 0x1p-53; }
  // Uniform in [-0.5, 0.5).
  double centered() { return uniform() - 0.5; }
  // Uniform in [-1, 1).
  double symmetric() { return static_cast<double>(next() >> 11) * 0x1.0p-52 - 1.0; }

 private:
  std::uint64_t state_;
};

}  // namespace hairbench
