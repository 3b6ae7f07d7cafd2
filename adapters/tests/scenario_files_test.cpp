// The shared scenario files (validation/scenarios), read by the TOML loader and run on
// both adapters: the same scenes core is checked against.
#include <filesystem>
#include <string>

#include <gtest/gtest.h>

#include "adapter_test_scenes.hpp"
#include "physval/validation/scenario_loader.hpp"

namespace physval::test {
namespace {

Scene load(const std::string& relative) {
  const ScenarioLoad l = load_scenario_file(std::filesystem::path(PHYSVAL_SCENARIO_DIR) / relative);
  if (!l.scene) {
    std::string all;
    for (const Diagnostic& d : l.errors) all += d.str() + "\n";
    throw std::runtime_error("cannot load " + relative + ":\n" + all);
  }
  return *l.scene;
}

class ScenarioFiles : public ::testing::TestWithParam<std::string> {};

// Final velocities of the elastic two-body files: the 1e-6 m/s.
TEST_P(ScenarioFiles, ElasticPairsMeetTheirClosedForms) {
  for (const char* file : {"basics/head_on_elastic.toml", "basics/equal_mass_swap.toml"}) {
    const Scene s = load(file);
    ASSERT_FALSE(s.expect.final_states.empty()) << file;
    auto e = make_engine(GetParam(), s);
    const auto events = run(*e, s, s.steps());
    const auto st = states(*e);
    for (const ExpectedFinal& f : s.expect.final_states) {
      const int i = s.body_index(f.body);
      ASSERT_GE(i, 0);
      ASSERT_TRUE(f.velocity.has_value());
      EXPECT_NEAR(st[i].velocity.x, f.velocity->x, 1e-6) << file << " " << f.body;
      EXPECT_NEAR(st[i].velocity.y, f.velocity->y, 1e-6) << file << " " << f.body;
    }
    // First contact: quantised to the step, at the step holding the analytic time or
    // the next (detected at the start of the following step).
    ASSERT_TRUE(s.expect.first_contact.has_value());
    ASSERT_FALSE(events.empty()) << file;
    EXPECT_GE(events[0].time, s.expect.first_contact->time - 1e-9) << file;
    EXPECT_LE(events[0].time, s.expect.first_contact->time + 2.0 * s.dt + 1e-9) << file;
  }
}

TEST_P(ScenarioFiles, CollisionMatrixFileRunsItsThreeResponses) {
  const Scene s = load("models/collision_matrix.toml");
  auto e = make_engine(GetParam(), s);
  const auto events = run(*e, s, s.steps());
  // prize (event), brick (destroyed after the bounce), prize again; the ghost is ignored.
  ASSERT_EQ(events.size(), s.expect.contacts.size());
  for (std::size_t k = 0; k < events.size(); ++k) {
    EXPECT_EQ(events[k].b.index, static_cast<std::uint32_t>(s.body_index(s.expect.contacts[k].b))) << k;
    // A pair begins when a step ends with it overlapping, seen at the start of the next
    // step (2 steps of quantisation); Bullet reflects the ball off the brick from where
    // it had penetrated, which puts it up to one more step behind: 3 steps.
    EXPECT_NEAR(events[k].time, s.expect.contacts[k].time, 3.0 * s.dt + 1e-9) << k;
  }
  const auto st = states(*e);
  EXPECT_FALSE(st[s.body_index("brick")].alive);
  EXPECT_TRUE(st[s.body_index("prize")].alive);
  EXPECT_NEAR(st[s.body_index("ball")].velocity.x, -2.0, 1e-6);
}

TEST_P(ScenarioFiles, EveryBuiltInScenarioLoadsOrIsUnsupportedByName) {
  // Every file either runs a step on this engine or names what it cannot model.
  const EngineFactory* f = find_engine(GetParam());
  ASSERT_NE(f, nullptr);
  const SuiteLoad suite = load_suite({PHYSVAL_SCENARIO_DIR});
  ASSERT_TRUE(suite.errors.empty());
  ASSERT_FALSE(suite.scenes.empty());
  for (const Scene& s : suite.scenes) {
    const auto missing = unsupported_features(f->info, s);
    if (!missing.empty()) continue;
    auto e = f->create();
    ASSERT_NO_THROW(e->load(s)) << s.name;
    e->step(s.dt);
    EXPECT_EQ(e->body_count(), s.bodies.size()) << s.name;
    EXPECT_FALSE(e->settings().empty()) << s.name;
  }
}

std::vector<std::string> adapter_names() {
  std::vector<std::string> all = {"box2d", "bullet"};
#ifdef PHYSVAL_HAVE_CHIPMUNK
  all.push_back("chipmunk");   // built in when its Debian package was found
#endif
#ifdef PHYSVAL_HAVE_ODE
  all.push_back("ode");
#endif
  return all;
}

INSTANTIATE_TEST_SUITE_P(Adapters, ScenarioFiles, ::testing::ValuesIn(adapter_names()),
                         [](const ::testing::TestParamInfo<std::string>& i) { return i.param; });

}  // namespace
}  // namespace physval::test
