#include "physval/validation/conservation.hpp"

#include <algorithm>
#include <cmath>

#include "physval/core/forces.hpp"

namespace physval {

Totals compute_totals(const Scene& scene, const std::vector<BodyMeta>& bodies,
                      const std::vector<BodyState>& states) {
  Totals t;
  const std::size_t n = std::min(bodies.size(), states.size());
  const Vec2 g = scene.world.gravity;
  for (std::size_t i = 0; i < n; ++i) {
    const BodyState& s = states[i];
    const BodyMeta& b = bodies[i];
    if (!s.alive || b.is_static) continue;
    t.kinetic += 0.5 * b.mass * length_squared(s.velocity);
    t.potential -= b.mass * dot(g, s.position);
    t.momentum += b.mass * s.velocity;
    t.angular_momentum += b.mass * cross(s.position, s.velocity);
  }
  if (scene.world.newtonian) {
    for (std::size_t i = 0; i < n; ++i) {
      if (!states[i].alive) continue;
      for (std::size_t j = i + 1; j < n; ++j) {
        if (!states[j].alive) continue;
        if (bodies[i].is_static && bodies[j].is_static) continue;
        // A static body's mass still attracts: scene bodies carry it in the scene.
        const double mi = bodies[i].is_static && i < scene.bodies.size() ? scene.bodies[i].mass : bodies[i].mass;
        const double mj = bodies[j].is_static && j < scene.bodies.size() ? scene.bodies[j].mass : bodies[j].mass;
        t.potential += newtonian_potential(scene.world.G, scene.world.softening, mi, mj, states[i].position,
                                           states[j].position);
      }
    }
  }
  return t;
}

double binding_energy(const Scene& scene, double initial_energy) {
  if (!scene.world.newtonian) return 0.0;
  double binding = std::max(0.0, -initial_energy);
  const std::size_t n = scene.bodies.size();
  for (std::size_t i = 0; i < n; ++i) {
    const BodyDef& a = scene.bodies[i];
    for (std::size_t j = i + 1; j < n; ++j) {
      const BodyDef& b = scene.bodies[j];
      if (a.is_static && b.is_static) continue;
      double kinetic = 0.0;
      if (a.is_static || b.is_static) {
        const BodyDef& m = a.is_static ? b : a;
        kinetic = 0.5 * m.mass * length_squared(m.velocity);
      } else {
        const double mu = a.mass * b.mass / (a.mass + b.mass);
        kinetic = 0.5 * mu * length_squared(a.velocity - b.velocity);
      }
      const double e = kinetic + newtonian_potential(scene.world.G, scene.world.softening, a.mass, b.mass,
                                                     a.position, b.position);
      if (std::isfinite(e)) binding = std::max(binding, -e);
    }
  }
  return binding;
}

Conserved conserved_quantities(const Scene& scene) {
  Conserved c;
  const bool has_barriers = !scene.walls.empty() || !scene.boxes.empty() || !scene.surfaces.empty() ||
                            std::any_of(scene.bodies.begin(), scene.bodies.end(), [](const BodyDef& b) { return b.is_static; });
  const bool field = scene.world.gravity.x != 0.0 || scene.world.gravity.y != 0.0;
  // A pair whose restitution is above 1 (a pinball bumper) gains energy at every impact:
  // energy is then neither conserved nor only lost (before the tenth hunt e = 1.2 counted as
  // elastic, and every engine, core too, read an energy drift of 0.27 in a scene held to
  // conserve it). A pair's restitution is the smaller of the two (or its override), so it
  // takes two objects above 1 (bodies, or a body and a barrier), or an override above 1.
  bool drag = false, thrust = false, friction = false, inelastic = false, superelastic = false;
  int bodies_above_one = 0;
  bool barrier_above_one = false;
  for (const BodyDef& b : scene.bodies) {
    drag = drag || b.drag_linear > 0.0 || b.drag_quadratic > 0.0;
    thrust = thrust || b.thrust.enabled();
    friction = friction || b.friction > 0.0 || b.static_friction > 0.0 || b.rolling_friction > 0.0;
    inelastic = inelastic || b.restitution < 1.0;
    if (b.restitution > 1.0) ++bodies_above_one;
  }
  auto static_material = [&](const StaticMaterial& m) {
    friction = friction || m.friction > 0.0 || m.static_friction > 0.0 || m.rolling_friction > 0.0;
    inelastic = inelastic || m.restitution < 1.0;
    barrier_above_one = barrier_above_one || m.restitution > 1.0;
  };
  for (const WallDef& w : scene.walls) static_material(w.material);
  for (const BoxDef& w : scene.boxes) static_material(w.material);
  for (const SurfaceDef& w : scene.surfaces) static_material(w.material);
  for (const MaterialOverride& m : scene.materials) {
    friction = friction || m.friction.value_or(0.0) > 0.0 || m.static_friction.value_or(0.0) > 0.0 ||
               m.rolling_friction.value_or(0.0) > 0.0;
    inelastic = inelastic || m.restitution.value_or(1.0) < 1.0;
    superelastic = superelastic || m.restitution.value_or(1.0) > 1.0;
  }
  superelastic = superelastic || bodies_above_one >= 2 || (bodies_above_one >= 1 && barrier_above_one);
  const bool particles = !scene.emitters.empty();
  const bool destroys = std::any_of(scene.collision_matrix.begin(), scene.collision_matrix.end(), [](const CollisionRule& r) {
    return r.response == CollisionResponse::DestroyA || r.response == CollisionResponse::DestroyB ||
           r.response == CollisionResponse::DestroyBoth;
  });

  // Friction between two moving bodies: its tangential impulse acts at the contact point,
  // but bodies do not spin (the lecture model, and every adapter's default fixed_rotation),
  // so the torque it exerts about each centre goes into no spin: orbital angular momentum
  // changes by (x_a - x_b) x J. A pair has friction when both bodies have a coefficient
  // (the rule is the geometric mean) or a [[materials]] override between bodies gives one.
  auto has_friction = [](const BodyDef& b) {
    return b.friction > 0.0 || b.static_friction > 0.0 || b.rolling_friction > 0.0;
  };
  const auto moving_with_friction = std::count_if(scene.bodies.begin(), scene.bodies.end(), [&](const BodyDef& b) {
    return !b.is_static && has_friction(b);
  });
  auto is_moving_body = [&](const std::string& name) {
    return std::any_of(scene.bodies.begin(), scene.bodies.end(),
                       [&](const BodyDef& b) { return b.name == name && !b.is_static; });
  };
  const bool pair_friction =
      moving_with_friction >= 2 ||
      std::any_of(scene.materials.begin(), scene.materials.end(), [&](const MaterialOverride& m) {
        return (m.friction.value_or(0.0) > 0.0 || m.static_friction.value_or(0.0) > 0.0 ||
                m.rolling_friction.value_or(0.0) > 0.0) &&
               is_moving_body(m.a) && is_moving_body(m.b);
      });

  if (has_barriers) c.momentum_why = "barriers or static bodies push";
  else if (field) c.momentum_why = "a uniform field pulls";
  else if (drag) c.momentum_why = "drag";
  else if (thrust) c.momentum_why = "thrust";
  else if (particles) c.momentum_why = "particles are emitted and die";
  else if (destroys) c.momentum_why = "the collision matrix destroys bodies";
  else c.momentum_why = "no external force";
  c.linear_momentum = c.momentum_why == "no external force";
  // Contact impulses act along the line through both centres at the contact point,
  // and friction impulses at that same point: about the origin they cancel too.
  c.angular_momentum = c.linear_momentum && !pair_friction;

  if (friction) c.energy_why = "friction";
  else if (drag) c.energy_why = "drag";
  else if (thrust) c.energy_why = "thrust";
  else if (inelastic) c.energy_why = "restitution below 1";
  else if (superelastic) c.energy_why = "restitution above 1";
  else if (particles) c.energy_why = "particles are emitted and die";
  else if (destroys) c.energy_why = "the collision matrix destroys bodies";
  else c.energy_why = "elastic, frictionless, no drag or thrust";
  c.energy = c.energy_why == "elastic, frictionless, no drag or thrust";

  const bool wind = scene.world.wind.x != 0.0 || scene.world.wind.y != 0.0;
  // A destroyed body takes its potential energy along, which can be negative (below the
  // field's zero, or bound in a Newtonian well): destroys are left out too.
  c.energy_non_increasing = !thrust && !particles && !(drag && wind) && !destroys && !superelastic;

  if (scene.conserves.energy) {
    c.energy = *scene.conserves.energy;
    c.energy_why = "declared by the scenario";
  }
  if (scene.conserves.linear_momentum) {
    c.linear_momentum = *scene.conserves.linear_momentum;
    c.momentum_why = "declared by the scenario";
  }
  if (scene.conserves.angular_momentum) c.angular_momentum = *scene.conserves.angular_momentum;
  return c;
}

Scales characteristic_scales(const Scene& scene, const Series* motion) {
  Scales s;
  Vec2 lo{1e300, 1e300}, hi{-1e300, -1e300};
  auto extend = [&](Vec2 p, double r) {
    lo.x = std::min(lo.x, p.x - r);
    lo.y = std::min(lo.y, p.y - r);
    hi.x = std::max(hi.x, p.x + r);
    hi.y = std::max(hi.y, p.y + r);
  };
  for (const BodyDef& b : scene.bodies) extend(b.position, b.radius);
  for (const WallDef& w : scene.walls) { extend(w.from, 0.0); extend(w.to, 0.0); }
  for (const BoxDef& b : scene.boxes) { extend(b.min, 0.0); extend(b.max, 0.0); }
  for (const SurfaceDef& sf : scene.surfaces) for (Vec2 p : sf.points) extend(p, 0.0);
  s.length = hi.x >= lo.x ? std::max(length(hi - lo), 1e-9) : 1.0;
  // The field's potential energy spans M |g| times the scene's extent along the field, not
  // its diagonal: a ball dropped 10 m onto a floor 2 km wide must not have a 200x larger
  // energy scale (and 200x smaller drifts) than on a floor 2 m wide.
  const double g_norm = length(scene.world.gravity);
  const Vec2 down = g_norm > 0.0 ? scene.world.gravity / g_norm : Vec2{0.0, 0.0};
  double h_lo = 1e300, h_hi = -1e300;
  auto extend_h = [&](Vec2 p, double r) {
    h_lo = std::min(h_lo, dot(p, down) - r);
    h_hi = std::max(h_hi, dot(p, down) + r);
  };
  for (const BodyDef& b : scene.bodies) extend_h(b.position, b.radius);
  for (const WallDef& w : scene.walls) { extend_h(w.from, 0.0); extend_h(w.to, 0.0); }
  for (const BoxDef& b : scene.boxes) {
    for (Vec2 c : {b.min, b.max, Vec2{b.min.x, b.max.y}, Vec2{b.max.x, b.min.y}}) extend_h(c, 0.0);
  }
  for (const SurfaceDef& sf : scene.surfaces) for (Vec2 p : sf.points) extend_h(p, 0.0);
  double height = h_hi >= h_lo ? h_hi - h_lo : 0.0;

  double mass = 0.0, ke = 0.0, p = 0.0, l = 0.0;
  for (const BodyDef& b : scene.bodies) {
    if (b.is_static) continue;
    mass += b.mass;
    ke += 0.5 * b.mass * length_squared(b.velocity);
    p += b.mass * length(b.velocity);
    l += b.mass * length(b.position) * length(b.velocity);
  }
  double u = 0.0;
  if (scene.world.newtonian) {
    for (std::size_t i = 0; i < scene.bodies.size(); ++i) {
      for (std::size_t j = i + 1; j < scene.bodies.size(); ++j) {
        u += std::abs(newtonian_potential(scene.world.G, scene.world.softening, scene.bodies[i].mass,
                                          scene.bodies[j].mass, scene.bodies[i].position, scene.bodies[j].position));
      }
    }
  }
  double motion_energy = 0.0;
  if (motion != nullptr && !motion->totals.empty()) {
    double travel = 0.0, ke_max = 0.0, pe_min = 1e300, pe_max = -1e300;
    for (std::size_t k = 0; k < motion->totals.size(); ++k) {
      ke_max = std::max(ke_max, motion->totals[k].kinetic);
      pe_min = std::min(pe_min, motion->totals[k].potential);
      pe_max = std::max(pe_max, motion->totals[k].potential);
      const auto& st = motion->states[k];
      for (std::size_t i = 0; i < st.size() && i < scene.bodies.size(); ++i) {
        if (!st[i].alive) continue;
        travel = std::max(travel, length(st[i].position - scene.bodies[i].position));
        height = std::max(height, std::abs(dot(st[i].position - scene.bodies[i].position, down)));
      }
    }
    s.length = std::max(s.length, travel);
    motion_energy = ke_max + (pe_max - pe_min) + u;
  }
  s.energy = std::max(ke + mass * g_norm * height + u, motion_energy);
  if (!(s.energy > 0.0)) s.energy = 1.0;   // nothing moves and nothing pulls: 1 J
  s.momentum = std::max(p, std::sqrt(2.0 * mass * s.energy));
  if (!(s.momentum > 0.0)) s.momentum = 1.0;
  s.angular_momentum = l + s.momentum * s.length;
  return s;
}

}  // namespace physval
