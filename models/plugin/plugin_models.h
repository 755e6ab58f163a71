// Models from shared libraries, through the C ABI of core/include/hairbench/plugin.h
// (docs/plugins.md): the loader checks a library and adds its models to the registry; each
// model runs behind an adapter that turns the HairModel calls into the ABI's and the ABI's
// failures (an error status, an exception across the boundary, positions of the wrong
// size) into HairModel::failure(), so that a failing plugin ends its own run as diverged
// and the others go on.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

namespace hairbench::plugin {

struct Library {
  std::string path;  // as loaded (canonical)
  std::string name;  // hb_plugin::name
  std::vector<std::string> models;
};

// Loads the library at `path` and adds its models to the registry (models/registry.h).
// Throws InputError "PATH: FIELD: what" when it cannot be opened, has no entry point, was
// built for another ABI version, describes a model badly, or names a model that exists.
// A library already loaded (the same canonical path) is not loaded again.
const Library& load(const std::filesystem::path& path);

// The libraries loaded so far, in load order.
const std::vector<Library>& loaded();

// The plugins a comparison loads by default: every library named in `names` (file
// NAME.so) in the first of `dirs` that has it. One that is missing or fails to load is
// left out with a line saying why, returned; the other models run.
std::vector<std::string> load_defaults(const std::vector<std::string>& names,
                                       const std::vector<std::filesystem::path>& dirs);

// Every library (*.so, in name order) in each folder of a search path (folders separated
// by ':'; a file is loaded as itself), as HAIRBENCH_PLUGIN_PATH gives it. Throws as load().
void load_search_path(const std::string& path_list);

}  // namespace hairbench::plugin
