// A convex corner's cap: the curved support of a body too slow to lift off where its face
// ends and the next face turns away (a table's edge, the crest of two slopes).
//
// A circle of radius r touching the corner V has its centre on the circle |x - V| = r. On
// the cap its centre is x = V + r n(phi), n(phi) = cos(phi) nA + sin(phi) dA (nA: its
// face's normal, dA: the face's direction out over V), moving at v = r omega tau(phi),
// tau = dn/dphi. With a the force acceleration (field, drag, wind, thrust: the body's own,
// body_acceleration) the corner pushes with N / m = -r omega^2 - a.n (>= 0 while it
// holds), and sliding, kinetic friction mu_k N / m acts against the motion (a wheel:
// rolling resistance), so
//     r domega/dt = a.tau - sign(omega) mu_k N / m.
// The ride is integrated by classical RK4 in time with steps of 1e-3 sqrt(r / |a|) (about
// 1e-14 r of error per step; only a body on a cap pays), and its events are found by
// bisection of the step to round-off:
//   - N reaches 0: it lifts off (free from there, its path the integrator's);
//   - phi reaches the next face's normal: it is handed over onto that face, which it
//     touches there tangentially (a free end: the back of its own face);
//   - phi comes back to 0: it is back on its face;
//   - omega reaches 0 with friction: static friction holds it there (|a.tau| <= mu_s N/m:
//     it stays at rest on the cap) or it slides back.
// Not taken (counted in limits_hit, the body then flies and micro-bounces as before, first
// order): other geometry within 2r of V, another body whose box reaches the cap's, Newtonian
// gravity, particles. A body that comes within reach of a riding one is a broken guarantee
// (its impacts with a curved path are not found).
#include <algorithm>
#include <cmath>

#include "world.hpp"

namespace physval::core_detail {

namespace {

constexpr double kEps = 2.220446049250313e-16;

using Ride = World::CapRide;

Vec2 cap_n(const Ride& c, double phi) { return std::cos(phi) * c.nA + std::sin(phi) * c.dA; }
Vec2 cap_tau(const Ride& c, double phi) { return -std::sin(phi) * c.nA + std::cos(phi) * c.dA; }

struct Friction {
  double moving = 0.0, holding = 0.0;
};

Friction cap_friction(const World& w, std::uint32_t i, const Segment& s) {
  const PairMaterial m = w.pair_material(w.material[i], s.material);
  if (m.rolling_friction > 0.0) return {m.rolling_friction, m.rolling_friction};
  return {m.friction, std::max(m.static_friction, m.friction)};
}

// The body's force acceleration at a state on the cap.
Vec2 force_on_cap(const World& w, std::uint32_t i, double r, const Ride& c, double phi, double omega) {
  if (!w.varying_forces) return w.acc[i];
  return body_acceleration(w, i, (r * omega) * cap_tau(c, phi));
}

struct State {
  double phi = 0.0, omega = 0.0;
};

struct Rhs {
  const World& w;
  std::uint32_t i;
  double r, mu_k;
  const Ride& c;
  double dir;   // the sign of the motion friction acts against (fixed over a step)
  double operator()(double phi, double omega) const {
    const Vec2 a = force_on_cap(w, i, r, c, phi, omega);
    const double N = std::max(-r * omega * omega - dot(a, cap_n(c, phi)), 0.0);
    return (dot(a, cap_tau(c, phi)) - dir * mu_k * N) / r;
  }
};

State rk4(const Rhs& f, State s, double h) {
  const double k1p = s.omega, k1w = f(s.phi, s.omega);
  const double k2p = s.omega + 0.5 * h * k1w, k2w = f(s.phi + 0.5 * h * k1p, k2p);
  const double k3p = s.omega + 0.5 * h * k2w, k3w = f(s.phi + 0.5 * h * k2p, k3p);
  const double k4p = s.omega + h * k3w, k4w = f(s.phi + h * k3p, k4p);
  return {s.phi + (h / 6.0) * (k1p + 2.0 * k2p + 2.0 * k3p + k4p),
          s.omega + (h / 6.0) * (k1w + 2.0 * k2w + 2.0 * k3w + k4w)};
}

enum class Exit { None, LiftOff, Next, Back, Stop };

// Which event state s has reached (in order of precedence), given the motion's sign.
Exit reached(const World& w, std::uint32_t i, double r, const Ride& c, State s, double dir, bool friction) {
  const Vec2 a = force_on_cap(w, i, r, c, s.phi, s.omega);
  if (-r * s.omega * s.omega - dot(a, cap_n(c, s.phi)) <= 0.0) return Exit::LiftOff;
  if (s.phi >= c.Phi) return Exit::Next;
  if (s.phi <= 0.0) return Exit::Back;
  if (friction && s.omega * dir <= 0.0) return Exit::Stop;
  return Exit::None;
}

void note_unmodelled(World& w, double t_abs) {
  if (w.cap_unmodelled++ == 0) w.cap_unmodelled_time = t_abs;
}

// The next face at corner V of face k (body on side nA, leaving over V along dA): the
// turn-away piece met first, or the back of k (a free end): 1. 0: no convex corner (a
// piece at V continues k's line or turns towards the body: the junction rules'). -1: the
// cap cannot be modelled: other geometry within 2r of V.
int find_cap(World& w, std::uint32_t i, std::uint32_t k, Ride& c) {
  const double r = w.radius[i];
  const Vec2 V = c.V;
  const double scale = std::max(std::fabs(V.x), std::fabs(V.y)) + r + w.length_scale;
  const double tol = 1024.0 * kEps * scale;
  const double reach = 2.0 * r + 1e-9 * (r + w.length_scale);
  thread_local std::vector<std::uint32_t> found;
  found.clear();
  w.statics.query(make_aabb(V.x - reach, V.y - reach, V.x + reach, V.y + reach), found);
  c.next = k;
  c.nB = -c.nA;
  c.Phi = std::acos(-1.0);
  for (std::uint32_t o : found) {
    if (o == k) continue;
    const Segment& q = w.statics.segments[o];
    if (w.any_rules && !w.response(w.group[i], q.group).collide) continue;
    const bool from_here = length(q.from - V) <= tol, to_here = length(q.to - V) <= tol;
    if (from_here == to_here) {
      // Not at the corner: it must stay out of the cap's reach.
      const double u = std::clamp(dot(V - q.from, q.dir), 0.0, q.length);
      if (length(q.from + u * q.dir - V) < reach) return -1;
      continue;
    }
    const Vec2 dq = from_here ? q.dir : -q.dir;
    if (!(dot(dq, c.nA) < -1e-12)) return 0;   // collinear or turning towards the body
    Vec2 nB = perp(dq);
    if (dot(nB, c.dA) < 0.0) nB = -nB;
    const double Phi = std::atan2(dot(nB, c.dA), dot(nB, c.nA));
    if (Phi < c.Phi) {
      c.Phi = Phi;
      c.nB = nB;
      c.next = o;
    }
  }
  return 1;
}

// No other body can reach the cap's disc (radius 2r about the corner) within the step
// (from its state now, at its speed and acceleration: a scan, paid only on a cap).
// Whether body j, from its state now, can reach the disc of radius R about V within dt.
bool may_reach(const World& w, std::uint32_t i, std::uint32_t j, Vec2 V, double R, double dt) {
  if (j == i || !w.alive(j)) return false;
  if (w.any_rules) {
    const PairResponse& rr = w.response(w.group[i], w.group[j]);
    if (!rr.collide && !rr.event) return false;
  }
  const double reach = R + w.radius[j] + length(w.vel[j]) * dt + 0.5 * length(w.force_acc(j)) * dt * dt;
  return length(w.pos[j] - V) <= reach;
}

double cap_disc(const World& w, std::uint32_t i) {
  return 2.0 * w.radius[i] + 1e-9 * (w.radius[i] + w.length_scale);
}

bool cap_alone(const World& w, std::uint32_t i, double dt) {
  const Vec2 V = w.caps.at(i).V;
  const double R = cap_disc(w, i);
  for (std::uint32_t j = 0; j < w.size(); ++j) {
    if (may_reach(w, i, j, V, R, dt)) return false;
  }
  return true;
}

// cap_alone for every rider at once (release_crowded_riders, each step): the same answer
// for each, from the bodies sorted by x. A body j can reach a rider's disc only within
// R + r_j + |v_j| dt + |a_j| dt^2 / 2 of its corner, so only the bodies whose x lies within
// R + the largest such r_j + ... of the corner's (widened by 1e-9 of it and of |x| against
// the sums' round-off) are asked, by the same test. One scan per rider made a floor of 3,000
// balls each riding a corner about once a second spend 45% of its steps there.
void riders_alone(const World& w, double dt, std::vector<std::uint32_t>& crowded) {
  thread_local std::vector<std::pair<double, std::uint32_t>> by_x;
  by_x.clear();
  double reach = 0.0;
  for (std::uint32_t j = 0; j < w.size(); ++j) {
    if (!w.alive(j) || std::isnan(w.pos[j].x)) continue;   // (NaN: never within reach)
    by_x.push_back({w.pos[j].x, j});
    reach = std::max(reach, w.radius[j] + length(w.vel[j]) * dt + 0.5 * length(w.force_acc(j)) * dt * dt);
  }
  std::sort(by_x.begin(), by_x.end());
  for (const auto& [i, c] : w.caps) {
    if (!w.dynamic(i)) {
      crowded.push_back(i);
      continue;
    }
    const double R = cap_disc(w, i);
    const double half = (R + reach) * (1.0 + 1e-9) + 1e-9 * std::fabs(c.V.x);
    if (!std::isfinite(half)) {   // a body without a bound: the plain scan
      if (!cap_alone(w, i, dt)) crowded.push_back(i);
      continue;
    }
    auto at = std::lower_bound(by_x.begin(), by_x.end(), std::pair<double, std::uint32_t>{c.V.x - half, 0u});
    for (; at != by_x.end() && at->first <= c.V.x + half; ++at) {
      if (may_reach(w, i, at->second, c.V, R, dt)) {
        crowded.push_back(i);
        break;
      }
    }
  }
}

// Body i leaves the cap at time te with state s: onto a face, or free. The ride is taken
// by value: erasing it from w.caps below would leave a reference into the map dangling.
void leave_cap(World& w, std::uint32_t i, const Ride c, State s, Exit why, double te, double t_abs, double dt) {
  const double r = w.radius[i];
  w.caps.erase(i);
  const Vec2 n = cap_n(c, s.phi);
  w.pos[i] = c.V + r * n;
  w.vel[i] = (r * s.omega) * cap_tau(c, s.phi);
  w.tloc[i] = te;
  // Leaving the cap's circle (at third order lifting off, at second order onto a face
  // tangent to it), the corner is no impact for a moment.
  const double amag = length(w.acc[i]);
  w.cap_lifts.push_back({i, c.V, te, amag > 0.0 ? 1e-2 * std::sqrt(r / amag) : 0.0});
  if (why == Exit::LiftOff) {
    w.support[i] = kNone;
    w.apath[i] = w.acc[i];   // free for the rest of the step
    return;
  }
  const bool next = why == Exit::Next;
  const std::uint32_t k = next ? c.next : c.face;
  const Vec2 nk = next ? c.nB : c.nA;
  w.pos[i] = c.V + r * nk;
  w.support[i] = k;
  w.support_n[i] = nk;
  support_path(w, i);
  if (next) record_contact(w, i, kNone, &w.statics.segments[k], t_abs, dt);
}

}  // namespace

void release_crowded_riders(World& w, double t_abs0, double dt) {
  if (w.caps.empty()) return;
  thread_local std::vector<std::uint32_t> out;
  out.clear();
  if (w.caps.size() < 8) {   // a few riders: a scan each costs less than sorting the bodies
    for (const auto& [i, c] : w.caps) {
      if (!w.dynamic(i) || !cap_alone(w, i, dt)) out.push_back(i);
    }
  } else {
    riders_alone(w, dt, out);
  }
  std::sort(out.begin(), out.end());
  for (std::uint32_t i : out) {
    w.caps.erase(i);
    if (!w.dynamic(i)) continue;
    w.apath[i] = w.acc[i];
    note_unmodelled(w, t_abs0);
  }
}

void note_cap_disturbed(World& w, std::uint32_t i, double t_abs) {
  if (w.cap_disturbed == kNone) w.cap_disturbed = i, w.cap_disturbed_time = t_abs;
}

bool corner_of_support(const World& w, std::uint32_t i, Vec2 corner, double t) {
  const double tol = 1e-9 * (w.radius[i] + w.length_scale);
  if (w.supported(i) && !w.on_body(i) && !w.is_held(i)) {
    const Segment& s = w.statics.segments[w.support[i]];
    if (length(corner - s.from) <= tol || length(corner - s.to) <= tol) return true;
  }
  for (const World::CapLift& l : w.cap_lifts) {
    if (l.body != i || t < l.t || t > l.t + l.window) continue;
    if (length(corner - l.V) <= tol) return true;
  }
  return false;
}

bool settle_on_cap(World& w, std::uint32_t i, double t, double t_abs0, double dt, bool impact) {
  const double r = w.radius[i];
  if (!(r > 0.0) || w.newtonian || i >= w.scene_bodies || w.supported(i) || w.riding(i)) return false;
  const Vec2 p = w.pos[i];
  const double tol = 1e-9 * (r + w.length_scale);
  thread_local std::vector<std::uint32_t> found;
  found.clear();
  w.statics.query(make_aabb(p.x - r - tol, p.y - r - tol, p.x + r + tol, p.y + r + tol), found);
  for (std::uint32_t k : found) {
    const Segment& s = w.statics.segments[k];
    if (w.any_rules && !w.response(w.group[i], s.group).collide) continue;
    for (const bool at_to : {false, true}) {
      Ride c;
      c.V = at_to ? s.to : s.from;
      c.dA = at_to ? s.dir : -s.dir;
      const Vec2 d = p - c.V;
      const double dl = length(d);
      if (!(std::fabs(dl - r) <= tol) || !(dot(d, c.dA) >= 0.0)) continue;
      const Vec2 n = d / dl;
      c.nA = dot(n, s.normal) >= 0.0 ? s.normal : -s.normal;
      c.face = k;
      const Vec2 a = w.varying_forces ? body_acceleration(w, i, w.vel[i]) : w.acc[i];
      const double an = dot(a, n), vn = dot(w.vel[i], n);
      if (!(an < 0.0) || (!impact && std::fabs(vn) > w.rest_speed(an, dt))) continue;
      const int found = find_cap(w, i, k, c);
      if (found == 0) continue;
      if (found < 0) {
        note_unmodelled(w, t_abs0 + t);
        return false;
      }
      const double phi = std::atan2(dot(n, c.dA), dot(n, c.nA));
      if (phi < 0.0 || phi > c.Phi) continue;   // over a face: detect_support's
      const Vec2 tau = -std::sin(phi) * c.nA + std::cos(phi) * c.dA;
      // Its normal velocity goes, with Coulomb's impulse (as settling on a face).
      const Vec2 v_before = w.vel[i];
      PairMaterial inelastic = w.pair_material(w.material[i], s.material);
      inelastic.restitution = 0.0;
      if (vn < 0.0) resolve_static(w, i, n, inelastic, 0.0);
      const double vt = dot(w.vel[i], tau);
      if (!(-vt * vt / r - an > 0.0)) {   // lifts off
        w.vel[i] = v_before;
        continue;
      }
      c.phi = phi;
      c.omega = vt / r;
      w.caps[i] = c;
      if (!cap_alone(w, i, dt)) {
        w.caps.erase(i);
        w.vel[i] = v_before;
        note_unmodelled(w, t_abs0 + t);
        return false;
      }
      w.pos[i] = c.V + r * n;
      w.vel[i] = vt * tau;
      w.apath[i] = {};
      record_contact(w, i, kNone, &s, t_abs0 + t, dt);
      return true;
    }
  }
  return false;
}

Aabb cap_box(const World& w, std::uint32_t i) {
  const World::CapRide& c = w.caps.at(i);
  const double R = 2.0 * w.radius[i];
  return make_aabb(c.V.x - R, c.V.y - R, c.V.x + R, c.V.y + R);
}

double ride_cap(World& w, std::uint32_t i, double t, double T, double t_abs0, double dt) {
  const double r = w.radius[i];
  if (!w.riding(i)) {
    // Entering: on face k, leaving over one of its ends.
    if (!w.supported(i) || w.on_body(i) || w.is_held(i) || !(r > 0.0)) return -1.0;
    const std::uint32_t k = w.support[i];
    const Segment& s = w.statics.segments[k];
    Ride c;
    c.face = k;
    c.nA = w.support_n[i];
    const bool at_to = dot(w.pos[i] - s.from, s.dir) > 0.5 * s.length;
    c.V = at_to ? s.to : s.from;
    c.dA = at_to ? s.dir : -s.dir;
    const Vec2 a = w.varying_forces ? body_acceleration(w, i, w.vel[i]) : w.acc[i];
    const double v_out = dot(w.vel[i], c.dA);
    // Fast enough to lift off (its gap to the corner grows): the exact flight.
    if (!(-v_out * v_out / r - dot(a, c.nA) > 0.0)) return -1.0;
    const int found = w.newtonian || i >= w.scene_bodies ? -1 : find_cap(w, i, k, c);
    if (found <= 0) {
      if (found < 0) note_unmodelled(w, t_abs0 + t);
      return -1.0;
    }
    c.phi = 0.0;
    c.omega = v_out / r;
    w.caps[i] = c;
    if (!cap_alone(w, i, dt)) {
      w.caps.erase(i);
      note_unmodelled(w, t_abs0 + t);
      return -1.0;
    }
    w.support[i] = kNone;   // the cap is the constraint now
  }
  Ride& c = w.caps.at(i);
  w.apath[i] = {};
  const Friction fr = cap_friction(w, i, w.statics.segments[c.face]);
  const bool friction = fr.moving > 0.0 || fr.holding > 0.0;
  State s{c.phi, c.omega};
  double tc = std::max(t, w.tloc[i]);   // riding, its state (phi, omega) is at tloc
  for (;;) {
    const Vec2 a = force_on_cap(w, i, r, c, s.phi, s.omega);
    const double an = dot(a, cap_n(c, s.phi)), at = dot(a, cap_tau(c, s.phi));
    double dir = s.omega > 0.0 ? 1.0 : s.omega < 0.0 ? -1.0 : 0.0;
    if (dir == 0.0) {
      // At rest on the cap: held while static friction can (exactly at the top, with
      // nothing pulling along, frictionless too).
      const double N = std::max(-an, 0.0);
      if (!(N > 0.0)) {
        leave_cap(w, i, c, s, Exit::LiftOff, tc, t_abs0 + tc, dt);
        return tc;
      }
      if (std::fabs(at) <= fr.holding * N) {
        c.phi = s.phi;
        c.omega = 0.0;
        const Vec2 n = cap_n(c, s.phi);
        w.pos[i] = c.V + r * n;
        w.vel[i] = {};
        w.tloc[i] = T;
        touch_contact(w, i, static_partner_key(w.statics.segments[c.face].owner), t_abs0 + T);
        return T;
      }
      dir = at > 0.0 ? 1.0 : -1.0;
    }
    const Rhs f{w, i, r, fr.moving, c, dir};
    const double amag = std::max(length(a), std::fabs(at) + std::fabs(an));
    double h = 1e-3 * std::sqrt(r / amag);
    if (s.omega != 0.0) h = std::min(h, 1e-3 / std::fabs(s.omega));
    if (!(h > 0.0) || !std::isfinite(h)) h = T - tc;
    h = std::min(h, T - tc);
    if (!(h > 0.0)) break;
    State e = rk4(f, s, h);
    Exit why = reached(w, i, r, c, e, dir, friction);
    if (why == Exit::None) {
      s = e;
      tc = tc + h == tc ? T : tc + h;
      if (tc >= T) break;
      continue;
    }
    // Bisect the step to its event (the earliest state that has reached one).
    double lo = 0.0, hi = h;
    for (int it = 0; it < 200; ++it) {
      const double mid = 0.5 * (lo + hi);
      if (mid <= lo || mid >= hi) break;
      const State m = rk4(f, s, mid);
      if (reached(w, i, r, c, m, dir, friction) != Exit::None) {
        hi = mid;
      } else {
        lo = mid;
      }
    }
    e = rk4(f, s, hi);
    why = reached(w, i, r, c, e, dir, friction);
    const double te = std::min(tc + hi, T);
    if (why == Exit::Stop) {
      s = {std::clamp(e.phi, 0.0, c.Phi), 0.0};
      tc = te;
      if (tc >= T) break;
      continue;
    }
    if (why == Exit::Next) e.phi = c.Phi;
    if (why == Exit::Back) e.phi = 0.0;
    leave_cap(w, i, c, e, why, te, t_abs0 + te, dt);
    return te;
  }
  // Still on the cap at the step's end.
  c.phi = s.phi;
  c.omega = s.omega;
  w.pos[i] = c.V + r * cap_n(c, s.phi);
  w.vel[i] = (r * s.omega) * cap_tau(c, s.phi);
  w.tloc[i] = T;
  touch_contact(w, i, static_partner_key(w.statics.segments[c.face].owner), t_abs0 + T);
  return T;
}

}  // namespace physval::core_detail
