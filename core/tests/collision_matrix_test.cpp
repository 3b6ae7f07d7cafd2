// The collision matrix: per pair of groups, bounce (default), destroy one or both,
// ignore (pass through silently), or event only (pass through, one event).
#include <gtest/gtest.h>

#include "scene_fixture.hpp"

namespace physval::test {

namespace {
// A ball (group "ball") at 2 m/s towards a brick (group "brick") 4 m away, R = 1.
Scene ball_and_brick(CollisionResponse rule) {
  BodyDef ball = circle("ball", {-2.0, 0.0}, {2.0, 0.0});
  ball.group = "ball";
  BodyDef brick = circle("brick", {2.0, 0.0});
  brick.group = "brick";
  Scene s = scene_of({ball, brick});
  s.collision_matrix.push_back({"ball", "brick", rule});
  return s;
}
struct Outcome {
  BodyState ball, brick;
  std::vector<ContactEvent> contacts;
};
Outcome run(CollisionResponse rule, const char* mode = "exact") {
  Sim sim(ball_and_brick(rule), options("velocity_verlet", mode));
  sim.run_until(3.0, 1.0 / 60.0);
  return {sim.state("ball"), sim.state("brick"), sim.contacts};
}
}  // namespace

TEST(CoreCollisionMatrix, Bounce) {
  const Outcome o = run(CollisionResponse::Bounce);
  EXPECT_NEAR(o.ball.velocity.x, 0.0, 1e-12);   // equal masses swap
  EXPECT_NEAR(o.brick.velocity.x, 2.0, 1e-12);
  EXPECT_TRUE(o.ball.alive && o.brick.alive);
  ASSERT_EQ(o.contacts.size(), 1u);
  EXPECT_NEAR(o.contacts[0].time, 1.5, 1e-12);   // gap 3 m closing at 2 m/s
}

TEST(CoreCollisionMatrix, DestroyOneOrBoth) {
  for (const char* mode : {"exact", "lecture"}) {
    SCOPED_TRACE(mode);
    const Outcome b = run(CollisionResponse::DestroyB, mode);   // rule {ball, brick}: the brick goes
    EXPECT_TRUE(b.ball.alive);
    EXPECT_FALSE(b.brick.alive);
    EXPECT_NEAR(b.ball.velocity.x, 0.0, 1e-12);   // it bounced before it was destroyed
    EXPECT_EQ(b.contacts.size(), 1u);
    const Outcome a = run(CollisionResponse::DestroyA, mode);
    EXPECT_FALSE(a.ball.alive);
    EXPECT_TRUE(a.brick.alive);
    const Outcome both = run(CollisionResponse::DestroyBoth, mode);
    EXPECT_FALSE(both.ball.alive);
    EXPECT_FALSE(both.brick.alive);
  }
}

TEST(CoreCollisionMatrix, IgnorePassesThroughSilently) {
  const Outcome o = run(CollisionResponse::Ignore);
  EXPECT_NEAR(o.ball.velocity.x, 2.0, 1e-12);
  EXPECT_NEAR(o.ball.position.x, -2.0 + 6.0, 1e-12);
  EXPECT_TRUE(o.contacts.empty());
}

TEST(CoreCollisionMatrix, EventOnlyReportsOnceAndPassesThrough) {
  for (const char* mode : {"exact", "lecture"}) {
    SCOPED_TRACE(mode);
    const Outcome o = run(CollisionResponse::Event, mode);
    EXPECT_NEAR(o.ball.velocity.x, 2.0, 1e-12);
    EXPECT_EQ(o.brick.velocity.x, 0.0);
    ASSERT_EQ(o.contacts.size(), 1u);   // once on entering, not every step of overlap
  }
  const Outcome exact = run(CollisionResponse::Event);
  EXPECT_NEAR(exact.contacts[0].time, 1.5, 1e-12);
}

TEST(CoreCollisionMatrix, WallGroups) {
  // A goal line (a wall in group "goal") raises an event and lets the ball through;
  // the back wall bounces it.
  BodyDef ball = circle("ball", {0.0, 0.0}, {5.0, 0.0}, 0.25);
  ball.group = "ball";
  WallDef goal = wall("goal", {2.0, -1.0}, {2.0, 1.0});
  goal.material.group = "goal";
  Scene s = scene_of({ball}, {goal, wall("back", {4.0, -1.0}, {4.0, 1.0})});
  s.collision_matrix.push_back({"ball", "goal", CollisionResponse::Event});
  Sim sim(s);
  sim.run_until(1.0, 1.0 / 60.0);
  ASSERT_GE(sim.contacts.size(), 2u);
  EXPECT_EQ(sim.contacts[0].b.kind, ObjectRef::Kind::Wall);
  EXPECT_EQ(sim.contacts[0].b.index, 0u);
  EXPECT_NEAR(sim.contacts[0].time, (2.0 - 0.25) / 5.0, 1e-12);
  EXPECT_EQ(sim.contacts[1].b.index, 1u);
  EXPECT_NEAR(sim.contacts[1].time, (4.0 - 0.25) / 5.0, 1e-12);
  EXPECT_NEAR(sim.state("ball").velocity.x, -5.0, 1e-12);
}

}  // namespace physval::test
