// A built-in scenario (validation/scenarios/RELATIVE), loaded for a test; throws if it
// does not load.
#pragma once

#include <stdexcept>
#include <string>

#include "physval/validation/scenario_loader.hpp"

namespace physval::test {

inline Scene load_builtin(const std::string& relative) {
  ScenarioLoad load = load_scenario_file(std::string(PHYSVAL_SCENARIO_DIR) + "/" + relative);
  if (!load.scene) throw std::runtime_error("cannot load " + relative);
  return *load.scene;
}

}  // namespace physval::test
