// The core engine: the Engine interface over core's world, and the step pipeline.
#include "physval/core/core_engine.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "world.hpp"

namespace physval {

using core_detail::CollisionMode;
using core_detail::World;

namespace {

EngineInfo make_info() {
  EngineInfo info;
  info.name = "core";
  info.version = "0.1.0";
  info.precision = Precision::Float64;
  info.summary =
      "physval's lecture-model engine: double precision, exact event-driven impacts "
      "(or the lecture's one-pass scheme), four integrators, four broad phases";
  for (int f = 0; f < static_cast<int>(Feature::Count); ++f) info.features.push_back(static_cast<Feature>(f));
  info.options = core_detail::core_option_specs();
  return info;
}

const EngineInfo& core_info() {
  static const EngineInfo info = make_info();
  return info;
}

}  // namespace

EngineFactory core_engine_factory() {
  EngineFactory f;
  f.info = core_info();
  f.create = [] { return std::make_unique<CoreEngine>(); };
  return f;
}

double particle_intensity(double age, double lifetime) {
  if (!(lifetime > 0.0)) return 0.0;
  return std::clamp(1.0 - age / lifetime, 0.0, 1.0);
}

CoreEngine::CoreEngine() : world_(std::make_unique<World>()) {}
CoreEngine::~CoreEngine() = default;

const EngineInfo& CoreEngine::info() const { return core_info(); }

namespace {

// The bounding box of everything in the scene (bodies with their radii, walls, boxes,
// surfaces); false when there is nothing.
bool scene_box(const Scene& scene, Vec2& lo, Vec2& hi) {
  lo = {INFINITY, INFINITY};
  hi = {-INFINITY, -INFINITY};
  auto add = [&](Vec2 p, double r) {
    lo = {std::min(lo.x, p.x - r), std::min(lo.y, p.y - r)};
    hi = {std::max(hi.x, p.x + r), std::max(hi.y, p.y + r)};
  };
  for (const BodyDef& b : scene.bodies) add(b.position, b.shape == ShapeKind::Point ? 0.0 : b.radius);
  for (const WallDef& w : scene.walls) { add(w.from, 0.0); add(w.to, 0.0); }
  for (const BoxDef& b : scene.boxes) { add(b.min, 0.0); add(b.max, 0.0); }
  for (const SurfaceDef& s : scene.surfaces) for (Vec2 p : s.points) add(p, 0.0);
  return lo.x <= hi.x && lo.y <= hi.y;
}

// Core's round-off tolerances are 1e-9 of the scene's extent from the origin
// (World::length_scale), so a scene drawn far from the origin (a map's grid: a 5 mm marble
// 4 mm above a floor at x 5e5, y 5e6 m) had a 5 mm tolerance: the marble was held up as
// resting for the whole run, and the reference converged to that. Physics does not depend
// on where the origin is, so a scene whose centre is farther from the origin than 8 x its
// own size is run in coordinates from its centre (rounded to a multiple of its size's
// power of two, so the subtraction keeps the low bits); every other scene runs as given, to
// the bit.
Vec2 working_origin(const Scene& scene) {
  Vec2 lo, hi;
  if (!scene_box(scene, lo, hi)) return {};
  const Vec2 c = 0.5 * (lo + hi);
  const double size = std::max({hi.x - lo.x, hi.y - lo.y, 1e-300});
  if (!std::isfinite(size) || !(std::max(std::fabs(c.x), std::fabs(c.y)) > 8.0 * size)) return {};
  const double q = std::exp2(std::ceil(std::log2(size)));
  return {std::round(c.x / q) * q, std::round(c.y / q) * q};
}

void move_scene(Scene& s, Vec2 by) {
  for (BodyDef& b : s.bodies) b.position = b.position + by;
  for (WallDef& w : s.walls) { w.from = w.from + by; w.to = w.to + by; }
  for (BoxDef& b : s.boxes) { b.min = b.min + by; b.max = b.max + by; }
  for (SurfaceDef& sf : s.surfaces) for (Vec2& p : sf.points) p = p + by;
}

// A scene whose extent (even from its own centre) is so much larger than its smallest
// moving circle that core's round-off tolerance, 1e-9 of the extent, exceeds 1e-3 of that
// radius cannot be core's to run: a body would be held as resting, or counted touching, that
// far from a support (a 0.05 m ball in a 2 m box beside a body parked at 1e11 m hovered
// 1.45 m above the floor, and the Sun 1 AU away did the same: the fifteenth hunt). Refused
// at load, saying why, when there is anything static to rest on.
void check_resolution(const World& w, const Scene& scene) {
  bool statics = !scene.walls.empty() || !scene.boxes.empty() || !scene.surfaces.empty();
  double r_min = INFINITY;
  const BodyDef* smallest = nullptr;
  for (const BodyDef& b : scene.bodies) {
    if (b.is_static) {
      statics = statics || (b.shape != ShapeKind::Point && b.radius > 0.0);
      continue;
    }
    if (b.shape == ShapeKind::Point || !(b.radius > 0.0) || !(b.radius < r_min)) continue;
    r_min = b.radius;
    smallest = &b;
  }
  const double tol = 1e-9 * w.length_scale;
  if (!statics || smallest == nullptr || !(tol > 1e-3 * r_min)) return;
  std::ostringstream m;
  m.precision(3);
  m << "core cannot resolve this scene: it spans " << w.length_scale << " m (from "
    << (w.origin.x != 0.0 || w.origin.y != 0.0 ? "its centre" : "the origin") << "), so core's round-off tolerance ("
    << "1e-9 of that, " << tol << " m) is more than 1e-3 of body '" << smallest->name << "''s radius (" << r_min
    << " m): a body could be held resting that far from a support. Bring the scene's objects nearer each other "
       "(or split the scene)";
  throw std::invalid_argument(m.str());
}

}  // namespace

void CoreEngine::load(const Scene& scene) {
  auto w = std::make_unique<World>();
  const Vec2 origin = working_origin(scene);
  if (origin.x != 0.0 || origin.y != 0.0) {
    Scene moved = scene;
    move_scene(moved, -1.0 * origin);
    core_detail::load_world(*w, moved);
    w->origin = origin;
  } else {
    core_detail::load_world(*w, scene);
  }
  check_resolution(*w, scene);
  world_ = std::move(w);
}

// One step: a pipeline of named stages, each present only when the scene needs it.
void CoreEngine::step(double dt) {
  if (!(dt >= 0.0) || !std::isfinite(dt)) throw std::invalid_argument("core: step dt must be finite and >= 0");
  World& w = *world_;
  w.contacts.clear();
  w.stats = {};
  if (dt == 0.0) return;
  core_detail::StepContext ctx;
  ctx.t0 = w.time;
  ctx.dt = dt;
  ctx.event_cap = w.max_events_option > 0 ? w.max_events_option
                                          : core_detail::default_event_cap(w.size());
  const bool exact = w.mode == CollisionMode::Exact;

  // 0. bodies moving in contact: hidden from the step, advanced after it (contact_group.cpp)
  w.group_dt = dt;
  const bool groups = !w.contact_groups.empty();
  if (groups) core_detail::hide_contact_groups(w, ctx);
  // 1. forces: accelerations at the start of the step
  if (w.any_forces) {
    core_detail::forget_old_contacts(w, ctx.t0, dt);
    core_detail::compute_accelerations(w, w.pos, w.vel, w.acc);
  }
  // 2. resting contacts: the support takes the normal force; friction along it
  if (w.any_forces && exact) core_detail::apply_supports(w, ctx);
  // 3. integrator: start-of-step kicks and each body's path over the step
  core_detail::begin_paths(w, ctx);
  // 4. collisions: exact impacts one by one, or the lecture's one pass
  if (exact) {
    core_detail::collide_exact(w, ctx);
  } else {
    core_detail::collide_lecture(w, ctx, 0.0);
  }
  // 5. integrator: everyone to the end of the step, end-of-step corrections
  core_detail::end_paths(w, ctx);
  if (groups || !w.contact_groups.empty()) core_detail::advance_contact_groups(w, ctx);
  // 6. particles: explosions and trails spawn, lives end
  if (!w.emitters.empty()) core_detail::finish_particles(w, ctx);

  w.time = ctx.t0 + dt;
  // An impact storm in this step (a pile's inelastic collapse): its bodies become a granular group
  if (!w.storm_bodies.empty()) core_detail::engage_storm_groups(w, ctx);
  // Holds made inside a step are judged at the next step's start (apply_supports), once
  // the supports are settled again. The run's last step has no next one: its holds are
  // judged at its end, so a hold made there is not `ok` unjudged (the same verdict and time
  // as a longer run gives at the next step's start).
  const double end_tol = 1e-9 * dt;
  if (exact && !w.braced_holds.empty() && ctx.t0 < w.end_time - end_tol && w.time >= w.end_time - end_tol) {
    core_detail::judge_braced_holds(w);
  }
}

double CoreEngine::time() const { return world_->time; }

std::size_t CoreEngine::body_count() const { return world_->size(); }

BodyMeta CoreEngine::body_meta(std::size_t i) const {
  const World& w = *world_;
  BodyMeta m;
  const auto k = static_cast<std::uint32_t>(i);
  if (i < w.scene_bodies) {
    m.name = w.name(i);
  } else {
    const std::size_t p = i - w.scene_bodies;
    m.name = w.emitters[w.emitter_of[p]].def.name + "#" + std::to_string(w.serial[p]);
  }
  m.is_static = w.is_static(k);
  m.mass = m.is_static ? 0.0 : 1.0 / w.inv_mass[i];
  m.radius = w.radius[i];
  return m;
}

void CoreEngine::read_states(std::vector<BodyState>& out) const {
  const World& w = *world_;
  out.resize(w.size());
  const bool moved = w.origin.x != 0.0 || w.origin.y != 0.0;
  for (std::size_t i = 0; i < w.size(); ++i) {
    BodyState& s = out[i];
    s.position = moved ? w.pos[i] + w.origin : w.pos[i];
    s.velocity = w.vel[i];
    s.angle = w.angle.empty() ? 0.0 : w.angle[i];
    s.angular_velocity = 0.0;   // bodies do not spin (lecture step 6)
    s.alive = w.alive(static_cast<std::uint32_t>(i));
  }
}

const std::vector<ContactEvent>& CoreEngine::contacts() const { return world_->contacts; }

std::vector<Setting> CoreEngine::settings() const {
  const World& w = *world_;
  std::vector<Setting> s;
  s.emplace_back("integrator", core_detail::integrator_name(w.integrator));
  s.emplace_back("collision", w.mode == CollisionMode::Exact ? "exact" : "lecture");
  s.emplace_back("impact_law",
                 w.impact_law == core_detail::ImpactLaw::Simultaneous ? "simultaneous" : "sequential");
  s.emplace_back("broadphase", std::string(broadphase_name(w.broadphase)) + (w.broadphase_auto ? " (auto)" : ""));
  s.emplace_back("cell_size", w.cell_size > 0.0 ? option_value_to_string(w.cell_size) : "auto");
  s.emplace_back("max_events_per_step",
                 w.max_events_option > 0 ? std::to_string(w.max_events_option)
                                         : std::to_string(core_detail::default_event_cap(w.size())) + " (auto)");
  s.emplace_back("rest_speed", w.rest_speed_option > 0.0
                                   ? option_value_to_string(w.rest_speed_option)
                                   : "auto (" + option_value_to_string(w.rest_factor) + " |a_n| dt)");
  s.emplace_back("precision", "float64");
  return s;
}

std::string CoreEngine::broken_guarantee() const {
  const World& w = *world_;
  if (w.unjustified_hold != core_detail::kNone) {
    std::ostringstream os;
    os << "core held body '" << w.name(w.unjustified_hold) << "' at t = " << w.unjustified_hold_time
       << " s on bodies that, judged with it and every body at rest they touch (" << w.unjustified_component
       << " bodies, faces fixed), "
       << (w.unjustified_undecided ? "core could not show to hold it (rigid Coulomb, its solver did not converge: "
                                   : "cannot hold it (rigid Coulomb: ")
       << "a member is left " << w.unjustified_residual
       << " m/s^2); core has no exact model of that collapse yet, so its path is not the physics (README, The hunt "
          "for wrong greens)";
    return os.str();
  }
  if (w.group_disturbed != core_detail::kNone) {
    std::ostringstream os;
    os << "bodies moving in contact (a group core moves on its contact forces, from t = " << w.group_first_time
       << " s): at t = " << w.group_disturbed_time << " s core could not run the group with body '"
       << w.name(w.group_disturbed) << "': " << w.group_why
       << "; the group's step was undone and the engine took its bodies back, not exact from there (README, "
          "Several supports and inelastic collapse)";
    return os.str();
  }
  if (w.cap_disturbed != core_detail::kNone) {
    std::ostringstream os;
    os << "a body came within reach of body '" << w.name(w.cap_disturbed) << "' riding a convex corner's cap at t = "
       << w.cap_disturbed_time
       << " s: core does not find impacts with a path on a cap, so bodies may have passed through each other "
          "(README, Junctions and corners)";
    return os.str();
  }
  if (!w.stats.event_cap_hit) return {};
  std::ostringstream os;
  os << "core reached its event cap (" << w.stats.events << " events) in the step ending at t = " << w.time
     << " s: the rest of the step was finished by the lecture pass, so impacts were no longer exact "
        "and bodies may have passed through each other (raise [core] max_events_per_step)";
  return os.str();
}

std::vector<std::string> CoreEngine::limits_hit() const {
  const World& w = *world_;
  std::vector<std::string> out;
  if (w.cap_hits > 0) {
    std::ostringstream os;
    os << "event cap reached in " << w.cap_hits << " step(s), first at t = " << w.first_cap_time
       << " s; the rest of each such step was finished by the lecture pass (max_events_per_step)";
    out.push_back(os.str());
  }
  if (w.group_steps > 0) {
    std::ostringstream os;
    os << "bodies moving in contact from t = " << w.group_first_time << " s (" << w.group_steps << " group step(s), "
       << w.group_events
       << " event(s)): a resting group core could not hold moved on its contact forces, integrated by RK4 on "
          "sub-steps of dt/8 and projected onto its contacts (order 4, not exact)";
    out.push_back(os.str());
  }
  if (w.granular_steps > 0) {
    std::ostringstream os;
    os << "granular contact from t = " << w.granular_first_time << " s (" << w.granular_steps
       << " group step(s)): bodies in persistent contact with several others (a pile, a collapse) moved by "
          "nonsmooth contact dynamics (Moreau-Jean time stepping on sub-steps of dt/4 or less, Signorini and Coulomb "
          "at the velocity level solved at every contact at once, overlaps projected off): first order, not exact";
    if (w.granular_unconverged > 0) {
      os << "; " << w.granular_unconverged
         << " sub-step solve(s) stopped short of 1e-10 of their speeds, their sweeps stagnating (largest residual "
         << w.granular_worst_residual << " m/s)";
    }
    out.push_back(os.str());
  }
  if (w.cap_unmodelled > 0) {
    std::ostringstream os;
    os << "convex corner: " << w.cap_unmodelled << " time(s) a body too slow to lift off at a corner (first at t = "
       << w.cap_unmodelled_time
       << " s) had other geometry or bodies within reach of the corner's cap (or Newtonian gravity, or was a "
          "particle): core has no curved support there, it micro-bounced over the corner (first order)";
    out.push_back(os.str());
  }
  return out;
}

double CoreEngine::particle_age(std::size_t i) const {
  const World& w = *world_;
  if (i < w.scene_bodies || i >= w.size()) return -1.0;
  return w.time - w.birth[i - w.scene_bodies];
}

double CoreEngine::particle_intensity(std::size_t i) const {
  const World& w = *world_;
  if (i < w.scene_bodies || i >= w.size()) return 1.0;
  return physval::particle_intensity(particle_age(i), w.lifetime[i - w.scene_bodies]);
}

const CoreStepStats& CoreEngine::last_step_stats() const { return world_->stats; }

std::vector<CoreEngine::RestingForce> CoreEngine::resting_forces() const {
  std::vector<RestingForce> out;
  for (const core_detail::RestingContact& c : core_detail::resting_contacts(*world_)) {
    RestingForce f;
    f.body = c.body;
    f.normal = c.n;
    f.force = c.force;
    if (c.other & core_detail::kBodySupport) {
      f.wall = world_->statics.segments[c.other & ~core_detail::kBodySupport].owner;
    } else {
      f.other = static_cast<std::int64_t>(c.other);
    }
    out.push_back(std::move(f));
  }
  return out;
}

std::size_t CoreEngine::memory_bytes() const { return world_->memory_bytes(); }

}  // namespace physval
