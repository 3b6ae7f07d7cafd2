// What is particular to Box2D 2.4.1: its compiled-in limits, reported on the run; its
// float precision; its options read from the scenario's [box2d] table.
#include <cmath>
#include <string>

#include <gtest/gtest.h>

#include "adapter_test_scenes.hpp"

namespace physval::test {
namespace {

Scene one_body(Vec2 position, Vec2 velocity, double angular_velocity = 0.0) {
  Scene s = empty_scene("one", 1.0 / 60.0, 1.0);
  BodyDef b = circle("b", 0.5, 1.0, position, velocity);
  b.angular_velocity = angular_velocity;
  s.bodies.push_back(b);
  return s;
}

TEST(Box2DAdapter, InfoNamesThePackageVersionAndFloatPrecision) {
  const EngineFactory* f = find_engine("box2d");
  ASSERT_NE(f, nullptr);
  EXPECT_EQ(f->info.version, "2.4.1");
  EXPECT_EQ(f->info.precision, Precision::Float32);
  auto e = make_engine("box2d", one_body({0, 0}, {0, 0}));
  // The library itself still says 2.4.0; the run records both.
  EXPECT_NE(setting(e->settings(), "runtime_b2_version").find("2.4.0"), std::string::npos);
}

TEST(Box2DAdapter, SpeedClampIsReported) {
  // 200 m/s at dt 1/60 is 3.3 m per step: Box2D scales it to b2_maxTranslation = 2 m.
  const Scene s = one_body({0, 0}, {200.0, 0.0});
  auto e = make_engine("box2d", s);
  e->step(s.dt);
  const BodyState st = states(*e)[0];
  EXPECT_NEAR(st.velocity.x, 2.0 / static_cast<float>(s.dt), 1e-3);   // 120 m/s, float
  EXPECT_NEAR(st.position.x, 2.0, 1e-5);
  ASSERT_TRUE(any_limit_starts_with(e->limits_hit(), "speed_clamp")) << testing::PrintToString(e->limits_hit());

  // Below the cap nothing is reported.
  const Scene slow = one_body({0, 0}, {100.0, 0.0});
  auto e2 = make_engine("box2d", slow);
  run(*e2, slow, 10);
  EXPECT_TRUE(e2->limits_hit().empty()) << testing::PrintToString(e2->limits_hit());
  EXPECT_EQ(states(*e2)[0].velocity.x, 100.0);
}

TEST(Box2DAdapter, SpinClampIsReported) {
  // 200 rad/s at dt 1/60 turns 3.3 rad per step; Box2D caps it at pi/2 (94.2 rad/s).
  const Scene s = one_body({0, 0}, {0, 0}, 200.0);
  auto e = make_engine("box2d", s);
  e->step(s.dt);
  EXPECT_NEAR(states(*e)[0].angular_velocity, (M_PI / 2.0) / static_cast<float>(s.dt), 1e-3);
  EXPECT_TRUE(any_limit_starts_with(e->limits_hit(), "spin_clamp"));
}

TEST(Box2DAdapter, FloatResolutionFarFromTheOrigin) {
  // float spacing exceeds 1e-4 m from 1024 m: 2^-13 = 1.2e-4 m there, 6.1e-5 m at 1000 m.
  auto near = make_engine("box2d", one_body({1000.0, 0.0}, {0.0, 0.0}));
  near->step(1.0 / 60.0);
  EXPECT_TRUE(near->limits_hit().empty());
  auto far = make_engine("box2d", one_body({0.0, -1100.0}, {0.0, 0.0}));
  far->step(1.0 / 60.0);
  EXPECT_TRUE(any_limit_starts_with(far->limits_hit(), "float_resolution"));
}

TEST(Box2DAdapter, ScenarioOptionsReachTheWorld) {
  // A 0.5 m/s elastic bounce. Box2D's own restitution threshold (1 m/s) would kill it;
  // physval's default 0 keeps it, and the option brings Box2D's behaviour back.
  Scene s = empty_scene("threshold", 1.0 / 60.0, 1.0);
  s.bodies.push_back(circle("ball", 0.5, 1.0, {0.0, 0.6}, {0.0, -0.5}));
  s.walls.push_back(wall("floor", {-5.0, 0.0}, {5.0, 0.0}));
  auto elastic = make_engine("box2d", s);
  run(*elastic, s, s.steps());
  EXPECT_NEAR(states(*elastic)[0].velocity.y, 0.5, 1e-6);

  s.engine_options["box2d"]["restitution_threshold"] = 1.0;
  s.engine_options["box2d"]["velocity_iterations"] = std::int64_t{20};
  auto sticky = make_engine("box2d", s);
  run(*sticky, s, s.steps());
  EXPECT_NEAR(states(*sticky)[0].velocity.y, 0.0, 1e-6);
  EXPECT_EQ(setting(sticky->settings(), "restitution_threshold"), "1");
  EXPECT_EQ(setting(sticky->settings(), "velocity_iterations"), "20");

  s.engine_options["box2d"]["velocity_iterations"] = std::int64_t{0};
  EXPECT_THROW(make_engine("box2d", s), std::invalid_argument);
}

TEST(Box2DAdapter, SurfaceFacesTheLeftOfItsPointOrder) {
  // Box2D chains are one-sided; a surface without normals faces the left of its point
  // order (physval's rule), so the adapter runs the chain to face that side. Points left
  // to right: the ball from above bounces; right to left: the ball from below does.
  for (bool reversed : {false, true}) {
    Scene s = empty_scene("surface", 1.0 / 60.0, 1.0);
    const double side = reversed ? -1.0 : 1.0;
    s.bodies.push_back(circle("ball", 0.25, 1.0, {0.0, side}, {0.0, -3.0 * side}));
    SurfaceDef surf;
    surf.name = "ground";
    surf.points = {{-2.0, 0.0}, {0.0, 0.0}, {2.0, 0.0}};
    if (reversed) std::reverse(surf.points.begin(), surf.points.end());
    s.surfaces.push_back(surf);
    auto e = make_engine("box2d", s);
    run(*e, s, s.steps());
    EXPECT_NEAR(states(*e)[0].velocity.y, 3.0 * side, 1e-5) << "reversed " << reversed;
  }
  // Precomputed normals are a model Box2D does not have: unsupported, named.
  Scene s = empty_scene("kicker", 1.0 / 60.0, 1.0);
  SurfaceDef surf;
  surf.name = "kicker";
  surf.points = {{-2.0, 0.0}, {2.0, 0.0}};
  surf.normals = {{0.5, 0.8660254037844386}, {0.5, 0.8660254037844386}};
  s.surfaces.push_back(surf);
  s.bodies.push_back(circle("ball", 0.25, 1.0, {0.0, 1.0}, {0.0, 0.0}));
  const std::vector<std::string> missing = unsupported_features(find_engine("box2d")->info, s);
  EXPECT_EQ(missing, std::vector<std::string>{"surface_normals"});
  EXPECT_THROW(make_engine("box2d", s), std::exception);
}

TEST(Box2DAdapter, DiscreteCollisionBetweenMovingBodiesIsReported) {
  // Two small fast bodies: without `bullet`, Box2D collides them only at step ends.
  Scene s = head_on(1.0, 1.0, 60.0, -60.0, 1.0 / 60.0);
  s.bodies[0].radius = s.bodies[1].radius = 0.1;
  auto e = make_engine("box2d", s);
  run(*e, s, 3);
  EXPECT_TRUE(any_limit_starts_with(e->limits_hit(), "discrete_collision"));
  s.engine_options["box2d"]["bullet"] = true;
  auto b = make_engine("box2d", s);
  run(*b, s, 3);
  EXPECT_FALSE(any_limit_starts_with(b->limits_hit(), "discrete_collision"));
}

}  // namespace
}  // namespace physval::test
