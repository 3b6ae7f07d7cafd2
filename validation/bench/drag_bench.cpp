// What sub-steps cost (core/src/substeps.cpp): the circle gas of gas_bench.cpp under RK4,
// once in still air (constant forces: impacts stay on the exact parabola) and once with
// quadratic drag on every body (k2 = 0.01 N s^2/m^2: each step evaluates RK4's stages,
// and every impact ends its bodies' sub-steps, finds its time on RK4's own path and
// starts new ones). The difference per impact bounds what an impact inside a step costs
// to keep RK4's order. Registered at start-up beside the gas (no edit of gas_bench's main).
#include <benchmark/benchmark.h>

#include <cstdint>
#include <string>

#include "physval/core/core_engine.hpp"
#include "physval/core/scene_builders.hpp"

namespace {

void drag_gas(benchmark::State& state, double k2) {
  const int n = static_cast<int>(state.range(0));
  physval::Scene scene = physval::make_circle_gas(n, 1);
  for (physval::BodyDef& b : scene.bodies) b.drag_quadratic = k2;
  scene.engine_options["core"] = {{"integrator", std::string("rk4")}};
  physval::CoreEngine engine;
  engine.load(scene);
  for (int k = 0; k < 60; ++k) engine.step(scene.dt);   // past the start's transient
  std::int64_t impacts = 0;
  for (auto _ : state) {
    engine.step(scene.dt);
    impacts += engine.last_step_stats().impacts;
  }
  using benchmark::Counter;
  state.counters["ns_per_body_step"] =
      Counter(static_cast<double>(n) * 1e-9, Counter::kIsIterationInvariantRate | Counter::kInvert);
  state.counters["impacts_per_step"] = Counter(static_cast<double>(impacts), Counter::kAvgIterations);
}

const bool registered = [] {
  for (int n : {1000, 10000}) {
    const int steps = n <= 1000 ? 300 : 60;
    benchmark::RegisterBenchmark("drag_gas/core_rk4_still_air", drag_gas, 0.0)
        ->Arg(n)
        ->Iterations(steps)
        ->Unit(benchmark::kMillisecond);
    benchmark::RegisterBenchmark("drag_gas/core_rk4_drag", drag_gas, 0.01)
        ->Arg(n)
        ->Iterations(steps)
        ->Unit(benchmark::kMillisecond);
  }
  return true;
}();

}  // namespace
