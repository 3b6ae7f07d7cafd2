// The loader's bounds, name rules, fractions and messages (issue 10, items 12-14), and
// the CLI messages around them, run through the real executable where a user meets them.
#include <gtest/gtest.h>

#include "physval_command.hpp"

#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include "physval/validation/scenario_loader.hpp"

namespace {

namespace fs = std::filesystem;
using namespace physval;

std::string all_errors(const ScenarioLoad& load) {
  std::string out;
  for (const Diagnostic& d : load.errors) out += d.str() + "\n";
  return out;
}

constexpr const char* kHead = R"(name = "limits"
duration = 1.0
dt = 0.01
)";

std::string body(const std::string& name, double x) {
  return "\n[[bodies]]\nname = \"" + name + "\"\nradius = 0.5\nmass = 1.0\nposition = [" + std::to_string(x) +
         ", 0.0]\n";
}

TEST(LoaderNames, BodyNamesWithCommasNewlinesOrEscapesAreRefusedAndShownEscaped) {
  for (const std::string& bad : {std::string("a,b"), std::string("a\\nb"), std::string("a\\u001b[31m"),
                                 std::string("Ball"), std::string("")}) {
    const ScenarioLoad load = parse_scenario(std::string(kHead) + body(bad, 0.0), "n.toml");
    ASSERT_FALSE(load.scene) << bad;
    const std::string e = all_errors(load);
    EXPECT_NE(e.find("n.toml:6:8: bodies[0].name: must match [a-z0-9_]+"), std::string::npos) << e;
    EXPECT_EQ(e.find('\x1b'), std::string::npos) << "a terminal escape must not reach the terminal";
  }
  const ScenarioLoad ok = parse_scenario(std::string(kHead) + body("ball_2", 0.0), "n.toml");
  EXPECT_TRUE(ok.scene) << all_errors(ok);
}

TEST(LoaderNames, BarrierNamesFollowTheSameRule) {
  const ScenarioLoad load = parse_scenario(std::string(kHead) +
                                               "\n[[walls]]\nname = \"floor,1\"\nfrom = [-1.0, 0.0]\nto = [1.0, 0.0]\n",
                                           "n.toml");
  ASSERT_FALSE(load.scene);
  EXPECT_NE(all_errors(load).find("walls[0].name: must match [a-z0-9_]+"), std::string::npos) << all_errors(load);
}

TEST(LoaderFractions, DtMayBeAFractionInQuotes) {
  const ScenarioLoad load = parse_scenario("name = \"f\"\nduration = 1.0\ndt = \"1/120\"\n" + body("a", 0.0), "f.toml");
  ASSERT_TRUE(load.scene) << all_errors(load);
  EXPECT_DOUBLE_EQ(load.scene->dt, 1.0 / 120.0);
  EXPECT_EQ(load.scene->steps(), 120);
}

TEST(LoaderFractions, ABadFractionSaysHowToWriteOne) {
  for (const char* bad : {"1/0", "one/60", "1/", "1/60x"}) {
    const ScenarioLoad load =
        parse_scenario("name = \"f\"\nduration = 1.0\ndt = \"" + std::string(bad) + "\"\n" + body("a", 0.0), "f.toml");
    ASSERT_FALSE(load.scene) << bad;
    EXPECT_NE(all_errors(load).find("f.toml:3:6: dt: expected a number, got a string \"" + std::string(bad) +
                                      "\" (a fraction is written in quotes: \"1/120\")"),
              std::string::npos)
        << all_errors(load);
  }
}

TEST(LoaderBounds, EmitterCountStatesItsBoundOnce) {
  const ScenarioLoad load = parse_scenario(std::string(kHead) + body("a", 0.0) +
                                               "\n[[emitters]]\nparent = \"a\"\ncount = 100000000\n",
                                           "b.toml");
  ASSERT_FALSE(load.scene);
  EXPECT_NE(all_errors(load).find("emitters[0].count: must be a whole number from 0 to 1000000, got 100000000"),
            std::string::npos)
      << all_errors(load);
  // ... and does not then contradict itself with "needs count > 0" (the count was refused).
  EXPECT_EQ(all_errors(load).find("needs count > 0"), std::string::npos) << all_errors(load);
}

TEST(LoaderBounds, ParticlesFromATrailBeyondTheBoundAreRefusedBeforeRunning) {
  // 1e9 particles a second for a second: would grow without bound while running.
  const ScenarioLoad load = parse_scenario(std::string(kHead) + body("a", 0.0) +
                                               "\n[[emitters]]\nparent = \"a\"\nmode = \"trail\"\nrate = 1e9\n",
                                           "b.toml");
  ASSERT_FALSE(load.scene);
  EXPECT_NE(all_errors(load).find("1 body and up to 1000000000 particles from emitters: more than physval's bound of "
                                  "200000 objects"),
            std::string::npos)
      << all_errors(load);
}

TEST(LoaderMessages, SampleIntervalErrorPointsAtItsLine) {
  const ScenarioLoad load = parse_scenario(std::string(kHead) + "sample_interval = 0.001\n" + body("a", 0.0), "s.toml");
  ASSERT_FALSE(load.scene);
  EXPECT_NE(all_errors(load).find("s.toml:4:19: sample_interval: must be >= dt (0.01) or 0 for automatic, got 0.001"),
            std::string::npos)
      << all_errors(load);
}

TEST(LoaderMessages, DuplicateNameErrorHasLineAndColumn) {
  const ScenarioLoad load = parse_scenario(std::string(kHead) + body("a", 0.0) + body("a", 3.0), "d.toml");
  ASSERT_FALSE(load.scene);
  EXPECT_NE(all_errors(load).find("d.toml:12:8: bodies[1].name: duplicate name \"a\" (already used by a body)"),
            std::string::npos)
      << all_errors(load);
}

class LoaderFiles : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("physval_limits_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path dir_;
};

TEST_F(LoaderFiles, AFileGivenTwiceIsLoadedOnceNotUsedByItself) {
  const fs::path f = dir_ / "one.toml";
  std::ofstream(f) << kHead << body("a", 0.0);
  const SuiteLoad load = load_suite({f.string(), dir_.string(), (dir_ / "." / "one.toml").string()});
  EXPECT_TRUE(load.errors.empty()) << (load.errors.empty() ? "" : load.errors.front().str());
  EXPECT_EQ(load.scenes.size(), 1u);
}

using physval_test::Result;
using physval_test::physval;

TEST_F(LoaderFiles, SweepGivenAFolderSaysSo) {
  const Result r = physval("sweep " + dir_.string());
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find("is a folder; sweep takes one scenario file"), std::string::npos) << r.output;
}

TEST_F(LoaderFiles, SweepWithEveryEngineUnsupportedFailsWithoutATable) {
  const fs::path f = dir_ / "p.toml";
  std::ofstream(f) << kHead << body("a", 0.0) << "\n[[emitters]]\nparent = \"a\"\ncount = 10\nspeed = 1.0\n";
  const Result r = physval("sweep " + f.string() + " --engines box2d,bullet --out " + (dir_ / "sw").string());
  EXPECT_EQ(r.status, 1) << r.output;
  EXPECT_NE(r.output.find("sweep measured nothing"), std::string::npos) << r.output;
  EXPECT_EQ(r.output.find("engine"), r.output.find("engine given")) << "no table header: " << r.output;
}

}  // namespace
