#include "core/params.h"

#include "core/error.h"

#include <cmath>
#include <sstream>

namespace hairbench {

ParamSet::ParamSet(std::span<const ParamSpec> specs, std::size_t region_count)
    : specs_(specs), region_(region_count) {
  for (const ParamSpec& s : specs_) base_.emplace(std::string(s.name), s.default_value);
}

const ParamSpec& ParamSet::spec(std::string_view name, const Origin& from) const {
  for (const ParamSpec& s : specs_)
    if (s.name == name) return s;
  std::string known;
  for (const ParamSpec& s : specs_) known += (known.empty() ? "" : ", ") + std::string(s.name);
  throw InputError(from.file, from.prefix + std::string(name),
                   "unknown parameter (known: " + known + ")");
}

namespace {
void check_value(const ParamSpec& s, double v, const ParamSet::Origin& from) {
  const std::string field = from.prefix + std::string(s.name);
  const std::string& where = from.file;
  if (!std::isfinite(v)) throw InputError(where, field, "value is NaN or infinite");
  if (v < s.min || v > s.max) {
    std::ostringstream os;
    os << v << " is outside [" << s.min << ", " << s.max << "]";
    throw InputError(where, field, os.str());
  }
  if (s.integer && v != std::floor(v)) throw InputError(where, field, "must be a whole number");
}
}  // namespace

double ParamSet::get(std::string_view name, std::size_t region) const {
  if (region < region_.size()) {
    const auto it = region_[region].find(name);
    if (it != region_[region].end()) return it->second;
  }
  return get(name);
}

double ParamSet::get(std::string_view name) const {
  const auto it = base_.find(name);
  if (it == base_.end()) throw std::logic_error("parameter not declared: " + std::string(name));
  return it->second;
}

bool ParamSet::has(std::string_view name) const { return base_.find(name) != base_.end(); }

void ParamSet::set(std::string_view name, double value, const Origin& from) {
  check_value(spec(name, from), value, from);
  base_.find(name)->second = value;
}

void ParamSet::set_region(std::size_t region, std::string_view name, double value,
                          const Origin& from) {
  check_value(spec(name, from), value, from);
  region_.at(region)[std::string(name)] = value;
}

void ParamSet::set_everywhere(std::string_view name, double value, const Origin& from) {
  set(name, value, from);
  for (auto& r : region_) {
    const auto it = r.find(name);
    if (it != r.end()) r.erase(it);
  }
}

void ParamSet::scale(std::string_view name, double factor) {
  if (auto it = base_.find(name); it != base_.end()) it->second *= factor;
  for (auto& r : region_)
    if (auto it = r.find(name); it != r.end()) it->second *= factor;
}

void ParamSet::set_chain_limit(const Origin& from) {
  for (const ParamSpec& p : specs_) {
    if (p.role == ParamRole::stiffness || p.role == ParamRole::damping)
      set_everywhere(p.name, 0.0, from);
    else if (p.role == ParamRole::chain_limit)
      set_everywhere(p.name, p.chain_value, from);
  }
}

}  // namespace hairbench
