// The sixth hunt (README, *The sixth hunt*): families the earlier hunts left (bodies in a
// uniform field passing through each other within a step, particles near moving bodies),
// judged against physics computed here. Each test failed before its fix.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "../src/containment.hpp"
#include "physval_command.hpp"

namespace physval {
namespace {

namespace fs = std::filesystem;
using physval_test::physval;
using physval_test::Result;

class Hunt6 : public physval_test::TempDirTest {
 protected:
  Hunt6() : TempDirTest("physval_hunt6_") {}
};

Scene two_balls(Vec2 g, double ra, double rb) {
  Scene s;
  s.name = "pass";
  s.duration = 1.0;
  s.dt = 0.25;
  s.world.gravity = g;
  BodyDef a;
  a.name = "a";
  a.radius = ra;
  BodyDef b;
  b.name = "b";
  b.radius = rb;
  s.bodies = {a, b};
  return s;
}

// One free flight of h under g from (x, v), as each integrator family steps it:
// explicit Euler (x += v h), the exact flight / Verlet (x += v h + g h^2 / 2),
// semi-implicit Euler (x += (v + g h) h); the velocity is v + g h in all three.
BodyState flight(Vec2 x, Vec2 v, Vec2 g, double h, double c) {
  BodyState s;
  s.position = x + v * h + g * (c * h * h);
  s.velocity = v + g * h;
  return s;
}

BodyState at(Vec2 x, Vec2 v) {
  BodyState s;
  s.position = x;
  s.velocity = v;
  return s;
}

// Two balls in free fall, one crossing the other within one step on a straight relative
// path 0.6 of the radii's sum off the other's centre (0.4 of it deep). Before: a free
// flight's own fall, g h^2 / 2, read as the kink of a collision, so no pass between
// bodies was judged in a field at a coarse step or between small balls; the same pass
// without the field was an escape. Whatever the integrator (three ways to step a flight),
// the field, the step or the size, it is one now; and a bounce inside the step (a
// collision, the velocity changed by more than the field) is still not judged by the
// chord.
TEST(Hunt6Containment, APassWithinOneStepInAUniformFieldIsAnEscape) {
  int judged = 0;
  for (const double g : {0.0, 9.8, 98.0}) {
    for (const double h : {1.0 / 60.0, 0.125, 0.25}) {
      for (const double r : {0.01, 0.5}) {
        for (const double c : {0.0, 0.5, 1.0}) {
          const Vec2 field{0.0, -g};
          Scene s = two_balls(field, r, r);
          s.dt = h;
          const double R = 2.0 * r;
          const double v = 3.3 * R / h;   // three radii sums a step: b is crossed mid-step
          const Vec2 a0{-1.65 * R, 0.6 * R}, b0{0.0, 0.0};
          ContainmentMonitor m(s);
          m.start({at(a0, {v, 0.0}), at(b0, {})});
          m.observe(h, {flight(a0, {v, 0.0}, field, h, c), flight(b0, {}, field, h, c)});
          const ContainmentRecord& rec = m.record();
          ASSERT_TRUE(rec.escaped_bodies.has_value());
          EXPECT_EQ(*rec.escaped_bodies, 2) << "g " << g << " h " << h << " r " << r << " scheme " << c;
          // A glancing collision at mid-step (a pushed up by 0.2 R / h, b down by as much):
          // the chord between the ends passes 0.7 R from b's centre, deeper than the 0.25 R
          // counted, but it cuts the corner of a bent path and is not judged.
          ContainmentMonitor bounce(s);
          bounce.start({at(a0, {v, 0.0}), at(b0, {})});
          const double u = 0.2 * R / h;
          BodyState a1 = flight(a0, {v, 0.0}, field, h, c), b1 = flight(b0, {}, field, h, c);
          a1.position.y += 0.5 * u * h;
          a1.velocity.y += u;
          b1.position.y -= 0.5 * u * h;
          b1.velocity.y -= u;
          bounce.observe(h, {a1, b1});
          EXPECT_EQ(*bounce.record().escaped_bodies, 0) << "g " << g << " h " << h << " r " << r << " scheme " << c;
          ++judged;
        }
      }
    }
  }
  EXPECT_EQ(judged, 54);
  // Two 1 cm balls rolling on a floor (supported: no fall, the step straight as it is) in
  // the field through each other at dt 1/60: judged before and still (the field taken out
  // of a step that never fell must not read as a kink).
  Scene s = two_balls({0.0, -9.8}, 0.01, 0.01);
  const double h = 1.0 / 60.0, v = 3.3 * 0.02 / h;
  s.dt = h;
  const Vec2 a0{-1.65 * 0.02, 0.6 * 0.02}, b0{0.0, 0.0};
  ContainmentMonitor m(s);
  m.start({at(a0, {v, 0.0}), at(b0, {})});
  m.observe(h, {at(a0 + Vec2{v * h, 0.0}, {v, 0.0}), at(b0, {})});
  EXPECT_EQ(*m.record().escaped_bodies, 2);
}

const std::string kFallPass = R"(name = "fall_pass"
duration = 1.0
dt = 0.25
[world]
gravity = [0.0, -9.8]
[[bodies]]
name = "a"
radius = 0.5
position = [-12.0, 0.0]
velocity = [40.0, 0.0]
[[bodies]]
name = "b"
radius = 0.5
position = [0.0, 0.6]
)";

// Through physval run: Bullet (no continuous collision between moving bodies) lets the
// ball through the other in free fall (it ends at x = 28 m, untouched), `ok` before, as
// `diverged` as the same pass without gravity always was. core, which meets the other
// ball, stays `ok` with no escape.
TEST_F(Hunt6, BulletLettingAFallingBallThroughAnotherIsDiverged) {
  const fs::path scene = write("fall_pass.toml", kFallPass);
  const fs::path out = dir_ / "out";
  Result r = physval("run " + scene.string() + " --engines core,bullet --quiet --no-cache --out " + out.string());
  ASSERT_EQ(r.status, 1) << r.output;
  std::ifstream in(out / "results.json");
  const nlohmann::json j = nlohmann::json::parse(in);
  int seen = 0;
  for (const auto& run : j["runs"]) {
    const std::string engine = run["engine"];
    if (engine == "core") {
      EXPECT_EQ(run["status"], "ok") << run.dump();
      EXPECT_EQ(run["metrics"]["escaped_bodies"], 0);
      ++seen;
    } else if (engine == "bullet") {
      // The oracle: b never moved sideways, a kept its speed, so they went through each
      // other by 0.4 m on the straight relative path.
      for (const auto& f : run["final"]) {
        if (f["body"] == "a") EXPECT_NEAR(f["velocity"][0].get<double>(), 40.0, 1e-9);
        if (f["body"] == "b") EXPECT_NEAR(f["velocity"][0].get<double>(), 0.0, 1e-9);
      }
      EXPECT_EQ(run["status"], "diverged") << run.dump();
      EXPECT_EQ(run["metrics"]["escaped_bodies"], 2);
      ++seen;
    }
  }
  EXPECT_EQ(seen, 2);
}

// Particles born within a step near a moving ball: a trail whose young particles fly into
// a 0.4 m ball rolling past its parent. Placed where their ballistic paths took them by
// the step's end, the paths checked against barriers and static bodies only, they were
// put inside the ball (0.09 m from its centre; core is the only engine with particles, and
// containment does not follow them, so the run was `ok`). Every alive particle must end
// outside every moving ball, in the three scenes that showed it and their neighbours.
TEST_F(Hunt6, ParticlesAreNeverPlacedInsideAMovingBall) {
  int scenes = 0;
  for (const double speed : {5.0, 50.0}) {
    for (const std::string dt : {"1/60", "1/10"}) {
      for (const double e : {0.5, 1.0}) {
        std::ostringstream t;
        t << "name = \"trail_ball\"\nduration = 3.0\ndt = \"" << dt << "\"\n[world]\ngravity = [0.0, -9.8]\n"
          << "[[bodies]]\nname = \"shell\"\nradius = 0.05\nposition = [0.3, 2.1]\nvelocity = [1.5, 2.0]\nrestitution = " << e
          << "\n[[bodies]]\nname = \"ball\"\nradius = 0.4\nmass = 5.0\nposition = [-1.0, 1.0]\nvelocity = [3.0, 4.0]\n"
          << "restitution = " << e << "\n";
        const char* c[4][2] = {{"-2.0, 0.0", "2.0, 0.0"}, {"2.0, 0.0", "2.0, 4.0"}, {"2.0, 4.0", "-2.0, 4.0"}, {"-2.0, 4.0", "-2.0, 0.0"}};
        for (int k = 0; k < 4; ++k) {
          t << "[[walls]]\nname = \"w" << k << "\"\nfrom = [" << c[k][0] << "]\nto = [" << c[k][1] << "]\nrestitution = " << e << "\n";
        }
        t << "[[emitters]]\nname = \"em\"\nparent = \"shell\"\nmode = \"trail\"\nrate = 100.0\nspeed = " << speed
          << "\nlifetime = 2.0\ndestroy_on_collision = false\nseed = 7\n";
        const fs::path scene = write("trail_ball.toml", t.str());
        const fs::path out = dir_ / "out";
        Result r = physval("run " + scene.string() + " --engines core --quiet --no-cache --out " + out.string());
        ASSERT_TRUE(r.status == 0 || r.status == 1) << r.output;
        std::ifstream in(out / "results.json");
        const nlohmann::json j = nlohmann::json::parse(in);
        const auto& run = j["runs"][0];
        if (run["status"] != "ok") continue;   // an event cap is honest; the test is about `ok` runs
        double bx = 0, by = 0;
        for (const auto& f : run["final"]) {
          if (f["body"] == "ball") {
            bx = f["position"][0];
            by = f["position"][1];
          }
        }
        int alive = 0;
        for (const auto& f : run["final"]) {
          const std::string name = f["body"];
          if (name.find('#') == std::string::npos || !f["alive"].get<bool>()) continue;
          ++alive;
          const double d = std::hypot(f["position"][0].get<double>() - bx, f["position"][1].get<double>() - by);
          EXPECT_GE(d, 0.4 - 1e-9) << name << " inside the ball, speed " << speed << " dt " << dt << " e " << e;
        }
        EXPECT_GT(alive, 100);
        ++scenes;
      }
    }
  }
  EXPECT_GE(scenes, 6);
}

}  // namespace
}  // namespace physval

namespace physval {
namespace {

// A car with angle 0.3 rad and angular_velocity 2 rad/s under a constant thrust table:
// core kept its heading (4 m/s along 0.3 rad after 2 s, the lecture's non-spinning body),
// Box2D, Bullet, Chipmunk and ODE turned it (ending at (-1.19, 1.38) m/s), every run `ok`
// against a reference that did not model the key. Bad input now, at the key; without a
// thrust table (the heading moves nothing) or with angular_velocity 0 it is accepted.
TEST_F(Hunt6, ASpinningBodyWithThrustIsBadInput) {
  const std::string car = "name = \"car\"\nduration = 2.0\n[[bodies]]\nname = \"car\"\nradius = 0.5\nposition = [0.0, 0.0]\n"
                          "angle = 0.3\n";
  const std::string thrust = "[bodies.thrust]\nspeeds = [0.0]\naccel = [2.0]\n";
  const fs::path spin = write("spin.toml", car + "angular_velocity = 2.0\n" + thrust);
  Result r = physval("check " + spin.string());
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find(spin.string() + ":8:20: bodies[0].angular_velocity: a body with a thrust table must not spin"),
            std::string::npos)
      << r.output;
  r = physval("run " + spin.string() + " --quiet --no-cache --out " + (dir_ / "out").string());
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_EQ(physval("check " + write("still.toml", car + "angular_velocity = 0.0\n" + thrust).string()).status, 0);
  EXPECT_EQ(physval("check " + write("free.toml", car + "angular_velocity = 2.0\n").string()).status, 0);
}

}  // namespace
}  // namespace physval
