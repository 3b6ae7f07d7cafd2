// PLACEHOLDER until the core engine lands: declares the engine with no features, so
// every run of it is reported "unsupported". Replaced by the real implementation.
#include <stdexcept>

#include "physval/core/core_engine.hpp"

namespace physval {

EngineFactory core_engine_factory() {
  EngineFactory f;
  f.info.name = "core";
  f.info.version = "unbuilt";
  f.info.summary = "not implemented yet";
  f.create = []() -> std::unique_ptr<Engine> { throw std::runtime_error("core engine not implemented yet"); };
  return f;
}

}  // namespace physval
