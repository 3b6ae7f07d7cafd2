// The scenario loader: every kind of bad input names file, line and key; all errors
// of a file are reported; good files load with their defaults.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include <unistd.h>

#include "physval/validation/scenario_loader.hpp"

namespace physval {
namespace {

constexpr const char* kGood = R"(name = "ok"
duration = 1.0
dt = 0.01

[[bodies]]
name = "a"
radius = 0.5
mass = 2
position = [0.0, 1.0]
velocity = [1, 0]

[[walls]]
name = "floor"
from = [-1.0, 0.0]
to = [1.0, 0.0]
)";

// Parses `text` and expects exactly one error mentioning `key` on `line`.
void expect_error(const std::string& text, int line, const std::string& key, const std::string& message_part) {
  const ScenarioLoad load = parse_scenario(text, "bad.toml");
  EXPECT_FALSE(load.scene.has_value());
  ASSERT_FALSE(load.errors.empty()) << "no error for:\n" << text;
  bool found = false;
  for (const Diagnostic& d : load.errors) {
    if (d.line == line && d.key == key && d.message.find(message_part) != std::string::npos) found = true;
  }
  std::string all;
  for (const Diagnostic& d : load.errors) all += d.str() + "\n";
  EXPECT_TRUE(found) << "wanted line " << line << " key " << key << " '" << message_part << "', got:\n" << all;
  EXPECT_EQ(load.errors.front().str().rfind("bad.toml:", 0), 0u) << "messages start with the file name";
}

TEST(ScenarioLoader, GoodFileLoadsWithDefaults) {
  const ScenarioLoad load = parse_scenario(kGood, "good.toml");
  ASSERT_TRUE(load.errors.empty()) << load.errors.front().str();
  ASSERT_TRUE(load.scene);
  const Scene& s = *load.scene;
  EXPECT_EQ(s.name, "ok");
  EXPECT_EQ(s.steps(), 100);
  ASSERT_EQ(s.bodies.size(), 1u);
  EXPECT_EQ(s.bodies[0].mass, 2.0);
  EXPECT_EQ(s.bodies[0].restitution, 1.0);   // documented default: elastic
  EXPECT_EQ(s.bodies[0].friction, 0.0);
  EXPECT_EQ(s.bodies[0].velocity, (Vec2{1.0, 0.0}));
  EXPECT_EQ(s.bodies[0].line, 5);
  ASSERT_EQ(s.walls.size(), 1u);
  EXPECT_EQ(s.walls[0].name, "floor");
  EXPECT_EQ(s.world.gravity, (Vec2{}));
}

TEST(ScenarioLoader, DefaultStepIsOneSixtieth) {
  const ScenarioLoad load = parse_scenario("name = \"x\"\nduration = 1.0\n", "x.toml");
  ASSERT_TRUE(load.scene);
  EXPECT_DOUBLE_EQ(load.scene->dt, 1.0 / 60.0);
}

TEST(ScenarioLoader, UnknownKey) {
  std::string t = kGood;
  t.replace(t.find("mass = 2"), 8, "masss = 2");
  expect_error(t, 8, "bodies[0].masss", "unknown key");
}

TEST(ScenarioLoader, UnknownTopLevelTable) {
  expect_error(std::string(kGood) + "\n[wrld]\ngravity = [0, 1]\n", 17, "wrld", "unknown key");
}

TEST(ScenarioLoader, WrongType) {
  std::string t = kGood;
  t.replace(t.find("mass = 2"), 8, "mass = \"heavy\"");
  expect_error(t, 8, "bodies[0].mass", "expected a number, got a string");
}

TEST(ScenarioLoader, WrongVectorShape) {
  std::string t = kGood;
  t.replace(t.find("velocity = [1, 0]"), 17, "velocity = [1, 0, 2]");
  expect_error(t, 10, "bodies[0].velocity", "2-D vector");
}

TEST(ScenarioLoader, MissingRequiredKey) {
  std::string t = kGood;
  t.replace(t.find("duration = 1.0\n"), 15, "");
  expect_error(t, 1, "duration", "required key is missing");
}

TEST(ScenarioLoader, MissingBodyPosition) {
  std::string t = kGood;
  t.replace(t.find("position = [0.0, 1.0]\n"), 22, "");
  expect_error(t, 5, "bodies[0].position", "required key is missing");
}

TEST(ScenarioLoader, NegativeMass) {
  std::string t = kGood;
  t.replace(t.find("mass = 2"), 8, "mass = -1");
  expect_error(t, 8, "bodies[0].mass", "must be > 0");
}

TEST(ScenarioLoader, ZeroMass) {
  std::string t = kGood;
  t.replace(t.find("mass = 2"), 8, "mass = 0");
  expect_error(t, 8, "bodies[0].mass", "must be > 0");
}

TEST(ScenarioLoader, NegativeRadius) {
  std::string t = kGood;
  t.replace(t.find("radius = 0.5"), 12, "radius = -0.5");
  expect_error(t, 7, "bodies[0].radius", "must be > 0");
}

TEST(ScenarioLoader, NanAndInfinity) {
  std::string t = kGood;
  t.replace(t.find("mass = 2"), 8, "mass = nan");
  expect_error(t, 8, "bodies[0].mass", "finite");
  t = kGood;
  t.replace(t.find("velocity = [1, 0]"), 17, "velocity = [inf, 0]");
  expect_error(t, 10, "bodies[0].velocity[0]", "finite");
}

TEST(ScenarioLoader, DuplicateBodyName) {
  std::string t = std::string(kGood) + "\n[[bodies]]\nname = \"a\"\nradius = 1\nposition = [3, 3]\n";
  expect_error(t, 18, "bodies[1].name", "duplicate name \"a\"");
}

TEST(ScenarioLoader, ZeroLengthWall) {
  std::string t = kGood;
  t.replace(t.find("to = [1.0, 0.0]"), 15, "to = [-1.0, 0.0]");
  expect_error(t, 12, "walls[0].to", "non-zero length");
}

TEST(ScenarioLoader, NonPositiveStepAndDuration) {
  std::string t = kGood;
  t.replace(t.find("dt = 0.01"), 9, "dt = 0");
  expect_error(t, 3, "dt", "must be > 0");
  t = kGood;
  t.replace(t.find("duration = 1.0"), 14, "duration = -2");
  expect_error(t, 2, "duration", "must be > 0");
}

TEST(ScenarioLoader, SyntaxErrorHasLineAndColumn) {
  const ScenarioLoad load = parse_scenario("name = \"x\"\nduration = 1.0\nbodies = [ {\n", "broken.toml");
  ASSERT_EQ(load.errors.size(), 1u);
  EXPECT_EQ(load.errors[0].file, "broken.toml");
  EXPECT_GE(load.errors[0].line, 3);
  EXPECT_GT(load.errors[0].column, 0);
  EXPECT_NE(load.errors[0].message.find("syntax"), std::string::npos);
}

TEST(ScenarioLoader, ReportsEveryErrorNotJustTheFirst) {
  std::string t = kGood;
  t.replace(t.find("mass = 2"), 8, "mass = -3");
  t.replace(t.find("dt = 0.01"), 9, "dt = -1");
  t += "bogus = 1\n";
  const ScenarioLoad load = parse_scenario(t, "many.toml");
  EXPECT_EQ(load.errors.size(), 3u);
  for (std::size_t i = 1; i < load.errors.size(); ++i) EXPECT_LE(load.errors[i - 1].line, load.errors[i].line);
}

TEST(ScenarioLoader, BadNameAndUnknownReferences) {
  std::string t = kGood;
  t.replace(t.find("name = \"ok\""), 11, "name = \"Not OK\"");
  t += "\n[expect]\nfinal = [ { body = \"nobody\", velocity = [0, 0] } ]\n";
  const ScenarioLoad load = parse_scenario(t, "refs.toml");
  ASSERT_EQ(load.errors.size(), 2u);
  EXPECT_EQ(load.errors[0].key, "name");
  EXPECT_EQ(load.errors[1].key, "expect.final[0].body");
}

TEST(ScenarioLoader, StaticFrictionBelowKineticIsRejected) {
  std::string t = kGood;
  t.replace(t.find("mass = 2"), 8, "mass = 2\nfriction = 0.5\nstatic_friction = 0.2");
  expect_error(t, 5, "bodies[0].static_friction", "mu_s >= mu_k");
}

// Hunt 10: the same rule for a pair whose [[materials]] entry gives only static_friction (the
// pair's kinetic friction is the materials' geometric mean, 0.5): accepted before.
TEST(ScenarioLoader, AnOverridesStaticFrictionBelowThePairsKineticIsRejected) {
  std::string t = kGood;
  t.replace(t.find("mass = 2"), 8, "mass = 2\nfriction = 0.5");
  t += "friction = 0.5\n[[materials]]\na = \"a\"\nb = \"floor\"\nstatic_friction = 0.1\n";
  expect_error(t, 18, "materials[0].static_friction", "mu_s >= mu_k");
  // at or above the pair's kinetic friction it is a valid pair
  std::string ok = t;
  ok.replace(ok.find("static_friction = 0.1"), 21, "static_friction = 0.5");
  EXPECT_TRUE(parse_scenario(ok, "ok.toml").scene.has_value());
  // and with the pair's kinetic friction given beside it
  ok = t;
  ok.replace(ok.find("static_friction = 0.1"), 21, "friction = 0.05\nstatic_friction = 0.1");
  EXPECT_TRUE(parse_scenario(ok, "ok.toml").scene.has_value());
}

TEST(ScenarioLoader, CentreOfMassFromVertexMasses) {
  const ScenarioLoad load = parse_scenario(R"(name = "com"
duration = 1.0
[[bodies]]
name = "ship"
radius = 1.0
vertices = [[0, 0], [4, 0], [0, 4]]
vertex_masses = [2, 1, 1]
)", "com.toml");
  ASSERT_TRUE(load.scene) << load.errors.front().str();
  // xc = sum(xi mi) / sum(mi) = 4 / 4, yc = 4 / 4.
  EXPECT_DOUBLE_EQ(load.scene->bodies[0].position.x, 1.0);
  EXPECT_DOUBLE_EQ(load.scene->bodies[0].position.y, 1.0);
  EXPECT_DOUBLE_EQ(load.scene->bodies[0].mass, 4.0);
}

TEST(ScenarioLoader, ThrustTableShapeIsChecked) {
  std::string t = std::string(kGood) + "[bodies.thrust]\nspeeds = [0, 10]\ngears = [1, 2]\naccel = [[1, 2]]\n";
  expect_error(t, 19, "bodies[0].thrust.accel", "one row per gear");
}

TEST(ScenarioLoader, SuiteRejectsDuplicateScenarioNames) {
  const auto dir = std::filesystem::temp_directory_path() / ("physval_suite_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir / "sub");
  std::ofstream(dir / "one.toml") << kGood;
  std::ofstream(dir / "sub" / "two.toml") << kGood;
  const SuiteLoad load = load_suite({dir.string()});
  EXPECT_EQ(load.scenes.size(), 1u);
  ASSERT_EQ(load.errors.size(), 1u);
  EXPECT_NE(load.errors[0].message.find("already used"), std::string::npos);
  std::filesystem::remove_all(dir);
}

TEST(ScenarioLoader, BuiltInSuiteIsValid) {
  const SuiteLoad load = load_suite({PHYSVAL_SCENARIO_DIR});
  std::string all;
  for (const Diagnostic& d : load.errors) all += d.str() + "\n";
  EXPECT_TRUE(load.errors.empty()) << all;
  EXPECT_GE(load.scenes.size(), 25u);
}

}  // namespace
}  // namespace physval
