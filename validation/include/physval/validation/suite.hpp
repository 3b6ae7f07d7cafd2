// A suite run: every scenario on every engine that can model it, compared with the
// reference and with each other.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "physval/validation/comparator.hpp"
#include "physval/validation/run_record.hpp"
#include "physval/validation/runner.hpp"

namespace physval {

struct ScenarioResult {
  Scene scene;                 // as run (dt and duration overrides applied)
  Reference reference;
  std::vector<RunRecord> runs;
  std::vector<PairComparison> pairs;
  // Harness accounting, thread CPU seconds (`physval run --overhead FILE`): the
  // reference (computed, or read from the cache) with its children; compare_run and
  // compare_pair; writing this scenario's series and its part of results.json (filled by
  // write_results, which takes the result as const: hence mutable).
  double reference_cpu_seconds = 0.0;
  double compare_cpu_seconds = 0.0;
  mutable double write_cpu_seconds = 0.0;
};

struct SuiteResult {
  std::vector<ScenarioResult> scenarios;
  bool gates_enforced = false;
  // `--shard I/N`: which part of which suite this is (results.json's "shard" block, what
  // `physval merge` checks the shards against each other with); null for a whole run.
  nlohmann::json shard;
};

using Progress = std::function<void(const std::string& line)>;

// `jobs`: references and engine runs of different scenarios and engines run on this
// many threads (each engine run is its own process); the result does not depend on it.
// The scenes are taken by value: pass them with std::move and the result keeps them
// without a copy (a copy of a 100k-body scene is 29 MB).
SuiteResult run_suite(std::vector<Scene> scenes, const std::vector<std::string>& engines,
                      const RunOptions& options, bool enforce_gates, const Progress& progress = {},
                      std::size_t jobs = 1);

// 0: everything ran and passed; 1: a check failed or a run diverged / errored.
int suite_exit_status(const SuiteResult& result);

}  // namespace physval
