// Model parameters: each model declares its parameters (name, default, range) in its
// settings.h; a ParamSet holds one model's resolved values, with per-region overrides
// (Han & Harada §5: regions with their own stiffness and iteration counts).
#pragma once

#include <cstdint>
#include <map>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace hairbench {

// What a parameter sets, for the runs that need to know (the plugin ABI's hb_param_role,
// core/include/hairbench/plugin.h): `--calibrate` (harness/calibrate.h) fits the one
// stiffness and reports the one damping per model; a cost knob repeats work that
// converges (substeps, iterations); a chain-limit switch at its `chain_value` turns the
// bending/shape terms off.
enum class ParamRole { none, stiffness, damping, cost_knob, chain_limit };

struct ParamSpec {
  std::string_view name;
  double default_value;
  double min;
  double max;
  bool integer;
  std::string_view help;
  ParamRole role = ParamRole::none;
  double chain_value = 0.0;  // ParamRole::chain_limit: the value that turns the term off
};

class ParamSet {
 public:
  ParamSet() = default;
  ParamSet(std::span<const ParamSpec> specs, std::size_t region_count);

  // Value for a region: the region's override if any, else the base value.
  double get(std::string_view name, std::size_t region) const;
  int get_int(std::string_view name, std::size_t region = SIZE_MAX) const {
    return static_cast<int>(get(name, region));
  }
  // Base value; for reports and region-free parameters.
  double get(std::string_view name) const;

  // Where a value came from, for error messages: "FILE: PREFIXNAME: why".
  struct Origin {
    std::string file;
    std::string prefix;
  };
  // The setters check that the name exists and the value is finite, in range and
  // integral where required, and throw InputError otherwise.
  void set(std::string_view name, double value, const Origin& from);
  void set_region(std::size_t region, std::string_view name, double value, const Origin& from);
  // Sets the base value and drops every region override of `name` (command-line
  // --set wins over everything a file says).
  void set_everywhere(std::string_view name, double value, const Origin& from);

  // Multiplies the base value and every region override of `name` by `factor`, with no
  // range check: for an adapter that turns a value given at one resolution into the one
  // its model runs at (models/halen2007/nodes_model.h).
  void scale(std::string_view name, double factor);

  // The chain limit (docs/truth.md): every `stiffness` and `damping` parameter at 0 and
  // every `chain_limit` switch at its chain_value, everywhere (region overrides dropped),
  // so that a hanging strand is a chain under gravity alone.
  void set_chain_limit(const Origin& from);

  bool has(std::string_view name) const;
  const std::map<std::string, double, std::less<>>& base() const { return base_; }
  const std::vector<std::map<std::string, double, std::less<>>>& regions() const { return region_; }
  std::span<const ParamSpec> specs() const { return specs_; }

 private:
  const ParamSpec& spec(std::string_view name, const Origin& from) const;
  std::span<const ParamSpec> specs_;
  std::map<std::string, double, std::less<>> base_;
  std::vector<std::map<std::string, double, std::less<>>> region_;
};

}  // namespace hairbench
