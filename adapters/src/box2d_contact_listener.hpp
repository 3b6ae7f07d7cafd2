// Box2D's contact callbacks for one physval run: imposes physval's material rule on
// every contact (PreSolve), the collision matrix (ShouldCollide, PreSolve SetEnabled,
// destruction after the step), and turns BeginContact into physval's contact events.
#pragma once

#include <map>
#include <vector>

#include "box2d_includes.hpp"
#include "physval/core/engine.hpp"
#include "scene_objects.hpp"

namespace physval::adapter {

class Box2DContactListener final : public b2ContactListener, public b2ContactFilter {
 public:
  Box2DContactListener(const SceneObjects& objects, float restitution_threshold)
      : objects_(objects), restitution_threshold_(restitution_threshold) {}

  // Events seen from now on are stamped with `end_time`: the end of the step about to run.
  void begin_step(double end_time);
  const std::vector<ContactEvent>& events() const { return events_; }
  // Bodies the collision matrix destroyed during the step (each once).
  std::vector<std::uint32_t> take_destroyed();

  // b2ContactFilter: pairs the collision matrix ignores never become contacts.
  bool ShouldCollide(b2Fixture* fixture_a, b2Fixture* fixture_b) override;
  // b2ContactListener
  void BeginContact(b2Contact* contact) override;
  void EndContact(b2Contact* contact) override;
  void PreSolve(b2Contact* contact, const b2Manifold* old_manifold) override;

 private:
  static ObjectRef ref_of(b2Fixture* f) { return unpack(f->GetUserData().pointer); }

  const SceneObjects& objects_;
  float restitution_threshold_;
  double end_time_ = 0.0;
  std::vector<ContactEvent> events_;
  std::vector<std::uint32_t> destroyed_;
  // Touching Box2D contacts per physval pair: a circle rolling along a chain touches
  // one child edge after another, but the pair (circle, surface) begins contact once.
  std::map<PairKey, int> touching_;
};

}  // namespace physval::adapter
