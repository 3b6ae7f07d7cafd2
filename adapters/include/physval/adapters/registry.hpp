// Every engine physval knows, in a fixed order. The runner iterates this list and
// never names an engine itself.
#pragma once

#include <string>
#include <vector>

#include "physval/core/engine.hpp"

namespace physval {

const std::vector<EngineFactory>& engine_registry();
// Adds an engine (a plugin) after the built-in ones. Call it before anything looks an
// engine up (before loading scenarios): it may move the registry's entries. Throws
// PluginError when the name is taken.
void register_engine(EngineFactory factory);
// Loads and registers each `--plugin` argument (a path, or a name searched in
// PHYSVAL_PLUGIN_PATH) after the built-in engines and the bundled plugins; returns the
// engines' names. Throws PluginError.
std::vector<std::string> register_plugins(const std::vector<std::string>& args);
// Plugins built with physval (physval_add_bundled_plugin), part of the registry from its
// first use, like built-in engines (so the built-in suite may carry their [gate.<name>]
// bounds): the *.so files, sorted, of $PHYSVAL_BUNDLED_PLUGIN_DIR when set, else of
// <the executable's folder>/plugins (the build tree) or else
// <the executable's folder>/../lib/physval/plugins (an installed physval).
std::vector<std::string> bundled_plugin_paths();
// nullptr when there is no engine of that name.
const EngineFactory* find_engine(const std::string& name);
// The engine whose converged runs serve as the reference (nullptr: none).
const EngineFactory* reference_engine();

}  // namespace physval
