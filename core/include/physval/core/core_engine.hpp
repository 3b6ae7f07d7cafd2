// core: physval's own engine, built from the lecture model (shared/lecture-model.md).
//
// Options ([core] in a scenario; defaults in brackets):
//   integrator           explicit_euler | semi_implicit_euler | velocity_verlet | rk4
//                        [velocity_verlet]
//   collision            exact | lecture [exact]
//   broadphase           auto | all_pairs | grid | multigrid | sort_and_sweep [auto]
//   cell_size            float, m; 0 = picked from the bodies each step [0]
//   max_events_per_step  integer; 0 = 1,000,000 + 100 N [0]
//   rest_speed           float, m/s; 0 = auto [0]
// The README's scenario reference documents each one; core_engine.cpp holds the specs.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "physval/core/engine.hpp"

namespace physval {

// Name "core". The registry entry.
EngineFactory core_engine_factory();

namespace core_detail {
struct World;
}

// Counters of the last step, for benchmarks and tests.
struct CoreStepStats {
  std::int64_t impacts = 0;         // impacts resolved (bounces, settling, pass-through events)
  std::int64_t events = 0;          // events processed (impacts, friction stops, leaving a support, ...)
  std::int64_t candidate_pairs = 0; // broad-phase pairs at the start of the step
  bool event_cap_hit = false;       // the step ended in the lecture pass (see max_events_per_step)
  std::int64_t wedged = 0;          // slow bodies held where no impulse could move them
};

// The core engine. Construct it through core_engine_factory() or directly (tests).
class CoreEngine final : public Engine {
 public:
  CoreEngine();
  ~CoreEngine() override;
  CoreEngine(const CoreEngine&) = delete;
  CoreEngine& operator=(const CoreEngine&) = delete;

  const EngineInfo& info() const override;
  void load(const Scene& scene) override;
  void step(double dt) override;
  double time() const override;
  std::size_t body_count() const override;
  BodyMeta body_meta(std::size_t i) const override;
  void read_states(std::vector<BodyState>& out) const override;
  const std::vector<ContactEvent>& contacts() const override;
  std::vector<Setting> settings() const override;
  std::vector<std::string> limits_hit() const override;
  // Non-empty when the last step reached the event cap: its remaining impacts were not
  // resolved exactly, so bodies may have passed through each other (the runner stops there).
  std::string broken_guarantee() const override;

  // Particles: age in seconds (-1 for a body that is not a particle) and colour
  // intensity, 1 at birth falling linearly to 0 at the end of its life.
  double particle_age(std::size_t i) const;
  double particle_intensity(std::size_t i) const;

  const CoreStepStats& last_step_stats() const;
  // The normal forces at the contacts of the bodies at rest (held on several supports,
  // or stuck on one), from the equilibrium of all of them at once: normal forces >= 0
  // that cancel every one's force where they can (frictionless; projected Gauss-Seidel
  // to round-off). `other` is a body index or, for a face, -1 and `wall` its owner.
  struct RestingForce {
    std::size_t body = 0;
    std::int64_t other = -1;
    ObjectRef wall;
    Vec2 normal;        // unit, towards `body`
    double force = 0.0; // N
  };
  std::vector<RestingForce> resting_forces() const;
  // Bytes of memory the engine holds (all its arrays, broad phase and queues).
  std::size_t memory_bytes() const;

 private:
  std::unique_ptr<core_detail::World> world_;
};

// Colour intensity of a particle of this age and lifetime: 1 - age / lifetime,
// clamped to [0, 1] (the lecture: colour intensity changes with age).
double particle_intensity(double age, double lifetime);

}  // namespace physval
