// A lone ball's Zeno sequence on a face WITH friction and motion along it (branch zeno12): a
// ball dropped from h onto a face tilted 0-40 degrees, launched along it at u0, restitution
// 0.1-0.95, kinetic friction mu_k and static mu_s, stepped at dt from 0.05 to 150 of its falls.
// The reference is the sequence summed bounce by bounce in long double (up to 10^5 bounces,
// collision_response.cpp's law at each impact: the normal speed reversed and scaled by e, the
// slip reduced by min(mu_k (1 + e) w, |slip|), w the closing speed; free flight under gravity
// between), then, from the Zeno limit on, the sliding contact: kinetic friction until the
// slip stops, then held iff |a_t| <= max(mu_s, mu_k) a_n, else sliding from rest. Before this
// test core ended such a sequence at its first impact slower than the rest speed |a| dt / 16
// (settled at once: one inelastic impact's friction, no flights), wrong by up to the whole
// tail's friction (mu_k (1 + e) w / (1 - e)) and its free flights; the reference (dt/8)
// ended it the same way.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <sstream>
#include <vector>

#include "scene_fixture.hpp"

namespace physval::test {
namespace {

constexpr double kG = 9.81;
using LD = long double;

struct Case {
  double h, e, mu_k, mu_s, tilt, u0, falls;
};

std::string describe(const Case& c) {
  std::ostringstream d;
  d << "h " << c.h << " e " << c.e << " mu_k " << c.mu_k << " mu_s " << c.mu_s << " tilt " << c.tilt << " u0 " << c.u0
    << " dt " << c.falls << " falls";
  return d.str();
}

// The bounce-by-bounce sum: impact k at t[k] (the first at tf), closing speed a tf e^k, the
// slip before (pre) and after (post) it, the displacement along the face x[k] at it.
struct Reference {
  LD a, at, e, mu_k, hold, tf, u0;
  std::vector<LD> t, x, pre, post;
  LD tL = 0, xL = 0, sL = 0;   // the Zeno limit: time, displacement, slip
  bool stopped_in_tail = false, slid_through_tail = false;

  Reference(const Case& c) {
    a = static_cast<LD>(kG) * std::cos(static_cast<LD>(c.tilt));
    at = -static_cast<LD>(kG) * std::sin(static_cast<LD>(c.tilt));
    e = c.e;
    mu_k = c.mu_k;
    hold = std::max(c.mu_s, c.mu_k);
    tf = std::sqrt(2 * static_cast<LD>(c.h) / a);
    u0 = c.u0;
    LD tk = tf, w = a * tf, s = u0 + at * tf, xk = u0 * tf + at * tf * tf / 2;
    for (int k = 0; k < 100000; ++k) {
      t.push_back(tk);
      x.push_back(xk);
      pre.push_back(s);
      const LD cap = mu_k * (1 + e) * w;
      const LD sp = std::fabs(s) <= cap ? LD(0) : s - std::copysign(cap, s);
      post.push_back(sp);
      const LD T = 2 * e * w / a;
      if (tk + T == tk) break;
      xk += sp * T + at * T * T / 2;
      s = sp + at * T;
      tk += T;
      w *= e;
    }
    // The rest of the sequence (after the last flight summed, under the long double's resolution).
    tL = t.back() + 2 * e * w / a / (1 - e);
    xL = x.back();
    sL = post.back();
    // The tail's regime, for the grid's coverage: the impacts after the first one slower than a
    // tenth of the first (the part a step of a few falls takes in closed form).
    for (std::size_t k = 1; k < t.size(); ++k) {
      if (std::pow(e, static_cast<LD>(k)) > 0.1L) continue;
      if (post[k] == 0 && pre[k] != 0) stopped_in_tail = true;
      if (post[k] != 0 && k + 1 == t.size()) slid_through_tail = true;
    }
  }

  // The contact from the Zeno limit on (time since it u >= 0): displacement and slip.
  void contact(LD u, LD& xo, LD& so) const {
    LD x0 = xL, s = sL;
    if (s != 0) {
      const LD as = at - std::copysign(mu_k * a, s);
      if (as * s >= 0) {
        xo = x0 + s * u + as * u * u / 2;
        so = s + as * u;
        return;
      }
      const LD ts = -s / as;
      if (u < ts) {
        xo = x0 + s * u + as * u * u / 2;
        so = s + as * u;
        return;
      }
      x0 += s * ts / 2;
      u -= ts;
    }
    if (std::fabs(at) <= hold * a) {
      xo = x0;
      so = 0;
      return;
    }
    const LD a2 = at - std::copysign(mu_k * a, at);
    xo = x0 + a2 * u * u / 2;
    so = a2 * u;
  }

  // The candidate states at time tt (two at an impact within round-off: before and after it).
  struct State {
    LD x, y, vx, vy;
  };
  void states(LD tt, std::vector<State>& out) const {
    out.clear();
    const LD eps = 1e-12L * (tt + tf);
    if (tt < tf) {
      out.push_back({u0 * tt + at * tt * tt / 2, a * (tf * tf - tt * tt) / 2, u0 + at * tt, -a * tt});
      if (std::fabs(tt - tf) < eps) out.push_back({x[0], 0, post[0], e * a * tf});
      return;
    }
    if (tt >= tL) {
      LD xo, so;
      contact(tt - tL, xo, so);
      out.push_back({xo, 0, so, 0});
      if (std::fabs(tt - tL) < eps) out.push_back({xL, 0, sL, 0});
      return;
    }
    std::size_t k = static_cast<std::size_t>(std::upper_bound(t.begin(), t.end(), tt) - t.begin()) - 1;
    const LD w = a * tf * std::pow(e, static_cast<LD>(k));
    const LD u = tt - t[k];
    out.push_back({x[k] + post[k] * u + at * u * u / 2, std::max(LD(0), e * w * u - a * u * u / 2), post[k] + at * u,
                   e * w - a * u});
    if (std::fabs(u) < eps) out.push_back({x[k], 0, pre[k], -w});
    if (k + 1 < t.size() && std::fabs(t[k + 1] - tt) < eps) {
      out.push_back({x[k + 1], 0, pre[k + 1], -w * e});
      out.push_back({x[k + 1], 0, post[k + 1], w * e * e});
    }
  }
};

// The largest miss over the steps' ends (position relative to the scene's size, velocity to
// its speeds, each over its tolerance), stepping at c.falls falls until the slip has settled
// (the Zeno limit, the contact's stop) and two steps more.
struct Miss {
  double pos = 0.0, vel = 0.0;
};
Miss run(const Case& c, const Reference& ref) {
  const double r = 0.1;
  const Vec2 dir{std::cos(c.tilt), std::sin(c.tilt)};
  const Vec2 n{-dir.y, dir.x};
  const Vec2 g{0.0, -kG};
  const double a = static_cast<double>(ref.a), tf = static_cast<double>(ref.tf);
  const double dt = c.falls * tf;
  double settle = static_cast<double>(ref.tL);
  if (ref.sL != 0) {   // the contact's slide to its stop, when it stops
    const LD as = ref.at - std::copysign(ref.mu_k * ref.a, ref.sL);
    if (as * ref.sL < 0) settle += static_cast<double>(-ref.sL / as);
  }
  const double T = std::max(settle, static_cast<double>(ref.tL)) + 2.0 * dt;
  const int steps = static_cast<int>(std::ceil(T / dt));
  const double span = steps * dt;
  const double reach = std::fabs(c.u0) * span + 0.5 * kG * span * span + 10.0;
  BodyDef ball = circle("b", (c.h + r) * n, c.u0 * dir, r, 1.0, c.e);
  ball.friction = c.mu_k;
  ball.static_friction = c.mu_s;
  Sim sim(scene_of({ball}, {wall("face", -reach * dir, reach * dir, c.e, c.mu_k, c.mu_s)}, g));
  Miss worst;
  std::vector<Reference::State> cand;
  for (int k = 1; k <= steps; ++k) {
    sim.step(dt);
    const BodyState b = sim.state("b");
    const double t = k * dt;
    ref.states(static_cast<LD>(t), cand);
    // The tolerance (as zeno_test.cpp): 1e-9 of the scene, plus the event bounces' accumulated
    // time round-off (16 ulps per event bounce: those whose rebound beats a dt / 16).
    const double ratio = dt / 16.0 / tf;
    const double n_ev = ratio < 1.0 ? std::ceil(std::log(ratio) / std::log(c.e)) + 1.0 : 1.0;
    const double tol = 1e-9 + 16.0 * 2.220446049250313e-16 * n_ev * (t / tf);
    double mp = INFINITY, mv = INFINITY;
    for (const Reference::State& s : cand) {
      const double scale = c.h + std::fabs(static_cast<double>(s.x)) + r;
      const double vscale = a * tf + std::fabs(static_cast<double>(s.vx));
      const double dx = std::fabs(dot(b.position, dir) - static_cast<double>(s.x));
      const double dy = std::fabs(dot(b.position, n) - r - static_cast<double>(s.y));
      const double dvx = std::fabs(dot(b.velocity, dir) - static_cast<double>(s.vx));
      const double dvy = std::fabs(dot(b.velocity, n) - static_cast<double>(s.vy));
      mp = std::min(mp, std::max(dx, dy) / scale / tol);
      mv = std::min(mv, std::max(dvx, dvy) / vscale / tol);
    }
    worst.pos = std::max(worst.pos, mp);
    worst.vel = std::max(worst.vel, mv);
  }
  return worst;
}

// u0s: speeds along the face, or (capacity) fractions of the whole sequence's friction
// capacity mu_k (1 + e) w / (1 - e) (w the first impact's closing speed): below 1 the slip
// stops at the impact where e^k falls under 1 - the fraction, above 1 it slides through.
void check_grid(std::initializer_list<double> tilts_deg, std::initializer_list<double> u0s,
                std::initializer_list<double> falls_list, int& stops, int& slides, bool capacity = false) {
  for (double tilt : tilts_deg) {
    for (double e : {0.1, 0.5, 0.8, 0.95}) {
      for (const auto& [mu_k, mu_s] : {std::pair{0.1, 0.1}, std::pair{0.3, 0.9}, std::pair{0.6, 0.8}}) {
        for (double u0 : u0s) {
          for (double falls : falls_list) {
            const double w = std::sqrt(2.0 * 0.1 * kG);
            const double u = capacity ? u0 * mu_k * (1.0 + e) * w / (1.0 - e) : u0;
            const Case c{0.1, e, mu_k, mu_s, tilt * std::numbers::pi / 180.0, u, falls};
            const Reference ref(c);
            stops += ref.stopped_in_tail;
            slides += ref.slid_through_tail;
            const Miss m = run(c, ref);
            EXPECT_LE(m.pos, 1.0) << describe(c);
            EXPECT_LE(m.vel, 1.0) << describe(c);
          }
        }
      }
    }
  }
}

// A level floor: the slip only decreases, stopping early, late within the tail (0.97, 0.995
// of the sequence's friction capacity) or not at all (1.2: the contact's kinetic friction
// stops it after the Zeno limit).
TEST(CoreZenoSlide, ABallSlidingOnALevelFloorWithFrictionMatchesTheBounceByBounceSum) {
  int stops = 0, slides = 0;
  check_grid({0.0}, {-0.5, 0.97, 0.995, 1.2}, {0.05, 0.3, 1.0, 10.0, 150.0}, stops, slides, true);
  EXPECT_GT(stops, 0);
  EXPECT_GT(slides, 0);
}

// Tilted faces (10-40 degrees): gravity along the face adds to the slip in every flight, the
// slip may turn within a flight, stop and stay stopped (|a_t| <= mu_k a (1 + e) / 2), stop and
// slide on, and at the limit the contact holds or slides (mu_s against tan(tilt)).
TEST(CoreZenoSlide, ABallBouncingOnATiltedFaceWithFrictionMatchesTheBounceByBounceSum) {
  int stops = 0, slides = 0;
  check_grid({10.0, 25.0, 40.0}, {0.0, 0.3, -0.3}, {0.3, 1.0, 10.0, 150.0}, stops, slides);
  EXPECT_GT(stops, 0);
  EXPECT_GT(slides, 0);
}

}  // namespace
}  // namespace physval::test
