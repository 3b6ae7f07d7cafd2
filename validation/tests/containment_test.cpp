// Containment (issue 10): escapes through every kind of barrier a scene can describe, and
// penetration measured at every step. A scripted engine moves bodies along paths whose
// answer is known by construction; real engines are then swept over steps and speeds,
// each run held against a geometric oracle computed here from its own final state.
// Before this, only loops of walls were containers, a box or a closed surface let bodies
// out `ok`, a thin wall tunnelled `ok`, and penetration was read from samples only.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>

#include "physval/adapters/registry.hpp"
#include "physval/validation/comparator.hpp"
#include "physval/validation/runner.hpp"

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
          if (outside > 0) EXPECT_EQ(r.status, RunStatus::Diverged) << where;
          if (*r.metrics.at("escaped_bodies") > 0) EXPECT_FALSE(r.passed()) << where;
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

}  // namespace
}  // namespace physval
