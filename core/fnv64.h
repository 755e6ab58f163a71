// FNV-1a, 64 bit, over bytes fed in order: the hashes that name a scenario's definition
// (scenario_hash) and a shard plan (plan_hash), which must agree across processes.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

namespace hairbench {

class Fnv64 {
 public:
  Fnv64& bytes(const void* p, std::size_t n) {
    const auto* c = static_cast<const unsigned char*>(p);
    for (std::size_t i = 0; i < n; ++i) {
      h_ ^= c[i];
      h_ *= 0x100000001b3ull;
    }
    return *this;
  }
  template <class T>
  Fnv64& value(const T& v) {
    return bytes(&v, sizeof v);
  }
  Fnv64& text(const std::string& s) {
    value(s.size());
    return bytes(s.data(), s.size());
  }
  std::uint64_t digest() const { return h_; }

 private:
  std::uint64_t h_ = 0xcbf29ce484222325ull;
};

}  // namespace hairbench
