// `-j N`: the task runner calls every task exactly once, and a suite run on several
// threads gives the same results as on one (apart from timings).
#include <gtest/gtest.h>

#include <atomic>
#include <stdexcept>

#include "physval/validation/scenario_loader.hpp"
#include "physval/validation/scheduler.hpp"
#include "physval/validation/suite.hpp"

namespace physval {
namespace {

TEST(RunTasks, CallsEveryTaskOnceWhateverTheJobCount) {
  for (std::size_t jobs : {1u, 2u, 5u, 64u}) {
    const std::vector<double> costs = {3, 1, 4, 1, 5, 9, 2, 6, 5, 3, 5};
    std::vector<std::atomic<int>> calls(costs.size());
    run_tasks(costs, jobs, [&](std::size_t i) { calls[i].fetch_add(1); });
    for (std::size_t i = 0; i < costs.size(); ++i) EXPECT_EQ(calls[i].load(), 1) << "task " << i << " jobs " << jobs;
  }
}

TEST(RunTasks, RethrowsATasksException) {
  EXPECT_THROW(run_tasks({1, 1, 1, 1}, 3,
                         [](std::size_t i) {
                           if (i == 2) throw std::runtime_error("task 2 failed");
                         }),
               std::runtime_error);
}

Scene scene_from(const std::string& text) {
  ScenarioLoad load = parse_scenario(text, "parallel_suite_test.toml");
  if (!load.scene) throw std::runtime_error("test scene does not load: " + text);
  return *load.scene;
}

// Compares everything a results.json holds except timings.
void expect_same_results(const SuiteResult& a, const SuiteResult& b) {
  ASSERT_EQ(a.scenarios.size(), b.scenarios.size());
  for (std::size_t s = 0; s < a.scenarios.size(); ++s) {
    const ScenarioResult& x = a.scenarios[s];
    const ScenarioResult& y = b.scenarios[s];
    EXPECT_EQ(x.scene.name, y.scene.name);
    EXPECT_EQ(x.reference.available, y.reference.available);
    EXPECT_EQ(x.reference.converged, y.reference.converged);
    EXPECT_EQ(x.reference.convergence_error, y.reference.convergence_error);
    ASSERT_EQ(x.runs.size(), y.runs.size());
    for (std::size_t r = 0; r < x.runs.size(); ++r) {
      EXPECT_EQ(x.runs[r].engine, y.runs[r].engine);
      EXPECT_EQ(x.runs[r].status, y.runs[r].status);
      EXPECT_EQ(x.runs[r].contacts.size(), y.runs[r].contacts.size());
      EXPECT_EQ(x.runs[r].series.time, y.runs[r].series.time);
      for (const auto& [name, value] : x.runs[r].metrics) {
        if (name == "wall_seconds") continue;
        EXPECT_EQ(value, y.runs[r].metrics.at(name)) << x.scene.name << " " << x.runs[r].engine << " " << name;
      }
    }
    ASSERT_EQ(x.pairs.size(), y.pairs.size());
    for (std::size_t p = 0; p < x.pairs.size(); ++p) EXPECT_EQ(x.pairs[p].metrics, y.pairs[p].metrics);
  }
}

TEST(ParallelSuite, ThreeJobsGiveTheResultsOfOne) {
  std::vector<Scene> scenes;
  for (int k = 0; k < 4; ++k) {
    scenes.push_back(scene_from("name = \"pair" + std::to_string(k) +
                                "\"\nduration = 1.0\ndt = 0.01\n"
                                "[[bodies]]\nname = \"a\"\nradius = 0.1\nmass = 1\nposition = [0, 0]\nvelocity = [" +
                                std::to_string(1 + k) +
                                ", 0]\n[[bodies]]\nname = \"b\"\nradius = 0.1\nmass = 2\nposition = [1, 0]\n"));
  }
  const RunOptions options;
  const SuiteResult one = run_suite(scenes, {}, options, true, {}, 1);
  const SuiteResult three = run_suite(scenes, {}, options, true, {}, 3);
  ASSERT_EQ(one.scenarios.size(), 4u);
  ASSERT_FALSE(one.scenarios[0].runs.empty());
  EXPECT_FALSE(one.scenarios[3].runs[0].contacts.empty());   // the scenes do collide
  expect_same_results(one, three);
}

}  // namespace
}  // namespace physval
