// A lone ball's Zeno sequence on one static face at restitution 0 < e < 1, frictionless,
// under uniform gravity, at steps of 0.3 to 400 of its falls (the eighth hunt's `zeno`).
// After an impact with rebound normal speed v under normal acceleration a, bounce k lasts
// 2 v e^k / a and the ball comes to rest at t + 2 v / (a (1 - e)) exactly; along the face it
// moves with constant acceleration throughout. Before this test core's rest speed
// |a_n| dt / 16 ended the sequence at the first rebound slower than it and held the ball at
// once, up to 2 v_r / ((1 - e) a) early (e 0.95 at a step of 10 falls: 8.6 mm off for a drop
// of 0.1 m; e 0.99 at 30 falls: 48 mm), and the reference (core at dt/4, dt/8) ended
// settled too, so physval said `ok` (a wrong green).
#include <gtest/gtest.h>

#include <cmath>
#include <utility>
#include <sstream>

#include "scene_fixture.hpp"

namespace physval::test {
namespace {

constexpr double kG = 9.81;

// The normal coordinate of a ball dropped from rest at height h above a face (its lowest
// point) under normal acceleration a: height and normal velocity at t, bounce by bounce
// (the flights summed one at a time, not the geometric sum core uses), and `flip`: t is
// within round-off of an impact (the step may end just before or just after it: the normal
// velocity is then -v_in or v_out).
struct Normal {
  double y, v, v_in, v_out;
  bool flip;
};
Normal bounce(double h, double e, double a, double t) {
  const double tf = std::sqrt(2.0 * h / a);
  const double eps = 1e-12 * (t + tf);
  if (t <= tf) return {h - 0.5 * a * t * t, -a * t, a * tf, e * a * tf, std::fabs(t - tf) < eps};
  if (t >= tf * (1.0 + e) / (1.0 - e) + eps) return {0.0, 0.0, 0.0, 0.0, false};   // at rest (the Zeno limit)
  double t0 = tf, v = e * a * tf, v_in = a * tf;   // leaves the face at t0 with speed v
  while (v > 0.0) {
    if (std::fabs(t - t0) < eps) return {0.0, v, v_in, v, true};
    const double flight = 2.0 * v / a;
    if (std::fabs(t - (t0 + flight)) < eps) return {0.0, e * v, v, e * v, true};
    if (t < t0 + flight || t0 + flight == t0) {
      const double s = t - t0;
      return {std::max(0.0, v * s - 0.5 * a * s * s), v - a * s, v, v, false};
    }
    t0 += flight;
    v_in = v;
    v *= e;
  }
  return {0.0, 0.0, 0.0, 0.0, false};   // at rest after the Zeno limit tf (1 + e) / (1 - e)
}

// The Zeno limit: the time the ball comes to rest.
double rest_time(double h, double e, double a) { return std::sqrt(2.0 * h / a) * (1.0 + e) / (1.0 - e); }

// The tolerance: core's impacts before the tail are exact events (each time a root to a few
// ulps of the time); the tail's state is its geometric sum (D (1 - e^k), D = 2 v / (a (1 -
// e)): a few ulps of D, and D / tf is at most 2 / (1 - e) = 2000 at e 0.999). The tail's own
// error is ~ 4 / (1 - e) x 1e-16 of the scene's scale, under 1e-12 here; 1e-9 is that with a
// margin of 1000 (the closed form here sums the flights one by one). Added to it: the event
// bounces' accumulated time error (run: 16 ulps per event of the time, relative to tf).
constexpr double kTol = 1e-9;

struct Case {
  double h, e, falls;
  double tilt = 0.0;   // the face's angle to the horizontal (gravity not along its normal)
  double u0 = 0.0;     // the ball's speed along the face at release
  double mu_k = 0.0, mu_s = 0.0;   // friction of ball and face (the pair's: the same)
};

std::string describe(const Case& c) {
  std::ostringstream d;
  d << "h " << c.h << " e " << c.e << " dt " << c.falls << " falls tilt " << c.tilt << " u0 " << c.u0 << " mu_k "
    << c.mu_k << " mu_s " << c.mu_s;
  return d.str();
}

// Runs the case at steps of `falls` falls (or `dt` when given) until the rest time and two
// steps more (or max_steps); returns the largest miss at a step's end in position (relative
// to the scene's size) and velocity (relative to its speeds), each over its tolerance.
struct Miss {
  double pos = 0.0, vel = 0.0;
};
Miss run(const Case& c, double dt = 0.0, int max_steps = 0) {
  const double r = 0.1;
  const Vec2 dir{std::cos(c.tilt), std::sin(c.tilt)};   // along the face
  const Vec2 n{-dir.y, dir.x};                         // its normal, up
  const Vec2 g{0.0, -kG};
  const double a = -dot(g, n);                          // normal acceleration (toward the face)
  const double at = dot(g, dir);                        // along the face
  const double tf = std::sqrt(2.0 * c.h / a);
  if (dt == 0.0) dt = c.falls * tf;
  const double T = rest_time(c.h, c.e, a) + 2.0 * dt;
  const int steps = max_steps > 0 ? max_steps : static_cast<int>(std::ceil(T / dt));
  // A face long enough for the slide over the whole run.
  const double reach = std::fabs(c.u0) * steps * dt + 0.5 * std::fabs(at) * (steps * dt) * (steps * dt) + 10.0;
  const Vec2 p0 = (c.h + r) * n;
  BodyDef ball = circle("b", p0, c.u0 * dir, r, 1.0, c.e);
  ball.friction = c.mu_k;
  ball.static_friction = c.mu_s;
  Sim sim(scene_of({ball}, {wall("face", -reach * dir, reach * dir, c.e, c.mu_k, c.mu_s)}, g));
  Miss worst;
  for (int k = 1; k <= steps; ++k) {
    sim.step(dt);
    const BodyState b = sim.state("b");
    const double t = k * dt;
    const Normal z = bounce(c.h, c.e, a, t);
    const double x = c.u0 * t + 0.5 * at * t * t, vx = c.u0 + at * t;
    const Vec2 q = b.position, v = b.velocity;
    const double scale = c.h + std::fabs(x) + r;
    const double vscale = a * tf + std::fabs(vx);
    const double dy = std::fabs(dot(q, n) - r - z.y);
    const double dx = std::fabs(dot(q, dir) - x);
    const double vn = dot(v, n);
    const double dvn = z.flip ? std::min(std::fabs(vn - z.v_out), std::fabs(vn + z.v_in)) : std::fabs(vn - z.v);
    const double dvx = std::fabs(dot(v, dir) - vx);
    // The tolerance (see kTol): the bounces before the tail are events, each impact's time a
    // root found to a few ulps of the time since the start; their errors add up (at most
    // linearly) over the n_ev event bounces, a time error dt' moving the state by a dt' in
    // normal speed (relative to a tf: dt' / tf) and V dt' in height (relative to h = V tf / 2:
    // 2 dt' / tf). n_ev: the bounces whose rebound is faster than the rest speed a dt / 16 (the
    // tail starts at the first slower one).
    const double ratio = a * dt / 16.0 / (a * tf);
    const double n_ev = ratio < 1.0 ? std::ceil(std::log(ratio) / std::log(c.e)) + 1.0 : 1.0;
    const double tol = kTol + 16.0 * 2.220446049250313e-16 * n_ev * (t / tf);
    worst.pos = std::max(worst.pos, std::max(dy, dx) / scale / tol);
    worst.vel = std::max(worst.vel, std::max(dvn, dvx) / vscale / tol);
  }
  return worst;
}

// The grid: drops of 1 cm to 1 m, e 0.3 to 0.999, steps of 0.3 to 400 falls, every step's
// end from the release to two steps past the rest (inside the tail, at rest after it).
TEST(CoreZeno, ALoneBounceEndsAtItsClosedFormTimeAtAnyStep) {
  for (double h : {0.01, 0.1, 1.0}) {
    for (double e : {0.3, 0.7, 0.9, 0.95, 0.99, 0.999}) {
      for (double falls : {0.3, 1.0, 3.0, 10.0, 30.0, 150.0, 400.0}) {
        const Case c{h, e, falls};
        const Miss m = run(c);
        EXPECT_LE(m.pos, 1.0) << describe(c);
        EXPECT_LE(m.vel, 1.0) << describe(c);
      }
    }
  }
}

// Tangential motion on a frictionless floor: the impacts change only the normal velocity.
TEST(CoreZeno, ABounceSlidingAlongAFrictionlessFloorKeepsItsSpeed) {
  for (double h : {0.01, 1.0}) {
    for (double e : {0.5, 0.9, 0.99}) {
      for (double falls : {1.0, 10.0, 30.0, 400.0}) {
        const Case c{h, e, falls, 0.0, 0.7};
        const Miss m = run(c);
        EXPECT_LE(m.pos, 1.0) << describe(c);
        EXPECT_LE(m.vel, 1.0) << describe(c);
      }
    }
  }
}

// A vertical drop onto a level floor with friction: no motion along the face, so no friction
// impulse acts at any impact and the sequence is the frictionless one (the tail in closed form
// takes such a ball too; before, friction kept the old cut: e 0.95 at 30 falls 15.5 mm off for
// h 1 m between impacts, core `ok`).
TEST(CoreZeno, AStraightDropOnAFloorWithFrictionEndsAtItsClosedFormTime) {
  for (double h : {0.01, 0.1, 1.0}) {
    for (double e : {0.5, 0.9, 0.95, 0.99}) {
      for (double falls : {1.0, 10.0, 30.0, 150.0}) {
        for (const auto& [mu_k, mu_s] : {std::pair{0.5, 0.5}, std::pair{0.2, 0.8}}) {
          Case c{h, e, falls};
          c.mu_k = mu_k;
          c.mu_s = mu_s;
          const Miss m = run(c);
          EXPECT_LE(m.pos, 1.0) << describe(c);
          EXPECT_LE(m.vel, 1.0) << describe(c);
        }
      }
    }
  }
}

// A tilted face (gravity not along its normal): the normal acceleration is g cos(tilt), the
// ball accelerates along the face throughout, before and after it comes to rest across it.
TEST(CoreZeno, ABounceOnATiltedFaceSlidesWithConstantAcceleration) {
  for (double tilt : {0.3, -1.0}) {
    for (double h : {0.01, 0.1}) {
      for (double e : {0.5, 0.9, 0.95}) {
        for (double falls : {1.0, 10.0, 30.0}) {
          const Case c{h, e, falls, tilt, 0.2};
          const Miss m = run(c);
          EXPECT_LE(m.pos, 1.0) << describe(c);
          EXPECT_LE(m.vel, 1.0) << describe(c);
        }
      }
    }
  }
}

// Steps that end exactly at an impact inside the tail (T = the k-th impact after the first,
// tf + D (1 - e^k), in 1 or 2 steps) and a step start there: the state is the closed form's
// on either side of the impact, the next steps' too.
TEST(CoreZeno, AStepEndingAtAnImpactOfTheTailGoesOnExactly) {
  for (double h : {0.01, 0.1, 1.0}) {
    for (double e : {0.7, 0.9, 0.99}) {
      for (int k : {3, 10, 40}) {
        for (int split : {1, 2}) {
          const double tf = std::sqrt(2.0 * h / kG);
          const double D = 2.0 * e * tf / (1.0 - e);
          const double Tk = tf + D * (1.0 - std::pow(e, k));
          const double dt = Tk / split;
          const Case c{h, e, dt / tf};
          const Miss m = run(c, dt, split + 4);
          EXPECT_LE(m.pos, 1.0) << describe(c) << " k " << k << " split " << split;
          EXPECT_LE(m.vel, 1.0) << describe(c) << " k " << k << " split " << split;
        }
      }
    }
  }
}

}  // namespace
}  // namespace physval::test
