// Particle systems (lecture, section 7): point masses spawned around a parent, with
// random velocities in a disc of radius `speed` around the parent's velocity, a fixed
// lifetime, gravity if the emitter asks, destroyed on collision if it asks.
//
//   explode: at time `at` the parent is destroyed (exact mode: at that exact time, an
//            event of the step) and `count` particles start from its position and
//            velocity then; they are created at the end of that step, placed where
//            their ballistic paths have taken them.
//   trail:   while the parent lives, one particle every 1/rate s (first at 1/rate).
//            Exact mode: each emission is an event of the step, which reads the
//            parent's position and velocity at that time; the particle is created at
//            the end of the step where its ballistic path from there has taken it,
//            aged from its emission time (like an explosion). Lecture mode (no events,
//            and a step the event cap cut short): emissions due in the step leave at
//            its end from the parent's end-of-step state, born then.
// Randomness: std::mt19937_64 seeded by the emitter, mapped to [0, 1) with 53 bits and
// disc points by rejection, so runs are bit-identical on every platform.
// A particle never collides with its own parent, nor points with points.
#include <cmath>
#include <string>

#include "physval/core/time_of_impact.hpp"
#include "world.hpp"

namespace physval::core_detail {

namespace {

double uniform01(std::mt19937_64& rng) { return static_cast<double>(rng() >> 11) * 0x1.0p-53; }

Vec2 in_disc(std::mt19937_64& rng, double radius) {
  for (;;) {
    const double x = 2.0 * uniform01(rng) - 1.0;
    const double y = 2.0 * uniform01(rng) - 1.0;
    if (x * x + y * y <= 1.0) return {radius * x, radius * y};
  }
}

void spawn(World& w, EmitterState& e, std::uint16_t emitter, Vec2 p, Vec2 v, double birth) {
  const std::uint32_t parent = e.parent;
  w.pos.push_back(p);
  w.vel.push_back(v);
  w.tloc.push_back(0.0);
  w.inv_mass.push_back(1.0 / e.def.mass);
  w.radius.push_back(0.0);
  w.version.push_back(0);
  std::uint8_t f = kAlive | kPoint | kParticle;
  if (e.def.destroy_on_collision) f |= kDestroyOnHit;
  if (!e.def.gravity) f |= kNoGravity;
  w.flags.push_back(f);
  w.group.push_back(w.group[parent]);
  w.material.push_back(w.material[parent]);
  if (!w.mass.empty()) w.mass.push_back(e.def.mass);
  if (!w.angle.empty()) w.angle.push_back(0.0);
  if (!w.fparams.empty()) w.fparams.push_back({});
  w.push_force_state();
  w.birth.push_back(birth);
  w.lifetime.push_back(e.def.lifetime);
  w.parent.push_back(parent);
  w.emitter_of.push_back(emitter);
  w.serial.push_back(e.serial++);
}

// Whether a particle's ballistic path from (p, v) under g over s seconds meets a
// barrier (a wall, box side or surface segment) or a static body it collides with.
// (`statics`: the scene's static bodies; `found`: scratch for the segments' query.)
bool placement_meets_barrier(const World& w, const std::vector<std::uint32_t>& statics, std::vector<std::uint32_t>& found,
                             std::uint16_t group, Vec2 p, Vec2 v, Vec2 g, double s) {
  if (!(s > 0.0)) return false;
  // The path's box: its chord's, widened by the parabola's largest distance from it.
  const Vec2 q = p + s * v + (0.5 * s * s) * g;
  const double pad = 0.125 * s * s * length(g) + 1e-9 * (w.length_scale + std::fabs(p.x) + std::fabs(p.y));
  found.clear();
  w.statics.query(make_aabb(std::min(p.x, q.x) - pad, std::min(p.y, q.y) - pad, std::max(p.x, q.x) + pad,
                            std::max(p.y, q.y) + pad),
                  found);
  for (std::uint32_t k : found) {
    const Segment& seg = w.statics.segments[k];
    if (!w.response(group, seg.group).collide) continue;
    if (toi::circle_segment(p, v, g, 0.0, seg.from, seg.to, s, w.length_scale, g).s != toi::kNever) return true;
  }
  const double speed = length(v) + length(g) * s;
  for (std::uint32_t i : statics) {
    if (!w.alive(i) || !w.response(group, w.group[i]).collide) continue;
    const double R = w.radius[i];
    if (toi::circle_circle(p - w.pos[i], v, g, R, s, toi::squared_tolerance(w.length_scale, speed, R)) != toi::kNever) {
      return true;
    }
  }
  return false;
}

// A particle born at `birth` within the step that ends at t_end starts where its
// ballistic path has taken it by then: exact while that path meets nothing it collides
// with. A path that meets a barrier is not followed through it (placed beyond, a particle
// at 500 m/s left a closed 4 m box in one 1/60 s step, and the run was `ok`): such a
// particle starts at t_end from its emission point and velocity instead (late by at most
// one step, a first-order error in its own path), and its impact comes in the next step.
// The scene's static bodies, listed on the first placement of a step that needs them
// (most steps emit nothing and list nothing).
struct StaticBodies {
  std::vector<std::uint32_t> list;
  bool listed = false;
  const std::vector<std::uint32_t>& of(const World& w) {
    if (!listed) {
      list.clear();
      for (std::uint32_t i = 0; i < w.scene_bodies; ++i) {
        if (w.is_static(i)) list.push_back(i);
      }
      listed = true;
    }
    return list;
  }
};

// The moving scene bodies (circles, alive, not the particle's parent) a particle born at
// `birth` collides with: each one's path over the particle's flight, t in [t_end - s,
// t_end], is read backwards from its state at the step's end along its current path
// (exact when it met nothing in that time), and the particle's ballistic path is held
// against it. A particle placed without this went inside a moving ball (a trail 0.3 m from
// a 0.4 m ball crossing its path: young particles 0.09 m from the ball's centre, the run
// `ok`; core is the only engine with particles, and containment does not follow them).
// Returns the first body met, or kNoBody.
constexpr std::uint32_t kNoBody = static_cast<std::uint32_t>(-1);

// (Called after end_paths: every body's clock is at the step's end, its local time 0.)
std::uint32_t placement_meets_body(const World& w, std::uint32_t parent, std::uint16_t group, Vec2 p, Vec2 v, Vec2 g,
                                   double s) {
  if (!(s >= 0.0)) return kNoBody;
  const Vec2 q = p + s * v + (0.5 * s * s) * g;
  for (std::uint32_t j = 0; j < w.scene_bodies; ++j) {
    if (j == parent || !w.alive(j) || w.is_static(j) || !(w.radius[j] > 0.0)) continue;
    if (!w.response(group, w.group[j]).collide) continue;
    const double R = w.radius[j];
    const Vec2 end = w.pos[j];
    if (length(q - end) < R) return j;   // placed inside it, however it got there
    if (!(s > 0.0)) continue;
    const Vec2 b0 = w.pos_at(j, -s), bv = w.vel_at(j, -s);
    const double speed = length(v - bv) + length(g - w.path_acc(j)) * s;
    if (length(p - b0) < R) continue;   // born inside it (a parent overlapping it): not this test's
    if (toi::circle_circle(p - b0, v - bv, g - w.path_acc(j), R, s,
                           toi::squared_tolerance(w.length_scale + length(p), speed, R)) != toi::kNever) {
      return j;
    }
  }
  return kNoBody;
}

void spawn_from(World& w, StaticBodies& statics, EmitterState& e, std::uint16_t emitter, Vec2 p, Vec2 v0, Vec2 g,
                double s, double birth) {
  thread_local std::vector<std::uint32_t> found;
  const std::uint16_t group = w.group[e.parent];
  if (!placement_meets_barrier(w, statics.of(w), found, group, p, v0, g, s) &&
      placement_meets_body(w, e.parent, group, p, v0, g, s) == kNoBody) {
    spawn(w, e, emitter, p + s * v0 + (0.5 * s * s) * g, v0 + s * g, birth);
    return;
  }
  // Late by s from its emission point: unless a moving body has come over that point in
  // the meantime. Then it starts where it was relative to that body when it was born
  // (outside it: its impact on it comes in the next step), when the straight way there
  // from its emission point crosses no barrier and ends inside no other moving body.
  const std::uint32_t j = placement_meets_body(w, e.parent, group, p, Vec2{}, Vec2{}, 0.0);
  if (j != kNoBody) {
    const Vec2 b = w.pos[j] + (p - w.pos_at(j, -s));
    if (!placement_meets_barrier(w, statics.of(w), found, group, p, b - p, Vec2{}, 1.0) &&
        placement_meets_body(w, e.parent, group, b, Vec2{}, Vec2{}, 0.0) == kNoBody) {
      spawn(w, e, emitter, b, v0, birth);
      return;
    }
  }
  spawn(w, e, emitter, p, v0, birth);
}

}  // namespace

void schedule_explosions(World& w, const StepContext& ctx, std::vector<Event>& out) {
  for (std::size_t k = 0; k < w.emitters.size(); ++k) {
    const EmitterState& e = w.emitters[k];
    if (e.def.mode != EmitterMode::Explode || e.exploded || !w.alive(e.parent)) continue;
    const double at = e.def.at - ctx.t0;
    if (at > ctx.dt) continue;
    out.push_back(Event::make(std::max(at, 0.0), e.parent, static_cast<std::uint32_t>(k), 0, 0, EventKind::Explode));
  }
}

void explode_parent(World& w, std::uint32_t emitter, double t_abs) {
  EmitterState& e = w.emitters[emitter];
  e.exploded = true;
  e.pending = true;
  e.at_position = w.pos[e.parent];
  e.at_velocity = w.vel[e.parent];
  e.at_time = t_abs;
  kill_body(w, e.parent);
}

void schedule_trail_emissions(World& w, const StepContext& ctx, std::vector<Event>& out) {
  for (std::size_t k = 0; k < w.emitters.size(); ++k) {
    const EmitterState& e = w.emitters[k];
    if (e.def.mode != EmitterMode::Trail || !(e.def.rate > 0.0) || !w.alive(e.parent)) continue;
    const double period = 1.0 / e.def.rate;
    for (std::uint32_t n = e.serial + 1;; ++n) {
      const double at = static_cast<double>(n) * period - ctx.t0;
      if (at > ctx.dt) break;
      out.push_back(Event::make(std::max(at, 0.0), e.parent, static_cast<std::uint32_t>(k), 0, 0, EventKind::Emit));
    }
  }
}

void record_emission(World& w, std::uint32_t emitter, Vec2 position, Vec2 velocity, double t_abs) {
  w.emitters[emitter].emitted.push_back({position, velocity, t_abs});
}

void finish_particles(World& w, const StepContext& ctx) {
  const double t_end = ctx.t0 + ctx.dt;
  thread_local StaticBodies statics;   // for spawn_from
  statics.listed = false;
  for (std::size_t k = 0; k < w.emitters.size(); ++k) {
    EmitterState& e = w.emitters[k];
    const auto id = static_cast<std::uint16_t>(k);
    if (e.def.mode == EmitterMode::Explode) {
      // Lecture mode has no events: the parent explodes at the end of its step.
      if (!e.exploded && w.alive(e.parent) && e.def.at <= t_end) explode_parent(w, id, t_end);
      if (!e.pending) continue;
      e.pending = false;
      const double s = t_end - e.at_time;
      const Vec2 g = e.def.gravity ? w.gravity : Vec2{};
      for (int c = 0; c < e.def.count; ++c) {
        const Vec2 v0 = e.at_velocity + in_disc(e.rng, e.def.speed);
        spawn_from(w, statics, e, id, e.at_position, v0, g, s, e.at_time);
      }
    } else {
      if (!(e.def.rate > 0.0)) continue;
      const double period = 1.0 / e.def.rate;
      const Vec2 g = e.def.gravity ? w.gravity : Vec2{};
      for (const EmitterState::Emission& em : e.emitted) {   // exact mode, in time order
        const double s = t_end - em.time;
        const Vec2 v0 = em.velocity + in_disc(e.rng, e.def.speed);
        spawn_from(w, statics, e, id, em.position, v0, g, s, em.time);
      }
      e.emitted.clear();
      e.next_emit = static_cast<double>(e.serial + 1) * period;   // no drift from summing
      while (w.alive(e.parent) && e.next_emit <= t_end) {
        spawn(w, e, id, w.pos[e.parent], w.vel[e.parent] + in_disc(e.rng, e.def.speed), t_end);
        e.next_emit = static_cast<double>(e.serial + 1) * period;
      }
    }
  }
  // End of life (exact mode kills at the exact time during the step; this catches
  // lecture mode and particles born this step).
  for (std::size_t k = 0; k < w.birth.size(); ++k) {
    const auto i = static_cast<std::uint32_t>(w.scene_bodies + k);
    if (w.alive(i) && w.birth[k] + w.lifetime[k] <= t_end) kill_body(w, i);
  }
}

}  // namespace physval::core_detail
