// The runner and comparator, driven by test-double engines so that each behaviour
// (exact flight, a crash, an exception, a NaN, a hang, an energy gain) is known exactly.
#include <gtest/gtest.h>

#include <signal.h>
#include <unistd.h>

#include <csignal>
#include <cmath>
#include <fstream>
#include <limits>
#include <thread>

#include "physval/validation/comparator.hpp"
#include "physval/validation/conservation.hpp"
#include "physval/validation/gate.hpp"
#include "physval/validation/run_record_io.hpp"
#include "physval/validation/runner.hpp"
#include "physval/validation/suite.hpp"

namespace physval {
namespace {

enum class Fault { None, Crash, Throw, NaN, Hang, GainEnergy };

// Exact ballistic flight x(t) = x0 + v0 t + g t^2 / 2 for every body; reports one
// contact "a"-"b" at t = 0.5 s when the scene has two bodies.
class FakeEngine final : public Engine {
 public:
  explicit FakeEngine(Fault fault) : fault_(fault) { info_.name = "fake"; info_.version = "1"; }
  const EngineInfo& info() const override { return info_; }
  void load(const Scene& scene) override {
    if (fault_ == Fault::Throw) throw std::runtime_error("cannot load this scene");
    scene_ = scene;
  }
  void step(double dt) override {
    const double before = t_;
    t_ += dt;
    events_.clear();
    if (scene_.bodies.size() >= 2 && before < 0.5 && t_ >= 0.5) {
      events_.push_back({{ObjectRef::Kind::Body, 0}, {ObjectRef::Kind::Body, 1}, t_});
    }
    if (fault_ == Fault::Crash && t_ > 0.25) std::raise(SIGSEGV);
    if (fault_ == Fault::Hang && t_ > 0.25) std::this_thread::sleep_for(std::chrono::hours(1));
  }
  double time() const override { return t_; }
  std::size_t body_count() const override { return scene_.bodies.size(); }
  BodyMeta body_meta(std::size_t i) const override {
    return {scene_.bodies[i].name, scene_.bodies[i].mass, scene_.bodies[i].radius, scene_.bodies[i].is_static};
  }
  void read_states(std::vector<BodyState>& out) const override {
    out.resize(scene_.bodies.size());
    const Vec2 g = scene_.world.gravity;
    for (std::size_t i = 0; i < out.size(); ++i) {
      const BodyDef& b = scene_.bodies[i];
      out[i].position = b.position + t_ * b.velocity + 0.5 * t_ * t_ * g;
      out[i].velocity = b.velocity + t_ * g;
      if (fault_ == Fault::GainEnergy) out[i].velocity *= 1.0 + t_;   // kinetic energy grows (1 + t)^2
      if (fault_ == Fault::NaN && t_ > 0.5) out[i].position.x = std::nan("");
    }
  }
  const std::vector<ContactEvent>& contacts() const override { return events_; }
  // The process it ran in (settings are read in the engine's process), for the worker tests.
  std::vector<Setting> settings() const override {
    return {{"fault", std::to_string(static_cast<int>(fault_))}, {"pid", std::to_string(::getpid())}};
  }

 private:
  Fault fault_;
  EngineInfo info_;
  Scene scene_;
  double t_ = 0.0;
  std::vector<ContactEvent> events_;
};

EngineFactory fake(Fault fault) {
  EngineFactory f;
  f.info.name = "fake";
  f.info.version = "1";
  f.create = [fault] { return std::make_unique<FakeEngine>(fault); };
  return f;
}

Scene two_bodies() {
  Scene s;
  s.name = "two";
  s.duration = 1.0;
  s.dt = 0.01;
  BodyDef a;
  a.name = "a";
  a.radius = 0.5;
  a.position = {-1.0, 0.0};
  a.velocity = {1.0, 0.0};
  BodyDef b = a;
  b.name = "b";
  // Offset so that the fake's discs (which pass each other) graze, 0.2 m deep, rather than
  // go through each other: centres closer than a radius are a pass-through (diverged).
  b.position = {1.0, 0.8};
  b.velocity = {-1.0, 0.0};
  s.bodies = {a, b};
  return s;
}

TEST(Runner, RecordsStepsSamplesContactsAndFinalState) {
  const Scene s = two_bodies();
  const RunRecord r = run_engine(s, fake(Fault::None), RunOptions{});
  EXPECT_EQ(r.status, RunStatus::Ok) << r.reason;
  EXPECT_EQ(r.steps, 100);
  ASSERT_EQ(r.contacts.size(), 1u);
  EXPECT_EQ(r.contacts[0].a, "a");
  EXPECT_EQ(r.contacts[0].b, "b");
  EXPECT_NEAR(r.contacts[0].time, 0.5, 1e-12);
  EXPECT_EQ(r.contacts[0].step, 50);
  // Samples at t = 0 and at every sample interval, the last at the end.
  ASSERT_GE(r.series.time.size(), 2u);
  EXPECT_EQ(r.series.time.front(), 0.0);
  EXPECT_NEAR(r.series.time.back(), 1.0, 1e-12);
  ASSERT_EQ(r.final_states.size(), 2u);
  EXPECT_NEAR(r.final_states[0].position.x, 0.0, 1e-12);
}

// The clock check after every step (clock_matches_steps): a plugin that keeps its time as
// k x dt, while the harness sums the steps it gave, drifts apart from the sum by round-off
// that grows with k. Summed here to 5e7 steps of dt = 1e-3 (a second of plain additions):
// the two differ by more than the old fixed 1% of a step (an error on an honest clock),
// and the check accepts them at every step count looked at; a clock 0.1% fast, or ahead by
// a whole step, an infinite or NaN one, is rejected at each of them (the fast ones once
// 0.1% of the time is more than 1% of a step).
TEST(RunnerClock, KTimesDtAtLargeStepCountsIsAcceptedAFastClockIsNot) {
  for (const double dt : {1e-3, 1.0 / 60.0}) {
    double stepped = 0.0;
    double widest = 0.0;   // |k dt - stepped| / dt, largest seen
    const long n = 50'000'000;
    for (long k = 1; k <= n; ++k) {
      stepped += dt;
      if ((k & 0xFFFF) != 0 && k != n && k > 64) continue;
      const double t = static_cast<double>(k) * dt;
      widest = std::max(widest, std::abs(t - stepped) / dt);
      ASSERT_TRUE(clock_matches_steps(t, stepped, k, dt)) << "dt " << dt << " k " << k << ": " << t << " vs " << stepped;
      ASSERT_TRUE(clock_matches_steps(stepped, stepped, k, dt));
      if (k > 10) {   // 0.1% of the time is more than 1% of a step from step 11 on
        ASSERT_FALSE(clock_matches_steps(t * (1.0 + 1e-3), stepped, k, dt)) << "dt " << dt << " k " << k;
        ASSERT_FALSE(clock_matches_steps(t * (1.0 - 1e-3), stepped, k, dt)) << "dt " << dt << " k " << k;
      }
      if (k < 30'000'000) {
        ASSERT_FALSE(clock_matches_steps(t + dt, stepped, k, dt)) << "dt " << dt << " k " << k;
      }
      ASSERT_FALSE(clock_matches_steps(std::numeric_limits<double>::infinity(), stepped, k, dt));
      ASSERT_FALSE(clock_matches_steps(std::nan(""), stepped, k, dt));
    }
    // What the old check (|t - stepped| <= 0.01 dt) would have called a wrong clock.
    EXPECT_GT(widest, 0.01) << "dt " << dt;
  }
}

// The same through run_engine: an engine whose clock is (steps taken) x dt runs ok, one
// whose clock runs 0.1% fast is an error naming its clock.
class CountedClockEngine final : public Engine {
 public:
  explicit CountedClockEngine(double rate) : inner_(Fault::None), rate_(rate) {}
  const EngineInfo& info() const override { return inner_.info(); }
  void load(const Scene& scene) override {
    inner_.load(scene);
    dt_ = scene.dt;
  }
  void step(double dt) override {
    inner_.step(dt);
    ++steps_;
  }
  double time() const override { return rate_ * static_cast<double>(steps_) * dt_; }
  std::size_t body_count() const override { return inner_.body_count(); }
  BodyMeta body_meta(std::size_t i) const override { return inner_.body_meta(i); }
  void read_states(std::vector<BodyState>& out) const override { inner_.read_states(out); }
  const std::vector<ContactEvent>& contacts() const override { return inner_.contacts(); }
  std::vector<Setting> settings() const override { return inner_.settings(); }

 private:
  FakeEngine inner_;
  double rate_;
  double dt_ = 0.0;
  long steps_ = 0;
};

TEST(RunnerClock, AnEngineCountingStepsTimesDtRunsAFastOneIsAnError) {
  Scene s = two_bodies();
  s.dt = 0.1 / 3.0;   // not a binary fraction: k dt and the sum differ in the last bits
  s.duration = 3000 * s.dt;
  for (const double rate : {1.0, 1.0 + 1e-3}) {
    EngineFactory f = fake(Fault::None);
    f.create = [rate] { return std::make_unique<CountedClockEngine>(rate); };
    const RunRecord r = run_engine(s, f, RunOptions{});
    if (rate == 1.0) {
      EXPECT_EQ(r.status, RunStatus::Ok) << r.reason;
      EXPECT_EQ(r.steps, 3000);
    } else {
      EXPECT_EQ(r.status, RunStatus::Error);
      EXPECT_NE(r.reason.find("reports its time as"), std::string::npos) << r.reason;
    }
  }
}

TEST(Runner, SampleIntervalFromScenarioAndMemoryBound) {
  Scene s = two_bodies();
  s.sample_interval = 0.1;
  EXPECT_EQ(sample_every(s, 1'000'000), 10);
  // 100 steps, 2 bodies, room for 10 states: the interval grows until <= 5 samples fit.
  s.sample_interval = 0.0;
  EXPECT_LE(s.steps() / sample_every(s, 10) + 1, 5);
}

TEST(Runner, CrashCostsOnlyItsOwnRun) {
  const Scene s = two_bodies();
  RunOptions o;
  o.isolate = true;
  const RunRecord crashed = run_engine_isolated(s, fake(Fault::Crash), o);
  EXPECT_EQ(crashed.status, RunStatus::Error);
  // A plain build dies by the signal; under AddressSanitizer its handler may exit instead.
  EXPECT_TRUE(crashed.reason.find("signal") != std::string::npos ||
              crashed.reason.find("exited with status") != std::string::npos)
      << crashed.reason;
  const RunRecord fine = run_engine_isolated(s, fake(Fault::None), o);
  EXPECT_EQ(fine.status, RunStatus::Ok);
  // The isolated run carries the same record back as the in-process one.
  const RunRecord local = run_engine(s, fake(Fault::None), o);
  ASSERT_EQ(fine.series.time.size(), local.series.time.size());
  EXPECT_EQ(fine.final_states[1].position, local.final_states[1].position);
  EXPECT_EQ(fine.contacts.size(), local.contacts.size());
}

TEST(Runner, ExceptionBecomesErrorWithReason) {
  const RunRecord r = run_engine_isolated(two_bodies(), fake(Fault::Throw), RunOptions{});
  EXPECT_EQ(r.status, RunStatus::Error);
  EXPECT_NE(r.reason.find("cannot load this scene"), std::string::npos) << r.reason;
}

TEST(Runner, NanIsDivergedWithTheTime) {
  const RunRecord r = run_engine_isolated(two_bodies(), fake(Fault::NaN), RunOptions{});
  EXPECT_EQ(r.status, RunStatus::Diverged);
  ASSERT_TRUE(r.diverged_at);
  EXPECT_GT(*r.diverged_at, 0.5);
  EXPECT_LT(r.steps, 100) << "stops at the first non-finite sample";
}

TEST(Runner, HangIsStoppedByTheTimeout) {
  RunOptions o;
  o.timeout_seconds = 1.0;
  const RunRecord r = run_engine_isolated(two_bodies(), fake(Fault::Hang), o);
  EXPECT_EQ(r.status, RunStatus::Error);
  EXPECT_NE(r.reason.find("timed out"), std::string::npos) << r.reason;
}

// --- Run workers: one long-lived child per thread takes its runs one after another --

std::string pid_of(const RunRecord& r) {
  for (const auto& [k, v] : r.settings) {
    if (k == "pid") return v;
  }
  return "";
}

// The record's bytes without what may differ between processes: timings and the pid.
std::vector<std::uint8_t> comparable(RunRecord r) {
  r.wall_seconds = r.load_seconds = r.step_cpu_seconds = 0.0;
  for (auto& [k, v] : r.settings) {
    if (k == "pid") v.clear();
  }
  return encode_run_record(r);
}

// Waits until the (killed) process is a zombie or gone: its parent has not reaped it.
void wait_until_dead(pid_t pid) {
  for (int i = 0; i < 400; ++i) {
    std::ifstream stat("/proc/" + std::to_string(pid) + "/stat");
    std::string line;
    if (!std::getline(stat, line)) return;
    const std::size_t close = line.rfind(')');
    if (close != std::string::npos && close + 2 < line.size() && line[close + 2] == 'Z') return;
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
}

TEST(RunWorkers, RunsOneAfterAnotherInOneProcessWithTheRecordsOfInProcessRuns) {
  const Scene a = two_bodies();
  Scene b = two_bodies();
  b.name = "shorter";
  b.duration = 0.55;
  const EngineFactory ok = fake(Fault::None);
  const RunOptions o;
  pid_t worker = 0;
  {
    RunWorkers workers({&a, &b}, {&ok});
    const RunRecord r1 = workers.run(0, ok, o);
    const RunRecord r2 = workers.run(1, ok, o);
    const RunRecord r3 = workers.run(0, ok, o);
    for (const RunRecord* r : {&r1, &r2, &r3}) ASSERT_EQ(r->status, RunStatus::Ok) << r->reason;
    EXPECT_EQ(r2.steps, 55);
    // One worker took all three: a process of its own, not this one.
    ASSERT_FALSE(pid_of(r1).empty());
    EXPECT_EQ(pid_of(r1), pid_of(r2));
    EXPECT_EQ(pid_of(r1), pid_of(r3));
    EXPECT_NE(pid_of(r1), std::to_string(::getpid()));
    // Each record is the one an in-process run gives (the same scene run twice too).
    EXPECT_EQ(comparable(r1), comparable(run_engine(a, ok, o)));
    EXPECT_EQ(comparable(r2), comparable(run_engine(b, ok, o)));
    EXPECT_EQ(comparable(r3), comparable(r1));
    // Each run is charged the worker's CPU it cost.
    EXPECT_GT(r1.child_cpu_seconds, 0.0);
    EXPECT_GT(r2.child_cpu_seconds, 0.0);
    worker = static_cast<pid_t>(std::stol(pid_of(r1)));
    EXPECT_EQ(::kill(worker, 0), 0) << "the worker lives between runs";
  }
  // The destructor ended and reaped it (a zombie would still answer kill 0).
  EXPECT_NE(::kill(worker, 0), 0) << "worker " << worker << " outlived its RunWorkers";
}

TEST(RunWorkers, ACrashAHangOrAnExceptionCostsOnlyItsOwnRun) {
  const Scene s = two_bodies();
  const EngineFactory ok = fake(Fault::None), crash = fake(Fault::Crash), hang = fake(Fault::Hang),
                      thrower = fake(Fault::Throw);
  const RunOptions o;
  RunWorkers workers({&s}, {&ok, &crash, &hang, &thrower});
  const RunRecord first = workers.run(0, ok, o);
  ASSERT_EQ(first.status, RunStatus::Ok) << first.reason;

  // A crash: the reason an isolated run gives, and the next run has a new worker.
  const RunRecord crashed = workers.run(0, crash, o);
  EXPECT_EQ(crashed.status, RunStatus::Error);
  EXPECT_EQ(crashed.reason, run_engine_isolated(s, crash, o).reason);
  EXPECT_TRUE(crashed.reason.find("signal") != std::string::npos ||
              crashed.reason.find("exited with status") != std::string::npos)
      << crashed.reason;
  EXPECT_GT(crashed.child_cpu_seconds, 0.0);
  const RunRecord after_crash = workers.run(0, ok, o);
  ASSERT_EQ(after_crash.status, RunStatus::Ok) << after_crash.reason;
  EXPECT_NE(pid_of(after_crash), pid_of(first));
  EXPECT_EQ(comparable(after_crash), comparable(first));

  // A hang: stopped at the timeout, as an isolated run is.
  RunOptions limited = o;
  limited.timeout_seconds = 0.5;
  const RunRecord hung = workers.run(0, hang, limited);
  EXPECT_EQ(hung.status, RunStatus::Error);
  EXPECT_EQ(hung.reason, "timed out after 0.5 s");
  const RunRecord after_hang = workers.run(0, ok, limited);
  ASSERT_EQ(after_hang.status, RunStatus::Ok) << after_hang.reason;
  EXPECT_NE(pid_of(after_hang), pid_of(after_crash));

  // An exception is the run's error; the worker goes on.
  const RunRecord threw = workers.run(0, thrower, o);
  EXPECT_EQ(threw.status, RunStatus::Error);
  EXPECT_EQ(threw.reason, run_engine(s, thrower, o).reason);
  const RunRecord after_throw = workers.run(0, ok, o);
  ASSERT_EQ(after_throw.status, RunStatus::Ok) << after_throw.reason;
  EXPECT_EQ(pid_of(after_throw), pid_of(after_hang));
}

TEST(RunWorkers, AWorkerKilledWhileIdleIsReplaced) {
  const Scene s = two_bodies();
  const EngineFactory ok = fake(Fault::None);
  RunWorkers workers({&s}, {&ok});
  const RunRecord first = workers.run(0, ok, RunOptions{});
  ASSERT_EQ(first.status, RunStatus::Ok) << first.reason;
  const auto pid = static_cast<pid_t>(std::stol(pid_of(first)));
  ASSERT_EQ(::kill(pid, SIGKILL), 0);
  wait_until_dead(pid);
  const RunRecord next = workers.run(0, ok, RunOptions{});
  ASSERT_EQ(next.status, RunStatus::Ok) << next.reason;
  EXPECT_NE(pid_of(next), pid_of(first));
  EXPECT_EQ(comparable(next), comparable(first));
}

TEST(RunWorkers, EachThreadHasAWorkerOfItsOwnAndAnUnlistedEngineAChildOfItsOwn) {
  const Scene s = two_bodies();
  const EngineFactory ok = fake(Fault::None), unlisted = fake(Fault::None);
  RunWorkers workers({&s}, {&ok});
  std::string pids[2][2];
  std::vector<std::uint8_t> bytes[2][2];
  std::thread threads[2];
  for (int t = 0; t < 2; ++t) {
    threads[t] = std::thread([&, t] {
      for (int k = 0; k < 2; ++k) {
        const RunRecord r = workers.run(0, ok, RunOptions{});
        pids[t][k] = r.status == RunStatus::Ok ? pid_of(r) : "failed: " + r.reason;
        bytes[t][k] = comparable(r);
      }
    });
  }
  for (std::thread& t : threads) t.join();
  EXPECT_EQ(pids[0][0], pids[0][1]);
  EXPECT_EQ(pids[1][0], pids[1][1]);
  EXPECT_NE(pids[0][0], pids[1][0]);
  EXPECT_EQ(bytes[0][0], bytes[1][1]);
  const RunRecord own = workers.run(0, unlisted, RunOptions{});
  ASSERT_EQ(own.status, RunStatus::Ok) << own.reason;
  EXPECT_NE(pid_of(own), pids[0][0]);
  EXPECT_NE(pid_of(own), pids[1][0]);
  EXPECT_NE(pid_of(own), std::to_string(::getpid()));
}

TEST(Comparator, EnergyRunawayIsDiverged) {
  const Scene s = two_bodies();
  RunRecord r = run_engine(s, fake(Fault::GainEnergy), RunOptions{});
  ASSERT_EQ(r.status, RunStatus::Ok);
  compare_run(r, s, Reference{}, false);
  // Kinetic energy (1 + t)^2 times the initial: drift 3 at t = 1, past the runaway limit of 1.
  EXPECT_EQ(r.status, RunStatus::Diverged);
  ASSERT_TRUE(r.metrics["energy_drift"]);
  EXPECT_NEAR(*r.metrics["energy_drift"], 3.0, 1e-9);
}

// A scene that can only lose energy (friction, e < 1) and whose reference cannot judge it
// (none here, as for a chaotic pile): before energy_gain, an engine blowing up was ok.
TEST(Comparator, EnergyGainInASceneThatCanOnlyLoseEnergyIsDiverged) {
  Scene s = two_bodies();
  s.bodies[0].restitution = 0.5;
  s.bodies[1].friction = 0.3;
  RunRecord r = run_engine(s, fake(Fault::GainEnergy), RunOptions{});
  compare_run(r, s, Reference{}, false);
  EXPECT_FALSE(r.metrics["energy_drift"]) << "energy is not conserved here";
  ASSERT_TRUE(r.metrics["energy_gain"]);
  EXPECT_NEAR(*r.metrics["energy_gain"], 3.0, 1e-9);
  EXPECT_EQ(r.status, RunStatus::Diverged);
  EXPECT_NE(r.reason.find("can only lose"), std::string::npos) << r.reason;

  RunRecord honest = run_engine(s, fake(Fault::None), RunOptions{});
  compare_run(honest, s, Reference{}, false);
  EXPECT_EQ(honest.status, RunStatus::Ok);
  ASSERT_TRUE(honest.metrics["energy_gain"]);
  EXPECT_EQ(*honest.metrics["energy_gain"], 0.0);

  // Thrust or wind can add energy: no bound is claimed, the metric is null.
  s.world.wind = {1.0, 0.0};
  s.bodies[0].drag_linear = 0.1;
  RunRecord windy = run_engine(s, fake(Fault::GainEnergy), RunOptions{});
  compare_run(windy, s, Reference{}, false);
  EXPECT_FALSE(windy.metrics["energy_gain"]);
  EXPECT_EQ(windy.status, RunStatus::Ok);
}

// core in exact mode guarantees no overlap; before this rule a core run whose pile
// collapsed into 6 cm overlaps was ok (and is the engine the others are measured against).
TEST(Comparator, ReferenceEngineOverlapBeyondRoundOffIsDiverged) {
  const Scene s = two_bodies();   // the fake lets the two discs graze 0.2 m deep
  RunRecord r = run_engine(s, fake(Fault::None), RunOptions{});
  r.engine = "core";
  r.settings = {{"collision", "exact"}};
  compare_run(r, s, Reference{}, false);
  ASSERT_TRUE(r.metrics["max_penetration"]);
  EXPECT_NEAR(*r.metrics["max_penetration"], 0.2, 1e-9);
  EXPECT_EQ(r.status, RunStatus::Diverged);
  EXPECT_NE(r.reason.find("no-overlap guarantee"), std::string::npos) << r.reason;

  // The lecture's one-pass scheme makes no such promise; another engine is held by its gates.
  RunRecord lecture = run_engine(s, fake(Fault::None), RunOptions{});
  lecture.engine = "core";
  lecture.settings = {{"collision", "lecture"}};
  compare_run(lecture, s, Reference{}, false);
  EXPECT_EQ(lecture.status, RunStatus::Ok);
  RunRecord other = run_engine(s, fake(Fault::None), RunOptions{});
  compare_run(other, s, Reference{}, false);
  EXPECT_EQ(other.status, RunStatus::Ok);
}

TEST(Comparator, DriftIsNullWhereNotConservedAndZeroForExactFlight) {
  Scene s = two_bodies();
  RunRecord r = run_engine(s, fake(Fault::None), RunOptions{});
  compare_run(r, s, Reference{}, false);
  ASSERT_TRUE(r.metrics["energy_drift"]);
  EXPECT_EQ(*r.metrics["energy_drift"], 0.0);
  EXPECT_EQ(*r.metrics["linear_momentum_drift"], 0.0);
  s.world.gravity = {0.0, -9.8};   // a uniform field: momentum is not conserved
  r = run_engine(s, fake(Fault::None), RunOptions{});
  compare_run(r, s, Reference{}, false);
  EXPECT_FALSE(r.metrics["linear_momentum_drift"].has_value());
  ASSERT_TRUE(r.metrics["energy_drift"]);
  EXPECT_LT(*r.metrics["energy_drift"], 1e-14) << "exact flight conserves KE + PE";
}

TEST(Comparator, ExpectationsAndGateLimits) {
  Scene s = two_bodies();
  s.expect.first_contact = ExpectedContact{"a", "b", 0.5, std::nullopt};
  s.expect.final_states.push_back({"a", Vec2{0.0, 0.0}, Vec2{1.0, 0.0}, 1e-9});
  s.gate.limits["energy_drift"] = 1e-12;
  s.gate.per_engine["fake"]["linear_momentum_drift"] = 0.0;
  RunRecord r = run_engine(s, fake(Fault::None), RunOptions{});
  compare_run(r, s, Reference{}, true);
  EXPECT_TRUE(r.passed());
  for (const Check& c : r.checks) EXPECT_TRUE(c.pass) << c.what;
  // A limit tightened below what the engine achieves fails only when gates are enforced.
  s.expect.final_states[0].position = Vec2{0.1, 0.0};
  compare_run(r, s, Reference{}, true);
  EXPECT_FALSE(r.passed());
  s.expect.final_states[0].position = Vec2{0.0, 0.0};
  s.gate.limits["energy_drift"] = 1e-12;
  RunRecord gaining = run_engine(s, fake(Fault::None), RunOptions{});
  s.gate.limits["first_contact_time"] = 0.1;   // the contact comes at 0.5 s
  compare_run(gaining, s, Reference{}, false);
  EXPECT_TRUE(gaining.passed()) << "run reports gate limits but does not enforce them";
  compare_run(gaining, s, Reference{}, true);
  EXPECT_FALSE(gaining.passed());
}

TEST(Comparator, ContactTimingAgainstExpectedContacts) {
  Scene s = two_bodies();
  s.expect.contacts.push_back({"a", "b", 0.495, std::nullopt});
  s.expect.contacts.push_back({"a", "b", 0.9, std::nullopt});   // never happens
  RunRecord r = run_engine(s, fake(Fault::None), RunOptions{});
  compare_run(r, s, Reference{}, false);
  ASSERT_TRUE(r.metrics["contact_time_error"]);
  EXPECT_NEAR(*r.metrics["contact_time_error"], 0.005, 1e-12);
  EXPECT_NEAR(*r.metrics["contact_time_error_steps"], 0.5, 1e-9);
  EXPECT_EQ(*r.metrics["missed_contacts"], 1.0);
  EXPECT_EQ(*r.metrics["extra_contacts"], 0.0);
  EXPECT_NEAR(*r.metrics["first_contact_time"], 0.5, 1e-12);
}

TEST(Comparator, PairOfIdenticalEnginesAgrees) {
  const Scene s = two_bodies();
  const RunRecord a = run_engine(s, fake(Fault::None), RunOptions{});
  const RunRecord b = run_engine(s, fake(Fault::None), RunOptions{});
  const PairComparison pc = compare_pair(a, b, s);
  EXPECT_EQ(*pc.metrics.at("position_divergence"), 0.0);
  EXPECT_EQ(*pc.metrics.at("contact_time_error"), 0.0);
  EXPECT_EQ(*pc.metrics.at("missed_contacts"), 0.0);
}

TEST(Conservation, RulesFollowTheScene) {
  Scene s = two_bodies();
  Conserved c = conserved_quantities(s);
  EXPECT_TRUE(c.energy);
  EXPECT_TRUE(c.linear_momentum);
  EXPECT_TRUE(c.angular_momentum);
  s.bodies[0].restitution = 0.5;
  c = conserved_quantities(s);
  EXPECT_FALSE(c.energy);
  EXPECT_TRUE(c.linear_momentum);
  s.walls.push_back(WallDef{"w", {0, -1}, {0, 1}, {}, 0});
  c = conserved_quantities(s);
  EXPECT_FALSE(c.linear_momentum);
  s.conserves.linear_momentum = true;
  EXPECT_TRUE(conserved_quantities(s).linear_momentum) << "a scenario may override";
}

TEST(Conservation, ScalesAreNeverNearZero) {
  Scene s;
  BodyDef b;
  b.name = "resting";
  b.radius = 0.5;
  b.position = {0.0, 0.5};
  s.bodies.push_back(b);
  s.world.gravity = {0.0, -9.8};
  const Scales sc = characteristic_scales(s);
  // A resting body: no kinetic energy, but the field sets a scale m g H, H the scene's
  // extent along g (the body's diameter here; not the diagonal of its box).
  EXPECT_NEAR(sc.energy, 1.0 * 9.8 * 1.0, 1e-12);
  EXPECT_GT(sc.momentum, 0.0);
}

TEST(Gate, JunitHasACasePerScenarioAndEngine) {
  SuiteResult result;
  ScenarioResult sr;
  sr.scene = two_bodies();
  RunRecord ok = run_engine(sr.scene, fake(Fault::None), RunOptions{});
  RunRecord bad = ok;
  bad.engine = "other<&>";
  bad.checks.push_back({"energy_drift", 1e-9, 1.0, false, true, false, ""});
  RunRecord skipped = unsupported_run(sr.scene, fake(Fault::None).info, {"particles"});
  sr.runs = {ok, bad, skipped};
  result.scenarios.push_back(sr);
  const std::string xml = junit_xml(result);
  EXPECT_NE(xml.find("tests=\"3\" failures=\"1\""), std::string::npos) << xml;
  EXPECT_NE(xml.find("name=\"other&lt;&amp;&gt;\""), std::string::npos);
  EXPECT_NE(xml.find("<skipped message=\"cannot model: particles\"/>"), std::string::npos);
  EXPECT_NE(xml.find("energy_drift = 1 &gt; limit 1e-09"), std::string::npos) << xml;
}

TEST(Gate, BaselineFailsOnRegressionBeyondFactor) {
  SuiteResult result;
  ScenarioResult sr;
  sr.scene = two_bodies();
  RunRecord r = run_engine(sr.scene, fake(Fault::None), RunOptions{});
  r.metrics["energy_drift"] = 3e-6;
  r.metrics["position_divergence"] = 1e-3;
  sr.runs = {r};
  result.scenarios.push_back(sr);
  const nlohmann::json baseline = {
      {"runs", {{{"scenario", "two"}, {"engine", "fake"}, {"metrics", {{"energy_drift", 1e-6}, {"position_divergence", 1e-3}}}}}}};
  EXPECT_EQ(apply_baseline(result, baseline, 2.0), 1);
  const auto& checks = result.scenarios[0].runs[0].checks;
  ASSERT_EQ(checks.size(), 2u);
  for (const Check& c : checks) {
    if (c.what == "baseline.energy_drift") {
      EXPECT_FALSE(c.pass) << "3e-6 > 2 x 1e-6";
    }
    if (c.what == "baseline.position_divergence") {
      EXPECT_TRUE(c.pass);
    }
  }
}

// A metric the baseline measured and this run did not (null: a reference that stopped
// converging, say) hid every regression in it: the check passed by being skipped.
TEST(Gate, BaselineFailsWhenAMeasuredMetricIsNoLongerMeasured) {
  SuiteResult result;
  ScenarioResult sr;
  sr.scene = two_bodies();
  RunRecord r = run_engine(sr.scene, fake(Fault::None), RunOptions{});
  r.metrics["energy_drift"] = 1e-6;
  r.metrics["position_divergence"] = std::nullopt;
  sr.runs = {r};
  result.scenarios.push_back(sr);
  const nlohmann::json baseline = {
      {"runs", {{{"scenario", "two"}, {"engine", "fake"}, {"metrics", {{"energy_drift", 1e-6}, {"position_divergence", 1e-3}}}}}}};
  EXPECT_EQ(apply_baseline(result, baseline, 2.0), 1);
  const auto& checks = result.scenarios[0].runs[0].checks;
  ASSERT_EQ(checks.size(), 2u);
  for (const Check& c : checks) {
    if (c.what == "baseline.energy_drift") {
      EXPECT_TRUE(c.pass);
    }
    if (c.what == "baseline.position_divergence") {
      EXPECT_FALSE(c.pass);
      EXPECT_FALSE(c.value.has_value());
      EXPECT_NE(c.detail.find("not measured"), std::string::npos) << c.detail;
    }
  }
}

}  // namespace
}  // namespace physval

namespace physval {
namespace {

// An engine that ran a scenario in the baseline and now reports it unsupported (a plugin
// that dropped a feature, a scene that gained one) checked nothing, and `gate
// --baseline` passed it: an unsupported run always passed, whatever its checks said.
TEST(Gate, BaselineFailsWhenAnEngineThatRanIsNowUnsupported) {
  for (const std::string before : {"ok", "diverged", "unsupported"}) {
    SuiteResult result;
    ScenarioResult sr;
    sr.scene = two_bodies();
    sr.runs = {unsupported_run(sr.scene, fake(Fault::None).info, {"particles"})};
    result.scenarios.push_back(sr);
    const nlohmann::json metrics = before == "unsupported" ? nlohmann::json::object()
                                                           : nlohmann::json{{"energy_drift", 1e-6}};
    const nlohmann::json baseline = {
        {"runs", {{{"scenario", "two"}, {"engine", "fake"}, {"status", before}, {"metrics", metrics}}}}};
    EXPECT_EQ(apply_baseline(result, baseline, 2.0), 1);
    const RunRecord& r = result.scenarios[0].runs[0];
    const std::string xml = junit_xml(result);
    if (before == "unsupported") {
      EXPECT_TRUE(r.passed());
      EXPECT_TRUE(r.checks.empty());
      EXPECT_NE(xml.find("<skipped"), std::string::npos) << xml;
    } else {
      EXPECT_FALSE(r.passed()) << before;
      ASSERT_EQ(r.checks.size(), 1u);
      EXPECT_EQ(r.checks[0].what, "baseline.status");
      EXPECT_NE(r.checks[0].detail.find("status " + before), std::string::npos) << r.checks[0].detail;
      EXPECT_EQ(xml.find("<skipped"), std::string::npos) << xml;
      EXPECT_NE(xml.find("failures=\"1\""), std::string::npos) << xml;
      EXPECT_NE(xml.find("baseline.status"), std::string::npos) << xml;
    }
  }
}

// A contact an engine now misses left contact_time_error smaller (it is the largest error
// of the contacts matched), and an overlap 100x deeper changed no metric the baseline
// compared: both passed `gate --baseline`.
TEST(Gate, BaselineFailsOnANewlyMissedContactOrADeeperOverlap) {
  struct Case { const char* metric; double before, now; bool pass; };
  for (const Case& k : {Case{"missed_contacts", 0.0, 1.0, false}, Case{"extra_contacts", 0.0, 2.0, false},
                        Case{"max_penetration", 1e-4, 1e-2, false}, Case{"energy_gain", 1e-6, 1e-3, false},
                        Case{"missed_contacts", 1.0, 2.0, true}, Case{"max_penetration", 1e-4, 1.5e-4, true}}) {
    SuiteResult result;
    ScenarioResult sr;
    sr.scene = two_bodies();
    RunRecord r = run_engine(sr.scene, fake(Fault::None), RunOptions{});
    r.metrics["contact_time_error"] = 1e-3;
    r.metrics[k.metric] = k.now;
    sr.runs = {r};
    result.scenarios.push_back(sr);
    const nlohmann::json baseline = {{"runs", {{{"scenario", "two"}, {"engine", "fake"},
                                                {"metrics", {{"contact_time_error", 2e-3}, {k.metric, k.before}}}}}}};
    EXPECT_EQ(apply_baseline(result, baseline, 2.0), 1);
    bool saw = false;
    for (const Check& c : result.scenarios[0].runs[0].checks) {
      if (c.what == "baseline.contact_time_error") {
        EXPECT_TRUE(c.pass);
      }
      if (c.what != std::string("baseline.") + k.metric) continue;
      saw = true;
      EXPECT_EQ(c.pass, k.pass) << k.metric << " " << k.before << " -> " << k.now;
    }
    EXPECT_TRUE(saw) << k.metric;
  }
}

}  // namespace
}  // namespace physval
