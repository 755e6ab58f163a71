#include "core/hair_model.h"

#include <stdexcept>

namespace hairbench {

void start_positions(std::span<const Vec4f> from, std::span<Vec4f> to) {
  if (from.size() != to.size())
    throw std::invalid_argument("start_from: " + std::to_string(from.size()) + " positions for a model of " +
                                std::to_string(to.size()));
  for (std::size_t v = 0; v < to.size(); ++v) to[v].head<3>() = from[v].head<3>();
}

}  // namespace hairbench
