#include "physval/adapters/registry.hpp"

#include <algorithm>
#include <cstdlib>
#include <filesystem>

#include "physval/adapters/box2d_adapter.hpp"
#include "physval/adapters/bullet_adapter.hpp"
#include "physval/adapters/plugin_engine.hpp"
#include "physval/core/core_engine.hpp"

namespace physval {

namespace {

std::vector<EngineFactory>& mutable_registry() {
  static std::vector<EngineFactory> engines = [] {
    std::vector<EngineFactory> all = {core_engine_factory(), box2d_engine_factory(), bullet_engine_factory()};
    // core, run with RK4 and event-driven impacts, is the reference.
    all[0].reference_options = {{"integrator", std::string("rk4")}, {"collision", std::string("exact")}};
    // The bundled plugins follow, as if built in (a broken one throws PluginError here,
    // at the registry's first use).
    for (const std::string& path : bundled_plugin_paths()) {
      EngineFactory f = load_plugin(path);
      for (const EngineFactory& other : all) {
        if (other.info.name == f.info.name) {
          throw PluginError("bundled plugin " + path + ": engine \"" + f.info.name + "\" exists already");
        }
      }
      all.push_back(std::move(f));
    }
    return all;
  }();
  return engines;
}

}  // namespace

const std::vector<EngineFactory>& engine_registry() { return mutable_registry(); }

void register_engine(EngineFactory factory) {
  if (const EngineFactory* same = find_engine(factory.info.name)) {
    throw PluginError("engine \"" + factory.info.name + "\" is already registered (" + same->info.summary +
                      "): each engine needs a name of its own");
  }
  mutable_registry().push_back(std::move(factory));
}

std::vector<std::string> bundled_plugin_paths() {
  namespace fs = std::filesystem;
  std::error_code ec;
  std::vector<fs::path> dirs;
  if (const char* env = std::getenv("PHYSVAL_BUNDLED_PLUGIN_DIR"); env != nullptr && *env != '\0') {
    dirs.emplace_back(env);
  } else {
    const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
    if (ec) return {};
    dirs = {exe.parent_path() / "plugins", exe.parent_path() / ".." / "lib" / "physval" / "plugins"};
  }
  std::vector<std::string> out;
  for (const fs::path& dir : dirs) {
    std::vector<std::string> here;
    for (const fs::directory_entry& e : fs::directory_iterator(dir, ec)) {
      if (e.is_regular_file() && e.path().extension() == ".so") here.push_back(e.path().string());
    }
    std::sort(here.begin(), here.end());
    out.insert(out.end(), here.begin(), here.end());
    if (!here.empty()) break;   // the build tree's, or else the installed ones
  }
  return out;
}

std::vector<std::string> register_plugins(const std::vector<std::string>& args) {
  const char* env = std::getenv("PHYSVAL_PLUGIN_PATH");
  std::vector<std::string> names;
  (void)engine_registry();   // the built-in engines and the bundled plugins first
  for (const std::string& arg : args) {
    EngineFactory f = load_plugin(resolve_plugin_path(arg, env == nullptr ? "" : env));
    names.push_back(f.info.name);
    register_engine(std::move(f));
  }
  return names;
}

const EngineFactory* find_engine(const std::string& name) {
  for (const EngineFactory& f : engine_registry()) {
    if (f.info.name == name) return &f;
  }
  return nullptr;
}

const EngineFactory* reference_engine() {
  for (const EngineFactory& f : engine_registry()) {
    if (!f.reference_options.empty()) return &f;
  }
  return nullptr;
}

}  // namespace physval
