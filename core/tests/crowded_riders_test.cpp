// review9: release_crowded_riders asks, at each step's start, whether another body can
// reach a rider's cap within the step. From 8 riders on it asks only the bodies near the
// corner in x (sorted once per step) instead of every body for every rider: it must give
// every rider the answer of the full scan (its own test, written out below).
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <set>
#include <vector>

#include "../src/world.hpp"
#include "scene_fixture.hpp"

namespace physval::test {
namespace {

using core_detail::World;

// The full scan's answer for rider i (cap_alone, convex_cap.cpp).
bool crowded_by_scan(const World& w, std::uint32_t i, Vec2 V, double dt) {
  const double R = 2.0 * w.radius[i] + 1e-9 * (w.radius[i] + w.length_scale);
  for (std::uint32_t j = 0; j < w.size(); ++j) {
    if (j == i || !w.alive(j)) continue;
    const double reach = R + w.radius[j] + length(w.vel[j]) * dt + 0.5 * length(w.force_acc(j)) * dt * dt;
    if (length(w.pos[j] - V) <= reach) return true;
  }
  return false;
}

TEST(CoreCapCrowd, EveryRiderGetsTheFullScansAnswer) {
  const double dt = 1.0 / 60.0;
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  int crowded_total = 0, alone_total = 0;
  for (int trial = 0; trial < 40; ++trial) {
    const double x0 = trial % 4 == 3 ? 1e6 : 0.0;   // far from the origin too
    std::vector<BodyDef> bodies;
    const int n = 60 + trial * 5;
    for (int k = 0; k < n; ++k) {
      const Vec2 p{x0 + 40.0 * u(rng), 4.0 * u(rng)};
      const double speed = u(rng) < 0.1 ? 30.0 * u(rng) : 2.0 * u(rng);
      const double a = 6.283185307179586 * u(rng);
      bodies.push_back(circle("b" + std::to_string(k), p, {speed * std::cos(a), speed * std::sin(a)}, 0.02 + 0.2 * u(rng)));
    }
    Scene sc = scene_of(bodies, {wall("floor", {x0 - 1.0, -1.0}, {x0 + 41.0, -1.0})}, {0.0, -9.8});
    World w;
    core_detail::load_world(w, sc);
    ASSERT_EQ(w.acc.size(), w.size());
    for (std::uint32_t j = 0; j < w.size(); ++j) w.acc[j] = {0.0, -9.8 * (1.0 + u(rng))};
    if (trial % 5 == 4) w.flags[3] &= ~core_detail::kAlive;   // a dead body is no company
    // 1 to 40 riders (fewer than 8: the scan itself), each with its corner 0 to 0.6 m off it.
    const int riders = 1 + trial % 40;
    std::set<std::uint32_t> chosen;
    while (static_cast<int>(chosen.size()) < riders) chosen.insert(static_cast<std::uint32_t>(u(rng) * n) % n);
    std::vector<std::pair<std::uint32_t, bool>> expect;
    for (const std::uint32_t i : chosen) {
      if (!w.alive(i)) continue;
      World::CapRide c;
      const double a = 6.283185307179586 * u(rng);
      c.V = w.pos[i] + 0.6 * u(rng) * Vec2{std::cos(a), std::sin(a)};
      w.caps[i] = c;
    }
    for (const auto& [i, c] : w.caps) expect.push_back({i, crowded_by_scan(w, i, c.V, dt)});
    core_detail::release_crowded_riders(w, 0.0, dt);
    for (const auto& [i, crowded] : expect) {
      EXPECT_EQ(w.caps.count(i) == 0, crowded) << "trial " << trial << " rider " << i;
      (crowded ? crowded_total : alone_total) += 1;
    }
  }
  // Both answers were asked for, many times.
  EXPECT_GT(crowded_total, 50);
  EXPECT_GT(alone_total, 50);
}

}  // namespace
}  // namespace physval::test
