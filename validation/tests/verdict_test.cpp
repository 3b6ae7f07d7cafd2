// Wrong greens (issue 10): a verdict that checked nothing, or measured the wrong thing,
// must not pass. Each test here failed before its fix.
#include <gtest/gtest.h>

#include "physval_command.hpp"

#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

namespace {

namespace fs = std::filesystem;

using physval_test::Result;
using physval_test::physval;

bool has(const Result& r, const std::string& text) { return r.output.find(text) != std::string::npos; }

class Verdict : public physval_test::TempDirTest {
 protected:
  Verdict() : TempDirTest("physval_verdict_") {}
  std::string out() const { return " --quiet --out " + (dir_ / "out").string(); }
};

// One ball falling onto the floor, on core only; the gate is whatever the test appends.
const std::string kDrop = R"(name = "drop"
duration = 0.5
dt = 0.01
engines = ["core"]

[world]
gravity = [0.0, -9.81]

[[bodies]]
name = "ball"
radius = 0.5
mass = 1.0
position = [0.0, 5.0]
)";

// Item 1: ceil(duration / dt) wrapped past 2^31 to a negative count and ran 0 steps, green.
TEST_F(Verdict, StepCountPastTheLimitIsRefusedNotWrapped) {
  const fs::path f = write("tiny_dt.toml", "name = \"tiny\"\nduration = 1.0\ndt = 2e-10\n"
                                           "[[bodies]]\nname = \"a\"\nradius = 0.5\nposition = [0, 0]\n");
  const Result r = physval("check " + f.string());
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_TRUE(has(r, f.string() + ":3:")) << r.output;
  EXPECT_TRUE(has(r, "dt")) << r.output;
  EXPECT_TRUE(has(r, "more than physval runs")) << r.output;
  EXPECT_FALSE(has(r, "-2147483648")) << r.output;

  const fs::path drop = write("drop.toml", kDrop + "[gate]\nenergy_drift = 1\n");
  const Result g = physval("gate " + drop.string() + " --duration 1e9" + out());
  EXPECT_EQ(g.status, 2) << g.output;
  EXPECT_TRUE(has(g, "more than physval runs")) << g.output;
}

// Item 6: out-of-range engine options passed `check`, then failed `run` without a
// location, or ran (Bullet's ball fell through the floor).
TEST_F(Verdict, CheckRejectsEngineOptionsOutOfRange) {
  const std::string head = "name = \"k\"\nduration = 1.0\n[[bodies]]\nname = \"a\"\nradius = 0.5\nposition = [0, 0]\n";
  struct Case {
    std::string table, key, value;
  };
  const std::vector<Case> cases = {{"box2d", "velocity_iterations", "-1"},
                                   {"core", "max_events_per_step", "-1"},
                                   {"bullet", "contact_processing_threshold", "-1"},
                                   {"bullet", "erp", "1.5"},
                                   {"bullet", "solver_iterations", "0"},
                                   {"core", "cell_size", "nan"}};
  for (const Case& c : cases) {
    const fs::path f = write(c.table + "_" + c.key + ".toml", head + "[" + c.table + "]\n" + c.key + " = " + c.value + "\n");
    const Result r = physval("check " + f.string());
    EXPECT_EQ(r.status, 2) << c.key << ": " << r.output;
    EXPECT_TRUE(has(r, f.string() + ":8:")) << c.key << ": " << r.output;
    EXPECT_TRUE(has(r, c.table + "." + c.key)) << c.key << ": " << r.output;
  }
  // In range still passes.
  const fs::path ok = write("ok.toml", head + "[box2d]\nvelocity_iterations = 1\n[bullet]\nerp = 1.0\n");
  EXPECT_EQ(physval("check " + ok.string()).status, 0);
}

// Item 3: gates that checked nothing.
TEST_F(Verdict, GateWithoutLimitsOrExpectationsFails) {
  const fs::path f = write("drop.toml", kDrop);
  const Result r = physval("gate " + f.string() + out());
  EXPECT_EQ(r.status, 1) << r.output;
  // `run` is not a gate: the same scenario runs fine.
  EXPECT_EQ(physval("run " + f.string() + out()).status, 0);
}

TEST_F(Verdict, GateWithNoRunFails) {
  const fs::path f = write("drop.toml", kDrop + "[gate]\nenergy_drift = 1\n");
  const Result r = physval("gate --engines box2d" + out() + " " + f.string());
  EXPECT_EQ(r.status, 1) << r.output;
  EXPECT_TRUE(has(r, "nothing was checked")) << r.output;
}

TEST_F(Verdict, NanFlagsAreBadInput) {
  const fs::path f = write("drop.toml", kDrop + "[gate]\nenergy_drift = 1\n");
  const Result b = physval("gate " + f.string() + out() + " --baseline " + f.string() + " --baseline-factor nan");
  EXPECT_EQ(b.status, 2) << b.output;
  const Result t = physval("gate " + f.string() + out() + " --timeout nan");
  EXPECT_EQ(t.status, 2) << t.output;
  EXPECT_TRUE(has(t, "--timeout")) << t.output;
}

TEST_F(Verdict, BaselineThatMatchesNoRunOrAnotherDtFails) {
  const fs::path f = write("drop.toml", kDrop + "[gate]\nenergy_drift = 1\n");
  const fs::path empty = write("empty.json", R"({"runs": []})");
  const Result none = physval("gate " + f.string() + out() + " --baseline " + empty.string());
  EXPECT_EQ(none.status, 2) << none.output;
  EXPECT_TRUE(has(none, "matches no run")) << none.output;

  const fs::path other = write("other.json", R"({"runs": [{"scenario": "drop", "engine": "core", "dt": 0.001,
                                                           "metrics": {"energy_drift": 1.0}}]})");
  const Result dt = physval("gate " + f.string() + out() + " --baseline " + other.string());
  EXPECT_EQ(dt.status, 1) << dt.output;
}

}  // namespace

namespace {

// Item 7: bodies overlapping at t = 0 were accepted silently.
TEST_F(Verdict, InitialOverlapIsAnErrorUnlessOptedIn) {
  const std::string two = "[[bodies]]\nname = \"a\"\nradius = 0.5\nposition = [0, 0]\n"
                          "[[bodies]]\nname = \"b\"\nradius = 0.5\nposition = [0.9, 0]\n";   // lines 3-10
  const fs::path f = write("overlap.toml", "name = \"o\"\nduration = 1.0\n" + two);
  const Result r = physval("check " + f.string());
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_TRUE(has(r, f.string() + ":10:")) << r.output;
  EXPECT_TRUE(has(r, "bodies[1].position")) << r.output;
  EXPECT_TRUE(has(r, "overlaps body \"a\"")) << r.output;

  const fs::path opt = write("opt.toml", "name = \"o\"\nduration = 1.0\nallow_initial_overlap = true\n" + two);
  EXPECT_EQ(physval("check " + opt.string()).status, 0);
  // Touching is not overlapping.
  const fs::path touch = write("touch.toml", "name = \"t\"\nduration = 1.0\n[[bodies]]\nname = \"a\"\nradius = 0.5\n"
                                             "position = [0, 0]\n[[bodies]]\nname = \"b\"\nradius = 0.5\nposition = [1, 0]\n");
  EXPECT_EQ(physval("check " + touch.string()).status, 0);
}

}  // namespace

namespace {

std::string read_text(const fs::path& p) {
  std::ifstream in(p);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// Item 2: the reference's convergence limit scaled with the scene's extent, so one body
// parked 1e7 m away made the chaotic gas's reference "converged" (limit ~10 m).
TEST_F(Verdict, AFarBodyDoesNotLoosenAnotherBodysConvergenceLimit) {
  std::string gas = read_text(fs::path(PHYSVAL_SCENARIO_DIR) / "models" / "circle_gas.toml");
  const std::size_t walls = gas.find("[[walls]]");
  const std::size_t gate = gas.find("[gate");
  ASSERT_NE(walls, std::string::npos);
  ASSERT_NE(gate, std::string::npos);
  const std::string far = "[[bodies]]\nname = \"far\"\nradius = 0.05\nposition = [1e7, 0.0]\n\n";
  const std::string base = gas.substr(0, gate);
  const std::string with_far = gas.substr(0, walls) + far + gas.substr(walls, gate - walls);
  for (const auto& [name, text] : {std::pair{"gas", base}, std::pair{"gas_far", with_far}}) {
    const fs::path f = write(std::string(name) + ".toml", text + "[gate]\nenergy_drift = 1\n");
    const fs::path o = dir_ / name;
    const Result r = physval("run --engines core --quiet --out " + o.string() + " " + f.string());
    ASSERT_NE(r.status, 2) << r.output;
    const std::string results = read_text(o / "results.json");
    // Not converged, with or without the far body, and the reason names a gas body.
    EXPECT_NE(results.find("\"converged\": false"), std::string::npos) << name;
    EXPECT_EQ(results.find("\"converged\": true"), std::string::npos) << name;
  }
}

}  // namespace

#include "physval/validation/comparator.hpp"

namespace {

// Item 8: a body destroyed exactly at a sample time, with the two runs' clocks on either
// side of it, made an energy divergence of 0.75 between runs whose positions agree.
TEST(VerdictCompare, DestructionAtASampleTimeIsNotAnEnergyDivergence) {
  physval::Scene scene;
  scene.name = "destroy";
  scene.dt = 0.1;
  scene.duration = 0.3;
  scene.bodies.resize(2);
  scene.bodies[0].name = "keep";
  scene.bodies[0].radius = 0.5;
  scene.bodies[0].velocity = {1.0, 0.0};
  scene.bodies[1].name = "gone";
  scene.bodies[1].radius = 0.5;
  scene.bodies[1].position = {5.0, 0.0};
  scene.bodies[1].velocity = {1.0, 0.0};
  auto record = [&](const std::string& engine, double clock_offset, bool gone_at_sample_1, bool gone_at_sample_2) {
    physval::RunRecord r;
    r.engine = engine;
    r.dt = 0.1;
    for (int k = 0; k < 4; ++k) {
      const double t = 0.1 * k + (k == 1 ? clock_offset : 0.0);
      const bool gone = (k == 1 && gone_at_sample_1) || (k >= 2 && gone_at_sample_2);
      physval::BodyState a{{t, 0.0}, {1.0, 0.0}};
      physval::BodyState b{{5.0 + t, 0.0}, {1.0, 0.0}};
      b.alive = !gone;
      r.series.time.push_back(t);
      r.series.states.push_back({a, b});
      physval::Totals tot;
      tot.kinetic = gone ? 0.5 : 1.0;
      tot.momentum = {gone ? 1.0 : 2.0, 0.0};
      r.series.totals.push_back(tot);
    }
    return r;
  };
  // Destroyed at t = 0.1: one clock a hair past it (gone), the other a hair before (alive).
  const physval::RunRecord a = record("a", 1e-13, true, true);
  const physval::RunRecord b = record("b", -1e-13, false, true);
  const physval::PairComparison same = physval::compare_pair(a, b, scene);
  ASSERT_TRUE(same.metrics.at("energy_divergence").has_value());
  EXPECT_LT(*same.metrics.at("energy_divergence"), 1e-12);
  ASSERT_TRUE(same.metrics.at("position_divergence").has_value());
  EXPECT_LT(*same.metrics.at("position_divergence"), 1e-12);

  // A destruction that really differs (b never destroys it) is still an energy divergence.
  const physval::RunRecord never = record("c", 0.0, false, false);
  const physval::PairComparison differs = physval::compare_pair(a, never, scene);
  ASSERT_TRUE(differs.metrics.at("energy_divergence").has_value());
  EXPECT_GT(*differs.metrics.at("energy_divergence"), 0.1);
}

}  // namespace

#include <nlohmann/json.hpp>

namespace {

// Item 5: a run that let bodies out of a closed box was `ok`. Now escaped_bodies counts
// them and the run is diverged at the first escape; max_penetration is measured.
TEST_F(Verdict, EscapeFromAClosedBoxIsDiverged) {
  const fs::path f = write("box.toml", R"(name = "box"
duration = 1.0
dt = 0.05
[[bodies]]
name = "fast"
radius = 0.05
position = [0.0, 0.0]
velocity = [40.0, 0.0]
[[walls]]
from = [-1.0, -1.0]
to = [1.0, -1.0]
[[walls]]
from = [1.0, -1.0]
to = [1.0, 1.0]
[[walls]]
from = [1.0, 1.0]
to = [-1.0, 1.0]
[[walls]]
from = [-1.0, 1.0]
to = [-1.0, -1.0]
[bullet]
wall_half_thickness = 0.0
[gate]
escaped_bodies = 0
)");
  const fs::path o = dir_ / "out";
  const Result r = physval("run --engines core,bullet --quiet --out " + o.string() + " " + f.string());
  const nlohmann::json results = nlohmann::json::parse(read_text(o / "results.json"));
  bool saw_core = false, saw_bullet = false;
  for (const nlohmann::json& run : results["runs"]) {
    const nlohmann::json& m = run["metrics"];
    ASSERT_TRUE(m.contains("escaped_bodies") && m.contains("max_penetration")) << run.dump();
    if (run["engine"] == "core") {
      saw_core = true;
      EXPECT_EQ(m["escaped_bodies"].get<double>(), 0.0) << run.dump();
      EXPECT_EQ(run["status"], "ok") << run.dump();
    } else {
      saw_bullet = true;
      // 40 m/s at dt 0.05 is a 2 m step: discrete Bullet steps over the wall.
      EXPECT_EQ(m["escaped_bodies"].get<double>(), 1.0) << run.dump();
      EXPECT_EQ(run["status"], "diverged") << run.dump();
    }
  }
  EXPECT_TRUE(saw_core && saw_bullet) << r.output;
  EXPECT_EQ(r.status, 1) << r.output;
}

}  // namespace
