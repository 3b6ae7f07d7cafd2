// Free motion against closed forms: projectiles, free fall, drag, thrust tables,
// variable steps. Velocity Verlet and RK4 are exact for constant forces, so those
// answers are held to round-off (1e-9, far above the ~1e-13 a few hundred steps of
// double arithmetic accumulate, far below any discretisation error).
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "scene_fixture.hpp"

namespace physval::test {

namespace {
constexpr double g = 9.8;
}

TEST(CoreMotion, ProjectileApexAndRange) {
  const double v0 = 20.0, theta = std::numbers::pi / 3.0;
  const double vx = v0 * std::cos(theta), vy = v0 * std::sin(theta);
  const double t_apex = vy / g, h_apex = vy * vy / (2.0 * g), range = 2.0 * vx * vy / g;
  for (const char* integ : {"velocity_verlet", "rk4"}) {
    SCOPED_TRACE(integ);
    Scene s = scene_of({point("p", {0.0, 0.0}, {vx, vy})}, {wall("ground", {-1.0, 0.0}, {100.0, 0.0}, 0.0)}, {0.0, -g});
    Sim sim(s, options(integ));
    sim.run_until(t_apex, 0.01);
    EXPECT_NEAR(sim.state("p").position.y, h_apex, 1e-9);
    EXPECT_NEAR(sim.state("p").velocity.y, 0.0, 1e-9);
    sim.run_until(2.0 * t_apex + 0.1, 0.01);
    ASSERT_EQ(sim.contacts.size(), 1u);
    EXPECT_NEAR(sim.contacts[0].time, 2.0 * t_apex, 1e-9);
    // Landed (e = 0) and slid on at vx along the frictionless ground.
    EXPECT_NEAR(sim.state("p").position.x, range + vx * (sim.engine.time() - 2.0 * t_apex), 1e-9);
    EXPECT_NEAR(sim.state("p").position.y, 0.0, 1e-9);
  }
}

TEST(CoreMotion, FreeFallContactTimeExact) {
  // Bottom of the ball 10 m above the floor: t = sqrt(2 h / g), to 1e-9 s at dt = 1/60.
  const double h = 10.0, t_hit = std::sqrt(2.0 * h / g);
  for (const char* integ : {"velocity_verlet", "rk4"}) {
    SCOPED_TRACE(integ);
    Sim sim(scene_of({circle("ball", {0.0, h + 0.5})}, {wall("floor", {-5.0, 0.0}, {5.0, 0.0})}, {0.0, -g}),
            options(integ));
    sim.steps(120, 1.0 / 60.0);
    ASSERT_GE(sim.contacts.size(), 1u);
    EXPECT_EQ(sim.contacts[0].a.index, 0u);
    EXPECT_EQ(sim.contacts[0].b.kind, ObjectRef::Kind::Wall);
    EXPECT_NEAR(sim.contacts[0].time, t_hit, 1e-9);
  }
}

TEST(CoreMotion, LinearDragTerminalVelocityAndPath) {
  // m dv/dt = m g - k v: v(t) = vt + (v0 - vt) e^{-kt/m}, vt = -m g / k.
  const double m = 2.0, k = 0.5, vt = -m * g / k, v0 = 5.0;
  Scene s = scene_of({point("p", {0.0, 0.0}, {0.0, v0}, m)}, {}, {0.0, -g});
  s.bodies[0].drag_linear = k;
  Sim sim(s, options("rk4"));
  const double tau = m / k;
  auto v_at = [&](double t) { return vt + (v0 - vt) * std::exp(-t / tau); };
  auto y_at = [&](double t) { return vt * t + (v0 - vt) * tau * (1.0 - std::exp(-t / tau)); };
  sim.run_until(3.0, 0.01);
  // RK4 at dt = 0.01 on a time scale of 4 s: error ~ (dt/tau)^4 ~ 1e-11 relative.
  EXPECT_NEAR(sim.state("p").velocity.y, v_at(3.0), 1e-8);
  EXPECT_NEAR(sim.state("p").position.y, y_at(3.0), 1e-8);
  sim.run_until(60.0, 0.01);
  EXPECT_NEAR(sim.state("p").velocity.y, vt, 2e-5);   // (v0 - vt) e^{-15} = 1.4e-5 short of it
  EXPECT_NEAR(sim.state("p").velocity.y, v_at(60.0), 1e-8);
}

TEST(CoreMotion, DragTowardsWind) {
  // No gravity, wind (5, 0): v_x(t) = 5 (1 - e^{-kt/m}).
  const double m = 1.0, k = 2.0;
  Scene s = scene_of({point("p", {0.0, 0.0}, {}, m)});
  s.bodies[0].drag_linear = k;
  s.world.wind = {5.0, 0.0};
  Sim sim(s, options("rk4"));
  sim.run_until(1.0, 0.001);
  EXPECT_NEAR(sim.state("p").velocity.x, 5.0 * (1.0 - std::exp(-k / m)), 1e-10);
  EXPECT_EQ(sim.state("p").velocity.y, 0.0);
}

TEST(CoreMotion, ThrustTableOneInput) {
  // a(v) = 4 - 0.2 v (table 0:4, 10:2, 20:0, linear between): v(t) = 20 (1 - e^{-0.2 t}).
  Scene s = scene_of({point("car", {0.0, 0.0}, {}, 1000.0)});
  s.bodies[0].thrust.speeds = {0.0, 10.0, 20.0};
  s.bodies[0].thrust.accel = {{4.0, 2.0, 0.0}};
  Sim sim(s, options("rk4"));
  sim.run_until(3.0, 0.01);
  EXPECT_NEAR(sim.state("car").velocity.x, 20.0 * (1.0 - std::exp(-0.6)), 1e-9);
  EXPECT_NEAR(sim.state("car").position.x, 20.0 * 3.0 - 100.0 * (1.0 - std::exp(-0.6)), 1e-9);
}

TEST(CoreMotion, ThrustTableGearsThrottleHeading) {
  // Gear 1.5 between rows of 2 and 4 m/s^2 -> 3; throttle 0.5 -> 1.5 m/s^2 along 30 deg.
  const double heading = std::numbers::pi / 6.0;
  Scene s = scene_of({point("car", {0.0, 0.0})});
  ThrustDef& t = s.bodies[0].thrust;
  t.speeds = {0.0, 50.0};
  t.gears = {1.0, 2.0};
  t.accel = {{2.0, 2.0}, {4.0, 4.0}};
  t.gear = 1.5;
  t.throttle = 0.5;
  s.bodies[0].angle = heading;
  Sim sim(s, options("velocity_verlet"));
  sim.run_until(2.0, 0.01);
  const BodyState st = sim.state("car");
  EXPECT_NEAR(st.velocity.x, 1.5 * std::cos(heading) * 2.0, 1e-12);
  EXPECT_NEAR(st.velocity.y, 1.5 * std::sin(heading) * 2.0, 1e-12);
  EXPECT_NEAR(st.position.x, 0.5 * 1.5 * std::cos(heading) * 4.0, 1e-12);
}

TEST(CoreMotion, VariableStepKeepsExactTimes) {
  // Steps of changing size: the path is still the exact parabola, the contact exact.
  const double h = 3.0, t_hit = std::sqrt(2.0 * h / g);
  Sim sim(scene_of({circle("ball", {0.0, h + 0.5}, {1.0, 0.0})}, {wall("floor", {-5.0, 0.0}, {5.0, 0.0})}, {0.0, -g}));
  const double dts[] = {0.01, 0.033, 0.002, 0.05, 0.017};
  double t = 0.0;
  for (int k = 0; t < 0.6; ++k) {
    sim.step(dts[k % 5]);
    t += dts[k % 5];
  }
  const BodyState st = sim.state("ball");
  const double te = sim.engine.time();
  EXPECT_NEAR(st.position.y, h + 0.5 - 0.5 * g * te * te, 1e-9);
  EXPECT_NEAR(st.position.x, te, 1e-12);
  while (sim.engine.time() < 1.0) sim.step(dts[(static_cast<int>(sim.engine.time() * 1000)) % 5]);
  ASSERT_GE(sim.contacts.size(), 1u);
  EXPECT_NEAR(sim.contacts[0].time, t_hit, 1e-9);
}

}  // namespace physval::test
