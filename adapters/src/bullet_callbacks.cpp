#include "bullet_callbacks.hpp"

#include <mutex>

namespace physval::adapter {
namespace {

// "phys": marks a collision object whose user pointer is an ObjectTag.
constexpr int kTagMark = 0x70687973;

btScalar combined_restitution(const btCollisionObject* a, const btCollisionObject* b) {
  const ObjectTag* ta = tag_of(a);
  const ObjectTag* tb = tag_of(b);
  if (ta == nullptr || tb == nullptr || ta->objects != tb->objects) {
    return a->getRestitution() * b->getRestitution();   // Bullet's own rule
  }
  return static_cast<btScalar>(ta->objects->pair_material(ta->ref, tb->ref).restitution);
}

btScalar combined_friction(const btCollisionObject* a, const btCollisionObject* b) {
  const ObjectTag* ta = tag_of(a);
  const ObjectTag* tb = tag_of(b);
  if (ta == nullptr || tb == nullptr || ta->objects != tb->objects) {
    const btScalar f = a->getFriction() * b->getFriction();   // Bullet's own rule, clamped at 10
    return btClamped(f, btScalar(-10.0), btScalar(10.0));
  }
  return static_cast<btScalar>(ta->objects->contact_friction(ta->ref, tb->ref));   // rolling_friction: mu = c
}

}  // namespace

void attach_tag(btCollisionObject& object, const ObjectTag& tag) {
  object.setUserIndex(kTagMark);
  object.setUserPointer(const_cast<ObjectTag*>(&tag));
}

const ObjectTag* tag_of(const btCollisionObject* object) {
  if (object == nullptr || object->getUserIndex() != kTagMark) return nullptr;
  return static_cast<const ObjectTag*>(object->getUserPointer());
}

void install_material_callbacks() {
  static std::once_flag once;
  std::call_once(once, [] {
    gCalculateCombinedRestitutionCallback = &combined_restitution;
    gCalculateCombinedFrictionCallback = &combined_friction;
  });
}

bool CollisionMatrixFilter::needBroadphaseCollision(btBroadphaseProxy* proxy0, btBroadphaseProxy* proxy1) const {
  // Bullet's default test first (static objects never pair with each other).
  const bool filtered = (proxy0->m_collisionFilterGroup & proxy1->m_collisionFilterMask) != 0 &&
                        (proxy1->m_collisionFilterGroup & proxy0->m_collisionFilterMask) != 0;
  if (!filtered) return false;
  const ObjectTag* t0 = tag_of(static_cast<const btCollisionObject*>(proxy0->m_clientObject));
  const ObjectTag* t1 = tag_of(static_cast<const btCollisionObject*>(proxy1->m_clientObject));
  if (t0 == nullptr || t1 == nullptr || t0->objects != t1->objects) return true;
  const PairResponse r = t0->objects->response(t0->ref, t1->ref);
  return r.collide || r.event;
}

btPersistentManifold* PhysvalDispatcher::getNewManifold(const btCollisionObject* b0, const btCollisionObject* b1) {
  btPersistentManifold* m = btCollisionDispatcher::getNewManifold(b0, b1);
  const ObjectTag* t0 = tag_of(b0);
  const ObjectTag* t1 = tag_of(b1);
  if (t0 != nullptr && t1 != nullptr && t0->objects == t1->objects &&
      !t0->objects->response(t0->ref, t1->ref).collide) {
    // An "event" pair: its points are found (and reported) but never solved.
    m->setContactProcessingThreshold(-BT_LARGE_FLOAT);
  }
  return m;
}

}  // namespace physval::adapter
