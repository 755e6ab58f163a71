#include "harness/plugin_loading.h"

#include "models/plugin/plugin_models.h"

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <sstream>

namespace hairbench {

namespace {

// The folders the default plugins are looked for in: beside the binary in a build tree
// (build/PRESET/plugins) and in an installed tree (PREFIX/lib/hairbench/plugins).
std::vector<std::filesystem::path> default_dirs() {
  std::error_code ec;
  const std::filesystem::path exe = std::filesystem::read_symlink("/proc/self/exe", ec);
  if (ec) return {};
  const std::filesystem::path dir = exe.parent_path();
  return {dir / "plugins", dir.parent_path() / "lib" / "hairbench" / "plugins"};
}

std::vector<std::string> default_names() {
  std::vector<std::string> names;
  std::stringstream in(HAIRBENCH_DEFAULT_PLUGINS);
  for (std::string n; std::getline(in, n, ',');)
    if (!n.empty()) names.push_back(n);
  return names;
}

}  // namespace

PluginLoad load_plugins(const std::vector<std::string>& paths) {
  PluginLoad out;
  out.left_out = plugin::load_defaults(default_names(), default_dirs());
  for (const std::string& line : out.left_out) std::fprintf(stderr, "hairbench: plugin %s\n", line.c_str());
  if (const char* env = std::getenv("HAIRBENCH_PLUGIN_PATH")) plugin::load_search_path(env);
  for (const std::string& p : paths) plugin::load(p);
  return out;
}

nlohmann::json plugins_json(const PluginLoad& load) {
  nlohmann::json libs = nlohmann::json::array();
  for (const plugin::Library& l : plugin::loaded())
    libs.push_back({{"path", l.path}, {"name", l.name}, {"models", l.models}});
  return {{"loaded", libs}, {"not_loaded", load.left_out}};
}

}  // namespace hairbench
