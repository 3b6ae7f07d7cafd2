// Holds runs against physics and against each other: conservation drift, divergence
// from the reference, contact timing, expectations, gates.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "physval/validation/run_record.hpp"
#include "physval/validation/runner.hpp"

namespace physval {

// The run every engine is held against: a converged run of core (finer step, RK4,
// exact impacts), checked by running it at two resolutions.
struct Reference {
  bool available = false;
  bool converged = false;
  std::string reason;               // why not available / not converged
  double dt = 0.0;                  // the finer of the two resolutions
  double convergence_error = 0.0;   // max position difference between them, m
  std::optional<RunRecord> run;     // the finer run
  // Wall-clock seconds its runs took when it was computed (kept in the reference cache,
  // so a reference read back is charged the same): --timeout's budget counts it.
  double seconds = 0.0;
  // CPU of its engine children when computed here (0 when read from the cache; not cached).
  double child_cpu_seconds = 0.0;
};

// Builds the reference for `scene` (already effective: dt/duration applied).
Reference make_reference(const Scene& scene, const RunOptions& options);

// Fills run.metrics and run.checks from the run, the scene and the reference.
// `enforce_gates`: the scene's [gate] limits count towards pass/fail (physval gate).
void compare_run(RunRecord& run, const Scene& scene, const Reference& reference, bool enforce_gates);

// The same measures between two engines' runs of one scene.
struct PairComparison {
  std::string scenario;
  std::string a;
  std::string b;
  Metrics metrics;   // position_divergence, energy_divergence, linear_momentum_divergence,
                     // contact_time_error, missed_contacts (in b, of a's), extra_contacts
};
PairComparison compare_pair(const RunRecord& a, const RunRecord& b, const Scene& scene);

// compare_run and compare_pair for all the runs of one scene, with the same results, but
// what several comparisons share is computed once: each run's contacts as ids of one
// table of object pairs (names hashed once per run, not once per comparison) and each
// series' characteristic scales. The scene, the reference and the runs must outlive it
// and their contacts and series must not change meanwhile (run_suite's comparisons).
class ScenarioComparer {
 public:
  ScenarioComparer(const Scene& scene, const Reference& reference);
  ~ScenarioComparer();
  void compare_run(RunRecord& run, bool enforce_gates);
  PairComparison compare_pair(const RunRecord& a, const RunRecord& b);

  struct Cache;

 private:
  const Scene& scene_;
  const Reference& reference_;
  std::unique_ptr<Cache> cache_;
};

}  // namespace physval
