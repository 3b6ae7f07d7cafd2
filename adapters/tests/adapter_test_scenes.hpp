// Small scenes built in code for the adapter tests (the TOML loader in validation/
// will read the same scenes from files), and helpers to run an engine on them.
#pragma once

#include <cmath>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "physval/adapters/registry.hpp"
#include "physval/core/engine.hpp"
#include "physval/core/scene.hpp"

namespace physval::test {

inline BodyDef circle(const std::string& name, double radius, double mass, Vec2 position, Vec2 velocity,
                      double restitution = 1.0) {
  BodyDef b;
  b.name = name;
  b.radius = radius;
  b.mass = mass;
  b.position = position;
  b.velocity = velocity;
  b.restitution = restitution;
  return b;
}

inline WallDef wall(const std::string& name, Vec2 from, Vec2 to, double restitution = 1.0) {
  WallDef w;
  w.name = name;
  w.from = from;
  w.to = to;
  w.material.restitution = restitution;
  return w;
}

inline Scene empty_scene(const std::string& name, double dt, double duration) {
  Scene s;
  s.name = name;
  s.dt = dt;
  s.duration = duration;
  return s;
}

// Two circles of radius 0.5 on the x axis, 4 m apart (centres), meeting head-on.
inline Scene head_on(double m1, double m2, double v1, double v2, double dt) {
  Scene s = empty_scene("head_on", dt, 2.0);
  s.bodies.push_back(circle("a", 0.5, m1, {-2.0, 0.0}, {v1, 0.0}));
  s.bodies.push_back(circle("b", 0.5, m2, {2.0, 0.0}, {v2, 0.0}));
  return s;
}

inline std::unique_ptr<Engine> make_engine(const std::string& engine, const Scene& scene) {
  const EngineFactory* f = find_engine(engine);
  if (f == nullptr) throw std::runtime_error("no engine " + engine);
  std::unique_ptr<Engine> e = f->create();
  e->load(scene);
  return e;
}

// Runs `steps` steps of scene.dt, collecting every contact event.
inline std::vector<ContactEvent> run(Engine& e, const Scene& scene, int steps) {
  std::vector<ContactEvent> all;
  for (int i = 0; i < steps; ++i) {
    e.step(scene.dt);
    all.insert(all.end(), e.contacts().begin(), e.contacts().end());
  }
  return all;
}

inline std::vector<BodyState> states(const Engine& e) {
  std::vector<BodyState> out;
  e.read_states(out);
  return out;
}

inline bool has_setting(const std::vector<Setting>& settings, const std::string& key) {
  for (const Setting& s : settings) {
    if (s.first == key) return true;
  }
  return false;
}

inline std::string setting(const std::vector<Setting>& settings, const std::string& key) {
  for (const Setting& s : settings) {
    if (s.first == key) return s.second;
  }
  return {};
}

inline bool any_limit_starts_with(const std::vector<std::string>& lines, const std::string& prefix) {
  for (const std::string& l : lines) {
    if (l.rfind(prefix, 0) == 0) return true;
  }
  return false;
}

}  // namespace physval::test
