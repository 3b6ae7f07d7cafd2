// Resting contact and friction (the lecture's section 5).
//
// A body pressed into a face (wall, box side, surface piece) that arrives too slowly
// to bounce clear settles onto it: it keeps no normal velocity, the normal component
// of its acceleration is taken by the support (N = -m a.n, so on an incline
// N = m g cos(theta)), and along the face it feels Coulomb friction:
//   - at rest, it stays at rest while |a_t| <= mu_s N / m (static friction);
//   - sliding, it is decelerated by mu_k N / m (kinetic friction) until it stops;
//     the stop is an event at the exact time, so friction never reverses a velocity;
//   - a pair with rolling_friction c > 0 is a wheel: it rolls instead of sliding, held
//     and slowed by c N (rolling resistance, c << mu) instead of mu_s and mu_k.
// Bodies do not spin (lecture step 6), so a circle on an incline slides; a
// "block on an incline" is a circle on an inclined wall.
// The support holds while the force presses the body into the face and its contact
// point stays on the segment; leaving either way releases it.
//
// A body can also rest on another body that is itself at rest (stuck) on a support: a
// stack. It must be held there (pressed, slow, static friction enough); it is then
// stuck too, and it is released, with everything resting on it, the moment its
// supporter moves or the force stops pressing it down. A body that would slide off a
// body does not rest on it: it micro-bounces (exact_collisions.cpp).
#include <algorithm>
#include <cmath>

#include "physval/core/time_of_impact.hpp"
#include "world.hpp"

namespace physval::core_detail {

namespace {

struct Coefficients {
  double moving;   // kinetic friction or rolling resistance
  double holding;  // static friction or rolling resistance
};

Coefficients coefficients(const World& w, std::uint32_t i, const Segment& s) {
  const PairMaterial m = w.pair_material(w.material[i], s.material);
  if (m.rolling_friction > 0.0) return {m.rolling_friction, m.rolling_friction};
  return {m.friction, std::max(m.static_friction, m.friction)};
}

}  // namespace

void support_path(World& w, std::uint32_t i) {
  if (w.on_body(i)) {   // held in place by static friction on a body at rest
    w.vel[i] = {};
    w.apath[i] = {};
    return;
  }
  const double vt = dot(w.vel[i], perp(w.support_n[i]));
  w.vel[i] = vt * perp(w.support_n[i]);   // no normal velocity on a support
  w.apath[i] = support_acceleration(w, i, w.acc[i], vt);
}

Vec2 support_acceleration(const World& w, std::uint32_t i, Vec2 a, double vt) {
  const Segment& s = w.statics.segments[w.support[i]];
  const Vec2 n = w.support_n[i];
  const Vec2 t = perp(n);
  const double normal_per_mass = -dot(a, n);   // N / m
  const double at = dot(a, t);
  const Coefficients c = coefficients(w, i, s);
  const double limit_moving = c.moving * std::max(normal_per_mass, 0.0);
  const double limit_holding = c.holding * std::max(normal_per_mass, 0.0);
  double a_t;
  if (vt == 0.0) {
    a_t = std::fabs(at) <= limit_holding ? 0.0 : at - std::copysign(limit_moving, at);
  } else {
    a_t = at - std::copysign(limit_moving, vt);
  }
  return a_t * t;
}

void release_support(World& w, std::uint32_t i) {
  if (w.on_body(i)) {   // unlink from the supporter's list of dependents
    const std::uint32_t j = w.support[i] & ~kBodySupport;
    std::uint32_t* link = &w.dep_head[j];
    while (*link != kNone && *link != i) link = &w.dep_next[*link];
    if (*link == i) *link = w.dep_next[i];
    w.dep_next[i] = kNone;
  }
  w.support[i] = kNone;
  w.apath[i] = w.acc[i];   // free for the rest of the step
}

bool can_rest_on(const World& w, std::uint32_t i, std::uint32_t j, Vec2 n, double rest_speed) {
  if (!w.stuck(j) || w.supported(i)) return false;
  const Vec2 a = w.acc[i];
  const double normal_per_mass = -dot(a, n);
  if (!(normal_per_mass > 0.0)) return false;
  if (length(w.vel[i]) > rest_speed) return false;
  const PairMaterial m = w.pair_material(w.material[i], w.material[j]);
  const double hold = m.rolling_friction > 0.0 ? m.rolling_friction : std::max(m.static_friction, m.friction);
  return length(a + normal_per_mass * n) <= hold * normal_per_mass;
}

void rest_on_body(World& w, std::uint32_t i, std::uint32_t j, Vec2 n) {
  w.vel[i] = {};
  w.apath[i] = {};
  w.support[i] = kBodySupport | j;
  w.support_n[i] = n;
  w.dep_next[i] = w.dep_head[j];
  w.dep_head[j] = i;
}

void collect_dependents(World& w, std::uint32_t j) {
  std::size_t k = w.released.size();
  for (std::uint32_t d = w.dep_head[j]; d != kNone; d = w.dep_next[d]) w.released.push_back(d);
  while (k < w.released.size()) {
    const std::uint32_t x = w.released[k++];
    for (std::uint32_t d = w.dep_head[x]; d != kNone; d = w.dep_next[d]) w.released.push_back(d);
  }
}

namespace {

// A body touching a face, pressed into it and not moving away, settles onto it at the
// start of the step (so that even explicit Euler, which applies a force only at the
// end of a step, never pulls a resting body into its support).
void detect_support(World& w, std::uint32_t i, const StepContext& ctx) {
  const double r = w.radius[i];
  const Vec2 p = w.pos[i];
  const double tol = 1e-9 * (r + w.length_scale);
  w.found_static.clear();
  w.statics.query(make_aabb(p.x - r - tol, p.y - r - tol, p.x + r + tol, p.y + r + tol), w.found_static);
  for (std::uint32_t k : w.found_static) {
    const Segment& s = w.statics.segments[k];
    if (w.any_rules && !w.response(w.group[i], s.group).collide) continue;
    const double u = dot(p - s.from, s.dir);
    if (u < 0.0 || u > s.length) continue;
    const double D = dot(p - s.from, s.normal);
    const Vec2 n = D >= 0.0 ? s.normal : -s.normal;
    if (std::fabs(std::fabs(D) - r) > tol) continue;
    const double an = dot(w.acc[i], n);
    if (!(an < 0.0)) continue;
    const double vn = dot(w.vel[i], n);
    if (vn > 0.0 || -vn > w.rest_speed(an, ctx.dt)) continue;
    w.support[i] = k;
    w.support_n[i] = n;
    record_contact(w, i, kNone, &s, ctx.t0, ctx.dt);
    return;
  }
}

}  // namespace

void apply_supports(World& w, const StepContext& ctx) {
  const std::size_t n = w.size();
  for (std::uint32_t i = 0; i < n; ++i) {
    if (w.support[i] == kNone) {
      if (w.dynamic(i) && !w.statics.segments.empty()) {
        detect_support(w, i, ctx);
        if (w.support[i] != kNone) support_path(w, i);
      }
      continue;
    }
    if (!w.dynamic(i)) {
      release_support(w, i);
      continue;
    }
    if (w.on_body(i)) continue;   // after every segment support is settled (below)
    const Segment& s = w.statics.segments[w.support[i]];
    const Vec2 nrm = w.support_n[i];
    const double u = dot(w.pos[i] - s.from, s.dir);
    const double gap = dot(w.pos[i] - s.from, nrm) - w.radius[i];
    const double tol = 1e-9 * (w.radius[i] + w.length_scale);
    const bool on_segment = u >= 0.0 && u <= s.length;
    const bool pressed = dot(w.acc[i], nrm) < 0.0;
    if (!on_segment || !pressed || std::fabs(gap) > tol) {
      release_support(w, i);
      continue;
    }
    support_path(w, i);
    // Still touching at the end of this step: one continuing contact.
    touch_contact(w, i, static_partner_key(s.owner), ctx.t0);
  }
  // Bodies at rest on bodies: valid while the supporter is stuck, they still touch, and
  // they are still held. A stack settles from the bottom up, one level per pass.
  for (bool changed = true; changed;) {
    changed = false;
    for (std::uint32_t i = 0; i < n; ++i) {
      if (!w.on_body(i)) continue;
      const std::uint32_t j = w.support[i] & ~kBodySupport;
      const Vec2 d = w.pos[i] - w.pos[j];
      const double dist = length(d);
      const double R = w.radius[i] + w.radius[j];
      const double tol = 1e-9 * (R + w.length_scale);
      const Vec2 nrm = dist > 0.0 ? d / dist : w.support_n[i];
      w.support[i] = kNone;   // judged as a free body pressed onto j
      const bool ok = w.alive(j) && std::fabs(dist - R) <= tol && can_rest_on(w, i, j, nrm, INFINITY);
      w.support[i] = kBodySupport | j;
      if (ok) {
        w.support_n[i] = nrm;
        support_path(w, i);
        touch_contact(w, i, j, ctx.t0);
      } else {
        release_support(w, i);
        changed = true;
      }
    }
  }
}

double support_stop_time(const World& w, std::uint32_t i, double t, double T) {
  if (w.on_body(i)) return toi::kNever;   // stuck
  const Vec2 tang = perp(w.support_n[i]);
  const double vt = dot(w.vel_at(i, t), tang);
  const double at = dot(w.apath[i], tang);
  if (vt == 0.0 || at == 0.0 || (vt > 0.0) == (at > 0.0)) return toi::kNever;
  const double s = -vt / at;
  return t + s <= T ? t + s : toi::kNever;
}

double support_leave_time(const World& w, std::uint32_t i, double t, double T) {
  if (w.on_body(i)) return toi::kNever;
  const Segment& s = w.statics.segments[w.support[i]];
  const Vec2 p = w.pos_at(i, t);
  const Vec2 v = w.vel_at(i, t);
  const Vec2 a = w.apath[i];
  // u(s) = u0 + u1 s + u2 s^2 along the segment; it leaves at u = 0 falling or at
  // u = L rising.
  const double u0 = dot(p - s.from, s.dir), u1 = dot(v, s.dir), u2 = 0.5 * dot(a, s.dir);
  const toi::Tolerance tol = toi::linear_tolerance(w.length_scale, length(v) + length(a) * (T - t));
  toi::Poly lo;
  lo.c[0] = u0;
  lo.c[1] = u1;
  lo.c[2] = u2;
  lo.degree = 2;
  toi::Poly hi;
  hi.c[0] = s.length - u0;
  hi.c[1] = -u1;
  hi.c[2] = -u2;
  hi.degree = 2;
  // Exactly at an end point: it leaves if moving (or accelerating) outwards, else stays.
  const double a_lo = toi::earliest_entry(lo, T - t, {0.0, tol.slope});
  const double a_hi = toi::earliest_entry(hi, T - t, {0.0, tol.slope});
  const double s_leave = std::min(a_lo, a_hi);
  return s_leave == toi::kNever ? toi::kNever : t + s_leave;
}

}  // namespace physval::core_detail
