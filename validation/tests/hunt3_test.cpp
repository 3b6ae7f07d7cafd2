// The third hunt (README, *The hunt for wrong greens*): engine runs that were `ok` while a
// body had gone into another. Each test runs the real engines and holds each verdict
// against an oracle computed here from the run's own states; each failed before its fix.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "physval/adapters/registry.hpp"
#include "physval/validation/comparator.hpp"
#include "physval/validation/conservation.hpp"
#include "physval/validation/runner.hpp"

namespace physval {
namespace {

// A small ball (radius 1-50 mm, 1 g) at 10-300 m/s into a resting 1 m, 1 kg ball, on its
// centre line or 0.3 and 0.7 m off it, dt 1/60. Physics: it bounces off the big ball's
// surface; it is never inside it. Box2D, Bullet, Chipmunk and ODE let it go up to 0.55 m
// deep into the big ball, or right through it off its centre, and the escape test (the
// centres closer than the smaller radius) never saw it: the small centre was never within
// its own radius of the big one's. Every such run was `ok`. Oracle: a run whose small ball
// is at some step wholly inside the big one (centres closer than R - r), or ends beyond
// it, has let it into the big ball, and must be `diverged` with an escape.
TEST(Hunt3, ASmallBallWhollyInsideALargeOneIsAnEscape) {
  int inside_runs = 0, runs = 0, core_runs = 0;
  for (double r : {0.001, 0.01, 0.05}) {
    for (double speed : {10.0, 30.0, 100.0, 300.0}) {
      for (double offset : {0.0, 0.3, 0.7}) {
        Scene s;
        s.name = "small_into_large";
        s.dt = 1.0 / 60.0;
        s.duration = 0.5;
        s.sample_interval = s.dt;
        BodyDef shot;
        shot.name = "shot";
        shot.radius = r;
        shot.mass = 0.001;
        shot.position = {-1.5 - 0.37 * speed * s.dt, offset};
        shot.velocity = {speed, 0.0};
        BodyDef big;
        big.name = "big";
        big.radius = 1.0;
        big.mass = 1.0;
        big.position = {0.0, 0.0};
        s.bodies = {shot, big};
        for (const EngineFactory& f : engine_registry()) {
          if (!unsupported_features(f.info, s).empty()) continue;
          RunRecord run = run_engine(s, f, RunOptions{});
          if (run.status == RunStatus::Error) continue;
          compare_run(run, s, Reference{}, false);
          ++runs;
          double closest = 1e300;
          for (const SampleRow& row : run.series.states) closest = std::min(closest, length(row[0].position - row[1].position));
          const bool beyond = run.final_states[0].position.x > run.final_states[1].position.x + 1.0;
          const std::string what = f.info.name + " r " + std::to_string(r) + " v " + std::to_string(speed) + " off " +
                                   std::to_string(offset) + ": closest " + std::to_string(closest);
          if (f.info.name == "core") {
            ++core_runs;
            EXPECT_EQ(run.status, RunStatus::Ok) << what << ": " << run.reason;
            EXPECT_GE(closest, 1.0 + r - 1e-9) << what;
          }
          if (closest < 1.0 - r || beyond) {
            ++inside_runs;
            EXPECT_EQ(run.status, RunStatus::Diverged) << what;
            ASSERT_TRUE(run.containment.escaped_bodies.has_value()) << what;
            EXPECT_GE(*run.containment.escaped_bodies, 1) << what;
          }
        }
      }
    }
  }
  EXPECT_EQ(core_runs, 36);
  EXPECT_GT(inside_runs, 100) << runs << " runs";   // 136 of the four other engines' 144 today
}

}  // namespace
}  // namespace physval
