// PLACEHOLDER until the box2d engine lands: declares the engine with no features, so
// every run of it is reported "unsupported". Replaced by the real implementation.
#include <stdexcept>

#include "physval/adapters/box2d_adapter.hpp"

namespace physval {

EngineFactory box2d_engine_factory() {
  EngineFactory f;
  f.info.name = "box2d";
  f.info.version = "unbuilt";
  f.info.summary = "not implemented yet";
  f.create = []() -> std::unique_ptr<Engine> { throw std::runtime_error("box2d engine not implemented yet"); };
  return f;
}

}  // namespace physval
