// Bouncing and resting against the floor under gravity: exact bounce times, energy
// never gained, a ball at rest stays at rest with a bounded number of events.
#include <gtest/gtest.h>

#include <cmath>

#include "scene_fixture.hpp"

namespace physval::test {

namespace {
constexpr double g = 9.8;
Scene ball_over_floor(double bottom_height, double e, Vec2 v = {}) {
  return scene_of({circle("ball", {0.0, bottom_height + 0.5}, v, 0.5, 1.0, e)},
                  {wall("floor", {-50.0, 0.0}, {50.0, 0.0}, e)}, {0.0, -g});
}
double energy(const BodyState& s) { return 0.5 * length_squared(s.velocity) + g * (s.position.y - 0.5); }
}  // namespace

TEST(CoreResting, BallAtRestStaysAtRest) {
  for (const char* integ : {"explicit_euler", "semi_implicit_euler", "velocity_verlet", "rk4"}) {
    for (double e : {1.0, 0.5, 0.0}) {
      SCOPED_TRACE(std::string(integ) + " e=" + std::to_string(e));
      Sim sim(ball_over_floor(0.0, e), options(integ));
      std::int64_t worst_events = 0;
      for (int k = 0; k < 600; ++k) {
        sim.step(1.0 / 60.0);
        worst_events = std::max(worst_events, sim.engine.last_step_stats().events);
        ASSERT_LE(energy(sim.state("ball")), 1e-9) << "step " << k;
      }
      EXPECT_NEAR(sim.state("ball").position.y, 0.5, 1e-9);
      EXPECT_NEAR(sim.state("ball").velocity.y, 0.0, 1e-9);
      EXPECT_LE(worst_events, 4);
      EXPECT_LE(sim.contacts.size(), 1u);   // one contact, not one per step
      EXPECT_TRUE(sim.engine.limits_hit().empty());
    }
  }
}

TEST(CoreResting, ElasticBounceKeepsItsHeight) {
  // e = 1, dropped from 2 m: every bounce returns to 2 m; Verlet's parabola is exact,
  // so the energy is conserved to round-off, bounce after bounce.
  Sim sim(ball_over_floor(2.0, 1.0));
  const double period = 2.0 * std::sqrt(2.0 * 2.0 / g);
  double top = 0.0;
  for (int k = 0; k < 1200; ++k) {
    sim.step(1.0 / 60.0);
    ASSERT_NEAR(energy(sim.state("ball")), 2.0 * g, 1e-9);
    if (sim.engine.time() > 15.0) top = std::max(top, sim.state("ball").position.y - 0.5);
  }
  EXPECT_NEAR(top, 2.0, 0.01);   // sampled at steps: within 1/60 s of the apex
  ASSERT_GE(sim.contacts.size(), 10u);
  for (std::size_t k = 0; k < sim.contacts.size(); ++k) {
    EXPECT_NEAR(sim.contacts[k].time, period * (static_cast<double>(k) + 0.5), 1e-9) << k;
  }
}

TEST(CoreResting, InelasticBouncesThenSettles) {
  // e = 0.5 from h = 1: impacts at t1 = sqrt(2h/g), then each flight 2 e^k v1 / g; the
  // series sums to t1 (1 + 2e / (1 - e)) = 3 t1, after which the ball rests.
  const double e = 0.5, h = 1.0, t1 = std::sqrt(2.0 * h / g), v1 = g * t1;
  Sim sim(ball_over_floor(h, e));
  sim.run_until(5.0, 1.0 / 60.0);
  ASSERT_GE(sim.contacts.size(), 3u);
  double t = t1;
  for (int k = 0; k < 3; ++k) {
    EXPECT_NEAR(sim.contacts[static_cast<std::size_t>(k)].time, t, 1e-9) << k;
    t += 2.0 * std::pow(e, k + 1) * v1 / g;
  }
  EXPECT_NEAR(sim.state("ball").position.y, 0.5, 1e-9);
  EXPECT_EQ(sim.state("ball").velocity.y, 0.0);
  for (const ContactEvent& c : sim.contacts) EXPECT_LT(c.time, 3.0 * t1 + 1e-9);
  EXPECT_TRUE(sim.engine.limits_hit().empty());
}

TEST(CoreResting, StackOfThreeRestsExactly) {
  // Three circles stacked on the floor, e = 0: they stay exactly where they are, with
  // one contact each and no events once settled.
  for (const char* integ : {"semi_implicit_euler", "velocity_verlet", "rk4"}) {
    SCOPED_TRACE(integ);
    Scene s = scene_of({circle("bottom", {0.0, 0.5}, {}, 0.5, 1.0, 0.0), circle("middle", {0.0, 1.5}, {}, 0.5, 1.0, 0.0),
                        circle("top", {0.0, 2.5}, {}, 0.5, 1.0, 0.0)},
                       {wall("floor", {-5.0, 0.0}, {5.0, 0.0}, 0.0)}, {0.0, -g});
    Sim sim(s, options(integ));
    sim.step(1.0 / 60.0);
    for (int k = 0; k < 300; ++k) {
      sim.step(1.0 / 60.0);
      ASSERT_EQ(sim.engine.last_step_stats().events, 0) << k;
    }
    for (std::size_t b = 0; b < 3; ++b) {
      EXPECT_NEAR(sim.state(b).position.y, 0.5 + static_cast<double>(b), 1e-12);
      EXPECT_EQ(length(sim.state(b).velocity), 0.0);
    }
    EXPECT_EQ(sim.contacts.size(), 3u);
  }
}

TEST(CoreResting, KnockedOutSupportDropsTheStack) {
  // A ball resting on another is left in the air when a third knocks the lower one
  // away: it must fall to the floor (e = 0, so it lands and stays).
  Scene s = scene_of({circle("bottom", {0.0, 0.5}, {}, 0.5, 1.0, 0.0), circle("top", {0.0, 1.5}, {}, 0.5, 1.0, 0.0),
                      circle("striker", {-5.0, 0.5}, {4.0, 0.0}, 0.5, 1.0, 1.0)},
                     {wall("floor", {-50.0, 0.0}, {50.0, 0.0}, 0.0)}, {0.0, -g});
  Sim sim(s);
  sim.run_until(0.5, 1.0 / 60.0);
  EXPECT_NEAR(sim.state("top").position.y, 1.5, 1e-12);   // still stacked before the hit (t = 1)
  sim.run_until(4.0, 1.0 / 60.0);
  EXPECT_NEAR(sim.state("top").position.y, 0.5, 1e-9);    // fell to the floor
  EXPECT_EQ(sim.state("top").velocity.y, 0.0);
  EXPECT_GT(sim.state("bottom").position.x, 1.0);         // knocked away
}

TEST(CoreResting, RollsOffTheEndAndFalls) {
  // A ball sliding on a frictionless ledge leaves it and falls; it does not hang on.
  Scene s = scene_of({circle("ball", {0.0, 5.5}, {2.0, 0.0})}, {wall("ledge", {-1.0, 5.0}, {1.0, 5.0})}, {0.0, -g});
  Sim sim(s);
  sim.run_until(2.0, 1.0 / 60.0);
  EXPECT_LT(sim.state("ball").position.y, 0.0);
  EXPECT_NEAR(sim.state("ball").velocity.x, 2.0, 1e-12);
}

}  // namespace physval::test

namespace physval::test {

TEST(CoreResting, TallStacksHoldExactly) {
  // Columns of 10 and 50 touching circles on a floor, e = 0, 0.5, 1: after 2 s each is
  // exactly where it started, one contact begins per touching pair, and no step comes
  // near the event cap (at most one event per body and step).
  for (int n : {10, 50}) {
    for (double e : {0.0, 0.5, 1.0}) {
      SCOPED_TRACE(std::to_string(n) + " bodies, e=" + std::to_string(e));
      std::vector<BodyDef> b;
      for (int k = 0; k < n; ++k) b.push_back(circle("b" + std::to_string(k), {0.0, 0.5 + k}, {}, 0.5, 1.0, e));
      Sim sim(scene_of(b, {wall("floor", {-10.0, 0.0}, {10.0, 0.0}, e)}, {0.0, -9.8}));
      std::int64_t worst = 0;
      for (int k = 0; k < 120; ++k) {
        sim.step(1.0 / 60.0);
        worst = std::max(worst, sim.engine.last_step_stats().events);
        ASSERT_EQ(sim.engine.broken_guarantee(), "");
      }
      EXPECT_LE(worst, n);
      EXPECT_EQ(sim.contacts.size(), static_cast<std::size_t>(n));
      for (int k = 0; k < n; ++k) {
        const BodyState st = sim.state(static_cast<std::size_t>(k));
        EXPECT_EQ(st.position.x, 0.0);
        EXPECT_EQ(st.position.y, 0.5 + k);
      }
    }
  }
}

// A point placed exactly on a floor (allow_initial_overlap) is on the floor whatever its
// velocity: the side gravity presses it from (toi::line_side). It used to be held there at
// rest but fall through moving down (the face tests took the side it moved into), y =
// -5.9 m after 1 s (validation/tests/hunt/point_on_floor_exact.toml). Every integrator,
// the floor drawn either way, gravity down (a floor) or up (a ceiling), e 0 to 1: it never
// crosses the line; at e = 0 moving down it stops on it at once; otherwise its first
// bounce reaches (e vn)^2 / 2g and a point moving up reaches vn^2 / 2g (Verlet, RK4 exact).
TEST(CoreResting, APointStartedExactlyOnAFloorNeverCrossesIt) {
  int cases = 0;
  for (const char* integ : {"explicit_euler", "semi_implicit_euler", "velocity_verlet", "rk4"}) {
    for (double dir : {1.0, -1.0}) {
      for (double up : {1.0, -1.0}) {   // +1: a floor (gravity down), -1: a ceiling
        for (double e : {0.0, 0.5, 1.0}) {
          for (Vec2 v : {Vec2{0.0, -1.0}, Vec2{0.7, -1.0}, Vec2{}, Vec2{0.0, 1.0}, Vec2{2.0, -3.0}, Vec2{-1.0, 0.0}}) {
            const Vec2 v0{v.x, up * v.y};
            SCOPED_TRACE(std::string(integ) + " dir " + std::to_string(dir) + " up " + std::to_string(up) + " e " +
                         std::to_string(e) + " v " + std::to_string(v.x) + "," + std::to_string(v.y));
            Scene sc = scene_of({point("p", {0.0, 0.0}, v0, 1.0, e)},
                                {wall("floor", {-50.0 * dir, 0.0}, {50.0 * dir, 0.0}, e)}, {0.0, -up * g});
            Sim sim(sc, options(integ));
            double apex = 0.0;
            for (int k = 0; k < 60; ++k) {
              sim.step(1.0 / 60.0);
              const double y = up * sim.state("p").position.y;
              ASSERT_GE(y, -1e-12) << "step " << k;   // never on the other side
              apex = std::max(apex, y);
              ASSERT_EQ(sim.engine.broken_guarantee(), "");
            }
            ++cases;
            const bool exact = std::string(integ) == "velocity_verlet" || std::string(integ) == "rk4";
            if (v.y < 0.0 && e == 0.0) {   // stops on the line at once and slides (frictionless)
              EXPECT_LE(apex, 1e-12);
              EXPECT_EQ(sim.state("p").velocity.y, 0.0);
              EXPECT_NEAR(sim.state("p").position.x, v.x, 1e-12);
            } else if (exact && v.y != 0.0) {
              const double vn = v.y < 0.0 ? -e * v.y : v.y;
              EXPECT_NEAR(apex, vn * vn / (2.0 * g), 1e-3 * vn * vn / (2.0 * g) + 2e-3 * vn) << "sampled per step";
            }
          }
        }
      }
    }
  }
  EXPECT_EQ(cases, 4 * 2 * 2 * 3 * 6);
}

}  // namespace physval::test
