// results.json: the contract's run records plus a context block (version, date, host,
// build type, engines), so a result file explains itself a year later.
#pragma once

#include <filesystem>
#include <string>

#include <nlohmann/json.hpp>

#include "physval/validation/suite.hpp"

namespace physval {

nlohmann::json context_json();
nlohmann::json run_to_json(const RunRecord& run);
nlohmann::json suite_to_json(const SuiteResult& result);

// Writes text to path whole or not at all (temporary file in the same folder, then
// rename). Creates the folder. Throws std::runtime_error on failure.
void write_file_atomically(const std::filesystem::path& path, const std::string& text);

// DIR/results.json, plus DIR/series/<scenario>/<engine>.csv (time series for plots:
// t, energy, kinetic, potential, px, py, angular_momentum, then x_i, y_i of each body).
void write_results(const std::filesystem::path& dir, const SuiteResult& result);

}  // namespace physval
