// Which quantities a scene conserves decides which drifts are measured and gated. A rule
// that claims too much fails a correct engine; one that claims a drift where nothing is
// conserved can hide a wrong one. Each case here is checked against physics: the exact
// engine (core) on a scene whose answer is known.
#include <gtest/gtest.h>

#include "physval_command.hpp"

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "physval/validation/conservation.hpp"

namespace {

namespace fs = std::filesystem;
using physval_test::physval;

// Two free discs meet off-centre with friction: their tangential impulse acts at the
// contact point, but bodies do not spin, so the torque it exerts about each centre is
// lost: orbital angular momentum changes (by (x_a - x_b) x J) while linear momentum and
// energy (e = 1, but friction dissipates) behave as physics says.
const char* kFrictionPair = R"(name = "friction_pair"
duration = 2.0
dt = 0.01
engines = ["core"]

[[bodies]]
name = "a"
radius = 0.5
mass = 1.0
position = [-2.0, 0.3]
velocity = [3.0, 0.0]
restitution = 1.0
friction = FRICTION

[[bodies]]
name = "b"
radius = 0.5
mass = 2.0
position = [2.0, -0.3]
velocity = [-1.0, 0.0]
restitution = 1.0
friction = FRICTION

[gate]
linear_momentum_drift = 1e-12
ANGULAR
)";

std::string replaced(const std::string& text, const std::string& key, const std::string& value) {
  std::string out;
  std::size_t from = 0;
  for (std::size_t at; (at = text.find(key, from)) != std::string::npos; from = at + key.size()) {
    out += text.substr(from, at - from);
    out += value;
  }
  return out + text.substr(from);
}

std::string scene_text(const std::string& friction, const std::string& angular_gate) {
  return replaced(replaced(kFrictionPair, "FRICTION", friction), "ANGULAR", angular_gate);
}

class ConservationRules : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("physval_conservation_" + std::to_string(::getpid()) + "_" +
                                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path write(const std::string& text) {
    const fs::path p = dir_ / "scene.toml";
    std::ofstream(p) << text;
    return p;
  }
  fs::path dir_;
};

TEST(ConservationRulesUnit, FrictionBetweenBodiesThatDoNotSpinBreaksAngularMomentum) {
  physval::Scene s;
  for (int i = 0; i < 2; ++i) {
    physval::BodyDef b;
    b.name = std::string(1, static_cast<char>('a' + i));
    b.radius = 0.5;
    b.mass = 1.0;
    b.position = {i == 0 ? -2.0 : 2.0, 0.0};
    s.bodies.push_back(b);
  }
  EXPECT_TRUE(physval::conserved_quantities(s).angular_momentum);
  s.bodies[0].friction = 0.4;  // one rough body against a smooth one: sqrt(f1 f2) = 0
  EXPECT_TRUE(physval::conserved_quantities(s).angular_momentum);
  s.bodies[1].friction = 0.4;
  const physval::Conserved c = physval::conserved_quantities(s);
  EXPECT_FALSE(c.angular_momentum);
  EXPECT_TRUE(c.linear_momentum) << "friction between bodies is internal: momentum still holds";
  s.bodies[1].friction = 0.0;
  s.materials.push_back(physval::MaterialOverride{"a", "b", std::nullopt, 0.3, std::nullopt, std::nullopt});
  EXPECT_FALSE(physval::conserved_quantities(s).angular_momentum) << "a [[materials]] override gives the pair friction";
}

// Before the fix the rule claimed angular momentum for this scene, and the exact engine
// failed a gate on it (drift 0.04): a verdict that fails a correct engine.
TEST_F(ConservationRules, ExactEngineWithFrictionBetweenDiscsPassesMomentumAndIsNotHeldToAngularMomentum) {
  const auto r = physval("gate " + write(scene_text("0.5", "")).string() + " --no-cache --quiet --out " +
                         (dir_ / "out").string());
  EXPECT_EQ(r.status, 0) << r.output;
  // A gate on it says plainly that it was not measured, and fails.
  const auto g = physval("gate " + write(scene_text("0.5", "angular_momentum_drift = 1e-12")).string() +
                         " --no-cache --out " + (dir_ / "out2").string());
  EXPECT_EQ(g.status, 1) << g.output;
  EXPECT_NE(g.output.find("angular_momentum_drift: not measured"), std::string::npos) << g.output;
}

// Without friction the same impact conserves angular momentum to round-off, and the gate
// holds it there.
TEST_F(ConservationRules, FrictionlessPairIsHeldToAngularMomentum) {
  const auto r = physval("gate " + write(scene_text("0.0", "angular_momentum_drift = 1e-12")).string() +
                         " --no-cache --out " + (dir_ / "out").string());
  EXPECT_EQ(r.status, 0) << r.output;
}

}  // namespace
