// Padded base64 (RFC 4648), for the report's binary strings: the snapshot strands and
// the player's frames (reports/report.h, reports/animation.h).
#pragma once

#include <string>
#include <string_view>

namespace hairbench {

std::string base64_encode(std::string_view bytes);
// Throws std::invalid_argument saying what is wrong ("not base64", ...).
std::string base64_decode(std::string_view code);

}  // namespace hairbench
