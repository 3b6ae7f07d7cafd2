// The plain description of a scenario: definition structs with defaults, the way
// b2WorldDef is. A scene is data first; engines (core and the adapters) build their
// own objects from it. The TOML loader in validation/ fills these structs; tests and
// benchmarks may build them directly in code.
//
// Units are SI (m, kg, s), angles in radians. Every default here is documented in
// the README's scenario reference; change both together.
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <variant>
#include <vector>

#include "physval/core/vec2.hpp"

namespace physval {

enum class ShapeKind : std::uint8_t { Circle, Point };

// What a thrust table maps: a(speed[, gear]) in m/s^2, piecewise linear between
// samples and clamped at the ends, times the throttle, along the body's heading
// (its angle): a_x = cos(angle) a, a_y = sin(angle) a.
struct ThrustDef {
  std::vector<double> speeds;               // strictly increasing, m/s (|v| of the body)
  std::vector<double> gears;                // strictly increasing; empty: one-input table
  std::vector<std::vector<double>> accel;   // [gear row][speed column], m/s^2
  double throttle = 1.0;                    // the lecture's pedal pressure
  double gear = 0.0;                        // the gear the body is in (interpolated)
  bool enabled() const { return !speeds.empty(); }
};

struct BodyDef {
  std::string name;
  ShapeKind shape = ShapeKind::Circle;
  double radius = 0.0;            // circles: > 0; points: 0
  double mass = 1.0;              // > 0; ignored for static bodies (infinite mass)
  bool is_static = false;         // immovable, infinite mass
  Vec2 position;
  Vec2 velocity;
  double angle = 0.0;             // heading, rad (thrust acts along it)
  double angular_velocity = 0.0;  // rad/s; core bodies do not spin (lecture step 6)
  double restitution = 1.0;       // coefficient of restitution e
  double friction = 0.0;          // kinetic Coulomb coefficient mu_k
  double static_friction = 0.0;   // mu_s >= mu_k (the loader defaults it to friction)
  double rolling_friction = 0.0;  // rolling-resistance coefficient (force = c N)
  double drag_linear = 0.0;       // N per m/s: F = -k1 (v - wind)
  double drag_quadratic = 0.0;    // N per (m/s)^2: F = -k2 |v - wind| (v - wind)
  std::string group;              // collision-matrix group ("" = default group)
  ThrustDef thrust;
  int line = 0;                   // source line in the scenario file (0: built in code)
};

// Material of a static barrier. Static barriers have infinite mass.
struct StaticMaterial {
  double restitution = 1.0;
  double friction = 0.0;
  double static_friction = 0.0;   // loader defaults it to friction
  double rolling_friction = 0.0;
  std::string group;
};

// An immovable segment. Circles collide with it on both sides and at its end points.
struct WallDef {
  std::string name;
  Vec2 from;
  Vec2 to;
  StaticMaterial material;
  int line = 0;
};

// An immovable axis-aligned box (the lecture's "point inside a box" test).
struct BoxDef {
  std::string name;
  Vec2 min;
  Vec2 max;
  StaticMaterial material;
  int line = 0;
};

// A precomputed surface (the lecture's pinball table): an open polyline of collision
// points. With `normals`, each point carries the surface normal a bounce uses
// (interpolated along each segment: a smooth bumper from a few points); without them
// the surface is a plain polyline and each segment bounces off its geometric normal.
struct SurfaceDef {
  std::string name;
  std::vector<Vec2> points;    // at least 2
  std::vector<Vec2> normals;   // unit, one per point; empty: geometric normals
  StaticMaterial material;
  int line = 0;
};

// A per-pair material override, by body or static-object name.
struct MaterialOverride {
  std::string a;
  std::string b;
  std::optional<double> restitution;
  std::optional<double> friction;
  std::optional<double> static_friction;
  std::optional<double> rolling_friction;
};

enum class CollisionResponse : std::uint8_t {
  Bounce,       // ordinary collision (the default for every pair)
  DestroyA,     // the object of group a is destroyed, b unaffected
  DestroyB,
  DestroyBoth,
  Ignore,       // pass through, no event
  Event,        // pass through, but a contact event is raised (a prize picked up)
};

// One cell of the collision matrix: what happens between group a and group b.
struct CollisionRule {
  std::string a;
  std::string b;
  CollisionResponse response = CollisionResponse::Bounce;
};

enum class EmitterMode : std::uint8_t { Explode, Trail };

// Particles: point masses with a lifetime, spawned around a parent body.
struct EmitterDef {
  std::string name;
  std::string parent;            // body name
  EmitterMode mode = EmitterMode::Explode;
  double at = 0.0;               // explode: the time the parent explodes (it is destroyed)
  double rate = 0.0;             // trail: particles per second while the parent lives
  int count = 0;                 // explode: how many particles
  double speed = 1.0;            // spread: velocities uniform in a disc of this radius
                                 // around the parent's velocity, m/s
  double lifetime = 1.0;         // s; a particle is destroyed at this age
  double mass = 1e-3;            // kg per particle
  bool destroy_on_collision = true;
  bool gravity = true;           // particles feel the uniform field
  std::uint64_t seed = 1;        // fixed seed: runs are repeatable
  int line = 0;
};

struct WorldDef {
  Vec2 gravity;                  // uniform field, m/s^2
  bool newtonian = false;        // F = G m1 m2 / (D^2 + softening^2) between all bodies
  double G = 6.674e-11;          // N m^2 kg^-2
  double softening = 0.0;        // m
  Vec2 wind;                     // velocity drag pulls towards, m/s
};

// An engine-specific option value from the scenario's [core], [box2d], [bullet]
// tables. Each engine declares its options (name, type, default, doc); the loader
// checks the scenario against those declarations.
using OptionValue = std::variant<bool, std::int64_t, double, std::string>;
using EngineOptions = std::map<std::string, OptionValue>;

// Which conserved quantities a scenario declares explicitly (overriding physval's
// derivation from the scene's contents).
struct ConservationOverride {
  std::optional<bool> energy;
  std::optional<bool> linear_momentum;
  std::optional<bool> angular_momentum;
};

struct ExpectedContact {
  std::string a;
  std::string b;
  double time = 0.0;
  std::optional<double> tolerance;   // s
};

struct ExpectedFinal {
  std::string body;
  std::optional<Vec2> position;
  std::optional<Vec2> velocity;
  std::optional<double> tolerance;   // absolute, in m or m/s
};

struct ExpectedApex {
  std::string body;
  double height = 0.0;               // the highest y reached, m
  std::optional<double> time;        // when it is first reached, s
  std::optional<double> tolerance;   // m (and s for the time)
};

struct ExpectedPeriod {
  std::string body;
  Vec2 around;                       // the point it revolves around
  double period = 0.0;               // s
  std::optional<double> tolerance;   // relative
};

struct Expectations {
  std::optional<ExpectedContact> first_contact;
  std::vector<ExpectedContact> contacts;   // in order, each matched by pair
  std::vector<ExpectedFinal> final_states;
  std::vector<ExpectedApex> apex;
  std::vector<ExpectedPeriod> period;
  bool empty() const {
    return !first_contact && contacts.empty() && final_states.empty() && apex.empty() &&
           period.empty();
  }
};

// Gate limits: metric name -> the largest value that passes. "" holds the limits for
// every engine; an engine's own table overrides per metric.
struct GateDef {
  std::map<std::string, double> limits;
  std::map<std::string, std::map<std::string, double>> per_engine;
};

struct Scene {
  std::string name;
  std::string description;
  std::string source_file;        // where it was loaded from ("" if built in code)
  double duration = 1.0;          // s, > 0
  double dt = 1.0 / 60.0;         // s, > 0
  double sample_interval = 0.0;   // s between state samples; 0: the loader picks
  std::vector<std::string> engines;   // restrict to these engines (empty: all)

  WorldDef world;
  std::vector<BodyDef> bodies;
  std::vector<WallDef> walls;
  std::vector<BoxDef> boxes;
  std::vector<SurfaceDef> surfaces;
  std::vector<MaterialOverride> materials;
  std::vector<CollisionRule> collision_matrix;
  std::vector<EmitterDef> emitters;

  std::map<std::string, EngineOptions> engine_options;   // "core", "box2d", "bullet"
  ConservationOverride conserves;
  Expectations expect;
  GateDef gate;

  // A run takes steps() steps of dt, the last one shortened so that it ends exactly
  // at `duration`: steps() = ceil(duration / dt) (a remainder under 1e-9 dt is round-off).
  // Never wraps: a duration / dt beyond kMaxSteps (or NaN) saturates at kMaxSteps + 1,
  // which still fits an int, and the loader and the --duration/--dt overrides refuse such
  // a scene with exit 2 (scene_steps_error).
  int steps() const;
  static constexpr int kMaxSteps = 1'000'000'000;
  double last_step() const;   // the length of the last step, in (0, dt]
  // Index of the body with this name, or -1.
  int body_index(const std::string& body_name) const;
};

// Physval's material rule, shared by every engine: the pair's restitution is the
// smaller of the two, its friction coefficients the geometric mean, unless the
// scenario overrides the pair by name.
struct PairMaterial {
  double restitution = 1.0;
  double friction = 0.0;
  double static_friction = 0.0;
  double rolling_friction = 0.0;
};
struct MaterialView {
  const std::string& name;
  double restitution;
  double friction;
  double static_friction;
  double rolling_friction;
};

// Empty when the scene's step count is within Scene::kMaxSteps; else a message saying why not.
std::string scene_steps_error(const Scene& s);

MaterialView material_of(const BodyDef& b);
MaterialView material_of(const std::string& name, const StaticMaterial& m);
PairMaterial combine_materials(const Scene& scene, const MaterialView& a, const MaterialView& b);

// What the collision matrix says happens when `first` (group g1) meets `second`
// (group g2). Destroy responses resolve the collision as a bounce first, then remove
// the named objects (a ball bounces off the brick it destroys). Pairs with no rule
// bounce. A static object is never destroyed by a "destroy" aimed at it unless it is
// a body (walls, boxes and surfaces are permanent).
struct PairResponse {
  bool collide = true;          // resolve the impact (bounce)
  bool event = true;            // raise a contact event
  bool destroy_first = false;
  bool destroy_second = false;
};
PairResponse response_between(const Scene& scene, const std::string& group_first,
                              const std::string& group_second);

// The models a scene switches on. Engines declare which they support; a run on an
// engine that lacks one the scene uses is "unsupported", the feature named.
enum class Feature : std::uint8_t {
  Circles,
  Points,
  StaticBodies,
  Walls,
  Boxes,
  Surfaces,
  UniformGravity,
  NewtonianGravity,
  LinearDrag,
  QuadraticDrag,
  Wind,
  Thrust,
  Friction,
  StaticFriction,      // mu_s > mu_k somewhere
  RollingFriction,
  MaterialOverrides,
  CollisionMatrix,
  Particles,
  SurfaceNormals,      // a surface with precomputed (interpolated) response normals
  Count
};
const char* feature_name(Feature f);
std::vector<Feature> scene_features(const Scene& scene);

}  // namespace physval
