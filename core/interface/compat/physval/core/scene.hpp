// Forwarding header: the engine interface lives in core/interface (target physval::engine_api).
#pragma once
#include "physval/engine/scene.hpp"
