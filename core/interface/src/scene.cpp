#include "physval/engine/scene.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <optional>

namespace physval {

int Scene::steps() const {
  const double n = std::ceil(duration / dt - 1e-9);
  if (!(n <= static_cast<double>(kMaxSteps))) return kMaxSteps + 1;   // also NaN: never wraps
  return n < 1.0 ? 1 : static_cast<int>(n);
}

std::string scene_steps_error(const Scene& s) {
  char text[260];
  // The reference steps at down to dt/16: a dt whose 16th is not a normal double (a
  // subnormal dt such as 5e-324 s, whose halves round to 0) is a step nothing can take.
  if (s.dt > 0.0 && !(s.dt / 16.0 >= std::numeric_limits<double>::min())) {
    std::snprintf(text, sizeof text, "dt = %.6g s is too small: the reference steps at dt/16, below the smallest "
                  "normal double (%.6g); use dt >= %.6g", s.dt, std::numeric_limits<double>::min(),
                  16.0 * std::numeric_limits<double>::min());
    return text;
  }
  if (s.steps() <= Scene::kMaxSteps) return {};
  std::snprintf(text, sizeof text, "duration / dt = %.6g / %.6g = %.4g steps, more than physval runs (%d); "
                "shorten the duration or enlarge dt", s.duration, s.dt, s.duration / s.dt, Scene::kMaxSteps);
  return text;
}

double Scene::last_step() const {
  const double rest = duration - static_cast<double>(steps() - 1) * dt;
  return std::abs(rest - dt) <= 1e-9 * dt ? dt : rest;
}

int Scene::body_index(const std::string& body_name) const {
  for (std::size_t i = 0; i < bodies.size(); ++i) {
    if (bodies[i].name == body_name) return static_cast<int>(i);
  }
  return -1;
}

MaterialView material_of(const BodyDef& b) {
  return {b.name, b.restitution, b.friction, b.static_friction, b.rolling_friction};
}

MaterialView material_of(const std::string& name, const StaticMaterial& m) {
  return {name, m.restitution, m.friction, m.static_friction, m.rolling_friction};
}

PairMaterial combine_materials(const Scene& scene, const MaterialView& a, const MaterialView& b) {
  PairMaterial pm;
  pm.restitution = std::min(a.restitution, b.restitution);
  pm.friction = std::sqrt(a.friction * b.friction);
  pm.static_friction = std::sqrt(a.static_friction * b.static_friction);
  pm.rolling_friction = std::sqrt(a.rolling_friction * b.rolling_friction);
  for (const MaterialOverride& o : scene.materials) {
    const bool match = (o.a == a.name && o.b == b.name) || (o.a == b.name && o.b == a.name);
    if (!match) continue;
    if (o.restitution) pm.restitution = *o.restitution;
    if (o.friction) pm.friction = *o.friction;
    if (o.static_friction) pm.static_friction = *o.static_friction;
    if (o.rolling_friction) pm.rolling_friction = *o.rolling_friction;
    // An entry giving `friction` alone gives the pair one coefficient (mu_s = mu_k), as a body
    // with `friction` alone has: `friction = 0.0` is a frictionless pair.
    if (o.friction && !o.static_friction) pm.static_friction = *o.friction;
  }
  return pm;
}

PairResponse response_between(const Scene& scene, const std::string& group_first,
                              const std::string& group_second) {
  PairResponse r;
  for (const CollisionRule& rule : scene.collision_matrix) {
    bool swapped;
    if (rule.a == group_first && rule.b == group_second) {
      swapped = false;
    } else if (rule.a == group_second && rule.b == group_first) {
      swapped = true;
    } else {
      continue;
    }
    switch (rule.response) {
      case CollisionResponse::Bounce: break;
      case CollisionResponse::Ignore: r.collide = false; r.event = false; break;
      case CollisionResponse::Event: r.collide = false; r.event = true; break;
      case CollisionResponse::DestroyA: (swapped ? r.destroy_second : r.destroy_first) = true; break;
      case CollisionResponse::DestroyB: (swapped ? r.destroy_first : r.destroy_second) = true; break;
      case CollisionResponse::DestroyBoth: r.destroy_first = r.destroy_second = true; break;
    }
    return r;
  }
  return r;
}

const char* feature_name(Feature f) {
  switch (f) {
    case Feature::Circles: return "circles";
    case Feature::Points: return "points";
    case Feature::StaticBodies: return "static_bodies";
    case Feature::Walls: return "walls";
    case Feature::Boxes: return "boxes";
    case Feature::Surfaces: return "surfaces";
    case Feature::UniformGravity: return "uniform_gravity";
    case Feature::NewtonianGravity: return "newtonian_gravity";
    case Feature::LinearDrag: return "linear_drag";
    case Feature::QuadraticDrag: return "quadratic_drag";
    case Feature::Wind: return "wind";
    case Feature::Thrust: return "thrust";
    case Feature::Friction: return "friction";
    case Feature::StaticFriction: return "static_friction";
    case Feature::RollingFriction: return "rolling_friction";
    case Feature::MaterialOverrides: return "material_overrides";
    case Feature::CollisionMatrix: return "collision_matrix";
    case Feature::Particles: return "particles";
    case Feature::SurfaceNormals: return "surface_normals";
    case Feature::Count: break;
  }
  return "unknown";
}

std::vector<Feature> scene_features(const Scene& scene) {
  bool used[static_cast<int>(Feature::Count)] = {};
  auto use = [&](Feature f) { used[static_cast<int>(f)] = true; };
  auto material = [&](double friction, double static_friction, double rolling) {
    if (friction > 0.0 || static_friction > 0.0) use(Feature::Friction);
    if (static_friction > friction) use(Feature::StaticFriction);
    if (rolling > 0.0) use(Feature::RollingFriction);
  };
  for (const BodyDef& b : scene.bodies) {
    use(b.shape == ShapeKind::Circle ? Feature::Circles : Feature::Points);
    if (b.is_static) use(Feature::StaticBodies);
    if (b.drag_linear > 0.0) use(Feature::LinearDrag);
    if (b.drag_quadratic > 0.0) use(Feature::QuadraticDrag);
    if (b.thrust.enabled()) use(Feature::Thrust);
    material(b.friction, b.static_friction, b.rolling_friction);
  }
  if (!scene.walls.empty()) use(Feature::Walls);
  if (!scene.boxes.empty()) use(Feature::Boxes);
  if (!scene.surfaces.empty()) use(Feature::Surfaces);
  for (const SurfaceDef& sf : scene.surfaces) {
    if (!sf.normals.empty()) use(Feature::SurfaceNormals);
  }
  for (const WallDef& w : scene.walls) material(w.material.friction, w.material.static_friction, w.material.rolling_friction);
  for (const BoxDef& w : scene.boxes) material(w.material.friction, w.material.static_friction, w.material.rolling_friction);
  for (const SurfaceDef& w : scene.surfaces) material(w.material.friction, w.material.static_friction, w.material.rolling_friction);
  if (scene.world.gravity.x != 0.0 || scene.world.gravity.y != 0.0) use(Feature::UniformGravity);
  if (scene.world.newtonian) use(Feature::NewtonianGravity);
  const bool drag = used[static_cast<int>(Feature::LinearDrag)] || used[static_cast<int>(Feature::QuadraticDrag)];
  if (drag && (scene.world.wind.x != 0.0 || scene.world.wind.y != 0.0)) use(Feature::Wind);
  if (!scene.materials.empty()) use(Feature::MaterialOverrides);
  // A [[materials]] override is a pair's material too: the pair's combined coefficients are
  // features (before the tenth hunt an override static_friction = 0.85 over a pair of kinetic
  // 0.2 ran on Box2D, Bullet, Chipmunk and ODE, which model one coefficient, as `ok`: a ball
  // core held on a 0.5 rad slope slid 1.5 m there).
  for (const MaterialOverride& o : scene.materials) {
    const auto view = [&](const std::string& name) -> std::optional<MaterialView> {
      for (const BodyDef& b : scene.bodies) if (b.name == name) return material_of(b);
      for (const WallDef& w : scene.walls) if (w.name == name) return material_of(w.name, w.material);
      for (const BoxDef& w : scene.boxes) if (w.name == name) return material_of(w.name, w.material);
      for (const SurfaceDef& w : scene.surfaces) if (w.name == name) return material_of(w.name, w.material);
      return std::nullopt;
    };
    const std::optional<MaterialView> a = view(o.a), b = view(o.b);
    if (!a || !b) continue;
    const PairMaterial pm = combine_materials(scene, *a, *b);
    if (pm.friction > 0.0 || pm.static_friction > 0.0) use(Feature::Friction);
    // also an override that lowers only the kinetic friction (`friction = 0.0` between rough
    // bodies): the pair keeps its static friction (combine_materials), so core holds it at rest
    // while an engine with one coefficient lets it slide
    if (pm.static_friction > pm.friction) use(Feature::StaticFriction);
    if (pm.rolling_friction > 0.0) use(Feature::RollingFriction);
  }
  if (!scene.collision_matrix.empty()) use(Feature::CollisionMatrix);
  if (!scene.emitters.empty()) use(Feature::Particles);
  std::vector<Feature> out;
  for (int i = 0; i < static_cast<int>(Feature::Count); ++i) {
    if (used[i]) out.push_back(static_cast<Feature>(i));
  }
  return out;
}

}  // namespace physval
