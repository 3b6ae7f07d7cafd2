// What `physval gate` adds to a run: JUnit XML for CI systems, and a comparison with
// an earlier results.json that fails on a regression beyond a stated factor.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "physval/validation/suite.hpp"

namespace physval {

// Removes a --junit FILE left by an earlier run, before anything else is done: a run that
// then stops (bad input, exit 2; killed by a CI timeout or an OOM; results that cannot be
// written) leaves no JUnit file, instead of the earlier run's, which a CI step publishing
// the file would read as this run's verdict (all passed). Only a regular file is removed.
void discard_earlier_junit(const std::string& file);

// One <testcase> per scenario and engine; unsupported runs are <skipped/>.
std::string junit_xml(const SuiteResult& result);

// Adds a check "baseline.<metric>" to each run for every error metric that both this
// run and the baseline's run of the same scenario and engine measured: it fails when
// the new value exceeds factor x the old one (plus `floor`, so values at round-off do
// not trip it). Returns how many runs of the baseline were matched.
int apply_baseline(SuiteResult& result, const nlohmann::json& baseline, double factor, double floor = 1e-12);

// A baseline run (scenario S, engine E, not unsupported there) with no run of E on S now,
// though S ran and E was not left out by `wanted` (--engines; empty: every engine): E is
// not loaded in this physval (a CI artifact without the bundled plugins, a --plugin
// dropped from the command) or S's own `engines` list no longer names it. Every
// regression the baseline would catch on it is hidden, so such a run is added as
// `unsupported` with a failing check `baseline.status` (JUnit: a failure). Returns how
// many were added.
int add_runs_missing_from_baseline(SuiteResult& result, const nlohmann::json& baseline,
                                   const std::vector<std::string>& wanted);

}  // namespace physval
