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

// Memory a run of `scene` needs, estimated before anything runs (README: "Bounds"): per
// scene body (the file's parsed tree and the scene), per particle its emitters can make
// (the engine's state), and per stored state sample (samples x objects: the runs' series
// and, passing from an engine's process to physval's, their decoded form), with the
// bytes of each measured on physval itself. `engines`: the engine runs held besides the
// reference's.
double estimated_memory_bytes(const Scene& scene, std::size_t engines);

// The limit `check`, `run` and `gate` hold that estimate to (bytes): --max-memory, or by
// default half of this machine's physical memory.
void set_memory_limit_bytes(double bytes);
double memory_limit_bytes();
// Empty when the estimate fits the limit; else the message (how much against how much).
std::string memory_bound_error(const Scene& scene, std::size_t engines);

}  // namespace physval
