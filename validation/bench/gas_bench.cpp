// The circle gas of issue 3 (radius 0.05, 30% packing, walled box, elastic, no
// gravity, dt 1/60) through every engine of the registry, side by side in one run:
// core in exact and in lecture mode at N = 1k, 10k, 100k, 1M, and each other engine
// up to the N it can step in reasonable time (Box2D and Bullet: 10k).
//
// Counters: ns_per_body_step (wall time / (steps * N)), collisions_per_step (contact
// begin events the engine reported, averaged over the timed steps), bytes_per_body
// (core only: everything the engine holds). Each engine runs a fixed number of steps
// after the same warm-up, so all see the gas over the same stretch of simulated time.
// Times are CPU time of the benchmark thread (the machine is shared).
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cstdint>
#include <cstdlib>
#include <map>
#include <memory>
#include <string>

#include "physval/adapters/registry.hpp"
#include "physval/core/core_engine.hpp"
#include "physval/core/scene_builders.hpp"

namespace {

using physval::EngineFactory;
using physval::EngineOptions;

// Each engine is measured in the gas's steady state: after 5 s of simulated time
// (300 steps) up to N = 10k. Box2D slows over its first few hundred steps (contacts
// churn, memory scatters: shared/engines.md); the first steps would flatter it. At
// 100k and 1M only core runs, and 10 warm-up steps keep the run short.
// PHYSVAL_GAS_WARMUP=k overrides the count for every N (a steady-state check at 1M).
int warmup_steps(int n) {
  if (const char* env = std::getenv("PHYSVAL_GAS_WARMUP")) return std::max(0, std::atoi(env));
  return n <= 10000 ? 300 : 10;
}

int timed_steps(int n) {
  if (n <= 1000) return 300;
  if (n <= 10000) return 60;
  if (n <= 100000) return 20;
  return 6;
}

void gas_benchmark(benchmark::State& state, const EngineFactory* factory, EngineOptions options) {
  const int n = static_cast<int>(state.range(0));
  physval::Scene scene = physval::make_circle_gas(n, 1);
  if (!options.empty()) scene.engine_options[factory->info.name] = options;
  std::unique_ptr<physval::Engine> engine;
  try {
    engine = factory->create();
    engine->load(scene);
  } catch (const std::exception& e) {
    state.SkipWithError(e.what());
    for (auto _ : state) {
    }
    return;
  }
  for (int k = 0; k < warmup_steps(n); ++k) engine->step(scene.dt);
  std::int64_t contacts = 0;
  for (auto _ : state) {
    engine->step(scene.dt);
    contacts += static_cast<std::int64_t>(engine->contacts().size());
  }
  using benchmark::Counter;
  state.counters["ns_per_body_step"] =
      Counter(static_cast<double>(n) * 1e-9, Counter::kIsIterationInvariantRate | Counter::kInvert);
  state.counters["collisions_per_step"] = Counter(static_cast<double>(contacts), Counter::kAvgIterations);
  if (const auto* core = dynamic_cast<const physval::CoreEngine*>(engine.get())) {
    state.counters["bytes_per_body"] = static_cast<double>(core->memory_bytes()) / n;
    state.counters["event_cap_hit"] = core->last_step_stats().event_cap_hit ? 1.0 : 0.0;
  }
}

void register_one(const std::string& name, const EngineFactory* f, const EngineOptions& opt, int n) {
  benchmark::RegisterBenchmark(name.c_str(), gas_benchmark, f, opt)
      ->Arg(n)
      ->Iterations(timed_steps(n))
      ->Unit(benchmark::kMillisecond);
}

void register_all() {
  const int sizes[] = {1000, 10000, 100000, 1000000};
  for (int n : sizes) {
    for (const EngineFactory& f : physval::engine_registry()) {
      if (f.info.name == "core") {
        for (const char* mode : {"exact", "lecture"}) {
          register_one("gas/core_" + std::string(mode), &f, {{"collision", std::string(mode)}}, n);
        }
      } else if (n <= 10000) {
        // Box2D takes over 1 s per step and Bullet about 0.5 s at 100k: stop at 10k.
        register_one("gas/" + f.info.name, &f, {}, n);
      }
    }
  }
}

}  // namespace

namespace physval::bench {
void register_contact_benchmarks();   // contact_bench.cpp
}

int main(int argc, char** argv) {
  register_all();
  physval::bench::register_contact_benchmarks();
  // Fixed step counts per N (see timed_steps), one repetition: the report is one run.
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
