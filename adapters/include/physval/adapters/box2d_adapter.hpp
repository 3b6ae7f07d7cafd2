// Box2D 2.4.1 (float) behind physval's engine interface.
#pragma once

#include "physval/core/engine.hpp"

namespace physval {

EngineFactory box2d_engine_factory();

}  // namespace physval
