// Resting contact on several supports and inelastic collapse (issue 9): a circle in a V,
// a column of circles, bodies touching at t = 0, a stack at mass ratios up to 1e9, and
// piles of 10 to 200 circles that must settle without overlap, without reaching the
// event cap and without gaining energy.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include "physval/core/scene_builders.hpp"
#include "scene_fixture.hpp"

namespace physval::test {

namespace {

constexpr double g = 9.8;
constexpr double dt = 1.0 / 60.0;

// A symmetric V: two walls at `angle` (rad) to the horizontal meeting at the origin.
std::vector<WallDef> v_walls(double angle, double e, double mu = 0.0) {
  const double L = 5.0;
  const Vec2 left{-L * std::cos(angle), L * std::sin(angle)};
  const Vec2 right{L * std::cos(angle), L * std::sin(angle)};
  return {wall("left", left, {0.0, 0.0}, e, mu), wall("right", {0.0, 0.0}, right, e, mu)};
}

// The centre of a circle of radius r resting in that V.
Vec2 v_rest(double angle, double r) { return {0.0, r / std::cos(angle)}; }

double energy(const std::vector<BodyState>& s, const Scene& scene) {
  double E = 0.0;
  for (std::size_t i = 0; i < s.size(); ++i) {
    const double m = scene.bodies[i].mass;
    E += 0.5 * m * length_squared(s[i].velocity) + m * g * s[i].position.y;
  }
  return E;
}

// Deepest overlap between circles, and between circles and the walls' lines on the
// segment spans.
double deepest_overlap(const std::vector<BodyState>& s, const Scene& scene) {
  double worst = 0.0;
  for (std::size_t i = 0; i < s.size(); ++i) {
    const double ri = scene.bodies[i].radius;
    for (std::size_t j = i + 1; j < s.size(); ++j) {
      const double d = length(s[i].position - s[j].position);
      worst = std::max(worst, ri + scene.bodies[j].radius - d);
    }
    for (const WallDef& w : scene.walls) {
      const Vec2 e = w.to - w.from;
      const double L = length(e);
      const Vec2 dir = e / L;
      const double u = dot(s[i].position - w.from, dir);
      if (u < 0.0 || u > L) continue;
      worst = std::max(worst, ri - std::fabs(cross(dir, s[i].position - w.from)));
    }
  }
  return worst;
}

}  // namespace

TEST(CorePile, CircleDroppedIntoVRestsInItsPocket) {
  // Frictionless, dropped off-centre from 1 m with e = 0.5: it ends at rest touching both
  // walls, exactly in the pocket, and each wall carries m g / (2 cos a).
  for (double deg : {20.0, 35.0, 50.0}) {
    SCOPED_TRACE(deg);
    const double a = deg * std::numbers::pi / 180.0, r = 0.25, m = 2.0;
    Sim sim(scene_of({circle("ball", {0.3, 1.5}, {}, r, m, 0.5)}, v_walls(a, 0.5), {0.0, -g}));
    double E_prev = INFINITY;
    for (int k = 0; k < 600; ++k) {
      sim.step(dt);
      ASSERT_TRUE(sim.engine.broken_guarantee().empty()) << k;
      sim.engine.read_states(sim.states);
      const double E = energy(sim.states, sim.scene);
      ASSERT_LE(E, E_prev + 1e-9) << "energy gained at step " << k;
      E_prev = E;
      ASSERT_LE(deepest_overlap(sim.states, sim.scene), 1e-9) << k;
    }
    const Vec2 p = sim.state("ball").position;
    const Vec2 want = v_rest(a, r);
    EXPECT_NEAR(p.x, want.x, 1e-9);
    EXPECT_NEAR(p.y, want.y, 1e-9);
    EXPECT_EQ(sim.state("ball").velocity, Vec2{});
    EXPECT_EQ(sim.engine.last_step_stats().events, 0);
    const auto forces = sim.engine.resting_forces();
    ASSERT_EQ(forces.size(), 2u);
    for (const auto& f : forces) EXPECT_NEAR(f.force, m * g / (2.0 * std::cos(a)), 1e-9 * m * g);
  }
}

TEST(CorePile, CircleDroppedCentredIntoVMeetsBothFacesAtOnceAndStaysOnTheAxis) {
  // Dropped on the V's axis, it meets both faces at one instant. Newton's law at both at
  // once keeps it on the axis (|x| <= 1e-12, whichever wall is listed first) and,
  // e < 1, it ends at rest in the pocket. Found by the hunt (validation/tests/hunt/
  // v_trough_inelastic.toml): at e = 0 core settled on the first face listed, then met the
  // second, and left the V sideways at 1.4 m/s for walls 5-22 degrees from horizontal.
  for (double deg : {5.0, 10.0, 15.0, 20.0, 22.0, 30.0, 45.0, 60.0}) {
    for (double e : {0.0, 0.3, 0.7}) {
      for (double mu : {0.0, 0.3}) {
        for (bool swapped : {false, true}) {
          SCOPED_TRACE(::testing::Message() << deg << " deg, e " << e << ", mu " << mu << (swapped ? ", right wall first" : ""));
          const double a = deg * std::numbers::pi / 180.0, r = 0.5;
          std::vector<WallDef> walls = v_walls(a, e, mu);
          if (swapped) std::swap(walls[0], walls[1]);
          const BodyDef ball = circle("ball", {0.0, v_rest(a, r).y + 2.0}, {0.0, -2.0}, r, 1.0, e);
          Sim sim(scene_of({ball}, walls, {0.0, -g}));
          double E_prev = INFINITY;
          for (int k = 0; k < 300; ++k) {
            sim.step(dt);
            ASSERT_TRUE(sim.engine.broken_guarantee().empty()) << k;
            sim.engine.read_states(sim.states);
            ASSERT_LE(std::fabs(sim.states[0].position.x), 1e-12) << "off the axis at step " << k;
            const double E = energy(sim.states, sim.scene);
            ASSERT_LE(E, E_prev + 1e-9) << "energy gained at step " << k;
            E_prev = E;
            ASSERT_LE(deepest_overlap(sim.states, sim.scene), 1e-9) << k;
          }
          EXPECT_NEAR(sim.state("ball").position.y, v_rest(a, r).y, 1e-9);
          EXPECT_EQ(sim.state("ball").velocity, Vec2{});
        }
      }
    }
  }
}

TEST(CorePile, CircleTouchingBothWallsAtStartNeverMoves) {
  // Placed in the pocket at t = 0 with e = 1: held from the first step, no event ever,
  // not a round-off off its position.
  const double a = 0.6, r = 0.3;
  const Vec2 p0 = v_rest(a, r);
  Sim sim(scene_of({circle("ball", p0, {}, r, 1.0, 1.0)}, v_walls(a, 1.0), {0.0, -g}));
  for (int k = 0; k < 300; ++k) {
    sim.step(dt);
    ASSERT_EQ(sim.engine.last_step_stats().events, 0) << k;
  }
  EXPECT_EQ(sim.state("ball").position, p0);
  EXPECT_EQ(sim.state("ball").velocity, Vec2{});
  EXPECT_LE(sim.contacts.size(), 2u);   // each wall begins once
}

TEST(CorePile, CircleOnTwoCirclesRestsExactly) {
  // A ball dropped onto two fixed balls a little apart settles in their pocket to 1e-9,
  // with each support force m g / (2 cos a), a the angle of the contact normals to the
  // vertical.
  const double r = 0.5, half = 0.7;
  const double a = std::asin(half / (2.0 * r));
  Sim sim(scene_of({static_circle("l", {-half, 0.0}, r, 0.3), static_circle("r", {half, 0.0}, r, 0.3),
                    circle("top", {0.05, 2.0}, {}, r, 1.5, 0.3)},
                   {}, {0.0, -g}));
  sim.run_until(6.0, dt);
  EXPECT_TRUE(sim.engine.limits_hit().empty());
  const Vec2 p = sim.state("top").position;
  EXPECT_NEAR(p.x, 0.0, 1e-9);
  EXPECT_NEAR(p.y, 2.0 * r * std::cos(a), 1e-9);
  sim.step(dt);
  EXPECT_EQ(sim.engine.last_step_stats().events, 0);
  const auto forces = sim.engine.resting_forces();
  ASSERT_EQ(forces.size(), 2u);
  for (const auto& f : forces) EXPECT_NEAR(f.force, 1.5 * g / (2.0 * std::cos(a)), 1e-9 * 1.5 * g);
}

TEST(CorePile, ColumnOfCirclesEachContactCarriesTheWeightAbove) {
  // Ten circles touching at t = 0 in a column between two walls one diameter apart
  // (frictionless): nothing moves, and the contact under circle k carries the weight of
  // circles k..9.
  const double r = 0.1;
  std::vector<BodyDef> bodies;
  for (int k = 0; k < 10; ++k) {
    bodies.push_back(circle("c" + std::to_string(k), {0.0, r + 2.0 * r * k}, {}, r, 1.0 + k, 0.3));
  }
  Sim sim(scene_of(bodies,
                   {wall("floor", {-1.0, 0.0}, {1.0, 0.0}, 0.3), wall("left", {-r, 0.0}, {-r, 5.0}, 0.3),
                    wall("right", {r, 0.0}, {r, 5.0}, 0.3)},
                   {0.0, -g}));
  for (int k = 0; k < 120; ++k) {
    sim.step(dt);
    ASSERT_EQ(sim.engine.last_step_stats().events, 0) << k;
  }
  for (int k = 0; k < 10; ++k) {
    EXPECT_EQ(sim.state("c" + std::to_string(k)).position, (Vec2{0.0, r + 2.0 * r * k}));
  }
  const auto forces = sim.engine.resting_forces();
  for (int k = 0; k < 10; ++k) {
    double carried = 0.0;
    for (int j = k; j < 10; ++j) carried += (1.0 + j) * g;
    double found = 0.0;
    int n_under = 0;
    for (const auto& f : forces) {
      if (f.body != static_cast<std::size_t>(k) || f.normal.y < 0.5) continue;   // the support below
      found += f.force;
      ++n_under;
    }
    EXPECT_EQ(n_under, 1) << k;
    EXPECT_NEAR(found, carried, 1e-9 * carried) << k;
  }
}

// Three frictionless circles (e 0.9) in a column on an open floor, at rest, off the vertical
// by round-off to 1e-6 m: unstable, it stands (held as a group within 1e-9 of its weight) or
// falls apart, but every step ends, nothing overlaps and no energy is gained (but the stated
// micro-bounce of a pressed pair nothing holds, bounded as in the piles below). Found by the
// thirteenth hunt (the middle of a frictionless pyramid after its collapse): at offsets of
// 1e-13 to 1e-11 m the first step never ended, the group hold (which passes the two upper
// circles together) and the one-body re-check (which passes neither alone) taking turns.
TEST(CorePile, AFrictionlessColumnOffTheVerticalByRoundOffEndsEveryStep) {
  const double r = 0.1;
  for (double off : {0.0, 1e-14, 1e-13, 1e-12, 1e-11, 1e-10, 1e-8, 1e-6}) {
    for (double h : {1.0 / 60.0, 1.0 / 240.0, 1.0 / 1000.0}) {
      SCOPED_TRACE("offset " + std::to_string(off) + ", dt " + std::to_string(h));
      Sim sim(scene_of({circle("a", {-0.74 * off, r}, {}, r, 1.0, 0.9), circle("b", {off, 3.0 * r + 1e-14}, {}, r, 1.0, 0.9),
                        circle("c", {-0.26 * off, 5.0 * r + 1e-14}, {}, r, 1.0, 0.9)},
                       {wall("floor", {-20.0, 0.0}, {20.0, 0.0}, 0.9)}, {0.0, -g}));
      sim.engine.read_states(sim.states);
      const double E0 = energy(sim.states, sim.scene);
      const double v_r = g * h / 16.0, micro_bounces = 3 * 0.5 * (0.5 * v_r) * (0.5 * v_r);
      const int steps = static_cast<int>(std::lround(0.5 / h));
      for (int k = 0; k < steps; ++k) {
        sim.step(h);
        ASSERT_FALSE(sim.engine.last_step_stats().event_cap_hit) << k;
        ASSERT_EQ(sim.engine.broken_guarantee(), "") << k;
        sim.engine.read_states(sim.states);
        ASSERT_LE(deepest_overlap(sim.states, sim.scene), 1e-9) << k;
        ASSERT_LE(energy(sim.states, sim.scene), E0 + 1e-12 * E0 + micro_bounces) << k;
      }
    }
  }
}

// The pyramid that column came from: 21 frictionless circles (rows of 6 down to 1, e 0.9)
// touching at t = 0 on an open floor. Rigid Coulomb cannot hold it; it collapses (in the
// granular mode) and spreads; every step ends, nothing overlaps, no energy is gained, and it
// stays mirror-symmetric about its axis to 1e-6 m in the centre of mass.
TEST(CorePile, AFrictionlessPyramidCollapsesAndEveryStepEnds) {
  const double r = 0.1;
  for (double h : {1.0 / 60.0, 1.0 / 240.0}) {
    SCOPED_TRACE("dt " + std::to_string(h));
    std::vector<BodyDef> bodies;
    for (int row = 0; row < 6; ++row) {
      for (int k = 0; k < 6 - row; ++k) {
        bodies.push_back(circle("q" + std::to_string(row) + "_" + std::to_string(k),
                                {-0.5 + row * r + 2.0 * r * k, r + row * std::sqrt(3.0) * r}, {}, r, 1.0, 0.9));
      }
    }
    Sim sim(scene_of(bodies, {wall("floor", {-20.0, 0.0}, {20.0, 0.0}, 0.9)}, {0.0, -g}));
    sim.engine.read_states(sim.states);
    const double E0 = energy(sim.states, sim.scene);
    const int steps = static_cast<int>(std::lround(2.0 / h));
    for (int k = 0; k < steps; ++k) {
      sim.step(h);
      ASSERT_FALSE(sim.engine.last_step_stats().event_cap_hit) << k;
      ASSERT_EQ(sim.engine.broken_guarantee(), "") << k;
      sim.engine.read_states(sim.states);
      ASSERT_LE(deepest_overlap(sim.states, sim.scene), 1e-9) << k;
      ASSERT_LE(energy(sim.states, sim.scene), E0 + 1e-12 * E0) << k;
    }
    double xc = 0.0;
    for (const BodyState& st : sim.states) xc += st.position.x / static_cast<double>(sim.states.size());
    EXPECT_NEAR(xc, 0.0, 1e-6);
  }
}

TEST(CorePile, StackAtMassRatiosUpTo1e9Holds) {
  // Three circles stacked on a floor, touching at t = 0, masses 1, M, 1 and M, 1, M for
  // M up to 1e9: they stay exactly where they are, with no events.
  for (double M : {1e3, 1e6, 1e9}) {
    for (bool heavy_middle : {true, false}) {
      SCOPED_TRACE(std::to_string(M) + (heavy_middle ? " heavy middle" : " light middle"));
      const double m0 = heavy_middle ? 1.0 : M, m1 = heavy_middle ? M : 1.0;
      Sim sim(scene_of({circle("a", {0.0, 0.5}, {}, 0.5, m0, 0.5), circle("b", {0.0, 1.5}, {}, 0.5, m1, 0.5),
                        circle("c", {0.0, 2.5}, {}, 0.5, m0, 0.5)},
                       {wall("floor", {-5.0, 0.0}, {5.0, 0.0}, 0.5)}, {0.0, -g}));
      for (int k = 0; k < 300; ++k) {
        sim.step(dt);
        ASSERT_EQ(sim.engine.last_step_stats().events, 0) << k;
      }
      EXPECT_EQ(sim.state("a").position, (Vec2{0.0, 0.5}));
      EXPECT_EQ(sim.state("b").position, (Vec2{0.0, 1.5}));
      EXPECT_EQ(sim.state("c").position, (Vec2{0.0, 2.5}));
    }
  }
}

TEST(CorePile, HeavyBodyDroppedOnLightStackSettles) {
  // A body 1e9 times heavier lands on a light one resting on the floor (e = 0.3): the
  // light one's support takes the blow, and both end at rest, no overlap.
  Sim sim(scene_of({circle("light", {0.0, 0.5}, {}, 0.5, 1.0, 0.3), circle("heavy", {0.0, 3.0}, {}, 0.5, 1e9, 0.3)},
                   {wall("floor", {-5.0, 0.0}, {5.0, 0.0}, 0.3)}, {0.0, -g}));
  sim.run_until(5.0, dt);
  EXPECT_TRUE(sim.engine.limits_hit().empty());
  EXPECT_NEAR(sim.state("light").position.y, 0.5, 1e-9);
  EXPECT_NEAR(sim.state("heavy").position.y, 1.5, 1e-9);
  EXPECT_EQ(sim.state("heavy").velocity, Vec2{});
}

// Piles: n circles (make_circle_pile) dropped into a closed box, 30 s. Each one collapses
// (issue 9's inelastic collapse) and settles. Since branch granular13 the dense phase of every
// pile is moved by core's granular groups (nonsmooth contact dynamics, granular.cpp): before,
// 8 of these 10 friction piles held a leaning group rigid Coulomb cannot hold (a broken
// guarantee: diverged), 6 of 7 frictionless ones a wedged one, and frictionless piles of 50
// and more did not settle in minutes. Now every one must settle within core's model: no broken
// guarantee, no event cap, no overlap deeper than 1e-9 m after any step, energy never rising (but the engine's micro-bounce, bounded below), every body at rest
// at the end with no events, and nothing in limits_hit but the granular mode's own statement
// (first order, not exact) or the exact group mode's.
struct PileCase {
  int n;
  double e;
  std::uint64_t seed;
  double mu = 0.5;
  double bullet = 0.0;   // > 0: a ball (e 0.9) shot down into the pile from near the lid at this speed
  int peg_rows = 0;      // > 0: rows of static pegs (r 0.04) in the lattice's gaps, from just above the floor
  double k1 = 0.0, k2 = 0.0;   // every body's linear and quadratic drag
  double wind = 0.0;           // the wind's x velocity
};

Scene pile_scene(const PileCase& c) {
  Scene s = make_circle_pile(c.n, c.e, c.mu, c.seed);
  if (c.bullet > 0.0) {
    BodyDef b = s.bodies.front();
    b.name = "bullet";
    b.restitution = 0.9;
    b.position = {0.5 * s.walls[0].to.x + 0.013, s.walls[1].to.y - 0.15};
    b.velocity = {0.2 * c.bullet, -c.bullet};
    s.bodies.push_back(b);
  }
  for (BodyDef& b : s.bodies) {
    b.drag_linear = c.k1;
    b.drag_quadratic = c.k2;
  }
  s.world.wind = {c.wind, 0.0};
  // Pegs at the corners between lattice cells (0.177 m from each cell's centre, which the
  // jitter moves by at most 0.028 m: no overlap at t = 0), the walls' gaps left open.
  const double W = s.walls[0].to.x;
  for (int row = 0; row < c.peg_rows; ++row) {
    for (int col = 1; 0.25 * col < W - 0.01; ++col) {
      BodyDef peg = s.bodies.front();
      peg.name = "peg" + std::to_string(row) + "_" + std::to_string(col);
      peg.is_static = true;
      peg.radius = 0.04;
      peg.position = {0.25 * col, 0.15 + 0.25 * row};
      peg.velocity = {};
      s.bodies.push_back(peg);
    }
  }
  return s;
}

class CorePileSettles : public ::testing::TestWithParam<PileCase> {};

bool only_group_notes(const std::vector<std::string>& limits) {
  for (const std::string& l : limits) {
    if (l.rfind("granular contact", 0) != 0 && l.rfind("bodies moving in contact", 0) != 0) return false;
  }
  return true;
}

TEST_P(CorePileSettles, SettlesWithoutOverlapCapOrEnergyGain) {
  const PileCase c = GetParam();
#if defined(__SANITIZE_ADDRESS__)
  // A sanitized Debug build is 10-20x slower; it checks the same code on the piles of 10-50.
  if (c.n > 50) GTEST_SKIP() << "pile of " << c.n << ": Release build only (too slow under the sanitizers)";
#endif
  Sim sim(pile_scene(c));
  // Energy never rises, but for the micro-bounce of a pressed pair that nothing can hold
  // (it leaves at half the rest speed v_r = g dt / 16): at most m (v_r / 2)^2 / 2 per body
  // and step. That is the README's stated exception, asserted as a bound.
  const double v_r = g * dt / 16.0;
  const double micro_bounces = static_cast<double>(sim.scene.bodies.size()) * 0.5 * (0.5 * v_r) * (0.5 * v_r);
  sim.engine.read_states(sim.states);
  const double E0 = energy(sim.states, sim.scene);
  double E_prev = INFINITY;
  double worst_rise = 0.0;
  std::int64_t last_events = -1;
  const int steps = 1800;
  for (int k = 0; k < steps; ++k) {
    sim.step(dt);
    ASSERT_FALSE(sim.engine.last_step_stats().event_cap_hit) << "step " << k;
    ASSERT_EQ(sim.engine.broken_guarantee(), "") << "step " << k;
    sim.engine.read_states(sim.states);
    const double E = energy(sim.states, sim.scene);
    if (k > 0) worst_rise = std::max(worst_rise, E - E_prev);
    if (c.wind == 0.0) {   // (the wind does work on the bodies)
      ASSERT_LE(E, E_prev + 1e-12 * std::fabs(E_prev) + micro_bounces) << "step " << k;
      ASSERT_LE(E, E0 + 1e-12 * std::fabs(E0)) << "step " << k;
    }
    E_prev = E;
    ASSERT_LE(deepest_overlap(sim.states, sim.scene), 1e-9) << "step " << k;   // every step
    // and nothing left the box (a body through a wall overlaps nothing)
    const double W = sim.scene.walls[0].to.x, H = sim.scene.walls[1].to.y;
    for (std::size_t i = 0; i < sim.states.size(); ++i) {
      const Vec2 p = sim.states[i].position;
      const double r = sim.scene.bodies[i].radius - 1e-9;
      ASSERT_TRUE(p.x >= r && p.x <= W - r && p.y >= r && p.y <= H - r) << "step " << k << ", body " << i;
    }
    last_events = sim.engine.last_step_stats().events;
  }
  EXPECT_LE(deepest_overlap(sim.states, sim.scene), 1e-9);
  EXPECT_EQ(last_events, 0);   // settled: nothing happens any more
  for (const BodyState& s : sim.states) EXPECT_EQ(s.velocity, Vec2{});
  EXPECT_TRUE(only_group_notes(sim.engine.limits_hit()));
  RecordProperty("worst_energy_rise_J", std::to_string(worst_rise));
}

INSTANTIATE_TEST_SUITE_P(Piles, CorePileSettles,
                         ::testing::Values(PileCase{10, 0.3, 1}, PileCase{10, 0.0, 2}, PileCase{10, 0.9, 3},
                                           PileCase{50, 0.3, 1}, PileCase{50, 0.0, 2}, PileCase{50, 0.9, 3},
                                           PileCase{50, 0.5, 4}, PileCase{100, 0.3, 5}, PileCase{100, 0.6, 6},
                                           PileCase{200, 0.3, 7},
                                           // mu 0.2: a projection that pushed bodies into
                                           // neighbours it had not listed left 4e-5 m overlaps
                                           PileCase{50, 0.6, 1, 0.2}, PileCase{200, 0.3, 1, 0.2},
                                           // a ball shot into the collapsing pile at 10-40 m/s
                                           PileCase{50, 0.3, 1, 0.5, 10.0}, PileCase{50, 0.3, 1, 0.5, 40.0},
                                           PileCase{100, 0.6, 6, 0.2, 25.0}),
                         [](const auto& test_info) {
                           return "n" + std::to_string(test_info.param.n) + "_e" +
                                  std::to_string(static_cast<int>(test_info.param.e * 10)) + "_seed" +
                                  std::to_string(test_info.param.seed) + "_mu" +
                                  std::to_string(static_cast<int>(test_info.param.mu * 10)) +
                                  (test_info.param.bullet > 0.0
                                       ? "_bullet" + std::to_string(static_cast<int>(test_info.param.bullet))
                                       : std::string());
                         });

// Frictionless piles (mu = 0): held only where the normals alone balance each body's weight
// (a pocket, a jammed group), which the collapse approaches through ever shorter hops.
INSTANTIATE_TEST_SUITE_P(FrictionlessPiles, CorePileSettles,
                         ::testing::Values(PileCase{10, 0.0, 1, 0.0}, PileCase{10, 0.3, 1, 0.0}, PileCase{10, 0.6, 1, 0.0},
                                           PileCase{10, 0.9, 1, 0.0}, PileCase{10, 0.3, 2, 0.0}, PileCase{10, 0.3, 3, 0.0},
                                           PileCase{50, 0.9, 3, 0.0}, PileCase{50, 0.3, 1, 0.0}),
                         [](const auto& test_info) {
                           return "n" + std::to_string(test_info.param.n) + "_e" +
                                  std::to_string(static_cast<int>(test_info.param.e * 10)) + "_seed" +
                                  std::to_string(test_info.param.seed) + "_mu0";
                         });

// Piles through and onto static pegs (a Galton board, a grate): the granular mode takes a
// static body within reach of a group as a fixed contact. Found by the thirteenth hunt: every
// such pile was `diverged` at its first or third group step ("body 'peg' came within reach
// of the group"), the reach check testing static bodies as if they were free ones.
INSTANTIATE_TEST_SUITE_P(PegPiles, CorePileSettles,
                         ::testing::Values(PileCase{20, 0.9, 1, 0.2, 0.0, 1}, PileCase{40, 0.3, 2, 0.0, 0.0, 1},
                                           PileCase{40, 0.9, 3, 0.5, 0.0, 2}, PileCase{30, 0.0, 5, 0.3, 0.0, 1},
                                           PileCase{50, 0.6, 4, 0.0, 0.0, 3}, PileCase{20, 0.9, 8, 0.2}),
                         [](const auto& test_info) {
                           return "n" + std::to_string(test_info.param.n) + "_e" +
                                  std::to_string(static_cast<int>(test_info.param.e * 10)) + "_seed" +
                                  std::to_string(test_info.param.seed) + "_mu" +
                                  std::to_string(static_cast<int>(test_info.param.mu * 10)) + "_pegrows" +
                                  std::to_string(test_info.param.peg_rows);
                         });

// Piles in air: linear and quadratic drag on every body, and a wind across the box (the
// granular mode takes every force at each sub-step's start). Before, a pile with drag had no
// granular mode: its collapse was an impact storm the event loop worked through, and the
// step at 0.25 s reached the event cap after 15 s of CPU (diverged).
INSTANTIATE_TEST_SUITE_P(DragPiles, CorePileSettles,
                         ::testing::Values(PileCase{30, 0.3, 1, 0.5, 0.0, 0, 0.5}, PileCase{30, 0.6, 2, 0.0, 0.0, 0, 0.2},
                                           PileCase{50, 0.3, 3, 0.2, 0.0, 0, 0.0, 0.3},
                                           PileCase{30, 0.3, 4, 0.5, 0.0, 0, 0.5, 0.0, 2.0},
                                           PileCase{30, 0.9, 5, 0.0, 0.0, 1, 0.1, 0.1, -1.0}),
                         [](const auto& test_info) {
                           const PileCase& c = test_info.param;
                           return "n" + std::to_string(c.n) + "_e" + std::to_string(static_cast<int>(c.e * 10)) +
                                  "_mu" + std::to_string(static_cast<int>(c.mu * 10)) + "_k1_" +
                                  std::to_string(static_cast<int>(c.k1 * 10)) + "_k2_" +
                                  std::to_string(static_cast<int>(c.k2 * 10)) + "_wind" +
                                  std::to_string(static_cast<int>(c.wind * 10 + 100));
                         });

// A grid of piles beside the cases above (the hand-run grid of the README's granular mode,
// thinned): 30 and 100 circles, e 0 to 0.9, frictionless to mu 1, seed 2.
std::vector<PileCase> pile_grid() {
  std::vector<PileCase> out;
  for (int n : {30, 100}) {
    for (double e : {0.0, 0.3, 0.6, 0.9}) {
      for (double mu : {0.0, 0.2, 1.0}) out.push_back(PileCase{n, e, 2, mu});
    }
  }
  return out;
}
INSTANTIATE_TEST_SUITE_P(PileGrid, CorePileSettles, ::testing::ValuesIn(pile_grid()),
                         [](const auto& test_info) {
                           return "n" + std::to_string(test_info.param.n) + "_e" +
                                  std::to_string(static_cast<int>(test_info.param.e * 10)) + "_mu" +
                                  std::to_string(static_cast<int>(test_info.param.mu * 10));
                         });

// A pile under a heavy ball (the lattice's top body 1e2 to 1e9 times heavier than the others):
// the granular mode's Gauss-Seidel converges at about the mass ratio's rate, so from some
// ratio on its solve cannot keep the light bodies apart or the energy from rising. Whatever
// happens, core must never say `ok` while wrong: a run that ends with no broken guarantee
// kept every overlap under 1e-9 m and never raised the energy (with the micro-bounce bound)
// at any step; otherwise it reported the broken guarantee (diverged).
TEST(CorePile, AHeavyBallOnAPileIsRightOrReported) {
  for (const double heavy : {1e2, 1e3, 1e4, 1e6, 1e9}) {
    SCOPED_TRACE("heavy " + std::to_string(heavy));
    Scene sc = make_circle_pile(30, 0.3, 0.5, 1);
    sc.bodies.back().mass = heavy;
    Sim sim(sc);
    const auto total = [&]() {
      double E = 0.0;
      for (std::size_t i = 0; i < sim.states.size(); ++i) {
        const double m = sim.scene.bodies[i].mass;
        E += 0.5 * m * length_squared(sim.states[i].velocity) + m * g * sim.states[i].position.y;
      }
      return E;
    };
    sim.engine.read_states(sim.states);
    const double E0 = total();
    const double v_r = g * dt / 16.0;
    const double bound = heavy * 0.5 * (0.5 * v_r) * (0.5 * v_r) * 2.0;   // the micro-bounce, heavy ball included
    double worst_overlap = 0.0, worst_rise = 0.0, E_prev = E0;
    std::string report;
    for (int k = 0; k < 600 && report.empty(); ++k) {
      sim.step(dt);
      report = sim.engine.broken_guarantee();
      sim.engine.read_states(sim.states);
      worst_overlap = std::max(worst_overlap, deepest_overlap(sim.states, sim.scene));
      const double E = total();
      worst_rise = std::max(worst_rise, E - E_prev);
      E_prev = E;
    }
    if (report.empty()) {
      EXPECT_LE(worst_overlap, 1e-9);
      EXPECT_LE(worst_rise, bound + 1e-12 * std::fabs(E0));
    }
    RecordProperty("heavy_" + std::to_string(static_cast<long long>(heavy)), report.empty() ? "ok" : report);
  }
}

// A Galton board: 60 balls (r 0.05, e 0.5, mu 0.3) dropped through 6 rows of static pegs into
// a closed box, where they pile up. The granular groups take the pegs as fixed contacts; before
// that fix every peg a group's box reached was taken for an intruder, and core's run (and its
// reference) was a broken guarantee at 0.37 s. Now: no broken guarantee, no overlap deeper than
// 1e-9 m with a peg, a ball or a wall after any step, energy never rising (with the
// micro-bounce bound), every ball at rest at 6 s.
TEST(CorePile, AGaltonBoardOfStaticPegsSettles) {
  Scene sc;
  sc.name = "galton";
  sc.world.gravity = {0.0, -g};
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> jitter(-0.02, 0.02);
  for (int row = 0; row < 6; ++row) {
    for (int col = 0; col < 8; ++col) {
      BodyDef peg = circle("peg" + std::to_string(8 * row + col),
                           {0.25 + 0.3 * col + (row % 2 ? 0.15 : 0.0), 0.6 + 0.3 * row}, {}, 0.04, 1.0, 0.5);
      peg.is_static = true;
      peg.friction = peg.static_friction = 0.3;
      sc.bodies.push_back(peg);
    }
  }
  for (int i = 0; i < 60; ++i) {
    BodyDef b = circle("b" + std::to_string(i), {0.2 + 0.2 * (i % 12) + jitter(rng), 2.6 + 0.15 * (i / 12)}, {}, 0.05,
                       1.0, 0.5);
    b.friction = b.static_friction = 0.3;
    sc.bodies.push_back(b);
  }
  const double W = 2.7, H = 3.6;
  sc.walls = {wall("floor", {0.0, 0.0}, {W, 0.0}, 0.5, 0.3), wall("right", {W, 0.0}, {W, H}, 0.5, 0.3),
              wall("lid", {W, H}, {0.0, H}, 0.5, 0.3), wall("left", {0.0, H}, {0.0, 0.0}, 0.5, 0.3)};
  Sim sim(sc);
  sim.engine.read_states(sim.states);
  double E_prev = energy(sim.states, sim.scene);
  const double v_r = g * dt / 16.0;
  const double micro_bounces = 60 * 0.5 * (0.5 * v_r) * (0.5 * v_r);
  for (int k = 0; k < 360; ++k) {
    sim.step(dt);
    ASSERT_EQ(sim.engine.broken_guarantee(), "") << "step " << k;
    sim.engine.read_states(sim.states);
    ASSERT_LE(deepest_overlap(sim.states, sim.scene), 1e-9) << "step " << k;
    const double E = energy(sim.states, sim.scene);
    ASSERT_LE(E, E_prev + 1e-12 * std::fabs(E_prev) + micro_bounces) << "step " << k;
    E_prev = E;
  }
  for (const BodyState& st : sim.states) EXPECT_EQ(st.velocity, Vec2{});
  EXPECT_TRUE(only_group_notes(sim.engine.limits_hit()));
}

// [core] dense_contact = "events" keeps core's dense phases event-driven (the option a user
// takes to see what the granular mode changes): issue 9's pile is then left to its impacts
// and never names the granular mode; with the default it settles in that mode. Until the
// twentieth round the event-driven pile reported at t = 0.37 s a leaning group its holds could
// not justify (`diverged`): a ball landing on balls resting on balls met them pair by pair.
// Now such a push goes down through the bodies under it at once (simultaneous_impacts.cpp,
// support_below), and the event-driven pile settles: at rest from 1 s, every hold justified,
// no overlap deeper than 1e-9 m, its energy never rising, over 10 s.
TEST(CorePile, DenseContactEventsLeavesThePileToItsImpacts) {
  for (const bool events : {true, false}) {
    SCOPED_TRACE(events ? "events" : "granular");
    EngineOptions opt;
    if (events) opt["dense_contact"] = std::string("events");
    Sim sim(make_circle_pile(50, 0.3, 0.5, 1), opt);
    sim.engine.read_states(sim.states);
    double E_prev = energy(sim.states, sim.scene);
    for (int k = 0; k < 600; ++k) {
      sim.step(dt);
      ASSERT_EQ(sim.engine.broken_guarantee(), "") << "step " << k;
      sim.engine.read_states(sim.states);
      ASSERT_LE(deepest_overlap(sim.states, sim.scene), 1e-9) << "step " << k;
      const double E = energy(sim.states, sim.scene);
      if (events) ASSERT_LE(E, E_prev + 1e-12 * std::fabs(E_prev)) << "step " << k;
      E_prev = E;
      if (k == 60 && events) {
        for (const BodyState& st : sim.states) EXPECT_EQ(st.velocity, Vec2{});
      }
    }
    for (const BodyState& st : sim.states) EXPECT_EQ(st.velocity, Vec2{});
    bool granular = false;
    for (const std::string& l : sim.engine.limits_hit()) granular = granular || l.rfind("granular contact", 0) == 0;
    EXPECT_EQ(granular, !events);
  }
}

// A frictionless crystal: rows of 10 and 9 circles (r 0.125, exactly representable) in a box
// exactly 10 diameters wide, each row dropped from 0.05 m above its place in the hexagonal
// packing (the bottom row on the floor, touching its neighbours and both walls). Every ball
// above the bottom row lands in a pocket, or against a wall and one ball; the packing is an
// equilibrium without friction, so the pile must end exactly there: x = r (2i + 1) (rows of
// 10) or r (2i + 2) (rows of 9), y = r + row sqrt(3) r. The scene is mirror-symmetric.
// On main (a3fdafd) the 4-row crystal never finished a step: a landing row's set (up to 76
// contacts, every ball of the crystal) did not converge in Gauss-Seidel (hyperstatic: its
// Delassus matrix is singular), and the exact solve it falls back to was refused because two
// resting balls came out at 1e-16 m/s against a tolerance of ~1e-29 m/s (1024 ulps of their
// own speeds, 0, while the projection is exact to round-off of the whole set's |u|), so the
// set ran 100,000 sweeps and met the same impact again at the same instant, for ever. The
// 3-row crystal at e 0 failed there too: 7.6e-10 m off the packing and its mirror image.
struct CrystalCase {
  int rows;
  double e;
  double bound;   // distance from the closed-form packing and from the mirror image, m
};

Scene crystal(int rows, double e) {
  constexpr double r = 0.125, gap = 0.05;
  constexpr int k = 10;
  Scene s;
  s.name = "crystal";
  s.world.gravity = {0.0, -g};
  for (int row = 0; row < rows; ++row) {
    const int cnt = row % 2 == 0 ? k : k - 1;
    for (int i = 0; i < cnt; ++i) {
      const double x = row % 2 == 0 ? r * (2 * i + 1) : r * (2 * i + 2);
      BodyDef b = circle("r" + std::to_string(row) + "_" + std::to_string(i), {x, r + row * std::sqrt(3.0) * r + row * gap},
                         {}, r, 1.0, e);
      b.friction = b.static_friction = 0.0;
      s.bodies.push_back(b);
    }
  }
  const double W = 2.0 * r * k, H = 20.0;
  s.walls = {wall("floor", {0.0, 0.0}, {W, 0.0}, e), wall("right", {W, 0.0}, {W, H}, e),
             wall("lid", {W, H}, {0.0, H}, e), wall("left", {0.0, H}, {0.0, 0.0}, e)};
  return s;
}

class CoreCrystal : public ::testing::TestWithParam<CrystalCase> {};

TEST_P(CoreCrystal, AFrictionlessCrystalSettlesIntoItsPackingSymmetrically) {
  const CrystalCase c = GetParam();
  constexpr double r = 0.125;
  constexpr int k = 10;
  Sim sim(crystal(c.rows, c.e));
  const std::size_t n = sim.scene.bodies.size();
  const double v_r = g * dt / 16.0;
  const double micro_bounces = static_cast<double>(n) * 0.5 * (0.5 * v_r) * (0.5 * v_r);
  sim.engine.read_states(sim.states);
  const double E0 = energy(sim.states, sim.scene);
  double E_prev = E0;
  std::int64_t last_events = -1;
  for (int step = 0; step < 180; ++step) {   // 3 s; every row has landed by 0.5 s
    sim.step(dt);
    ASSERT_FALSE(sim.engine.last_step_stats().event_cap_hit) << "step " << step;
    EXPECT_EQ(sim.engine.broken_guarantee(), "") << "step " << step;
    sim.engine.read_states(sim.states);
    const double E = energy(sim.states, sim.scene);
    ASSERT_LE(E, E_prev + 1e-12 * std::fabs(E_prev) + micro_bounces) << "step " << step;
    ASSERT_LE(E, E0 + 1e-12 * std::fabs(E0)) << "step " << step;
    ASSERT_LE(deepest_overlap(sim.states, sim.scene), 1e-9) << "step " << step;
    E_prev = E;
    last_events = sim.engine.last_step_stats().events;
  }
  EXPECT_EQ(last_events, 0);
  EXPECT_TRUE(sim.engine.limits_hit().empty());
  std::size_t b = 0;
  for (int row = 0; row < c.rows; ++row) {
    const int cnt = row % 2 == 0 ? k : k - 1;
    const std::size_t first = b;
    for (int i = 0; i < cnt; ++i, ++b) {
      const BodyState& s = sim.states[b];
      EXPECT_EQ(s.velocity, Vec2{}) << sim.scene.bodies[b].name;
      const Vec2 want{row % 2 == 0 ? r * (2 * i + 1) : r * (2 * i + 2), r + row * std::sqrt(3.0) * r};
      EXPECT_LE(length(s.position - want), c.bound) << sim.scene.bodies[b].name;
      const BodyState& m = sim.states[first + static_cast<std::size_t>(cnt - 1 - i)];
      EXPECT_LE(length(Vec2{s.position.x + m.position.x - 2.0 * r * k, s.position.y - m.position.y}), c.bound)
          << sim.scene.bodies[b].name << " and its mirror image";
    }
  }
}

// 3 rows (29 circles) end on the closed form and symmetric to round-off. 4 rows (38) at e 0:
// measured 6.9e-9 m off the closed form (and from the mirror image); the bound is the largest
// move core's model makes at rest, a pocket hold's v_r dt = g dt^2 / 16 (1.7e-4 m; README,
// Pockets), not round-off: the frictionless solve takes its contacts in the order they were
// found, so the mirror pairs differ by round-off that the landings grow. Not here (README,
// Frictionless piles): 4 rows at e 0.3 and 0.7 end 2.7e-6 and 7.7e-6 m off and are reported
// ("could not show to hold it": the braced judgement's solver does not converge on the
// hyperstatic crystal, a false report), 5 rows and more still spend minutes in one step
// (the exact solve's least-distance reduction picks a wrong active set there).
INSTANTIATE_TEST_SUITE_P(Crystals, CoreCrystal,
                         ::testing::Values(CrystalCase{3, 0.0, 1e-12}, CrystalCase{3, 0.3, 1e-12},
                                           CrystalCase{4, 0.0, g * dt * dt / 16.0}),
                         [](const auto& test_info) {
                           return "rows" + std::to_string(test_info.param.rows) + "_e" +
                                  std::to_string(static_cast<int>(test_info.param.e * 10));
                         });

}  // namespace physval::test
