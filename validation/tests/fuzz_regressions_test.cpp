// Replays every input the scenario-loader fuzzer found (validation/fuzz/regressions/) with
// the fuzzer's own invariants, in every normal ctest run (and so under ASan/UBSan in the
// sanitizer build): what was fixed stays fixed.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "physval/validation/scenario_loader.hpp"

namespace {

namespace fs = std::filesystem;
using namespace physval;

TEST(FuzzRegressions, EveryKeptInputLoadsOrFailsWithLocatedErrors) {
  const fs::path dir = fs::path(PHYSVAL_SOURCE_DIR) / "validation" / "fuzz" / "regressions";
  int replayed = 0;
  for (const auto& entry : fs::directory_iterator(dir)) {
    if (!entry.is_regular_file() || entry.path().filename() == "README.md") continue;
    std::ifstream in(entry.path(), std::ios::binary);
    std::ostringstream text;
    text << in.rdbuf();
    const ScenarioLoad load = parse_scenario(text.str(), "fuzz.toml");
    EXPECT_NE(load.scene.has_value(), !load.errors.empty()) << entry.path() << ": a scene xor errors";
    for (const Diagnostic& d : load.errors) EXPECT_FALSE(d.message.empty()) << entry.path();
    if (load.scene) {
      EXPECT_TRUE(load.scene->dt > 0.0 && std::isfinite(load.scene->dt)) << entry.path();
      EXPECT_TRUE(load.scene->duration > 0.0 && std::isfinite(load.scene->duration)) << entry.path();
    }
    ++replayed;
  }
  EXPECT_GE(replayed, 2) << "the regression corpus is in " << dir;
}

}  // namespace
