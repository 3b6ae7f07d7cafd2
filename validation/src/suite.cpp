#include "physval/validation/suite.hpp"

#include <sstream>

namespace physval {

SuiteResult run_suite(const std::vector<Scene>& scenes, const std::vector<std::string>& engines,
                      const RunOptions& options, bool enforce_gates, const Progress& progress) {
  SuiteResult result;
  result.gates_enforced = enforce_gates;
  for (const Scene& original : scenes) {
    ScenarioResult sr;
    sr.scene = effective_scene(original, options);
    if (progress) progress(sr.scene.name + ": reference");
    sr.reference = make_reference(sr.scene, options);
    for (const EngineFactory* f : engines_for(sr.scene, engines)) {
      const std::vector<std::string> missing = unsupported_features(f->info, sr.scene);
      RunRecord run;
      if (!missing.empty()) {
        run = unsupported_run(sr.scene, f->info, missing);
      } else {
        if (progress) progress(sr.scene.name + ": " + f->info.name);
        run = run_engine_isolated(sr.scene, *f, options);
      }
      compare_run(run, sr.scene, sr.reference, enforce_gates);
      sr.runs.push_back(std::move(run));
    }
    for (std::size_t i = 0; i < sr.runs.size(); ++i) {
      for (std::size_t j = i + 1; j < sr.runs.size(); ++j) {
        if (sr.runs[i].status != RunStatus::Ok || sr.runs[j].status != RunStatus::Ok) continue;
        sr.pairs.push_back(compare_pair(sr.runs[i], sr.runs[j], sr.scene));
      }
    }
    result.scenarios.push_back(std::move(sr));
  }
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
