// Chipmunk2D and ODE publish their settings in results.json: the thresholds, slop or
// surface layer, iterations, sleeping and continuous collision each engine ran with.
#include <algorithm>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "../../../validation/tests/physval_command.hpp"

namespace physval::test {
namespace {

std::vector<std::string> optional_engines() {
  std::vector<std::string> out;
#ifdef PHYSVAL_HAVE_CHIPMUNK
  out.push_back("chipmunk");
#endif
#ifdef PHYSVAL_HAVE_ODE
  out.push_back("ode");
#endif
  return out;
}

class OptionalEngine : public testing::TestWithParam<std::string> {};

// `physval run` writes each run's settings into results.json: the thresholds, slop or
// surface layer, iterations, sleeping and continuous collision each engine ran with.
TEST_P(OptionalEngine, SettingsArePublishedInResultsJson) {
  const std::filesystem::path out =
      std::filesystem::path(PHYSVAL_EXE).parent_path() / "engine-settings-test-tmp" / GetParam();
  std::filesystem::remove_all(out);
  const std::string scenario = std::string(PHYSVAL_SCENARIO_DIR) + "/basics/head_on_elastic.toml";
  const physval_test::Result r = physval_test::physval("run " + scenario + " --engines " + GetParam() + " --out " +
                                                       out.string() + " --no-cache --quiet");
  ASSERT_EQ(r.status, 0) << r.output;
  std::ifstream in(out / "results.json");
  const nlohmann::json j = nlohmann::json::parse(in);
  const nlohmann::json* run = nullptr;
  for (const auto& x : j["runs"]) {
    if (x["engine"] == GetParam()) run = &x;
  }
  ASSERT_NE(run, nullptr);
  std::vector<std::string> keys;
  for (const auto& [k, v] : (*run)["settings"].items()) keys.push_back(k);
  const std::vector<std::string> wanted =
      GetParam() == "chipmunk"
          ? std::vector<std::string>{"solver_iterations", "collision_slop", "collision_bias", "sleep_time_threshold",
                                     "continuous_collision", "restitution_threshold", "material_rule", "integration"}
          : std::vector<std::string>{"step_mode", "erp", "cfm", "restitution_threshold", "contact_surface_layer",
                                     "auto_disable", "continuous_collision", "material_rule", "contact_mode"};
  for (const std::string& k : wanted) {
    EXPECT_NE(std::find(keys.begin(), keys.end(), k), keys.end()) << k << " in " << (*run)["settings"].dump();
  }
}

INSTANTIATE_TEST_SUITE_P(Adapters, OptionalEngine, testing::ValuesIn(optional_engines()));

}  // namespace
}  // namespace physval::test
