#include "box2d_contact_listener.hpp"

#include <algorithm>

namespace physval::adapter {

void Box2DContactListener::begin_step(double end_time) {
  end_time_ = end_time;
  events_.clear();
}

std::vector<std::uint32_t> Box2DContactListener::take_destroyed() {
  std::vector<std::uint32_t> out;
  out.swap(destroyed_);
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

bool Box2DContactListener::ShouldCollide(b2Fixture* fixture_a, b2Fixture* fixture_b) {
  const PairResponse r = objects_.response(ref_of(fixture_a), ref_of(fixture_b));
  return r.collide || r.event;
}

void Box2DContactListener::BeginContact(b2Contact* contact) {
  ObjectRef a;
  ObjectRef b;
  if (!order_pair(ref_of(contact->GetFixtureA()), ref_of(contact->GetFixtureB()), a, b)) return;
  if (++touching_[pair_key(a, b)] != 1) return;   // this pair already touches elsewhere
  const PairResponse r = objects_.response(a, b);
  if (r.event) events_.push_back({a, b, end_time_});
  // Destroyed after the step: Box2D resolves this step's bounce first, as the matrix says.
  if (r.destroy_first && SceneObjects::destructible(a)) destroyed_.push_back(a.index);
  if (r.destroy_second && SceneObjects::destructible(b)) destroyed_.push_back(b.index);
}

void Box2DContactListener::EndContact(b2Contact* contact) {
  ObjectRef a;
  ObjectRef b;
  if (!order_pair(ref_of(contact->GetFixtureA()), ref_of(contact->GetFixtureB()), a, b)) return;
  auto it = touching_.find(pair_key(a, b));
  if (it != touching_.end() && --it->second <= 0) touching_.erase(it);
}

void Box2DContactListener::PreSolve(b2Contact* contact, const b2Manifold* /*old_manifold*/) {
  const ObjectRef a = ref_of(contact->GetFixtureA());
  const ObjectRef b = ref_of(contact->GetFixtureB());
  const PairResponse r = objects_.response(a, b);
  if (!r.collide) {   // an "event" pair: reported, but it passes through
    contact->SetEnabled(false);
    return;
  }
  // Box2D mixes restitution as max(e1, e2); physval's rule replaces it on every contact.
  const PairMaterial m = objects_.pair_material(a, b);
  contact->SetRestitution(static_cast<float>(m.restitution));
  contact->SetFriction(static_cast<float>(objects_.contact_friction(a, b)));   // rolling_friction: mu = c
  contact->SetRestitutionThreshold(restitution_threshold_);
}

}  // namespace physval::adapter
