// What `physval gate` adds to a run: JUnit XML for CI systems, and a comparison with
// an earlier results.json that fails on a regression beyond a stated factor.
#pragma once

#include <filesystem>
#include <string>

#include <nlohmann/json.hpp>

#include "physval/validation/suite.hpp"

namespace physval {

// One <testcase> per scenario and engine; unsupported runs are <skipped/>.
std::string junit_xml(const SuiteResult& result);

// Adds a check "baseline.<metric>" to each run for every error metric that both this
// run and the baseline's run of the same scenario and engine measured: it fails when
// the new value exceeds factor x the old one (plus `floor`, so values at round-off do
// not trip it). Returns how many runs of the baseline were matched.
int apply_baseline(SuiteResult& result, const nlohmann::json& baseline, double factor, double floor = 1e-12);

}  // namespace physval
