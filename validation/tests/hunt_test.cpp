// The hunt for wrong greens (branch hunt): scenes a user writes where physval said `ok`
// (or a gate passed) while the physics was wrong. Each test runs real engines over a grid
// and holds each run's verdict against an oracle computed here from the run's own final
// state or from the closed form; each failed before its fix. scripts/hunt.sh reruns the
// grids end to end through the physval command.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "physval/adapters/registry.hpp"
#include "physval/validation/comparator.hpp"
#include "physval/validation/conservation.hpp"
#include "physval/validation/runner.hpp"
#include "physval/validation/scenario_loader.hpp"

namespace physval {
namespace {

RunRecord run_and_compare(const Scene& s, const EngineFactory& f) {
  RunRecord r = run_engine(s, f, RunOptions{});
  compare_run(r, s, Reference{}, false);
  return r;
}

BodyDef circle(const std::string& name, Vec2 at, double radius, double mass) {
  BodyDef b;
  b.name = name;
  b.radius = radius;
  b.mass = mass;
  b.position = at;
  return b;
}

// Finding 1. A 5 cm, 10 g ball at 60-300 m/s meets a 0.5 m, 1 kg ball at rest, on one
// line. Physics: it bounces back (mass ratio 0.01: v' = -0.98 v). Bullet, Chipmunk and ODE
// (no continuous collision between moving bodies) and Box2D below its speed clamp let it
// through within one step; its centre was never inside the target at a step's end, so
// escaped_bodies stayed 0, energy and momentum are untouched, and each run was `ok`. A
// point (radius 0) was never an escape from a moving ball at all, even ending inside it
// (Chipmunk lets a 30 m/s point through; a static ball caught the same pass).
// Oracle: a ball that ends beyond the target went through it.
TEST(Hunt, AFastBallThroughAMovingBallWithinOneStepIsAnEscape) {
  int passed_through = 0, runs = 0;
  for (double shot_radius : {0.05, 0.0}) {
  for (double dt : {1.0 / 60.0, 1.0 / 30.0}) {
    for (double speed : {30.0, 60.0, 100.0, 150.0, 300.0}) {
      Scene s;
      s.name = "through_a_ball";
      s.dt = dt;
      s.duration = 0.5;
      BodyDef shot = circle("shot", {-3.0, 0.0}, shot_radius, 0.01);
      if (shot_radius == 0.0) shot.shape = ShapeKind::Point;
      shot.velocity = {speed, 0.0};
      s.bodies = {shot, circle("target", {0.0, 0.0}, 0.5, 1.0)};
      for (const EngineFactory& f : engine_registry()) {
        if (!unsupported_features(f.info, s).empty()) continue;
        const RunRecord r = run_and_compare(s, f);
        if (r.status == RunStatus::Error) continue;
        ++runs;
        const std::string where = f.info.name + " r " + std::to_string(shot_radius) + " dt " + std::to_string(dt) +
                                  " v " + std::to_string(speed);
        const bool through = r.final_states[0].position.x > r.final_states[1].position.x;
        ASSERT_TRUE(r.metrics.at("escaped_bodies").has_value()) << where;
        if (through) {
          ++passed_through;
          EXPECT_GE(*r.metrics.at("escaped_bodies"), 1.0) << where;
          EXPECT_EQ(r.status, RunStatus::Diverged) << where << ": " << r.reason;
          EXPECT_FALSE(r.passed()) << where;
        }   // (one that went in and was pushed back out is an escape too: Box2D at 60 m/s)
        if (f.info.name == "core") {
          EXPECT_FALSE(through) << where;   // exact impacts: it bounces back
          EXPECT_EQ(r.status, RunStatus::Ok) << where << ": " << r.reason;
        }
      }
    }
  }
  }
  EXPECT_GT(runs, 8);
  EXPECT_GT(passed_through, 0);   // the grid reaches the engines' pass-through (else it shows nothing)
}

// Finding 2. A point that starts within round-off of a floor's line (1e-15 m or 1e-9 m
// above it, inside the containment's eps) and falls through it: it never "landed" on the
// line from a side, so leaving it downwards was no crossing, and Bullet's and Chipmunk's
// runs, with the point 5 m below the floor, were `ok`. Oracle: final y below the floor.
TEST(Hunt, APointStartingOnAFloorWithinRoundOffThatFallsThroughIsAnEscape) {
  int fell = 0;
  for (double y0 : {1e-15, 1e-12, 1e-9}) {
    for (double vy : {0.0, -1.0}) {
      Scene s;
      s.name = "point_on_floor";
      s.dt = 1.0 / 60.0;
      s.duration = 1.0;
      s.world.gravity = {0.0, -9.81};
      BodyDef p;
      p.name = "p";
      p.shape = ShapeKind::Point;
      p.radius = 0.0;
      p.position = {0.0, y0};
      p.velocity = {0.0, vy};
      p.restitution = 0.0;
      s.bodies = {p};
      WallDef floor;
      floor.name = "floor";
      floor.from = {-5.0, 0.0};
      floor.to = {5.0, 0.0};
      s.walls = {floor};
      for (const EngineFactory& f : engine_registry()) {
        if (!unsupported_features(f.info, s).empty()) continue;
        const RunRecord r = run_and_compare(s, f);
        if (r.status == RunStatus::Error) continue;
        const std::string where = f.info.name + " y0 " + std::to_string(y0) + " vy " + std::to_string(vy);
        ASSERT_TRUE(r.metrics.at("escaped_bodies").has_value()) << where;
        if (r.final_states[0].position.y < -1e-6) {
          ++fell;
          EXPECT_EQ(*r.metrics.at("escaped_bodies"), 1.0) << where;
          EXPECT_EQ(r.status, RunStatus::Diverged) << where << ": " << r.reason;
        } else {
          EXPECT_EQ(*r.metrics.at("escaped_bodies"), 0.0) << where;
        }
      }
    }
  }
  EXPECT_GT(fell, 0);
  // A point that starts within round-off above a floor and leaves upwards crossed nothing.
  Scene s;
  s.name = "point_leaves_floor";
  s.dt = 1.0 / 60.0;
  s.duration = 0.5;
  BodyDef p;
  p.name = "p";
  p.shape = ShapeKind::Point;
  p.position = {0.0, 1e-12};
  p.velocity = {0.3, 2.0};
  s.bodies = {p};
  WallDef floor;
  floor.name = "floor";
  floor.from = {-5.0, 0.0};
  floor.to = {5.0, 0.0};
  s.walls = {floor};
  for (const EngineFactory& f : engine_registry()) {
    if (!unsupported_features(f.info, s).empty()) continue;
    const RunRecord r = run_and_compare(s, f);
    if (r.status == RunStatus::Error) continue;
    EXPECT_EQ(*r.metrics.at("escaped_bodies"), 0.0) << f.info.name;
    EXPECT_EQ(r.status, RunStatus::Ok) << f.info.name << ": " << r.reason;
  }
}

// Finding 2b. A point exactly on a floor's line (to round-off) is on neither side of a
// zero-thickness barrier: at rest there, core kept it on the floor and Box2D, Bullet,
// Chipmunk and ODE let it fall through; moving down, all five let it through; every run
// `ok`, and no containment rule can say which side it started on. It is bad input now
// (file:line:col and key, like an overlap); 1e-9 m above the floor it loads and runs.
TEST(Hunt, APointOnABarriersLineIsRefusedWithFileLineAndKey) {
  auto text = [](const std::string& y, const std::string& extra) {
    return "name = \"p\"\nduration = 1.0\n" + extra + "[world]\ngravity = [0.0, -9.81]\n[[bodies]]\nname = \"p\"\n"
           "shape = \"point\"\nposition = [0.5, " + y + "]\n[[walls]]\nname = \"floor\"\nfrom = [-5.0, 0.0]\n"
           "to = [5.0, 0.0]\n";
  };
  for (const char* y : {"0.0", "1e-15", "-1e-12"}) {
    const ScenarioLoad l = parse_scenario(text(y, ""), "on.toml");
    EXPECT_FALSE(l.scene.has_value()) << y;
    ASSERT_EQ(l.errors.size(), 1u) << y;
    EXPECT_EQ(l.errors[0].line, 8) << y;   // position = ...
    EXPECT_EQ(l.errors[0].key, "bodies[0].position") << y;
    EXPECT_NE(l.errors[0].message.find("a point on wall \"floor\""), std::string::npos) << l.errors[0].str();
  }
  EXPECT_TRUE(parse_scenario(text("1e-9", ""), "above.toml").scene.has_value());
  EXPECT_TRUE(parse_scenario(text("0.0", "allow_initial_overlap = true\n"), "meant.toml").scene.has_value());
  // Beyond the wall's end the line is no barrier.
  EXPECT_TRUE(parse_scenario(text("0.0", "").replace(text("0.0", "").find("[0.5, 0.0]"), 10, "[6.0, 0.0]"), "past.toml")
                  .scene.has_value());
}

// Finding 4. `apex` is the highest y reached, the start included: a ball dropped from 10 m
// and expected to bounce back to 10 m met it at t = 0 whatever the run did. ODE with a
// bounce threshold (the ball stopped dead on the floor, half the energy gone) passed
// `apex = [{ body = "ball", height = 10.0 }]`, exit 0. Such an apex is bad input now.
TEST(Hunt, AnApexTheStartAlreadyMeetsIsRefused) {
  auto text = [](const std::string& apex) {
    return "name = \"drop\"\nduration = 4.0\n[world]\ngravity = [0.0, -9.81]\n[[bodies]]\nname = \"ball\"\n"
           "radius = 0.5\nposition = [0.0, 10.0]\n[[walls]]\nname = \"floor\"\nfrom = [-5.0, -0.5]\n"
           "to = [5.0, -0.5]\n[expect]\napex = [ " + apex + " ]\n";
  };
  for (const char* apex : {"{ body = \"ball\", height = 10.0 }", "{ body = \"ball\", height = 10.0005 }",
                           "{ body = \"ball\", height = 9.9, tolerance = 0.2 }"}) {
    const ScenarioLoad l = parse_scenario(text(apex), "drop.toml");
    EXPECT_FALSE(l.scene.has_value()) << apex;
    ASSERT_EQ(l.errors.size(), 1u) << apex;
    EXPECT_EQ(l.errors[0].key, "expect.apex[0].height") << l.errors[0].str();
    EXPECT_EQ(l.errors[0].str().rfind("drop.toml:", 0), 0u) << l.errors[0].str();
  }
  // Above the start (a ball thrown up), with its time, or out of the tolerance: it can fail.
  for (const char* apex : {"{ body = \"ball\", height = 12.0 }", "{ body = \"ball\", height = 10.0, time = 2.9 }",
                           "{ body = \"ball\", height = 9.0 }"}) {
    EXPECT_TRUE(parse_scenario(text(apex), "drop.toml").scene.has_value()) << apex;
  }
}

// Finding 3. A ball dropped 10 m onto a floor: the same motion whatever the floor's width,
// but the energy scale was M |g| x the scene's diagonal, so a 2 km floor made every energy
// drift 200x smaller. Box2D gains 2% of the ball's energy per bounce (apex 10.21 m): its
// energy_drift read 1.7e-2 on a 2 m floor (a gate of 1e-2 failed it) and 1.6e-5 on a 20 km
// one (the same gate passed it). Oracle: the drift of the run's own energies over
// m g H, H = 10.5 m the scene's extent along g (floor to the ball's top), whatever the width.
TEST(Hunt, EnergyDriftDoesNotShrinkWithAWiderFloor) {
  int runs = 0;
  for (double half_width : {1.0, 5.0, 100.0, 10000.0}) {
    Scene s;
    s.name = "wide_floor";
    s.dt = 1.0 / 60.0;
    s.duration = 4.5;
    s.world.gravity = {0.0, -9.8};
    s.bodies = {circle("ball", {0.0, 10.0}, 0.5, 2.0)};
    WallDef floor;
    floor.name = "floor";
    floor.from = {-half_width, 0.0};
    floor.to = {half_width, 0.0};
    s.walls = {floor};
    const double scale = 2.0 * 9.8 * 10.5;
    for (const EngineFactory& f : engine_registry()) {
      if (!unsupported_features(f.info, s).empty()) continue;
      const RunRecord r = run_and_compare(s, f);
      if (r.status == RunStatus::Error) continue;
      ++runs;
      double drift = 0.0;
      for (const Totals& t : r.series.totals) drift = std::max(drift, std::abs(t.energy() - r.series.totals[0].energy()));
      drift /= scale;
      ASSERT_TRUE(r.metrics.at("energy_drift").has_value()) << f.info.name;
      EXPECT_NEAR(*r.metrics.at("energy_drift"), drift, 1e-12 + 1e-9 * drift) << f.info.name << " floor half-width "
                                                                             << half_width;
    }
  }
  EXPECT_GT(runs, 8);
}

// Core bugs the hunt found. Each scene's [expect] is its closed form.
// v_trough_inelastic: an e = 0 ball meeting both faces of a V at once was resolved face after
// face in wall order and left sideways (symmetry broken; every other engine stops it). Fixed:
// the simultaneous law at both faces.
// point_on_floor_exact: a point starting exactly on a floor, moving into it, fell through it
// (such a start is refused without allow_initial_overlap). Fixed: toi::line_side.
void expect_core_meets(const char* file) {
  const EngineFactory* core = reference_engine();
  ASSERT_NE(core, nullptr);
  const ScenarioLoad l = load_scenario_file(std::string(PHYSVAL_SOURCE_DIR) + "/validation/tests/hunt/" + file);
  ASSERT_TRUE(l.scene.has_value()) << file;
  const RunRecord r = run_and_compare(*l.scene, *core);
  EXPECT_EQ(r.status, RunStatus::Ok) << file << ": " << r.reason;
  ASSERT_TRUE(r.metrics.at("expectation_failures").has_value()) << file;
  EXPECT_EQ(*r.metrics.at("expectation_failures"), 0.0) << file;
}

TEST(Hunt, CoreMeetsTheHuntsVTroughClosedForm) { expect_core_meets("v_trough_inelastic.toml"); }

TEST(Hunt, CoreMeetsThePointOnFloorClosedForm) { expect_core_meets("point_on_floor_exact.toml"); }

// slope_pair_push: two balls at rest touching on a slope, the upper with too little
// friction to stay, the lower with enough for itself but not for both: they must slide
// together at 0.1287 m/s^2; core held both at rest for ever, `ok` (a held body leaned on a
// stuck one as on a fixed support, and the stuck one was never judged with that load).
// Fixed: such a hold is judged as a group, and bodies on faces pressed together slide as
// one (resting_contact.cpp: leaning_group_holds, push_trains).
TEST(Hunt, CoreMeetsTheSlopePairClosedForm) { expect_core_meets("slope_pair_push.toml"); }

// catch_row: a ball catching two touching balls sliding on a floor (e 0): the impact passes
// through the touching balls and the three slide on as one train. core micro-bounced them
// against one another at one instant until the event cap (`diverged`, 0.24 m off). Fixed:
// the whole touching chain is joined at once (resting_contact.cpp: join_train).
TEST(Hunt, CoreMeetsTheCatchRowClosedForm) { expect_core_meets("catch_row.toml"); }

// train_hold_frictionless_leader (hunt4): a ball struck through a touching row at rest on a
// floor (e 0) whose front ball is frictionless: after the impact all four move at 0.0466 m/s;
// the three with friction stop within 0.37 mm, the frictionless one slides on for ever. In 10
// of the 24 body orders core ended with all four at rest (47.6 N s gone) or the front ball 9%
// slow, `ok`: met pairwise, the 1000 kg ball reached the frictionless one below the collapse
// speed and the slow impact met it, at rest, as fixed ("its supports absorb it"), though a
// frictionless face absorbs nothing along it. Fixed: a body at rest on one frictionless face,
// touching no body but the striker, is not fixed in a slow impact (simultaneous_impacts.cpp,
// lone_on_frictionless_faces). Every order of the four bodies must meet the closed form.
TEST(Hunt, CoreMeetsTheFrictionlessLeaderClosedFormInEveryNumbering) {
  const EngineFactory* core = reference_engine();
  ASSERT_NE(core, nullptr);
  const ScenarioLoad l = load_scenario_file(std::string(PHYSVAL_SOURCE_DIR) +
                                            "/validation/tests/hunt/train_hold_frictionless_leader.toml");
  ASSERT_TRUE(l.scene.has_value());
  Scene scene = *l.scene;
  ASSERT_EQ(scene.bodies.size(), 4u);
  std::vector<std::size_t> order{0, 1, 2, 3};
  const std::vector<BodyDef> listed = scene.bodies;
  int runs = 0;
  do {
    for (std::size_t k = 0; k < order.size(); ++k) scene.bodies[k] = listed[order[k]];
    const RunRecord r = run_and_compare(scene, *core);
    const std::string which = "order " + std::to_string(order[0]) + std::to_string(order[1]) +
                              std::to_string(order[2]) + std::to_string(order[3]);
    EXPECT_EQ(r.status, RunStatus::Ok) << which << ": " << r.reason;
    ASSERT_TRUE(r.metrics.at("expectation_failures").has_value()) << which;
    EXPECT_EQ(*r.metrics.at("expectation_failures"), 0.0) << which;
    ++runs;
  } while (std::next_permutation(order.begin(), order.end()));
  EXPECT_EQ(runs, 24);
}

// slow_strike_frictionless_at_rest (hunt4): the same cause alone: a ball at 0.01 m/s strikes a
// frictionless ball at rest on the floor, which never moved (0.0167 m short at 2 s, `ok`). Fixed
// as the one above: both leave at 10 0.01 / 11 m/s.
TEST(Hunt, CoreMeetsTheSlowStrikeOnAFrictionlessBallClosedForm) {
  expect_core_meets("slow_strike_frictionless_at_rest.toml");
}

// frictionless_into_row_at_wall (hunt4, open): a frictionless ball strikes (e 0) a ball at
// rest against a wall; it must stop dead, core sends it back at half the rest speed (the
// micro-bounce's minimum separation) and, frictionless, it slides away for ever (5 mm at 2 s).
TEST(Hunt, CoreMeetsTheFrictionlessStrikerIntoARowAtAWallClosedForm) {
  expect_core_meets("frictionless_into_row_at_wall.toml");
}

// The same scene over a grid: a frictionless striker (radius 0.05 m) at u meets a row of
// 1-3 touching balls at rest on a floor, the last touching a wall, at t_hit (inside a
// step). Closed form (Newton's law at every contact at once): the row is backed by the
// wall, so it never moves; the striker leaves at -e u, and slides back on the frictionless
// floor for ever. Nothing presses the striker into the row along the flat floor, so core's
// collapse threshold (v_r = g dt / 16) does not apply at any speed (branch collapse3:
// before, an impact closing slower than v_r, here 0.01 m/s at dt 1/60, was made perfectly
// inelastic and this grid expected the striker to stop there). Speeds 0.01-2 m/s, striker:row masses 1:1,
// 1:1000, 1000:1, e 0 and 0.5, dt 1/60 and 1/240, the row with friction 0.5 or none,
// every numbering of the bodies (24 for a row of 3) and the mirror image.
struct RowAtWall {
  int n = 1;
  double u = 1.0, m_striker = 1.0, m_row = 1.0, e = 0.0, dt = 1.0 / 60.0, row_mu = 0.5;
  bool mirror = false;
  bool wall = true;   // false: the same row with no wall behind it
};

Scene row_at_wall_scene(const RowAtWall& c, const std::vector<std::size_t>& order, double& t_hit) {
  const double r = 0.05, x_wall = 0.5, sx = c.mirror ? -1.0 : 1.0;
  Scene s;
  s.name = "row_at_wall";
  s.dt = c.dt;
  s.duration = 2.0;
  s.world.gravity = {0.0, -9.8};
  t_hit = 0.5 + 0.37 * c.dt;
  std::vector<BodyDef> listed;
  const double x_first = x_wall - r - 2.0 * r * (c.n - 1);
  BodyDef striker = circle("s", {sx * (x_first - 2.0 * r - c.u * t_hit), r}, r, c.m_striker);
  striker.velocity = {sx * c.u, 0.0};
  listed.push_back(striker);
  for (int k = 0; k < c.n; ++k) {
    listed.push_back(circle("b" + std::to_string(k), {sx * (x_first + 2.0 * r * k), r}, r, c.m_row));
  }
  for (BodyDef& b : listed) b.restitution = c.e;
  s.bodies.clear();
  for (std::size_t k : order) s.bodies.push_back(listed[k]);
  WallDef floor;
  floor.name = "floor";
  floor.from = {-50.0, 0.0};
  floor.to = {50.0, 0.0};
  floor.material.restitution = c.e;
  WallDef end;
  end.name = "end";
  end.from = {sx * x_wall, 0.0};
  end.to = {sx * x_wall, 3.0 * r};
  end.material.restitution = c.e;
  s.walls = {floor, end};
  if (!c.wall) s.walls = {floor};
  for (const BodyDef& b : listed) {
    const double mu = b.name == "s" ? 0.0 : c.row_mu;
    for (const WallDef& wd : s.walls) {
      const std::string& w = wd.name;
      MaterialOverride m;
      m.a = b.name;
      m.b = w;
      m.friction = mu;
      m.static_friction = mu;
      s.materials.push_back(m);
    }
  }
  return s;
}

// The part of the grid that was open until branch rowwall: a row of 2-3 balls with floor
// friction struck at e = 0.5, or by a striker 1000 times lighter than the row. Core gave
// the sequential law's answer there (equal masses, 2 balls at 0.3 m/s: the striker left at
// -0.0656 m/s), or sent a light striker back at a micro-bounce's minimum separation: a ball
// at rest on a face with friction took part in a touching set with its faces only, so the
// impulse crossed the row pair by pair. The closed form is right with friction too. In an
// impact the floor's friction impulse on a ball is at most mu times the floor's normal
// impulse on it, and that is 0: the striker's impulse and every ball-ball and ball-wall
// normal is horizontal, so nothing presses a ball into the floor (and the wall's friction
// acts vertically, where no ball moves). Newton's law at every contact at once (core's
// documented law, `impact_law = "simultaneous"`) is then the frictionless row's problem:
// every contact of the row with the wall behind it closes at 0 and must not close, so
// one impulse (1 + e') m_s u through the whole row stops it dead and sends the striker
// back at -e' u, for every mass ratio. (The sequential law, a wave contact by contact, is
// another law: core gives it only with `impact_law = "sequential"`.)
bool row_at_wall_was_open(const RowAtWall& c) {
  return c.row_mu > 0.0 && c.n >= 2 && (c.e > 0.0 || c.m_striker < c.m_row);
}

void expect_row_at_wall_grid(bool open) {
  const EngineFactory* core = reference_engine();
  ASSERT_NE(core, nullptr);
  int runs = 0, considered = 0, bounced = 0, failures = 0;
  for (int n : {1, 2, 3}) {
    for (double u : {0.01, 0.05, 0.3, 2.0}) {
      for (const auto& [ms, mr] : {std::pair{1.0, 1.0}, std::pair{1.0, 1000.0}, std::pair{1000.0, 1.0}}) {
        for (double e : {0.0, 0.5}) {
          for (double dt : {1.0 / 60.0, 1.0 / 240.0}) {
            for (double row_mu : {0.5, 0.0}) {
              for (bool mirror : {false, true}) {
                RowAtWall c{n, u, ms, mr, e, dt, row_mu, mirror};
                if (row_at_wall_was_open(c) != open) continue;
                std::vector<std::size_t> order(static_cast<std::size_t>(n) + 1);
                for (std::size_t k = 0; k < order.size(); ++k) order[k] = k;
                int perm = 0;
                do {
                  if (n == 3 && perm++ % 3 != 0) continue;   // 8 of the 24 orders of a row of 3
                  if (considered++ % PHYSVAL_GRID_STRIDE != 0) continue;   // sanitizers: a quarter
                  double t_hit = 0.0;
                  const Scene scene = row_at_wall_scene(c, order, t_hit);
                  const RunRecord rec = run_and_compare(scene, *core);
                  std::string which = "n " + std::to_string(n) + " u " + std::to_string(u) + " m " +
                                      std::to_string(ms) + ":" + std::to_string(mr) + " e " + std::to_string(e) +
                                      " dt 1/" + std::to_string(std::lround(1.0 / dt)) + " row mu " +
                                      std::to_string(row_mu) + (mirror ? " mirrored" : "") + " order";
                  for (std::size_t k : order) which += " " + std::to_string(k);
                  std::string wrong;
                  if (rec.status != RunStatus::Ok) wrong += " status " + rec.reason;
                  const double e_eff = e;   // nothing presses the pair along the floor
                  const double sx = mirror ? -1.0 : 1.0;
                  for (std::size_t slot = 0; slot < order.size(); ++slot) {
                    const BodyDef& b = scene.bodies[slot];
                    const BodyState& f = rec.final_states[slot];
                    Vec2 want_p = b.position, want_v{};
                    if (b.name == "s") {
                      const double x_hit = b.position.x + b.velocity.x * t_hit;
                      want_v = {-sx * e_eff * u, 0.0};
                      want_p = {x_hit + want_v.x * (scene.duration - t_hit), b.position.y};
                    }
                    const double off = std::max(length(f.position - want_p), length(f.velocity - want_v));
                    if (!(off <= 1e-9)) {
                      wrong += " " + b.name + " at (" + std::to_string(f.position.x) + ", " +
                               std::to_string(f.position.y) + ") v (" + std::to_string(f.velocity.x) + ", " +
                               std::to_string(f.velocity.y) + "), off " + std::to_string(off);
                    }
                  }
                  if (!wrong.empty() && ++failures <= 30) ADD_FAILURE() << which << ":" << wrong;
                  if (e_eff > 0.0) ++bounced;
                  ++runs;
                } while (std::next_permutation(order.begin(), order.end()));
              }
            }
          }
        }
      }
    }
  }
  EXPECT_EQ(failures, 0) << "of " << runs << " runs";
  EXPECT_GT(runs, 0);
  // a row of 1: 192 cases x 2 orders; rows of 2 and 3: the 96 frictionless cases and the
  // 32 with friction at e 0 and a striker not lighter, x 6 and 8 orders; the rest (was
  // open): with friction, the 48 cases at e 0.5 and the 16 at e 0 with a lighter striker
  EXPECT_EQ(considered, open ? 64 * (6 + 8) : 192 * 2 + 128 * (6 + 8));
  EXPECT_EQ(runs, (considered + PHYSVAL_GRID_STRIDE - 1) / PHYSVAL_GRID_STRIDE);
  EXPECT_GT(bounced, 0);
}

TEST(Hunt, CoreMeetsTheStrikerIntoARowAtAWallClosedFormOverAGrid) { expect_row_at_wall_grid(false); }

// The part of the grid with floor friction that was open (see row_at_wall_was_open): 896 runs.
TEST(Hunt, CoreMeetsTheStrikerIntoAFrictionRowAtAWallClosedFormWhenItBouncesOrIsLighter) {
  expect_row_at_wall_grid(true);
}

// The same row of 3 with no wall behind it (branch rowwall): on a floor with friction 0.5 or
// none, struck end-on by a frictionless ball at u (0.3 and 1 m/s), e 0, 0.5 and 1. Equal
// masses, Newton's law at every contact at once: the row's contacts close at 0 and stay
// closed, so the three leave together at V = (1 + e) u / 4 and the striker at u (1 - 3e) / 4
// (momentum kept, the first contact opening at e u). The floor's friction takes no part in
// the impact (its normal impulse is 0), then stops each ball: at e 0.5 and 1 each ball
// slides V^2 / (2 mu g) and the striker leaves backwards for ever; at e 0 the striker
// pushes the row and the four stop together after (u / 4)^2 / (2 (3/4) mu g) (the
// striker has no friction). Before, with friction, every ball but the first was a leaf of
// the set, so at e 1 core gave Newton's cradle (the last ball leaving at u, the striker
// stopped) in some numberings and other answers in others. Striker:row masses 1000:1 and
// 1:1000 (no closed form written here): every numbering and the mirror image must agree
// to 1e-9. All 24 orders x mirror, status `ok`.
TEST(Hunt, CoreMeetsNewtonsLawOnAFreeRowOnAFloorWithFrictionStruckEndOn) {
  const EngineFactory* core = reference_engine();
  ASSERT_NE(core, nullptr);
  const double g = 9.8;
  int runs = 0, failures = 0;
  for (double u : {0.3, 1.0}) {
    for (const auto& [ms, mr] : {std::pair{1.0, 1.0}, std::pair{1000.0, 1.0}, std::pair{1.0, 1000.0}}) {
      for (double e : {0.0, 0.5, 1.0}) {
        for (double row_mu : {0.5, 0.0}) {
          std::vector<std::pair<std::string, BodyState>> first;   // the first run's finals, unmirrored
          for (bool mirror : {false, true}) {
            RowAtWall c{3, u, ms, mr, e, 1.0 / 60.0, row_mu, mirror, false};
            std::vector<std::size_t> order{0, 1, 2, 3};
            do {
              double t_hit = 0.0;
              const Scene scene = row_at_wall_scene(c, order, t_hit);
              const RunRecord rec = run_and_compare(scene, *core);
              std::string which = "u " + std::to_string(u) + " m " + std::to_string(ms) + ":" + std::to_string(mr) +
                                  " e " + std::to_string(e) + " mu " + std::to_string(row_mu) + (mirror ? " mirrored" : "") +
                                  " order";
              for (std::size_t k : order) which += " " + std::to_string(k);
              std::string wrong;
              if (rec.status != RunStatus::Ok) wrong += " status " + rec.reason;
              const double sx = mirror ? -1.0 : 1.0, T = scene.duration;
              for (std::size_t slot = 0; slot < order.size(); ++slot) {
                const BodyDef& b = scene.bodies[slot];
                BodyState f = rec.final_states[slot];
                f.position.x *= sx;
                f.velocity.x *= sx;
                if (ms == mr) {
                  const double V = (1.0 + e) * u / 4.0, vs = (1.0 - 3.0 * e) * u / 4.0;
                  const double x0 = sx * b.position.x + (b.name == "s" ? u * t_hit : 0.0);
                  Vec2 want_p{x0, b.position.y}, want_v{};
                  if (row_mu == 0.0) {
                    want_v.x = b.name == "s" ? vs : V;
                  } else if (e == 0.0) {
                    want_p.x += V * V / (2.0 * 0.75 * row_mu * g);
                  } else if (b.name == "s") {
                    want_v.x = vs;
                  } else {
                    want_p.x += V * V / (2.0 * row_mu * g);
                  }
                  if (want_v.x != 0.0) want_p.x += want_v.x * (T - t_hit);
                  const double off = std::max(length(f.position - want_p), length(f.velocity - want_v));
                  if (!(off <= 1e-9)) {
                    wrong += " " + b.name + " at (" + std::to_string(f.position.x) + ", " + std::to_string(f.position.y) +
                             ") v " + std::to_string(f.velocity.x) + ", off " + std::to_string(off);
                  }
                }
                const auto same = std::find_if(first.begin(), first.end(), [&](const auto& x) { return x.first == b.name; });
                if (same == first.end()) {
                  first.emplace_back(b.name, f);
                } else {
                  const double d = std::max(length(f.position - same->second.position), length(f.velocity - same->second.velocity));
                  if (!(d <= 1e-9)) wrong += " " + b.name + " differs from the first order by " + std::to_string(d);
                }
              }
              if (!wrong.empty() && ++failures <= 30) ADD_FAILURE() << which << ":" << wrong;
              ++runs;
            } while (std::next_permutation(order.begin(), order.end()));
          }
        }
      }
    }
  }
  EXPECT_EQ(failures, 0) << "of " << runs << " runs";
  EXPECT_EQ(runs, 2 * 3 * 3 * 2 * 2 * 24);
}

// row_at_wall_unproven_hold (hunt4, a false alarm): a 1000 kg frictionless ball struck (e 0)
// into a row of three at rest against a wall: all four end at rest, exactly. In 2 of 8
// numberings the braced-group judgement's Gauss-Seidel left a member 4e-5 m/s^2 and its exact
// least-squares fallback found forces leaving every member at 1.5e-14 m/s^2, but only a
// certificate of collapse was looked for there, so the run was `diverged` ("could not show").
// Fixed: forces >= 0 from the exact solve that leave every member at rest hold it
// (resting_contact.cpp, component_holds). Every order of the four bodies and the mirror
// image (48 runs) must be `ok` and meet the closed form.
TEST(Hunt, CoreHoldsTheRowStruckIntoAWallInEveryNumbering) {
  const EngineFactory* core = reference_engine();
  ASSERT_NE(core, nullptr);
  const ScenarioLoad l =
      load_scenario_file(std::string(PHYSVAL_SOURCE_DIR) + "/validation/tests/hunt/row_at_wall_unproven_hold.toml");
  ASSERT_TRUE(l.scene.has_value());
  ASSERT_EQ(l.scene->bodies.size(), 4u);
  int runs = 0;
  for (bool mirror : {false, true}) {
    Scene scene = *l.scene;
    if (mirror) {
      for (BodyDef& b : scene.bodies) {
        b.position.x = -b.position.x;
        b.velocity.x = -b.velocity.x;
      }
      for (WallDef& w : scene.walls) {
        w.from.x = -w.from.x;
        w.to.x = -w.to.x;
      }
    }
    scene.expect = {};
    const std::vector<BodyDef> listed = scene.bodies;
    std::vector<std::size_t> order{0, 1, 2, 3};
    do {
      for (std::size_t k = 0; k < order.size(); ++k) scene.bodies[k] = listed[order[k]];
      const RunRecord r = run_and_compare(scene, *core);
      std::string which = mirror ? "mirrored, order" : "order";
      for (std::size_t k : order) which += " " + std::to_string(k);
      EXPECT_EQ(r.status, RunStatus::Ok) << which << ": " << r.reason;
      for (std::size_t k = 0; k < order.size(); ++k) {
        const BodyDef& b = scene.bodies[k];
        // b0 (the striker) moves 0.01 m to the row; the rest never move; all end at rest
        const double x = b.name == "b0" ? b.position.x + (mirror ? -0.01 : 0.01) : b.position.x;
        EXPECT_NEAR(r.final_states[k].position.x, x, 1e-9) << which << " " << b.name;
        EXPECT_NEAR(r.final_states[k].position.y, b.position.y, 1e-9) << which << " " << b.name;
        EXPECT_EQ(r.final_states[k].velocity, (Vec2{0.0, 0.0})) << which << " " << b.name;
      }
      ++runs;
    } while (std::next_permutation(order.begin(), order.end()));
  }
  EXPECT_EQ(runs, 48);
}

// last_step_hold: a hold made inside the run's last step was never judged (holds made inside
// a step are judged at the next step's start), so a pyramid rigid Coulomb cannot hold, held
// in a run of one step, was `ok`; a longer run is `diverged` at t = 1/60 s. Fixed: the last
// step's holds are judged at its end (core_engine.cpp).
TEST(Hunt, CoreJudgesAHoldMadeInTheLastStep) {
  const EngineFactory* core = reference_engine();
  ASSERT_NE(core, nullptr);
  const ScenarioLoad l =
      load_scenario_file(std::string(PHYSVAL_SOURCE_DIR) + "/validation/tests/hunt/last_step_hold.toml");
  ASSERT_TRUE(l.scene.has_value());
  for (double duration : {l.scene->duration, 0.05}) {
    Scene scene = *l.scene;
    scene.duration = duration;
    const RunRecord r = run_and_compare(scene, *core);
    if (duration == 0.05) {   // since contact12: judged at step 2's start, moved in the contact-group mode
      EXPECT_EQ(r.status, RunStatus::Ok) << duration << ": " << r.reason;
      ASSERT_FALSE(r.limits_hit.empty());
      EXPECT_NE(r.limits_hit.front().find("bodies moving in contact"), std::string::npos) << r.limits_hit.front();
      continue;
    }
    EXPECT_EQ(r.status, RunStatus::Diverged) << duration << ": " << r.reason;
    EXPECT_NE(r.reason.find("'top' at t = 0.0166667 s"), std::string::npos) << r.reason;
  }
}

// pyramid_of_three: two balls on a frictionless floor and one on top: they must collapse
// (every other engine does); core held all three at rest for ever, `ok`, then reported the
// hold as a broken guarantee. Now core moves them in its contact-group mode: the top lands on
// the floor between the bottom balls (the file's [expect]), the run is `ok`, and core does not
// claim exact paths there (its limits_hit names the mode, so its own-reference check is not
// judged: the mode is integrated at RK4's order).
TEST(Hunt, CoreCollapsesTheFrictionlessPyramid) {
  const EngineFactory* core = reference_engine();
  ASSERT_NE(core, nullptr);
  const ScenarioLoad l =
      load_scenario_file(std::string(PHYSVAL_SOURCE_DIR) + "/validation/tests/hunt/pyramid_of_three.toml");
  ASSERT_TRUE(l.scene.has_value());
  const RunRecord r = run_and_compare(*l.scene, *core);
  EXPECT_EQ(r.status, RunStatus::Ok) << r.reason;
  ASSERT_FALSE(r.limits_hit.empty());
  EXPECT_NE(r.limits_hit.front().find("bodies moving in contact"), std::string::npos) << r.limits_hit.front();
  EXPECT_FALSE(r.reference_check.judged) << r.reference_check.note;
  ASSERT_FALSE(r.series.states.empty());
  const auto& last = r.series.states.back();
  ASSERT_EQ(last.size(), 3u);
  EXPECT_NEAR(last[2].position.x, 0.0, 1e-6);
  EXPECT_NEAR(last[2].position.y, 0.5, 1e-6);
  EXPECT_GT(last[1].position.x, 1.0);
  EXPECT_LT(last[0].position.x, -1.0);
}

// pile_50 (issue 9's pile, once in the suite as hard/pile_50): core used to hold a leaning
// tower there (42 bodies at rest touching) that rigid Coulomb cannot hold, and reported its run
// diverged. Since branch granular13 the pile's dense phase is moved by core's granular mode
// (nonsmooth contact dynamics): the run is `ok`, says so in limits_hit (first order, not
// exact), and meets the file's checks: every body at rest at 10 s, no overlap deeper than
// 1e-9 m, nothing escaped.
TEST(Hunt, CoreSettlesPile50) {
  const EngineFactory* core = reference_engine();
  ASSERT_NE(core, nullptr);
  const ScenarioLoad l = load_scenario_file(std::string(PHYSVAL_SOURCE_DIR) + "/validation/scenarios/hard/pile_50.toml");
  ASSERT_TRUE(l.scene.has_value());
  const RunRecord r = run_and_compare(*l.scene, *core);
  EXPECT_EQ(r.status, RunStatus::Ok) << r.reason;
  bool granular = false;
  for (const std::string& s : r.limits_hit) granular = granular || s.rfind("granular contact", 0) == 0;
  EXPECT_TRUE(granular);
  for (const Check& c : r.checks) EXPECT_TRUE(c.pass) << c.what;
  EXPECT_FALSE(r.checks.empty());
}

}  // namespace
}  // namespace physval
