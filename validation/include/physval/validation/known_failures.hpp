// Recording what an engine is known to miss: `physval gate PATH --record-known F` runs
// the scenarios and writes, into each scenario file, every expectation an engine misses
// with F x its measured error as the largest error accepted ([gate.<engine>]
// known_failures). Nobody writes these bounds by hand.
#pragma once

#include <map>
#include <string>

#include "physval/validation/suite.hpp"

namespace physval {

// engine -> (expectation check -> bound)
using KnownFailures = std::map<std::string, std::map<std::string, double>>;

// The misses of one scenario's runs with bounds `margin` x the measured error. Every
// engine that ran appears (with an empty map when it missed nothing).
KnownFailures measured_known_failures(const ScenarioResult& scenario, double margin);

// The scenario text with each listed engine's `known_failures` line replaced (or added
// under its [gate.<engine>] table, which is appended when missing); the engine's other
// keys and every comment stay as they were. An engine with no misses loses the line.
std::string rewrite_known_failures(const std::string& toml_text, const KnownFailures& known);

}  // namespace physval
