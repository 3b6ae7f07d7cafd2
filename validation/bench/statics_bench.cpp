// What core's per-step statics work costs in scenes with segments (review9):
// - statics/gas_in_walls: the circle gas of gas_bench.cpp (four walls) in a field
//   (gravity -9.8), so that every free body is asked each step whether it rests on a face
//   (detect_support) and whether it sits on a convex corner (settle_on_cap).
// - statics/washboard: n balls rolling at 1 m/s over a floor of 2n segments with a convex
//   corner every metre (peaks 2 cm high), one ball per metre: every ball rides a corner's
//   cap about once a second, and each rider is checked for company every step (cap_alone).
// Registered at start-up beside the gas (no edit of gas_bench's main).
#include <benchmark/benchmark.h>

#include <cstdint>
#include <string>

#include "physval/core/core_engine.hpp"
#include "physval/core/scene_builders.hpp"

namespace {

void gas_in_walls(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  physval::Scene scene = physval::make_circle_gas(n, 1);
  scene.world.gravity = {0.0, -9.8};
  physval::CoreEngine engine;
  engine.load(scene);
  for (int k = 0; k < 30; ++k) engine.step(scene.dt);
  for (auto _ : state) engine.step(scene.dt);
  state.counters["ns_per_body_step"] = benchmark::Counter(
      static_cast<double>(n) * 1e-9, benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}

physval::Scene washboard(int n) {
  physval::Scene s;
  s.name = "washboard_" + std::to_string(n);
  s.dt = 1.0 / 60.0;
  s.duration = 10.0;
  s.world.gravity = {0.0, -9.8};
  const int m = n + 2;
  for (int k = 0; k < m; ++k) {
    physval::WallDef up, down;
    up.name = "u" + std::to_string(k);
    up.from = {k * 1.0, 0.0};
    up.to = {k * 1.0 + 0.5, 0.02};
    down.name = "d" + std::to_string(k);
    down.from = up.to;
    down.to = {k * 1.0 + 1.0, 0.0};
    s.walls.push_back(up);
    s.walls.push_back(down);
  }
  for (int b = 0; b < n; ++b) {
    physval::BodyDef body;
    body.name = "b" + std::to_string(b);
    body.radius = 0.1;
    body.mass = 1.0;
    body.restitution = 0.5;
    body.position = {1.25 + b, 0.1101};
    body.velocity = {1.0, 0.0};
    s.bodies.push_back(body);
  }
  return s;
}

void washboard_riders(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  physval::Scene scene = washboard(n);
  physval::CoreEngine engine;
  engine.load(scene);
  for (int k = 0; k < 30; ++k) engine.step(scene.dt);
  for (auto _ : state) engine.step(scene.dt);
  state.counters["ns_per_body_step"] = benchmark::Counter(
      static_cast<double>(n) * 1e-9, benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}

const bool registered = [] {
  for (int n : {1000, 10000}) {
    benchmark::RegisterBenchmark("statics/gas_in_walls", gas_in_walls)->Arg(n)->Iterations(n <= 1000 ? 120 : 30)->Unit(benchmark::kMillisecond);
  }
  for (int n : {300, 1000, 3000}) {
    benchmark::RegisterBenchmark("statics/washboard", washboard_riders)->Arg(n)->Iterations(120)->Unit(benchmark::kMillisecond);
  }
  return true;
}();

}  // namespace
