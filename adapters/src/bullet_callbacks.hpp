// Bullet's hooks into physval's rules. Every physval collision object carries an
// ObjectTag (user pointer, marked by its user index) naming its scene object, so that
// Bullet's global callbacks, its pair filter and its dispatcher can find the scene:
//  - the combine callbacks impose physval's material rule (Bullet's own: e1 e2, f1 f2);
//  - the overlap filter drops pairs the collision matrix ignores;
//  - the dispatcher gives "event" pairs manifolds the solver never processes.
// No global state names a run: the callbacks find everything through the tags, so
// runs on different threads do not meet.
#pragma once

#include "bullet_includes.hpp"
#include "scene_objects.hpp"

namespace physval::adapter {

struct ObjectTag {
  const SceneObjects* objects = nullptr;
  ObjectRef ref;
};

// Marks `object` as physval's, pointing at `tag` (which must outlive it).
void attach_tag(btCollisionObject& object, const ObjectTag& tag);
// The tag of a physval object, or nullptr for any other collision object.
const ObjectTag* tag_of(const btCollisionObject* object);

// Installs physval's combine callbacks (once per process). Objects without a tag keep
// Bullet's own rules, so the installation changes nothing for anyone else.
void install_material_callbacks();

class CollisionMatrixFilter final : public btOverlapFilterCallback {
 public:
  bool needBroadphaseCollision(btBroadphaseProxy* proxy0, btBroadphaseProxy* proxy1) const override;
};

class PhysvalDispatcher final : public btCollisionDispatcher {
 public:
  explicit PhysvalDispatcher(btCollisionConfiguration* config) : btCollisionDispatcher(config) {}
  btPersistentManifold* getNewManifold(const btCollisionObject* b0, const btCollisionObject* b1) override;
};

}  // namespace physval::adapter
