// Impacts against closed forms: the lecture's head-on formula (with its typo caught),
// equal masses, oblique impacts, extreme mass ratios, tunnelling, Newton's cradle.
#include <gtest/gtest.h>

#include <cmath>

#include "scene_fixture.hpp"

namespace physval::test {

TEST(CoreCollision, HeadOnElasticOneToThree) {
  // m1 = 1 at v = +2, m2 = 3 at v = -1: v1' = -2.5, v2' = +0.5. The lecture's slide
  // prints v2' with (m1 - m2), which would give +1.5 and break momentum conservation.
  for (const char* mode : {"exact", "lecture"}) {
    SCOPED_TRACE(mode);
    Sim sim(scene_of({circle("a", {-2.0, 0.0}, {2.0, 0.0}, 0.5, 1.0), circle("b", {2.0, 0.0}, {-1.0, 0.0}, 0.5, 3.0)}),
            options("velocity_verlet", mode));
    sim.run_until(2.0, 1.0 / 60.0);
    EXPECT_NEAR(sim.state("a").velocity.x, -2.5, 1e-12);
    EXPECT_NEAR(sim.state("b").velocity.x, 0.5, 1e-12);
    ASSERT_EQ(sim.contacts.size(), 1u);
    // Gap 3 m closing at 3 m/s: t = 1. Exact mode finds it to round-off; the lecture's
    // interpolation is exact here too (straight lines, head-on).
    EXPECT_NEAR(sim.contacts[0].time, 1.0, 1e-12);
    EXPECT_EQ(sim.contacts[0].a.index, 0u);
    EXPECT_EQ(sim.contacts[0].b.index, 1u);
    // And the positions continue from the impact point: a met b at x = 0, then -2.5 m/s.
    EXPECT_NEAR(sim.state("a").position.x, 0.0 - 2.5 * 1.0, 1e-12);
  }
}

TEST(CoreCollision, EqualMassesSwapVelocities) {
  Sim sim(scene_of({circle("a", {-2.0, 0.0}, {3.0, 0.0}), circle("b", {2.0, 0.0}, {-1.0, 0.0})}));
  sim.run_until(2.0, 0.01);
  EXPECT_NEAR(sim.state("a").velocity.x, -1.0, 1e-12);
  EXPECT_NEAR(sim.state("b").velocity.x, 3.0, 1e-12);
}

TEST(CoreCollision, ObliqueKeepsTangentialVelocity) {
  // a moves along x with its centre 0.5 above b's (R = 1): at contact the normal is
  // (sqrt(0.75), -0.5). Only the normal component changes; equal masses exchange it.
  const Vec2 v{2.0, 0.0};
  Sim sim(scene_of({circle("a", {-3.0, 0.5}, v), circle("b", {0.0, 0.0})}));
  sim.run_until(2.0, 0.01);
  const Vec2 n{std::sqrt(0.75), -0.5};
  const Vec2 t = perp(n);
  const BodyState a = sim.state("a"), b = sim.state("b");
  EXPECT_NEAR(dot(a.velocity, t), dot(v, t), 1e-12);
  EXPECT_NEAR(dot(a.velocity, n), 0.0, 1e-12);
  EXPECT_NEAR(b.velocity.x, dot(v, n) * n.x, 1e-12);
  EXPECT_NEAR(b.velocity.y, dot(v, n) * n.y, 1e-12);
  // Energy is conserved (e = 1).
  EXPECT_NEAR(length_squared(a.velocity) + length_squared(b.velocity), length_squared(v), 1e-12);
}

TEST(CoreCollision, MassRatioMillionConservesMomentum) {
  const double M = 1e6, m = 1.0;
  Sim sim(scene_of({circle("heavy", {-2.0, 0.0}, {1.0, 0.0}, 0.5, M), circle("light", {2.0, 0.0}, {-1.0, 0.0}, 0.5, m)}));
  const double p0 = M * 1.0 + m * -1.0;
  sim.run_until(3.0, 0.01);
  const double vh = sim.state("heavy").velocity.x, vl = sim.state("light").velocity.x;
  // Round-off: each velocity carries a relative error of a few ulps; momentum is the
  // sum of two terms of size 1e6, so a few ulps of 1e6.
  EXPECT_NEAR(M * vh + m * vl, p0, 8.0 * 2.2e-16 * M);
  EXPECT_NEAR(vh, (2.0 * m * -1.0 + 1.0 * (M - m)) / (M + m), 1e-15 * 4.0);
  EXPECT_NEAR(vl, (2.0 * M * 1.0 + -1.0 * (m - M)) / (M + m), 1e-15 * 8.0);
}

TEST(CoreCollision, StaticBodyReflects) {
  Sim sim(scene_of({circle("ball", {-3.0, 0.0}, {2.0, 1.0}), static_circle("post", {0.0, 0.0}, 0.5)}));
  sim.run_until(1.25, 0.01);   // head-on component: the centres at y = 0.5t...
  sim.run_until(4.0, 0.01);
  const BodyState b = sim.state("ball");
  EXPECT_NEAR(length(b.velocity), std::sqrt(5.0), 1e-12);   // infinite mass: speed kept
  EXPECT_EQ(sim.state("post").velocity.x, 0.0);
  EXPECT_EQ(sim.state("post").position.x, 0.0);
}

TEST(CoreCollision, NoTunnellingAt1e4MetresPerSecond) {
  // 166 m per step against a zero-thickness wall: exact mode reflects at t = 0.009995.
  const double v = 1e4, r = 0.05;
  Sim sim(scene_of({circle("bullet", {-100.0, 0.0}, {v, 0.0}, r)}, {wall("plate", {0.0, -1.0}, {0.0, 1.0})}));
  sim.steps(3, 1.0 / 60.0);
  ASSERT_EQ(sim.contacts.size(), 1u);
  const double t_hit = (100.0 - r) / v;
  EXPECT_NEAR(sim.contacts[0].time, t_hit, 1e-15 * 100.0);
  EXPECT_NEAR(sim.state("bullet").position.x, -r - v * (3.0 / 60.0 - t_hit), 1e-9);
  EXPECT_EQ(sim.state("bullet").velocity.x, -v);
}

TEST(CoreCollision, LectureModeTunnelsWhereExactDoesNot) {
  // A small fast ball and a post: in one step the ball jumps from one side of the post
  // to the other, so the end-of-step overlap test never sees it.
  Scene s = scene_of({circle("bullet", {-2.0, 0.0}, {240.0, 0.0}, 0.05), static_circle("post", {0.0, 0.0}, 0.5)});
  Sim lecture(s, options("velocity_verlet", "lecture"));
  Sim exact(s, options("velocity_verlet", "exact"));
  lecture.steps(2, 1.0 / 60.0);
  exact.steps(2, 1.0 / 60.0);
  EXPECT_GT(lecture.state("bullet").position.x, 0.0);   // passed through
  EXPECT_TRUE(lecture.contacts.empty());
  EXPECT_LT(exact.state("bullet").position.x, 0.0);     // bounced back
  ASSERT_EQ(exact.contacts.size(), 1u);
  EXPECT_NEAR(exact.contacts[0].time, (2.0 - 0.55) / 240.0, 1e-15);
}

TEST(CoreCollision, NewtonsCradlePassesMomentumThrough) {
  // Ball 0 at 1 m/s meets four touching balls at t = 1: four impacts at the same
  // instant, resolved in turn; the last ball leaves at 1 m/s, the others stop.
  std::vector<BodyDef> balls = {circle("b0", {-2.0, 0.0}, {1.0, 0.0})};
  for (int k = 1; k <= 4; ++k) balls.push_back(circle("b" + std::to_string(k), {static_cast<double>(k - 1), 0.0}));
  Sim sim(scene_of(balls));
  sim.run_until(2.0, 1.0 / 60.0);
  for (int k = 0; k < 4; ++k) EXPECT_NEAR(sim.state(static_cast<std::size_t>(k)).velocity.x, 0.0, 1e-12) << k;
  EXPECT_NEAR(sim.state(4).velocity.x, 1.0, 1e-12);
  EXPECT_NEAR(sim.state(4).position.x, 3.0 + 1.0, 1e-12);
  ASSERT_EQ(sim.contacts.size(), 4u);
  for (const ContactEvent& c : sim.contacts) EXPECT_NEAR(c.time, 1.0, 1e-12);
  EXPECT_TRUE(sim.engine.limits_hit().empty());
}

TEST(CoreCollision, EventCapFinishesWithLecturePass) {
  // Cap at 2 events: the cradle needs 4 at one instant. The step finishes with the
  // lecture pass instead of stalling, and the run says so.
  std::vector<BodyDef> balls = {circle("b0", {-2.0, 0.0}, {1.0, 0.0})};
  for (int k = 1; k <= 4; ++k) balls.push_back(circle("b" + std::to_string(k), {static_cast<double>(k - 1), 0.0}));
  EngineOptions opt = options("velocity_verlet");
  opt["max_events_per_step"] = std::int64_t{2};
  Sim sim(scene_of(balls), opt);
  sim.run_until(3.0, 1.0 / 60.0);
  EXPECT_FALSE(sim.engine.limits_hit().empty());
  double ke = 0.0, p = 0.0;
  for (std::size_t k = 0; k < 5; ++k) {
    ke += 0.5 * length_squared(sim.state(k).velocity);
    p += sim.state(k).velocity.x;
  }
  EXPECT_LE(ke, 0.5 + 1e-12);    // no energy gained
  EXPECT_NEAR(p, 1.0, 1e-12);    // momentum kept
}

}  // namespace physval::test

namespace physval::test {

// Galperin's billiard: a light ball between a wall and a ball M/m = 100^k heavier bounces
// exactly as many times as pi's first k+1 digits (e = 1). At 1e8 that is 31,415 impacts,
// thousands of them inside single steps near the turning point.
TEST(CoreCollision, PiBilliardMassRatio1e8FinishesExactlyUnderTheDefaultCap) {
  const double M = 1e8;
  Sim sim(scene_of({circle("light", {1.0, 0.0}, {}, 0.1, 1.0), circle("heavy", {2.0, 0.0}, {-1.0, 0.0}, 0.1, M)},
                   {wall("wall", {0.0, -1.0}, {0.0, 1.0})}));
  std::int64_t impacts = 0, most_in_a_step = 0;
  while (sim.engine.time() < 3.0 - 1e-12) {
    sim.step(0.01);
    ASSERT_EQ(sim.engine.broken_guarantee(), "") << "t = " << sim.engine.time();
    impacts += sim.engine.last_step_stats().impacts;
    most_in_a_step = std::max(most_in_a_step, sim.engine.last_step_stats().impacts);
  }
  EXPECT_EQ(impacts, 31415);
  EXPECT_GT(most_in_a_step, 1000);     // the old default cap (1000 + 100 N) broke here
  EXPECT_TRUE(sim.engine.limits_hit().empty());
  // Energy (round-off over 31,415 impacts: 1.9e-12 relative measured) and the final
  // order: the heavy ball leaves faster than the light one follows.
  const BodyState l = sim.state("light"), h = sim.state("heavy");
  EXPECT_NEAR((0.5 * l.velocity.x * l.velocity.x + 0.5 * M * h.velocity.x * h.velocity.x) / (0.5 * M), 1.0, 1e-11);
  EXPECT_GT(h.velocity.x, 0.0);
  EXPECT_LE(l.velocity.x, h.velocity.x);
  EXPECT_LT(l.position.x, h.position.x);   // no pass-through
}

TEST(CoreCollision, EventCapReachedIsABrokenGuarantee) {
  // The same billiard with a cap of 500 events: the step that reaches it says so, and a
  // step that does not leaves broken_guarantee() empty again.
  EngineOptions opt = options("velocity_verlet");
  opt["max_events_per_step"] = std::int64_t{500};
  Sim sim(scene_of({circle("light", {1.0, 0.0}, {}, 0.1, 1.0), circle("heavy", {2.0, 0.0}, {-1.0, 0.0}, 0.1, 1e8)},
                   {wall("wall", {0.0, -1.0}, {0.0, 1.0})}),
          opt);
  sim.step(0.01);
  EXPECT_EQ(sim.engine.broken_guarantee(), "");
  bool broke = false;
  while (!broke && sim.engine.time() < 3.0) {
    sim.step(0.01);
    broke = !sim.engine.broken_guarantee().empty();
  }
  ASSERT_TRUE(broke);
  EXPECT_NE(sim.engine.broken_guarantee().find("event cap"), std::string::npos);
  EXPECT_TRUE(sim.engine.last_step_stats().event_cap_hit);
}

}  // namespace physval::test

namespace physval::test {

TEST(CoreCollision, BodiesTouchingAtTheStart) {
  // Touching and closing at t = 0: the impact is at t = 0 exactly. Touching and
  // separating, or touching at rest: nothing happens, no contact.
  {
    Sim sim(scene_of({circle("a", {-0.5, 0.0}, {1.0, 0.0}), circle("b", {0.5, 0.0}, {-1.0, 0.0})}));
    sim.run_until(1.0, 0.01);
    ASSERT_EQ(sim.contacts.size(), 1u);
    EXPECT_EQ(sim.contacts[0].time, 0.0);
    EXPECT_NEAR(sim.state("a").velocity.x, -1.0, 1e-15);
    EXPECT_NEAR(sim.state("b").velocity.x, 1.0, 1e-15);
    EXPECT_NEAR(sim.state("a").position.x, -1.5, 1e-12);
  }
  {
    Sim sim(scene_of({circle("a", {-0.5, 0.0}, {-1.0, 0.0}), circle("b", {0.5, 0.0}, {1.0, 0.0})}));
    sim.run_until(1.0, 0.01);
    EXPECT_TRUE(sim.contacts.empty());
    EXPECT_EQ(sim.state("a").velocity.x, -1.0);
    EXPECT_EQ(sim.state("b").velocity.x, 1.0);
  }
  {
    Sim sim(scene_of({circle("a", {-0.5, 0.0}), circle("b", {0.5, 0.0}), circle("c", {1.5, 0.0})}));
    sim.run_until(1.0, 0.01);
    EXPECT_TRUE(sim.contacts.empty());
    for (std::size_t k = 0; k < 3; ++k) EXPECT_EQ(length_squared(sim.state(k).velocity), 0.0);
  }
}

}  // namespace physval::test

namespace physval::test {

TEST(CoreCollision, GalperinBilliardCountsAtEveryMassRatioUpTo1e10) {
  // A light ball between a wall and a heavy one (e = 1) collides N times in all, N the
  // largest n with n atan(sqrt(m / M)) < pi (Galperin): 314 at 1e4, 3,141 at 1e6,
  // 99,345 at 1e9, 314,159 at 1e10. Every impact must be resolved, under the default
  // event cap, whatever the step.
  for (double M : {1e4, 1e6, 1e9, 1e10}) {
    SCOPED_TRACE(M);
    const long double theta = std::atan(std::sqrt(1.0L / static_cast<long double>(M)));
    const auto expected = static_cast<std::int64_t>(std::ceil(std::acos(-1.0L) / theta)) - 1;
    Sim sim(scene_of({circle("light", {1.0, 0.0}, {}, 0.1, 1.0), circle("heavy", {2.0, 0.0}, {-1.0, 0.0}, 0.1, M)},
                     {wall("wall", {0.0, -1.0}, {0.0, 1.0})}));
    // Long enough for the last, slow return of the light ball from the wall.
    std::int64_t impacts = 0;
    while (sim.engine.time() < 200.0 - 1e-9) {
      sim.step(0.05);
      ASSERT_EQ(sim.engine.broken_guarantee(), "");
      impacts += sim.engine.last_step_stats().impacts;
    }
    EXPECT_EQ(impacts, expected);
    EXPECT_LT(sim.state("light").position.x, sim.state("heavy").position.x);
  }
}

}  // namespace physval::test
