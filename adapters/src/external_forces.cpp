#include "external_forces.hpp"

#include "physval/core/forces.hpp"

namespace physval::adapter {

ExternalForces::ExternalForces(const Scene& scene) : scene_(scene), field_free_(scene.world) {
  field_free_.gravity = {};
  newtonian_ = scene.world.newtonian;
  active_ = newtonian_;
  for (const BodyDef& b : scene.bodies) {
    if (b.is_static) continue;
    if (b.drag_linear != 0.0 || b.drag_quadratic != 0.0 || b.thrust.enabled()) active_ = true;
  }
}

void ExternalForces::compute(const std::vector<BodyState>& states, std::vector<Vec2>& forces) {
  forces.assign(states.size(), Vec2{});
  for (std::size_t i = 0; i < states.size() && i < scene_.bodies.size(); ++i) {
    const BodyDef& b = scene_.bodies[i];
    if (b.is_static || !states[i].alive) continue;
    // body_force() of a field-free world: drag towards the wind and thrust.
    forces[i] = body_force(b, field_free_, states[i].velocity, states[i].angle);
  }
  if (!newtonian_) return;
  positions_.clear();
  masses_.clear();
  alive_.clear();
  for (std::size_t i = 0; i < states.size() && i < scene_.bodies.size(); ++i) {
    if (!states[i].alive) continue;
    alive_.push_back(i);
    positions_.push_back(states[i].position);
    masses_.push_back(scene_.bodies[i].mass);   // static bodies attract with their mass
  }
  pair_forces_.assign(alive_.size(), Vec2{});
  add_newtonian_forces(scene_.world.G, scene_.world.softening, positions_, masses_, pair_forces_);
  for (std::size_t k = 0; k < alive_.size(); ++k) {
    const std::size_t i = alive_[k];
    if (!scene_.bodies[i].is_static) forces[i] += pair_forces_[k];
  }
}

}  // namespace physval::adapter
