// Bullet 3.24 (double precision build) behind physval's engine interface, held in the plane.
#pragma once

#include "physval/core/engine.hpp"

namespace physval {

EngineFactory bullet_engine_factory();

}  // namespace physval
