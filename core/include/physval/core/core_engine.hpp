// core: physval's own engine, built from the lecture model (shared/lecture-model.md).
#pragma once

#include "physval/core/engine.hpp"

namespace physval {

// Name "core". Options ([core] in a scenario): integrator, collision mode, broad phase.
EngineFactory core_engine_factory();

}  // namespace physval
