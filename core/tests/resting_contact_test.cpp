// Bouncing and resting against the floor under gravity: exact bounce times, energy
// never gained, a ball at rest stays at rest with a bounded number of events.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

#include "scene_fixture.hpp"

namespace physval::test {

namespace {
constexpr double g = 9.8;
Scene ball_over_floor(double bottom_height, double e, Vec2 v = {}) {
  return scene_of({circle("ball", {0.0, bottom_height + 0.5}, v, 0.5, 1.0, e)},
                  {wall("floor", {-50.0, 0.0}, {50.0, 0.0}, e)}, {0.0, -g});
}
double energy(const BodyState& s) { return 0.5 * length_squared(s.velocity) + g * (s.position.y - 0.5); }
}  // namespace

TEST(CoreResting, BallAtRestStaysAtRest) {
  for (const char* integ : {"explicit_euler", "semi_implicit_euler", "velocity_verlet", "rk4"}) {
    for (double e : {1.0, 0.5, 0.0}) {
      SCOPED_TRACE(std::string(integ) + " e=" + std::to_string(e));
      Sim sim(ball_over_floor(0.0, e), options(integ));
      std::int64_t worst_events = 0;
      for (int k = 0; k < 600; ++k) {
        sim.step(1.0 / 60.0);
        worst_events = std::max(worst_events, sim.engine.last_step_stats().events);
        ASSERT_LE(energy(sim.state("ball")), 1e-9) << "step " << k;
      }
      EXPECT_NEAR(sim.state("ball").position.y, 0.5, 1e-9);
      EXPECT_NEAR(sim.state("ball").velocity.y, 0.0, 1e-9);
      EXPECT_LE(worst_events, 4);
      EXPECT_LE(sim.contacts.size(), 1u);   // one contact, not one per step
      EXPECT_TRUE(sim.engine.limits_hit().empty());
    }
  }
}

TEST(CoreResting, ElasticBounceKeepsItsHeight) {
  // e = 1, dropped from 2 m: every bounce returns to 2 m; Verlet's parabola is exact,
  // so the energy is conserved to round-off, bounce after bounce.
  Sim sim(ball_over_floor(2.0, 1.0));
  const double period = 2.0 * std::sqrt(2.0 * 2.0 / g);
  double top = 0.0;
  for (int k = 0; k < 1200; ++k) {
    sim.step(1.0 / 60.0);
    ASSERT_NEAR(energy(sim.state("ball")), 2.0 * g, 1e-9);
    if (sim.engine.time() > 15.0) top = std::max(top, sim.state("ball").position.y - 0.5);
  }
  EXPECT_NEAR(top, 2.0, 0.01);   // sampled at steps: within 1/60 s of the apex
  ASSERT_GE(sim.contacts.size(), 10u);
  for (std::size_t k = 0; k < sim.contacts.size(); ++k) {
    EXPECT_NEAR(sim.contacts[k].time, period * (static_cast<double>(k) + 0.5), 1e-9) << k;
  }
}

TEST(CoreResting, InelasticBouncesThenSettles) {
  // e = 0.5 from h = 1: impacts at t1 = sqrt(2h/g), then each flight 2 e^k v1 / g; the
  // series sums to t1 (1 + 2e / (1 - e)) = 3 t1, after which the ball rests.
  const double e = 0.5, h = 1.0, t1 = std::sqrt(2.0 * h / g), v1 = g * t1;
  Sim sim(ball_over_floor(h, e));
  sim.run_until(5.0, 1.0 / 60.0);
  ASSERT_GE(sim.contacts.size(), 3u);
  double t = t1;
  for (int k = 0; k < 3; ++k) {
    EXPECT_NEAR(sim.contacts[static_cast<std::size_t>(k)].time, t, 1e-9) << k;
    t += 2.0 * std::pow(e, k + 1) * v1 / g;
  }
  EXPECT_NEAR(sim.state("ball").position.y, 0.5, 1e-9);
  EXPECT_EQ(sim.state("ball").velocity.y, 0.0);
  for (const ContactEvent& c : sim.contacts) EXPECT_LT(c.time, 3.0 * t1 + 1e-9);
  EXPECT_TRUE(sim.engine.limits_hit().empty());
}

TEST(CoreResting, StackOfThreeRestsExactly) {
  // Three circles stacked on the floor, e = 0: they stay exactly where they are, with
  // one contact each and no events once settled.
  for (const char* integ : {"semi_implicit_euler", "velocity_verlet", "rk4"}) {
    SCOPED_TRACE(integ);
    Scene s = scene_of({circle("bottom", {0.0, 0.5}, {}, 0.5, 1.0, 0.0), circle("middle", {0.0, 1.5}, {}, 0.5, 1.0, 0.0),
                        circle("top", {0.0, 2.5}, {}, 0.5, 1.0, 0.0)},
                       {wall("floor", {-5.0, 0.0}, {5.0, 0.0}, 0.0)}, {0.0, -g});
    Sim sim(s, options(integ));
    sim.step(1.0 / 60.0);
    for (int k = 0; k < 300; ++k) {
      sim.step(1.0 / 60.0);
      ASSERT_EQ(sim.engine.last_step_stats().events, 0) << k;
    }
    for (std::size_t b = 0; b < 3; ++b) {
      EXPECT_NEAR(sim.state(b).position.y, 0.5 + static_cast<double>(b), 1e-12);
      EXPECT_EQ(length(sim.state(b).velocity), 0.0);
    }
    EXPECT_EQ(sim.contacts.size(), 3u);
  }
}

TEST(CoreResting, KnockedOutSupportDropsTheStack) {
  // A ball resting on another is left in the air when a third knocks the lower one
  // away: it must fall to the floor (e = 0, so it lands and stays).
  Scene s = scene_of({circle("bottom", {0.0, 0.5}, {}, 0.5, 1.0, 0.0), circle("top", {0.0, 1.5}, {}, 0.5, 1.0, 0.0),
                      circle("striker", {-5.0, 0.5}, {4.0, 0.0}, 0.5, 1.0, 1.0)},
                     {wall("floor", {-50.0, 0.0}, {50.0, 0.0}, 0.0)}, {0.0, -g});
  Sim sim(s);
  sim.run_until(0.5, 1.0 / 60.0);
  EXPECT_NEAR(sim.state("top").position.y, 1.5, 1e-12);   // still stacked before the hit (t = 1)
  sim.run_until(4.0, 1.0 / 60.0);
  EXPECT_NEAR(sim.state("top").position.y, 0.5, 1e-9);    // fell to the floor
  EXPECT_EQ(sim.state("top").velocity.y, 0.0);
  EXPECT_GT(sim.state("bottom").position.x, 1.0);         // knocked away
}

TEST(CoreResting, RollsOffTheEndAndFalls) {
  // A ball sliding on a frictionless ledge leaves it and falls; it does not hang on.
  // At 2 m/s, v^2 < g r: it turns about the ledge's end until N = 0, at
  // cos(phi) = (v^2 / (g r) + 2) / 3, and leaves with vx = v' cos(phi), v'^2 = v^2 +
  // 2 g r (1 - cos(phi)): 2.013449 m/s. (This test used to demand vx = 2 exactly, the
  // answer of a ball that does not turn, which core gave by a round-off accident at the
  // end point; table_edge_test.cpp has the whole story.) core turns it by
  // micro-bounces, first order: 5e-5 m/s off at dt 1/60.
  Scene s = scene_of({circle("ball", {0.0, 5.5}, {2.0, 0.0})}, {wall("ledge", {-1.0, 5.0}, {1.0, 5.0})}, {0.0, -g});
  Sim sim(s);
  sim.run_until(2.0, 1.0 / 60.0);
  const double r = 0.5, v = 2.0, c = (v * v / (g * r) + 2.0) / 3.0;
  EXPECT_LT(sim.state("ball").position.y, 0.0);
  EXPECT_NEAR(sim.state("ball").velocity.x, std::sqrt(v * v + 2.0 * g * r * (1.0 - c)) * c, 1e-4);
}
}  // namespace physval::test

namespace physval::test {

TEST(CoreResting, TallStacksHoldExactly) {
  // Columns of 10 and 50 touching circles on a floor, e = 0, 0.5, 1: after 2 s each is
  // exactly where it started, one contact begins per touching pair, and no step comes
  // near the event cap (at most one event per body and step).
  for (int n : {10, 50}) {
    for (double e : {0.0, 0.5, 1.0}) {
      SCOPED_TRACE(std::to_string(n) + " bodies, e=" + std::to_string(e));
      std::vector<BodyDef> b;
      for (int k = 0; k < n; ++k) b.push_back(circle("b" + std::to_string(k), {0.0, 0.5 + k}, {}, 0.5, 1.0, e));
      Sim sim(scene_of(b, {wall("floor", {-10.0, 0.0}, {10.0, 0.0}, e)}, {0.0, -9.8}));
      std::int64_t worst = 0;
      for (int k = 0; k < 120; ++k) {
        sim.step(1.0 / 60.0);
        worst = std::max(worst, sim.engine.last_step_stats().events);
        ASSERT_EQ(sim.engine.broken_guarantee(), "");
      }
      EXPECT_LE(worst, n);
      EXPECT_EQ(sim.contacts.size(), static_cast<std::size_t>(n));
      for (int k = 0; k < n; ++k) {
        const BodyState st = sim.state(static_cast<std::size_t>(k));
        EXPECT_EQ(st.position.x, 0.0);
        EXPECT_EQ(st.position.y, 0.5 + k);
      }
    }
  }
}

// A point placed exactly on a floor (allow_initial_overlap) is on the floor whatever its
// velocity: the side gravity presses it from (toi::line_side). It used to be held there at
// rest but fall through moving down (the face tests took the side it moved into), y =
// -5.9 m after 1 s (validation/tests/hunt/point_on_floor_exact.toml). Every integrator,
// the floor drawn either way, gravity down (a floor) or up (a ceiling), e 0 to 1: it never
// crosses the line; at e = 0 moving down it stops on it at once; otherwise its first
// bounce reaches (e vn)^2 / 2g and a point moving up reaches vn^2 / 2g (Verlet, RK4 exact).
TEST(CoreResting, APointStartedExactlyOnAFloorNeverCrossesIt) {
  int cases = 0;
  for (const char* integ : {"explicit_euler", "semi_implicit_euler", "velocity_verlet", "rk4"}) {
    for (double dir : {1.0, -1.0}) {
      for (double up : {1.0, -1.0}) {   // +1: a floor (gravity down), -1: a ceiling
        for (double e : {0.0, 0.5, 1.0}) {
          for (Vec2 v : {Vec2{0.0, -1.0}, Vec2{0.7, -1.0}, Vec2{}, Vec2{0.0, 1.0}, Vec2{2.0, -3.0}, Vec2{-1.0, 0.0}}) {
            const Vec2 v0{v.x, up * v.y};
            SCOPED_TRACE(std::string(integ) + " dir " + std::to_string(dir) + " up " + std::to_string(up) + " e " +
                         std::to_string(e) + " v " + std::to_string(v.x) + "," + std::to_string(v.y));
            Scene sc = scene_of({point("p", {0.0, 0.0}, v0, 1.0, e)},
                                {wall("floor", {-50.0 * dir, 0.0}, {50.0 * dir, 0.0}, e)}, {0.0, -up * g});
            Sim sim(sc, options(integ));
            double apex = 0.0;
            for (int k = 0; k < 60; ++k) {
              sim.step(1.0 / 60.0);
              const double y = up * sim.state("p").position.y;
              ASSERT_GE(y, -1e-12) << "step " << k;   // never on the other side
              apex = std::max(apex, y);
              ASSERT_EQ(sim.engine.broken_guarantee(), "");
            }
            ++cases;
            const bool exact = std::string(integ) == "velocity_verlet" || std::string(integ) == "rk4";
            if (v.y < 0.0 && e == 0.0) {   // stops on the line at once and slides (frictionless)
              EXPECT_LE(apex, 1e-12);
              EXPECT_EQ(sim.state("p").velocity.y, 0.0);
              EXPECT_NEAR(sim.state("p").position.x, v.x, 1e-12);
            } else if (exact && v.y != 0.0) {
              const double vn = v.y < 0.0 ? -e * v.y : v.y;
              EXPECT_NEAR(apex, vn * vn / (2.0 * g), 1e-3 * vn * vn / (2.0 * g) + 2e-3 * vn) << "sampled per step";
            }
          }
        }
      }
    }
  }
  EXPECT_EQ(cases, 4 * 2 * 2 * 3 * 6);
}

// Balls in a row touching along a slope, each with its own friction against it, none
// between them, released at rest (hunt: slope_pair_push). Rigid Coulomb: a ball behind
// (up the slope) that would accelerate faster than the one in front pushes it, and
// pressed neighbours move as one block whose acceleration down the slope is
// max(0, g (sum m sin - sum mu m cos) / sum m) (held iff the block's friction can hold its
// weight); blocks form by pooling adjacent violators from the front (a block behind
// faster than the one in front joins it). Each ball's path is then x = a t^2 / 2 along the
// slope, touching balls of a block stay touching, and blocks separate by (a_f - a_b) t^2 / 2.
// Grid: slopes 5-60 degrees, mu in both orders, mass ratios 0.01-100, 2, 3 and 4 balls,
// the balls listed front first and back first. Cases within 1e-6 g of a threshold are
// not judged (held or sliding, touching or parting, is round-off there). No run meets an
// event (the blocks' paths are exact: touching balls never approach by round-off) or the
// event cap.
static void balls_in_a_row_on_a_slope(std::size_t balls, int min_held = 20) {
  const std::vector<std::vector<double>> mus = {
      {0.5, 0.2},  {0.2, 0.5},   {0.05, 1.0},     {1.0, 0.05},      {0.3, 0.3},      {2.0, 0.1},
      {0.1, 2.0},  {0.7, 0.0},   {0.5, 0.2, 0.2}, {0.2, 0.5, 0.2},  {0.2, 0.2, 0.5}, {1.0, 0.1, 0.5},
      {0.1, 1.0, 0.1}, {0.05, 0.05, 2.0}, {2.0, 0.05, 0.05}, {0.6, 0.3, 0.0}, {1.2, 0.6, 0.9}, {0.3, 0.8, 1.5},
      {0.5, 0.2, 0.2, 0.2}, {0.2, 0.5, 0.2, 0.5}, {0.1, 1.0, 0.1, 1.0}, {1.0, 0.1, 0.1, 0.6}, {0.3, 0.3, 0.05, 0.9},
      {2.0, 0.05, 0.5, 0.05}, {0.6, 0.3, 0.0, 0.4}, {1.2, 0.6, 0.9, 0.7}, {1.5, 0.8, 1.2, 0.9}};
  const std::vector<std::vector<double>> masses = {
      {1, 1, 1, 1}, {0.01, 1, 100, 1}, {100, 1, 0.01, 10}, {1, 100, 1, 0.01}, {1, 0.01, 1, 100}};
  int judged = 0, skipped = 0, held_all = 0, slid_all = 0, parted = 0;
  for (double deg : {5.0, 10.0, 20.0, 35.0, 50.0, 60.0}) {
    const double th = deg * std::numbers::pi / 180.0;
    const Vec2 t{std::cos(th), std::sin(th)}, nrm{-std::sin(th), std::cos(th)};
    for (const auto& mu : mus) {
      if (mu.size() != balls) continue;
      for (const auto& mass : masses) {
        const std::size_t N = mu.size();
        // The closed form: blocks pooled from the front (ball 0, lowest) backwards.
        const auto alone = [&](std::size_t b, std::size_t e) {   // unclipped, down the slope
          double M = 0.0, F = 0.0;
          for (std::size_t k = b; k < e; ++k) {
            M += mass[k];
            F += mass[k] * g * (std::sin(th) - mu[k] * std::cos(th));
          }
          return F / M;
        };
        std::vector<std::pair<std::size_t, std::size_t>> blocks;   // [begin, end)
        bool near_threshold = false;
        for (std::size_t k = 0; k < N; ++k) {
          blocks.push_back({k, k + 1});
          while (blocks.size() > 1) {
            const auto [fb, fe] = blocks[blocks.size() - 2];
            const auto [bb, be] = blocks.back();
            const double af = std::max(0.0, alone(fb, fe)), ab = std::max(0.0, alone(bb, be));
            // A tie to round-off (balls alike sliding alike) is no threshold: pooled or not, the
            // same accelerations; near one, the outcome turns on round-off.
            const double gap_a = std::fabs(ab - af);
            if (gap_a < 1e-6 * g && gap_a > 1e-12 * g && (ab > 0.0 || af > 0.0)) near_threshold = true;
            if (!(ab > af)) break;
            blocks.pop_back();
            blocks.back().second = be;
          }
        }
        std::vector<double> a(N);
        for (const auto& [b, e] : blocks) {
          const double u = alone(b, e);
          if (std::fabs(u) < 1e-6 * g) near_threshold = true;
          for (std::size_t k = b; k < e; ++k) a[k] = std::max(0.0, u);
        }
        if (near_threshold) {
          ++skipped;
          continue;
        }
        if (blocks.size() == 1) (a[0] == 0.0 ? held_all : slid_all)++;
        if (blocks.size() > 1) ++parted;
        for (bool front_first : {true, false}) {
          std::vector<BodyDef> bodies;
          std::vector<std::size_t> index(N);   // ball k (0: front, lowest) -> body index
          std::vector<Vec2> start(N);
          for (std::size_t q = 0; q < N; ++q) {
            const std::size_t k = front_first ? q : N - 1 - q;
            start[k] = (20.0 + static_cast<double>(k)) * t + 0.5 * nrm;
            bodies.push_back(circle("b" + std::to_string(k), start[k], {}, 0.5, mass[k], 0.0));
            index[k] = q;
          }
          Scene sc = scene_of(bodies, {wall("slope", {0.0, 0.0}, 40.0 * t, 0.0)}, {0.0, -g});
          for (std::size_t k = 0; k < N; ++k) {
            MaterialOverride m;
            m.a = bodies[index[k]].name;
            m.b = "slope";
            m.friction = mu[k];
            sc.materials.push_back(m);
            for (std::size_t l = k + 1; l < N; ++l) {
              MaterialOverride p;
              p.a = m.a;
              p.b = bodies[index[l]].name;
              p.friction = 0.0;
              sc.materials.push_back(p);
            }
          }
          const std::string where = std::to_string(deg) + " deg, " + std::to_string(N) + " balls, mu0 " +
                                    std::to_string(mu[0]) + " mu1 " + std::to_string(mu[1]) + " mass0 " +
                                    std::to_string(mass[0]) + " mass1 " + std::to_string(mass[1]) +
                                    (front_first ? ", front first" : ", back first");
          Sim sim(sc);
          double worst_overlap = 0.0, worst = 0.0;
          bool cap_hit = false;
          std::int64_t events = 0;
          for (int step = 1; step <= 60; ++step) {
            sim.step(1.0 / 60.0);
            cap_hit = cap_hit || sim.engine.last_step_stats().event_cap_hit;
            events += sim.engine.last_step_stats().events;
            const double time = step / 60.0;
            for (std::size_t k = 0; k < N; ++k) {
              const BodyState b = sim.state(index[k]);
              const Vec2 expect = start[k] - (0.5 * a[k] * time * time) * t;
              worst = std::max({worst, length(b.position - expect), length(b.velocity - (-a[k] * time) * t)});
              if (k + 1 < N) {
                const double gap = length(sim.state(index[k + 1]).position - b.position) - 1.0;
                worst_overlap = std::max(worst_overlap, -gap);
                worst = std::max(worst, std::fabs(gap - 0.5 * (a[k] - a[k + 1]) * time * time));
              }
            }
          }
          EXPECT_LE(worst, 1e-9) << where << ": a " << a[0] << " " << a[1] << (N > 2 ? " " + std::to_string(a[2]) : "") << (N > 3 ? " " + std::to_string(a[3]) : "");
          EXPECT_LE(worst_overlap, 1e-9) << where;
          EXPECT_FALSE(cap_hit) << where;
          EXPECT_EQ(events, 0) << where << ": the blocks' paths meet no event in a second";
          ++judged;
        }
      }
    }
  }
  EXPECT_GT(held_all, min_held);   // cases where every ball is held in one block
  EXPECT_GT(slid_all, 20);
  EXPECT_GT(parted, 20);
  EXPECT_LT(skipped, 30);   // ties (two balls alike behind one another), not judged
  EXPECT_GT(judged, 350);
}

TEST(CoreResting, TwoBallsOnASlopeMeetRigidCoulomb) { balls_in_a_row_on_a_slope(2); }

// Three balls: two behind sliding alike join the train only once the front one slows the
// middle one (push_trains takes every touching pair, pressed or not).
TEST(CoreResting, ThreeBallsInARowOnASlopeMeetRigidCoulomb) { balls_in_a_row_on_a_slope(3); }
// Four balls (a 4-ball set held as one block is rarer: 11 of the grid's cases).
TEST(CoreResting, FourBallsInARowOnASlopeMeetRigidCoulomb) { balls_in_a_row_on_a_slope(4, 8); }

// Balls in a row sliding at v0 down a floor or a 15 degree slope (toward ball 0, the
// front), each with its own friction, none between them, until they stop (hunt: a block
// stopping at once). Rigid Coulomb: while moving, blocks pool from the front as above with
// each block's acceleration along the motion g (sum m sin - sum mu m cos) / sum m (kinetic
// friction, no clipping); a block decelerating from v0 at d stops at v0 / d and stays there
// if, pooled again from rest, its members are all held (cases where some would slide on
// from rest, and cases within 1e-6 g of a threshold or stopping within 1e-3 s of a step's
// end, are not judged). Blocks behind the front decelerate more, so they never meet again.
// Every step to 1e-9 in position and velocity, no overlap, both numberings. Before the
// fix, a pushed ball whose block stopped inside a step kept the push of the moving block
// at rest and was sent back (9e-5 m at masses 100, 1, 0.01 on the floor).
TEST(CoreResting, BallsInARowSlidingToAStopMeetRigidCoulomb) {
  const std::vector<std::vector<double>> mus = {{0.5, 0.2, 0.2},      {1.0, 0.1, 0.5},      {0.2, 0.2, 0.5},
                                                {0.6, 0.3, 0.05},     {0.4, 0.2},           {0.2, 0.4},
                                                {0.5, 0.2, 0.2, 0.2}, {0.1, 1.0, 0.1, 1.0}, {1.0, 0.1, 0.1, 0.6}};
  const std::vector<std::vector<double>> masses = {
      {1, 1, 1, 1}, {0.01, 1, 100, 1}, {100, 1, 0.01, 10}, {1, 100, 1, 0.01}};
  int judged = 0, stopped = 0;
  for (double deg : {0.0, 15.0}) {
    const double th = deg * std::numbers::pi / 180.0;
    const Vec2 t{std::cos(th), std::sin(th)}, nrm{-std::sin(th), std::cos(th)};
    for (double v0 : {1.0, 3.0}) {
      for (const auto& mu : mus) {
        for (const auto& mass : masses) {
          const std::size_t N = mu.size();
          const auto alone = [&](std::size_t b, std::size_t e, bool from_rest) {   // along the motion
            double M = 0.0, F = 0.0, H = 0.0;
            for (std::size_t k = b; k < e; ++k) {
              M += mass[k];
              F += mass[k] * g * std::sin(th);
              H += mass[k] * g * mu[k] * std::cos(th);
            }
            return from_rest ? std::max(0.0, (F - H) / M) : (F - H) / M;
          };
          const auto pool = [&](std::size_t b0, std::size_t e0, bool from_rest, bool& near) {
            std::vector<std::pair<std::size_t, std::size_t>> blocks;
            for (std::size_t k = b0; k < e0; ++k) {
              blocks.push_back({k, k + 1});
              while (blocks.size() > 1) {
                const auto [fb, fe] = blocks[blocks.size() - 2];
                const auto [bb, be] = blocks.back();
                const double af = alone(fb, fe, from_rest), ab = alone(bb, be, from_rest);
                const double gap = std::fabs(ab - af);
                if (gap < 1e-6 * g && gap > 1e-12 * g && (ab != 0.0 || af != 0.0)) near = true;
                if (!(ab > af)) break;
                blocks.pop_back();
                blocks.back().second = be;
              }
            }
            return blocks;
          };
          bool near = false;
          std::vector<double> a(N), stop(N, INFINITY);
          for (const auto& [b, e] : pool(0, N, false, near)) {
            const double u = alone(b, e, false);
            if (std::fabs(u) < 1e-6 * g) near = true;
            double ts = INFINITY;
            if (u < 0.0) {
              ts = v0 / -u;
              for (const auto& [rb, re] : pool(b, e, true, near)) {
                const double ur = alone(rb, re, true);
                if (ur != 0.0 || std::fabs((alone(rb, re, false))) < 1e-6 * g) near = true;   // slides on
              }
              const double steps = ts * 60.0;
              if (ts < 1.0 && std::fabs(steps - std::round(steps)) < 1e-3 * 60.0) near = true;
            }
            for (std::size_t k = b; k < e; ++k) a[k] = u, stop[k] = ts;
          }
          if (near) continue;
          for (double s : stop) stopped += s < 1.0;
          for (bool front_first : {true, false}) {
            std::vector<BodyDef> bodies;
            std::vector<std::size_t> index(N);
            std::vector<Vec2> start(N);
            for (std::size_t q = 0; q < N; ++q) {
              const std::size_t k = front_first ? q : N - 1 - q;
              start[k] = (20.0 + static_cast<double>(k)) * t + 0.5 * nrm;
              bodies.push_back(circle("b" + std::to_string(k), start[k], -v0 * t, 0.5, mass[k], 0.0));
              index[k] = q;
            }
            Scene sc = scene_of(bodies, {wall("floor", {0.0, 0.0}, 40.0 * t, 0.0)}, {0.0, -g});
            for (std::size_t k = 0; k < N; ++k) {
              MaterialOverride m;
              m.a = bodies[index[k]].name;
              m.b = "floor";
              m.friction = mu[k];
              sc.materials.push_back(m);
              for (std::size_t l = k + 1; l < N; ++l) {
                MaterialOverride p;
                p.a = m.a;
                p.b = bodies[index[l]].name;
                p.friction = 0.0;
                sc.materials.push_back(p);
              }
            }
            const std::string where = std::to_string(deg) + " deg, v0 " + std::to_string(v0) + ", " +
                                      std::to_string(N) + " balls, mu0 " + std::to_string(mu[0]) + " mu1 " +
                                      std::to_string(mu[1]) + " mass0 " + std::to_string(mass[0]) +
                                      (front_first ? ", front first" : ", back first");
            Sim sim(sc);
            double worst = 0.0, worst_overlap = 0.0;
            bool cap_hit = false;
            for (int step = 1; step <= 60; ++step) {
              sim.step(1.0 / 60.0);
              cap_hit = cap_hit || sim.engine.last_step_stats().event_cap_hit;
              const double time = step / 60.0;
              for (std::size_t k = 0; k < N; ++k) {
                const double tk = std::min(time, stop[k]);
                const double s = v0 * tk + 0.5 * a[k] * tk * tk, v = time < stop[k] ? v0 + a[k] * time : 0.0;
                const BodyState b = sim.state(index[k]);
                worst = std::max({worst, length(b.position - (start[k] - s * t)), length(b.velocity - (-v) * t)});
                if (k + 1 < N) worst_overlap = std::max(worst_overlap, 1.0 - length(sim.state(index[k + 1]).position - b.position));
              }
            }
            EXPECT_LE(worst, 1e-9) << where << ", masses " << mass[0] << " " << mass[1] << " " << mass[2];
            EXPECT_LE(worst_overlap, 1e-9) << where;
            EXPECT_FALSE(cap_hit) << where;
            ++judged;
          }
        }
      }
    }
  }
  EXPECT_GT(judged, 200);
  EXPECT_GT(stopped, 100);   // ball-cases that stop within the second
}

// Three equal balls (r 0.5, m 1, e 0): two on a floor touching each other at x = -0.5 and
// 0.5, the third on top of them (hunt: pyramid_of_three). Non-rotating circles, no friction
// between the balls, floor friction mu. Rigid Coulomb by hand: each contact normal to the
// top is 30 degrees from the vertical; at rest each bottom ball is pushed out by
// g / (2 sqrt 3) = 0.289 g and pressed on the floor by 1.5 g, so the pyramid holds iff
// mu >= 1 / (3 sqrt 3) = 0.19245. Below that, with N the top's contact force and the
// bottom balls sliding out (a_b = sqrt 3 a_t keeps the contacts):
//   top    a_t = g - sqrt 3 N,   bottom  a_b = N / 2 - mu (g + sqrt 3 N / 2)
//   =>     a_t = g (1 - 3 sqrt 3 mu) / (7 - sqrt 3 mu)   (g / 7 frictionless)
// Checked: the velocities after a first step of 1e-4 s meet a t to 1e-9 m/s (a changes
// only at O(t^2) from rest); then to 4 s: no energy gained, no overlap over 1e-9 m, the
// mirror symmetry and a renumbering to 1e-12, and the end: collapsed (top on the floor,
// bottom balls apart) or held (nothing moved).
// core holds the top as on fixed supports, then judges the resting component; one that
// rigid Coulomb says cannot hold used to be reported as a broken guarantee (diverged); it is
// now moved by the contact-group mode (contact_group.cpp, README, Several supports): iff it
// cannot hold, with either numbering, core says so in limits_hit and the top comes down;
// no broken guarantee either way. Every body and the floor have friction mu, so every
// contact has mu (the pair rule is sqrt(f1 f2)). Friction at the top's contacts tilts their
// force towards the vertical by atan(mu): each bottom ball is pushed out by
// (W/2) tan(30 deg - atan mu) and the floor holds it up to 1.5 mu W, so the pyramid holds
// iff mu >= 0.13 (mu 0.1: 0.226 W against 0.15 W; mu 0.15: 0.197 W against 0.225 W). A
// rough floor under frictionless balls is no friction at all (sqrt(0 x 1) = 0): it spreads.
// Between two walls that brace the bottom balls it holds on any floor.
TEST(CoreResting, APyramidThatCannotHoldCollapsesInTheContactGroupMode) {
  const double s3 = std::sqrt(3.0);
  for (double mu : {0.0, 0.05, 0.1, 0.15, 0.2, 0.3, 1.0, -1.0}) {   // -1: floor 1.0, balls 0
    for (bool braced : {false, true}) {
      for (bool top_first : {false, true}) {
        SCOPED_TRACE("mu " + std::to_string(mu) + (braced ? ", braced" : "") + (top_first ? ", top first" : ""));
        std::vector<BodyDef> b = {circle("left", {-0.5, 0.5}, {}, 0.5, 1.0, 0.0),
                                  circle("right", {0.5, 0.5}, {}, 0.5, 1.0, 0.0),
                                  circle("top", {0.0, 0.5 + s3 / 2.0}, {}, 0.5, 1.0, 0.0)};
        for (BodyDef& x : b) x.friction = x.static_friction = std::max(mu, 0.0);
        if (top_first) b = {b[2], b[1], b[0]};
        std::vector<WallDef> walls = {wall("floor", {-50.0, 0.0}, {50.0, 0.0}, 0.0, mu < 0.0 ? 1.0 : mu)};
        if (braced) {
          walls.push_back(wall("lw", {-1.0, 3.0}, {-1.0, 0.0}, 0.0, 0.0));
          walls.push_back(wall("rw", {1.0, 0.0}, {1.0, 3.0}, 0.0, 0.0));
        }
        Scene sc = scene_of(b, walls, {0.0, -g});
        Sim sim(sc);
        const bool should_hold = braced || mu >= 0.15;
        bool broken = false;
        while (sim.engine.time() < 2.0 - 1e-12 && !broken) {
          sim.step(1.0 / 60.0);
          broken = !sim.engine.broken_guarantee().empty();
        }
        EXPECT_FALSE(broken) << sim.engine.broken_guarantee();
        const auto limits = sim.engine.limits_hit();
        const bool grouped = std::any_of(limits.begin(), limits.end(), [](const std::string& x) {
          return x.find("bodies moving in contact") != std::string::npos;
        });
        EXPECT_EQ(grouped, !should_hold);
        if (!should_hold) {
          EXPECT_LT(sim.state("top").position.y, 0.5 + s3 / 2.0 - 0.1);
        }
        if (should_hold) {
          EXPECT_NEAR(sim.state("top").position.y, 0.5 + s3 / 2.0, 1e-9);
        }
      }
    }
  }
}

// Still disabled (branch piles10, 2026-11-25): not a fault a local fix can remove. Below
// mu = 1 / (3 sqrt 3) the closed form is a motion *under* contact forces: the top slides down
// both bottom balls with N > 0 at each contact the whole time (a_t = g (1 - 3 sqrt 3 mu) /
// (7 - sqrt 3 mu)), an index-2 constrained motion with three bodies in persistent contact.
// core's exact mode has two models of a contact, neither of which is that: a held body (v = 0,
// no path; the braced judgement reports the hold, APyramidCoreCannotJustifyHoldingIsABroken-
// Guarantee above) and free flights between impacts (which, for a top pressed into bodies that
// give way, is the inelastic collapse: micro-bounces of >= dt/16 whose mean motion is not the
// closed form's, off at first order in dt). Passing needs a third: a group of free bodies
// moving on the acceleration-level contact problem (the LCP the braced judgement already
// solves, A f >= -b, f >= 0, complementary) between events, with lift-off (f -> 0), a new
// contact and a stop as its exact events, and its own integrator (positions drift off the
// constraint at the integrator's order without a projection). That is a new engine mode, not
// done here.
TEST(CoreResting, PyramidOfThreeCollapsesIffRigidCoulombSays) {
  const double s3 = std::sqrt(3.0);
  for (double mu : {0.0, 0.1, 0.15, 0.3, 1.0}) {
    const bool holds = mu >= 1.0 / (3.0 * s3);
    const double at = holds ? 0.0 : g * (1.0 - 3.0 * s3 * mu) / (7.0 - s3 * mu);
    std::vector<std::vector<BodyState>> runs;
    for (bool top_first : {false, true}) {
      SCOPED_TRACE("mu " + std::to_string(mu) + (top_first ? ", top listed first" : ", top listed last"));
      std::vector<BodyDef> b = {circle("left", {-0.5, 0.5}, {}, 0.5, 1.0, 0.0),
                                circle("right", {0.5, 0.5}, {}, 0.5, 1.0, 0.0),
                                circle("top", {0.0, 0.5 + s3 / 2.0}, {}, 0.5, 1.0, 0.0)};
      if (top_first) b = {b[2], b[1], b[0]};
      Scene sc = scene_of(b, {wall("floor", {-50.0, 0.0}, {50.0, 0.0}, 0.0, mu)}, {0.0, -g});
      // The floor's mu on the ball-floor pairs (the pair rule sqrt(f1 f2) would give 0: the
      // balls have none), none between the balls, as the closed form above assumes.
      for (const char* nm : {"left", "right", "top"}) {
        MaterialOverride m;
        m.a = nm;
        m.b = "floor";
        m.friction = mu;
        m.static_friction = mu;
        sc.materials.push_back(m);
      }
      Sim sim(sc);
      const auto st = [&](const char* name) { return sim.state(name); };
      const auto energy3 = [&]() {
        double e = 0.0;
        for (const char* nm : {"left", "right", "top"}) {
          const BodyState x = st(nm);
          e += 0.5 * length_squared(x.velocity) + g * x.position.y;
        }
        return e;
      };
      const double e0 = energy3();
      const double h = 1e-4;
      sim.step(h);
      EXPECT_NEAR(st("top").velocity.y, -at * h, 1e-9);
      EXPECT_NEAR(st("top").velocity.x, 0.0, 1e-12);
      EXPECT_NEAR(st("right").velocity.x, s3 * at * h, 1e-9);
      EXPECT_NEAR(st("left").velocity.x, -s3 * at * h, 1e-9);
      double gained = 0.0, overlap = 0.0, asym = 0.0;
      while (sim.engine.time() < 4.0 - 1e-12) {
        sim.step(std::min(1.0 / 60.0, 4.0 - sim.engine.time()));
        gained = std::max(gained, energy3() - e0);
        const BodyState l = st("left"), r = st("right"), t = st("top");
        overlap = std::max({overlap, 1.0 - length(l.position - r.position), 1.0 - length(l.position - t.position),
                            1.0 - length(r.position - t.position), 0.5 - l.position.y, 0.5 - r.position.y,
                            0.5 - t.position.y});
        asym = std::max({asym, std::fabs(l.position.x + r.position.x), std::fabs(l.position.y - r.position.y),
                         std::fabs(t.position.x)});
      }
      EXPECT_LE(gained, 1e-9);
      EXPECT_LE(overlap, 1e-9);
      EXPECT_LE(asym, 1e-12);
      const BodyState l = st("left"), r = st("right"), t = st("top");
      if (holds) {
        EXPECT_NEAR(t.position.y, 0.5 + s3 / 2.0, 1e-9);
        EXPECT_NEAR(r.position.x, 0.5, 1e-9);
        EXPECT_NEAR(l.position.x, -0.5, 1e-9);
      } else {
        EXPECT_NEAR(t.position.y, 0.5, 1e-9);   // on the floor between them
        EXPECT_GE(r.position.x, 1.0 - 1e-9);
        EXPECT_LE(l.position.x, -1.0 + 1e-9);
      }
      runs.push_back({l, r, t});
    }
    for (std::size_t k = 0; k < 3; ++k) {
      EXPECT_LE(length(runs[0][k].position - runs[1][k].position), 1e-12) << "mu " << mu << " body " << k;
    }
  }
}


// Bodies moving in contact (contact_group.cpp), a closed form of its own: the frictionless
// pyramid with bottom balls of mass M under a top of mass m (d = 2r between centres, theta the
// angle of a top contact from the vertical, c = cos theta, c0 = cos 30 deg). While both top
// contacts hold, energy and the constraint give the rate of theta:
//   theta'^2 = 2 m g (c0 - c) / (d (m (1 - c^2) + 2 M c^2)),
// the bottom balls move out at d c theta' and the top down at d sin(theta) theta'. The contact
// force pushes the bottom balls out until it reaches 0 (lift-off), which is where their speed
// d c theta' is largest; after it they coast on the frictionless floor at that speed for ever
// (the top falls faster than the contact would let it and lands on the floor between them).
// Checked: while in contact, the speeds against the angle to 1e-7; the bottom balls' final
// speed against the maximum of d c theta' (found by golden section) to 1e-7; the top at rest
// on the floor; no overlap beyond 1e-9 m; no energy gained.
TEST(CoreResting, APyramidCollapsingFrictionlessMeetsEnergyAndLiftOffClosedForms) {
  const double s3 = std::sqrt(3.0), c0 = s3 / 2.0, d = 1.0;
  for (double M : {1.0, 3.0, 0.25}) {
    SCOPED_TRACE("bottom mass " + std::to_string(M));
    const double m = 1.0;
    const auto rate2 = [&](double c) { return 2.0 * m * g * (c0 - c) / (d * (m * (1.0 - c * c) + 2.0 * M * c * c)); };
    const auto vb_of = [&](double c) { return d * c * std::sqrt(std::max(0.0, rate2(c))); };
    double lo = 0.0, hi = c0;   // golden section for the largest d c theta'
    for (int it = 0; it < 200; ++it) {
      const double a = hi - 0.618033988749895 * (hi - lo), b = lo + 0.618033988749895 * (hi - lo);
      if (vb_of(a) > vb_of(b)) {
        hi = b;
      } else {
        lo = a;
      }
    }
    const double vb_final = vb_of(0.5 * (lo + hi));
    std::vector<BodyDef> b = {circle("left", {-0.5, 0.5}, {}, 0.5, M, 0.0), circle("right", {0.5, 0.5}, {}, 0.5, M, 0.0),
                              circle("top", {0.0, 0.5 + s3 / 2.0}, {}, 0.5, m, 0.0)};
    Scene sc = scene_of(b, {wall("floor", {-500.0, 0.0}, {500.0, 0.0}, 0.0, 0.0)}, {0.0, -g});
    Sim sim(sc);
    const auto energy = [&]() {
      double e = 0.0;
      for (std::size_t k = 0; k < 3; ++k) {
        const BodyState x = sim.state(k);
        const double mk = k == 2 ? m : M;
        e += mk * (0.5 * length_squared(x.velocity) + g * x.position.y);
      }
      return e;
    };
    const double e0 = energy();
    double worst_speed = 0.0, overlap = 0.0, gained = 0.0;
    int in_contact_checks = 0;
    while (sim.engine.time() < 3.0 - 1e-12) {
      sim.step(1.0 / 60.0);
      const BodyState l = sim.state(0), r = sim.state(1), t = sim.state(2);
      gained = std::max(gained, energy() - e0);
      overlap = std::max({overlap, 1.0 - length(l.position - r.position), 1.0 - length(l.position - t.position),
                          1.0 - length(r.position - t.position), 0.5 - l.position.y, 0.5 - r.position.y,
                          0.5 - t.position.y});
      const double gap = length(r.position - t.position) - 1.0;
      if (std::fabs(gap) <= 1e-9 && r.velocity.x > 0.0 && t.position.y > 0.5 + 1e-6) {   // still in contact
        const double c = (t.position.y - 0.5) / d, s = (r.position.x - t.position.x) / d;
        const double rate = std::sqrt(rate2(c));
        worst_speed = std::max({worst_speed, std::fabs(r.velocity.x - d * c * rate), std::fabs(-l.velocity.x - d * c * rate),
                                std::fabs(-t.velocity.y - d * s * rate)});
        ++in_contact_checks;
      }
    }
    EXPECT_GE(in_contact_checks, 5);
    EXPECT_LE(worst_speed, 1e-7);
    const BodyState l = sim.state(0), r = sim.state(1), t = sim.state(2);
    EXPECT_NEAR(r.velocity.x, vb_final, 1e-7);
    EXPECT_NEAR(l.velocity.x, -vb_final, 1e-7);
    EXPECT_NEAR(t.position.y, 0.5, 1e-9);
    EXPECT_NEAR(t.position.x, 0.0, 1e-12);
    EXPECT_NEAR(length(t.velocity), 0.0, 1e-9);
    EXPECT_LE(overlap, 1e-9);
    EXPECT_LE(gained, 1e-9);
    EXPECT_TRUE(sim.engine.broken_guarantee().empty()) << sim.engine.broken_guarantee();
  }
}

// The contact-group mode is not exact: it is integrated by RK4 on sub-steps of dt/8, so its
// error falls as dt^4. Runs of the frictionless pyramid at dt = 1/30, 1/60, 1/120, 1/240: the
// difference between successive runs at t = 0.3 s (mid-collapse, both top contacts closed) and
// at 1.2 s (after the lift-off and the top's landing) falls by at least 8 (order >= 3) per
// halving while above round-off, and core says in limits_hit that it used the mode.
TEST(CoreResting, TheContactGroupModeConvergesAtItsIntegratorsOrder) {
  const double s3 = std::sqrt(3.0);
  const auto run = [&](double dt, double until) {
    std::vector<BodyDef> b = {circle("left", {-0.5, 0.5}, {}, 0.5, 1.0, 0.0), circle("right", {0.5, 0.5}, {}, 0.5, 1.0, 0.0),
                              circle("top", {0.0, 0.5 + s3 / 2.0}, {}, 0.5, 1.0, 0.0)};
    Sim sim(scene_of(b, {wall("floor", {-50.0, 0.0}, {50.0, 0.0}, 0.0, 0.0)}, {0.0, -g}));
    while (sim.engine.time() < until - 1e-12) sim.step(std::min(dt, until - sim.engine.time()));
    const auto limits = sim.engine.limits_hit();
    EXPECT_TRUE(std::any_of(limits.begin(), limits.end(),
                            [](const std::string& s) { return s.find("bodies moving in contact") != std::string::npos; }));
    std::vector<Vec2> out;
    for (std::size_t k = 0; k < 3; ++k) out.push_back(sim.state(k).position);
    return out;
  };
  for (double until : {0.3, 1.2}) {
    std::vector<double> diffs;
    std::vector<Vec2> prev = run(1.0 / 30.0, until);
    for (double dt : {1.0 / 60.0, 1.0 / 120.0, 1.0 / 240.0}) {
      const std::vector<Vec2> cur = run(dt, until);
      double dmax = 0.0;
      for (std::size_t k = 0; k < 3; ++k) dmax = std::max(dmax, length(cur[k] - prev[k]));
      diffs.push_back(dmax);
      prev = cur;
    }
    SCOPED_TRACE("t " + std::to_string(until) + ": " + std::to_string(diffs[0]) + " " + std::to_string(diffs[1]) + " " +
                 std::to_string(diffs[2]));
    EXPECT_GT(diffs[0], 0.0);   // not exact: the runs differ
    for (std::size_t q = 1; q < diffs.size(); ++q) {
      if (diffs[q - 1] > 1e-11) {   // above round-off
        EXPECT_LE(diffs[q], diffs[q - 1] / 8.0);
      }
    }
  }
}

}  // namespace physval::test
