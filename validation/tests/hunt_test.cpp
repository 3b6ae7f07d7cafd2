// The hunt for wrong greens (branch hunt): scenes a user writes where physval said `ok`
// (or a gate passed) while the physics was wrong. Each test runs real engines over a grid
// and holds each run's verdict against an oracle computed here from the run's own final
// state or from the closed form; each failed before its fix. scripts/hunt.sh reruns the
// grids end to end through the physval command.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "physval/adapters/registry.hpp"
#include "physval/validation/comparator.hpp"
#include "physval/validation/conservation.hpp"
#include "physval/validation/runner.hpp"

namespace physval {
namespace {

RunRecord run_and_compare(const Scene& s, const EngineFactory& f) {
  RunRecord r = run_engine(s, f, RunOptions{});
  compare_run(r, s, Reference{}, false);
  return r;
}

BodyDef circle(const std::string& name, Vec2 at, double radius, double mass) {
  BodyDef b;
  b.name = name;
  b.radius = radius;
  b.mass = mass;
  b.position = at;
  return b;
}

// Finding 1. A 5 cm, 10 g ball at 60-300 m/s meets a 0.5 m, 1 kg ball at rest, on one
// line. Physics: it bounces back (mass ratio 0.01: v' = -0.98 v). Bullet, Chipmunk and ODE
// (no continuous collision between moving bodies) and Box2D below its speed clamp let it
// through within one step; its centre was never inside the target at a step's end, so
// escaped_bodies stayed 0, energy and momentum are untouched, and each run was `ok`.
// Oracle: a ball that ends beyond the target went through it.
TEST(Hunt, AFastBallThroughAMovingBallWithinOneStepIsAnEscape) {
  int passed_through = 0, runs = 0;
  for (double dt : {1.0 / 60.0, 1.0 / 30.0}) {
    for (double speed : {60.0, 100.0, 150.0, 300.0}) {
      Scene s;
      s.name = "through_a_ball";
      s.dt = dt;
      s.duration = 0.5;
      BodyDef shot = circle("shot", {-3.0, 0.0}, 0.05, 0.01);
      shot.velocity = {speed, 0.0};
      s.bodies = {shot, circle("target", {0.0, 0.0}, 0.5, 1.0)};
      for (const EngineFactory& f : engine_registry()) {
        if (!unsupported_features(f.info, s).empty()) continue;
        const RunRecord r = run_and_compare(s, f);
        if (r.status == RunStatus::Error) continue;
        ++runs;
        const std::string where = f.info.name + " dt " + std::to_string(dt) + " v " + std::to_string(speed);
        const bool through = r.final_states[0].position.x > r.final_states[1].position.x;
        ASSERT_TRUE(r.metrics.at("escaped_bodies").has_value()) << where;
        if (through) {
          ++passed_through;
          EXPECT_GE(*r.metrics.at("escaped_bodies"), 1.0) << where;
          EXPECT_EQ(r.status, RunStatus::Diverged) << where << ": " << r.reason;
          EXPECT_FALSE(r.passed()) << where;
        }   // (one that went in and was pushed back out is an escape too: Box2D at 60 m/s)
        if (f.info.name == "core") {
          EXPECT_FALSE(through) << where;   // exact impacts: it bounces back
          EXPECT_EQ(r.status, RunStatus::Ok) << where << ": " << r.reason;
        }
      }
    }
  }
  EXPECT_GT(runs, 8);
  EXPECT_GT(passed_through, 0);   // the grid reaches the engines' pass-through (else it shows nothing)
}

// Finding 2. A point that starts within round-off of a floor's line (1e-15 m or 1e-9 m
// above it, inside the containment's eps) and falls through it: it never "landed" on the
// line from a side, so leaving it downwards was no crossing, and Bullet's and Chipmunk's
// runs, with the point 5 m below the floor, were `ok`. Oracle: final y below the floor.
TEST(Hunt, APointStartingOnAFloorWithinRoundOffThatFallsThroughIsAnEscape) {
  int fell = 0;
  for (double y0 : {1e-15, 1e-12, 1e-9}) {
    for (double vy : {0.0, -1.0}) {
      Scene s;
      s.name = "point_on_floor";
      s.dt = 1.0 / 60.0;
      s.duration = 1.0;
      s.world.gravity = {0.0, -9.81};
      BodyDef p;
      p.name = "p";
      p.shape = ShapeKind::Point;
      p.radius = 0.0;
      p.position = {0.0, y0};
      p.velocity = {0.0, vy};
      p.restitution = 0.0;
      s.bodies = {p};
      WallDef floor;
      floor.name = "floor";
      floor.from = {-5.0, 0.0};
      floor.to = {5.0, 0.0};
      s.walls = {floor};
      for (const EngineFactory& f : engine_registry()) {
        if (!unsupported_features(f.info, s).empty()) continue;
        const RunRecord r = run_and_compare(s, f);
        if (r.status == RunStatus::Error) continue;
        const std::string where = f.info.name + " y0 " + std::to_string(y0) + " vy " + std::to_string(vy);
        ASSERT_TRUE(r.metrics.at("escaped_bodies").has_value()) << where;
        if (r.final_states[0].position.y < -1e-6) {
          ++fell;
          EXPECT_EQ(*r.metrics.at("escaped_bodies"), 1.0) << where;
          EXPECT_EQ(r.status, RunStatus::Diverged) << where << ": " << r.reason;
        } else {
          EXPECT_EQ(*r.metrics.at("escaped_bodies"), 0.0) << where;
        }
      }
    }
  }
  EXPECT_GT(fell, 0);
  // A point that starts within round-off above a floor and leaves upwards crossed nothing.
  Scene s;
  s.name = "point_leaves_floor";
  s.dt = 1.0 / 60.0;
  s.duration = 0.5;
  BodyDef p;
  p.name = "p";
  p.shape = ShapeKind::Point;
  p.position = {0.0, 1e-12};
  p.velocity = {0.3, 2.0};
  s.bodies = {p};
  WallDef floor;
  floor.name = "floor";
  floor.from = {-5.0, 0.0};
  floor.to = {5.0, 0.0};
  s.walls = {floor};
  for (const EngineFactory& f : engine_registry()) {
    if (!unsupported_features(f.info, s).empty()) continue;
    const RunRecord r = run_and_compare(s, f);
    if (r.status == RunStatus::Error) continue;
    EXPECT_EQ(*r.metrics.at("escaped_bodies"), 0.0) << f.info.name;
    EXPECT_EQ(r.status, RunStatus::Ok) << f.info.name << ": " << r.reason;
  }
}

}  // namespace
}  // namespace physval
