// What an adapter needs to know of the objects a contact involves: the scene's names,
// materials and collision-matrix groups behind an ObjectRef, and the order physval
// reports a pair in. Both adapters store ObjectRefs in their engine's user data and
// come back here from the engine's callbacks.
#pragma once

#include <cstdint>
#include <string>

#include "physval/core/engine.hpp"
#include "physval/core/scene.hpp"

namespace physval::adapter {

// An ObjectRef packed into one integer (kind above bit 32), for an engine's user data.
inline std::uint64_t pack(ObjectRef r) {
  return (static_cast<std::uint64_t>(r.kind) << 32) | static_cast<std::uint64_t>(r.index);
}
inline ObjectRef unpack(std::uint64_t v) {
  return {static_cast<ObjectRef::Kind>(v >> 32), static_cast<std::uint32_t>(v & 0xffffffffULL)};
}

// A pair of objects in physval's order (see make_contact_event), packed: a map key.
struct PairKey {
  std::uint64_t a = 0;
  std::uint64_t b = 0;
  friend auto operator<=>(const PairKey&, const PairKey&) = default;
};

// The pair in physval's order: a body first; two bodies by index (a.index < b.index).
// Returns false when neither object is a body (static barriers never meet each other).
bool order_pair(ObjectRef x, ObjectRef y, ObjectRef& a, ObjectRef& b);
PairKey pair_key(ObjectRef a, ObjectRef b);   // of an ordered pair

// An engine maps rolling_friction to contact friction mu = c only for bodies that do
// not spin; with rotation on, that friction would make a wheel roll free. Throws
// invalid_argument naming the engine's option otherwise.
void require_fixed_rotation_for_rolling(const Scene& scene, bool fixed_rotation, const char* engine);

class SceneObjects {
 public:
  explicit SceneObjects(const Scene& scene) : scene_(scene) {}

  const std::string& name(ObjectRef r) const;
  MaterialView material(ObjectRef r) const;
  const std::string& group(ObjectRef r) const;

  // physval's one material rule (scene.hpp), the same for every engine.
  PairMaterial pair_material(ObjectRef a, ObjectRef b) const {
    return combine_materials(scene_, material(a), material(b));
  }
  // The one friction coefficient an engine's contact gets. core models a pair with
  // rolling_friction c > 0, for bodies that do not spin, as Coulomb friction with
  // mu_s = mu_k = c (resting_contact.cpp); an engine expresses exactly that through its
  // contact friction. Otherwise the kinetic coefficient (engines have one coefficient).
  double contact_friction(ObjectRef a, ObjectRef b) const {
    const PairMaterial m = pair_material(a, b);
    return m.rolling_friction > 0.0 ? m.rolling_friction : m.friction;
  }
  // What the collision matrix says happens between a and b (destroy_first names a).
  PairResponse response(ObjectRef a, ObjectRef b) const {
    return response_between(scene_, group(a), group(b));
  }
  // Walls, boxes and surfaces are permanent; only bodies can be destroyed.
  static bool destructible(ObjectRef r) { return r.kind == ObjectRef::Kind::Body; }

  // What the comparator needs of scene body i: name, mass (0 when static), radius.
  BodyMeta body_meta(std::size_t i) const {
    const BodyDef& b = scene_.bodies.at(i);
    return {b.name, b.is_static ? 0.0 : b.mass, b.shape == ShapeKind::Point ? 0.0 : b.radius, b.is_static};
  }

 private:
  const Scene& scene_;
};

}  // namespace physval::adapter
