// Newtonian gravity: a two-body circular orbit, its period, energy drift over 100
// orbits by integrator, and each integrator's order of convergence.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "physval/core/forces.hpp"
#include "scene_fixture.hpp"

namespace physval::test {

namespace {

// Two equal point masses (G = 1, m = 1) a distance d = 2 apart, circling their centre
// of mass at radius 1: v = sqrt(G m / (2 d)) = 0.5, period 2 pi r / v = 4 pi.
constexpr double kPeriod = 4.0 * std::numbers::pi;

Scene binary() {
  Scene s = scene_of({point("a", {1.0, 0.0}, {0.0, 0.5}), point("b", {-1.0, 0.0}, {0.0, -0.5})});
  s.world.newtonian = true;
  s.world.G = 1.0;
  return s;
}

double energy(Sim& sim) {
  const BodyState a = sim.state("a"), b = sim.state("b");
  return 0.5 * (length_squared(a.velocity) + length_squared(b.velocity)) +
         newtonian_potential(1.0, 0.0, 1.0, 1.0, a.position, b.position);
}

// Position error of body a after time t against the exact circle.
double orbit_error(const char* integ, double dt, double t) {
  Sim sim(binary(), options(integ));
  const int n = static_cast<int>(std::lround(t / dt));
  sim.steps(n, dt);
  const double w = 2.0 * std::numbers::pi / kPeriod;
  const double te = n * dt;
  return length(sim.state("a").position - Vec2{std::cos(w * te), std::sin(w * te)});
}

}  // namespace

TEST(CoreOrbit, PeriodOfCircularOrbit) {
  Sim sim(binary(), options("rk4"));
  sim.run_until(kPeriod, 0.01);
  // RK4 at dt = 0.01 over 1257 steps: ~1e-10 per orbit.
  EXPECT_NEAR(sim.state("a").position.x, 1.0, 1e-8);
  EXPECT_NEAR(sim.state("a").position.y, 0.0, 1e-8);
  EXPECT_NEAR(sim.state("b").position.x, -1.0, 1e-8);
}

TEST(CoreOrbit, EnergyDriftOver100Orbits) {
  const double dt = 0.005;   // 2513 steps per orbit
  const int per_orbit = static_cast<int>(std::lround(kPeriod / dt));
  auto drift_profile = [&](const char* integ, double& first, double& last) {
    Sim sim(binary(), options(integ));
    const double e0 = energy(sim);
    first = last = 0.0;
    for (int orbit = 0; orbit < 100; ++orbit) {
      double worst = 0.0;
      for (int k = 0; k < per_orbit; ++k) {
        sim.step(dt);
        worst = std::max(worst, std::fabs(energy(sim) - e0) / std::fabs(e0));
      }
      if (orbit == 0) first = worst;
      if (orbit == 99) last = worst;
    }
  };
  double v_first, v_last, e_first, e_last;
  drift_profile("velocity_verlet", v_first, v_last);
  drift_profile("explicit_euler", e_first, e_last);
  // Verlet is symplectic: its energy error oscillates, bounded by O((w dt)^2), and the
  // 100th orbit is no worse than the first.
  EXPECT_LT(v_last, 1e-3);
  EXPECT_LT(v_last, 1.5 * v_first);
  // Explicit Euler gains energy every step: the drift keeps growing.
  EXPECT_GT(e_last, 10.0 * e_first);
  EXPECT_GT(e_last, 100.0 * v_last);
}

TEST(CoreOrbit, ConvergenceOrders) {
  // Error after one radian of orbit at dt and dt/2: order = log2(e(dt) / e(dt/2)).
  struct Case {
    const char* integ;
    double order;
    double dt;
  };
  const Case cases[] = {{"explicit_euler", 1.0, 0.01}, {"semi_implicit_euler", 1.0, 0.01},
                        {"velocity_verlet", 2.0, 0.01}, {"rk4", 4.0, 0.05}};
  for (const Case& c : cases) {
    SCOPED_TRACE(c.integ);
    const double e1 = orbit_error(c.integ, c.dt, 2.0);
    const double e2 = orbit_error(c.integ, c.dt / 2.0, 2.0);
    const double e3 = orbit_error(c.integ, c.dt / 4.0, 2.0);
    // Asymptotic regime: both halvings give the same order to within 0.15.
    EXPECT_NEAR(std::log2(e1 / e2), c.order, 0.15);
    EXPECT_NEAR(std::log2(e2 / e3), c.order, 0.15);
  }
}

}  // namespace physval::test
