// Bullet's headers, included as system headers so physval's warnings apply to physval's
// code only. physval links Bullet's double-precision build (pkg-config bullet-float64,
// which defines BT_USE_DOUBLE_PRECISION); mixing it with float headers fails at link
// time or, worse, at run time, so every translation unit checks it.
#pragma once

#pragma GCC system_header
#include <btBulletDynamicsCommon.h>

static_assert(sizeof(btScalar) == 8, "physval needs Bullet's double build: BT_USE_DOUBLE_PRECISION (bullet-float64)");
