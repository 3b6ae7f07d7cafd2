// Box2D's headers, included as system headers so physval's warnings (-Wshadow,
// -Wconversion, ...) apply to physval's code only.
#pragma once

#pragma GCC system_header
#include <box2d/box2d.h>
