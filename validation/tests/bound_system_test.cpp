// A bound system cannot come apart (README, *What physval measures*, Diverged): with no
// uniform field and energy conserved (or only lost), E(0) < 0 keeps E(t) < 0. A run whose
// energy crosses 0 and stays above it broke that, however small the crossing is next to
// the scene's energy scale. Before this rule, a Kepler orbit broken up at its periapsis
// (box2d, bullet, chipmunk, ode at periapsis 0.01 m, dt 1e-3: the planet leaves for good)
// and chipmunk's binary blown apart in the built-in close_encounter (-0.062 J to +9.4 J)
// were `ok`: their energy drift (0.1-0.35) stayed under the scene's scale, which the pass's
// peak kinetic energy sets.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "physval_command.hpp"

namespace {

namespace fs = std::filesystem;

using physval_test::physval;
using physval_test::Result;

class BoundSystem : public physval_test::TempDirTest {
 protected:
  BoundSystem() : TempDirTest("physval_bound_") {}

  // A light planet at apoapsis 1 m of a Kepler ellipse with the given periapsis (G M = 1).
  static std::string kepler(double periapsis, const std::string& extra = "") {
    const double ra = 1.0;
    const double va = std::sqrt(2.0 * periapsis / (ra * (ra + periapsis)));
    std::ostringstream os;
    os.precision(17);
    os << "name = \"kepler\"\nduration = 6.0\ndt = 0.001\n[world]\nnewtonian = true\nG = 1.0\n"
       << "[[bodies]]\nname = \"sun\"\nshape = \"point\"\nmass = 1.0\nposition = [0.0, 0.0]\n"
       << "[[bodies]]\nname = \"planet\"\nshape = \"point\"\nmass = 0.001\nposition = [" << ra << ", 0.0]\n"
       << "velocity = [0.0, " << va << "]\n"
       << extra;
    return os.str();
  }

  nlohmann::json run_core(const fs::path& scene, int expect_status, const std::string& engines = "core") {
    const fs::path out = dir_ / ("out_" + scene.stem().string());
    const Result r = physval("run " + scene.string() + " --engines " + engines + " --quiet --no-cache --out " + out.string());
    EXPECT_EQ(r.status, expect_status) << r.output;
    std::ifstream in(out / "results.json");
    return nlohmann::json::parse(in);
  }
};

// The planet at periapsis 0.002 m and dt 1e-3: core's own step cannot follow the pass, the
// energy goes from -1e-3 J to +0.06 J and the planet leaves. The run must be diverged (it was
// ok: energy drift 0.05 of the scale), at the time the energy crossed 0 for good.
TEST_F(BoundSystem, AnOrbitBrokenUpAtItsPeriapsisIsDiverged) {
  const nlohmann::json res = run_core(write("close.toml", kepler(0.002)), 1);
  const nlohmann::json& run = res["runs"][0];
  EXPECT_EQ(run["status"], "diverged") << run.dump();
  EXPECT_NE(run["reason"].get<std::string>().find("a bound system came apart"), std::string::npos) << run.dump();
  ASSERT_TRUE(run["diverged_at"].is_number()) << run.dump();
  EXPECT_GT(run["diverged_at"].get<double>(), 0.0);
  EXPECT_LT(run["diverged_at"].get<double>(), 6.0);
}

// The same orbit with a periapsis the step resolves (0.2 m) stays bound and ok, and so does
// one whose energy error at periapsis is transient (0.05 m: core's drift 4e-4).
TEST_F(BoundSystem, AnOrbitTheStepFollowsStaysOk) {
  for (double periapsis : {0.2, 0.05}) {
    const nlohmann::json res = run_core(write("far.toml", kepler(periapsis)), 0);
    EXPECT_EQ(res["runs"][0]["status"], "ok") << periapsis << ": " << res["runs"][0].dump();
  }
}

// `[gate.<engine>] known_failures = { energy_crossed_zero = R }` accepts a break-up whose
// final energy is at most R x the binding energy (a known failure, still diverged); a worse
// one fails, and a bound that is not a finite number >= 0 is bad input (file:line:col, key).
TEST_F(BoundSystem, AKnownBreakUpIsBoundedByItsRatio) {
  // core ends at 61.3 x the binding energy (0.0612 J against -0.000998 J).
  nlohmann::json res = run_core(
      write("known.toml", kepler(0.002, "[gate.core]\nknown_failures = { energy_crossed_zero = 100 }\n")), 0);
  EXPECT_EQ(res["runs"][0]["status"], "diverged");
  EXPECT_TRUE(res["runs"][0]["known_divergence"].get<bool>()) << res["runs"][0].dump();

  res = run_core(write("worse.toml", kepler(0.002, "[gate.core]\nknown_failures = { energy_crossed_zero = 10 }\n")), 1);
  EXPECT_FALSE(res["runs"][0]["known_divergence"].get<bool>()) << res["runs"][0].dump();
  EXPECT_NE(res["runs"][0]["reason"].get<std::string>().find("more than the 10 x"), std::string::npos);

  const fs::path bad = write("bad.toml", kepler(0.002, "[gate.core]\nknown_failures = { energy_crossed_zero = -1 }\n"));
  const Result r = physval("check " + bad.string());
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find(bad.string() + ":19:"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("energy_crossed_zero"), std::string::npos) << r.output;
}

}  // namespace
