// The fifth hunt (README, *The fifth hunt*): scenes the independent checkers write, at many
// parameters, judged against physics computed here. Each test failed before its fix.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <string>

#include "physval/validation/comparator.hpp"
#include "physval/validation/scenario_loader.hpp"
#include "physval_command.hpp"

namespace {

namespace fs = std::filesystem;

using physval_test::Result;
using physval_test::physval;

class Hunt5 : public physval_test::TempDirTest {
 protected:
  Hunt5() : TempDirTest("physval_hunt5_") {}
};

const std::string kFlight = R"(name = "flight"
duration = 1.0
[[bodies]]
name = "b"
radius = 0.1
position = [0.0, 0.0]
velocity = [1.0, 0.0]
)";

// Bullet's `ccd = true` works through predictive contacts, which a
// contact_processing_threshold of 0 (physval's default) never solves: Bullet refused to
// start, so `check` passed the scene (exit 0) and `run` reported an engine error (exit 1)
// on Bullet alone. Bad input: exit 2 from check, naming file:line:col and the key.
TEST_F(Hunt5, BulletCcdWithoutAContactProcessingThresholdIsBadInput) {
  const fs::path bare = write("bare.toml", kFlight + "[bullet]\nccd = true\n");
  Result r = physval("check " + bare.string());
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find(bare.string() + ":9:7: bullet.ccd: ccd = true needs bullet.contact_processing_threshold > 0"),
            std::string::npos)
      << r.output;
  r = physval("run " + bare.string() + " --quiet --no-cache --out " + (dir_ / "out").string());
  EXPECT_EQ(r.status, 2) << r.output;

  const fs::path zero = write("zero.toml", kFlight + "[bullet]\nccd = true\ncontact_processing_threshold = 0.0\n");
  r = physval("check " + zero.string());
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find(zero.string() + ":10:32: bullet.contact_processing_threshold: ccd = true needs"), std::string::npos)
      << r.output;

  const fs::path given = write("given.toml", kFlight + "[bullet]\nccd = true\ncontact_processing_threshold = 1e30\n");
  r = physval("check " + given.string());
  EXPECT_EQ(r.status, 0) << r.output;
  const fs::path off = write("off.toml", kFlight + "[bullet]\nccd = false\n");
  r = physval("check " + off.string());
  EXPECT_EQ(r.status, 0) << r.output;
}

// dt = 5e-324 s (the smallest subnormal) and a duration of 988 of them: `check` passed it,
// and the reference's step dt/8 rounds to 0, so its run never advanced while it filled
// the memory (18 GB before it was killed; std::bad_alloc under a 3 GB limit). The
// reference steps at down to dt/16: a dt whose 16th is not a normal double is bad input.
TEST_F(Hunt5, AStepTheReferenceCannotDivideIsBadInput) {
  const std::string scene = R"(name = "tiny_step"
duration = 4.94e-321
dt = 5e-324
[[bodies]]
name = "b"
radius = 0.1
position = [0.0, 0.0]
velocity = [1e-3, 0.0]
)";
  const fs::path f = write("tiny.toml", scene);
  Result r = physval("check " + f.string());
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find(f.string() + ":3:6: dt: dt = 4.94066e-324 s is too small"), std::string::npos) << r.output;
  // The CLI's --dt goes through the same rule (refused before anything runs).
  const fs::path ok = write("ok.toml", kFlight);
  r = physval("run " + ok.string() + " --dt 1e-307 --quiet --no-cache --out " + (dir_ / "out").string());
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find("is too small"), std::string::npos) << r.output;
  // A tiny dt whose 16th is still a normal double is accepted.
  const fs::path small = write("small.toml", R"(name = "small_step"
duration = 1e-298
dt = 1e-300
[[bodies]]
name = "b"
radius = 0.1
position = [0.0, 0.0]
)");
  r = physval("check " + small.string());
  EXPECT_EQ(r.status, 0) << r.output;
}

// A scene of 6e8 steps (within the 1e9 a run may take): its reference at dt/2 needs 1.2e9
// steps, beyond Scene::kMaxSteps, where the step count saturates at 1e9 + 1 and the run
// ends in one last step of 2e8 dt. The reference is refused with the reason instead (at
// once: before, it ran until the timeout).
TEST(Hunt5Reference, AReferenceBeyondTheMostStepsARunTakesIsNotMade) {
  physval::ScenarioLoad load = physval::parse_scenario(R"(name = "long_flight"
duration = 600000.0
dt = 0.001
[[bodies]]
name = "b"
radius = 0.1
position = [0.0, 0.0]
velocity = [1.0, 0.0]
)",
                                                       "long.toml");
  ASSERT_TRUE(load.scene.has_value());
  ASSERT_EQ(load.scene->steps(), 600000000);
  physval::RunOptions o;
  o.timeout_seconds = 5.0;
  const auto t0 = std::chrono::steady_clock::now();
  const physval::Reference ref = physval::make_reference(*load.scene, o);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  EXPECT_FALSE(ref.available);
  EXPECT_FALSE(ref.converged);
  EXPECT_NE(ref.reason.find("more than a run takes"), std::string::npos) << ref.reason;
  EXPECT_LT(seconds, 2.0) << ref.reason;
}

// A ball thrown at 200 m/s (then 50 m/s) against quadratic drag k2 = 10 N/(m/s)^2, 1 kg,
// towards a wall at x = 3 over a floor (e 0.9). Drag only slows a body along its own
// velocity: x never decreases while vx > 0, and vx never changes sign by drag, so the
// ball's x stays >= 0 (it stops at x = 0.623 m: RK4 at 1e-5 s with exact impacts,
// scripts/hunt5.py). The reference (core, RK4 at dt/8 = 2.1 ms, k |v| dt / m = 4.2)
// reversed the ball 3 m within one step, the same at dt/4, so its two runs agreed to 0 m
// and it was "converged", and every engine was measured against a ball 3.6 m from the
// truth (Box2D, nearer the truth, 3.1 m "off"). Oracle: a reference that claims
// convergence must keep x >= 0 throughout; a stiff-drag reference says it is not converged.
TEST(Hunt5Reference, AReferenceUnderDragTooStiffForItsStepIsNotConverged) {
  const physval::ScenarioLoad load =
      physval::load_scenario_file(std::string(PHYSVAL_SOURCE_DIR) + "/validation/tests/hunt/stiff_quadratic_drag.toml");
  ASSERT_TRUE(load.scene.has_value());
  for (double speed : {200.0, 50.0}) {
    physval::Scene s = *load.scene;
    s.bodies[0].velocity = {speed, 0.3 * speed};
    const physval::Reference ref = physval::make_reference(s, physval::RunOptions{});
    ASSERT_TRUE(ref.run.has_value()) << ref.reason;
    double x_min = 0.0;
    for (const auto& row : ref.run->series.states) x_min = std::min(x_min, row[0].position.x);
    if (ref.converged) {
      EXPECT_GE(x_min, 0.0) << speed << " m/s: a converged reference went backwards against drag";
    }
    EXPECT_FALSE(ref.converged) << speed << " m/s";
    EXPECT_NE(ref.reason.find("drag is too stiff for the reference's step"), std::string::npos) << ref.reason;
  }
  // Drag the reference's step resolves (k dt / m = 0.1) still converges, to the closed
  // form of linear drag without impacts: x = v0 m / k (1 - exp(-k t / m)).
  physval::Scene s = *load.scene;
  s.walls.clear();
  s.world.gravity = {0.0, 0.0};
  s.bodies[0].drag_quadratic = 0.0;
  s.bodies[0].drag_linear = 0.4;
  s.bodies[0].velocity = {5.0, 0.0};
  s.duration = 2.0;
  const physval::Reference ref = physval::make_reference(s, physval::RunOptions{});
  ASSERT_TRUE(ref.converged) << ref.reason;
  const double x = ref.run->final_states[0].position.x;
  EXPECT_NEAR(x, 5.0 / 0.4 * (1.0 - std::exp(-0.4 * 2.0)), 1e-6);
}

}  // namespace
