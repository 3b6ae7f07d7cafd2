// The one interface that core and every adapter implement identically. The runner
// and the comparator talk to engines only through it and know none by name.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "physval/engine/options.hpp"
#include "physval/engine/scene.hpp"
#include "physval/engine/vec2.hpp"

namespace physval {

struct BodyState {
  Vec2 position;
  Vec2 velocity;
  double angle = 0.0;
  double angular_velocity = 0.0;
  bool alive = true;   // false once destroyed (collision matrix, particle death)
};

// What the comparator needs to know of a body it did not find in the scene file
// (particles are created while the scene runs). For i < scene.bodies.size() the
// body is scene.bodies[i].
struct BodyMeta {
  std::string name;
  double mass = 0.0;     // 0 for static bodies
  double radius = 0.0;
  bool is_static = false;
};

// Something a contact can involve: a body (scene order, then particles in order of
// creation) or one of the scene's static barriers.
struct ObjectRef {
  enum class Kind : std::uint8_t { Body, Wall, Box, Surface };
  Kind kind = Kind::Body;
  std::uint32_t index = 0;
  friend bool operator==(ObjectRef, ObjectRef) = default;
};

// A contact that began during the last step, at simulated time `time` (an exact
// impact time for engines that compute one, otherwise the end of the step in which
// the engine saw it begin). `a` is always a body; a pair of bodies is ordered by
// index (a.index < b.index).
struct ContactEvent {
  ObjectRef a;
  ObjectRef b;
  double time = 0.0;
};

enum class Precision : std::uint8_t { Float32, Float64 };
inline const char* precision_name(Precision p) { return p == Precision::Float32 ? "float32" : "float64"; }

struct EngineInfo {
  std::string name;          // "core", "box2d", "bullet": the scenario's option table
  std::string version;       // the library's version (as packaged)
  Precision precision = Precision::Float64;
  std::string summary;       // one line: what it is
  std::vector<Feature> features;     // what it can model
  std::vector<OptionSpec> options;   // its scenario options, with defaults
};

// A setting the engine ran with, as a name and a printable value (written into
// results.json so each run explains itself).
using Setting = std::pair<std::string, std::string>;

class Engine {
 public:
  virtual ~Engine() = default;

  virtual const EngineInfo& info() const = 0;

  // Builds the engine's world from the scene. Throws std::exception on failure.
  // Options come from scene.engine_options[info().name] (read them with
  // OptionReader, which applies the declared defaults).
  virtual void load(const Scene& scene) = 0;

  // Advances the simulation by dt seconds (dt may change from call to call).
  virtual void step(double dt) = 0;

  // Simulated time since load.
  virtual double time() const = 0;

  // Bodies so far, including destroyed ones (alive = false) and particles.
  virtual std::size_t body_count() const = 0;
  virtual BodyMeta body_meta(std::size_t i) const = 0;
  // Fills out[i] for every body; resizes out to body_count().
  virtual void read_states(std::vector<BodyState>& out) const = 0;
  // The same for the runner's containment check after every step, which reads where each
  // body is, its velocity and whether it is alive only: an engine may leave angle and
  // angular_velocity as they were (Bullet works the angle out of its rotation matrix with
  // an atan2 per body). The default reads everything.
  virtual void read_motion(std::vector<BodyState>& out) const { read_states(out); }

  // Contacts that began during the last step().
  virtual const std::vector<ContactEvent>& contacts() const = 0;

  // The settings this run actually uses, after defaults and the scene's options.
  virtual std::vector<Setting> settings() const = 0;

  // Limits the engine imposed during the run so far (a speed clamp hit, float
  // precision lost far from the origin): one line each, empty when none.
  virtual std::vector<std::string> limits_hit() const { return {}; }

  // A guarantee the engine could not keep during the last step (core: its event cap
  // was reached, so impacts were no longer resolved exactly and bodies may have passed
  // through each other). Empty while every guarantee holds. The runner stops the run
  // at that step and reports it `diverged` with this text and the time.
  virtual std::string broken_guarantee() const { return {}; }
};

// The features of `scene` that `info` does not support, by name (empty: it can run).
std::vector<std::string> unsupported_features(const EngineInfo& info, const Scene& scene);

struct EngineFactory {
  EngineInfo info;
  std::function<std::unique_ptr<Engine>()> create;
  // Options that make this engine a converged reference (finest integrator, exact
  // impacts); empty when it cannot serve as one. The comparator uses the first engine
  // of the registry that can.
  EngineOptions reference_options;
};

}  // namespace physval
