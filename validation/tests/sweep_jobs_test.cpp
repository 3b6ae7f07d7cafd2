// sweep -j: the error runs of the points in parallel give the same errors and statuses
// as one at a time (timings are measured alone afterwards, so they are not compared).
#include <gtest/gtest.h>

#include "physval/validation/scenario_loader.hpp"
#include "physval/validation/sweep.hpp"

namespace physval {
namespace {

TEST(SweepJobs, ThreeJobsGiveTheErrorsOfOne) {
  ScenarioLoad load = parse_scenario(
      "name = \"pair\"\nduration = 1.0\ndt = 0.01\n"
      "[[bodies]]\nname = \"a\"\nradius = 0.1\nmass = 1\nposition = [0, 0]\nvelocity = [2, 0]\n"
      "[[bodies]]\nname = \"b\"\nradius = 0.1\nmass = 2\nposition = [1, 0]\n",
      "sweep_jobs_test.toml");
  ASSERT_TRUE(load.scene);
  SweepOptions options;
  options.dts = {0.02, 0.01, 0.005};
  options.repetitions = 1;
  options.min_seconds_per_repetition = 0.0;
  options.jobs = 1;
  const SweepResult one = run_sweep(*load.scene, options, {});
  options.jobs = 3;
  const SweepResult three = run_sweep(*load.scene, options, {});
  ASSERT_GT(one.points.size(), 3u);
  ASSERT_EQ(one.points.size(), three.points.size());
  int with_error = 0;
  for (std::size_t i = 0; i < one.points.size(); ++i) {
    const SweepPoint& x = one.points[i];
    const SweepPoint& y = three.points[i];
    EXPECT_EQ(x.engine, y.engine);
    EXPECT_EQ(x.setting, y.setting);
    EXPECT_EQ(x.dt, y.dt);
    EXPECT_EQ(x.status, y.status) << x.engine << " " << x.setting;
    EXPECT_EQ(x.position_error, y.position_error) << x.engine << " " << x.setting;
    EXPECT_EQ(x.energy_error, y.energy_error);
    EXPECT_EQ(x.contact_time_error, y.contact_time_error);
    with_error += x.position_error ? 1 : 0;
  }
  EXPECT_GT(with_error, 0);   // errors were measured, so the comparison means something
}

}  // namespace
}  // namespace physval
