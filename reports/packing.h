// How the report packs integers into its strings (the snapshot strands, reports/report.h;
// the player's frames, reports/animation.h): each a zigzag-mapped ((r << 1) ^ (r >> 63))
// LEB128 varint (7 bits a byte, low bits first, the high bit set while more follow), the
// bytes as padded base64 (RFC 4648).
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace hairbench {

void append_zigzag(std::string& bytes, std::int64_t r);
// Every varint of `bytes`; throws std::invalid_argument("truncated varint") on a cut one.
std::vector<std::int64_t> read_zigzag(std::string_view bytes);

std::string base64_encode(std::string_view bytes);
// Throws std::invalid_argument saying what is wrong ("not base64", ...).
std::string base64_decode(std::string_view code);

}  // namespace hairbench
