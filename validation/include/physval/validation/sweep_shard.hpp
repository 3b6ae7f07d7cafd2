// A sweep put back together from its shards' sweep.json files (`physval merge`).
#pragma once

#include <vector>

#include <nlohmann/json.hpp>

#include "physval/validation/sweep.hpp"

namespace physval {

// The shards' points in the whole sweep's order, the reference and notes of the first
// (the caller has checked that the shards belong together), then analyse_sweep() over
// all points: orders of convergence and the Pareto front as one sweep finds them.
// Throws std::invalid_argument when the points do not add up to the whole sweep.
SweepResult sweep_from_shards(const std::vector<nlohmann::json>& shards);

}  // namespace physval
