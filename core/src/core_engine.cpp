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

void CoreEngine::load(const Scene& scene) {
  auto w = std::make_unique<World>();
  core_detail::load_world(*w, scene);
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
  for (std::size_t i = 0; i < w.size(); ++i) {
    BodyState& s = out[i];
    s.position = w.pos[i];
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
