// The physval command as a user meets it: exit statuses, messages naming file, line
// and key, results.json whole, gate failures, JUnit XML a parser accepts.
#include <gtest/gtest.h>

#include "physval/adapters/registry.hpp"
#include "physval_command.hpp"

#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <nlohmann/json.hpp>

namespace {

namespace fs = std::filesystem;

using physval_test::Result;
using physval_test::physval;

class Cli : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("physval_cli_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path write(const std::string& name, const std::string& text) {
    const fs::path p = dir_ / name;
    std::ofstream(p) << text;
    return p;
  }
  fs::path dir_;
};

constexpr const char* kHeadOn = R"(name = "head_on"
duration = 1.0
dt = 0.001
engines = ["core"]

[[bodies]]
name = "a"
radius = 0.5
mass = 1.0
position = [-1.25, 0.0]
velocity = [2.0, 0.0]

[[bodies]]
name = "b"
radius = 0.5
mass = 3.0
position = [1.25, 0.0]
velocity = [-1.0, 0.0]

[expect]
first_contact = { a = "a", b = "b", time = 0.5 }
final = [ { body = "a", velocity = [-2.5, 0.0] }, { body = "b", velocity = [0.5, 0.0] } ]

[gate]
energy_drift = 1e-9
linear_momentum_drift = 1e-12
)";

TEST_F(Cli, CheckAcceptsTheBuiltInSuite) {
  const Result r = physval(std::string("check ") + PHYSVAL_SCENARIO_DIR);
  EXPECT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("scenarios valid"), std::string::npos) << r.output;
}

TEST_F(Cli, CheckNamesFileLineAndKeyAndExitsTwo) {
  const fs::path bad = write("bad.toml", "name = \"bad\"\nduration = 1.0\n[[bodies]]\nname = \"a\"\nradius = -1\nposition = [0, 0]\n");
  const Result r = physval("check " + bad.string());
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.output.find(bad.string() + ":5:"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("bodies[0].radius"), std::string::npos) << r.output;
}

// Each kind of bad input, through the command: exit 2, and "file:line:" and the key named.
TEST_F(Cli, CheckEveryKindOfBadFile) {
  const std::string head = "name = \"k\"\nduration = 1.0\n";   // lines 1-2
  const std::string body = "[[bodies]]\nname = \"a\"\nradius = 0.5\nposition = [0, 0]\n";   // lines 3-6
  struct Case {
    const char* kind;
    std::string text;
    int line;
    const char* key;
  };
  const std::vector<Case> cases = {
      {"unknown key", head + body + "colour = 3\n", 7, "bodies[0].colour"},
      {"wrong type", head + "dt = \"fast\"\n", 3, "dt"},
      {"missing required key", "name = \"k\"\n", 1, "duration"},
      {"negative mass", head + body + "mass = -2\n", 7, "bodies[0].mass"},
      {"zero mass", head + body + "mass = 0\n", 7, "bodies[0].mass"},
      {"negative radius", head + "[[bodies]]\nname = \"a\"\nradius = -1\nposition = [0, 0]\n", 5, "bodies[0].radius"},
      {"NaN", head + body + "velocity = [nan, 0]\n", 7, "bodies[0].velocity[0]"},
      {"infinity", head + "dt = inf\n", 3, "dt"},
      {"duplicate body name", head + body + body, 8, "bodies[1].name"},
      {"zero-length wall", head + "[[walls]]\nfrom = [1, 1]\nto = [1, 1]\n", 3, "walls[0].to"},
      {"non-positive dt", head + "dt = 0\n", 3, "dt"},
      {"non-positive duration", "name = \"k\"\nduration = -1\n", 2, "duration"},
      {"syntax error", head + "[[bodies]\n", 3, ""},
  };
  for (const Case& c : cases) {
    const fs::path f = write("bad.toml", c.text);
    const Result r = physval("check " + f.string());
    EXPECT_EQ(r.status, 2) << c.kind << "\n" << r.output;
    const std::string where = f.string() + ":" + std::to_string(c.line) + ":";
    EXPECT_NE(r.output.find(where), std::string::npos) << c.kind << ": wanted " << where << "\n" << r.output;
    if (*c.key != '\0') {
      EXPECT_NE(r.output.find(std::string(": ") + c.key + ": "), std::string::npos) << c.kind << "\n" << r.output;
    }
  }
}

TEST_F(Cli, RunWithBadInputRunsNothingAndWritesNothing) {
  const fs::path bad = write("bad.toml", "name = \"bad\"\nduration = 0\n");
  const Result r = physval("run " + bad.string() + " --out " + (dir_ / "out").string());
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_FALSE(fs::exists(dir_ / "out" / "results.json"));
}

TEST_F(Cli, UsageErrorsExitTwo) {
  EXPECT_EQ(physval("").status, 2);
  EXPECT_EQ(physval("frobnicate").status, 2);
  const fs::path good = write("good.toml", kHeadOn);
  EXPECT_EQ(physval("run " + good.string() + " --dt banana").status, 2);
  EXPECT_EQ(physval("run " + good.string() + " --engines nosuch").status, 2);
  EXPECT_EQ(physval("run --help").status, 0);
}

TEST_F(Cli, EnginesListsEveryEngine) {
  const Result r = physval("engines --json");
  ASSERT_EQ(r.status, 0) << r.output;
  const auto j = nlohmann::json::parse(r.output);
  std::vector<std::string> names;
  for (const auto& e : j) names.push_back(e["name"].get<std::string>());
  // Chipmunk2D and ODE follow when their Debian packages were found at build time.
  std::vector<std::string> expected{"core", "box2d", "bullet"};
  for (const char* optional : {"chipmunk", "ode"}) {
    if (physval::find_engine(optional) != nullptr) expected.push_back(optional);
  }
  EXPECT_EQ(names, expected);
}

TEST_F(Cli, RunWritesResultsJsonWithTheContractKeys) {
  const fs::path good = write("good.toml", kHeadOn);
  const fs::path out = dir_ / "out";
  const Result r = physval("run " + good.string() + " --out " + out.string());
  EXPECT_EQ(r.status, 0) << r.output;
  std::ifstream in(out / "results.json");
  ASSERT_TRUE(in.good());
  const auto j = nlohmann::json::parse(in);
  EXPECT_TRUE(j.contains("physval_version"));
  for (const char* k : {"date", "host", "build_type", "engines"}) EXPECT_TRUE(j["context"].contains(k)) << k;
  ASSERT_EQ(j["runs"].size(), 1u);
  const auto& run = j["runs"][0];
  for (const char* k : {"scenario", "engine", "engine_version", "dt", "steps", "status", "reason", "wall_seconds",
                        "metrics", "contacts", "final", "checks"}) {
    EXPECT_TRUE(run.contains(k)) << k;
  }
  for (const char* k : {"energy_drift", "linear_momentum_drift", "angular_momentum_drift", "energy_divergence",
                        "linear_momentum_divergence", "position_divergence", "first_contact_time", "contact_time_error",
                        "missed_contacts", "extra_contacts"}) {
    EXPECT_TRUE(run["metrics"].contains(k)) << k;
  }
  EXPECT_EQ(run["status"], "ok");
  EXPECT_EQ(run["steps"], 1000);
  // The table fits in 100 columns.
  std::istringstream lines(r.output);
  for (std::string line; std::getline(lines, line);) EXPECT_LE(line.size(), 100u) << line;
}

TEST_F(Cli, GateFailsWhenALimitIsTightenedBelowWhatTheEngineAchieves) {
  const fs::path good = write("good.toml", kHeadOn);
  const fs::path junit = dir_ / "junit.xml";
  Result r = physval("gate " + good.string() + " --out " + (dir_ / "o1").string() + " --junit " + junit.string());
  EXPECT_EQ(r.status, 0) << r.output;
  // Contact time is exact in core to round-off, but not to zero: a limit of 0 must fail.
  std::string tight = kHeadOn;
  tight += "contact_time_error = 0.0\nposition_divergence = 0.0\n";
  const fs::path t = write("tight.toml", tight);
  r = physval("gate " + t.string() + " --out " + (dir_ / "o2").string() + " --junit " + junit.string());
  EXPECT_EQ(r.status, 1) << r.output;
  EXPECT_NE(r.output.find("FAILED"), std::string::npos) << r.output;
  // A JUnit parser accepts the file: Python's ElementTree, counting cases and failures.
  const std::string py = "python3 -c \"import xml.etree.ElementTree as E,sys; r=E.parse(sys.argv[1]).getroot(); "
                         "s=r.find('testsuite'); c=s.findall('testcase'); "
                         "print(len(c), len([x for x in c if x.find('failure') is not None]))\" " +
                         junit.string();
  FILE* p = ::popen(py.c_str(), "r");
  ASSERT_NE(p, nullptr);
  char buf[64] = {};
  const std::size_t n = std::fread(buf, 1, sizeof buf - 1, p);
  EXPECT_EQ(::pclose(p), 0);
  EXPECT_EQ(std::string(buf, n), "1 1\n");
}

}  // namespace
