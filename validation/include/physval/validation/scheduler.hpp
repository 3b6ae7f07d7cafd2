// Runs independent tasks on N worker threads (`-j N`). Every task writes only its own
// result slot, so the results do not depend on N or on the order tasks finish in.
#pragma once

#include <cstddef>
#include <functional>
#include <vector>

namespace physval {

// The default for `-j`: every core this process may use (at least 1).
std::size_t default_jobs();

// Calls task(i) once for every i in [0, costs.size()) on up to `jobs` threads. With
// jobs <= 1 the tasks run in index order on this thread; otherwise the costliest start
// first (longest-processing-time order), so a long task does not start last. The first
// exception a task throws is rethrown here after all started tasks have finished.
void run_tasks(const std::vector<double>& costs, std::size_t jobs, const std::function<void(std::size_t)>& task);

}  // namespace physval
