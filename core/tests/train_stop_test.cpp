// Two balls sliding as one train until friction stops them (the hunt's grid `train`): a
// ball of friction mu_b behind one of mu_f, touching, both at v0 (e 0, no friction between
// them). Rigid Coulomb, non-rotating circles:
//   mu_b < mu_f: the back one pushes; together they decelerate at
//                a = g (m_b mu_b + m_f mu_f) / (m_b + m_f) and stop together at v0 / a;
//   mu_b >= mu_f: they part at once, each decelerated by its own mu g.
// At rest on a flat floor nothing pushes any more: both stay where they stopped.
// Found: with a frictionless back ball, the push that had decelerated it stayed in its
// acceleration after the stop, and it slid backwards at up to 3 cm/s for ever (core `ok`,
// its reference "converged").
// On a slope, launched uphill: the train stops, and then a frictionless back (downhill)
// ball slides back down at g sin(theta) from the stop while the front one, held by its
// static friction (tan(theta) <= mu_f), stays.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>
#include <utility>
#include <vector>

#include "scene_fixture.hpp"

namespace physval::test {
namespace {

constexpr double g = 9.8;

Scene train(double deg, double mub, double muf, double mb, double mf, double v0, bool front_first) {
  const double th = deg * std::numbers::pi / 180.0;
  const Vec2 t{std::cos(th), std::sin(th)}, n{-std::sin(th), std::cos(th)};   // uphill, off the slope
  const double r = 0.5;
  BodyDef back = circle("back", -0.5 * t + r * n, v0 * t, r, mb, 0.0);
  BodyDef front = circle("front", 0.5 * t + r * n, v0 * t, r, mf, 0.0);
  back.friction = back.static_friction = mub;
  front.friction = front.static_friction = muf;
  std::vector<BodyDef> b = {back, front};
  if (front_first) std::swap(b[0], b[1]);
  Scene sc = scene_of(b, {wall("floor", -60.0 * t, 60.0 * t, 0.0, 1.0)}, {0.0, -g});
  // Each ball's own friction with the floor, none between the balls.
  sc.materials.push_back(pair_friction("back", "floor", mub));
  sc.materials.push_back(pair_friction("front", "floor", muf));
  sc.materials.push_back(pair_friction("back", "front", 0.0));
  return sc;
}

// Distance along the slope from the start, and speed, of a body decelerated at a from v0
// until it stops (a > 0), at time T.
std::pair<double, double> decelerated(double v0, double a, double T) {
  const double ts = v0 / a;
  const double t = std::min(T, ts);
  return {v0 * t - 0.5 * a * t * t, T < ts ? v0 - a * T : 0.0};
}

TEST(CoreTrainStop, DISABLED_TwoBallsSlidingAsOneStopTogetherAndStay) {
  int judged = 0;
  for (const auto& [mub, muf] : std::vector<std::pair<double, double>>{{0.1, 0.5}, {0.5, 0.1}, {0.0, 0.3}, {0.3, 0.3}, {0.2, 0.6}}) {
    for (const auto& [mb, mf] : std::vector<std::pair<double, double>>{{1.0, 1.0}, {3.0, 1.0}, {1.0, 3.0}}) {
      for (double v0 : {1.0, 4.0}) {
        for (bool front_first : {false, true}) {
          const bool together = mub < muf;
          const double ab = together ? g * (mub * mb + muf * mf) / (mb + mf) : g * mub;
          const double af = together ? ab : g * muf;
          const double T = 1.2 * v0 / std::min(ab > 0.0 ? ab : 1e9, af);
          Sim sim(train(0.0, mub, muf, mb, mf, v0, front_first));
          sim.run_until(T, 1.0 / 60.0);
          const std::string where = "mu " + std::to_string(mub) + "/" + std::to_string(muf) + " m " + std::to_string(mb) +
                                    "/" + std::to_string(mf) + " v0 " + std::to_string(v0) + (front_first ? " front first" : "");
          const auto [sb, vb] = ab > 0.0 ? decelerated(v0, ab, T) : std::pair<double, double>{v0 * T, v0};
          const auto [sf, vf] = decelerated(v0, af, T);
          EXPECT_EQ(sim.engine.broken_guarantee(), "") << where;
          EXPECT_NEAR(sim.state("back").position.x, -0.5 + sb, 1e-9) << where;
          EXPECT_NEAR(sim.state("back").velocity.x, vb, 1e-9) << where;
          EXPECT_NEAR(sim.state("front").position.x, 0.5 + sf, 1e-9) << where;
          EXPECT_NEAR(sim.state("front").velocity.x, vf, 1e-9) << where;
          ++judged;
        }
      }
    }
  }
  EXPECT_EQ(judged, 60);
}

TEST(CoreTrainStop, DISABLED_UphillTheFrictionlessBackBallSlidesBackFromTheStop) {
  for (double deg : {5.0, 15.0}) {
    for (double v0 : {1.0, 3.0}) {
      for (bool front_first : {false, true}) {
        const double th = deg * std::numbers::pi / 180.0;
        const double muf = 0.6, mb = 1.0, mf = 1.0;
        ASSERT_LE(std::tan(th), muf);
        // Together uphill: a = g sin + g cos (mb * 0 + mf muf) / (mb + mf).
        const double a = g * std::sin(th) + g * std::cos(th) * (mf * muf) / (mb + mf);
        const double ts = v0 / a, s_stop = 0.5 * v0 * ts;
        const double T = ts + 0.5;
        Sim sim(train(deg, 0.0, muf, mb, mf, v0, front_first));
        sim.run_until(T, 1.0 / 60.0);
        const std::string where = std::to_string(deg) + " deg, v0 " + std::to_string(v0) + (front_first ? " front first" : "");
        const Vec2 t{std::cos(th), std::sin(th)}, n{-std::sin(th), std::cos(th)};
        const double back_down = 0.5 * g * std::sin(th) * (T - ts) * (T - ts);
        const Vec2 front = (0.5 + s_stop) * t + 0.5 * n, back = (-0.5 + s_stop - back_down) * t + 0.5 * n;
        EXPECT_EQ(sim.engine.broken_guarantee(), "") << where;
        EXPECT_NEAR(length(sim.state("front").position - front), 0.0, 1e-9) << where;
        EXPECT_NEAR(length(sim.state("front").velocity), 0.0, 1e-9) << where;
        EXPECT_NEAR(length(sim.state("back").position - back), 0.0, 1e-9) << where;
        EXPECT_NEAR(length(sim.state("back").velocity - (-g * std::sin(th) * (T - ts)) * t), 0.0, 1e-9) << where;
      }
    }
  }
}

}  // namespace
}  // namespace physval::test
