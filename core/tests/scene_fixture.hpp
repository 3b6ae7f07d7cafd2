// Small scenes in a line each, and a runner that steps core and gathers its contacts
// (in the spirit of Jolt's PhysicsTestContext).
#pragma once

#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include "physval/core/core_engine.hpp"
#include "physval/core/scene.hpp"

namespace physval::test {

inline BodyDef circle(std::string name, Vec2 p, Vec2 v = {}, double r = 0.5, double m = 1.0, double e = 1.0) {
  BodyDef b;
  b.name = std::move(name);
  b.shape = ShapeKind::Circle;
  b.radius = r;
  b.mass = m;
  b.position = p;
  b.velocity = v;
  b.restitution = e;
  return b;
}

inline BodyDef point(std::string name, Vec2 p, Vec2 v = {}, double m = 1.0, double e = 1.0) {
  BodyDef b = circle(std::move(name), p, v, 0.0, m, e);
  b.shape = ShapeKind::Point;
  return b;
}

inline BodyDef static_circle(std::string name, Vec2 p, double r, double e = 1.0) {
  BodyDef b = circle(std::move(name), p, {}, r, 1.0, e);
  b.is_static = true;
  return b;
}

inline WallDef wall(std::string name, Vec2 from, Vec2 to, double e = 1.0, double mu = 0.0, double mu_s = -1.0) {
  WallDef w;
  w.name = std::move(name);
  w.from = from;
  w.to = to;
  w.material.restitution = e;
  w.material.friction = mu;
  w.material.static_friction = mu_s < 0.0 ? mu : mu_s;
  return w;
}

// A [[materials]] override of a pair's friction (kinetic and static both mu).
inline MaterialOverride pair_friction(std::string a, std::string b, double mu) {
  MaterialOverride m;
  m.a = std::move(a);
  m.b = std::move(b);
  m.friction = mu;
  m.static_friction = mu;
  return m;
}

inline Scene scene_of(std::vector<BodyDef> bodies, std::vector<WallDef> walls = {}, Vec2 gravity = {}) {
  Scene s;
  s.name = "test";
  s.bodies = std::move(bodies);
  s.walls = std::move(walls);
  s.world.gravity = gravity;
  return s;
}

// The scene's mirror image in x = 0 (bodies and walls; each wall drawn the other way, so
// the same side faces the bodies), and a state mirrored back.
inline void mirror_x(Scene& s) {
  for (BodyDef& b : s.bodies) {
    b.position.x = -b.position.x;
    b.velocity.x = -b.velocity.x;
  }
  for (WallDef& w : s.walls) {
    w.from.x = -w.from.x;
    w.to.x = -w.to.x;
    std::swap(w.from, w.to);
  }
}
inline void mirror_x(BodyState& b) {
  b.position.x = -b.position.x;
  b.velocity.x = -b.velocity.x;
}

inline EngineOptions options(std::string integrator, std::string collision = "exact") {
  return {{"integrator", std::move(integrator)}, {"collision", std::move(collision)}};
}

// Loads a scene into core and steps it, keeping every contact event.
struct Sim {
  CoreEngine engine;
  std::vector<ContactEvent> contacts;
  std::vector<BodyState> states;
  Scene scene;

  explicit Sim(Scene s, EngineOptions opts = {}) : scene(std::move(s)) {
    if (!opts.empty()) scene.engine_options["core"] = std::move(opts);
    engine.load(scene);
  }
  void step(double dt) {
    engine.step(dt);
    const auto& c = engine.contacts();
    contacts.insert(contacts.end(), c.begin(), c.end());
  }
  void steps(int n, double dt) {
    for (int k = 0; k < n; ++k) step(dt);
  }
  // Steps of dt until time t (the last step shortened to land on t exactly).
  void run_until(double t, double dt) {
    while (engine.time() < t - 1e-12) step(std::min(dt, t - engine.time()));
  }
  BodyState state(std::size_t i) {
    engine.read_states(states);
    return states.at(i);
  }
  BodyState state(const std::string& name) { return state(static_cast<std::size_t>(scene.body_index(name))); }
};

}  // namespace physval::test
