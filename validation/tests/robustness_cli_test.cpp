// Robustness of the physval command as a process: children die with their parent, the
// output folder appears whole, --out is checked before anything runs, one --timeout
// bounds the reference's runs too, and the CLI messages a user meets.
#include <gtest/gtest.h>

#include "physval_command.hpp"

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

namespace {

namespace fs = std::filesystem;

using physval_test::Result;
using physval_test::physval;

// Starts physval with these arguments, output to a file; returns its pid.
pid_t spawn_physval(const std::vector<std::string>& args, const fs::path& log) {
  const pid_t pid = ::fork();
  if (pid == 0) {
    std::FILE* f = std::freopen(log.c_str(), "w", stdout);
    if (f == nullptr) ::_exit(120);
    ::dup2(::fileno(stdout), 2);
    std::vector<char*> argv;
    std::string exe = PHYSVAL_EXE;
    argv.push_back(exe.data());
    std::vector<std::string> copy = args;
    for (std::string& a : copy) argv.push_back(a.data());
    argv.push_back(nullptr);
    ::execv(exe.c_str(), argv.data());
    ::_exit(127);
  }
  return pid;
}

// Children of every thread of pid (under -j, engine children are forked by worker threads).
std::vector<pid_t> children_of(pid_t pid) {
  std::vector<pid_t> out;
  std::error_code ec;
  for (const auto& task : fs::directory_iterator("/proc/" + std::to_string(pid) + "/task", ec)) {
    std::ifstream in(task.path() / "children");
    pid_t c;
    while (in >> c) out.push_back(c);
  }
  return out;
}

// Alive and not a zombie.
bool running(pid_t pid) {
  std::ifstream in("/proc/" + std::to_string(pid) + "/stat");
  if (!in) return false;
  std::string line;
  std::getline(in, line);
  const auto close = line.rfind(')');
  return close != std::string::npos && close + 2 < line.size() && line[close + 2] != 'Z';
}

// A scenario that runs for minutes on core: 1e8 steps of a body in flight.
constexpr const char* kLongFlight = R"(name = "long_flight"
duration = 10000.0
dt = 0.0001
engines = ["core"]

[[bodies]]
name = "ball"
radius = 0.5
mass = 1.0
position = [0.0, 0.0]
velocity = [1.0, 0.0]
)";

constexpr const char* kShortFlight = R"(name = "short_flight"
duration = 0.5
dt = 0.01
engines = ["core"]

[[bodies]]
name = "ball"
radius = 0.5
mass = 1.0
position = [0.0, 0.0]
velocity = [1.0, 0.0]
)";

class Robust : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("physval_robust_" + std::to_string(::getpid()) + "_" +
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
  // Starts `physval run` on the long scenario, waits for its engine child, sends the
  // parent `sig`, and says whether the child was gone within two seconds.
  void expect_child_dies_with_parent(int sig) {
    const fs::path scenario = write("long.toml", kLongFlight);
    const pid_t parent = spawn_physval({"run", scenario.string(), "--no-cache", "--out", (dir_ / "out").string()}, dir_ / "log.txt");
    ASSERT_GT(parent, 0);
    std::vector<pid_t> kids;
    for (int i = 0; i < 200 && kids.empty(); ++i) {
      std::this_thread::sleep_for(std::chrono::milliseconds(25));
      kids = children_of(parent);
    }
    // Under -j the reference's runs (and the engine's) may run at once: every child must go.
    ASSERT_GE(kids.size(), 1u) << "physval started no engine child";
    for (pid_t child : kids) ASSERT_TRUE(running(child));
    ::kill(parent, sig);
    int wstatus = 0;
    ::waitpid(parent, &wstatus, 0);
    EXPECT_TRUE(WIFSIGNALED(wstatus) && WTERMSIG(wstatus) == sig) << "the parent ends by the signal it got";
    for (pid_t child : kids) {
      bool gone = false;
      for (int i = 0; i < 80 && !gone; ++i) {
        gone = !running(child);
        if (!gone) std::this_thread::sleep_for(std::chrono::milliseconds(25));
      }
      if (!gone) ::kill(child, SIGKILL);   // do not leave it behind either way
      EXPECT_TRUE(gone) << "the engine child " << child << " outlived its killed parent";
    }
  }
  fs::path dir_;
};

TEST_F(Robust, SigkillOfTheParentTakesTheEngineChild) { expect_child_dies_with_parent(SIGKILL); }

TEST_F(Robust, SigtermOfTheParentIsForwardedToTheEngineChild) { expect_child_dies_with_parent(SIGTERM); }

TEST_F(Robust, SigintOfTheParentIsForwardedToTheEngineChild) { expect_child_dies_with_parent(SIGINT); }

TEST_F(Robust, KilledMidRunTheEarlierOutputStaysWhole) {
  const fs::path out = dir_ / "out";
  ASSERT_EQ(physval("run " + write("short.toml", kShortFlight).string() + " --out " + out.string()).status, 0);
  const fs::path results = out / "results.json";
  ASSERT_TRUE(fs::exists(results));
  const auto before = fs::last_write_time(results);
  const fs::path scenario = write("long.toml", kLongFlight);
  const pid_t parent = spawn_physval({"run", scenario.string(), "--out", out.string()}, dir_ / "log.txt");
  std::this_thread::sleep_for(std::chrono::milliseconds(700));
  ::kill(parent, SIGKILL);
  ::waitpid(parent, nullptr, 0);
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  EXPECT_EQ(fs::last_write_time(results), before);
  EXPECT_TRUE(fs::exists(out / "series" / "short_flight")) << "the earlier output is untouched";
  EXPECT_FALSE(fs::exists(out / "series" / "long_flight")) << "nothing of the killed run is mixed in";
}

TEST_F(Robust, OutputFolderIsReplacedWholeNotMerged) {
  const fs::path out = dir_ / "out";
  ASSERT_EQ(physval("run " + write("short.toml", kShortFlight).string() + " --out " + out.string()).status, 0);
  fs::create_directories(out / "series" / "stale");
  std::ofstream(out / "series" / "stale" / "core.csv") << "t\n0\n";
  const Result r = physval("run " + dir_.string() + "/short.toml --out " + out.string());
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_TRUE(fs::exists(out / "results.json"));
  EXPECT_FALSE(fs::exists(out / "series" / "stale")) << "an old series must not sit beside new results";
  for (const auto& e : fs::directory_iterator(dir_)) {
    EXPECT_EQ(e.path().filename().string().find(".out."), std::string::npos) << "left behind: " << e.path();
  }
}

TEST_F(Robust, OutThatIsAFileFailsBeforeAnythingRuns) {
  const fs::path file = write("taken", "x");
  const Result r = physval("gate " + write("long.toml", kLongFlight).string() + " --out " + file.string());
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find("--out: " + file.string() + " exists and is not a folder; nothing was run"), std::string::npos)
      << r.output;
}

TEST_F(Robust, OutWhereNothingCanBeWrittenFailsBeforeAnythingRuns) {
  const Result r = physval("run " + write("long.toml", kLongFlight).string() + " --out /proc/physval-out");
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find("--out: cannot write in /proc"), std::string::npos) << r.output;
}

TEST_F(Robust, OutThatIsSomeoneElsesFolderIsNotReplaced) {
  fs::create_directories(dir_ / "thesis");
  std::ofstream(dir_ / "thesis" / "chapter1.tex") << "precious";
  const Result r = physval("run " + write("short.toml", kShortFlight).string() + " --out " + (dir_ / "thesis").string());
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find("no results.json"), std::string::npos) << r.output;
  EXPECT_TRUE(fs::exists(dir_ / "thesis" / "chapter1.tex"));
}

TEST_F(Robust, OneTimeoutBoundsTheReferenceRunsAndReadsPlainly) {
  const Result r = physval("run " + write("long.toml", kLongFlight).string() + " --no-cache --timeout 0.5 --out " +
                           (dir_ / "out").string());
  EXPECT_EQ(r.status, 1) << r.output;
  EXPECT_NE(r.output.find("the reference run error: timed out after 0.5 s"), std::string::npos) << r.output;
  // One budget for an engine run and its reference: the reference used it all.
  EXPECT_NE(r.output.find("core: timed out: the reference took"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("of the --timeout budget of 0.5 s"), std::string::npos) << r.output;
}

TEST_F(Robust, EnginesOptionBeforeThePathLeavesThePathAlone) {
  const fs::path scenario = write("short.toml", kShortFlight);
  const Result r = physval("run --engines core " + scenario.string() + " --out " + (dir_ / "out").string());
  EXPECT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("1 runs: 1 ok"), std::string::npos) << r.output;
}

TEST_F(Robust, CheckCountsOneBodyInTheSingular) {
  const Result r = physval("check " + write("short.toml", kShortFlight).string());
  EXPECT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("1 body, 0 barriers, 50 steps"), std::string::npos) << r.output;
}

TEST_F(Robust, WithoutATerminalProgressIsOneLinePerScenario) {
  write("one.toml", kShortFlight);
  std::string second = kShortFlight;
  second.replace(second.find("short_flight"), 12, "second_flight");
  write("two.toml", second);
  // popen: stderr is a pipe, as in a CI log.
  const Result r = physval("run " + dir_.string() + " --out " + (dir_ / "out").string());
  ASSERT_EQ(r.status, 0) << r.output;
  // Under -j (the default: every core) the two scenarios finish in either order.
  const bool in_order = r.output.find("[1/2] short_flight\n") != std::string::npos &&
                        r.output.find("[2/2] second_flight\n") != std::string::npos;
  const bool swapped = r.output.find("[1/2] second_flight\n") != std::string::npos &&
                       r.output.find("[2/2] short_flight\n") != std::string::npos;
  EXPECT_TRUE(in_order || swapped) << r.output;
  EXPECT_EQ(r.output.find('\r'), std::string::npos) << "no carriage returns in a log";
  EXPECT_EQ(r.output.find("[1/2]"), r.output.rfind("[1/2]")) << "one line per scenario, not per engine";
}

}  // namespace
