// Engine plugins (physval/plugin.h): the loader's checks, and the test plugins of
// tests/plugins run through the real `physval` command. Each misbehaviour (a crash, a
// hang, NaN, a failing step, another ABI version) must be reported as what it is, the
// way a built-in engine's would.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <nlohmann/json.hpp>

#include "../../validation/tests/physval_command.hpp"
#include "physval/adapters/plugin_engine.hpp"
#include "physval/engine/engine.hpp"

namespace fs = std::filesystem;
using Run = physval_test::Result;
Run pv(const std::string& args) { return physval_test::physval(args); }

namespace {

const std::string kDir = PHYSVAL_TEST_PLUGIN_DIR;
const std::string kScenarios = PHYSVAL_PLUGIN_TEST_SCENARIOS;

std::string lib(const std::string& name) { return kDir + "/" + name + ".so"; }

fs::path temp_dir(const std::string& name) {
  const fs::path d = fs::path(PHYSVAL_TEST_PLUGIN_DIR).parent_path() / "plugin-test-tmp" / name;
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

nlohmann::json results(const fs::path& out) {
  std::ifstream in(out / "results.json");
  return nlohmann::json::parse(in);
}

TEST(PluginLoader, RunsTheHonestPluginThroughTheEngineInterface) {
  const physval::EngineFactory f = physval::load_plugin(lib("ballistic"));
  EXPECT_EQ(f.info.name, "ballistic");
  EXPECT_EQ(f.info.precision, physval::Precision::Float64);
  ASSERT_EQ(f.info.features.size(), 3u);
  EXPECT_EQ(f.info.features[2], physval::Feature::UniformGravity);
  ASSERT_EQ(f.info.options.size(), 1u);
  EXPECT_EQ(f.info.options[0].key, "substeps");
  EXPECT_EQ(std::get<std::int64_t>(f.info.options[0].default_value), 1);
  EXPECT_FALSE(f.info.options[0].range.contains(0.0));

  physval::Scene s;
  s.world.gravity = {0.0, -10.0};
  physval::BodyDef b;
  b.name = "shell";
  b.shape = physval::ShapeKind::Point;
  b.velocity = {10.0, 10.0};
  s.bodies.push_back(b);
  s.engine_options["ballistic"]["substeps"] = std::int64_t{3};
  auto e = f.create();
  e->load(s);
  for (int i = 0; i < 100; ++i) e->step(0.01);
  std::vector<physval::BodyState> st;
  e->read_states(st);
  ASSERT_EQ(st.size(), 1u);
  // Exact for a constant field: x = v t, y = v t - g t^2 / 2 at t = 1 s.
  EXPECT_NEAR(st[0].position.x, 10.0, 1e-12);
  EXPECT_NEAR(st[0].position.y, 5.0, 1e-12);
  EXPECT_NEAR(st[0].velocity.y, 0.0, 1e-12);
  EXPECT_NEAR(e->time(), 1.0, 1e-12);
  EXPECT_EQ(e->body_meta(0).name, "shell");
  const auto settings = e->settings();
  ASSERT_EQ(settings.size(), 2u);
  EXPECT_EQ(settings[1], (physval::Setting{"substeps", "3"}));   // the scenario's value reached the plugin
}

TEST(PluginLoader, RefusesAnotherAbiVersionByName) {
  try {
    physval::load_plugin(lib("wrongabi"));
    FAIL() << "loaded a plugin of ABI version 99";
  } catch (const physval::PluginError& e) {
    EXPECT_NE(std::string(e.what()).find("ABI version 99"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("speaks version 1"), std::string::npos) << e.what();
  }
}

TEST(PluginLoader, RefusesALibraryThatIsNoPlugin) {
  // The C math library: a real shared library without the entry point.
  const std::string libm = "libm.so.6";
  try {
    physval::load_plugin(libm);
    FAIL() << "loaded libm as a plugin";
  } catch (const physval::PluginError& e) {
    EXPECT_NE(std::string(e.what()).find("exports no function physval_plugin_v1"), std::string::npos) << e.what();
  }
}

TEST(PluginLoader, SearchPathResolvesNames) {
  EXPECT_EQ(physval::resolve_plugin_path("ballistic", "/nonexistent:" + kDir), kDir + "/ballistic.so");
  EXPECT_THROW(physval::resolve_plugin_path("nosuch", kDir), physval::PluginError);
  EXPECT_THROW(physval::resolve_plugin_path("nosuch", ""), physval::PluginError);
  EXPECT_THROW(physval::resolve_plugin_path("./nosuch.so", kDir), physval::PluginError);
}

TEST(PluginCli, GatesTheHonestPlugin) {
  const fs::path out = temp_dir("honest");
  const auto r = pv("gate " + kScenarios + " --plugin " + lib("ballistic") + " --engines ballistic --quiet --no-cache --out " +
                         out.string() + " --junit " + (out / "junit.xml").string());
  EXPECT_EQ(r.status, 0) << r.output;
  const auto j = results(out);
  ASSERT_EQ(j["runs"].size(), 1u);
  EXPECT_EQ(j["runs"][0]["engine"], "ballistic");
  EXPECT_EQ(j["runs"][0]["status"], "ok");
  EXPECT_EQ(j["runs"][0]["settings"]["integrator"], "exact constant-acceleration update");
  EXPECT_TRUE(fs::exists(out / "junit.xml"));
}

TEST(PluginCli, SearchPathVariableFindsThePluginByName) {
  const auto r = pv("engines --json --plugin ballistic");
  EXPECT_EQ(r.status, 2) << r.output;   // not a file, and no PHYSVAL_PLUGIN_PATH
  const std::string cmd = "PHYSVAL_PLUGIN_PATH=" + kDir + " " + std::string(PHYSVAL_EXE) + " engines --json --plugin ballistic";
  FILE* p = ::popen(cmd.c_str(), "r");
  ASSERT_NE(p, nullptr);
  std::string text;
  char buf[4096];
  std::size_t n;
  while ((n = std::fread(buf, 1, sizeof buf, p)) > 0) text.append(buf, n);
  ASSERT_EQ(::pclose(p), 0) << text;
  const auto engines = nlohmann::json::parse(text);
  const auto& last = engines.back();
  EXPECT_EQ(last["name"], "ballistic");
  EXPECT_EQ(last["features"], nlohmann::json({"circles", "points", "uniform_gravity"}));
  EXPECT_EQ(last["options"][0]["key"], "substeps");
  EXPECT_EQ(last["options"][0]["default"], "1");
}

// Bundled plugins load with every command, from beside the executable: <bin>/plugins in a
// build tree, <bin>/../lib/physval/plugins in an installed physval.
TEST(PluginCli, BundledPluginsLoadWithoutTheOption) {
  for (const std::string layout : {"bin/plugins", "lib/physval/plugins"}) {
    const fs::path d = temp_dir("bundled");
    fs::create_directories(d / "bin");
    fs::create_directories(d / layout);
    fs::copy_file(PHYSVAL_EXE, d / "bin" / "physval");
    fs::copy_file(lib("ballistic"), d / layout / "ballistic.so");
    const std::string exe = (d / "bin" / "physval").string();
    FILE* p = ::popen(("env -u PHYSVAL_BUNDLED_PLUGIN_DIR " + exe + " engines --json").c_str(), "r");
    ASSERT_NE(p, nullptr);
    std::string text;
    char buf[4096];
    std::size_t n;
    while ((n = std::fread(buf, 1, sizeof buf, p)) > 0) text.append(buf, n);
    ASSERT_EQ(::pclose(p), 0) << text;
    EXPECT_EQ(nlohmann::json::parse(text).back()["name"], "ballistic") << layout;
    // And its [gate.ballistic] tables are then known to `check`.
    EXPECT_EQ(std::system(("env -u PHYSVAL_BUNDLED_PLUGIN_DIR " + exe + " check " + kScenarios + " > /dev/null").c_str()), 0) << layout;
  }
}

TEST(PluginCli, CheckValidatesThePluginsOptions) {
  const fs::path d = temp_dir("check");
  std::ifstream in(kScenarios + "/projectile.toml");
  std::stringstream text;
  text << in.rdbuf();
  std::ofstream(d / "bad.toml") << text.str() << "\n[ballistic]\nsubsteps = 0\n";
  const auto r = pv("check " + (d / "bad.toml").string() + " --plugin " + lib("ballistic"));
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find("bad.toml:25:12: ballistic.substeps: must be >= 1, got 0"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("ballistic.substeps"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find(">= 1"), std::string::npos) << r.output;
  // Without the plugin, its tables are unknown: an error, not silently ignored.
  const auto without = pv("check " + (d / "bad.toml").string());
  EXPECT_EQ(without.status, 2) << without.output;
  const auto good = pv("check " + kScenarios + " --plugin " + lib("ballistic"));
  EXPECT_EQ(good.status, 0) << good.output;
}

TEST(PluginCli, AnotherAbiVersionIsBadInputNamingBoth) {
  const auto r = pv("engines --plugin " + lib("wrongabi"));
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find("built for plugin ABI version 99, but this physval speaks version 1"), std::string::npos)
      << r.output;
}

TEST(PluginCli, TwoEnginesOfOneNameAreRefused) {
  const auto r = pv("engines --plugin " + lib("ballistic") + " --plugin " + lib("ballistic"));
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find("already registered"), std::string::npos) << r.output;
}

// A misbehaving plugin, run the way CI runs it: gate, isolated, exit 1, the run's status
// and reason saying what happened.
nlohmann::json misbehaving_run(const std::string& name, const std::string& extra, int& status) {
  const fs::path out = temp_dir(name);
  const auto r = pv("gate " + kScenarios + " --plugin " + lib("ballistic") + " --plugin " + lib(name) +
                         " --engines " + name + " --quiet --no-cache --out " + out.string() + " " + extra);
  status = r.status;
  if (!fs::exists(out / "results.json")) {
    ADD_FAILURE() << r.output;
    return {};
  }
  return results(out)["runs"][0];
}

TEST(PluginCli, ACrashIsContainedAndReported) {
  int status = 0;
  const auto run = misbehaving_run("crashy", "", status);
  EXPECT_EQ(status, 1);
  EXPECT_EQ(run["status"], "error");
#if defined(__SANITIZE_ADDRESS__)
  // AddressSanitizer catches the SIGSEGV itself and aborts or exits: still a crash of the child.
  const std::string reason = run["reason"];
  EXPECT_TRUE(reason.rfind("engine crashed: signal", 0) == 0 || reason.rfind("engine process exited with status", 0) == 0)
      << reason;
#else
  EXPECT_EQ(run["reason"], "engine crashed: signal 11 (Segmentation fault)");
#endif
}

TEST(PluginCli, AHangIsStoppedByTheTimeout) {
  int status = 0;
  const auto run = misbehaving_run("hangy", "--timeout 1", status);
  EXPECT_EQ(status, 1);
  EXPECT_EQ(run["status"], "error");
  // One --timeout for the run and its reference (README: "--timeout").
  const std::string reason = run["reason"];
  EXPECT_EQ(reason.rfind("timed out", 0), 0u) << reason;
  EXPECT_NE(reason.find("the --timeout budget of 1 s"), std::string::npos) << reason;
}

TEST(PluginCli, NaNIsADivergence) {
  int status = 0;
  const auto run = misbehaving_run("nanny", "", status);
  EXPECT_EQ(status, 1);
  EXPECT_EQ(run["status"], "diverged");
  ASSERT_TRUE(run["diverged_at"].is_number()) << run.dump();
  // The velocity turns NaN in the step that starts at t = 0.05 s (dt 0.01).
  EXPECT_NEAR(run["diverged_at"].get<double>(), 0.06, 1e-9);
}

TEST(PluginCli, AFailingStepIsAnErrorWithThePluginsMessage) {
  int status = 0;
  const auto run = misbehaving_run("failing", "", status);
  EXPECT_EQ(status, 1);
  EXPECT_EQ(run["status"], "error");
  EXPECT_NE(run["reason"].get<std::string>().find("plugin failing: step failed: the solver gave up"), std::string::npos)
      << run.dump();
  const std::string kReplacement = "\xEF\xBF\xBD";   // U+FFFD
  // The message is Latin-1 with a stray byte (not UTF-8): results.json stays valid (it was
  // not written at all, exit 2, every engine's results lost), each bad byte read as U+FFFD.
  EXPECT_NE(run["reason"].get<std::string>().find(std::string("(r") + kReplacement + "ckw" + kReplacement + "rts " + kReplacement + ")"), std::string::npos)
      << run.dump();
}

TEST(PluginCli, LimitsAndABrokenGuaranteeReachTheResults) {
  int status = 0;
  const auto run = misbehaving_run("strained", "", status);
  EXPECT_EQ(status, 1);
  EXPECT_EQ(run["status"], "diverged");
  EXPECT_NE(run["reason"].get<std::string>().find("event cap reached: impacts no longer exact"), std::string::npos)
      << run.dump();
  // The step ending at 0.11 s is the first to end past 0.1 s.
  ASSERT_TRUE(run["diverged_at"].is_number()) << run.dump();
  EXPECT_NEAR(run["diverged_at"].get<double>(), 0.11, 1e-9);
  EXPECT_EQ(run["limits_hit"], nlohmann::json({"speed clamp: a body was held at 100 m/s"}));
}

TEST(PluginCli, AContactWithAnObjectThatDoesNotExistIsThePluginsError) {
  int status = 0;
  const auto run = misbehaving_run("liar", "", status);
  EXPECT_EQ(status, 1);
  EXPECT_EQ(run["status"], "error");
  EXPECT_NE(run["reason"].get<std::string>().find("plugin liar: a contact names wall 99, but there are 0"),
            std::string::npos)
      << run.dump();
}

TEST(PluginCli, SweepRunsAPlugin) {
  const fs::path out = temp_dir("sweep");
  const auto r = pv("sweep " + kScenarios + "/projectile.toml --plugin " + lib("ballistic") +
                         " --engines ballistic --dt 1/50,1/100 --repetitions 1 --quiet --no-cache --out " + out.string());
  EXPECT_EQ(r.status, 0) << r.output;
  std::ifstream in(out / "sweep.json");
  const auto j = nlohmann::json::parse(in);
  EXPECT_NE(j.dump().find("\"ballistic\""), std::string::npos);
}

}  // namespace
