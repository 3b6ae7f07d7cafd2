// Google Benchmark: the comparator on a contact-heavy pair of runs (a gas of circles
// with `range(0)` contact events per run, bodies and samples of a 1k-body scene).
#include <benchmark/benchmark.h>

#include <unistd.h>

#include <charconv>
#include <cmath>
#include <filesystem>
#include <random>

#include "physval/validation/comparator.hpp"
#include "physval/validation/results_json.hpp"
#include "physval/validation/runner.hpp"
#include "physval/validation/scenario_loader.hpp"
#include "physval/adapters/registry.hpp"
#include "../src/containment.hpp"
#include "../src/number_text.hpp"

namespace physval {
namespace {

RunRecord gas_run(const std::string& engine, std::size_t bodies, std::size_t contacts, std::size_t samples,
                  unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_int_distribution<std::size_t> body(0, bodies - 1);
  std::normal_distribution<double> jitter(0.0, 0.002);
  RunRecord r;
  r.engine = engine;
  r.dt = 1.0 / 240.0;
  r.status = RunStatus::Ok;
  const double duration = 4.0;
  for (std::size_t k = 0; k < contacts; ++k) {
    const std::size_t a = body(rng);
    const std::size_t b = (a + 1 + body(rng) % (bodies - 1)) % bodies;
    const double t = duration * static_cast<double>(k) / static_cast<double>(contacts) + jitter(rng);
    r.contacts.push_back({std::string(1, 'c').append(std::to_string(a)), std::string(1, 'c').append(std::to_string(b)), t, static_cast<long>(t / r.dt)});
  }
  for (std::size_t s = 0; s < samples; ++s) {
    r.series.time.push_back(duration * static_cast<double>(s) / static_cast<double>(samples - 1));
    Totals t;
    t.kinetic = 1.0;
    r.series.totals.push_back(t);
    std::vector<BodyState> states(bodies);
    for (std::size_t i = 0; i < bodies; ++i) states[i].position = {static_cast<double>(i), static_cast<double>(s)};
    r.series.states.push_back(std::move(states));
  }
  return r;
}

void BM_ComparePairContactHeavy(benchmark::State& state) {
  const auto contacts = static_cast<std::size_t>(state.range(0));
  const std::size_t bodies = 1000, samples = 100;
  Scene scene;
  scene.name = "gas";
  scene.dt = 1.0 / 240.0;
  scene.duration = 4.0;
  const RunRecord a = gas_run("a", bodies, contacts, samples, 1);
  const RunRecord b = gas_run("b", bodies, contacts, samples, 1);   // same pairs, same times
  for (auto _ : state) {
    PairComparison pc = compare_pair(a, b, scene);
    benchmark::DoNotOptimize(pc);
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(contacts));
}
BENCHMARK(BM_ComparePairContactHeavy)->Arg(1000)->Arg(10000)->Arg(40000)->Unit(benchmark::kMillisecond);

// pi_billiard_1e8's kind of contact list: two balls and a wall, the contacts alternating
// between the two pairs (31k per run there), each name a short string.
void BM_ComparePairTwoPairsAlternating(benchmark::State& state) {
  const auto contacts = static_cast<std::size_t>(state.range(0));
  Scene scene;
  scene.name = "billiard";
  scene.dt = 1.0 / 240.0;
  scene.duration = 4.0;
  RunRecord a = gas_run("a", 2, 0, 100, 1);
  for (std::size_t k = 0; k < contacts; ++k) {
    const double t = scene.duration * static_cast<double>(k) / static_cast<double>(contacts);
    a.contacts.push_back({"light", k % 2 == 0 ? "heavy" : "wall", t, static_cast<long>(t / scene.dt)});
  }
  RunRecord b = a;
  b.engine = "b";
  for (auto _ : state) {
    PairComparison pc = compare_pair(a, b, scene);
    benchmark::DoNotOptimize(pc);
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(contacts));
}
BENCHMARK(BM_ComparePairTwoPairsAlternating)->Arg(31416)->Unit(benchmark::kMillisecond);

// What run_suite does for one contact-heavy scene of five engines: each run against the
// reference, then the ten pairs, through one ScenarioComparer (the contacts' pair ids and
// the scales computed once per run).
void BM_ScenarioComparisonsContactHeavy(benchmark::State& state) {
  const auto contacts = static_cast<std::size_t>(state.range(0));
  const std::size_t bodies = 1000, samples = 100;
  Scene scene;
  scene.name = "gas";
  scene.dt = 1.0 / 240.0;
  scene.duration = 4.0;
  Reference reference;
  reference.available = reference.converged = true;
  reference.dt = scene.dt / 8.0;
  reference.run = gas_run("reference", bodies, contacts, samples, 1);
  std::vector<RunRecord> runs;
  for (unsigned e = 0; e < 5; ++e) runs.push_back(gas_run("engine" + std::to_string(e), bodies, contacts, samples, 1 + e % 2));
  for (auto _ : state) {
    ScenarioComparer comparer(scene, reference);
    for (RunRecord& r : runs) comparer.compare_run(r, false);
    std::vector<PairComparison> pairs;
    for (std::size_t i = 0; i < runs.size(); ++i) {
      for (std::size_t j = i + 1; j < runs.size(); ++j) pairs.push_back(comparer.compare_pair(runs[i], runs[j]));
    }
    benchmark::DoNotOptimize(pairs);
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(15 * contacts));
}
BENCHMARK(BM_ScenarioComparisonsContactHeavy)->Arg(10000)->Arg(30000)->Unit(benchmark::kMillisecond);

// core's run held against its own converged reference (judge_against_own_reference): a
// run of `range(0)` bodies and 100 samples under the reference engine's name, with settings
// that claim exact paths (judged: one more pass over the samples, the per-body limits and
// the pairing) or the lecture's collision pass (not judged: the check only reads the
// settings). The ratio of the two is the check's cost in compare_run.
void BM_CompareRunCoreOwnReference(benchmark::State& state) {
  const auto bodies = static_cast<std::size_t>(state.range(0));
  const bool judged = state.range(1) != 0;
  Scene scene;
  scene.name = "gas";
  scene.dt = 1.0 / 240.0;
  scene.duration = 4.0;
  for (std::size_t i = 0; i < bodies; ++i) {
    BodyDef b;
    b.name = std::string("c").append(std::to_string(i));
    b.radius = 0.05;
    b.position = {static_cast<double>(i), 0.0};
    scene.bodies.push_back(b);
  }
  Reference reference;
  reference.available = reference.converged = true;
  reference.dt = scene.dt / 8.0;
  reference.run = gas_run("reference", bodies, 0, 100, 1);
  RunRecord run = gas_run("core", bodies, 0, 100, 1);
  run.settings = {{"integrator", "velocity_verlet"}, {"collision", judged ? "exact" : "lecture"}};
  ScenarioComparer comparer(scene, reference);
  for (auto _ : state) {
    comparer.compare_run(run, false);   // clears and refills the run's verdict; the series stay
    if (run.reference_check.judged != judged || run.status != RunStatus::Ok) state.SkipWithError("not as meant");
    benchmark::DoNotOptimize(run);
  }
}
BENCHMARK(BM_CompareRunCoreOwnReference)->Args({1000, 0})->Args({1000, 1})->Unit(benchmark::kMillisecond);

// Containment after one step of a gas (runner.cpp calls it after every step of every
// run): `range(0)` circles (r = 0.05 m) `range(1)` mm apart in a walled box (220: as
// scripts/make_gas.py makes them, 16% packing; 162: circle_gas's 30%, where most x
// neighbours pass the y filter), moving straight and bouncing off the walls.
void BM_ContainmentObserveGas(benchmark::State& state) {
  const auto n = static_cast<std::size_t>(state.range(0));
  const std::size_t side = static_cast<std::size_t>(std::ceil(std::sqrt(static_cast<double>(n))));
  const double spacing = static_cast<double>(state.range(1)) / 1000.0, half = static_cast<double>(side) * spacing / 2.0 + 0.1;
  Scene scene;
  scene.name = "gas";
  const Vec2 c[4] = {{-half, -half}, {half, -half}, {half, half}, {-half, half}};
  for (int k = 0; k < 4; ++k) {
    WallDef w;
    w.name = std::string("w").append(std::to_string(k));
    w.from = c[k];
    w.to = c[(k + 1) % 4];
    scene.walls.push_back(w);
  }
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  std::vector<BodyState> states(n);
  for (std::size_t i = 0; i < n; ++i) {
    BodyDef b;
    b.name = std::string("c").append(std::to_string(i));
    b.radius = 0.05;
    b.position = {static_cast<double>(i % side) * spacing - half + 0.1 + spacing / 2.0,
                  static_cast<double>(i / side) * spacing - half + 0.1 + spacing / 2.0};
    scene.bodies.push_back(b);
    states[i].position = b.position;
    states[i].velocity = {unit(rng), unit(rng)};
  }
  ContainmentMonitor monitor(scene);
  monitor.start(states);
  const double h = 1.0 / 60.0;
  double t = 0.0;
  for (auto _ : state) {
    t += h;
    for (BodyState& s : states) {
      s.position = s.position + s.velocity * h;
      for (double* x : {&s.position.x, &s.position.y}) {
        if (std::abs(*x) > half - 0.05) *x = std::copysign(half - 0.05, *x);
      }
      if (std::abs(s.position.x) >= half - 0.05) s.velocity.x = -s.velocity.x;
      if (std::abs(s.position.y) >= half - 0.05) s.velocity.y = -s.velocity.y;
    }
    monitor.observe(t, states);
    benchmark::DoNotOptimize(monitor.record());
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(n));
}
BENCHMARK(BM_ContainmentObserveGas)->Args({200, 220})->Args({1000, 220})->Args({200, 162})->Unit(benchmark::kMicrosecond);

// Containment after every step of circle_gas as an engine ran it (`range(0)`: 0 core, 1
// box2d): the states after each of its 300 steps are recorded once, then one iteration
// observes them all with a fresh monitor (start and 300 observes). The gas of the
// synthetic case above moves straight through itself; this one collides, packs and
// bounces as the runs the harness checks do.
void BM_ContainmentCircleGasRun(benchmark::State& state) {
  const ScenarioLoad load = load_scenario_file(PHYSVAL_SOURCE_SCENARIOS "/models/circle_gas.toml");
  if (!load.scene) {
    state.SkipWithError("cannot load circle_gas.toml");
    return;
  }
  const Scene& scene = *load.scene;
  const char* wanted = state.range(0) == 0 ? "core" : "box2d";
  const EngineFactory* factory = nullptr;
  for (const EngineFactory& f : engine_registry()) {
    if (f.info.name == wanted) factory = &f;
  }
  if (factory == nullptr) {
    state.SkipWithError("engine not built");
    return;
  }
  std::unique_ptr<Engine> engine = factory->create();
  engine->load(scene);
  std::vector<std::vector<BodyState>> after(static_cast<std::size_t>(scene.steps()) + 1);
  engine->read_states(after[0]);
  for (std::size_t k = 1; k < after.size(); ++k) {
    engine->step(scene.dt);
    engine->read_states(after[k]);
  }
  for (auto _ : state) {
    ContainmentMonitor monitor(scene);
    monitor.start(after[0]);
    for (std::size_t k = 1; k < after.size(); ++k) monitor.observe(scene.dt * static_cast<double>(k), after[k]);
    benchmark::DoNotOptimize(monitor.record());
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(after.size() - 1));
}
BENCHMARK(BM_ContainmentCircleGasRun)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

// Containment after one step of orbit_1000_periods (two points, no barriers: 2M calls in
// the built-in suite, a fixed cost of every step of every small scene).
void BM_ContainmentObserveTwoPoints(benchmark::State& state) {
  Scene scene;
  scene.name = "orbit";
  scene.world.newtonian = true;
  for (int k = 0; k < 2; ++k) {
    BodyDef b;
    b.name = k == 0 ? "sun_a" : "sun_b";
    b.shape = ShapeKind::Point;
    b.radius = 0.0;
    b.position = {k == 0 ? 1.0 : -1.0, 0.0};
    b.velocity = {0.0, k == 0 ? 0.5 : -0.5};
    scene.bodies.push_back(b);
  }
  std::vector<BodyState> states(2);
  for (std::size_t i = 0; i < 2; ++i) {
    states[i].position = scene.bodies[i].position;
    states[i].velocity = scene.bodies[i].velocity;
  }
  ContainmentMonitor monitor(scene);
  monitor.start(states);
  // One period's 400 steps of the circular orbit, computed beforehand and cycled (the
  // time goes on), so that only observe is timed.
  const double h = 0.031415926535897934;
  std::vector<std::vector<BodyState>> orbit(400, states);
  for (std::size_t k = 0; k < orbit.size(); ++k) {
    for (std::size_t i = 0; i < 2; ++i) {
      const double a = 0.5 * h * static_cast<double>(k + 1) + (i == 0 ? 0.0 : 3.141592653589793);
      orbit[k][i].position = {std::cos(a), std::sin(a)};
      orbit[k][i].velocity = {-0.5 * std::sin(a), 0.5 * std::cos(a)};
    }
  }
  double t = 0.0;
  std::size_t k = 0;
  for (auto _ : state) {
    t += h;
    monitor.observe(t, orbit[k]);
    k = k + 1 == orbit.size() ? 0 : k + 1;
    benchmark::DoNotOptimize(monitor.record());
  }
}
BENCHMARK(BM_ContainmentObserveTwoPoints)->Unit(benchmark::kNanosecond);


// The series CSVs' number text (results_json.cpp writes six CSVs of up to 807 columns a
// sample; on circle_gas that was a third of the harness): 4096 positions of a gas (full
// 17-digit doubles in +-3.5 m, a few energies and momenta), each as %.12g and a comma.
// range(0) = 0: std::to_chars(general, 12); 1: to_chars_g12 (the same bytes).
void BM_SeriesNumberText(benchmark::State& state) {
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> position(-3.5, 3.5), energy(10.0, 200.0);
  std::vector<double> values(4096);
  for (std::size_t i = 0; i < values.size(); ++i) values[i] = i % 64 == 0 ? energy(rng) : position(rng);
  std::vector<char> buffer(values.size() * 33);
  const bool fast = state.range(0) == 1;
  for (auto _ : state) {
    char* o = buffer.data();
    for (const double v : values) {
      o = fast ? to_chars_g12(o, o + 32, v) : std::to_chars(o, o + 32, v, std::chars_format::general, 12).ptr;
      *o++ = ',';
    }
    benchmark::DoNotOptimize(o);
    benchmark::ClobberMemory();
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(values.size()));
}
BENCHMARK(BM_SeriesNumberText)->Arg(0)->Arg(1)->Unit(benchmark::kMicrosecond);

// write_results on circle_gas's shape (one scenario, five engine runs and a reference of 200
// bodies x 301 samples, positions in +-1.1 m), into a fresh folder under $TMPDIR: the series'
// text, the files' creation and the kernel's copy into the page cache (CPU time counts the
// system time). perf of it (README "Harness overhead", eleventh pass): the number text about
// two thirds, the kernel's copy 2-3%.
void BM_WriteSeriesGas(benchmark::State& state) {
  SuiteResult suite;
  ScenarioResult sr;
  sr.scene.name = "gas";
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> position(-1.1, 1.1), energy(30.0, 50.0);
  RunRecord r;
  r.scenario = "gas";
  r.bodies.resize(200);
  for (std::size_t i = 0; i < r.bodies.size(); ++i) r.bodies[i].name = "c" + std::to_string(i);
  for (int k = 0; k <= 300; ++k) {
    r.series.time.push_back(k / 60.0);
    Totals t;
    t.kinetic = energy(rng);
    t.momentum = {position(rng), position(rng)};
    t.angular_momentum = position(rng);
    r.series.totals.push_back(t);
    SampleRow row(r.bodies.size());
    for (SampleState& s : row) s = SampleState({position(rng), position(rng)}, true);
    r.series.states.push_back(std::move(row));
  }
  for (const char* e : {"core", "box2d", "bullet", "chipmunk", "ode"}) {
    r.engine = e;
    sr.runs.push_back(r);
  }
  r.engine = "reference";
  sr.reference.available = true;
  sr.reference.run = r;
  suite.scenarios.push_back(std::move(sr));
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("physval-bench-series-" + std::to_string(::getpid()));
  int n = 0;
  for (auto _ : state) {
    state.PauseTiming();
    std::filesystem::remove_all(dir);
    state.ResumeTiming();
    write_results(dir / std::to_string(n++ % 2), suite);
  }
  std::filesystem::remove_all(dir);
}
BENCHMARK(BM_WriteSeriesGas)->Unit(benchmark::kMillisecond);

// The stepping loop's own cost a step (runner.cpp: the clock, the clock check, reading the
// motion, containment, the sample countdown): run_engine on an engine whose step() does
// almost nothing (two points in free flight), 100k steps a run, sampled every 250 steps.
// Reported per step: the harness's per-step cost plus the engine's near-empty step.
class FreeFlight final : public Engine {
 public:
  FreeFlight() { info_.name = "free_flight"; }
  const EngineInfo& info() const override { return info_; }
  void load(const Scene& scene) override {
    bodies_ = scene.bodies;
    t_ = 0.0;
  }
  void step(double dt) override {
    t_ += dt;
    for (BodyDef& b : bodies_) b.position += dt * b.velocity;
  }
  double time() const override { return t_; }
  std::size_t body_count() const override { return bodies_.size(); }
  BodyMeta body_meta(std::size_t i) const override {
    return {bodies_[i].name, bodies_[i].mass, bodies_[i].radius, bodies_[i].is_static};
  }
  void read_states(std::vector<BodyState>& out) const override {
    out.resize(bodies_.size());
    for (std::size_t i = 0; i < out.size(); ++i) {
      out[i].position = bodies_[i].position;
      out[i].velocity = bodies_[i].velocity;
    }
  }
  const std::vector<ContactEvent>& contacts() const override { return none_; }
  std::vector<Setting> settings() const override { return {}; }

 private:
  EngineInfo info_;
  std::vector<BodyDef> bodies_;
  double t_ = 0.0;
  std::vector<ContactEvent> none_;
};

void BM_RunLoopCheapSteps(benchmark::State& state) {
  Scene scene;
  scene.name = "free";
  scene.dt = 1e-3;
  scene.duration = 100.0;   // 100k steps
  scene.sample_interval = 0.25;
  for (int k = 0; k < 2; ++k) {
    BodyDef b;
    b.name = k == 0 ? "a" : "b";
    b.shape = ShapeKind::Point;
    b.radius = 0.0;
    b.position = {k == 0 ? 1.0 : -1.0, 0.0};
    b.velocity = {0.0, k == 0 ? 0.5 : -0.5};
    scene.bodies.push_back(b);
  }
  EngineFactory f;
  f.info.name = "free_flight";
  f.create = [] { return std::make_unique<FreeFlight>(); };
  RunOptions options;
  options.isolate = false;
  long steps = 0;
  for (auto _ : state) {
    const RunRecord r = run_engine(scene, f, options);
    if (r.status != RunStatus::Ok) state.SkipWithError(r.reason.c_str());
    steps += r.steps;
    benchmark::DoNotOptimize(r.series.time.data());
  }
  state.SetItemsProcessed(steps);
  state.counters["ns_per_step"] =
      benchmark::Counter(static_cast<double>(steps), benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}
BENCHMARK(BM_RunLoopCheapSteps)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace physval

BENCHMARK_MAIN();
