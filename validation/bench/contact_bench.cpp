// Contact benchmarks beside the gas, every engine side by side in one run:
//   slope/<engine>/N: N circles (r 0.1) released touching a 30 degree incline, mu_s =
//   mu_k = 0.3 < tan 30, each sliding at a = g (sin 30 - 0.3 cos 30); one step of 1/60 s
//   timed over 120 steps after 1 s of sliding. Resting and sliding contact at its
//   simplest: core's supported bodies have no impacts at all here.
//   pile/<engine>/N: issue 9's pile, N circles (r 0.1, e 0.3, mu 0.5; make_circle_pile,
//   seed 1) dropped into a closed box under gravity; one iteration is the whole 10 s run
//   (600 steps of 1/60 s: the fall, the inelastic collapse, the settled pile) from load.
#include <benchmark/benchmark.h>

#include <cmath>
#include <memory>
#include <string>

#include "physval/adapters/registry.hpp"
#include "physval/core/core_engine.hpp"
#include "physval/core/scene_builders.hpp"

namespace physval::bench {

namespace {

Scene slope_scene(int n) {
  const double th = std::acos(-1.0) / 6.0, r = 0.1, mu = 0.3;
  const Vec2 d{std::cos(th), -std::sin(th)}, nrm{std::sin(th), std::cos(th)};
  Scene s;
  s.name = "slope_bench";
  s.dt = 1.0 / 60.0;
  s.world.gravity = {0.0, -9.8};
  for (int k = 0; k < n; ++k) {
    BodyDef b;
    b.name = std::to_string(k);
    b.name.insert(b.name.begin(), 'c');
    b.shape = ShapeKind::Circle;
    b.radius = r;
    b.mass = 1.0;
    b.restitution = 0.0;
    b.friction = mu;
    b.static_friction = mu;
    b.position = (0.5 * static_cast<double>(k)) * d + r * nrm;   // 0.3 m apart: never meet
    s.bodies.push_back(b);
  }
  WallDef w;
  w.name = "incline";
  w.from = -10.0 * d;
  w.to = (0.5 * n + 200.0) * d;
  w.material.restitution = 0.0;
  w.material.friction = mu;
  w.material.static_friction = mu;
  s.walls.push_back(w);
  return s;
}

void slope_benchmark(benchmark::State& state, const EngineFactory* factory) {
  const int n = static_cast<int>(state.range(0));
  Scene scene = slope_scene(n);
  std::unique_ptr<Engine> engine;
  try {
    engine = factory->create();
    engine->load(scene);
  } catch (const std::exception& e) {
    state.SkipWithError(e.what());
    for (auto _ : state) {
    }
    return;
  }
  for (int k = 0; k < 60; ++k) engine->step(scene.dt);
  for (auto _ : state) engine->step(scene.dt);
  state.counters["ns_per_body_step"] = benchmark::Counter(
      static_cast<double>(n) * 1e-9, benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
  if (const auto* core = dynamic_cast<const CoreEngine*>(engine.get())) {
    state.counters["events_per_step"] = static_cast<double>(core->last_step_stats().events);
  }
}

void pile_benchmark(benchmark::State& state, const EngineFactory* factory) {
  const int n = static_cast<int>(state.range(0));
  const Scene scene = make_circle_pile(n, 0.3, 0.5, 1);
  const int steps = static_cast<int>(std::lround(scene.duration / scene.dt));
  std::int64_t events = 0;
  for (auto _ : state) {
    std::unique_ptr<Engine> engine;
    try {
      engine = factory->create();
      engine->load(scene);
    } catch (const std::exception& e) {
      state.SkipWithError(e.what());
      break;
    }
    events = 0;
    for (int k = 0; k < steps; ++k) {
      engine->step(scene.dt);
      if (const auto* core = dynamic_cast<const CoreEngine*>(engine.get())) events += core->last_step_stats().events;
    }
  }
  state.counters["ms_per_step"] = benchmark::Counter(static_cast<double>(steps) * 1e-3,
                                                     benchmark::Counter::kIsIterationInvariantRate |
                                                         benchmark::Counter::kInvert);
  state.counters["events_per_run"] = static_cast<double>(events);
}

}  // namespace

void register_contact_benchmarks() {
  for (const EngineFactory& f : engine_registry()) {
    benchmark::RegisterBenchmark(("pile/" + f.info.name).c_str(), pile_benchmark, &f)
        ->Arg(50)
        ->Iterations(3)
        ->Unit(benchmark::kMillisecond);
  }
  for (int n : {100, 1000}) {
    for (const EngineFactory& f : engine_registry()) {
      benchmark::RegisterBenchmark(("slope/" + f.info.name).c_str(), slope_benchmark, &f)
          ->Arg(n)
          ->Iterations(120)
          ->Unit(benchmark::kMillisecond);
    }
  }
}

}  // namespace physval::bench
