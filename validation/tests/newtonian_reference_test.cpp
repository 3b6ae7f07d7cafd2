// Newtonian gravity plus impacts (issue 9): core's reference converges at RK4's order
// on scenes whose bodies attract each other and collide, so every divergence metric is
// measured there. Before an impact cut the step of the whole coupled system, the
// built-in scene's runs at dt/8 and dt/4 differed by 3.0e-5 m (core missed its final
// state by 1.6e-4 m).
#include <gtest/gtest.h>

#include <string>

#include "physval/validation/comparator.hpp"
#include "physval/validation/scenario_loader.hpp"

#include "builtin_scene.hpp"

namespace physval {
namespace {

using test::load_builtin;

TEST(NewtonianReference, BuiltinHeadOnBounceHasAConvergedReference) {
  const Scene scene = load_builtin("models/newtonian_head_on_bounce.toml");
  const Reference ref = make_reference(scene, RunOptions{});
  ASSERT_TRUE(ref.available) << ref.reason;
  EXPECT_TRUE(ref.converged) << ref.reason;
  // RK4 at dt/8 = 1/800 s: the two runs agree to ~2e-13 m (the limit is 1e-6 x travel).
  EXPECT_LT(ref.convergence_error, 1e-10);
  ASSERT_TRUE(ref.run.has_value());
  ASSERT_EQ(ref.run->contacts.size(), 1u);
  // The closed form's impact time (the Kepler radial fall to d = 2 m).
  EXPECT_NEAR(ref.run->contacts[0].time, scene.expect.contacts.at(0).time, 1e-11);

  RunRecord run = *ref.run;
  run.engine = "core";
  compare_run(run, scene, ref, false);
  for (const char* m : {"position_divergence", "energy_divergence", "linear_momentum_divergence", "contact_time_error"}) {
    ASSERT_TRUE(run.metrics.count(m)) << m;
    EXPECT_TRUE(run.metrics.at(m).has_value()) << m << " is not measured";
  }
}

// Three bodies attracting each other in a uniform field, between a floor and a wall,
// elastic and not: they hit each other and the walls many times, and the reference
// converges every time.
TEST(NewtonianReference, ThreeBodiesWithWallsConverge) {
  const Scene base = load_builtin("models/newtonian_head_on_bounce.toml");
  for (double e : {1.0, 0.7}) {
    SCOPED_TRACE("e " + std::to_string(e));
    Scene s = base;
    s.expect = {};
    s.gate = {};
    s.world.gravity = {0.0, -1.5};
    s.duration = 4.0;
    s.dt = 0.01;
    BodyDef a = base.bodies[0], b = base.bodies[0], c = base.bodies[0];
    a.name = "a";
    a.position = {0.0, 2.0};
    a.velocity = {1.5, 0.3};
    a.radius = 0.5;
    a.mass = 2.0;
    b.name = "b";
    b.position = {1.6, 2.35};
    b.velocity = {-0.4, 0.1};
    b.radius = 0.4;
    b.mass = 1.0;
    c.name = "c";
    c.position = {0.7, 3.6};
    c.velocity = {0.2, -0.6};
    c.radius = 0.6;
    c.mass = 1.5;
    s.bodies = {a, b, c};
    for (BodyDef& x : s.bodies) x.restitution = e;
    WallDef floor, wall;
    floor.name = "floor";
    floor.from = {-10.0, 0.0};
    floor.to = {10.0, 0.0};
    wall.name = "wall";
    wall.from = {2.6, -1.0};
    wall.to = {2.6, 10.0};
    for (WallDef* w : {&floor, &wall}) w->material.restitution = e;
    s.walls = {floor, wall};
    const Reference ref = make_reference(s, RunOptions{});
    ASSERT_TRUE(ref.available) << ref.reason;
    EXPECT_TRUE(ref.converged) << ref.reason;
    EXPECT_LT(ref.convergence_error, 1e-9);
    ASSERT_TRUE(ref.run.has_value());
    EXPECT_GE(ref.run->contacts.size(), 5u);
  }
}

}  // namespace
}  // namespace physval
