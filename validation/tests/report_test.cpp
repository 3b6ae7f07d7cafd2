// The report, from results folders: one written by write_results from a synthetic
// suite (so the report reads what physval actually writes), and a bare results.json
// with fields missing (older or partial files degrade, they do not fail).
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <regex>
#include <set>
#include <sstream>
#include <string>

#include "physval/validation/plot.hpp"
#include "physval/validation/report.hpp"
#include "physval/validation/results_json.hpp"
#include "../src/report_figures.hpp"

namespace physval {
namespace {

namespace fs = std::filesystem;

fs::path fresh_dir(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / ("physval-report-test-" + name + "-" + std::to_string(::getpid()));
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

std::string read_text(const fs::path& file) {
  std::ifstream in(file);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// A body falling from `height` (g = 9.81), with a small per-engine error, and a
// contact with the floor at `contact_time` when it is positive.
RunRecord falling_run(const std::string& scenario, const std::string& engine, double height, double error,
                      double contact_time) {
  RunRecord r;
  r.scenario = scenario;
  r.engine = engine;
  r.engine_version = "test";
  r.precision = "float64";
  r.dt = 0.01;
  r.steps = 100;
  r.steps_planned = 100;
  r.wall_seconds = 0.001;
  r.bodies = {BodyMeta{"ball", 1.0, 0.1, false}, BodyMeta{"puck", 2.0, 0.1, false}};
  for (int k = 0; k <= 100; ++k) {
    const double t = 0.01 * k;
    std::vector<BodyState> states(2);
    states[0].position = {0.5 * t, height - 0.5 * 9.81 * t * t * (1.0 + error)};
    states[0].velocity = {0.5, -9.81 * t};
    states[1].position = {std::cos(t), std::sin(t)};
    states[1].velocity = {-std::sin(t), std::cos(t)};
    Totals totals;
    totals.kinetic = 0.5 * (0.25 + 9.81 * 9.81 * t * t) + 1.0;
    totals.potential = 9.81 * states[0].position.y;
    totals.momentum = {0.5 + 2.0 * states[1].velocity.x, -9.81 * t + 2.0 * states[1].velocity.y};
    totals.angular_momentum = 2.0 + 0.1 * t * error;
    r.series.time.push_back(t);
    r.series.totals.push_back(totals);
    r.series.states.push_back(states);
  }
  const auto last = r.series.states.back();
  r.final_states = SampleRow(last.begin(), last.end());
  if (contact_time > 0.0) r.contacts.push_back({"ball", "floor", contact_time + error, 1});
  r.metrics["energy_drift"] = std::nullopt;
  r.metrics["position_divergence"] = error * 4.9;
  r.metrics["energy_divergence"] = error;
  r.metrics["contact_time_error"] = contact_time > 0.0 ? std::optional<double>(error) : std::nullopt;
  r.checks.push_back({"expectation_failures", 0.0, 0.0, true, true, false, ""});
  return r;
}

ScenarioResult scenario(const std::string& name, double contact_time) {
  ScenarioResult s;
  s.scene.name = name;
  s.scene.duration = 1.0;
  s.scene.dt = 0.01;
  s.reference.available = true;
  s.reference.converged = true;
  s.reference.dt = 0.00125;
  s.reference.run = falling_run(name, "core", 10.0, 0.0, contact_time);
  s.runs.push_back(falling_run(name, "core", 10.0, 1e-6, contact_time));
  s.runs.push_back(falling_run(name, "box2d", 10.0, 2e-3, contact_time));
  RunRecord unsupported;
  unsupported.scenario = name;
  unsupported.engine = "bullet";
  unsupported.status = RunStatus::Unsupported;
  unsupported.reason = "cannot model newtonian_gravity";
  s.runs.push_back(unsupported);
  return s;
}

// Every <img src="..."> of the page.
std::set<std::string> images(const std::string& page) {
  std::set<std::string> out;
  const std::regex img("<img src=\"([^\"]+)\"");
  for (auto it = std::sregex_iterator(page.begin(), page.end(), img); it != std::sregex_iterator(); ++it) {
    out.insert((*it)[1].str());
  }
  return out;
}

TEST(Report, FromWrittenResultsEveryScenarioWithItsPlots) {
  const fs::path dir = fresh_dir("suite");
  SuiteResult suite;
  suite.scenarios.push_back(scenario("ball_drop", 0.4));
  suite.scenarios.push_back(scenario("quiet_orbit", 0.0));   // no contacts anywhere
  write_results(dir, suite);

  write_report(dir);
  const fs::path page_file = dir / "report.html";
  ASSERT_TRUE(fs::exists(page_file));
  const std::string page = read_text(page_file);
  for (const char* name : {"ball_drop", "quiet_orbit"}) {
    EXPECT_NE(page.find("<h2 id=\"" + std::string(name) + "\">"), std::string::npos) << name;
  }
  EXPECT_NE(page.find("cannot model newtonian_gravity"), std::string::npos);

  const std::set<std::string> srcs = images(page);
  for (const std::string& src : srcs) {
    ASSERT_TRUE(fs::exists(dir / src)) << src;
    EXPECT_GT(fs::file_size(dir / src), 1000u) << src;
  }
  for (const char* expected : {"plots/overview.png", "plots/ball_drop_energy.png", "plots/ball_drop_momentum.png",
                               "plots/ball_drop_trajectories.png", "plots/ball_drop_contacts.png",
                               "plots/quiet_orbit_energy.png", "plots/quiet_orbit_trajectories.png"}) {
    EXPECT_EQ(srcs.count(expected), 1u) << expected;
  }
  // No contacts: no contact plot, a sentence instead.
  EXPECT_EQ(srcs.count("plots/quiet_orbit_contacts.png"), 0u);
  EXPECT_NE(page.find("No contacts in this scenario"), std::string::npos);
  fs::remove_all(dir);
}

TEST(Report, DegradesWhenFieldsAreMissing) {
  const fs::path dir = fresh_dir("bare");
  // No context, no references, no series folder, a run with almost nothing.
  std::ofstream(dir / "results.json") << R"({"runs": [
    {"scenario": "lonely", "engine": "core", "status": "ok", "metrics": {"energy_drift": null}},
    {"scenario": "lonely", "engine": "box2d", "status": "error", "reason": "it <crashed> & burned"}
  ]})";
  write_report(dir);
  const std::string page = read_text(dir / "report.html");
  EXPECT_NE(page.find("lonely"), std::string::npos);
  EXPECT_NE(page.find("no &quot;references&quot;"), std::string::npos);
  EXPECT_NE(page.find("it &lt;crashed&gt; &amp; burned"), std::string::npos);
  for (const std::string& src : images(page)) EXPECT_TRUE(fs::exists(dir / src)) << src;
  fs::remove_all(dir);
}

// A divergence its scenario records as known (the gate passes it) read in the summary
// exactly like one that fails the gate; the cell now says "(known)", and only there.
TEST(Report, TheSummaryMarksAKnownDivergence) {
  const fs::path dir = fresh_dir("known");
  std::ofstream(dir / "results.json") << R"({"runs": [
    {"scenario": "orbit", "engine": "core", "status": "ok", "metrics": {}},
    {"scenario": "orbit", "engine": "chipmunk", "status": "diverged", "known_divergence": true, "metrics": {}},
    {"scenario": "orbit", "engine": "ode", "status": "diverged", "known_divergence": false, "metrics": {}}
  ]})";
  write_report(dir);
  const std::string page = read_text(dir / "report.html");
  const std::string known = "<span class=bad>diverged</span> <span class=grey";
  const std::size_t at = page.find(known);
  ASSERT_NE(at, std::string::npos) << "no known divergence marked";
  EXPECT_EQ(page.find(known, at + 1), std::string::npos) << "the unknown divergence is marked known too";
  EXPECT_NE(page.find("(known)</span>"), std::string::npos);
  fs::remove_all(dir);
}

TEST(Report, WithoutGnuplotThePageIsWrittenAndTheErrorRaised) {
  const fs::path dir = fresh_dir("nognuplot");
  SuiteResult suite;
  suite.scenarios.push_back(scenario("ball_drop", 0.4));
  write_results(dir, suite);
  const char* old_path = std::getenv("PATH");
  const std::string saved = old_path != nullptr ? old_path : "";
  ::setenv("PATH", "/nonexistent-physval-test", 1);
  std::string message;
  try {
    write_report(dir);
  } catch (const plot::PlotError& e) {
    message = e.what();
  }
  ::setenv("PATH", saved.c_str(), 1);
  EXPECT_NE(message.find("ball_drop_energy.png"), std::string::npos) << message;
  ASSERT_TRUE(fs::exists(dir / "report.html"));
  const std::string page = read_text(dir / "report.html");
  EXPECT_NE(page.find("could not be drawn"), std::string::npos);
  EXPECT_TRUE(images(page).empty());   // no links to pictures that do not exist
  fs::remove_all(dir);
}

TEST(Report, MissingResultsIsAnError) {
  const fs::path dir = fresh_dir("empty");
  EXPECT_THROW(write_report(dir), std::runtime_error);
  EXPECT_FALSE(fs::exists(dir / "report.html"));
  fs::remove_all(dir);
}

TEST(Report, FileNamesMatchTheSeriesFolder) {
  EXPECT_EQ(report_file_name("head_on-elastic_2"), "head_on-elastic_2");
  EXPECT_EQ(report_file_name("a b/c"), "a_b_c");
}

// Body names starting on top of one another (a gas) are not printed over each other:
// of three bodies starting within a few centimetres only one is named, the one far
// away keeps its name, and the panel says how many names it left out.
TEST(Report, TrajectoryNamesDoNotCollide) {
  report_detail::ScenarioView v;
  v.name = "crowd";
  report_detail::Source s;
  s.label = "core";
  s.engine = "core";
  s.table.names = {"t", "x_a", "y_a", "x_b", "y_b", "x_c", "y_c", "x_far", "y_far"};
  s.table.columns = {{0, 1}, {0, 0}, {0, 1}, {0.01, 0}, {0, 1}, {0.02, 0}, {0.01, 1}, {10, 10}, {0, 1}};
  v.sources.push_back(s);
  const plot::Figure fig = report_detail::trajectory_figure(v, {"core"});
  ASSERT_EQ(fig.panels.size(), 1u);
  std::set<std::string> named;
  for (const plot::Label& l : fig.panels[0].labels) named.insert(l.text);
  EXPECT_EQ(named, (std::set<std::string>{"a", "far"}));
  EXPECT_NE(fig.panels[0].note.find("2 body names left out"), std::string::npos) << fig.panels[0].note;
}

// The overview tells an exact zero from "not measured": a zero becomes an open marker
// in its own series (left of every measured value), a null no point at all.
TEST(Report, OverviewTellsZeroFromNotMeasured) {
  const nlohmann::json zero = {{"engine", "core"}, {"metrics", {{"position_divergence", 0.0}}}};
  const nlohmann::json some = {{"engine", "core"}, {"metrics", {{"position_divergence", 1e-3}}}};
  const nlohmann::json none = {{"engine", "core"}, {"metrics", {{"position_divergence", nullptr}}}};
  std::vector<report_detail::ScenarioView> views(3);
  views[0].runs = {&zero};
  views[1].runs = {&some};
  views[2].runs = {&none};
  const plot::Figure fig = report_detail::overview_figure(views, {"core"});
  const plot::Panel& p = fig.panels.at(0);
  ASSERT_EQ(p.series.size(), 2u);
  EXPECT_EQ(p.series[0].x, std::vector<double>{1e-3});
  EXPECT_EQ(p.series[1].title, "core = 0");
  ASSERT_EQ(p.series[1].x.size(), 1u);
  EXPECT_LT(p.series[1].x[0], 1e-3);
  EXPECT_NE(p.series[1].point_type, p.series[0].point_type);
}

}  // namespace
}  // namespace physval
