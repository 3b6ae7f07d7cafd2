// Loads scenario files (TOML) into Scene descriptions, with strict validation: every
// unknown key, wrong type, missing required key, out-of-range or non-finite number,
// duplicate name and syntax error is reported with file, line, column and key; all
// errors of a file are reported, not just the first.
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "physval/core/scene.hpp"
#include "physval/validation/diagnostics.hpp"

namespace physval {

struct ScenarioLoad {
  std::optional<Scene> scene;   // set only when there are no errors
  Diagnostics errors;
};

// Parses scenario text; `source_name` is what messages call the file.
ScenarioLoad parse_scenario(std::string_view text, const std::string& source_name);
ScenarioLoad load_scenario_file(const std::filesystem::path& file);

struct SuiteLoad {
  std::vector<Scene> scenes;    // in path order, then sorted file order within folders
  Diagnostics errors;
};

// Each path is a scenario file or a folder searched recursively for *.toml (sorted).
// Scenario names must be unique across the suite.
SuiteLoad load_suite(const std::vector<std::string>& paths);

}  // namespace physval
