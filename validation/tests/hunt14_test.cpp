// The fourteenth hunt (README, *Containment*): a body through an opening narrower than itself
// (a drain between two floor pieces, the gap between two pegs, between a peg and a wall)
// left its container as surely as one through a wall, and was `ok`. Each test failed before
// the fix.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

#include "../src/containment.hpp"
#include "containment_fixture.hpp"
#include "physval_command.hpp"

namespace physval {
namespace {

namespace fs = std::filesystem;
using physval_test::physval;
using physval_test::Result;

class Hunt14 : public physval_test::TempDirTest {
 protected:
  Hunt14() : TempDirTest("physval_hunt14_") {}
};

using containment_test::at;
using containment_test::ball;
using containment_test::wall;

// A ball of radius r moved in three steps from above an opening to below it, through the
// opening's middle (x = 1): the monitor's escapes.
int escapes_through(const Scene& s, double r, std::string* first = nullptr) {
  ContainmentMonitor m(s);
  const std::size_t i = s.bodies.size() - 1;   // the moving ball is the last body
  std::vector<BodyState> states;
  for (const BodyDef& b : s.bodies) states.push_back(at(b.position));
  m.start(states);
  const double ys[] = {0.5 * r, -0.5 * r, -3.0 * r};
  double t = 0.0;
  for (double y : ys) {
    t += 0.1;
    states[i] = at({1.0, y}, {0.0, -1.0});
    m.observe(t, states);
  }
  if (first) *first = m.record().first_escape;
  return m.record().escaped_bodies.value_or(-1);
}

// A drain between two floor pieces, w wide, under a 0.1 m ball: narrower than its diameter
// (beyond the 2% slop the monitor allows any solver), crossing it is an escape; as wide or
// wider, it is a way out like any other. A point passes anything.
TEST(Hunt14Containment, ABodyThroughADrainNarrowerThanItselfIsAnEscape) {
  for (const double w : {0.05, 0.12, 0.15, 0.18, 0.195, 0.2, 0.21, 0.3}) {
    SCOPED_TRACE("drain " + std::to_string(w));
    Scene s;
    s.name = "drain";
    s.dt = 0.1;
    s.walls = {wall("floor_a", {-1.0, 0.0}, {1.0 - 0.5 * w, 0.0}), wall("floor_b", {1.0 + 0.5 * w, 0.0}, {3.0, 0.0})};
    s.bodies = {ball("b", {1.0, 1.0}, 0.1)};
    std::string first;
    const int n = escapes_through(s, 0.1, &first);
    if (w < 0.2 * (1.0 - ContainmentRecord::kGrazeSlop)) {
      EXPECT_EQ(n, 1);
      EXPECT_EQ(first.rfind("b through the gap between wall 'floor_a' and wall 'floor_b' (", 0), 0u) << first;
    } else {
      EXPECT_EQ(n, 0) << first;
    }
    s.bodies = {ball("p", {1.0, 1.0}, 0.0)};
    EXPECT_EQ(escapes_through(s, 0.0), 0) << "a point";
  }
}

// The same between two static pegs, a peg and a wall's end, a peg above a floor; and between
// pegs far enough apart, no escape. A ball moving beside an opening without crossing it, or
// resting on it, has none either.
TEST(Hunt14Containment, ABodyBetweenPegsOrAPegAndAWallNarrowerThanItselfIsAnEscape) {
  struct Case {
    const char* what;
    Scene s;
    bool escape;
  };
  std::vector<Case> cases;
  {
    Scene s;   // pegs of 0.05 m at x = 0.88 and 1.12: a gap of 0.14 m
    s.bodies = {ball("l", {0.88, 0.0}, 0.05, true), ball("r", {1.12, 0.0}, 0.05, true), ball("b", {1.0, 1.0}, 0.1)};
    cases.push_back({"two pegs 0.14 m apart", s, true});
    s.bodies[0].position.x = 0.8;
    s.bodies[1].position.x = 1.2;   // 0.3 m apart
    cases.push_back({"two pegs 0.3 m apart", s, false});
  }
  {
    Scene s;   // a wall ending at x = 0.93, a peg of 0.05 m at 1.12: 0.14 m
    s.walls = {wall("ledge", {-1.0, 0.0}, {0.93, 0.0})};
    s.bodies = {ball("peg", {1.12, 0.0}, 0.05, true), ball("b", {1.0, 1.0}, 0.1)};
    cases.push_back({"a wall's end and a peg", s, true});
  }
  {
    Scene s;   // a peg of 0.05 m hanging 0.15 m above a floor, crossed sideways
    s.walls = {wall("floor", {-2.0, 0.0}, {4.0, 0.0})};
    s.bodies = {ball("peg", {1.0, 0.2}, 0.05, true), ball("b", {0.5, 0.07}, 0.1)};
    ContainmentMonitor m(s);
    std::vector<BodyState> states = {at({1.0, 0.2}), at({0.5, 0.07})};
    m.start(states);
    states[1] = at({0.9, 0.07});
    m.observe(0.1, states);
    states[1] = at({1.1, 0.07});
    m.observe(0.2, states);
    EXPECT_EQ(m.record().escaped_bodies.value_or(-1), 1) << "under a peg lower than the ball";
    const std::string& first = m.record().first_escape;
    EXPECT_EQ(first.rfind("b through the gap between ", 0), 0u) << first;
    EXPECT_NE(first.find("static body 'peg'"), std::string::npos) << first;
    EXPECT_NE(first.find("wall 'floor'"), std::string::npos) << first;
  }
  for (Case& c : cases) {
    c.s.name = "pegs";
    c.s.dt = 0.1;
    EXPECT_EQ(escapes_through(c.s, 0.1), c.escape ? 1 : 0) << c.what;
  }
  {
    // A ball resting on a 0.12 m drain, then rolling off to the side: no escape.
    Scene s;
    s.walls = {wall("floor_a", {-1.0, 0.0}, {0.94, 0.0}), wall("floor_b", {1.06, 0.0}, {3.0, 0.0})};
    s.bodies = {ball("b", {1.0, 0.08}, 0.1)};
    ContainmentMonitor m(s);
    std::vector<BodyState> states = {at({1.0, 0.08})};
    m.start(states);
    for (int k = 1; k <= 20; ++k) {
      states[0] = at({1.0 + 0.05 * k, k < 3 ? 0.08 : 0.1});
      m.observe(0.1 * k, states);
    }
    EXPECT_EQ(m.record().escaped_bodies.value_or(-1), 0);
  }
}

// The hunt's scene end to end: a ball dropped onto a drain 0.12 m wide in a closed box. An
// engine that pushes it through (it ends below the floor) is `diverged`, naming the gap; one
// that keeps it in the box (core: wedged above the drain) is `ok`. Before: Bullet, Chipmunk
// and ODE let it fall out, `ok`, escaped 0.
TEST_F(Hunt14, ABallPushedThroughANarrowDrainIsDiverged) {
  const fs::path scene = fs::path(PHYSVAL_TESTS_DIR) / "hunt14" / "narrow_drain.toml";
  const fs::path out = dir_ / "out";
  const Result r = physval("run " + scene.string() + " --quiet --no-cache --out " + out.string());
  ASSERT_TRUE(r.status == 0 || r.status == 1) << r.output;
  std::ifstream in(out / "results.json");
  const nlohmann::json j = nlohmann::json::parse(in);
  int fell = 0;
  for (const auto& run : j["runs"]) {
    if (run["status"] == "unsupported") continue;
    double y = 0.0;
    for (const auto& f : run["final"]) {
      if (f["body"] == "b0") y = f["position"][1].get<double>();
    }
    const std::string reason = run.value("reason", "");
    if (y < 0.0) {
      ++fell;
      EXPECT_EQ(run["status"], "diverged") << run["engine"] << " ended at y = " << y;
      EXPECT_NE(reason.find("b0 through the gap between wall 'floor_a' and wall 'floor_b'"), std::string::npos) << reason;
    } else {
      EXPECT_EQ(run["status"], "ok") << run["engine"] << ": " << reason;
    }
    if (run["engine"] == "core") EXPECT_GT(y, 0.0) << "core keeps the ball in the box";
  }
  EXPECT_GE(fell, 1) << "the scene no longer shows the squeeze (the hunt saw Bullet, Chipmunk and ODE do it)";
}

// Six balls (e 0.6, mu 0.2) settle into one row filling a 1.2 m box's width. At dt/8 (the
// reference) one simultaneous set of four touching balls in the row, some sliding and some in
// flight, pressed together by the sliders' friction alone, was met again and again at one
// instant from t = 1.17 s (~3.5 ms a set): the step crawled towards the event cap, about an
// hour, and `physval run` never returned (with --timeout, `error`). A pair met at one instant
// over and over now counts as an impact storm, and the granular mode takes the row.
TEST_F(Hunt14, ARowOfSixFillingTheBoxFinishes) {
  const fs::path scene = fs::path(PHYSVAL_TESTS_DIR) / "hunt14" / "row_of_six_crawl.toml";
  const fs::path out = dir_ / "out";
  const Result r = physval("run " + scene.string() + " --engines core --quiet --no-cache --timeout 300 --out " + out.string());
  ASSERT_EQ(r.status, 0) << r.output;
  std::ifstream in(out / "results.json");
  const nlohmann::json j = nlohmann::json::parse(in);
  ASSERT_EQ(j["runs"].size(), 1u);
  EXPECT_EQ(j["runs"][0]["status"], "ok") << j["runs"][0].value("reason", "");
  EXPECT_EQ(j["references"][0]["available"], true) << j["references"][0].value("reason", "");
}

}  // namespace
}  // namespace physval
