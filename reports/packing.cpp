#include "reports/packing.h"

#include <cstdint>
#include <cstring>
#include <stdexcept>

namespace hairbench {

namespace {
constexpr char kAlphabet[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
}

void append_zigzag(std::string& bytes, std::int64_t r) {
  std::uint64_t z = (static_cast<std::uint64_t>(r) << 1) ^ static_cast<std::uint64_t>(r >> 63);
  for (; z >= 0x80; z >>= 7) bytes.push_back(static_cast<char>((z & 0x7f) | 0x80));
  bytes.push_back(static_cast<char>(z));
}

std::vector<std::int64_t> read_zigzag(std::string_view bytes) {
  std::vector<std::int64_t> out;
  for (std::size_t i = 0; i < bytes.size();) {
    std::uint64_t z = 0;
    for (int shift = 0;; shift += 7) {
      if (i >= bytes.size() || shift > 63) throw std::invalid_argument("truncated varint");
      const auto b = static_cast<unsigned char>(bytes[i++]);
      z |= std::uint64_t(b & 0x7f) << shift;
      if (!(b & 0x80)) break;
    }
    out.push_back(static_cast<std::int64_t>(z >> 1) ^ -static_cast<std::int64_t>(z & 1));
  }
  return out;
}

std::string base64_encode(std::string_view bytes) {
  std::string out;
  for (std::size_t i = 0; i < bytes.size(); i += 3) {
    const std::size_t n = std::min<std::size_t>(3, bytes.size() - i);
    std::uint32_t w = 0;
    for (std::size_t k = 0; k < 3; ++k) w = (w << 8) | (k < n ? static_cast<unsigned char>(bytes[i + k]) : 0u);
    for (std::size_t k = 0; k < 4; ++k) out.push_back(k <= n ? kAlphabet[(w >> (18 - 6 * k)) & 0x3f] : '=');
  }
  return out;
}

std::string base64_decode(std::string_view code) {
  if (code.size() % 4) throw std::invalid_argument("base64 length is not a multiple of 4");
  std::string bytes;
  for (std::size_t i = 0; i < code.size(); i += 4) {
    std::uint32_t w = 0;
    std::size_t pad = 0;
    for (std::size_t k = 0; k < 4; ++k) {
      const char c = code[i + k];
      const char* at = c == '=' ? nullptr : std::strchr(kAlphabet, c);
      if (c == '=') ++pad;
      else if (!at || !c || pad) throw std::invalid_argument("not base64");
      w = (w << 6) | (at ? static_cast<std::uint32_t>(at - kAlphabet) : 0u);
    }
    if (pad > 2 || (pad && i + 4 != code.size())) throw std::invalid_argument("misplaced base64 padding");
    for (std::size_t k = 0; k < 3 - pad; ++k) bytes.push_back(static_cast<char>((w >> (16 - 8 * k)) & 0xff));
  }
  return bytes;
}

}  // namespace hairbench
