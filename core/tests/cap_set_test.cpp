// A body meeting two end points of barriers at one instant (the fourteenth hunt): a ball
// dropped square onto a drain narrower than it lands on both of the drain's ends at once.
// Newton's law at both together sends it straight back up; taken one at a time (before),
// the end listed first took the whole impact and the ball left 60 degrees off the vertical,
// to the side the walls' order gave, with a converged reference and every other engine
// right.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "scene_fixture.hpp"

namespace physval::test {
namespace {

constexpr double g = 9.8;

// Two floor pieces on y = 0 leaving a drain of width w around x = 0 (or, `posts`, two
// vertical posts whose tops are the drain's ends), the ball of radius r dropped from rest
// at height h above the drain's middle. `swapped` lists the walls the other way round,
// `mirrored` reflects the scene in x = 0.
Scene drain(double w, double r, double h, double e, double mu, bool posts, bool swapped, bool mirrored) {
  const double s = mirrored ? -1.0 : 1.0;
  std::vector<WallDef> walls;
  if (posts) {
    walls = {wall("pa", {s * -0.5 * w, -2.0}, {s * -0.5 * w, 0.0}, e, mu), wall("pb", {s * 0.5 * w, -2.0}, {s * 0.5 * w, 0.0}, e, mu)};
  } else {
    walls = {wall("pa", {s * -2.0, 0.0}, {s * -0.5 * w, 0.0}, e, mu), wall("pb", {s * 0.5 * w, 0.0}, {s * 2.0, 0.0}, e, mu)};
  }
  if (swapped) std::swap(walls[0], walls[1]);
  BodyDef b = circle("ball", {0.0, h}, {}, r, 1.0, e);
  b.friction = b.static_friction = mu;
  return scene_of({b}, walls, {0.0, -g});
}

// The ball's height and vertical velocity at time T: it falls onto the ends, at which its
// centre is c = sqrt(r^2 - (w/2)^2) above them, and bounces straight up with e times its speed.
void closed_form(double r, double w, double h, double e, double T, double& y, double& vy) {
  const double c = std::sqrt(r * r - 0.25 * w * w);
  double t = std::sqrt(2.0 * (h - c) / g), v = g * t;   // first landing
  y = c;
  if (T < t) {
    y = h - 0.5 * g * T * T;
    vy = -g * T;
    return;
  }
  for (;;) {
    v *= e;
    const double flight = 2.0 * v / g;
    if (v == 0.0 || T < t + flight) {
      const double dt = T - t;
      y = c + v * dt - 0.5 * g * dt * dt;
      vy = v - g * dt;
      if (v == 0.0) y = c, vy = 0.0;
      return;
    }
    t += flight;
  }
}

TEST(CoreCapSet, ABallDroppedOntoADrainNarrowerThanItBouncesStraightBack) {
  const double r = 0.125, h = 0.9, T = 1.0, dt = 1.0 / 64.0;
  for (const bool posts : {false, true}) {
    for (const double w : {0.05, 0.125, 0.2}) {
      for (const double e : {1.0, 0.5, 0.0}) {
        for (const double mu : {0.0, 0.5}) {
          for (const bool swapped : {false, true}) {
            for (const bool mirrored : {false, true}) {
              SCOPED_TRACE(std::string(posts ? "posts" : "floor pieces") + " w " + std::to_string(w) + " e " +
                           std::to_string(e) + " mu " + std::to_string(mu) + (swapped ? " swapped" : "") +
                           (mirrored ? " mirrored" : ""));
              Sim sim(drain(w, r, h, e, mu, posts, swapped, mirrored));
              sim.run_until(T, dt);
              ASSERT_EQ(sim.engine.broken_guarantee(), "");
              const BodyState st = sim.state("ball");
              EXPECT_NEAR(st.position.x, 0.0, 1e-12);
              EXPECT_NEAR(st.velocity.x, 0.0, 1e-12);
              double y, vy;
              closed_form(r, w, h, e, T, y, vy);
              EXPECT_NEAR(st.position.y, y, 1e-9);
              EXPECT_NEAR(st.velocity.y, vy, 1e-9);
            }
          }
        }
      }
    }
  }
}

}  // namespace
}  // namespace physval::test
