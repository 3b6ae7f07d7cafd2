// With PHYSVAL_OPTIONAL_ENGINES_BUILTIN=ON: libphysval_chipmunk.so and libphysval_ode.so,
// the adapters through the plugin ABI (physval/plugin.h) loaded by physval's own loader,
// run every built-in scenario they can model bit for bit like the built-in engines of the
// same name.
#include <algorithm>
#include <filesystem>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "../adapter_test_scenes.hpp"
#include "physval/adapters/plugin_engine.hpp"
#include "physval/validation/scenario_loader.hpp"

namespace physval::test {
namespace {

std::vector<std::string> built_plugins() {
  std::vector<std::string> out;
#ifdef PHYSVAL_HAVE_CHIPMUNK
  out.push_back("chipmunk");
#endif
#ifdef PHYSVAL_HAVE_ODE
  out.push_back("ode");
#endif
  return out;
}

std::string plugin_path(const std::string& engine) {
  return std::string(PHYSVAL_ENGINE_PLUGIN_DIR) + "/libphysval_" + engine + ".so";
}

class EnginePlugin : public testing::TestWithParam<std::string> {};

TEST_P(EnginePlugin, DeclaresWhatTheBuiltInEngineDeclares) {
  const EngineFactory plugin = load_plugin(plugin_path(GetParam()));
  const EngineFactory* builtin = find_engine(GetParam());
  ASSERT_NE(builtin, nullptr);
  EXPECT_EQ(plugin.info.name, builtin->info.name);
  EXPECT_EQ(plugin.info.version, builtin->info.version);
  EXPECT_EQ(plugin.info.precision, builtin->info.precision);
  auto sorted = [](std::vector<Feature> f) {
    std::sort(f.begin(), f.end());
    return f;
  };
  EXPECT_EQ(sorted(plugin.info.features), sorted(builtin->info.features));
  ASSERT_EQ(plugin.info.options.size(), builtin->info.options.size());
  for (std::size_t i = 0; i < plugin.info.options.size(); ++i) {
    EXPECT_EQ(plugin.info.options[i].key, builtin->info.options[i].key);
    EXPECT_EQ(plugin.info.options[i].default_value, builtin->info.options[i].default_value) << plugin.info.options[i].key;
    EXPECT_EQ(plugin.info.options[i].choices, builtin->info.options[i].choices);
  }
}

// Every built-in scenario the engine can model: the plugin's states, contacts, settings
// and limits equal the built-in engine's, step by step, bit for bit.
TEST_P(EnginePlugin, RunsEveryBuiltInScenarioBitForBitLikeTheBuiltInEngine) {
  const EngineFactory plugin = load_plugin(plugin_path(GetParam()));
  const EngineFactory* builtin = find_engine(GetParam());
  int scenarios = 0;
  for (const auto& entry : std::filesystem::recursive_directory_iterator(PHYSVAL_SCENARIO_DIR)) {
    if (entry.path().extension() != ".toml") continue;
    const ScenarioLoad l = load_scenario_file(entry.path());
    ASSERT_TRUE(l.errors.empty()) << entry.path();
    const Scene& s = *l.scene;
    if (!unsupported_features(builtin->info, s).empty()) continue;
    if (!s.engines.empty() && std::find(s.engines.begin(), s.engines.end(), GetParam()) == s.engines.end()) continue;
    // A few hundred steps of each: enough to meet every contact of the short scenes.
    const int steps = std::min(s.steps(), 600);
    auto a = builtin->create();
    auto b = plugin.create();
    a->load(s);
    b->load(s);
    for (int n = 0; n < steps; ++n) {
      a->step(s.dt);
      b->step(s.dt);
      const auto sa = states(*a);
      const auto sb = states(*b);
      ASSERT_EQ(sa.size(), sb.size());
      for (std::size_t i = 0; i < sa.size(); ++i) {
        ASSERT_EQ(sa[i].position.x, sb[i].position.x) << s.name << " step " << n << " body " << i;
        ASSERT_EQ(sa[i].position.y, sb[i].position.y) << s.name << " step " << n << " body " << i;
        ASSERT_EQ(sa[i].velocity.x, sb[i].velocity.x) << s.name << " step " << n << " body " << i;
        ASSERT_EQ(sa[i].velocity.y, sb[i].velocity.y) << s.name << " step " << n << " body " << i;
        ASSERT_EQ(sa[i].alive, sb[i].alive) << s.name << " step " << n << " body " << i;
      }
      ASSERT_EQ(a->contacts().size(), b->contacts().size()) << s.name << " step " << n;
      for (std::size_t k = 0; k < a->contacts().size(); ++k) {
        EXPECT_TRUE(a->contacts()[k].a == b->contacts()[k].a && a->contacts()[k].b == b->contacts()[k].b);
        EXPECT_EQ(a->contacts()[k].time, b->contacts()[k].time);
      }
    }
    EXPECT_EQ(a->settings(), b->settings()) << s.name;
    // ODE keeps one message handler per process, and this test holds two copies of the
    // ODE adapter (built in and plugin; physval itself never loads both, names being
    // unique): its messages reach one copy only. Every other limit must match.
    auto without_messages = [](std::vector<std::string> v) {
      std::erase_if(v, [](const std::string& line) { return line.rfind("ode_message", 0) == 0; });
      return v;
    };
    EXPECT_EQ(without_messages(a->limits_hit()), without_messages(b->limits_hit())) << s.name;
    ++scenarios;
  }
  EXPECT_GE(scenarios, 25);
}

INSTANTIATE_TEST_SUITE_P(Adapters, EnginePlugin, testing::ValuesIn(built_plugins()));

}  // namespace
}  // namespace physval::test
