#include "physval/adapters/registry.hpp"

#include "physval/adapters/box2d_adapter.hpp"
#include "physval/adapters/bullet_adapter.hpp"
#include "physval/core/core_engine.hpp"

namespace physval {

const std::vector<EngineFactory>& engine_registry() {
  static const std::vector<EngineFactory> engines = {
      core_engine_factory(), box2d_engine_factory(), bullet_engine_factory()};
  return engines;
}

const EngineFactory* find_engine(const std::string& name) {
  for (const EngineFactory& f : engine_registry()) {
    if (f.info.name == name) return &f;
  }
  return nullptr;
}

}  // namespace physval
