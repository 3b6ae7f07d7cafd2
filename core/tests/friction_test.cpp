// Coulomb friction on walls and inclines: static friction holds, kinetic friction
// decelerates at mu_k N / m and never reverses a velocity, rolling resistance is the
// smaller coefficient of a wheel. Constant accelerations, so the closed forms hold to
// round-off (1e-9).
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "scene_fixture.hpp"

namespace physval::test {

namespace {
constexpr double g = 9.8;

// A circle resting halfway up an incline of angle theta (a wall rising to the right).
Scene incline(double theta, double mu_k, double mu_s) {
  const Vec2 dir{std::cos(theta), std::sin(theta)};
  const Vec2 n = perp(dir);
  const Vec2 contact = 5.0 * dir;
  BodyDef block = circle("block", contact + 0.5 * n);
  block.friction = mu_k;
  block.static_friction = mu_s;
  return scene_of({block}, {wall("incline", {0.0, 0.0}, 10.0 * dir, 1.0, mu_k, mu_s)}, {0.0, -g});
}
}  // namespace

TEST(CoreFriction, BlockOnInclineHoldsBelowStaticLimit) {
  // tan(20 deg) = 0.364 < mu_s = 0.5: no motion at all.
  const double theta = 20.0 * std::numbers::pi / 180.0;
  Scene s = incline(theta, 0.3, 0.5);
  const Vec2 start = s.bodies[0].position;
  for (const char* integ : {"semi_implicit_euler", "velocity_verlet", "rk4"}) {
    SCOPED_TRACE(integ);
    Sim sim(s, options(integ));
    sim.run_until(3.0, 1.0 / 60.0);
    EXPECT_NEAR(sim.state("block").position.x, start.x, 1e-12);
    EXPECT_NEAR(sim.state("block").position.y, start.y, 1e-12);
    EXPECT_EQ(length(sim.state("block").velocity), 0.0);
  }
}

TEST(CoreFriction, BlockOnInclineSlidesAtKineticRate) {
  // tan(20 deg) > mu_s = 0.3: slides with a = g (sin - mu_k cos), mu_k = 0.2.
  const double theta = 20.0 * std::numbers::pi / 180.0;
  const double mu_k = 0.2;
  Scene s = incline(theta, mu_k, 0.3);
  const Vec2 start = s.bodies[0].position;
  const Vec2 down{-std::cos(theta), -std::sin(theta)};
  Sim sim(s);
  const double t = 1.5;
  sim.run_until(t, 1.0 / 60.0);
  const double a = g * (std::sin(theta) - mu_k * std::cos(theta));
  const BodyState st = sim.state("block");
  EXPECT_NEAR(dot(st.position - start, down), 0.5 * a * t * t, 1e-9);
  EXPECT_NEAR(dot(st.velocity, down), a * t, 1e-9);
  EXPECT_NEAR(cross(down, st.position - start), 0.0, 1e-9);   // stays on the incline
}

TEST(CoreFriction, SlidingStopsAndNeverReverses) {
  // v0 = 3 m/s on a flat floor with mu_k = 0.3: stops at t = v0 / (mu g) after
  // v0^2 / (2 mu g), and stays there.
  const double mu = 0.3, v0 = 3.0;
  BodyDef b = circle("puck", {0.0, 0.5}, {v0, 0.0});
  b.friction = mu;
  b.static_friction = mu;
  Sim sim(scene_of({b}, {wall("floor", {-10.0, 0.0}, {10.0, 0.0}, 1.0, mu)}, {0.0, -g}));
  const double t_stop = v0 / (mu * g), d_stop = v0 * v0 / (2.0 * mu * g);
  sim.run_until(0.5 * t_stop, 1.0 / 60.0);
  EXPECT_NEAR(sim.state("puck").velocity.x, v0 - mu * g * 0.5 * t_stop, 1e-9);
  double min_v = v0;
  while (sim.engine.time() < 3.0) {
    sim.step(1.0 / 60.0);
    min_v = std::min(min_v, sim.state("puck").velocity.x);
  }
  EXPECT_EQ(min_v, 0.0);   // reaches exactly zero, never negative
  EXPECT_NEAR(sim.state("puck").position.x, d_stop, 1e-9);
  EXPECT_EQ(sim.state("puck").velocity.x, 0.0);
}

TEST(CoreFriction, RollingResistanceIsTheSmallerBrake) {
  // A wheel (rolling_friction c = 0.02) rolls v0^2 / (2 c g); the same body sliding
  // with mu_k = 0.3 stops after v0^2 / (2 mu g).
  const double v0 = 2.0, c = 0.02, mu = 0.3;
  auto distance = [&](double rolling) {
    BodyDef b = circle("wheel", {0.0, 0.5}, {v0, 0.0});
    b.friction = mu;
    b.static_friction = mu;
    b.rolling_friction = rolling;
    WallDef f = wall("floor", {-1.0, 0.0}, {100.0, 0.0}, 1.0, mu);
    f.material.rolling_friction = rolling;
    Sim sim(scene_of({b}, {f}, {0.0, -g}));
    sim.run_until(15.0, 1.0 / 60.0);
    EXPECT_EQ(sim.state("wheel").velocity.x, 0.0);
    return sim.state("wheel").position.x;
  };
  EXPECT_NEAR(distance(c), v0 * v0 / (2.0 * c * g), 1e-9);
  EXPECT_NEAR(distance(0.0), v0 * v0 / (2.0 * mu * g), 1e-9);
}

TEST(CoreFriction, ImpactFrictionNeverReversesTangentialVelocity) {
  // A ball hitting a rough floor obliquely: the Coulomb impulse reduces the
  // tangential speed by mu (1 + e) |vn| at most, and never below zero.
  for (double mu : {0.1, 5.0}) {
    SCOPED_TRACE(mu);
    BodyDef b = circle("ball", {0.0, 1.5}, {1.0, -3.0});
    b.friction = mu;
    b.static_friction = mu;
    Sim sim(scene_of({b}, {wall("floor", {-10.0, 0.0}, {10.0, 0.0}, 1.0, mu)}));
    sim.run_until(0.5, 0.01);
    const BodyState st = sim.state("ball");
    EXPECT_NEAR(st.velocity.y, 3.0, 1e-12);
    EXPECT_NEAR(st.velocity.x, std::max(0.0, 1.0 - mu * 2.0 * 3.0), 1e-12);
  }
}

TEST(CoreFriction, SlopeGridHoldsOrSlidesExactlyWithNoZeroTimeImpacts) {
  // A circle released touching an incline, over a grid of angles and (mu_s, mu_k): it
  // holds where tan(angle) <= mu_s, else slides with a = g (sin - mu_k cos); after 2 s it
  // is on the line to round-off and where the closed form says, and no step has any
  // event. Before the body's own face stopped being an impact candidate, 12 of these
  // 110 cases spun on zero-time impacts every step (a ~1e-16 normal acceleration read
  // as "pressed together") and hit the event cap.
  const double g = 9.8, r = 0.5;
  int cases = 0;
  for (int deg = 10; deg <= 60; deg += 5) {
    for (double mu_s : {0.1, 0.2, 0.3, 0.5, 0.8}) {
      for (double ratio : {0.5, 1.0}) {
        const double mu_k = mu_s * ratio;
        SCOPED_TRACE(std::to_string(deg) + " deg, mu_s " + std::to_string(mu_s) + ", mu_k " + std::to_string(mu_k));
        const double th = deg * std::acos(-1.0) / 180.0;
        const Vec2 d{std::cos(th), -std::sin(th)}, n{std::sin(th), std::cos(th)};
        BodyDef b = circle("block", r * n, {}, r, 1.0, 0.0);
        b.friction = mu_k;
        b.static_friction = mu_s;
        EngineOptions opt = options("velocity_verlet");
        opt["max_events_per_step"] = std::int64_t{2000};
        Sim sim(scene_of({b}, {wall("incline", -100.0 * d, 100.0 * d, 0.0, mu_k, mu_s)}, {0.0, -g}), opt);
        std::int64_t events = 0;
        for (int k = 0; k < 120; ++k) {
          sim.step(1.0 / 60.0);
          events += sim.engine.last_step_stats().events;
          ASSERT_EQ(sim.engine.broken_guarantee(), "");
        }
        const double a = std::tan(th) > mu_s ? g * (std::sin(th) - mu_k * std::cos(th)) : 0.0;
        const BodyState st = sim.state("block");
        EXPECT_EQ(events, 0);
        EXPECT_NEAR(dot(st.position, n) - r, 0.0, 1e-12);
        EXPECT_NEAR(dot(st.position, d), 0.5 * a * 4.0, 1e-9);
        EXPECT_NEAR(dot(st.velocity, d), a * 2.0, 1e-9);
        ++cases;
      }
    }
  }
  EXPECT_EQ(cases, 110);
}

}  // namespace physval::test

namespace physval::test {

TEST(CoreFriction, LiftsOffAConvexKinkAndLandsOnTime) {
  // Frictionless: a small circle slides 1 m down a 20 degree slope to a kink where a 50
  // degree slope begins. Leaving the first face is an exact event (at sqrt(2 s / a)), and
  // then it flies: it needs v^2 / r >> g cos to follow the corner, so it leaves along the
  // first slope and lands on the second where its gap, r (cos 30 - 1) + v t sin 30 -
  // g cos 50 t^2 / 2, comes back to 0.
  const double g = 9.8, r = 0.01, s = 1.0, pi = std::acos(-1.0);
  const double t1 = 20.0 * pi / 180.0, t2 = 50.0 * pi / 180.0;
  const Vec2 d1{std::cos(t1), -std::sin(t1)}, n1{std::sin(t1), std::cos(t1)};
  const Vec2 d2{std::cos(t2), -std::sin(t2)};
  Sim sim(scene_of({circle("ball", -s * d1 + r * n1, {}, r, 1.0, 0.0)},
                   {wall("upper", -5.0 * d1, {0.0, 0.0}, 0.0), wall("lower", {0.0, 0.0}, 20.0 * d2, 0.0)}, {0.0, -g}));
  const double a = g * std::sin(t1);
  const double t_leave = std::sqrt(2.0 * s / a), v = a * t_leave;
  const double A = -0.5 * g * std::cos(t2), B = v * std::sin(pi / 6.0), C = r * (std::cos(pi / 6.0) - 1.0);
  const double t_fly = (-B - std::sqrt(B * B - 4.0 * A * C)) / (2.0 * A);
  sim.run_until(t_leave + t_fly + 0.5, 1.0 / 60.0);
  double landing = -1.0;
  for (const ContactEvent& c : sim.contacts)
    if (c.b.kind != ObjectRef::Kind::Body && c.b.index == 1u && landing < 0.0) landing = c.time;
  EXPECT_NEAR(landing, t_leave + t_fly, 1e-9);
}

}  // namespace physval::test
