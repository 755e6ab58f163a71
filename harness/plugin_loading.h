// Which plugins a `hairbench` command loads (docs/plugins.md): the default ones built
// beside the binary, then every library on HAIRBENCH_PLUGIN_PATH, then each --plugin.
#pragma once

#include <nlohmann/json.hpp>

#include <string>
#include <vector>

namespace hairbench {

struct PluginLoad {
  std::vector<std::string> left_out;  // default plugins not loaded, one line each, with why
};

// Loads them; prints one line on stderr for each default plugin left out (the other
// models run) and throws InputError for a HAIRBENCH_PLUGIN_PATH or --plugin library that
// fails (the user asked for it: exit 2).
PluginLoad load_plugins(const std::vector<std::string>& paths);

// The report's context.plugins: each library loaded, with its models, and what was left out.
nlohmann::json plugins_json(const PluginLoad& load);

}  // namespace hairbench
