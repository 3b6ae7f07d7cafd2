// Chipmunk2D 7.0.3 (double) behind physval's engine interface. Built when the library is
// found (PHYSVAL_HAVE_CHIPMUNK); the factory is self-contained, so a thin plugin wrapper
// can expose the same engine through physval/plugin.h.
#pragma once

#include "physval/core/engine.hpp"

namespace physval {

EngineFactory chipmunk_engine_factory();

}  // namespace physval
