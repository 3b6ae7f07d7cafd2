// Chipmunk2D 7 behind physval: the adapter reproduces the raw library bit for bit (the
// same space built by hand, the material rule written out), imposes physval's rule where
// Chipmunk's own would differ, and publishes its settings.
#include <chipmunk/chipmunk.h>

#include <cmath>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "../adapter_test_scenes.hpp"

namespace physval::test {
namespace {

// Two balls (e 0.9 and 0.6, mu 0.3 and 0.5) dropped onto a 20 degree floor (e 0.8, mu 0.4)
// and onto each other.
Scene two_balls_on_a_slope() {
  Scene s = empty_scene("slope", 1.0 / 60.0, 3.0);
  s.world.gravity = {0.0, -9.81};
  BodyDef a = circle("a", 0.5, 1.0, {0.0, 3.0}, {0.5, 0.0}, 0.9);
  a.friction = a.static_friction = 0.3;
  BodyDef b = circle("b", 0.3, 2.0, {0.2, 5.0}, {0.0, -1.0}, 0.6);
  b.friction = b.static_friction = 0.5;
  s.bodies = {a, b};
  const double th = 20.0 * M_PI / 180.0;
  WallDef floor = wall("floor", {-10.0 * std::cos(th), 10.0 * std::sin(th)}, {10.0 * std::cos(th), -10.0 * std::sin(th)}, 0.8);
  floor.material.friction = floor.material.static_friction = 0.4;
  s.walls = {floor};
  return s;
}

// The same scene in raw Chipmunk: the calls the README's adapter table lists.
struct RawChipmunk {
  cpSpace* space = cpSpaceNew();
  std::vector<cpBody*> bodies;
  std::vector<cpShape*> shapes;
  static cpBool pre_solve(cpArbiter* arb, cpSpace*, cpDataPointer) {
    cpShape* x = nullptr;
    cpShape* y = nullptr;
    cpArbiterGetShapes(arb, &x, &y);
    // physval's rule: min(e1, e2), sqrt(f1 f2).
    cpArbiterSetRestitution(arb, std::min(cpShapeGetElasticity(x), cpShapeGetElasticity(y)));
    cpArbiterSetFriction(arb, std::sqrt(cpShapeGetFriction(x) * cpShapeGetFriction(y)));
    return cpTrue;
  }
  explicit RawChipmunk(const Scene& s, double slop) {
    cpSpaceSetGravity(space, cpv(s.world.gravity.x, s.world.gravity.y));
    cpSpaceSetCollisionSlop(space, slop);
    cpCollisionHandler* h = cpSpaceAddDefaultCollisionHandler(space);
    h->preSolveFunc = &pre_solve;
    for (const WallDef& w : s.walls) {
      cpShape* seg = cpSpaceAddShape(space, cpSegmentShapeNew(cpSpaceGetStaticBody(space), cpv(w.from.x, w.from.y),
                                                              cpv(w.to.x, w.to.y), 0.0));
      cpShapeSetElasticity(seg, w.material.restitution);
      cpShapeSetFriction(seg, w.material.friction);
      shapes.push_back(seg);
    }
    for (const BodyDef& b : s.bodies) {
      cpBody* body = cpSpaceAddBody(space, cpBodyNew(b.mass, INFINITY));
      cpBodySetPosition(body, cpv(b.position.x, b.position.y));
      cpBodySetVelocity(body, cpv(b.velocity.x, b.velocity.y));
      cpShape* c = cpSpaceAddShape(space, cpCircleShapeNew(body, b.radius, cpvzero));
      cpShapeSetElasticity(c, b.restitution);
      cpShapeSetFriction(c, b.friction);
      bodies.push_back(body);
      shapes.push_back(c);
    }
  }
  ~RawChipmunk() {
    for (cpShape* s : shapes) {
      cpSpaceRemoveShape(space, s);
      cpShapeFree(s);
    }
    for (cpBody* b : bodies) {
      cpSpaceRemoveBody(space, b);
      cpBodyFree(b);
    }
    cpSpaceFree(space);
  }
};

void expect_same_bits(const Scene& s, double slop, int min_contact_steps = 2) {
  auto e = make_engine("chipmunk", s);
  RawChipmunk raw(s, slop);
  int touching_steps = 0;
  for (int n = 0; n < s.steps(); ++n) {
    e->step(s.dt);
    cpSpaceStep(raw.space, s.dt);
    const auto st = states(*e);
    for (std::size_t i = 0; i < raw.bodies.size(); ++i) {
      const cpVect p = cpBodyGetPosition(raw.bodies[i]);
      const cpVect v = cpBodyGetVelocity(raw.bodies[i]);
      ASSERT_EQ(st[i].position.x, p.x) << "step " << n << " body " << i;
      ASSERT_EQ(st[i].position.y, p.y) << "step " << n << " body " << i;
      ASSERT_EQ(st[i].velocity.x, v.x) << "step " << n << " body " << i;
      ASSERT_EQ(st[i].velocity.y, v.y) << "step " << n << " body " << i;
    }
    if (!e->contacts().empty()) ++touching_steps;
  }
  // The scene is not trivial: bodies met.
  EXPECT_GE(touching_steps, min_contact_steps);
}

TEST(ChipmunkAdapter, ReproducesTheRawLibraryBitForBit) {
  expect_same_bits(two_balls_on_a_slope(), 0.0);
  // With Chipmunk's own slop through the option, the same.
  Scene s = two_balls_on_a_slope();
  s.engine_options["chipmunk"]["collision_slop"] = 0.1;
  expect_same_bits(s, 0.1);
}

TEST(ChipmunkAdapter, ReproducesAHeadOnCollisionBitForBit) {
  Scene s = head_on(1.0, 3.0, 2.0, -1.0, 1.0 / 60.0);
  s.bodies[0].restitution = 0.7;
  expect_same_bits(s, 0.0, 1);
}

TEST(ChipmunkAdapter, ImposesPhysvalsRestitutionNotChipmunksProduct) {
  // e = 0.5 ball on an e = 1 floor: physval's min is 0.5; Chipmunk's own product too, so
  // take 0.5 and 0.8: min 0.5, product 0.4. No gravity: it leaves at exactly e v.
  Scene s = empty_scene("bounce", 1.0 / 60.0, 1.0);
  s.bodies.push_back(circle("ball", 0.5, 1.0, {0.0, 0.5 + 0.11}, {0.0, -2.0}, 0.5));
  s.walls.push_back(wall("floor", {-5.0, 0.0}, {5.0, 0.0}, 0.8));
  auto e = make_engine("chipmunk", s);
  const auto events = run(*e, s, s.steps());
  EXPECT_DOUBLE_EQ(states(*e)[0].velocity.y, 1.0);
  ASSERT_EQ(events.size(), 1u);
  // Chipmunk collides the positions a step reached: the contact is stamped with the end
  // of the step in which the ball first overlaps the floor (0.11 m at 2 m/s: step 4).
  EXPECT_DOUBLE_EQ(events[0].time, 4.0 / 60.0);
}

TEST(ChipmunkAdapter, CollisionMatrixEventPassesThroughAndIsReportedOnce) {
  Scene s = empty_scene("prize", 1.0 / 60.0, 1.0);
  BodyDef ball = circle("ball", 0.2, 1.0, {0.0, 0.0}, {3.0, 0.0});
  ball.group = "player";
  BodyDef prize = circle("prize", 0.2, 1.0, {1.5, 0.0}, {0.0, 0.0});
  prize.is_static = true;
  prize.group = "prizes";
  s.bodies = {ball, prize};
  s.collision_matrix.push_back({"player", "prizes", CollisionResponse::Event});
  auto e = make_engine("chipmunk", s);
  const auto events = run(*e, s, s.steps());
  ASSERT_EQ(events.size(), 1u);
  EXPECT_EQ(events[0].b.index, 1u);
  EXPECT_DOUBLE_EQ(states(*e)[0].velocity.x, 3.0);   // passed through
  EXPECT_GT(states(*e)[0].position.x, 2.5);
}

TEST(ChipmunkAdapter, PublishesItsSettings) {
  const Scene s = two_balls_on_a_slope();
  auto e = make_engine("chipmunk", s);
  const auto set = e->settings();
  EXPECT_EQ(setting(set, "version"), "7.0.3");
  EXPECT_EQ(setting(set, "solver_iterations"), "10");
  EXPECT_EQ(setting(set, "collision_slop"), "0");
  EXPECT_NE(setting(set, "sleep_time_threshold").find("INFINITY"), std::string::npos);
  EXPECT_NE(setting(set, "continuous_collision").find("none"), std::string::npos);
  EXPECT_NE(setting(set, "restitution_threshold").find("none"), std::string::npos);
  for (const char* key : {"collision_bias", "collision_persistence", "damping", "material_rule", "fixed_rotation",
                          "external_forces_evaluated", "integration"}) {
    EXPECT_TRUE(has_setting(set, key)) << key;
  }
  EXPECT_EQ(find_engine("chipmunk")->info.precision, Precision::Float64);
}

TEST(ChipmunkAdapter, TunnellingIsReportedAsALimit) {
  Scene s = empty_scene("tunnel", 1.0 / 60.0, 0.1);
  s.bodies.push_back(circle("bullet", 0.02, 0.01, {0.0, 0.0}, {300.0, 0.0}));
  s.walls.push_back(wall("plate", {9.9, -1.0}, {9.9, 1.0}));
  auto e = make_engine("chipmunk", s);
  EXPECT_TRUE(run(*e, s, s.steps()).empty());   // no continuous collision: it passes
  EXPECT_TRUE(any_limit_starts_with(e->limits_hit(), "discrete_collision"));
}

}  // namespace
}  // namespace physval::test
