#include "physval/validation/suite.hpp"

#include <algorithm>
#include <mutex>
#include <optional>
#include <sstream>

#include "physval/validation/reference_cache.hpp"
#include "physval/validation/scheduler.hpp"

namespace physval {

namespace {

// What a run costs, roughly: body-steps (the reference runs the scene twice at a finer
// step, so it weighs about twelve runs). Used only to start the longest tasks first.
double estimated_cost(const Scene& scene) {
  return static_cast<double>(std::max<std::size_t>(1, scene.bodies.size())) * static_cast<double>(scene.steps());
}

std::string seconds_text(double seconds) {
  std::ostringstream os;
  os.precision(3);
  os << seconds;   // 20 -> "20", 0.5 -> "0.5", 1.23456 -> "1.23"
  return os.str();
}

}  // namespace

SuiteResult run_suite(std::vector<Scene> scenes, const std::vector<std::string>& engines,
                      const RunOptions& options, bool enforce_gates, const Progress& progress, std::size_t jobs) {
  SuiteResult result;
  result.gates_enforced = enforce_gates;
  // In-process runs share the process: one at a time.
  if (!options.isolate) jobs = 1;

  // One task per reference and per engine run; each writes only its own slot.
  struct Task {
    std::size_t scenario;
    const EngineFactory* engine;   // nullptr: the scenario's reference
    std::size_t slot;
  };
  std::vector<Task> tasks;
  std::vector<double> costs;
  std::vector<std::vector<const EngineFactory*>> scenario_engines(scenes.size());
  result.scenarios.resize(scenes.size());
  for (std::size_t s = 0; s < scenes.size(); ++s) {
    ScenarioResult& sr = result.scenarios[s];
    sr.scene = std::move(scenes[s]);   // effective_scene() in place, without a copy
    if (options.dt) sr.scene.dt = *options.dt;
    if (options.duration) sr.scene.duration = *options.duration;
    const double cost = estimated_cost(sr.scene);
    tasks.push_back({s, nullptr, 0});
    costs.push_back(12.0 * cost);
    scenario_engines[s] = engines_for(sr.scene, engines);
    sr.runs.resize(scenario_engines[s].size());
    for (std::size_t e = 0; e < scenario_engines[s].size(); ++e) {
      const EngineFactory* f = scenario_engines[s][e];
      const std::vector<std::string> missing = unsupported_features(f->info, sr.scene);
      if (!missing.empty()) {
        sr.runs[e] = unsupported_run(sr.scene, f->info, missing);
        continue;
      }
      tasks.push_back({s, f, e});
      costs.push_back(cost);
    }
  }

  std::mutex progress_mutex;
  auto say = [&](const Task& t) {
    if (!progress) return;
    const std::lock_guard<std::mutex> lock(progress_mutex);
    const std::string what = result.scenarios[t.scenario].scene.name + ": " + (t.engine ? t.engine->info.name : "reference");
    progress(what);   // the caller counts scenarios (physval's "[n/N]")
  };
  // The engine runs go to long-lived workers (one per thread of run_tasks), forked when
  // the scenes are final; the workers end (and are reaped) at the end of the runs.
  std::vector<const Scene*> scene_list;
  for (const ScenarioResult& sr : result.scenarios) scene_list.push_back(&sr.scene);
  std::vector<const EngineFactory*> engine_list;
  for (const std::vector<const EngineFactory*>& list : scenario_engines) {
    for (const EngineFactory* f : list) {
      if (std::find(engine_list.begin(), engine_list.end(), f) == engine_list.end()) engine_list.push_back(f);
    }
  }
  std::optional<RunWorkers> workers(std::in_place, std::move(scene_list), std::move(engine_list));
  // References first, then the engine runs: one --timeout is the budget of an engine run
  // together with the reference it is compared with, so each engine run gets what its
  // scenario's reference left of it (README: "--timeout").
  for (const bool references : {true, false}) {
    std::vector<std::size_t> phase;
    std::vector<double> phase_costs;
    for (std::size_t i = 0; i < tasks.size(); ++i) {
      if ((tasks[i].engine == nullptr) != references) continue;
      phase.push_back(i);
      phase_costs.push_back(costs[i]);
    }
    run_tasks(phase_costs, jobs, [&](std::size_t k) {
      const Task& t = tasks[phase[k]];
      ScenarioResult& sr = result.scenarios[t.scenario];
      say(t);
      const double cpu0 = thread_cpu_seconds();
      if (t.engine == nullptr) {
        sr.reference = cached_reference(sr.scene, options).reference;
        sr.reference_cpu_seconds = thread_cpu_seconds() - cpu0 + sr.reference.child_cpu_seconds;
        return;
      }
      if (options.timeout_seconds <= 0.0) {
        sr.runs[t.slot] = workers->run(t.scenario, *t.engine, options);
        sr.runs[t.slot].parent_cpu_seconds = thread_cpu_seconds() - cpu0;
        return;
      }
      RunOptions budget = options;
      const double spent = sr.reference.seconds;
      budget.timeout_seconds = options.timeout_seconds - spent;
      RunRecord r;
      if (budget.timeout_seconds <= 0.0) {
        r = unsupported_run(sr.scene, t.engine->info, {});
        r.status = RunStatus::Error;
        r.reason = "timed out: the reference took " + seconds_text(spent) + " s of the --timeout budget of " +
                   seconds_text(options.timeout_seconds) + " s, nothing was left for this run";
      } else {
        r = workers->run(t.scenario, *t.engine, budget);
        if (r.status == RunStatus::Error && r.reason.rfind("timed out", 0) == 0 && spent > 0.0) {
          r.reason = "timed out: the engine run and the reference (" + seconds_text(spent) +
                     " s) together took longer than the --timeout budget of " +
                     seconds_text(options.timeout_seconds) + " s";
        }
      }
      r.parent_cpu_seconds = thread_cpu_seconds() - cpu0;
      sr.runs[t.slot] = std::move(r);
    });
  }

  workers.reset();

  // Comparisons, per scenario (independent of each other).
  std::vector<double> compare_costs;
  for (const ScenarioResult& sr : result.scenarios) compare_costs.push_back(static_cast<double>(sr.runs.size()));
  run_tasks(compare_costs, jobs, [&](std::size_t s) {
    ScenarioResult& sr = result.scenarios[s];
    const double cpu0 = thread_cpu_seconds();
    ScenarioComparer comparer(sr.scene, sr.reference);   // what the comparisons share, computed once
    for (RunRecord& run : sr.runs) comparer.compare_run(run, enforce_gates);
    for (std::size_t i = 0; i < sr.runs.size(); ++i) {
      for (std::size_t j = i + 1; j < sr.runs.size(); ++j) {
        if (sr.runs[i].status != RunStatus::Ok || sr.runs[j].status != RunStatus::Ok) continue;
        sr.pairs.push_back(comparer.compare_pair(sr.runs[i], sr.runs[j]));
      }
    }
    sr.compare_cpu_seconds = thread_cpu_seconds() - cpu0;
  });
  return result;
}

int suite_exit_status(const SuiteResult& result) {
  for (const ScenarioResult& sr : result.scenarios) {
    for (const RunRecord& r : sr.runs) {
      if (!r.passed()) return 1;
    }
  }
  return 0;
}

}  // namespace physval
