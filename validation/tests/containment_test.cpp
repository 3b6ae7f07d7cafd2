// Containment (issue 10): escapes through every kind of barrier a scene can describe, and
// penetration measured at every step. A scripted engine moves bodies along paths whose
// answer is known by construction; real engines are then swept over steps and speeds,
// each run held against a geometric oracle computed here from its own final state.
// Before this, only loops of walls were containers, a box or a closed surface let bodies
// out `ok`, a thin wall tunnelled `ok`, and penetration was read from samples only.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <functional>

#include "physval/adapters/registry.hpp"
#include "physval/validation/comparator.hpp"
#include "physval/validation/runner.hpp"
#include "../src/containment.hpp"

#include <random>

namespace physval {
namespace {

// Body 0 (or every moving body) at path(t); everything else where the scene put it.
class ScriptedEngine final : public Engine {
 public:
  using Path = std::function<Vec2(std::size_t body, double t)>;
  explicit ScriptedEngine(Path path) : path_(std::move(path)) { info_.name = "scripted"; }
  const EngineInfo& info() const override { return info_; }
  void load(const Scene& scene) override { scene_ = scene; }
  void step(double dt) override { t_ += dt; }
  double time() const override { return t_; }
  std::size_t body_count() const override { return scene_.bodies.size(); }
  BodyMeta body_meta(std::size_t i) const override {
    return {scene_.bodies[i].name, scene_.bodies[i].mass, scene_.bodies[i].radius, scene_.bodies[i].is_static};
  }
  void read_states(std::vector<BodyState>& out) const override {
    out.resize(scene_.bodies.size());
    for (std::size_t i = 0; i < out.size(); ++i) {
      out[i].position = scene_.bodies[i].is_static ? scene_.bodies[i].position : path_(i, t_);
      out[i].velocity = {};
    }
  }
  const std::vector<ContactEvent>& contacts() const override { return none_; }
  std::vector<Setting> settings() const override { return {}; }

 private:
  Path path_;
  EngineInfo info_;
  Scene scene_;
  double t_ = 0.0;
  std::vector<ContactEvent> none_;
};

EngineFactory scripted(ScriptedEngine::Path path) {
  EngineFactory f;
  f.info.name = "scripted";
  f.create = [path] { return std::make_unique<ScriptedEngine>(path); };
  return f;
}

BodyDef ball(const std::string& name, Vec2 at, double radius = 0.05) {
  BodyDef b;
  b.name = name;
  b.radius = radius;
  b.position = at;
  return b;
}

Scene base(double dt = 0.01) {
  Scene s;
  s.name = "containment";
  s.duration = 1.0;
  s.dt = dt;
  return s;
}

WallDef wall(const std::string& name, Vec2 a, Vec2 b) {
  WallDef w;
  w.name = name;
  w.from = a;
  w.to = b;
  return w;
}

RunRecord run_and_compare(const Scene& s, const EngineFactory& f) {
  RunRecord r = run_engine(s, f, RunOptions{});
  compare_run(r, s, Reference{}, false);
  return r;
}

// A straight path from `a` to `b` over the run (1 s).
ScriptedEngine::Path straight(Vec2 a, Vec2 b) {
  return [a, b](std::size_t, double t) { return a + (b - a) * std::min(t, 1.0); };
}

// Every closed container a scene can describe: a box; a closed surface (one polyline whose
// last point is its first); a loop of walls; a mix of walls and surface pieces.
std::vector<Scene> containers() {
  std::vector<Scene> out;
  {
    Scene s = base();
    BoxDef b;
    b.name = "cage";
    b.min = {-1.0, -1.0};
    b.max = {1.0, 1.0};
    s.boxes.push_back(b);
    out.push_back(s);
  }
  {
    Scene s = base();
    SurfaceDef f;
    f.name = "bowl";
    for (int k = 0; k <= 12; ++k) {   // a 12-gon of radius 1.2 (encloses the unit disc)
      const double a = 2.0 * M_PI * (k % 12) / 12.0;
      f.points.push_back({1.2 * std::cos(a), 1.2 * std::sin(a)});
    }
    s.surfaces.push_back(f);
    out.push_back(s);
  }
  {
    Scene s = base();
    s.walls = {wall("s", {-1, -1}, {1, -1}), wall("e", {1, -1}, {1, 1}), wall("n", {1, 1}, {-1, 1}),
               wall("w", {-1, 1}, {-1, -1})};
    out.push_back(s);
  }
  {
    Scene s = base();
    s.walls = {wall("s", {-1, -1}, {1, -1}), wall("w", {-1, 1}, {-1, -1})};
    SurfaceDef f;
    f.name = "roof";
    f.points = {{1, -1}, {1, 1}, {-1, 1}};
    s.surfaces.push_back(f);
    out.push_back(s);
  }
  return out;
}

TEST(Containment, LeavingAnyClosedContainerIsAnEscapeAndDiverged) {
  int kind = 0;
  for (Scene s : containers()) {
    s.bodies = {ball("inside", {0.0, 0.0})};
    for (Vec2 to : {Vec2{3.0, 0.2}, Vec2{-0.3, -5.0}, Vec2{2.5, 2.5}}) {
      const RunRecord r = run_and_compare(s, scripted(straight({0.0, 0.0}, to)));
      ASSERT_TRUE(r.metrics.at("escaped_bodies").has_value()) << kind;
      EXPECT_EQ(*r.metrics.at("escaped_bodies"), 1.0) << kind << " to " << to.x << "," << to.y;
      EXPECT_EQ(r.status, RunStatus::Diverged) << kind << " " << r.reason;
      ASSERT_TRUE(r.diverged_at.has_value());
      EXPECT_GT(*r.diverged_at, 0.0);
      EXPECT_FALSE(r.passed());
    }
    ++kind;
  }
}

TEST(Containment, StayingInsideOrStartingOutsideIsNoEscape) {
  for (Scene s : containers()) {
    s.bodies = {ball("inside", {0.0, 0.0}), ball("outside", {5.0, 5.0})};
    // Inside: a circle of radius 0.5 around the centre; outside: far away and back.
    auto path = [](std::size_t i, double t) {
      return i == 0 ? Vec2{0.5 * std::cos(6 * t), 0.5 * std::sin(6 * t)} : Vec2{5.0 + 3 * t, 5.0 - 2 * t};
    };
    const RunRecord r = run_and_compare(s, scripted(path));
    EXPECT_EQ(*r.metrics.at("escaped_bodies"), 0.0);
    EXPECT_EQ(r.status, RunStatus::Ok) << r.reason;
  }
}

// Legitimate ways out: through a gap, and around the free end of a wall.
TEST(Containment, LeavingThroughAGapOrAroundAWallEndIsNoEscape) {
  Scene s = base();
  // A box of walls with a 0.5 m gap in its east side (y in [-0.25, 0.25]).
  s.walls = {wall("s", {-1, -1}, {1, -1}), wall("e1", {1, -1}, {1, -0.25}), wall("e2", {1, 0.25}, {1, 1}),
             wall("n", {1, 1}, {-1, 1}), wall("w", {-1, 1}, {-1, -1})};
  s.bodies = {ball("out", {0.0, 0.0})};
  for (double speed : {0.5, 3.0, 50.0, 400.0}) {   // up to 4 m per step: still through the gap
    const RunRecord r = run_and_compare(s, scripted(straight({0, 0}, {speed, 0.0})));
    EXPECT_EQ(*r.metrics.at("escaped_bodies"), 0.0) << speed;
    EXPECT_EQ(r.status, RunStatus::Ok) << speed << " " << r.reason;
  }
  // Around the end of a single wall (x = 0, y in [0, 2]): below it and back up.
  Scene t = base();
  t.walls = {wall("fin", {0, 0}, {0, 2})};
  t.bodies = {ball("b", {-1.0, 1.0})};
  auto around = [](std::size_t, double u) {
    const double a = M_PI * u;   // from (-1, 1) down to (0, -0.5), below the end (0, 0), up to (1, 1)
    return Vec2{-std::cos(a) * 1.0, 1.0 - 1.5 * std::sin(a)};
  };
  const RunRecord r = run_and_compare(t, scripted(around));
  EXPECT_EQ(*r.metrics.at("escaped_bodies"), 0.0);
  EXPECT_EQ(r.status, RunStatus::Ok) << r.reason;
}

// A thin wall that is no container at all: stepping over it is tunnelling.
TEST(Containment, SteppingOverAThinWallIsAnEscape) {
  Scene s = base(1.0 / 60.0);
  s.walls = {wall("plate", {9.9, -1.0}, {9.9, 1.0})};
  s.bodies = {ball("bullet", {0.0, 0.0}, 0.02)};
  const RunRecord r = run_and_compare(s, scripted(straight({0, 0}, {20.0, 0.0})));
  EXPECT_EQ(*r.metrics.at("escaped_bodies"), 1.0);
  EXPECT_EQ(r.status, RunStatus::Diverged);
  EXPECT_NE(r.reason.find("bullet through wall 'plate'"), std::string::npos) << r.reason;
  // The step that crossed x = 9.9: 20 m/s, so t = 0.495 lies in the step ending at 30/60.
  ASSERT_TRUE(r.diverged_at.has_value());
  EXPECT_NEAR(*r.diverged_at, 0.5, 1e-9);
}

TEST(Containment, PassingThroughAStaticBodyIsAnEscape) {
  Scene s = base();
  BodyDef post = ball("post", {2.0, 0.0}, 0.3);
  post.is_static = true;
  s.bodies = {ball("b", {0.0, 0.0}), post};
  const RunRecord through = run_and_compare(s, scripted(straight({0, 0}, {4.0, 0.1})));
  EXPECT_EQ(*through.metrics.at("escaped_bodies"), 1.0);
  EXPECT_EQ(through.status, RunStatus::Diverged) << through.reason;
  const RunRecord past = run_and_compare(s, scripted(straight({0, 0}, {4.0, 1.0})));   // passes 0.5 m above
  EXPECT_EQ(*past.metrics.at("escaped_bodies"), 0.0);
  EXPECT_EQ(past.status, RunStatus::Ok);
}

// Two moving discs that pass into each other (centres closer than the smaller radius):
// Box2D's default discrete collision did this to half of a 3 m/s gas at dt 1/60, and the
// light ball of the pi billiard went into the heavy one, all `ok` before. A graze half a
// radius deep (a soft solver's overlap) is no pass.
TEST(Containment, MovingBodiesPassingIntoEachOtherAreAnEscapeAndDiverged) {
  Scene s = base();
  s.bodies = {ball("a", {-1.0, 0.0}, 0.1), ball("b", {1.0, 0.0}, 0.2)};
  auto crossing = [](double offset) {
    return [offset](std::size_t i, double t) {
      const double u = std::min(t, 1.0);
      return i == 0 ? Vec2{-1.0 + 2.0 * u, 0.0} : Vec2{1.0 - 2.0 * u, offset};
    };
  };
  const RunRecord through = run_and_compare(s, scripted(crossing(0.0)));
  ASSERT_TRUE(through.metrics.at("escaped_bodies").has_value());
  EXPECT_EQ(*through.metrics.at("escaped_bodies"), 2.0);
  EXPECT_EQ(through.status, RunStatus::Diverged);
  EXPECT_NE(through.reason.find("into body"), std::string::npos) << through.reason;
  for (const double offset : {0.15, 0.25, 0.5}) {   // closest approach 0.15 (depth 0.15 < 0.2), 0.25, 0.5
    const RunRecord graze = run_and_compare(s, scripted(crossing(offset)));
    EXPECT_EQ(*graze.metrics.at("escaped_bodies"), 0.0) << offset;
    EXPECT_EQ(graze.status, RunStatus::Ok) << offset << " " << graze.reason;
  }
  // A pair the collision matrix lets pass is no escape.
  s.bodies[0].group = "ghost";
  s.bodies[1].group = "solid";
  s.collision_matrix.push_back(CollisionRule{"ghost", "solid", CollisionResponse::Ignore});
  const RunRecord ghost = run_and_compare(s, scripted(crossing(0.0)));
  EXPECT_EQ(ghost.status, RunStatus::Ok) << ghost.reason;
}

// The collision matrix lets a group through a wall: that is no escape.
TEST(Containment, AGroupTheMatrixLetsThroughDoesNotEscape) {
  Scene s = base();
  s.walls = {wall("gate", {1, -1}, {1, 1})};
  s.walls[0].material.group = "gate";
  BodyDef ghost = ball("ghost", {0, 0});
  ghost.group = "ghosts";
  s.bodies = {ghost};
  s.collision_matrix.push_back({"ghosts", "gate", CollisionResponse::Ignore});
  const RunRecord r = run_and_compare(s, scripted(straight({0, 0}, {3.0, 0.0})));
  EXPECT_FALSE(r.metrics.at("escaped_bodies").has_value());   // nothing it collides with
  EXPECT_EQ(r.status, RunStatus::Ok);
}

// Penetration at every step: the deepest overlap falls between two samples.
TEST(Containment, PenetrationBetweenSamplesIsMeasured) {
  Scene s = base(0.01);
  s.sample_interval = 0.5;   // samples at t = 0, 0.5, 1
  s.walls = {wall("floor", {-5, 0}, {5, 0})};
  s.bodies = {ball("b", {0.0, 1.0}, 0.1)};
  // Down into the floor to 0.04 m deep at t = 0.23, and back up.
  auto dive = [](std::size_t, double t) { return Vec2{0.0, 0.06 + 4.0 * (t - 0.23) * (t - 0.23)}; };
  const RunRecord r = run_and_compare(s, scripted(dive));
  ASSERT_TRUE(r.metrics.at("max_penetration").has_value());
  EXPECT_NEAR(*r.metrics.at("max_penetration"), 0.04, 1e-9);
  ASSERT_TRUE(r.containment.max_penetration_time.has_value());
  EXPECT_NEAR(*r.containment.max_penetration_time, 0.23, 1e-9);
  EXPECT_NE(r.containment.max_penetration_what.find("wall 'floor'"), std::string::npos);
  // None of the three samples holds an overlap: a sampled measure would say 0.
  for (const auto& states : r.series.states) EXPECT_GT(states[0].position.y, 0.1);
}

// Real engines in a closed box, over steps and speeds. Oracle: a body whose final centre
// is outside the box passed through it; then the run must count an escape and be
// diverged. core (exact impacts) must keep every body in at every step and speed.
TEST(Containment, RealEnginesInAClosedBoxAtManySteps) {
  int bullet_escapes = 0, runs = 0;
  for (const char* kind : {"box", "walls"}) {
    for (double dt : {1.0 / 60.0, 1.0 / 6.0, 0.5}) {
      for (double speed : {3.0, 15.0, 40.0}) {
        Scene s = base(dt);
        s.duration = 2.0;
        if (std::string(kind) == "box") {
          BoxDef b;
          b.name = "cage";
          b.min = {-1.0, -1.0};
          b.max = {1.0, 1.0};
          s.boxes.push_back(b);
        } else {
          s.walls = {wall("s", {-1, -1}, {1, -1}), wall("e", {1, -1}, {1, 1}), wall("n", {1, 1}, {-1, 1}),
                     wall("w", {-1, 1}, {-1, -1})};
        }
        for (int k = 0; k < 8; ++k) {
          BodyDef b = ball("b" + std::to_string(k), {-0.6 + 0.17 * k, -0.5 + 0.13 * k}, 0.05);
          b.velocity = {speed * std::cos(0.7 * k + 0.3), speed * std::sin(0.7 * k + 0.3)};
          s.bodies.push_back(b);
        }
        for (const EngineFactory& f : engine_registry()) {
          if (!unsupported_features(f.info, s).empty()) continue;
          const RunRecord r = run_and_compare(s, f);
          ++runs;
          if (r.status == RunStatus::Error) continue;
          int outside = 0;
          for (std::size_t i = 0; i < s.bodies.size(); ++i) {
            const Vec2 p = r.final_states[i].position;
            outside += r.final_states[i].alive && (std::abs(p.x) > 1.0 || std::abs(p.y) > 1.0) ? 1 : 0;
          }
          const std::string where = f.info.name + " " + kind + " dt " + std::to_string(dt) + " v " + std::to_string(speed);
          ASSERT_TRUE(r.metrics.at("escaped_bodies").has_value()) << where;
          EXPECT_GE(*r.metrics.at("escaped_bodies"), outside) << where;
          if (outside > 0) {
            EXPECT_EQ(r.status, RunStatus::Diverged) << where;
          }
          if (*r.metrics.at("escaped_bodies") > 0) {
            EXPECT_FALSE(r.passed()) << where;
          }
          if (f.info.name == "core") {
            EXPECT_EQ(*r.metrics.at("escaped_bodies"), 0.0) << where;
          }
          if (f.info.name == "bullet") bullet_escapes += *r.metrics.at("escaped_bodies") > 0 ? 1 : 0;
        }
      }
    }
  }
  EXPECT_GT(runs, 30);
  EXPECT_GT(bullet_escapes, 0);   // the sweep reaches Bullet's tunnelling (else it shows nothing)
}


// The moving pairs through horizontal strips (the monitor's default from 512 moving bodies)
// against the plain x sweep: the same record after every step (deepest overlap, its time
// and pair, escapes, the first escape's names) on gases where pairs overlap, tie exactly
// (a lattice), pass into each other (jumps), die and come back, with mixed radii, points,
// a group the matrix lets through and walls; some steps move no body at all.
TEST(Containment, StripsEqualPlainSweepOnRandomGases) {
  int escapes_seen = 0, steps = 0;
  for (unsigned seed = 1; seed <= 12; ++seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> unit(-1.0, 1.0), prob(0.0, 1.0);
    Scene scene;
    scene.name = "gas";
    const double half = 3.0;
    const Vec2 c[4] = {{-half, -half}, {half, -half}, {half, half}, {-half, half}};
    for (int k = 0; k < 4; ++k) {
      WallDef w;
      w.name = std::string("w").append(std::to_string(k));
      w.from = c[k];
      w.to = c[(k + 1) % 4];
      scene.walls.push_back(w);
    }
    const std::size_t n = 40 + 30 * seed;
    const bool lattice = seed % 3 == 0;
    const double spacing = lattice ? 0.0625 : 0.0;   // exact: every lattice overlap ties at start
    const std::size_t side = static_cast<std::size_t>(std::ceil(std::sqrt(static_cast<double>(n))));
    std::vector<BodyState> states(n);
    for (std::size_t i = 0; i < n; ++i) {
      BodyDef b;
      b.name = std::string("b").append(std::to_string(i));
      b.shape = i % 17 == 5 ? ShapeKind::Point : ShapeKind::Circle;
      b.radius = b.shape == ShapeKind::Point ? 0.0 : (lattice ? 0.05 : 0.02 + 0.06 * prob(rng));
      if (i % 11 == 3) b.group = "ghost";
      b.position = lattice ? Vec2{static_cast<double>(i % side) * spacing - 1.0, static_cast<double>(i / side) * spacing - 1.0}
                           : Vec2{2.5 * unit(rng), 2.5 * unit(rng)};
      // The last body, far below and to the right, sets the lowest y and so where the strips
      // divide the lattice's rows (tied overlaps in neighbouring strips: their order counts).
      if (lattice && i + 1 == n) b.position = {2.5, -2.0 - 0.021 * seed};
      scene.bodies.push_back(b);
      states[i].position = b.position;
      states[i].velocity = {unit(rng), unit(rng)};
    }
    scene.collision_matrix.push_back({"ghost", "", CollisionResponse::Ignore});
    ContainmentMonitor strips(scene), plain(scene);
    strips.use_strips(true);   // from 32 bodies (by default from 512)
    plain.use_plain_sweep(true);
    auto same = [&](int k) {
      const ContainmentRecord& a = strips.record();
      const ContainmentRecord& b = plain.record();
      const std::string where = "seed " + std::to_string(seed) + " step " + std::to_string(k);
      EXPECT_EQ(a.max_penetration, b.max_penetration) << where;
      EXPECT_EQ(a.max_penetration_time, b.max_penetration_time) << where;
      EXPECT_EQ(a.max_penetration_what, b.max_penetration_what) << where;
      EXPECT_EQ(a.escaped_bodies, b.escaped_bodies) << where;
      EXPECT_EQ(a.first_escape_time, b.first_escape_time) << where;
      EXPECT_EQ(a.first_escape, b.first_escape) << where;
      return !::testing::Test::HasFailure();
    };
    strips.start(states);
    plain.start(states);
    ASSERT_TRUE(same(0));
    const double h = 1.0 / 60.0;
    for (int k = 1; k <= 200; ++k) {
      const bool still = k % 50 == 0;
      for (std::size_t i = 0; i < n && !still; ++i) {
        BodyState& s = states[i];
        if (prob(rng) < 0.01) s.alive = !s.alive;
        const double jump = prob(rng) < 0.02 ? 20.0 : 1.0;   // now and then through a neighbour
        s.position = s.position + s.velocity * (h * jump);
        for (double* x : {&s.position.x, &s.position.y}) *x = std::clamp(*x, -half + 0.01, half - 0.01);
        if (prob(rng) < 0.05) s.velocity = {unit(rng), unit(rng)};
      }
      strips.observe(k * h, states);
      plain.observe(k * h, states);
      ASSERT_TRUE(same(k));
      ++steps;
    }
    escapes_seen += strips.record().escaped_bodies.value_or(0) > 0 ? 1 : 0;
  }
  EXPECT_EQ(steps, 12 * 200);
  EXPECT_GT(escapes_seen, 6);   // the gases do pass bodies into each other
}


// Pairs left out as apart all step (their straight relative path farther apart than the
// radii together) against the full tests for every pair the filters pass: the same whole
// record after every step (deepest overlap, its time and pair, escapes and their list, the
// first escape, every skipped-impact graze and the dropped count) on gases of circles and
// points whose bodies fly straight (grazes), jump through neighbours (passes into each
// other), turn within a step (bends), rest pressed into each other (overlaps), die and come
// back, with a group the matrix lets through.
TEST(Containment, FarPairSkipEqualsFullTestsOnRandomGases) {
  int escapes_seen = 0, grazes_seen = 0;
  std::uint64_t skipped = 0;
  for (unsigned seed = 1; seed <= 12; ++seed) {
    std::mt19937 rng(100 + seed);
    std::uniform_real_distribution<double> unit(-1.0, 1.0), prob(0.0, 1.0);
    Scene scene;
    scene.name = "gas";
    const double half = 2.0;
    const Vec2 c[4] = {{-half, -half}, {half, -half}, {half, half}, {-half, half}};
    for (int k = 0; k < 4; ++k) {
      WallDef w;
      w.name = std::string("w").append(std::to_string(k));
      w.from = c[k];
      w.to = c[(k + 1) % 4];
      scene.walls.push_back(w);
    }
    const std::size_t n = 30 + 25 * seed;
    std::vector<BodyState> states(n);
    for (std::size_t i = 0; i < n; ++i) {
      BodyDef b;
      b.name = std::string("b").append(std::to_string(i));
      b.shape = i % 13 == 5 ? ShapeKind::Point : ShapeKind::Circle;
      b.radius = b.shape == ShapeKind::Point ? 0.0 : 0.03 + 0.05 * prob(rng);
      if (i % 11 == 3) b.group = "ghost";
      b.position = {1.8 * unit(rng), 1.8 * unit(rng)};
      scene.bodies.push_back(b);
      states[i].position = b.position;
      states[i].velocity = {2.0 * unit(rng), 2.0 * unit(rng)};
    }
    scene.collision_matrix.push_back({"ghost", "", CollisionResponse::Ignore});
    ContainmentMonitor fast(scene), full(scene);
    full.use_full_pair_tests(true);
    auto same = [&](int k) {
      const ContainmentRecord& a = fast.record();
      const ContainmentRecord& b = full.record();
      const std::string where = "seed " + std::to_string(seed) + " step " + std::to_string(k);
      EXPECT_EQ(a.max_penetration, b.max_penetration) << where;
      EXPECT_EQ(a.max_penetration_time, b.max_penetration_time) << where;
      EXPECT_EQ(a.max_penetration_what, b.max_penetration_what) << where;
      EXPECT_EQ(a.escaped_bodies, b.escaped_bodies) << where;
      EXPECT_EQ(a.escaped_list, b.escaped_list) << where;
      EXPECT_EQ(a.first_escape_time, b.first_escape_time) << where;
      EXPECT_EQ(a.first_escape, b.first_escape) << where;
      EXPECT_EQ(a.grazes.size(), b.grazes.size()) << where;
      for (std::size_t g = 0; g < std::min(a.grazes.size(), b.grazes.size()); ++g) {
        EXPECT_EQ(a.grazes[g].a, b.grazes[g].a) << where;
        EXPECT_EQ(a.grazes[g].b, b.grazes[g].b) << where;
        EXPECT_EQ(a.grazes[g].time, b.grazes[g].time) << where;
        EXPECT_EQ(a.grazes[g].depth, b.grazes[g].depth) << where;
      }
      EXPECT_EQ(a.grazes_dropped, b.grazes_dropped) << where;
      return !::testing::Test::HasFailure();
    };
    fast.start(states);
    full.start(states);
    ASSERT_TRUE(same(0));
    const double h = 1.0 / 60.0;
    for (int k = 1; k <= 150; ++k) {
      for (std::size_t i = 0; i < n; ++i) {
        BodyState& s = states[i];
        if (prob(rng) < 0.005) s.alive = !s.alive;
        const double r = prob(rng);
        if (r < 0.02) {
          s.position = s.position + s.velocity * (20.0 * h);   // a jump, through a neighbour now and then
        } else if (r < 0.06) {
          const Vec2 v0 = s.velocity;   // turns within the step: a bent path
          s.velocity = {2.0 * unit(rng), 2.0 * unit(rng)};
          s.position = s.position + (v0 + s.velocity) * (0.25 * h);
        } else if (i % 7 == 0 && i + 1 < n) {
          s.position = states[i + 1].position + Vec2{0.05 * unit(rng), 0.05 * unit(rng)};   // pressed into another
        } else {
          s.position = s.position + s.velocity * h;   // straight
        }
        for (double* x : {&s.position.x, &s.position.y}) *x = std::clamp(*x, -half + 0.01, half - 0.01);
      }
      fast.observe(k * h, states);
      full.observe(k * h, states);
      ASSERT_TRUE(same(k));
    }
    escapes_seen += fast.record().escaped_bodies.value_or(0) > 0 ? 1 : 0;
    grazes_seen += fast.record().grazes.empty() ? 0 : 1;
    skipped += fast.far_pairs_skipped();
    EXPECT_EQ(full.far_pairs_skipped(), 0u);
  }
  EXPECT_GT(escapes_seen, 6);    // the gases do pass bodies into each other
  EXPECT_GT(grazes_seen, 6);     // and keep skipped-impact grazes
  EXPECT_GT(skipped, 10000u);    // and most pairs are apart
}

// The barrier test's open box (a body whose swept box lies inside every barrier box's
// outside skips the barriers): one step from anywhere inside a walled square to anywhere
// around it, 4000 times, held against the geometry worked out here: an end beyond a wall
// is an escape, and the penetration is the radius less the end's distance to the nearest
// wall. Steps from near the middle (inside the open box) and from near the walls (outside
// it), ending inside, touching a wall or beyond it, and a seed (the bodies' mean) off centre.
TEST(Containment, OneStepAgainstTheWallsOfASquareMatchesTheGeometry) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> inside(-0.98, 0.98), around(-1.3, 1.3), radius(0.0, 0.2);
  auto segment_distance = [](Vec2 p, Vec2 a, Vec2 b) {
    const Vec2 d = b - a;
    const double u = std::clamp(dot(p - a, d) / dot(d, d), 0.0, 1.0);
    return length(p - (a + d * u));
  };
  const Vec2 c[4] = {{-1.0, -1.0}, {1.0, -1.0}, {1.0, 1.0}, {-1.0, 1.0}};
  int escapes = 0, touching = 0, skipped = 0;
  for (int trial = 0; trial < 4000; ++trial) {
    const double r = trial % 4 == 0 ? 0.0 : radius(rng);
    const Vec2 p0{inside(rng), inside(rng)}, p1{around(rng), around(rng)};
    // Ends within 1e-6 of a wall's line are left out (which side they are on is round-off).
    if (std::abs(std::abs(p1.x) - 1.0) < 1e-6 || std::abs(std::abs(p1.y) - 1.0) < 1e-6) {
      ++skipped;
      continue;
    }
    Scene s = base();
    for (int k = 0; k < 4; ++k) s.walls.push_back(wall("w" + std::to_string(k), c[k], c[(k + 1) % 4]));
    BodyDef b = ball("b", p0, r);
    if (r == 0.0) b.shape = ShapeKind::Point;
    s.bodies.push_back(b);
    // A resting second body moves the seed of the open box off the centre.
    // (in a group the moving body passes through: only the walls are judged here).
    BodyDef rest = ball("rest", {trial % 2 ? 0.9 : -0.5, 0.3}, 0.01);
    rest.group = "ghost";
    s.bodies.push_back(rest);
    s.collision_matrix.push_back({s.bodies[0].group, "ghost", CollisionResponse::Ignore});
    ContainmentMonitor monitor(s);
    std::vector<BodyState> states(2);
    states[0].position = p0;
    states[1].position = s.bodies[1].position;
    monitor.start(states);
    states[0].position = p1;
    monitor.observe(0.01, states);
    const bool out = std::abs(p1.x) > 1.0 || std::abs(p1.y) > 1.0;
    double nearest = std::numeric_limits<double>::infinity();
    for (int k = 0; k < 4; ++k) nearest = std::min(nearest, segment_distance(p1, c[k], c[(k + 1) % 4]));
    const double start_depth = r - std::min({1.0 - std::abs(p0.x), 1.0 - std::abs(p0.y)});
    const double depth = std::max({0.0, r - nearest, start_depth});
    const ContainmentRecord& rec = monitor.record();
    ASSERT_TRUE(rec.escaped_bodies.has_value());
    EXPECT_EQ(*rec.escaped_bodies, out ? 1 : 0) << "trial " << trial << " from (" << p0.x << ", " << p0.y << ") to ("
                                                << p1.x << ", " << p1.y << ") r " << r;
    EXPECT_NEAR(rec.max_penetration, depth, 1e-12) << "trial " << trial;
    escapes += out ? 1 : 0;
    touching += !out && r - nearest > 0.0 ? 1 : 0;
  }
  EXPECT_GT(escapes, 1000);
  EXPECT_GT(touching, 100);
  EXPECT_LT(skipped, 40);
}

}  // namespace
}  // namespace physval
