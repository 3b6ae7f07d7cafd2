// Runs one engine on one scene: load, step, sample, collect contacts. The isolated
// variant forks, so an engine that crashes, aborts or hangs costs only its own run.
#include "physval/validation/runner.hpp"

#include <fcntl.h>
#include <malloc.h>
#include <poll.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/resource.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#if defined(__x86_64__)
#include <x86intrin.h>
#endif
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <limits>
#include <thread>
#include <numbers>
#include <sstream>

#include "physval/adapters/registry.hpp"
#include "physval/validation/conservation.hpp"
#include "physval/validation/run_record_io.hpp"
#include "containment.hpp"
#include "step_timing.hpp"

namespace physval {

const char* run_status_name(RunStatus s) {
  switch (s) {
    case RunStatus::Ok: return "ok";
    case RunStatus::Diverged: return "diverged";
    case RunStatus::Unsupported: return "unsupported";
    case RunStatus::Error: return "error";
  }
  return "error";
}

bool RunRecord::passed() const {
  if (status == RunStatus::Unsupported) {
    // Nothing ran, so nothing failed, unless a check says the run was owed (a baseline
    // that ran it: `baseline.status`).
    return std::all_of(checks.begin(), checks.end(), [](const Check& c) { return c.pass || !c.enforced; });
  }
  if (status != RunStatus::Ok && !(status == RunStatus::Diverged && known_divergence)) return false;
  return std::all_of(checks.begin(), checks.end(), [](const Check& c) { return c.pass || !c.enforced; });
}

Scene effective_scene(const Scene& scene, const RunOptions& options) {
  Scene s = scene;
  if (options.dt) s.dt = *options.dt;
  if (options.duration) s.duration = *options.duration;
  return s;
}

long sample_every(const Scene& scene, std::size_t max_sample_states) {
  const long steps = scene.steps();
  long every;
  if (scene.sample_interval > 0.0) {
    every = std::max(1L, std::lround(scene.sample_interval / scene.dt));
  } else {
    every = std::max(1L, steps / 400);   // about 400 samples
  }
  const std::size_t bodies = std::max<std::size_t>(1, scene.bodies.size());
  const std::size_t max_samples = std::max<std::size_t>(2, max_sample_states / bodies);
  while (static_cast<std::size_t>(steps / every) + 1 > max_samples) every *= 2;
  return every;
}

std::vector<const EngineFactory*> engines_for(const Scene& scene, const std::vector<std::string>& wanted) {
  std::vector<const EngineFactory*> out;
  for (const EngineFactory& f : engine_registry()) {
    if (!wanted.empty() && std::find(wanted.begin(), wanted.end(), f.info.name) == wanted.end()) continue;
    if (!scene.engines.empty() &&
        std::find(scene.engines.begin(), scene.engines.end(), f.info.name) == scene.engines.end()) {
      continue;
    }
    out.push_back(&f);
  }
  return out;
}

namespace {

RunRecord blank_record(const Scene& scene, const EngineInfo& info) {
  RunRecord r;
  r.scenario = scene.name;
  r.engine = info.name;
  r.engine_version = info.version;
  r.precision = precision_name(info.precision);
  r.dt = scene.dt;
  r.steps_planned = scene.steps();
  return r;
}

std::string object_name(const Scene& scene, const std::vector<BodyMeta>& metas, ObjectRef ref) {
  switch (ref.kind) {
    case ObjectRef::Kind::Body:
      return ref.index < metas.size() ? metas[ref.index].name : "body#" + std::to_string(ref.index);
    case ObjectRef::Kind::Wall:
      return ref.index < scene.walls.size() ? scene.walls[ref.index].name : "wall#" + std::to_string(ref.index);
    case ObjectRef::Kind::Box:
      return ref.index < scene.boxes.size() ? scene.boxes[ref.index].name : "box#" + std::to_string(ref.index);
    case ObjectRef::Kind::Surface:
      return ref.index < scene.surfaces.size() ? scene.surfaces[ref.index].name : "surface#" + std::to_string(ref.index);
  }
  return "?";
}

void refresh_metas(const Engine& engine, std::vector<BodyMeta>& metas, const Scene& scene) {
  const std::size_t n = engine.body_count();
  // Objects beyond the scene's bodies are particles, which only emitters make. Others (a
  // helper body an engine made for itself, a body doubled) would be counted in the
  // energy and momenta: one that took up the energy the scene's bodies lost hid it.
  if (n > scene.bodies.size() && scene.emitters.empty()) {
    throw std::runtime_error(engine.info().name + " reports " + std::to_string(n) + " bodies, but the scene has " +
                             std::to_string(scene.bodies.size()) + " and no emitter to make more");
  }
  for (std::size_t i = metas.size(); i < n; ++i) metas.push_back(engine.body_meta(i));
}

// The scene's bodies as the engine reports them must be the scene's: the energy, the
// momenta and containment are computed from the reported mass, radius and static flag.
// An engine (a plugin) that reported its bodies massless or static had an energy and a
// momentum of 0 at every sample, so every drift limit passed whatever it did. Masses
// and radii are held to float32's round-off (Box2D derives mass from a density).
void check_scene_bodies(const Scene& scene, const std::vector<BodyMeta>& metas, const std::string& engine) {
  auto close = [](double a, double b) { return std::abs(a - b) <= 1e-5 * std::max(std::abs(a), std::abs(b)) + 1e-12; };
  for (std::size_t i = 0; i < scene.bodies.size() && i < metas.size(); ++i) {
    const BodyDef& want = scene.bodies[i];
    const BodyMeta& got = metas[i];
    std::string wrong;
    if (got.name != want.name) {
      wrong = "is named \"" + got.name + "\"";
    } else if (got.is_static != want.is_static) {
      wrong = got.is_static ? "is static" : "is not static";
    } else if (!want.is_static && !close(got.mass, want.mass)) {
      wrong = "has a mass of " + std::to_string(got.mass) + " kg (the scene's: " + std::to_string(want.mass) + " kg)";
    } else if (!close(got.radius, want.radius)) {
      wrong = "has a radius of " + std::to_string(got.radius) + " m (the scene's: " + std::to_string(want.radius) + " m)";
    }
    if (!wrong.empty()) {
      throw std::runtime_error(engine + " reports the scene's body " + std::to_string(i) + " (\"" + want.name + "\") as one that " +
                               wrong + ": its energy and momenta would not be the scene's");
    }
  }
}

bool states_finite(const std::vector<BodyState>& states) {
  for (const BodyState& s : states) {
    if (!s.alive) continue;
    if (!is_finite(s.position) || !is_finite(s.velocity) || !std::isfinite(s.angle)) return false;
  }
  return true;
}


struct ProbeTracker {
  std::size_t body;
  Vec2 around;
  bool tracks_period;
  double last_angle = 0.0;
  double accumulated = 0.0;
  // The last sample of y and whether y rose (or held) into it, for the apexes' local maxima.
  bool have_prev = false;
  bool prev_rising = true;
  double prev_y = 0.0;
  double prev_t = 0.0;
};

// The previous sample is a local maximum of y (the start counts: nothing came before it);
// the first one at or above an apex's threshold is that apex's time.
void note_apex_peak(ProbeTracker& tr, Probe& p, bool peak) {
  if (!peak) return;
  for (auto& [threshold, time] : p.apex_first) {
    if (std::isnan(time) && tr.prev_y >= threshold) time = tr.prev_t;
  }
}

}  // namespace

RunRecord unsupported_run(const Scene& scene, const EngineInfo& info, const std::vector<std::string>& missing) {
  RunRecord r = blank_record(scene, info);
  r.status = RunStatus::Unsupported;
  r.reason = "cannot model: ";
  for (std::size_t i = 0; i < missing.size(); ++i) r.reason += (i ? ", " : "") + missing[i];
  return r;
}

RunRecord run_engine(const Scene& scene, const EngineFactory& factory, const RunOptions& options) {
  RunRecord r = blank_record(scene, factory.info);
  using clock = std::chrono::steady_clock;
  std::unique_ptr<Engine> engine;
  std::vector<BodyState> states;
  try {
    engine = factory.create();
    const auto t_load = clock::now();
    engine->load(scene);
    r.load_seconds = std::chrono::duration<double>(clock::now() - t_load).count();
    r.settings = engine->settings();
    refresh_metas(*engine, r.bodies, scene);
    check_scene_bodies(scene, r.bodies, factory.info.name);

    // Probes: every step, for the bodies the expectations name.
    std::vector<ProbeTracker> trackers;
    auto add_probe = [&](const std::string& body, bool period, Vec2 around) {
      const int i = scene.body_index(body);
      if (i < 0) return;
      for (std::size_t k = 0; k < r.probes.size(); ++k) {
        if (r.probes[k].body == body) {
          if (period) { trackers[k].tracks_period = true; trackers[k].around = around; }
          return;
        }
      }
      r.probes.push_back(Probe{body});
      trackers.push_back({static_cast<std::size_t>(i), around, period});
    };
    for (const ExpectedApex& a : scene.expect.apex) {
      add_probe(a.body, false, {});
      if (!a.time) continue;
      for (Probe& p : r.probes) {
        if (p.body == a.body) p.apex_first.emplace_back(a.height - a.tolerance.value_or(1e-3), std::numeric_limits<double>::quiet_NaN());
      }
    }
    for (const ExpectedPeriod& p : scene.expect.period) add_probe(p.body, true, p.around);

    const long every = sample_every(scene, options.max_sample_states);
    // Which of the scene's bodies anything in the scene can destroy: a collision-matrix
    // destroy rule (any body may meet one), or an explode emitter (its parent). Positions
    // of a body dead in either run are not compared, so an engine that reported bodies
    // destroyed that nothing destroys was compared on nothing but its energy: with
    // friction in the scene (no energy conserved) a position gate passed it.
    const bool destroy_rules = std::any_of(scene.collision_matrix.begin(), scene.collision_matrix.end(), [](const CollisionRule& c) {
      return c.response == CollisionResponse::DestroyA || c.response == CollisionResponse::DestroyB ||
             c.response == CollisionResponse::DestroyBoth;
    });
    std::vector<bool> may_die(scene.bodies.size(), destroy_rules);
    for (const EmitterDef& e : scene.emitters) {
      if (e.mode != EmitterMode::Explode) continue;
      if (const int i = scene.body_index(e.parent); i >= 0) may_die[static_cast<std::size_t>(i)] = true;
    }
    auto check_deaths = [&] {
      for (std::size_t i = 0; i < may_die.size() && i < states.size(); ++i) {
        if (!states[i].alive && !may_die[i]) {
          throw std::runtime_error(factory.info.name + " reports the scene's body " + std::to_string(i) + " (\"" +
                                   scene.bodies[i].name + "\") destroyed, but nothing in the scene destroys it (no " +
                                   "collision-matrix destroy rule, no explode emitter of it)");
        }
      }
    };
    // A sample is finite when every live body's state is and so are the totals made of
    // them: a body at 1e160 m/s has a finite state and an infinite kinetic energy, whose
    // drift (inf - inf) was skipped as NaN and read 0, a vacuous pass of any gate.
    auto sample = [&](double t) {
      engine->read_states(states);
      check_deaths();
      refresh_metas(*engine, r.bodies, scene);
      r.series.time.push_back(t);
      const Totals totals = compute_totals(scene, r.bodies, states);
      r.series.totals.push_back(totals);
      r.series.states.push_back(states);
      return states_finite(states) && std::isfinite(totals.energy()) && is_finite(totals.momentum) &&
             std::isfinite(totals.angular_momentum);
    };
    auto update_probes = [&](double t, double step_dt, bool have_states) {
      if (trackers.empty()) return;
      if (!have_states) engine->read_states(states);
      for (std::size_t k = 0; k < trackers.size(); ++k) {
        const BodyState& s = states[trackers[k].body];
        Probe& p = r.probes[k];
        if (s.position.y > p.max_y) {
          p.max_y = s.position.y;
          p.max_y_time = t;
        }
        if (!p.apex_first.empty()) {
          ProbeTracker& tr = trackers[k];
          const double y = s.position.y;
          if (tr.have_prev) {
            note_apex_peak(tr, p, tr.prev_rising && tr.prev_y >= y);
            tr.prev_rising = y >= tr.prev_y;
          }
          tr.have_prev = true;
          tr.prev_y = y;
          tr.prev_t = t;
        }
        if (trackers[k].tracks_period) {
          const Vec2 d = s.position - trackers[k].around;
          const double angle = std::atan2(d.y, d.x);
          double delta = angle - trackers[k].last_angle;
          if (delta > std::numbers::pi) delta -= 2.0 * std::numbers::pi;
          if (delta < -std::numbers::pi) delta += 2.0 * std::numbers::pi;
          if (t > 0.0) trackers[k].accumulated += delta;
          trackers[k].last_angle = angle;
          // floor(turns) > full_revolutions exactly when turns >= full_revolutions + 1 (an
          // integer, exact in a double): the floor only when a turn is completed.
          const double turns = std::abs(trackers[k].accumulated) / (2.0 * std::numbers::pi);
          if (turns >= static_cast<double>(p.full_revolutions) + 1.0) {
            const int full = static_cast<int>(std::floor(turns));
            // Interpolate within the step to the moment the angle completed the turn.
            const double target = 2.0 * std::numbers::pi * full;
            const double over = std::abs(trackers[k].accumulated) - target;
            const double frac = std::abs(delta) > 0.0 ? over / std::abs(delta) : 0.0;
            p.last_full_rev_time = t - frac * step_dt;
            p.full_revolutions = full;
          }
          p.revolutions = turns;
        }
      }
    };

    // Containment after every step (penetration depth, bodies through barriers): the
    // states are read each step for it, outside the timed step().
    ContainmentMonitor containment(scene);
    containment.set_object_names([&engine](std::size_t i) { return engine->body_meta(i).name; });
    const long n = scene.steps();
    // The series' block made once for the samples planned (one every `every` steps, the
    // start and the last step's): rows grow it only when particles appear.
    {
      const auto rows = static_cast<std::size_t>(n / every) + 2;
      r.series.time.reserve(rows);
      r.series.totals.reserve(rows);
      r.series.states.reserve(rows, rows * engine->body_count());
    }
    if (!sample(0.0)) {
      r.status = RunStatus::Diverged;
      r.reason = "the initial state is not finite (a position or velocity, or the energy or momentum made of them)";
      r.diverged_at = 0.0;
    }
    update_probes(0.0, scene.dt, true);
    containment.start(states);
    double wall = 0.0;
    const double last_dt = scene.last_step();
    const double loop_cpu0 = thread_cpu_seconds();
    const auto loop_t0 = clock::now();
    const StepTicks loop_ticks0 = step_ticks();
    StepTiming timing;
    long until_sample = every;   // steps to the next sample: k % every == 0 without a division a step
    double stepped = 0.0;   // the time the steps asked for add up to
    for (long k = 1; k <= n && r.status == RunStatus::Ok; ++k) {
      const double h = k == n ? last_dt : scene.dt;
      const bool timed = timing.timed(k);
      StepTicks t0 = 0, t1 = 0;
      if (timed) t0 = step_ticks();
      engine->step(h);
      if (timed) t1 = step_ticks();
      r.steps = k;
      const std::vector<ContactEvent>& events = engine->contacts();
      if (!events.empty()) {
        refresh_metas(*engine, r.bodies, scene);
        for (const ContactEvent& e : events) {
          r.contacts.push_back({object_name(scene, r.bodies, e.a), object_name(scene, r.bodies, e.b), e.time, k});
        }
      }
      const double t = engine->time();
      // Samples are paired with the reference's by this clock (to 1% of a step): one that
      // is not the steps taken paired no sample, or the wrong ones, and a run whose clock
      // ran 0.1% fast measured a position divergence of 0. The steps' round-off is allowed
      // for (clock_matches_steps, runner.hpp).
      stepped += h;
      if (!clock_matches_steps(t, stepped, k, scene.dt)) {
        throw std::runtime_error(factory.info.name + " reports its time as " + std::to_string(t) + " s after step " +
                                 std::to_string(k) + ", but it was stepped " + std::to_string(stepped) + " s");
      }
      const bool on_interval = --until_sample == 0;
      if (on_interval) until_sample = every;
      const bool sampled = on_interval || k == n;
      if (std::string broken = engine->broken_guarantee(); !broken.empty()) {
        sample(t);
        r.status = RunStatus::Diverged;
        r.reason = std::move(broken);
        r.diverged_at = t;
      } else if (sampled && !sample(t)) {
        r.status = RunStatus::Diverged;
        r.reason = "state became NaN or infinite (a position or velocity, or the energy or momentum made of them)";
        r.diverged_at = t;
      }
      // Containment and the probes read positions, velocities and liveness only (the
      // angles in `states` may be a sample's until the next one).
      if (!sampled) engine->read_motion(states);
      containment.observe(t, states);
      update_probes(t, h, true);
      if (timed) timing.add(t1 - t0, step_ticks() - t0);
    }
    {
      const double loop_cpu = thread_cpu_seconds() - loop_cpu0;
      const StepTicks loop_ticks = step_ticks() - loop_ticks0;
      const double loop_wall = std::chrono::duration<double>(clock::now() - loop_t0).count();
      // The steps' share of the loop's ticks, in seconds of the monotonic clock.
      wall = loop_ticks > 0 ? loop_wall * std::min(1.0, timing.step_ticks(loop_ticks) / static_cast<double>(loop_ticks)) : 0.0;
      r.wall_seconds = wall;
      r.step_cpu_seconds = loop_wall > 0.0 ? std::min(loop_cpu, loop_cpu * wall / loop_wall) : 0.0;
    }
    // The last sample is a peak if y rose (or held) into it: a body still rising at the end.
    for (std::size_t k = 0; k < trackers.size(); ++k) {
      if (trackers[k].have_prev) note_apex_peak(trackers[k], r.probes[k], trackers[k].prev_rising);
    }
    r.limits_hit = engine->limits_hit();
    engine->read_states(states);
    r.final_states = states;
    refresh_metas(*engine, r.bodies, scene);
    r.containment = containment.record();
  } catch (const std::exception& e) {
    r.status = RunStatus::Error;
    r.reason = std::string("engine failed: ") + e.what();
  } catch (...) {
    r.status = RunStatus::Error;
    r.reason = "engine failed with an unknown exception";
  }
  return r;
}

namespace {

// --- Child processes die with their parent -----------------------------------------
// Two mechanisms, because neither covers every way a parent ends:
//  - SIGKILL of the parent (nothing of it runs): the kernel sends the child
//    PR_SET_PDEATHSIG. Caveat for future threads: it fires when the *thread* that forked
//    exits, so fork from a thread that outlives the child.
//  - SIGTERM/SIGINT of the parent: its handler kills every live child, then ends the
//    parent with the same signal (so the shell sees the usual status).
// The table of live children holds several so that parallel runs compose with it.

constexpr std::size_t kMaxLiveChildren = 256;
std::array<std::atomic<pid_t>, kMaxLiveChildren> g_live_children{};

void kill_live_children_and_reraise(int sig) {
  for (std::atomic<pid_t>& slot : g_live_children) {
    const pid_t child = slot.load();
    if (child > 0) ::kill(child, SIGKILL);
  }
  ::signal(sig, SIG_DFL);
  ::raise(sig);
}

void install_child_forwarding_handlers() {
  static std::atomic<bool> installed{false};
  if (installed.exchange(true)) return;
  for (int sig : {SIGTERM, SIGINT, SIGHUP}) {
    struct sigaction current{};
    ::sigaction(sig, nullptr, &current);
    if (current.sa_handler == SIG_IGN) continue;   // e.g. nohup: keep ignoring
    struct sigaction action{};
    action.sa_handler = kill_live_children_and_reraise;
    sigemptyset(&action.sa_mask);
    ::sigaction(sig, &action, nullptr);
  }
}

void remember_live_child(pid_t child) {
  for (std::atomic<pid_t>& slot : g_live_children) {
    pid_t expected = 0;
    if (slot.compare_exchange_strong(expected, child)) return;
  }
}

void forget_live_child(pid_t child) {
  for (std::atomic<pid_t>& slot : g_live_children) {
    pid_t expected = child;
    if (slot.compare_exchange_strong(expected, 0)) return;
  }
}

// In the forked child, first thing: die when the parent dies. The getppid check closes
// the race where the parent died between fork and prctl.
void die_with_parent(pid_t parent) {
  ::prctl(PR_SET_PDEATHSIG, SIGKILL);
  if (::getppid() != parent) ::_exit(5);
  // The parent's forwarding handlers are not for the child: default actions again.
  for (int sig : {SIGTERM, SIGINT, SIGHUP}) {
    struct sigaction current{};
    ::sigaction(sig, nullptr, &current);
    if (current.sa_handler == kill_live_children_and_reraise) ::signal(sig, SIG_DFL);
  }
}

std::string seconds_text(double seconds) {
  std::ostringstream os;
  os << seconds;   // 20 -> "20", 0.5 -> "0.5"
  return os.str();
}

}  // namespace

namespace {

// Reaps a child (after forgetting it: an unreaped pid cannot be reused by another
// process); its whole CPU time, s.
double reap(pid_t pid, int& wstatus) {
  forget_live_child(pid);
  wstatus = 0;
  struct rusage usage{};
  while (::wait4(pid, &wstatus, 0, &usage) < 0 && errno == EINTR) {
  }
  return static_cast<double>(usage.ru_utime.tv_sec + usage.ru_stime.tv_sec) +
         1e-6 * static_cast<double>(usage.ru_utime.tv_usec + usage.ru_stime.tv_usec);
}

// Why a child's end makes its run an error, or "" when it exited 0 after sending something.
std::string exit_failure(int wstatus, std::size_t bytes_read) {
  if (WIFSIGNALED(wstatus)) {
    const int sig = WTERMSIG(wstatus);
    return std::string("engine crashed: signal ") + std::to_string(sig) + " (" + strsignal(sig) + ")";
  }
  if (!WIFEXITED(wstatus) || WEXITSTATUS(wstatus) != 0 || bytes_read == 0) {
    return "engine process exited with status " + std::to_string(WIFEXITED(wstatus) ? WEXITSTATUS(wstatus) : -1);
  }
  return {};
}

// The reason of a run whose child (reaped, `wstatus`) gave no whole record, or ran out of time.
void judge_failed_child(RunRecord& fallback, bool timed_out, int wstatus, std::size_t bytes_read,
                        const std::string& read_error, const RunOptions& options) {
  if (timed_out) {
    fallback.reason = "timed out after " + seconds_text(options.timeout_seconds) + " s";
  } else if (std::string why = exit_failure(wstatus, bytes_read); !why.empty()) {
    fallback.reason = std::move(why);
  } else {
    fallback.reason = "could not read the engine process's result: " + read_error;
  }
}

// The deadline of an isolated run: its timeout from now, or the shared deadline if earlier.
std::optional<std::chrono::steady_clock::time_point> run_deadline(const RunOptions& options) {
  std::optional<std::chrono::steady_clock::time_point> deadline;
  if (options.timeout_seconds > 0.0) {
    deadline = std::chrono::steady_clock::now() + std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                                                      std::chrono::duration<double>(options.timeout_seconds));
  }
  if (options.deadline) deadline = deadline ? std::min(*deadline, *options.deadline) : *options.deadline;
  return deadline;
}

// Whatever else a child writes is drained, so it is never left blocked on a full pipe.
void drain(int fd, std::size_t& bytes_read) {
  std::uint8_t sink[1 << 12];
  for (;;) {
    const ssize_t got = ::read(fd, sink, sizeof sink);
    if (got < 0 && errno == EINTR) continue;
    if (got <= 0) break;
    bytes_read += static_cast<std::size_t>(got);
  }
}

// `owned`: the caller's scene, released in the parent as soon as the child has its copy
// (a large scene's copy need not live while the record comes back).
RunRecord run_isolated(const Scene& scene, const EngineFactory& factory, const RunOptions& options, Scene* owned) {
  if (!options.isolate) return run_engine(scene, factory, options);
  int fds[2];
  if (::pipe(fds) != 0) return run_engine(scene, factory, options);
  // A larger pipe (1 MB where the system allows it; else the default 64 kB stays): the
  // record of a large run crosses in a few turns of child and parent, not hundreds.
  (void)::fcntl(fds[1], F_SETPIPE_SZ, 1 << 20);
  std::fflush(stdout);
  std::fflush(stderr);
  install_child_forwarding_handlers();
  const pid_t parent = ::getpid();
  const pid_t pid = ::fork();
  if (pid < 0) {
    ::close(fds[0]);
    ::close(fds[1]);
    return run_engine(scene, factory, options);
  }
  if (pid == 0) {
    die_with_parent(parent);
    ::close(fds[0]);
    int code = 0;
    try {
      const RunRecord r = run_engine(scene, factory, options);
      if (!write_run_record(fds[1], r)) code = 3;   // streamed: no second copy of the series
    } catch (...) {
      code = 4;
    }
    ::close(fds[1]);
    ::_exit(code);   // no atexit handlers, no double-flushed stdio buffers
  }
  remember_live_child(pid);
  ::close(fds[1]);
  RunRecord fallback = blank_record(scene, factory.info);
  fallback.status = RunStatus::Error;
  if (owned != nullptr) *owned = Scene{};   // `scene` is not read again below
  // The record is read straight from the pipe into a RunRecord as it arrives.
  const std::optional<std::chrono::steady_clock::time_point> deadline = run_deadline(options);
  bool timed_out = false;
  std::optional<RunRecord> record;
  std::string read_error;
  std::size_t bytes_read = 0;
  int wstatus_of_reaped = 0;
  try {
    record = read_run_record(fds[0], deadline, bytes_read);
  } catch (const RecordTimeout&) {
    timed_out = true;
  } catch (const std::exception& e) {
    read_error = e.what();
    drain(fds[0], bytes_read);
  }
  ::close(fds[0]);
  if (timed_out) ::kill(pid, SIGKILL);
  fallback.child_cpu_seconds = reap(pid, wstatus_of_reaped);
  if (!record || timed_out) {
    judge_failed_child(fallback, timed_out, wstatus_of_reaped, bytes_read, read_error, options);
    return fallback;
  }
  if (std::string why = exit_failure(wstatus_of_reaped, bytes_read); !why.empty()) {
    fallback.reason = std::move(why);
    return fallback;
  }
  record->child_cpu_seconds = fallback.child_cpu_seconds;
  return std::move(*record);
}

}  // namespace

double thread_cpu_seconds() {
  timespec ts{};
  ::clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

RunRecord run_engine_isolated(const Scene& scene, const EngineFactory& factory, const RunOptions& options) {
  return run_isolated(scene, factory, options, nullptr);
}

RunRecord run_engine_isolated(Scene&& scene, const EngineFactory& factory, const RunOptions& options) {
  return run_isolated(scene, factory, options, &scene);
}

// --- Run workers -------------------------------------------------------------------

namespace {

// What the parent asks of a worker: a run of one of its scenes on one registered engine.
struct WorkerRequest {
  std::uint64_t scene;
  std::uint64_t engine;
  std::uint64_t max_sample_states;
};

double process_cpu_seconds() {
  timespec ts{};
  ::clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

// False at end of stream (or any error) before n bytes came.
bool read_exactly(int fd, void* p, std::size_t n) {
  auto* c = static_cast<std::uint8_t*>(p);
  while (n > 0) {
    const ssize_t got = ::read(fd, c, n);
    if (got < 0 && errno == EINTR) continue;
    if (got <= 0) return false;
    c += got;
    n -= static_cast<std::size_t>(got);
  }
  return true;
}

bool write_exactly(int fd, const void* p, std::size_t n) {
  const auto* c = static_cast<const std::uint8_t*>(p);
  while (n > 0) {
    const ssize_t put = ::write(fd, c, n);
    if (put < 0 && errno == EINTR) continue;
    if (put <= 0) return false;
    c += put;
    n -= static_cast<std::size_t>(put);
  }
  return true;
}

// Closes every descriptor above stderr but the two given: a worker lives long, so it must
// not hold another worker's pipe ends open (that worker's parent would never see its end).
void close_all_but(int a, int b) {
  if (a > b) std::swap(a, b);
  auto close_from_to = [](int lo, int hi) {
    if (lo <= hi) (void)::close_range(static_cast<unsigned>(lo), static_cast<unsigned>(hi), 0);
  };
  close_from_to(3, a - 1);
  close_from_to(a + 1, b - 1);
  close_from_to(b + 1, std::numeric_limits<int>::max());
}

// glibc gives the top of the heap back to the kernel once more than 128 kB of it is free,
// and serves blocks from 128 kB up (the threshold grows to the largest freed) by mmap,
// unmapped on free: a run's series (a block of states a sample) and its record were
// faulted in page by page again on every run, a fifth of a 200-body gas's harness.
// Kept instead: the worker holds at most what its largest run needed; blocks above 32 MB
// are still mapped and unmapped.
void keep_freed_memory() {
#if defined(__GLIBC__)
  ::mallopt(M_MMAP_THRESHOLD, 32 << 20);
  ::mallopt(M_TRIM_THRESHOLD, 1 << 30);
#endif
}

// The worker's life: a request, the run, its record and then the CPU it cost (from the end
// of the previous run, or the fork), until the parent closes its end. Exit statuses as an
// isolated run's child: 3 the record could not be written, 4 an exception.
[[noreturn]] void worker_main(int requests, int records, const std::vector<const Scene*>& scenes,
                              const std::vector<const EngineFactory*>& engines) {
  double mark = 0.0;   // a child's CPU clock starts at 0 at fork
  keep_freed_memory();
  for (;;) {
    WorkerRequest q{};
    if (!read_exactly(requests, &q, sizeof q)) ::_exit(0);
    if (q.scene >= scenes.size() || q.engine >= engines.size()) ::_exit(6);
    int code = 0;
    try {
      RunOptions o;
      o.max_sample_states = static_cast<std::size_t>(q.max_sample_states);
      const RunRecord r = run_engine(*scenes[q.scene], *engines[q.engine], o);
      if (!write_run_record(records, r)) code = 3;
    } catch (...) {
      code = 4;
    }
    if (code != 0) ::_exit(code);
    const double now = process_cpu_seconds();
    const double cpu = now - mark;
    mark = now;
    if (!write_exactly(records, &cpu, sizeof cpu)) ::_exit(3);
  }
}

}  // namespace

struct RunWorkers::Worker {
  std::thread::id thread;
  pid_t pid = -1;
  int requests = -1;   // socket (send with MSG_NOSIGNAL: a worker killed while idle is no SIGPIPE)
  int records = -1;    // pipe, read end
  double reported_cpu = 0.0;   // the CPU of the runs it finished, s

  bool start(const std::vector<const Scene*>& scenes, const std::vector<const EngineFactory*>& engines) {
    int sv[2];
    if (::socketpair(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0, sv) != 0) return false;
    int fds[2];
    if (::pipe2(fds, O_CLOEXEC) != 0) {
      ::close(sv[0]);
      ::close(sv[1]);
      return false;
    }
    (void)::fcntl(fds[1], F_SETPIPE_SZ, 1 << 20);   // as for an isolated run
    std::fflush(stdout);
    std::fflush(stderr);
    install_child_forwarding_handlers();
    const pid_t parent = ::getpid();
    const pid_t child = ::fork();
    if (child < 0) {
      for (int fd : {sv[0], sv[1], fds[0], fds[1]}) ::close(fd);
      return false;
    }
    if (child == 0) {
      // The forking thread outlives the worker (PR_SET_PDEATHSIG follows the thread).
      die_with_parent(parent);
      close_all_but(sv[1], fds[1]);
      worker_main(sv[1], fds[1], scenes, engines);
    }
    remember_live_child(child);
    ::close(sv[1]);
    ::close(fds[1]);
    pid = child;
    requests = sv[0];
    records = fds[0];
    reported_cpu = 0.0;
    return true;
  }

  // Closes the parent's ends (a live worker then exits 0) and reaps it; its CPU beyond
  // the runs it reported, s.
  double end(int& wstatus) {
    if (requests >= 0) ::close(requests);
    if (records >= 0) ::close(records);
    requests = records = -1;
    double unreported = 0.0;
    if (pid > 0) unreported = reap(pid, wstatus) - reported_cpu;
    pid = -1;
    reported_cpu = 0.0;
    return unreported;
  }
};

RunWorkers::RunWorkers(std::vector<const Scene*> scenes, std::vector<const EngineFactory*> engines)
    : scenes_(std::move(scenes)), engines_(std::move(engines)) {}

RunWorkers::~RunWorkers() {
  for (const std::unique_ptr<Worker>& w : workers_) {
    int wstatus = 0;
    w->end(wstatus);
  }
}

RunWorkers::Worker& RunWorkers::mine() {
  const std::lock_guard<std::mutex> lock(mutex_);
  const std::thread::id self = std::this_thread::get_id();
  for (const std::unique_ptr<Worker>& w : workers_) {
    if (w->thread == self) return *w;
  }
  workers_.push_back(std::make_unique<Worker>());
  workers_.back()->thread = self;
  return *workers_.back();
}

RunRecord RunWorkers::run(std::size_t scene_index, const EngineFactory& factory, const RunOptions& options) {
  const Scene& scene = *scenes_.at(scene_index);
  if (!options.isolate) return run_engine(scene, factory, options);
  const auto known = std::find(engines_.begin(), engines_.end(), &factory);
  if (known == engines_.end()) return run_engine_isolated(scene, factory, options);
  const auto engine_index = static_cast<std::size_t>(known - engines_.begin());
  Worker& w = mine();
  const WorkerRequest q{scene_index, engine_index, options.max_sample_states};
  bool sent = false;
  for (int attempt = 0; attempt < 2 && !sent; ++attempt) {
    if (w.pid < 0 && !w.start(scenes_, engines_)) break;
    sent = ::send(w.requests, &q, sizeof q, MSG_NOSIGNAL) == static_cast<ssize_t>(sizeof q);
    if (!sent) {   // it died while idle (killed from outside): a new one
      int wstatus = 0;
      w.end(wstatus);
    }
  }
  if (!sent) return run_engine_isolated(scene, factory, options);   // no worker could be started

  RunRecord fallback = blank_record(scene, factory.info);
  fallback.status = RunStatus::Error;
  bool timed_out = false;
  std::optional<RunRecord> record;
  std::string read_error;
  std::size_t bytes_read = 0;
  double cpu = 0.0;
  try {
    record = read_run_record(w.records, run_deadline(options), bytes_read, cpu);
  } catch (const RecordTimeout&) {
    timed_out = true;
  } catch (const std::exception& e) {
    read_error = e.what();
    // No more requests: once it has written what it had, a live worker exits.
    ::close(w.requests);
    w.requests = -1;
    drain(w.records, bytes_read);
  }
  if (record) {
    record->child_cpu_seconds = cpu;
    w.reported_cpu += cpu;
    return std::move(*record);
  }
  if (timed_out) ::kill(w.pid, SIGKILL);
  int wstatus = 0;
  fallback.child_cpu_seconds = w.end(wstatus);
  judge_failed_child(fallback, timed_out, wstatus, bytes_read, read_error, options);
  return fallback;
}

}  // namespace physval
