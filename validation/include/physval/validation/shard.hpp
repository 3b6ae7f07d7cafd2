// `--shard I/N`: one of N deterministic parts of a suite (whole scenarios, each with all
// its engines and its reference) or of a sweep (points), balanced by estimated cost, so
// N machines (a Slurm job array, a CI matrix) can share the work; `physval merge` joins
// their output folders into what one run would have written.
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "physval/core/scene.hpp"

namespace physval {

struct ShardSpec {
  std::size_t index = 0;   // 0-based: I in [0, N) (SLURM_ARRAY_TASK_ID with --array=0-(N-1))
  std::size_t count = 1;   // N >= 1
};

// "I/N" with 0 <= I < N; nullopt and a reason in `error` otherwise.
std::optional<ShardSpec> parse_shard(const std::string& text, std::string& error);

// Which shard each item goes to: items are taken by estimated cost, largest first (ties
// by position), each to the shard with the least cost so far (ties: the lowest index),
// the longest-processing-time rule. Depends only on the costs and N, never on the
// machine, so every shard computes the same split.
std::vector<std::size_t> assign_shards(const std::vector<double>& costs, std::size_t count);

// A scenario's estimated cost, what the split balances: body-steps (at least one body)
// times (12 + the engines that will run it); the reference runs the scene about twelve
// times over (two finer steps), each engine once.
double scenario_cost(const Scene& effective_scene, std::size_t engine_runs);

// A fingerprint of a scenario file's text (FNV-1a 64, hex): shards run on different
// machines must have run the same scenario files. Empty when the file cannot be read.
std::string file_fingerprint(const std::string& path);

// What the results were computed with, beyond the options: a hash of the physval
// executable, every engine of the registry (name, version, precision) and a hash of each
// plugin library loaded. Shards whose builds differ are not parts of one job (`merge`
// refuses them): the version number alone stays the same across rebuilds, so a shard
// folder left from an earlier build (a job whose task died before writing) merged as if
// it were current, and a machine without the bundled plugins ran fewer engines.
nlohmann::json build_identity();

}  // namespace physval
