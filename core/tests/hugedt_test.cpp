// A ball bouncing on a floor at steps of many bounces (the eighth hunt's `hugedt`): core's
// impacts are exact events, so the state at every step's end is the closed form's whatever
// the step. Before this test core's rest speed |a_n| dt / 16 settled an elastic (e = 1)
// bounce whose impact speed was below it (a step longer than 16 falls): an error, since an
// elastic bounce never collapses (its flights do not shorten).
#include <gtest/gtest.h>

#include <cmath>
#include <sstream>

#include "scene_fixture.hpp"

namespace physval::test {
namespace {

constexpr double kG = 9.81;

// The closed form of a ball dropped from rest at height h above a floor (its lowest point),
// restitution e <= 1: height above the contact and vertical velocity at time t.
std::pair<double, double> bounce(double h, double e, double t) {
  const double tf = std::sqrt(2.0 * h / kG);
  if (t <= tf) return {h - 0.5 * kG * t * t, -kG * t};
  if (e == 1.0) {   // periodic, period 2 tf, the first impact at tf
    const double s = std::fmod(t - tf, 2.0 * tf);   // time since the last impact
    const double v = kG * tf;
    return {v * s - 0.5 * kG * s * s, v - kG * s};
  }
  double t0 = tf, v = e * kG * tf;   // leaves the floor at t0 with speed v
  for (int k = 0; k < 10000 && v > 0.0; ++k) {
    const double flight = 2.0 * v / kG;
    if (t <= t0 + flight) {
      const double s = t - t0;
      return {v * s - 0.5 * kG * s * s, v - kG * s};
    }
    t0 += flight;
    v *= e;
  }
  return {0.0, 0.0};   // at rest after the Zeno limit tf (1 + e) / (1 - e)
}

struct Off {
  double dy, dv;
};

// Runs `steps` steps of dt falls and returns the largest miss of the closed form at a step's end.
Off run(double h, double e, double falls, int steps) {
  const double r = 0.1;
  const double tf = std::sqrt(2.0 * h / kG);
  const double dt = falls * tf;
  Sim sim(scene_of({circle("b", {0.0, h + r}, {}, r, 1.0, e)}, {wall("floor", {-1.0, 0.0}, {1.0, 0.0}, e)}, {0.0, -kG}));
  Off worst{0.0, 0.0};
  for (int k = 1; k <= steps; ++k) {
    sim.step(dt);
    const BodyState b = sim.state("b");
    const auto [y, vy] = bounce(h, e, k * dt);
    worst.dy = std::max(worst.dy, std::fabs(b.position.y - r - y));
    // A step that ends at an impact (an odd number of falls) may end just before or just
    // after it: there only the speed is the closed form's.
    const double phase = std::fmod(k * falls, 2.0);
    const bool at_impact = e == 1.0 && std::fabs(phase - 1.0) < 1e-9 * (1.0 + k * falls);
    worst.dv = std::max(worst.dv, at_impact ? std::fabs(std::fabs(b.velocity.y) - std::fabs(vy))
                                            : std::fabs(b.velocity.y - vy));
  }
  return worst;
}

// e = 1 at steps of 0.3 to 400 falls (the reference's dt/8 and dt/4 of the hunt's 150-400):
// and steps that end exactly at an impact (17, 151 falls; 18.75 x 4 = 37.5 x 2 = 75 falls).
// the periodic closed form at every step's end. The tolerance is the round-off of a time of
// ~k dt in the phase (k dt / tf bounces, each exact to round-off of its own time).
TEST(CoreHugeDt, AnElasticBounceStaysPeriodicAtAnyStep) {
  for (double h : {0.01, 0.1, 1.0}) {
    for (double falls : {0.3, 1.0, 7.0, 17.0, 18.7, 18.75, 30.0, 37.3, 37.5, 100.0, 150.0, 151.0, 400.0}) {
      const int steps = 5;
      const Off o = run(h, 1.0, falls, steps);
      const double bounces = steps * falls;
      const double v = std::sqrt(2.0 * kG * h);
      std::ostringstream d;
      d << "h " << h << " dt " << falls << " falls";
      EXPECT_LE(o.dy, 1e-9 * h * (1.0 + bounces)) << d.str();
      EXPECT_LE(o.dv, 1e-9 * v * (1.0 + bounces)) << d.str();
    }
  }
}

// e < 1: the bounce's Zeno sequence ends at the closed-form time tf (1 + e) / (1 - e); a step
// beyond that time ends with the ball at rest on the floor, one before it with the ball in
// the closed form's bounce.
TEST(CoreHugeDt, AnInelasticBounceMeetsItsClosedFormAtAnyStep) {
  for (double h : {0.01, 0.1}) {
    for (double e : {0.3, 0.5}) {
      for (double falls : {0.3, 1.1, 30.0, 150.0, 400.0}) {
        const Off o = run(h, e, falls, 5);
        std::ostringstream d;
        d << "h " << h << " e " << e << " dt " << falls << " falls";
        EXPECT_LE(o.dy, 1e-9 * h) << d.str();
        EXPECT_LE(o.dv, 1e-9 * std::sqrt(2.0 * kG * h)) << d.str();
      }
    }
  }
}

}  // namespace
}  // namespace physval::test
