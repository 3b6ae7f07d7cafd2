// A built-in scenario (validation/scenarios/RELATIVE of the source tree, found from any
// working folder), loaded for a test; throws with the loader's messages if it does not
// load.
#pragma once

#include <stdexcept>
#include <string>

#include "physval/validation/scenario_loader.hpp"

namespace physval::test {

inline Scene load_builtin(const std::string& relative) {
  ScenarioLoad load = load_scenario_file(std::string(PHYSVAL_SCENARIO_DIR) + "/" + relative);
  if (!load.scene) {
    std::string why;
    for (const Diagnostic& d : load.errors) why += "\n  " + d.str();
    throw std::runtime_error("cannot load " + relative + why);
  }
  return *load.scene;
}

}  // namespace physval::test
