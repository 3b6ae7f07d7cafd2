// Engines from shared libraries: the plugin ABI of physval/plugin.h, loaded with dlopen
// and wrapped as an ordinary Engine. A plugin is listed, run, isolated (in the child
// process of each run) and gated exactly like a built-in engine.
#pragma once

#include <stdexcept>
#include <string>
#include <vector>

#include "physval/engine/engine.hpp"

namespace physval {

// A plugin that cannot be used: not found, not a physval plugin, a different ABI
// version, an invalid declaration. The message names the library and what is wrong.
class PluginError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Where `--plugin ARG` points: ARG itself when it names a file (or contains a '/');
// otherwise the first of DIR/ARG, DIR/libARG.so, DIR/ARG.so for each DIR of the
// colon-separated `search_path` (the environment's PHYSVAL_PLUGIN_PATH). Throws
// PluginError when nothing is found.
std::string resolve_plugin_path(const std::string& arg, const std::string& search_path);

// Opens the library, checks its ABI version and its declaration (name, features,
// options), and returns its factory. The library stays loaded for the life of the
// process. Throws PluginError.
EngineFactory load_plugin(const std::string& path);

}  // namespace physval
