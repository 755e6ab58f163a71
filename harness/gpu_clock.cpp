#include "harness/gpu_clock.h"

#include <cstdio>
#include <cstdlib>
#include <sstream>

namespace hairbench {
namespace {

std::string trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \t\r\n");
  if (b == std::string::npos) return "";
  return s.substr(b, s.find_last_not_of(" \t\r\n") - b + 1);
}

// A clock field: MHz, or nothing for "[N/A]" and the like.
std::optional<double> mhz(const std::string& field) {
  const std::string f = trim(field);
  char* end = nullptr;
  const double v = std::strtod(f.c_str(), &end);
  if (f.empty() || *end != '\0' || !(v > 0.0)) return std::nullopt;
  return v;
}

}  // namespace

GpuClock read_gpu_clock(const std::string& device) {
  GpuClock out;
  std::FILE* p = popen("nvidia-smi --query-gpu=name,clocks.sm,clocks.max.sm --format=csv,noheader,nounits 2>/dev/null", "r");
  std::string text;
  if (p) {
    char buf[512];
    while (std::fgets(buf, sizeof buf, p)) text += buf;
    if (pclose(p) != 0) text.clear();
  }
  if (text.empty()) {
    out.source = "not queryable: Vulkan has no clock query, and nvidia-smi is not there or did not answer";
    return out;
  }
  // Lines "NAME, CLOCK, MAX"; a name may hold commas, so the two clocks are taken from the right.
  int matches = 0;
  std::istringstream lines(text);
  for (std::string line; std::getline(lines, line);) {
    const auto second = line.rfind(',');
    const auto first = second == std::string::npos || second == 0 ? std::string::npos : line.rfind(',', second - 1);
    if (first == std::string::npos || trim(line.substr(0, first)) != device) continue;
    ++matches;
    out.mhz = mhz(line.substr(first + 1, second - first - 1));
    out.max_mhz = mhz(line.substr(second + 1));
  }
  if (matches == 1) {
    out.source = "nvidia-smi";
    return out;
  }
  out = {};
  out.source = matches == 0 ? "not queryable: nvidia-smi lists no GPU named '" + device + "'"
                            : "not queryable: nvidia-smi lists " + std::to_string(matches) + " GPUs named '" + device +
                                  "' and cannot tell which one Vulkan uses";
  return out;
}

}  // namespace hairbench
