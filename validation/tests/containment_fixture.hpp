// Small builders for containment tests that feed ContainmentMonitor states by hand.
#pragma once

#include "physval/engine/engine.hpp"
#include "physval/engine/scene.hpp"

namespace physval::containment_test {

inline BodyState at(Vec2 x, Vec2 v = {}) {
  BodyState s;
  s.position = x;
  s.velocity = v;
  s.alive = true;
  return s;
}

inline WallDef wall(const char* name, Vec2 a, Vec2 b) {
  WallDef w;
  w.name = name;
  w.from = a;
  w.to = b;
  return w;
}

inline BodyDef ball(const char* name, Vec2 x, double r, bool is_static = false) {
  BodyDef b;
  b.name = name;
  b.radius = r;
  b.position = x;
  b.is_static = is_static;
  return b;
}

}  // namespace physval::containment_test
