// Runs scenarios on engines. Each engine run can happen in a child process, so an
// engine that crashes or hangs costs only its own run.
#pragma once

#include <chrono>
#include <cmath>
#include <functional>
#include <limits>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "physval/core/engine.hpp"
#include "physval/validation/run_record.hpp"

namespace physval {

struct RunOptions {
  std::optional<double> dt;          // overrides the scenario's dt
  std::optional<double> duration;    // overrides the scenario's duration
  bool isolate = true;               // run each engine in a child process
  double timeout_seconds = 0.0;      // per run; 0: none
  // A shared end for several runs that count as one (the reference's two runs): an
  // isolated run stops at the earlier of its timeout and this deadline.
  std::optional<std::chrono::steady_clock::time_point> deadline;
  // Bound on stored samples x bodies (memory); the sample interval grows to fit.
  std::size_t max_sample_states = 1'000'000;
  // Folder of the reference cache (see reference_cache.hpp); empty: no cache.
  std::string reference_cache;
};

// The scene as it will run: the options' dt and duration applied.
Scene effective_scene(const Scene& scene, const RunOptions& options);

// How many steps between samples for this scene (from sample_interval, or automatic:
// about 400 samples, fewer for scenes with many bodies).
long sample_every(const Scene& scene, std::size_t max_sample_states);

// Whether an engine's clock `t` after its step k agrees with `stepped`, the sum of the k
// step lengths it was given (dt each, the last one maybe shorter), checked after every
// step: to 1% of a step plus the round-off the two may have gathered. An engine that sums
// its steps rounds k times, each by at most half an ulp of the sum (eps/2 x |t|), and so
// does `stepped`; one that computes k x dt rounds once: together within k x eps x |t|.
// Four times that is allowed (an engine that sums substeps rounds more often). Without
// it a plugin keeping t = k x dt was an error past about 2.6e7 steps of dt = 1e-3 (the
// sums then differ by 1% of a step). A clock 0.1% fast (off by 1e-3 |t|) stays an error
// up to k = 1e12; one a whole step ahead up to k = 1/sqrt(4 eps), about 3.4e7 steps of
// any dt. The round-off term scales with `stepped` (finite), never with t: an infinite or
// NaN t is never accepted.
inline bool clock_matches_steps(double t, double stepped, long k, double dt) {
  const double roundoff = 4.0 * static_cast<double>(k) * std::numeric_limits<double>::epsilon() * std::abs(stepped);
  return std::abs(t - stepped) <= 0.01 * dt + roundoff;
}

// Runs one engine on one scene in this process. Never throws: failures become
// status error / diverged with a reason.
RunRecord run_engine(const Scene& scene, const EngineFactory& engine, const RunOptions& options);

// The same in a child process (when options.isolate), surviving crashes and hangs.
RunRecord run_engine_isolated(const Scene& scene, const EngineFactory& engine, const RunOptions& options);
// The same for a scene the caller gives away (a variant made for this run): the parent
// releases it once the child has forked, before the record comes back.
RunRecord run_engine_isolated(Scene&& scene, const EngineFactory& factory, const RunOptions& options);

// Engine runs in long-lived child processes (README "Harness overhead"): each thread that
// calls run() gets its own worker, forked at its first run, which then takes that
// thread's runs one after another; a fresh process per run cost about 0.4 ms of fork,
// page faults on the engines' code and exit, a third of the built-in suite's harness.
// The worker inherited `scenes` and `engines` when it was forked: they must stay as they
// are for the workers' lifetime, and a request names them by index. A run's record and exit
// are judged as run_engine_isolated judges them (same reasons for a crash, an exit
// status, a timeout): a worker that dies or is stopped costs only the run it was on, and
// the next run forks a new one. The destructor ends the workers and reaps them.
class RunWorkers {
 public:
  RunWorkers(std::vector<const Scene*> scenes, std::vector<const EngineFactory*> engines);
  ~RunWorkers();
  RunWorkers(const RunWorkers&) = delete;
  RunWorkers& operator=(const RunWorkers&) = delete;

  // run_engine_isolated(*scenes[scene], factory, options), in this thread's worker (in
  // a child of its own when `factory` is not one of `engines`; in this process when
  // !options.isolate). child_cpu_seconds: the worker's CPU from the end of its previous
  // run (or its fork) to the end of this one.
  RunRecord run(std::size_t scene, const EngineFactory& factory, const RunOptions& options);

 private:
  struct Worker;
  Worker& mine();
  std::vector<const Scene*> scenes_;
  std::vector<const EngineFactory*> engines_;
  std::mutex mutex_;
  std::vector<std::unique_ptr<Worker>> workers_;
};

// CPU time of the calling thread (CLOCK_THREAD_CPUTIME_ID), s: the harness's accounting.
double thread_cpu_seconds();

// A run that never happened because the engine cannot model the scene.
RunRecord unsupported_run(const Scene& scene, const EngineInfo& info, const std::vector<std::string>& missing);

// The engines to run a scene on: `wanted` (empty: all in the registry), narrowed by
// the scene's own `engines` list.
std::vector<const EngineFactory*> engines_for(const Scene& scene, const std::vector<std::string>& wanted);

}  // namespace physval
