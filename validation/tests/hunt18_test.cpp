// The eighteenth hunt (README, *The eighteenth hunt*): containment's passes of two circles
// into each other, on core's exact runs.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <filesystem>
#include <fstream>
#include <string>

#include "physval_command.hpp"

namespace physval {
namespace {

namespace fs = std::filesystem;

class Hunt18 : public physval_test::TempDirTest {
 protected:
  Hunt18() : TempDirTest("physval_hunt18_") {}
};

// A step's bend is now the smaller of |dx - v0 h| and |dx - v1 h|; the mean velocity's
// reading, taken before, matched a small ball's path bounced several times within a step
// against large ones. core's exact runs of mixed gases (5 and 30 cm circles at 10-30 m/s a
// side, dt 1/60; the eighteenth and nineteenth hunts' four reproducers) were `diverged`
// with 2-5 bodies "passed into" others they had bounced off, at max penetration 0.
TEST_F(Hunt18, CoresExactRunsOfAFastMixedGasPassNobodyThroughAnybody) {
  for (const char* file : {"mixed_gas_10ms.toml", "mixed_gas_30ms.toml", "core_false_pass_small.toml", "mixed_gas_core_false_pass.toml"}) {
    SCOPED_TRACE(file);
    const fs::path scene = fs::path(PHYSVAL_TESTS_DIR) / "hunt18" / file;
    const fs::path out = dir_ / "out";
    const physval_test::Result r =
        physval_test::physval("run " + scene.string() + " --engines core --quiet --no-cache --out " + out.string());
    ASSERT_TRUE(r.status == 0 || r.status == 1) << r.output;
    std::ifstream in(out / "results.json");
    const nlohmann::json j = nlohmann::json::parse(in);
    const nlohmann::json& run = j["runs"][0];
    EXPECT_EQ(run["status"], "ok") << run["reason"];
    EXPECT_EQ(run["metrics"]["escaped_bodies"], 0) << run["reason"];
    EXPECT_EQ(run["metrics"]["max_penetration"], 0.0);
  }
}

}  // namespace
}  // namespace physval
