// The sweep's analysis and outputs on synthetic points (no engine runs, no timing):
// orders of convergence, the Pareto front, the table, CSV, JSON and the plots; and
// which solver settings an engine is swept over, from the options it declares.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "physval/validation/sweep.hpp"

namespace physval {
namespace {

namespace fs = std::filesystem;

const std::vector<double> kDts = {1.0 / 30, 1.0 / 60, 1.0 / 120, 1.0 / 240, 1.0 / 480, 1.0 / 960};

SweepPoint point(const std::string& engine, const std::string& setting, double dt, double wall,
                 std::optional<double> position, std::optional<double> energy = std::nullopt) {
  SweepPoint p;
  p.engine = engine;
  p.setting = setting;
  p.dt = dt;
  p.steps = std::lround(2.0 / dt);
  p.simulated_seconds = static_cast<double>(p.steps) * dt;
  p.repetitions = 5;
  p.runs = 5;
  p.wall_per_sim_median = wall;
  p.wall_per_sim_min = 0.9 * wall;
  p.wall_per_sim_max = 1.1 * wall;
  p.spread = 0.2;
  p.position_error = position;
  p.energy_error = energy;
  return p;
}

// Two engines: alpha's error is 3 dt^2 (second order), beta's 0.5 dt (first order);
// beta is cheaper per step.
SweepResult synthetic() {
  SweepResult r;
  r.scenario = "synthetic_fall";
  r.duration = 2.0;
  r.reference_available = true;
  r.reference_converged = true;
  r.reference_dt = 1.0 / 7680;
  for (double dt : kDts) r.points.push_back(point("alpha", "integrator=rk4", dt, 1e-6 / dt, 3.0 * dt * dt, 7.0 * dt * dt));
  for (double dt : kDts) r.points.push_back(point("beta", "", dt, 1e-7 / dt, 0.5 * dt, 2.0 * dt));
  analyse_sweep(r);
  return r;
}

fs::path fresh_dir(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / ("physval-sweep-test-" + name + "-" + std::to_string(::getpid()));
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> out;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) out.push_back(line);
  return out;
}

TEST(SweepFit, RecoversTheOrderOfAPowerLaw) {
  std::vector<std::optional<double>> err;
  for (double dt : kDts) err.push_back(3.7 * dt * dt);
  const LogLogFit fit = fit_log_log(kDts, err);
  ASSERT_TRUE(fit.slope.has_value());
  EXPECT_NEAR(*fit.slope, 2.0, 1e-9);
  EXPECT_NEAR(std::pow(10.0, fit.intercept), 3.7, 1e-9);
  EXPECT_NEAR(fit.r_squared, 1.0, 1e-9);
  EXPECT_EQ(fit.points, 6);
}

TEST(SweepFit, LeavesOutUnmeasuredAndNonPositiveErrors) {
  std::vector<std::optional<double>> err;
  for (double dt : kDts) err.push_back(0.25 * dt * dt * dt * dt);
  err[1] = std::nullopt;
  err[3] = 0.0;
  const LogLogFit fit = fit_log_log(kDts, err);
  ASSERT_TRUE(fit.slope.has_value());
  EXPECT_NEAR(*fit.slope, 4.0, 1e-9);
  EXPECT_EQ(fit.points, 4);
}

TEST(SweepFit, NeedsTwoDistinctStepSizes) {
  EXPECT_FALSE(fit_log_log({0.1}, {0.01}).slope.has_value());
  EXPECT_FALSE(fit_log_log({0.1, 0.1}, {0.01, 0.02}).slope.has_value());
  EXPECT_FALSE(fit_log_log({0.1, 0.05}, {std::nullopt, 0.02}).slope.has_value());
}

TEST(SweepAnalysis, OneOrderPerEngineAndSettingInPointOrder) {
  SweepResult r = synthetic();
  // A failed point must not bend the fit.
  SweepPoint bad = point("alpha", "integrator=rk4", 1.0 / 15, 1.0, 1e6);
  bad.status = RunStatus::Diverged;
  r.points.insert(r.points.begin(), bad);
  analyse_sweep(r);
  ASSERT_EQ(r.orders.size(), 2u);
  EXPECT_EQ(r.orders[0].engine, "alpha");
  EXPECT_EQ(r.orders[0].setting, "integrator=rk4");
  ASSERT_TRUE(r.orders[0].position.slope);
  EXPECT_NEAR(*r.orders[0].position.slope, 2.0, 1e-9);
  EXPECT_EQ(r.orders[0].position.points, 6);
  ASSERT_TRUE(r.orders[0].energy.slope);
  EXPECT_NEAR(*r.orders[0].energy.slope, 2.0, 1e-9);
  EXPECT_EQ(r.orders[1].engine, "beta");
  ASSERT_TRUE(r.orders[1].position.slope);
  EXPECT_NEAR(*r.orders[1].position.slope, 1.0, 1e-9);
  EXPECT_FALSE(r.points.front().pareto);
}

TEST(SweepAnalysis, RoundOffErrorsAreNotAnOrder) {
  SweepResult r = synthetic();
  for (std::size_t i = 0; i < kDts.size(); ++i) r.points[i].position_error = 1e-13 * static_cast<double>(i + 1);
  analyse_sweep(r);
  EXPECT_TRUE(r.orders[0].exact_to_round_off);
  EXPECT_FALSE(r.orders[1].exact_to_round_off);
  std::ostringstream os;
  print_sweep_table(os, r);
  EXPECT_NE(os.str().find("exact to round-off"), std::string::npos);
}

TEST(SweepAnalysis, ParetoFrontIsThePointsNothingBeats) {
  SweepResult r;
  r.scenario = "front";
  const double wall[] = {1, 2, 3, 4, 5, 0.5};
  const double err[] = {10, 5, 5, 1, 2, 20};
  for (int i = 0; i < 6; ++i) {
    std::string name = "e";
    name += std::to_string(i);
    r.points.push_back(point(name, "", 0.01, wall[i], err[i]));
  }
  r.points[5].status = RunStatus::Error;   // fastest, but failed: not a candidate
  analyse_sweep(r);
  const bool expected[] = {true, true, false, true, false, false};
  for (int i = 0; i < 6; ++i) EXPECT_EQ(r.points[static_cast<std::size_t>(i)].pareto, expected[i]) << "point " << i;
}

TEST(SweepTable, HasItsColumnsOneRowPerPointAndTheOrders) {
  const SweepResult r = synthetic();
  std::ostringstream os;
  print_sweep_table(os, r);
  const std::vector<std::string> lines = lines_of(os.str());
  ASSERT_GE(lines.size(), 2u);
  const std::string& header = lines[1];
  for (const char* column : {"engine", "setting", "dt", "steps", "wall s/sim s", "spread", "position err (m)",
                             "energy err", "contact err (s)", "front", "status"}) {
    EXPECT_NE(header.find(column), std::string::npos) << column;
  }
  std::size_t rows = 0;
  for (const std::string& line : lines) {
    if (line.rfind("alpha ", 0) == 0 || line.rfind("beta ", 0) == 0) ++rows;
  }
  EXPECT_EQ(rows, r.points.size());
  EXPECT_NE(os.str().find("1/960"), std::string::npos);
  // The orders section names each series with its slope.
  bool alpha_order = false, beta_order = false;
  for (const std::string& line : lines) {
    if (line.find("alpha rk4") != std::string::npos && line.find("position 2.00") != std::string::npos) alpha_order = true;
    if (line.find("  beta") == 0 && line.find("position 1.00") != std::string::npos) beta_order = true;
  }
  EXPECT_TRUE(alpha_order) << os.str();
  EXPECT_TRUE(beta_order) << os.str();
}

TEST(SweepTable, MarksWideSpreadAndUnmeasuredValues) {
  SweepResult r = synthetic();
  r.points[2].spread = 0.6;
  r.points[2].spread_warning = true;
  r.points[3].position_error = std::nullopt;
  std::ostringstream os;
  print_sweep_table(os, r);
  const std::vector<std::string> lines = lines_of(os.str());
  EXPECT_NE(lines[2 + 2].find("60% !"), std::string::npos) << lines[2 + 2];
  EXPECT_EQ(lines[2 + 1].find('!'), std::string::npos);
}

TEST(SweepCsv, HeaderAndOneLinePerPointWithEmptyNulls) {
  SweepResult r = synthetic();
  r.points[0].energy_error = std::nullopt;
  const std::vector<std::string> lines = lines_of(sweep_to_csv(r));
  ASSERT_EQ(lines.size(), r.points.size() + 1);
  auto fields = [](const std::string& line) {
    std::vector<std::string> out;
    std::string cell;
    std::istringstream in(line);
    while (std::getline(in, cell, ',')) out.push_back(cell);
    if (!line.empty() && line.back() == ',') out.push_back("");
    return out;
  };
  const std::vector<std::string> header = fields(lines[0]);
  EXPECT_EQ(header.front(), "scenario");
  const auto col = [&](const std::string& name) {
    return static_cast<std::size_t>(std::find(header.begin(), header.end(), name) - header.begin());
  };
  ASSERT_LT(col("energy_error"), header.size());
  ASSERT_LT(col("position_error"), header.size());
  for (std::size_t i = 1; i < lines.size(); ++i) EXPECT_EQ(fields(lines[i]).size(), header.size()) << lines[i];
  EXPECT_EQ(fields(lines[1])[col("energy_error")], "");
  EXPECT_NEAR(std::stod(fields(lines[1])[col("position_error")]), *r.points[0].position_error, 1e-12);
  EXPECT_EQ(fields(lines[1])[col("dt_label")], "1/30");
  EXPECT_EQ(fields(lines[1])[col("setting")], "integrator=rk4");   // full label, not the short one
}

TEST(SweepJson, PointsOrdersAndNulls) {
  SweepResult r = synthetic();
  r.points[1].contact_time_error = std::nullopt;
  const nlohmann::json j = sweep_to_json(r);
  EXPECT_EQ(j["scenario"], "synthetic_fall");
  ASSERT_EQ(j["points"].size(), r.points.size());
  EXPECT_TRUE(j["points"][1]["contact_time_error"].is_null());
  EXPECT_DOUBLE_EQ(j["points"][1]["position_error"].get<double>(), *r.points[1].position_error);
  ASSERT_EQ(j["orders"].size(), 2u);
  EXPECT_NEAR(j["orders"][0]["position"]["order"].get<double>(), 2.0, 1e-9);
  EXPECT_TRUE(j.contains("context"));
}

TEST(SweepFiles, CsvJsonAndBothPlotsAreWrittenAndNonEmpty) {
  const fs::path dir = fresh_dir("files");
  const SweepResult r = synthetic();
  write_sweep(dir, r);
  for (const char* name : {"sweep.csv", "sweep.json", "speed_vs_error.png", "error_vs_dt.png"}) {
    ASSERT_TRUE(fs::exists(dir / name)) << name;
    EXPECT_GT(fs::file_size(dir / name), 100u) << name;
  }
  std::ifstream png(dir / "speed_vs_error.png", std::ios::binary);
  char sig[4] = {};
  png.read(sig, 4);
  EXPECT_EQ(std::string(sig + 1, 3), "PNG");
  nlohmann::json j;
  std::ifstream(dir / "sweep.json") >> j;
  EXPECT_EQ(j["points"].size(), r.points.size());
  fs::remove_all(dir);
}

TEST(SweepFiles, PlotsEvenWithoutAnyMeasuredError) {
  const fs::path dir = fresh_dir("noerror");
  SweepResult r = synthetic();
  for (SweepPoint& p : r.points) p.position_error = std::nullopt;
  analyse_sweep(r);
  write_sweep(dir, r);
  EXPECT_GT(fs::file_size(dir / "speed_vs_error.png"), 100u);
  EXPECT_GT(fs::file_size(dir / "error_vs_dt.png"), 100u);
  fs::remove_all(dir);
}

EngineInfo fake_engine() {
  EngineInfo info;
  info.name = "fake";
  info.options.push_back({"broad_phase", std::string("grid"), {"grid", "brute"}, "not an accuracy setting"});
  info.options.push_back({"collision", std::string("exact"), {"exact", "lecture"}, ""});
  info.options.push_back({"integrator", std::string("semi_implicit_euler"),
                          {"explicit_euler", "semi_implicit_euler", "velocity_verlet", "rk4"}, ""});
  info.options.push_back({"velocity_iterations", std::int64_t{8}, {}, ""});
  info.options.push_back({"sleep", false, {}, ""});
  return info;
}

std::vector<std::string> labels(const std::vector<SweepVariant>& v) {
  std::vector<std::string> out;
  for (const SweepVariant& s : v) out.push_back(s.label);
  return out;
}

TEST(SweepVariants, FromTheDeclaredOptions) {
  Scene scene;
  const std::vector<SweepVariant> v = sweep_variants(fake_engine(), scene, true);
  const std::vector<std::string> expected = {
      "integrator=explicit_euler collision=exact velocity_iterations=8",
      "integrator=semi_implicit_euler collision=exact velocity_iterations=8",
      "integrator=velocity_verlet collision=exact velocity_iterations=8",
      "integrator=rk4 collision=exact velocity_iterations=8",
      "integrator=semi_implicit_euler collision=lecture velocity_iterations=8",
      "integrator=semi_implicit_euler collision=exact velocity_iterations=4",
      "integrator=semi_implicit_euler collision=exact velocity_iterations=16"};
  EXPECT_EQ(labels(v), expected);
  EXPECT_EQ(std::get<std::string>(v[3].options.at("integrator")), "rk4");
  EXPECT_EQ(std::get<std::int64_t>(v[6].options.at("velocity_iterations")), 16);
  EXPECT_EQ(v[0].options.count("broad_phase"), 0u);
}

TEST(SweepVariants, BaseValuesComeFromTheScene) {
  Scene scene;
  scene.engine_options["fake"]["integrator"] = std::string("rk4");
  scene.engine_options["fake"]["velocity_iterations"] = std::int64_t{3};
  const std::vector<std::string> l = labels(sweep_variants(fake_engine(), scene, true));
  EXPECT_NE(std::find(l.begin(), l.end(), "integrator=rk4 collision=lecture velocity_iterations=3"), l.end());
  EXPECT_NE(std::find(l.begin(), l.end(), "integrator=rk4 collision=exact velocity_iterations=1"), l.end());
  EXPECT_NE(std::find(l.begin(), l.end(), "integrator=rk4 collision=exact velocity_iterations=6"), l.end());
}

TEST(SweepVariants, OneVariantWithoutSettings) {
  Scene scene;
  const std::vector<SweepVariant> off = sweep_variants(fake_engine(), scene, false);
  ASSERT_EQ(off.size(), 1u);
  EXPECT_TRUE(off[0].label.empty());
  EXPECT_TRUE(off[0].options.empty());
  EngineInfo plain;
  plain.name = "plain";
  EXPECT_EQ(sweep_variants(plain, scene, true).size(), 1u);
}

// End to end on core: a two-body orbit with semi-implicit Euler, whose position
// error is first order in dt. Checks the wiring (reference, common sample times,
// comparison), not core's accuracy: the bounds on the order are loose.
TEST(SweepRun, FirstOrderIntegratorOnAnOrbit) {
  Scene scene;
  scene.name = "sweep_orbit";
  scene.duration = 3.0;
  scene.dt = 0.01;
  scene.world.newtonian = true;
  scene.world.G = 1.0;
  BodyDef a;
  a.name = "a";
  a.shape = ShapeKind::Point;
  a.radius = 0.0;
  a.mass = 1.0;
  a.position = {1.0, 0.0};
  a.velocity = {0.0, 0.5};
  BodyDef b = a;
  b.name = "b";
  b.position = {-1.0, 0.0};
  b.velocity = {0.0, -0.5};
  scene.bodies = {a, b};
  scene.engine_options["core"]["integrator"] = std::string("semi_implicit_euler");

  SweepOptions options;
  options.dts = {1.0 / 60, 1.0 / 30, 1.0 / 120};   // unsorted on purpose
  options.engines = {"core"};
  options.repetitions = 2;
  options.settings = false;
  options.min_seconds_per_repetition = 0.0;
  std::vector<std::string> progress;
  const SweepResult r = run_sweep(scene, options, [&](const std::string& line) { progress.push_back(line); });

  ASSERT_TRUE(r.reference_available) << r.reference_reason;
  ASSERT_EQ(r.points.size(), 3u);
  EXPECT_GE(progress.size(), 3u);
  double previous_dt = 1.0;
  for (const SweepPoint& p : r.points) {
    EXPECT_EQ(p.engine, "core");
    EXPECT_EQ(p.status, RunStatus::Ok) << p.reason;
    EXPECT_LT(p.dt, previous_dt);   // coarse to fine
    previous_dt = p.dt;
    EXPECT_EQ(p.repetitions, 2);
    EXPECT_GT(p.wall_per_sim_median, 0.0);
    EXPECT_LE(p.wall_per_sim_min, p.wall_per_sim_median);
    EXPECT_GE(p.wall_per_sim_max, p.wall_per_sim_median);
    ASSERT_TRUE(p.position_error.has_value());
    EXPECT_GT(*p.position_error, 0.0);
  }
  ASSERT_EQ(r.orders.size(), 1u);
  ASSERT_TRUE(r.orders[0].position.slope.has_value());
  EXPECT_NEAR(*r.orders[0].position.slope, 1.0, 0.25);
}

TEST(SweepRun, RejectsBadStepSizes) {
  Scene scene;
  scene.name = "x";
  SweepOptions options;
  options.dts = {0.01, -0.02};
  EXPECT_THROW(run_sweep(scene, options), std::invalid_argument);
  options.dts = {};
  EXPECT_THROW(run_sweep(scene, options), std::invalid_argument);
}

TEST(SweepLabels, StepSizes) {
  EXPECT_EQ(dt_label(1.0 / 60), "1/60");
  EXPECT_EQ(dt_label(1.0 / 960), "1/960");
  EXPECT_EQ(dt_label(1.0), "1");
  EXPECT_EQ(dt_label(0.0125), "1/80");
  EXPECT_EQ(dt_label(0.003), "0.003");
}

}  // namespace
}  // namespace physval
