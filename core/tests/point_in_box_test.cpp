// A point or a small ball at 5 to 5000 m/s in a box of four walls, e = 1 (the hunt's grid
// `box`): it never leaves, and its path is the closed form of the unfolded straight line,
// x(t) = fold(x0 + vx t) with fold the triangle wave of the box's half-width (minus the
// radius), each axis alone. Found: a point's side of a wall was read from the sign of its
// offset at impact, a round-off (a point at 5000 m/s met a wall 4.4e-15 m past it in a 4 m
// box and left through it); and at a corner (45 degrees) a point 4e-16 m past the other
// wall's line was outside it. Now a face's event carries the side it was found from, and a
// point within the round-off of a line is on the side it comes from.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <string>

#include "scene_fixture.hpp"

namespace physval::test {
namespace {

// The triangle wave: x on [-h, h], reflected at both ends.
double fold(double x, double h) {
  const double period = 4.0 * h;
  double u = std::fmod(x + h, period);
  if (u < 0.0) u += period;
  return u <= 2.0 * h ? u - h : 3.0 * h - u;
}
double fold_velocity(double x, double v, double h) {
  const double period = 4.0 * h;
  double u = std::fmod(x + h, period);
  if (u < 0.0) u += period;
  return u <= 2.0 * h ? v : -v;
}

TEST(CorePointInBox, NeverLeavesAndFollowsTheUnfoldedLine) {
  int judged = 0;
  for (double v : {5.0, 50.0, 200.0, 1000.0, 5000.0}) {
    for (double s : {0.3, 2.0, 20.0}) {
      for (double deg : {0.0, 17.0, 45.0}) {
        for (bool is_point : {true, false}) {
          const double r = is_point ? 0.0 : std::min(0.05, s / 10.0);
          const double a = deg * std::numbers::pi / 180.0;
          const Vec2 vel{v * std::cos(a), v * std::sin(a)};
          BodyDef b = is_point ? point("b", {0.0, 0.0}, vel) : circle("b", {0.0, 0.0}, vel, r);
          Sim sim(scene_of({b}, {wall("w1", {-s, -s}, {s, -s}), wall("w2", {s, -s}, {s, s}), wall("w3", {s, s}, {-s, s}),
                                 wall("w4", {-s, s}, {-s, -s})}));
          const std::string where = "v " + std::to_string(v) + " box " + std::to_string(s) + " deg " +
                                    std::to_string(deg) + (is_point ? " point" : " circle");
          const double h = s - r;
          double worst = 0.0, worst_out = 0.0;
          for (int k = 1; k <= 60; ++k) {
            sim.step(1.0 / 60.0);
            const BodyState st = sim.state("b");
            const double t = k / 60.0;
            worst_out = std::max({worst_out, std::fabs(st.position.x) - h, std::fabs(st.position.y) - h});
            // The unfolded line's round-off grows with the bounces (up to 16,000 here).
            worst = std::max({worst, std::fabs(st.position.x - fold(vel.x * t, h)),
                              std::fabs(st.position.y - fold(vel.y * t, h))});
            // The velocity, except at a wall at the step's end (before or after the bounce).
            if (std::fabs(fold(vel.x * t, h)) < h * (1.0 - 1e-9)) {
              EXPECT_NEAR(st.velocity.x, fold_velocity(vel.x * t, vel.x, h), 1e-9 * v) << where << " t " << t;
            }
            if (std::fabs(fold(vel.y * t, h)) < h * (1.0 - 1e-9)) {
              EXPECT_NEAR(st.velocity.y, fold_velocity(vel.y * t, vel.y, h), 1e-9 * v) << where << " t " << t;
            }
            EXPECT_NEAR(std::hypot(st.velocity.x, st.velocity.y), v, 1e-12 * v) << where;
          }
          EXPECT_LE(worst_out, 1e-9 * s) << where;
          EXPECT_LE(worst, 1e-7 * s) << where;
          ++judged;
        }
      }
    }
  }
  EXPECT_EQ(judged, 90);
}

}  // namespace
}  // namespace physval::test
