// PLACEHOLDER until the bullet engine lands: declares the engine with no features, so
// every run of it is reported "unsupported". Replaced by the real implementation.
#include <stdexcept>

#include "physval/adapters/bullet_adapter.hpp"

namespace physval {

EngineFactory bullet_engine_factory() {
  EngineFactory f;
  f.info.name = "bullet";
  f.info.version = "unbuilt";
  f.info.summary = "not implemented yet";
  f.create = []() -> std::unique_ptr<Engine> { throw std::runtime_error("bullet engine not implemented yet"); };
  return f;
}

}  // namespace physval
