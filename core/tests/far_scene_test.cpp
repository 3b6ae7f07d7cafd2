// The fifteenth hunt: core's round-off tolerances are 1e-9 of the scene's extent from the
// origin, so a scene drawn far from the origin, or one that also holds something far away,
// had tolerances of millimetres to metres. A 5 mm marble 4 mm above a floor at (5e5, 5e6) m
// was held as resting for the whole run; a ball in a 2 m box beside a body parked at 1e11 m
// hovered 1.45 m above the floor. The reference converged to the hover each time, so core
// was `ok`. Now a scene far from the origin next to its size runs in coordinates from its
// centre (the same physics to round-off), and one whose extent core cannot resolve is
// refused at load, saying why.
#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>
#include <string>

#include "scene_fixture.hpp"

namespace physval::test {

namespace {

constexpr double g = 9.8;

// A marble of radius r released `gap` above a floor 2 m long, the whole scene moved to
// `at`; the floor's restitution e.
Scene marble(Vec2 at, double r, double gap, double e) {
  Scene s = scene_of({circle("marble", {at.x, at.y + r + gap}, {0.2, 0.0}, r, 1.0, e)},
                     {wall("floor", {at.x - 1.0, at.y}, {at.x + 1.0, at.y}, e)}, {0.0, -g});
  return s;
}

}  // namespace

// The marble falls and bounces as it would at the origin, wherever the scene is drawn: its
// first two impacts at the free fall's closed form (from the gap the doubles hold: the
// subtraction of two nearby doubles is exact), at offsets from 0 to 1e7 m in x and y, gaps
// of 0.2 to 4 mm, e 0.5 and 1.
TEST(CoreFarScene, AMarbleFarFromTheOriginFallsAndBouncesAsAtTheOrigin) {
  for (double off : {0.0, 1e3, 1e5, 1e6, 5e6, 1e7}) {
    for (Vec2 dir : {Vec2{1.0, 0.0}, Vec2{0.0, 1.0}, Vec2{0.1, 1.0}, Vec2{-1.0, -1.0}}) {
      for (double gap : {2e-4, 1e-3, 4e-3}) {
        for (double e : {0.5, 1.0}) {
          const double r = 0.005;
          const Vec2 at = dir * off;
          const Scene s = marble(at, r, gap, e);
          SCOPED_TRACE("offset " + std::to_string(off) + " dir (" + std::to_string(dir.x) + ", " + std::to_string(dir.y) +
                       ") gap " + std::to_string(gap) + " e " + std::to_string(e));
          // The gap as the doubles hold it (ball centre minus floor, both near at.y).
          const double held = (s.bodies[0].position.y - s.walls[0].from.y) - r;
          const double t1 = std::sqrt(2.0 * held / g);
          const double t2 = t1 + 2.0 * e * g * t1 / g;
          Sim sim(s);
          sim.run_until(std::min(t2 * 1.5, 0.2), 1.0 / 240.0);
          ASSERT_GE(sim.contacts.size(), 2u);
          // Round-off of a position at the offset (ulp 1e-9 m at 5e6 m) over a fall speed of
          // at least 0.06 m/s: 1e-7 s covers it.
          const double dt_tol = 1e-7;
          EXPECT_NEAR(sim.contacts[0].time, t1, dt_tol);
          EXPECT_NEAR(sim.contacts[1].time, t2, dt_tol);
          // In the air before the first impact: never held above the floor.
          const BodyState b = sim.state(0);
          EXPECT_GT(b.position.y - at.y, r - 1e-6);
        }
      }
    }
  }
}

// The other end of the scale: a marble of radius 1e-7 to 1e-2 m released 0.5% of its
// radius above a floor (0.5 nm for the smallest). The tolerance was 1e-9 of the extent but
// never below 1e-9 m, so below a metre it stopped shrinking with the scene: the 0.1 um
// marble was taken as touching at t = 0 and held in the air. Now it is 1e-9 of the extent
// at every scale: the first two impacts at the closed form to 1e-6 of the first's time.
TEST(CoreFarScene, ASmallMarbleFallsAsALargeOneDoes) {
  for (double r : {1e-7, 1e-6, 1e-4, 1e-2}) {
    for (double e : {0.5, 1.0}) {
      SCOPED_TRACE("r " + std::to_string(r) + " e " + std::to_string(e));
      const double gap = 0.005 * r;
      Scene s = scene_of({circle("marble", {0.0, r + gap}, {}, r, 1.0, e)},
                         {wall("floor", {-100.0 * r, 0.0}, {100.0 * r, 0.0}, e)}, {0.0, -g});
      const double held = (r + gap) - r;
      const double t1 = std::sqrt(2.0 * held / g);
      const double t2 = t1 + 2.0 * e * t1;
      Sim sim(s);
      sim.run_until(1.5 * t2, t2 / 16.0);
      ASSERT_GE(sim.contacts.size(), 2u);
      EXPECT_NEAR(sim.contacts[0].time, t1, 1e-6 * t1);
      EXPECT_NEAR(sim.contacts[1].time, t2, 1e-6 * t1);
    }
  }
}

// The same bounces give the same states at the origin and at (5e6, -3e6) m, up to the
// round-off of positions there.
TEST(CoreFarScene, ASceneMovedFarAwayGivesTheSameStatesMovedAlong) {
  const Vec2 far{5e6, -3e6};
  Sim near(marble({}, 0.05, 0.3, 0.7));
  Sim away(marble(far, 0.05, 0.3, 0.7));
  for (int k = 0; k < 120; ++k) {
    near.step(1.0 / 60.0);
    away.step(1.0 / 60.0);
    const BodyState a = near.state(0), b = away.state(0);
    ASSERT_NEAR(b.position.x - far.x, a.position.x, 1e-8) << "step " << k;
    ASSERT_NEAR(b.position.y - far.y, a.position.y, 1e-8) << "step " << k;
    ASSERT_NEAR(b.velocity.x, a.velocity.x, 1e-8) << "step " << k;
    ASSERT_NEAR(b.velocity.y, a.velocity.y, 1e-8) << "step " << k;
  }
  EXPECT_EQ(near.contacts.size(), away.contacts.size());
}

// A ball in a 2 m box beside something far away (a static body, a free one, a wall): core
// resolves it while its tolerance (1e-9 of the extent) is within 1e-3 of the ball's radius,
// and runs it to the closed form (the first impact with the floor); past that it refuses at
// load, naming the extent and the ball, instead of holding the ball in the air.
TEST(CoreFarScene, ASceneSpanningMoreThanCoreResolvesIsRefusedAtLoad) {
  const double r = 0.05;
  for (double far : {1e3, 1e4, 4e4, 6e4, 1e6, 1e9, 1e11}) {
    for (int kind = 0; kind < 3; ++kind) {
      SCOPED_TRACE("far " + std::to_string(far) + " kind " + std::to_string(kind));
      Scene s = scene_of({circle("ball", {0.0, 0.5}, {}, r, 1.0, 0.5)},
                         {wall("floor", {-1.0, -1.0}, {1.0, -1.0}, 0.5), wall("l", {-1.0, 1.0}, {-1.0, -1.0}, 0.5),
                          wall("r", {1.0, -1.0}, {1.0, 1.0}, 0.5)},
                         {0.0, -g});
      if (kind == 0) {
        BodyDef parked = circle("parked", {far, 0.0}, {}, 1.0);
        parked.is_static = true;
        s.bodies.push_back(parked);
      } else if (kind == 1) {
        s.bodies.push_back(circle("drifter", {0.0, far}, {}, 1.0));
      } else {
        s.walls.push_back(wall("far_wall", {far, -1.0}, {far, 1.0}));
      }
      const bool resolvable = 1e-9 * (far + 1.0) <= 1e-3 * r;
      if (!resolvable) {
        try {
          CoreEngine e;
          e.load(s);
          ADD_FAILURE() << "loaded a scene it cannot resolve";
        } catch (const std::invalid_argument& x) {
          const std::string m = x.what();
          EXPECT_NE(m.find("core cannot resolve this scene"), std::string::npos) << m;
          EXPECT_NE(m.find("'ball'"), std::string::npos) << m;
        }
        continue;
      }
      Sim sim(s);
      sim.run_until(0.6, 1.0 / 60.0);
      ASSERT_FALSE(sim.contacts.empty());
      EXPECT_NEAR(sim.contacts[0].time, std::sqrt(2.0 * (1.5 - r) / g), 1e-9);
    }
  }
}

}  // namespace physval::test
