// results.json: the contract's run records plus a context block (version, date, host,
// build type, engines), so a result file explains itself a year later.
#pragma once

#include <filesystem>
#include <ostream>
#include <string>
#include <string_view>

#include <nlohmann/json.hpp>

#include "physval/validation/series_file.hpp"
#include "physval/validation/suite.hpp"

namespace physval {

nlohmann::json context_json();
nlohmann::json run_to_json(const RunRecord& run);
nlohmann::json suite_to_json(const SuiteResult& result);
// series/<scenario>/scene.json: what the report's player draws besides the series:
// every body's name, radius, mass and whether it is static, and the barriers (walls
// from/to, boxes min/max, surfaces' points), in scene coordinates (m).
nlohmann::json scene_geometry_json(const ScenarioResult& result);

// The text suite_to_json(result).dump(2) + "\n", streamed run by run and contact by
// contact (no tree of the whole file in memory); the file version writes atomically.
void write_results_json(std::ostream& os, const SuiteResult& result);
void write_results_json(const std::filesystem::path& path, const SuiteResult& result);

// Writes text to path whole or not at all (temporary file in the same folder, then
// rename). Creates the folder. Throws std::runtime_error on failure.
void write_file_atomically(const std::filesystem::path& path, std::string_view text);

// An output folder that appears whole or not at all. The constructor checks the final
// folder before anything runs (not a file; an existing folder is replaced only when it
// is empty or holds a results.json, i.e. an earlier physval output) and creates a staging
// folder beside it, ".NAME.staging.PID"; everything is written there, and commit()
// swaps it into place with renames. Not committed (an exception, a kill): the staging
// folder is removed (or left, on SIGKILL) and the final folder is untouched.
// Throws std::runtime_error with a message naming the folder.
class StagedOutputFolder {
 public:
  explicit StagedOutputFolder(std::filesystem::path final_dir);
  ~StagedOutputFolder();
  StagedOutputFolder(const StagedOutputFolder&) = delete;
  StagedOutputFolder& operator=(const StagedOutputFolder&) = delete;
  const std::filesystem::path& staging() const { return staging_; }
  const std::filesystem::path& final_dir() const { return final_; }
  void commit();

 private:
  std::filesystem::path final_;
  std::filesystem::path staging_;
  bool committed_ = false;
};

// DIR/results.json, plus DIR/series/<scenario>/scene.json and <engine>.bin (time series for
// plots and the player: t, energy, kinetic, potential, px, py, angular_momentum, then x_i,
// y_i of each body; series_file.hpp), or <engine>.csv with SeriesFormat::Csv.
void write_results(const std::filesystem::path& dir, const SuiteResult& result,
                   SeriesFormat series = SeriesFormat::Binary);

// `--overhead FILE`: the harness's cost per scenario next to the engines' stepping (README
// "Running at scale", "Harness overhead"), all CPU seconds. `process_cpu_seconds`: user +
// system CPU of physval and its reaped children so far (what is not attributed to a
// scenario, e.g. start-up, loading, the table, is the suite's `unattributed`).
nlohmann::json overhead_json(const SuiteResult& result, double process_cpu_seconds);

}  // namespace physval
