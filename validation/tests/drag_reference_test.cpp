// Drag plus contact (issue 9, point 7): core's reference converges on the scene a
// newcomer writes first, a ball with air drag thrown at a wall and a floor, so every
// divergence metric is measured there. Before core's impacts kept the integrator's
// order, its runs at dt/8 and dt/4 differed by 3.5 mm and the reference was "not
// converged".
#include <gtest/gtest.h>

#include <string>

#include "physval/validation/comparator.hpp"
#include "physval/validation/scenario_loader.hpp"

#include "builtin_scene.hpp"

namespace physval {
namespace {

using test::load_builtin;

TEST(DragReference, BuiltinDragBallSceneHasAConvergedReference) {
  const Scene scene = load_builtin("models/drag_ball_wall_floor.toml");
  const Reference ref = make_reference(scene, RunOptions{});
  ASSERT_TRUE(ref.available) << ref.reason;
  EXPECT_TRUE(ref.converged) << ref.reason;
  // RK4 at dt/8 = 1/960 s: the two runs agree to ~1e-13 m; the limit is 1e-6 x travel.
  EXPECT_LT(ref.convergence_error, 1e-10);
  ASSERT_TRUE(ref.run.has_value());
  EXPECT_EQ(ref.run->contacts.size(), 3u);   // the wall, then the floor twice

  // And every divergence metric of a run is measured against it (not "not measured").
  RunRecord run = *ref.run;
  run.engine = "core";
  compare_run(run, scene, ref, false);
  for (const char* m : {"position_divergence", "energy_divergence", "linear_momentum_divergence", "contact_time_error"}) {
    ASSERT_TRUE(run.metrics.count(m)) << m;
    EXPECT_TRUE(run.metrics.at(m).has_value()) << m << " is not measured";
  }
}

// The same throw with quadratic drag (no closed form), winds, restitution 1 and < 1,
// other angles, and one that bounces to rest and slides to a stop: the reference
// converges every time.
TEST(DragReference, DragAndContactVariantsConverge) {
  const Scene base = load_builtin("models/drag_ball_wall_floor.toml");
  struct Variant {
    double k1, k2;
    Vec2 wind;
    double e;
    Vec2 v0;
    double mu = 0.0;
    double duration = 3.0;
  };
  const Variant variants[] = {
      {0.0, 0.02, {0.0, 0.0}, 1.0, {12.0, 7.0}},
      {0.0, 0.05, {-3.0, 0.0}, 0.8, {12.0, 7.0}},
      {0.3, 0.01, {2.0, -1.0}, 0.6, {10.0, 9.0}},
      {0.12, 0.0, {-3.0, 0.0}, 1.0, {14.0, 3.0}},
      // Bounces to rest on the floor (micro-bounces, then resting contact), slides with
      // friction against the headwind's drag and stops.
      {0.12, 0.02, {-3.0, 0.0}, 0.5, {12.0, 7.0}, 0.2, 6.0},
  };
  for (const Variant& v : variants) {
    SCOPED_TRACE("k1 " + std::to_string(v.k1) + " k2 " + std::to_string(v.k2) + " e " + std::to_string(v.e));
    Scene s = base;
    s.engine_options.clear();
    s.expect = {};
    s.world.wind = v.wind;
    s.bodies[0].drag_linear = v.k1;
    s.bodies[0].drag_quadratic = v.k2;
    s.bodies[0].velocity = v.v0;
    s.bodies[0].restitution = v.e;
    s.bodies[0].friction = v.mu;
    s.bodies[0].static_friction = v.mu;
    s.duration = v.duration;
    for (WallDef& w : s.walls) {
      w.material.restitution = v.e;
      w.material.friction = v.mu;
      w.material.static_friction = v.mu;
    }
    const Reference ref = make_reference(s, RunOptions{});
    ASSERT_TRUE(ref.available) << ref.reason;
    EXPECT_TRUE(ref.converged) << ref.reason;
    ASSERT_TRUE(ref.run.has_value());
    EXPECT_GE(ref.run->contacts.size(), 2u);   // it did meet the wall and the floor
  }
}

}  // namespace
}  // namespace physval
