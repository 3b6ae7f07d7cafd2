#include "scene_objects.hpp"

#include <stdexcept>
#include <string>

namespace physval::adapter {

bool order_pair(ObjectRef x, ObjectRef y, ObjectRef& a, ObjectRef& b) {
  const bool x_body = x.kind == ObjectRef::Kind::Body;
  const bool y_body = y.kind == ObjectRef::Kind::Body;
  if (!x_body && !y_body) return false;
  if (x_body && y_body) {
    a = x.index < y.index ? x : y;
    b = x.index < y.index ? y : x;
  } else {
    a = x_body ? x : y;
    b = x_body ? y : x;
  }
  return true;
}

void require_fixed_rotation_for_rolling(const Scene& scene, bool fixed_rotation, const char* engine) {
  if (fixed_rotation) return;
  for (const Feature f : scene_features(scene)) {
    if (f == Feature::RollingFriction) {
      throw std::invalid_argument(std::string(engine) +
                                  ": rolling_friction is mapped to contact friction mu = c for bodies that do not "
                                  "spin; it needs " + engine + ".fixed_rotation = true");
    }
  }
}

PairKey pair_key(ObjectRef a, ObjectRef b) { return {pack(a), pack(b)}; }

const std::string& SceneObjects::name(ObjectRef r) const {
  switch (r.kind) {
    case ObjectRef::Kind::Body: return scene_.bodies.at(r.index).name;
    case ObjectRef::Kind::Wall: return scene_.walls.at(r.index).name;
    case ObjectRef::Kind::Box: return scene_.boxes.at(r.index).name;
    case ObjectRef::Kind::Surface: return scene_.surfaces.at(r.index).name;
  }
  throw std::logic_error("unknown object kind");
}

MaterialView SceneObjects::material(ObjectRef r) const {
  switch (r.kind) {
    case ObjectRef::Kind::Body: return material_of(scene_.bodies.at(r.index));
    case ObjectRef::Kind::Wall: {
      const WallDef& w = scene_.walls.at(r.index);
      return material_of(w.name, w.material);
    }
    case ObjectRef::Kind::Box: {
      const BoxDef& w = scene_.boxes.at(r.index);
      return material_of(w.name, w.material);
    }
    case ObjectRef::Kind::Surface: {
      const SurfaceDef& w = scene_.surfaces.at(r.index);
      return material_of(w.name, w.material);
    }
  }
  throw std::logic_error("unknown object kind");
}

const std::string& SceneObjects::group(ObjectRef r) const {
  switch (r.kind) {
    case ObjectRef::Kind::Body: return scene_.bodies.at(r.index).group;
    case ObjectRef::Kind::Wall: return scene_.walls.at(r.index).material.group;
    case ObjectRef::Kind::Box: return scene_.boxes.at(r.index).material.group;
    case ObjectRef::Kind::Surface: return scene_.surfaces.at(r.index).material.group;
  }
  throw std::logic_error("unknown object kind");
}

}  // namespace physval::adapter
