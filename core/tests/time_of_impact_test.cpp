// Time of impact: the earliest closing root of a gap polynomial, against closed forms.
#include <gtest/gtest.h>

#include <cmath>

#include "physval/core/time_of_impact.hpp"

namespace physval::toi {

namespace {
const Tolerance kTol = squared_tolerance(10.0, 10.0, 1.0);
}

TEST(CoreTimeOfImpact, ConstantVelocityCircles) {
  // Centres 5 apart closing at 2 m/s, R = 1: touch at t = 2.
  EXPECT_NEAR(circle_circle({5.0, 0.0}, {-2.0, 0.0}, {}, 1.0, 10.0, kTol), 2.0, 1e-15);
  // Moving apart or missing: never.
  EXPECT_EQ(circle_circle({5.0, 0.0}, {2.0, 0.0}, {}, 1.0, 10.0, kTol), kNever);
  EXPECT_EQ(circle_circle({5.0, 3.0}, {-2.0, 0.0}, {}, 1.0, 10.0, kTol), kNever);
  // Beyond the step.
  EXPECT_EQ(circle_circle({5.0, 0.0}, {-2.0, 0.0}, {}, 1.0, 1.5, kTol), kNever);
  // Touching and closing now: 0; touching and separating: not an impact.
  EXPECT_EQ(circle_circle({1.0, 0.0}, {-1.0, 0.0}, {}, 1.0, 1.0, kTol), 0.0);
  EXPECT_EQ(circle_circle({1.0, 0.0}, {1.0, 0.0}, {}, 1.0, 1.0, kTol), kNever);
}

TEST(CoreTimeOfImpact, AcceleratingCirclesQuartic) {
  // Relative acceleration: d(s) = (4, 0) + (0, 0) s + 1/2 (-2, 0) s^2 -> |d| = 1 at
  // 4 - s^2 = 1, s = sqrt(3), via the degree-4 solver.
  EXPECT_NEAR(circle_circle({4.0, 0.0}, {}, {-2.0, 0.0}, 1.0, 5.0, kTol), std::sqrt(3.0), 1e-14);
  // A sideways offset: d = (4 - s^2, 0.5): touch when (4 - s^2)^2 = 0.75.
  EXPECT_NEAR(circle_circle({4.0, 0.5}, {}, {-2.0, 0.0}, 1.0, 5.0, kTol), std::sqrt(4.0 - std::sqrt(0.75)), 1e-14);
  // Closing while decelerating: d_y = 3 - 2 s + 0.4 s^2 = 1 first at (2 - sqrt(0.8)) / 0.8.
  EXPECT_NEAR(circle_circle({0.0, 3.0}, {0.0, -2.0}, {0.0, 0.8}, 1.0, 10.0, kTol), (2.0 - std::sqrt(0.8)) / 0.8, 1e-14);
  // Decelerating enough to turn back before touching: d_y = 3 - 2 s + 0.5 s^2 > 1 (grazes 1 at s = 2
  // only with 0.5; with 0.6 it stays above).
  EXPECT_EQ(circle_circle({0.0, 3.0}, {0.0, -2.0}, {0.0, 1.2}, 1.0, 10.0, kTol), kNever);
}

TEST(CoreTimeOfImpact, SegmentFacesAndCaps) {
  const double L = 1000.0;
  // Falling onto a floor: bottom 10 m above, g = 9.8: t = sqrt(20 / 9.8).
  SegmentHit h = circle_segment({0.0, 10.5}, {}, {0.0, -9.8}, 0.5, {-5.0, 0.0}, {5.0, 0.0}, 5.0, L);
  EXPECT_NEAR(h.s, std::sqrt(20.0 / 9.8), 1e-15);
  EXPECT_FALSE(h.cap);
  EXPECT_EQ(h.normal.y, 1.0);
  // From below: the other face.
  h = circle_segment({0.0, -2.0}, {0.0, 3.0}, {}, 0.5, {-5.0, 0.0}, {5.0, 0.0}, 5.0, L);
  EXPECT_NEAR(h.s, 0.5, 1e-15);
  EXPECT_EQ(h.normal.y, -1.0);
  // Past the end: the cap, at |p - end| = r.
  h = circle_segment({6.0, 3.0}, {0.0, -1.0}, {}, 0.5, {-5.0, 0.0}, {5.0, 0.0}, 5.0, L);
  EXPECT_EQ(h.s, kNever);   // passes 1 m beyond the end: closer than 0.5 never
  h = circle_segment({5.3, 3.0}, {0.0, -1.0}, {}, 0.5, {-5.0, 0.0}, {5.0, 0.0}, 5.0, L);
  EXPECT_TRUE(h.cap);
  EXPECT_NEAR(h.s, 3.0 - 0.4, 1e-14);   // 0.3^2 + 0.4^2 = 0.5^2
  EXPECT_NEAR(h.normal.x, 0.6, 1e-14);
  // A point particle through a zero-thickness wall at 1e4 m/s.
  h = circle_segment({-100.0, 0.0}, {1e4, 0.0}, {}, 0.0, {0.0, -1.0}, {0.0, 1.0}, 1.0 / 60.0, L);
  EXPECT_NEAR(h.s, 0.01, 1e-17);
}

TEST(CoreTimeOfImpact, PolynomialEntry) {
  // g = (s - 1)(s - 2)(s - 3)(s - 4) + 0: positive at 0, first falls through 0 at 1.
  Poly g;
  g.degree = 4;
  g.c[0] = 24.0;
  g.c[1] = -50.0;
  g.c[2] = 35.0;
  g.c[3] = -10.0;
  g.c[4] = 1.0;
  const Tolerance tol{1e-12, 1e-12};
  EXPECT_NEAR(earliest_entry(g, 10.0, tol), 1.0, 1e-14);
  // Starting inside (negative at 0, rising): the next fall, at 3.
  Poly shifted;   // g(s + 1.5): roots at -0.5, 0.5, 1.5, 2.5; negative at 0, rising
  shifted.degree = 4;
  const double a = 1.5;
  shifted.c[4] = 1.0;
  shifted.c[3] = 4.0 * a - 10.0;
  shifted.c[2] = 6.0 * a * a - 30.0 * a + 35.0;
  shifted.c[1] = 4.0 * a * a * a - 30.0 * a * a + 70.0 * a - 50.0;
  shifted.c[0] = g.eval(a);
  EXPECT_LT(shifted.c[0], 0.0);
  EXPECT_NEAR(earliest_entry(shifted, 10.0, tol), 1.5, 1e-13);
}


// A point exactly on a line (placed there with allow_initial_overlap) is on one side
// whatever its velocity: the side its acceleration presses it from. Before, it was the
// side it moved into: a point on a floor under gravity was on the floor at rest and
// under it moving down (it fell through), one spot read as two sides.
TEST(CoreTimeOfImpact, APointOnALineIsOnTheSideItsAccelerationPressesFrom) {
  const double L = 10.0;
  const Vec2 g{0.0, -9.81};
  for (double dir : {1.0, -1.0}) {   // the floor drawn left to right (normal up) or right to left (down)
    const Vec2 from{-5.0 * dir, 0.0}, to{5.0 * dir, 0.0};
    // Moving down into it: an impact now, against the upper face.
    SegmentHit h = circle_segment({0.0, 0.0}, {0.3, -1.0}, g, 0.0, from, to, 1.0 / 60.0, L);
    EXPECT_EQ(h.s, 0.0) << dir;
    EXPECT_EQ(h.normal.y, 1.0) << dir;
    // At rest, pressed by gravity: an impact now (it settles), upper face.
    h = circle_segment({0.0, 0.0}, {}, g, 0.0, from, to, 1.0 / 60.0, L);
    EXPECT_EQ(h.s, 0.0) << dir;
    EXPECT_EQ(h.normal.y, 1.0) << dir;
    // Moving up out of it: no impact (it leaves the floor upwards, and falls back onto it
    // at 2 v / g, beyond this step).
    h = circle_segment({0.0, 0.0}, {0.0, 1.0}, g, 0.0, from, to, 1.0 / 60.0, L);
    EXPECT_EQ(h.s, kNever) << dir;
    h = circle_segment({0.0, 0.0}, {0.0, 1.0}, g, 0.0, from, to, 1.0, L);
    EXPECT_NEAR(h.s, 2.0 / 9.81, 1e-15) << dir;
    EXPECT_EQ(h.normal.y, 1.0) << dir;
    // A ceiling: gravity up presses it from below.
    h = circle_segment({0.0, 0.0}, {0.0, 1.0}, -g, 0.0, from, to, 1.0 / 60.0, L);
    EXPECT_EQ(h.s, 0.0) << dir;
    EXPECT_EQ(h.normal.y, -1.0) << dir;
  }
  // The rule itself: off the line, the sign of D; on it, against the acceleration; without
  // one, the side it moves from; with neither, +1.
  EXPECT_EQ(line_side(1e-300, -1.0, 1.0), 1.0);
  EXPECT_EQ(line_side(-1e-300, 1.0, -1.0), -1.0);
  EXPECT_EQ(line_side(0.0, 1.0, -9.8), 1.0);
  EXPECT_EQ(line_side(0.0, -1.0, 9.8), -1.0);
  EXPECT_EQ(line_side(0.0, -1.0, 0.0), 1.0);
  EXPECT_EQ(line_side(0.0, 1.0, 0.0), -1.0);
  EXPECT_EQ(line_side(0.0, 0.0, 0.0), 1.0);
  // Explicit Euler's path has no acceleration within the step; the force still decides
  // the side (`press`): a point on a floor moving up leaves it, moving down meets it.
  EXPECT_EQ(circle_segment({0.0, 0.0}, {0.0, 1.0}, {}, 0.0, {-5.0, 0.0}, {5.0, 0.0}, 0.1, L, g).s, kNever);
  EXPECT_EQ(circle_segment({0.0, 0.0}, {0.0, -1.0}, {}, 0.0, {-5.0, 0.0}, {5.0, 0.0}, 0.1, L, g).normal.y, 1.0);
  // No acceleration, moving into the line: met now, from the side it comes from.
  const SegmentHit h = circle_segment({0.0, 0.0}, {0.0, -2.0}, {}, 0.0, {-5.0, 0.0}, {5.0, 0.0}, 0.1, L);
  EXPECT_EQ(h.s, 0.0);
  EXPECT_EQ(h.normal.y, 1.0);
}

}  // namespace physval::toi
