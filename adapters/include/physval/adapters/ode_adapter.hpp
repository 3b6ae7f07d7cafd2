// ODE 0.16 (double) behind physval's engine interface: a 3-D engine whose bodies are held
// in the plane z = 0 by its plane-2D joint. Built when the library is found
// (PHYSVAL_HAVE_ODE); the factory is self-contained, so a thin plugin wrapper can expose
// the same engine through physval/plugin.h.
#pragma once

#include "physval/core/engine.hpp"

namespace physval {

EngineFactory ode_engine_factory();

}  // namespace physval
