// A floor drawn as several segments end to end (walls, or one surface's polyline): a
// body sliding along it crosses the junctions as if the floor were one segment. Found by
// the third hunt (README, *The hunt for wrong greens*): a point fell through the floor at
// a junction.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "scene_fixture.hpp"

namespace physval::test {
namespace {

// The floor from -5 to 15 (in the floor's own coordinate) cut into `parts` pieces at
// -5 + 20 i / parts, turned by `angle` (gravity along its normal, into it): a junction's
// coordinates are the round-off of that formula, so the pieces meet to an ulp or so.
Scene split_floor(int parts, double angle, bool surface, BodyDef body) {
  const Vec2 dir{std::cos(angle), std::sin(angle)};
  const Vec2 n{-dir.y, dir.x};
  std::vector<Vec2> points;
  for (int i = 0; i <= parts; ++i) {
    const double u = -5.0 + 20.0 * i / parts;
    points.push_back({u * dir.x, u * dir.y});
  }
  Scene s = scene_of({body}, {}, {9.81 * n.x * -1.0, 9.81 * n.y * -1.0});
  if (surface) {
    SurfaceDef f;
    f.name = "floor";
    f.points = points;
    f.material.restitution = 0.0;
    s.surfaces.push_back(f);
  } else {
    for (int i = 0; i < parts; ++i) {
      s.walls.push_back(wall("f" + std::to_string(i), points[static_cast<std::size_t>(i)],
                             points[static_cast<std::size_t>(i) + 1], 0.0));
    }
  }
  return s;
}

// A point dropped from h (e = 0) lands and slides on at v along a frictionless floor cut
// into pieces: it must stay on the floor's line (never more than round-off below it) and
// be at u = v T at the end. Before the fix it fell through the junction at
// u = 0.7142857142857144 (seven pieces): released at the end of one piece, computed along
// it, a hair before the next one's start, it never met that face (strictly outside its
// span) and fell, `ok` when it started on the line (nothing crossed from a side), and its
// converged reference was the falling path.
TEST(CoreJunction, APointSlidesAcrossTheJunctionsOfAFloorDrawnInPieces) {
  int runs = 0;
  for (bool surface : {false, true}) {
    for (int parts : {2, 3, 7}) {
      for (double angle : {0.0, 0.3, -0.45}) {
        for (double v : {0.5, 3.0, 7.0}) {
          for (double h : {0.0, 1e-6, 1e-3}) {
            const Vec2 dir{std::cos(angle), std::sin(angle)};
            const Vec2 n{-dir.y, dir.x};
            BodyDef p = point("p", {h * n.x, h * n.y}, {v * dir.x, v * dir.y}, 1.0, 0.0);
            Sim sim(split_floor(parts, angle, surface, p));
            const double T = 1.5;
            const double dt = 1.0 / 60.0;
            double lowest = 0.0;
            while (sim.engine.time() < T - 1e-12) {
              sim.step(std::min(dt, T - sim.engine.time()));
              lowest = std::min(lowest, dot(sim.state(0).position, n));
            }
            const BodyState end = sim.state(0);
            const std::string what = std::string(surface ? "surface" : "walls") + " parts " + std::to_string(parts) +
                                     " angle " + std::to_string(angle) + " v " + std::to_string(v) + " h " +
                                     std::to_string(h);
            EXPECT_GT(lowest, -1e-9) << what;
            EXPECT_NEAR(dot(end.position, dir), v * T, 1e-9) << what;
            EXPECT_NEAR(dot(end.position, n), 0.0, 1e-9) << what;
            EXPECT_NEAR(dot(end.velocity, dir), v, 1e-9) << what;
            EXPECT_NEAR(dot(end.velocity, n), 0.0, 1e-9) << what;
            ++runs;
          }
        }
      }
    }
  }
  EXPECT_EQ(runs, 162);
}

// A ball (r = 0.25) starting on the floor slides across its junctions at v: on the floor
// all the way (its centre r above the line), at u = u0 + v T at the end, and no more than a
// few events a step. Before the fix, at the junction the ball was released from one piece
// at its end, met the next piece's face and, touching the first piece too, was taken as in
// a V: the simultaneous law at both (one normal) changed nothing, left it free, and it met
// the next piece again at the same instant until the event cap (`diverged`, no reference),
// at 2.9 and 3 m/s with the junction at x = 5 (and 7 pieces on a 0.3 rad slope).
TEST(CoreJunction, ABallSlidesAcrossTheJunctionsOfAFloorDrawnInPieces) {
  int runs = 0;
  for (bool surface : {false, true}) {
    for (int parts : {2, 3, 7}) {
      for (double angle : {0.0, 0.3, -0.45}) {
        for (double v : {0.5, 2.9, 3.0, 7.0}) {
          for (double u0 : {0.0, -1e-4, 1e-3}) {
            const Vec2 dir{std::cos(angle), std::sin(angle)};
            const Vec2 n{-dir.y, dir.x};
            const double r = 0.25;
            BodyDef b = circle("b", {u0 * dir.x + r * n.x, u0 * dir.y + r * n.y}, {v * dir.x, v * dir.y}, r, 1.0, 0.0);
            Sim sim(split_floor(parts, angle, surface, b));
            const double T = 2.0;
            const double dt = 1.0 / 60.0;
            double lowest = r;
            bool broken = false;
            while (sim.engine.time() < T - 1e-12) {
              sim.step(std::min(dt, T - sim.engine.time()));
              lowest = std::min(lowest, dot(sim.state(0).position, n));
              broken = broken || !sim.engine.broken_guarantee().empty();
            }
            const BodyState end = sim.state(0);
            const std::string what = std::string(surface ? "surface" : "walls") + " parts " + std::to_string(parts) +
                                     " angle " + std::to_string(angle) + " v " + std::to_string(v) + " u0 " +
                                     std::to_string(u0);
            EXPECT_FALSE(broken) << what << ": " << sim.engine.broken_guarantee();
            EXPECT_GT(lowest, r - 1e-9) << what;
            EXPECT_NEAR(dot(end.position, dir), u0 + v * T, 1e-9) << what;
            EXPECT_NEAR(dot(end.position, n), r, 1e-9) << what;
            EXPECT_NEAR(dot(end.velocity, dir), v, 1e-9) << what;
            EXPECT_NEAR(dot(end.velocity, n), 0.0, 1e-9) << what;
            ++runs;
          }
        }
      }
    }
  }
  EXPECT_EQ(runs, 216);
}

}  // namespace
}  // namespace physval::test
