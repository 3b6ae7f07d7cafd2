// A ball striking a train of two or three touching balls on a floor (e 0 between the
// balls, none between them and friction only with the floor): the whole touching chain
// takes the impact at once (join_train). Rigid Coulomb, non-rotating circles, closed form:
//   before: the striker decelerates at mu_s g; the train (its frictions non-decreasing
//           towards the front, so its back members press the front ones) as one block at
//           g sum(m mu) / sum(m) (or at rest);
//   the catch-up time t1 by bisection on the two paths;
//   at t1: one velocity v = (m_s v_s + M v_train) / (m_s + M) (perfectly inelastic, the
//          train touching: momentum passes through it);
//   after: the balls pooled from the rear at v (a block behind that would decelerate less
//          than the block in front presses it and joins it), each block decelerating at
//          its own g sum(m mu) / sum(m) to its stop; blocks part (the one behind decelerates
//          more), nothing meets again; at rest on a flat floor nothing pushes.
// Judged: every ball's position and velocity to 1e-9 at 1.2 x the last stop, no event
// cap, at most 2 events a step after the impact (a train, not micro-bounces), no broken
// guarantee. Found: not joined (main before), the balls micro-bounced against one another
// (hundreds to 1,000,300 events a step, the event cap) and ended up to 0.61 m off (148 of
// the first 236 two-ball floor scenes); joined pair by pair (the striker with the ball it
// hits; tried and reverted), each join changed the middle ball's path and they met one
// another at one instant until the event cap.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <string>
#include <utility>
#include <vector>

#include "scene_fixture.hpp"

namespace physval::test {
namespace {

constexpr double g = 9.8;

// Distance and speed after time t of a body at v0 >= 0 decelerated at a (a > 0: to its
// stop, then held; a <= 0: speeding up).
double dist_of(double v0, double a, double t) {
  if (a <= 0.0) return v0 * t - 0.5 * a * t * t;
  const double u = std::min(t, v0 / a);
  return v0 * u - 0.5 * a * u * u;
}
double speed_of(double v0, double a, double t) { return a <= 0.0 ? v0 - a * t : std::max(0.0, v0 - a * t); }

// Down a slope of `deg` degrees (0: a floor); its sine and cosine.
struct Slope {
  double sin, cos;
};

struct Block {
  std::size_t b, e;
  double M, Mmu;
  Slope sl;
  double a() const { return g * (Mmu / M * sl.cos - sl.sin); }   // deceleration along the way
};

// Rigid Coulomb pooling of balls sorted from the rear (all sliding forward at one speed).
std::vector<Block> pool(const std::vector<double>& m, const std::vector<double>& mu, Slope sl) {
  std::vector<Block> out;
  for (std::size_t x = 0; x < m.size(); ++x) {
    out.push_back({x, x + 1, m[x], m[x] * mu[x], sl});
    while (out.size() > 1 && out[out.size() - 2].a() <= out.back().a() + 1e-12) {
      const Block f = out.back();
      out.pop_back();
      out.back() = {out.back().b, f.e, out.back().M + f.M, out.back().Mmu + f.Mmu, sl};
    }
  }
  return out;
}

struct Case {
  std::vector<double> m, mu;   // striker first, then the train from its back to its front
  double vs, vt;               // the striker's and the train's speeds at the start
  bool reversed;               // bodies listed front first
  double deg = 0.0;            // down a slope of so many degrees
  bool mirrored = false;       // on a floor, towards -x
};

std::string describe(const Case& c) {
  std::string s = "m";
  for (double x : c.m) s += " " + std::to_string(x);
  s += " mu";
  for (double x : c.mu) s += " " + std::to_string(x);
  return s + " vs " + std::to_string(c.vs) + " vt " + std::to_string(c.vt) + (c.reversed ? " reversed" : "") + " " +
         std::to_string(c.deg) + " deg" + (c.mirrored ? " mirrored" : "");
}

// Runs one case; false if it is not one (the train parts before, or is never caught).
bool judge(const Case& c) {
  const std::size_t k = c.m.size() - 1;   // train members
  const double r = 0.5, gap = 0.3;
  const double th = c.deg * std::numbers::pi / 180.0;
  const Slope sl{std::sin(th), std::cos(th)};
  const Vec2 dn = c.mirrored ? Vec2{-1.0, 0.0} : Vec2{std::cos(th), -std::sin(th)};   // down the slope
  const Vec2 up{std::sin(th), std::cos(th)};                                           // off it
  std::vector<double> tm(c.m.begin() + 1, c.m.end()), tmu(c.mu.begin() + 1, c.mu.end());
  const std::vector<Block> train = pool(tm, tmu, sl);
  if (train.size() != 1) return false;   // the train parts at once
  const double at = train[0].a();
  if (c.vt == 0.0 && at < 0.0) return false;   // not at rest: it slides off at once
  const double as = pool({c.m[0]}, {c.mu[0]}, sl)[0].a();
  const double xs0 = -2.0 * r - gap, xt0 = 0.0;   // the striker's and the train's back ball's centres
  const auto gap_at = [&](double t) { return (xt0 + dist_of(c.vt, at, t)) - (xs0 + dist_of(c.vs, as, t)) - 2.0 * r; };
  double lo = 0.0, hi = 20.0;
  if (gap_at(hi) > 0.0) return false;   // never caught
  for (int it = 0; it < 200; ++it) {
    const double mid = 0.5 * (lo + hi);
    (gap_at(mid) > 0.0 ? lo : hi) = mid;
  }
  const double t1 = hi;
  const double vs1 = speed_of(c.vs, as, t1), vt1 = speed_of(c.vt, at, t1);
  if (vs1 - vt1 < 0.05) return false;   // a crawl: below any rest speed, not this case
  double M = 0.0, P = c.m[0] * vs1;
  for (double x : c.m) M += x;
  P += (M - c.m[0]) * vt1;
  const double v = P / M;
  const std::vector<Block> blocks = pool(c.m, c.mu, sl);
  double last_stop = 0.0;
  for (const Block& b : blocks) {
    if (b.a() > 0.0) last_stop = std::max(last_stop, v / b.a());
  }
  const double T = t1 + 1.2 * last_stop + 0.1;
  if (xs0 + dist_of(c.vs, as, T) > 50.0 || xt0 + dist_of(c.vt, at, T) > 50.0) return false;   // off the slope
  const double xb1 = xt0 + dist_of(c.vt, at, t1) - 2.0 * r;   // the striker's centre at t1

  std::vector<BodyDef> bodies;
  for (std::size_t x = 0; x <= k; ++x) {
    const std::string name = "b" + std::to_string(x);
    const double x0 = x == 0 ? xs0 : xt0 + 2.0 * r * static_cast<double>(x - 1);
    BodyDef b = circle(name, x0 * dn + r * up, (x == 0 ? c.vs : c.vt) * dn, r, c.m[x], 0.0);
    b.friction = b.static_friction = c.mu[x];
    bodies.push_back(b);
  }
  if (c.reversed) std::reverse(bodies.begin(), bodies.end());
  Scene sc = scene_of(bodies, {wall("floor", -60.0 * dn, 60.0 * dn, 0.0, 1.0)}, {0.0, -g});
  for (std::size_t x = 0; x <= k; ++x) {
    sc.materials.push_back(pair_friction("b" + std::to_string(x), "floor", c.mu[x]));
    for (std::size_t y = x + 1; y <= k; ++y) sc.materials.push_back(pair_friction("b" + std::to_string(x), "b" + std::to_string(y), 0.0));
  }
  Sim sim(sc);
  std::int64_t worst = 0;
  bool capped = false;
  while (sim.engine.time() < T - 1e-12) {
    sim.step(std::min(1.0 / 60.0, T - sim.engine.time()));
    capped |= sim.engine.last_step_stats().event_cap_hit;
    if (sim.engine.time() > t1 + 2.0 / 60.0) worst = std::max(worst, sim.engine.last_step_stats().events);
  }
  const std::string where = describe(c);
  EXPECT_FALSE(capped) << where;
  EXPECT_LE(worst, 2) << where;
  EXPECT_EQ(sim.engine.broken_guarantee(), "") << where;
  for (const Block& b : blocks) {
    for (std::size_t x = b.b; x < b.e; ++x) {
      const std::string name = "b" + std::to_string(x);
      const double x1 = xb1 + 2.0 * r * static_cast<double>(x);
      const Vec2 p = (x1 + dist_of(v, b.a(), T - t1)) * dn + r * up, u = speed_of(v, b.a(), T - t1) * dn;
      EXPECT_NEAR(length(sim.state(name).position - p), 0.0, 1e-9) << where << " " << name;
      EXPECT_NEAR(length(sim.state(name).velocity - u), 0.0, 1e-9) << where << " " << name;
    }
  }
  return true;
}

// Frictions: the striker's, then the train's from its back (non-decreasing towards its
// front, or pooled into one block anyway).
const std::vector<std::vector<double>> kFrictions2 = {
    {0.1, 0.3, 0.5}, {0.0, 0.2, 0.4}, {0.5, 0.2, 0.4}, {0.3, 0.3, 0.3}, {0.2, 0.1, 0.6}, {0.6, 0.4, 0.4}, {0.25, 0.5, 0.1}};
const std::vector<std::vector<double>> kFrictions3 = {{0.1, 0.3, 0.4, 0.5}, {0.0, 0.2, 0.2, 0.4}, {0.5, 0.1, 0.2, 0.3},
                                                      {0.3, 0.3, 0.3, 0.3}, {0.2, 0.4, 0.1, 0.6}, {0.6, 0.2, 0.4, 0.4}};

TEST(CoreTrainJoin, ABallStruckIntoTwoTouchingBallsMovesOnAsTheClosedFormSays) {
  int judged = 0;
  for (const auto& mu : kFrictions2) {
    for (const auto& m : std::vector<std::vector<double>>{{1.0, 1.0, 1.0}, {3.0, 1.0, 1.0}, {1.0, 3.0, 0.5}, {0.2, 1.0, 5.0}, {10.0, 0.1, 1.0}}) {
      for (const auto& [vs, vt] : std::vector<std::pair<double, double>>{{2.0, 0.5}, {5.0, 0.5}, {3.0, 0.0}, {6.0, 2.0}}) {
        for (bool reversed : {false, true}) judged += judge({m, mu, vs, vt, reversed}) ? 1 : 0;
        judged += judge({m, mu, vs, vt, false, 0.0, true}) ? 1 : 0;
      }
    }
  }
  EXPECT_EQ(judged, 354);
}

TEST(CoreTrainJoin, ABallStruckIntoThreeTouchingBallsMovesOnAsTheClosedFormSays) {
  int judged = 0;
  for (const auto& mu : kFrictions3) {
    for (const auto& m : std::vector<std::vector<double>>{{1.0, 1.0, 1.0, 1.0}, {3.0, 1.0, 2.0, 1.0}, {0.5, 2.0, 1.0, 4.0}, {10.0, 0.1, 1.0, 0.3}}) {
      for (const auto& [vs, vt] : std::vector<std::pair<double, double>>{{2.0, 0.5}, {5.0, 0.5}, {3.0, 0.0}, {6.0, 2.0}}) {
        for (bool reversed : {false, true}) judged += judge({m, mu, vs, vt, reversed}) ? 1 : 0;
        judged += judge({m, mu, vs, vt, false, 0.0, true}) ? 1 : 0;
      }
    }
  }
  EXPECT_EQ(judged, 246);
}

TEST(CoreTrainJoin, DownASlopeABallStruckIntoTwoOrThreeTouchingBallsMovesOnAsTheClosedFormSays) {
  int judged = 0;
  for (double deg : {5.0, 10.0, 20.0}) {
    for (const auto& mu : kFrictions2) {
      for (const auto& m : std::vector<std::vector<double>>{{1.0, 1.0, 1.0}, {3.0, 1.0, 1.0}, {0.2, 1.0, 5.0}}) {
        for (const auto& [vs, vt] : std::vector<std::pair<double, double>>{{3.0, 0.5}, {3.0, 0.0}}) {
          for (bool reversed : {false, true}) judged += judge({m, mu, vs, vt, reversed, deg}) ? 1 : 0;
        }
      }
    }
    for (const auto& mu : kFrictions3) {
      for (const auto& m : std::vector<std::vector<double>>{{1.0, 1.0, 1.0, 1.0}, {0.5, 2.0, 1.0, 4.0}}) {
        for (const auto& [vs, vt] : std::vector<std::pair<double, double>>{{3.0, 0.5}, {3.0, 0.0}}) {
          for (bool reversed : {false, true}) judged += judge({m, mu, vs, vt, reversed, deg}) ? 1 : 0;
        }
      }
    }
  }
  EXPECT_EQ(judged, 298);
}

// Rows of 3 to 7 balls on a floor (touching or 5 cm to 1 m apart, speeds -4..4 m/s, masses
// 0.5 to 5, frictions 0 to 0.6 with the floor, e 0 between the balls, half of the rows
// against a wall): trains form, are struck, part and stop. An exact event-driven answer
// does not depend on the step: every ball at 3 s the same to 1e-9 at dt 1/60, 1/97 and
// 1/240, no event cap, no broken guarantee. Found: without whole-chain joining (main
// before) 19 of these 24 rows depended on the step, by up to 3e-3 m (micro-bounces); in
// similar rows through `physval run` the reference's convergence error was up to 4.7e-4 m
// and one row ran for over a minute.
TEST(CoreTrainJoin, RowsOfBallsOnAFloorDoNotDependOnTheStep) {
  std::uint64_t state = 12345;
  const auto next = [&]() {   // a portable generator: the same rows everywhere
    state = state * 6364136223846793005ULL + 1442695040888963407ULL;
    return static_cast<double>(state >> 11) * 0x1.0p-53;
  };
  const auto pick = [&](std::vector<double> xs) { return xs[std::min(xs.size() - 1, static_cast<std::size_t>(next() * static_cast<double>(xs.size())))]; };
  for (int k = 0; k < 24; ++k) {
    const int n = 3 + static_cast<int>(next() * 5);
    std::vector<BodyDef> bodies;
    double x = 0.0;
    for (int i = 0; i < n; ++i) {
      BodyDef b = circle("b" + std::to_string(i), {x, 0.5}, {-4.0 + 8.0 * next(), 0.0}, 0.5, pick({0.5, 1.0, 2.0, 5.0}), 0.0);
      bodies.push_back(b);
      x += 1.0 + (next() < 0.5 ? 0.0 : 0.05 + 0.95 * next());
    }
    std::vector<WallDef> walls = {wall("floor", {-30.0, 0.0}, {40.0, 0.0}, 0.0, 0.0)};
    if (k % 2) walls.push_back(wall("wall", {-3.0, 0.0}, {-3.0, 3.0}, 0.0, 0.0));
    Scene sc = scene_of(bodies, walls, {0.0, -g});
    for (int i = 0; i < n; ++i) sc.materials.push_back(pair_friction("b" + std::to_string(i), "floor", pick({0.0, 0.1, 0.3, 0.6})));
    std::vector<std::vector<BodyState>> finals;
    for (double dt : {1.0 / 60.0, 1.0 / 97.0, 1.0 / 240.0}) {
      Sim sim(sc);
      bool capped = false;
      while (sim.engine.time() < 3.0 - 1e-12) {
        sim.step(std::min(dt, 3.0 - sim.engine.time()));
        capped |= sim.engine.last_step_stats().event_cap_hit;
      }
      EXPECT_FALSE(capped) << "row " << k << " dt " << dt;
      EXPECT_EQ(sim.engine.broken_guarantee(), "") << "row " << k << " dt " << dt;
      std::vector<BodyState> f;
      for (int i = 0; i < n; ++i) f.push_back(sim.state("b" + std::to_string(i)));
      finals.push_back(f);
    }
    for (std::size_t d = 1; d < finals.size(); ++d) {
      for (int i = 0; i < n; ++i) {
        EXPECT_NEAR(length(finals[d][i].position - finals[0][i].position), 0.0, 1e-9) << "row " << k << " ball " << i;
        EXPECT_NEAR(length(finals[d][i].velocity - finals[0][i].velocity), 0.0, 1e-9) << "row " << k << " ball " << i;
      }
    }
  }
}

// Elastic (e 1 between the balls and with the floor's normal, equal masses, one friction):
// far above the rest speed, so no train is joined. With `impact_law = "sequential"` the
// impact passes along the touching balls as a row of exchanges (Newton's cradle): the
// front ball leaves at the striker's speed, the striker and the middle one go on at the
// train's speed (together, alike), each decelerating at mu g to its stop. With the default
// law (Newton's law at every contact at once) the striker meets the touching pair at once,
// as on a frictionless floor: u = vs1 - vt1 closing, the striker leaves at vt1 - u / 3 and
// the pair at vt1 + 2 u / 3 (momentum and energy kept), each then decelerating at mu g to its
// stop (the striker backwards when u > 3 vt1). The floor's friction takes no part in the
// impact: its impulse is at most mu times the floor's normal impulse, which a horizontal
// impact does not make. (Until branch rowwall the default law gave the exchanges here,
// because a ball on a face with friction took part in a touching set with its faces only:
// the answer depended on whether the floor had friction.)
TEST(CoreTrainJoin, AnElasticStrikeOnATouchingPairMeetsEachImpactLawsClosedForm) {
  int judged = 0;
  for (double mu : {0.1, 0.3}) {
    for (const auto& [vs, vt] : std::vector<std::pair<double, double>>{{2.0, 0.5}, {5.0, 0.5}, {3.0, 0.0}, {6.0, 2.0}}) {
      for (bool reversed : {false, true}) {
       for (bool sequential : {true, false}) {
        const double r = 0.5, gap = 0.3, a = g * mu;
        const double xs0 = -2.0 * r - gap;
        const auto gap_at = [&](double t) { return dist_of(vt, a, t) - (xs0 + dist_of(vs, a, t)) - 2.0 * r; };
        double lo = 0.0, hi = 20.0;
        ASSERT_LT(gap_at(hi), 0.0);
        for (int it = 0; it < 200; ++it) {
          const double mid = 0.5 * (lo + hi);
          (gap_at(mid) > 0.0 ? lo : hi) = mid;
        }
        const double t1 = hi, vs1 = speed_of(vs, a, t1), vt1 = speed_of(vt, a, t1);
        const double xb1 = dist_of(vt, a, t1) - 2.0 * r;
        const double T = t1 + 1.2 * vs1 / a;
        std::vector<BodyDef> bodies;
        for (int x = 0; x <= 2; ++x) {
          BodyDef b = circle("b" + std::to_string(x), {x == 0 ? xs0 : 2.0 * r * (x - 1), r}, {x == 0 ? vs : vt, 0.0}, r, 1.0, 1.0);
          b.friction = b.static_friction = mu;
          bodies.push_back(b);
        }
        if (reversed) std::reverse(bodies.begin(), bodies.end());
        Scene sc = scene_of(bodies, {wall("floor", {-60.0, 0.0}, {60.0, 0.0}, 0.0, mu)}, {0.0, -g});
        for (int x = 0; x <= 2; ++x) {
          for (int y = x + 1; y <= 2; ++y) sc.materials.push_back(pair_friction("b" + std::to_string(x), "b" + std::to_string(y), 0.0));
        }
        EngineOptions opts;
        if (sequential) opts["impact_law"] = std::string("sequential");
        Sim sim(sc, opts);
        sim.run_until(T, 1.0 / 60.0);
        const std::string where = "mu " + std::to_string(mu) + " vs " + std::to_string(vs) + " vt " + std::to_string(vt) +
                                  (reversed ? " reversed" : "") + (sequential ? " sequential" : " simultaneous");
        EXPECT_EQ(sim.engine.broken_guarantee(), "") << where;
        const double u = vs1 - vt1;
        for (int x = 0; x <= 2; ++x) {
          const std::string name = "b" + std::to_string(x);
          const double v = sequential ? (x == 2 ? vs1 : vt1) : (x == 0 ? vt1 - u / 3.0 : vt1 + 2.0 * u / 3.0);
          const double sign = v < 0.0 ? -1.0 : 1.0;   // friction decelerates either way to a stop
          EXPECT_NEAR(sim.state(name).position.x, xb1 + 2.0 * r * x + sign * dist_of(sign * v, a, T - t1), 1e-9) << where << " " << name;
          EXPECT_NEAR(sim.state(name).velocity.x, sign * speed_of(sign * v, a, T - t1), 1e-9) << where << " " << name;
        }
        ++judged;
       }
      }
    }
  }
  EXPECT_EQ(judged, 32);
}

}  // namespace
}  // namespace physval::test
