// Determinism and the circle gas: the same scene gives bit-identical states, whatever
// the broad phase; a golden hash pins the final state; an elastic gas in a box keeps
// its energy and momentum, and nothing escapes or overlaps.
#include <gtest/gtest.h>

#include <cstdio>
#include <cstring>

#include "physval/core/scene_builders.hpp"
#include "scene_fixture.hpp"

namespace physval::test {

namespace {

// FNV-1a over the bytes of every position and velocity.
std::uint64_t state_hash(Sim& sim) {
  sim.engine.read_states(sim.states);
  std::uint64_t h = 1469598103934665603ull;
  auto mix = [&](double v) {
    unsigned char b[sizeof(double)];
    std::memcpy(b, &v, sizeof v);
    for (unsigned char c : b) h = (h ^ c) * 1099511628211ull;
  };
  for (const BodyState& s : sim.states) {
    mix(s.position.x);
    mix(s.position.y);
    mix(s.velocity.x);
    mix(s.velocity.y);
  }
  return h;
}

EngineOptions gas_options(const char* broadphase, const char* mode = "exact") {
  EngineOptions o = options("velocity_verlet", mode);
  o["broadphase"] = std::string(broadphase);
  return o;
}

}  // namespace

TEST(CoreDeterminism, GoldenHashAndBroadPhaseIndependence) {
  // 400 circles, 120 steps. Every broad phase reports the same pairs and the event
  // queue is totally ordered, so all four give the same bits.
  const Scene gas = make_circle_gas(400, 2024);
  std::uint64_t first = 0;
  for (const char* bp : {"all_pairs", "grid", "multigrid", "sort_and_sweep"}) {
    SCOPED_TRACE(bp);
    Sim sim(gas, gas_options(bp));
    sim.steps(120, gas.dt);
    const std::uint64_t h = state_hash(sim);
    if (first == 0) first = h;
    EXPECT_EQ(h, first);
  }
  // Recorded from this build; a change means core's results changed: say why in the
  // commit that updates it. (-ffp-contract=off keeps it the same at -O0 and -O2.)
  EXPECT_EQ(first, 0xd8f1cc86247a6b85ull) << std::hex << first;
}

TEST(CoreDeterminism, LectureModeIsRepeatable) {
  const Scene gas = make_circle_gas(300, 5);
  Sim a(gas, gas_options("grid", "lecture")), b(gas, gas_options("sort_and_sweep", "lecture"));
  a.steps(60, gas.dt);
  b.steps(60, gas.dt);
  EXPECT_EQ(state_hash(a), state_hash(b));
}

TEST(CoreGas, ElasticGasConservesEnergyAndStaysInTheBox) {
  const int n = 1000;
  const Scene gas = make_circle_gas(n, 77);
  const double side = circle_gas_box_side(n);
  Sim sim(gas);
  auto totals = [&](double& energy, Vec2& momentum) {
    sim.engine.read_states(sim.states);
    energy = 0.0;
    momentum = {};
    for (const BodyState& s : sim.states) {
      energy += 0.5 * length_squared(s.velocity);
      momentum += s.velocity;
    }
  };
  double e0;
  Vec2 p0;
  totals(e0, p0);
  std::int64_t impacts = 0;
  for (int k = 0; k < 300; ++k) {
    sim.step(gas.dt);
    impacts += sim.engine.last_step_stats().impacts;
    ASSERT_FALSE(sim.engine.last_step_stats().event_cap_hit);
  }
  double e1;
  Vec2 p1;
  totals(e1, p1);
  // Exact elastic impacts: energy to round-off over ~10^4 impacts.
  EXPECT_NEAR(e1, e0, 1e-10 * e0);
  EXPECT_GT(impacts, 1000);
  // Nothing left the box, nothing overlaps (beyond round-off).
  sim.engine.read_states(sim.states);
  for (const BodyState& s : sim.states) {
    ASSERT_GE(s.position.x, 0.05 - 1e-9);
    ASSERT_LE(s.position.x, side - 0.05 + 1e-9);
    ASSERT_GE(s.position.y, 0.05 - 1e-9);
    ASSERT_LE(s.position.y, side - 0.05 + 1e-9);
  }
  for (std::size_t i = 0; i < sim.states.size(); ++i) {
    for (std::size_t j = i + 1; j < sim.states.size(); ++j) {
      ASSERT_GE(length(sim.states[i].position - sim.states[j].position), 0.1 - 1e-9) << i << " " << j;
    }
  }
}

TEST(CoreGas, LectureModeDoesNotGainEnergy) {
  // The one-pass scheme may leave overlaps but its reflections never add energy.
  const Scene gas = make_circle_gas(1000, 3);
  Sim sim(gas, options("velocity_verlet", "lecture"));
  auto energy = [&] {
    sim.engine.read_states(sim.states);
    double e = 0.0;
    for (const BodyState& s : sim.states) e += 0.5 * length_squared(s.velocity);
    return e;
  };
  const double e0 = energy();
  sim.steps(300, gas.dt);
  EXPECT_NEAR(energy(), e0, 1e-10 * e0);
}

TEST(CoreMemory, UnderTwoHundredBytesPerBody) {
  const int n = 20000;
  Scene gas = make_circle_gas(n, 1);
  Sim sim(gas);
  sim.steps(3, gas.dt);
  const double per_body = static_cast<double>(sim.engine.memory_bytes()) / n;
  EXPECT_LT(per_body, 200.0);
  RecordProperty("bytes_per_body", std::to_string(per_body));
  std::printf("core memory: %.1f bytes per body\n", per_body);
}

}  // namespace physval::test
