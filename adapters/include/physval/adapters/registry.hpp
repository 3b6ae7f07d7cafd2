// Every engine physval knows, in a fixed order. The runner iterates this list and
// never names an engine itself.
#pragma once

#include <string>
#include <vector>

#include "physval/core/engine.hpp"

namespace physval {

const std::vector<EngineFactory>& engine_registry();
// nullptr when there is no engine of that name.
const EngineFactory* find_engine(const std::string& name);
// The engine whose converged runs serve as the reference (nullptr: none).
const EngineFactory* reference_engine();

}  // namespace physval
