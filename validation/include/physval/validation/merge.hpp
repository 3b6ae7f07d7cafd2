// `physval merge DIR... --out DIR`: joins the output folders of the N parts of a
// `run`/`gate --shard I/N` (or of a `sweep --shard I/N`) into the folder one run would
// have written: results.json (runs, references and comparisons in the suite's order),
// series/, and on request the JUnit file and the report (drawn by the report's own code
// from the merged folder). Sweeps: sweep.json, sweep.csv and the plots, with the orders
// of convergence and the Pareto front computed over all points.
//
// It refuses (exit 2, nothing written) parts that do not belong together: not a shard's
// output, another physval version, another scenario set or scenario file text, other
// options, another N, a part given twice or missing.
#pragma once

#include <ostream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "physval/validation/suite.hpp"

namespace physval {

struct MergeOptions {
  std::vector<std::string> dirs;
  std::string out;      // empty: physval-out (suites) or physval-sweep (sweeps)
  std::string junit;    // empty: none
  bool report = false;
};

// Exit status as `run`/`gate` would have returned it for the whole suite (0, 1), or 2
// when the parts are refused. Messages go to `err`, what was written to `out`.
int merge_shards(const MergeOptions& options, std::ostream& out, std::ostream& err);

// A results.json read back into what junit_xml() and suite_exit_status() need (scenario
// names; each run's engine, status, reason, time and checks; no series).
SuiteResult suite_from_json(const nlohmann::json& results);

}  // namespace physval
