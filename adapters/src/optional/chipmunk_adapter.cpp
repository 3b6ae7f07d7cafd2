// Chipmunk2D 7.0.3 (Debian libchipmunk-dev, cpFloat = double) behind physval's engine
// interface. The adapter runs the scene in Chipmunk's best honest setting, imposes
// physval's material rule and collision matrix through Chipmunk's own collision handler
// (begin / preSolve / separate), never sleeps, and writes down every choice. Measured
// traps of the raw library: adapters/probes/chipmunk_probe.cpp and the README.
#include "physval/adapters/chipmunk_adapter.hpp"

#include <chipmunk/chipmunk.h>
#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <memory>
#include <mutex>
#include <stdexcept>
#include <string>
#include <utility>

#include "external_forces.hpp"
#include "limit_monitor.hpp"
#include "scene_objects.hpp"

namespace physval {
namespace {

using adapter::ExternalForces;
using adapter::LimitMonitor;
using adapter::SceneObjects;

constexpr const char* kEngineName = "chipmunk";

std::string chipmunk_version() {
  return std::to_string(CP_VERSION_MAJOR) + "." + std::to_string(CP_VERSION_MINOR) + "." +
         std::to_string(CP_VERSION_RELEASE);
}

// The Debian build is a debug build: its first cpSpaceInit prints a banner on stdout,
// where physval writes its own output. Create (and free) the first space once, with
// stdout pointed at /dev/null, before any run needs one.
void silence_banner_once() {
  static std::once_flag once;
  std::call_once(once, [] {
    std::fflush(stdout);
    const int saved = ::dup(STDOUT_FILENO);
    const int null_fd = ::open("/dev/null", O_WRONLY);
    if (saved >= 0 && null_fd >= 0) ::dup2(null_fd, STDOUT_FILENO);
    if (null_fd >= 0) ::close(null_fd);
    cpSpaceFree(cpSpaceNew());
    std::fflush(stdout);
    if (saved >= 0) {
      ::dup2(saved, STDOUT_FILENO);
      ::close(saved);
    }
  });
}

// Chipmunk's own defaults, read from a fresh space.
struct ChipmunkDefaults {
  int iterations = 10;
  double collision_slop = 0.1;
  double collision_bias = 0.0;
  unsigned persistence = 3;
};
ChipmunkDefaults chipmunk_defaults() {
  silence_banner_once();
  cpSpace* s = cpSpaceNew();
  ChipmunkDefaults d{cpSpaceGetIterations(s), static_cast<double>(cpSpaceGetCollisionSlop(s)),
                     static_cast<double>(cpSpaceGetCollisionBias(s)),
                     static_cast<unsigned>(cpSpaceGetCollisionPersistence(s))};
  cpSpaceFree(s);
  return d;
}

std::vector<OptionSpec> chipmunk_options() {
  const ChipmunkDefaults d = chipmunk_defaults();
  return {
      {"solver_iterations", std::int64_t{d.iterations}, {},
       "Solver iterations per step (cpSpaceSetIterations). Chipmunk's default.", OptionRange::between(1, 100000)},
      {"collision_slop", 0.0, {},
       "Overlap (m) Chipmunk leaves uncorrected (cpSpaceSetCollisionSlop). Chipmunk's own is 0.1 m (the float "
       "0.1f), which let a ball rest 0.0126 m inside the floor (probe); physval's 0 keeps the scene's geometry.",
       OptionRange::at_least(0)},
      {"collision_bias", d.collision_bias, {},
       "Fraction of an overlap left uncorrected after 1 s (cpSpaceSetCollisionBias); the correction moves "
       "positions through a bias velocity, not the real velocity. Chipmunk's default pow(1 - 0.1, 60).",
       OptionRange::between(0, 1)},
      {"collision_persistence", std::int64_t{d.persistence}, {},
       "Steps a separated pair's contact data is kept for warm starting (cpSpaceSetCollisionPersistence). "
       "Chipmunk's default.",
       OptionRange::between(1, 1000)},
      {"fixed_rotation", true, {},
       "Bodies do not spin (lecture model, collision step 6): moment of inertia INFINITY. false: a circle has "
       "a uniform disc's moment 0.5 m r^2 (points never spin)."},
  };
}

std::vector<Feature> chipmunk_features() {
  // Not here: static friction above kinetic (Chipmunk has one coefficient), particles (not
  // mapped), precomputed surface normals (segments bounce off their geometry). Rolling
  // resistance: core's model of it for bodies that do not spin is Coulomb friction with
  // mu = c, which the preSolve handler imposes (fixed_rotation only).
  return {Feature::Circles,          Feature::Points,        Feature::StaticBodies,
          Feature::Walls,            Feature::Boxes,         Feature::Surfaces,
          Feature::UniformGravity,   Feature::NewtonianGravity, Feature::LinearDrag,
          Feature::QuadraticDrag,    Feature::Wind,          Feature::Thrust,
          Feature::Friction,         Feature::MaterialOverrides, Feature::CollisionMatrix,
          Feature::RollingFriction};
}

cpVect to_cp(Vec2 v) { return cpv(v.x, v.y); }
Vec2 from_cp(cpVect v) { return {static_cast<double>(v.x), static_cast<double>(v.y)}; }
std::string fmt(double v) { return option_value_to_string(OptionValue{v}); }

struct ChipmunkOptions {
  int iterations = 10;
  double collision_slop = 0.0;
  double collision_bias = 0.0;
  unsigned persistence = 3;
  bool fixed_rotation = true;
};

class ChipmunkEngine final : public Engine {
 public:
  explicit ChipmunkEngine(EngineInfo info) : info_(std::move(info)) {}
  ~ChipmunkEngine() override { teardown(); }
  ChipmunkEngine(const ChipmunkEngine&) = delete;
  ChipmunkEngine& operator=(const ChipmunkEngine&) = delete;

  const EngineInfo& info() const override { return info_; }
  void load(const Scene& scene) override;
  void step(double dt) override;
  double time() const override { return time_; }
  std::size_t body_count() const override { return scene_.bodies.size(); }
  BodyMeta body_meta(std::size_t i) const override { return objects_->body_meta(i); }
  void read_states(std::vector<BodyState>& out) const override;
  const std::vector<ContactEvent>& contacts() const override { return contacts_; }
  std::vector<Setting> settings() const override;
  std::vector<std::string> limits_hit() const override { return limits_.lines(); }

 private:
  static cpBool on_begin(cpArbiter* arb, cpSpace* space, cpDataPointer data);
  static cpBool on_pre_solve(cpArbiter* arb, cpSpace* space, cpDataPointer data);
  static void on_separate(cpArbiter* arb, cpSpace* space, cpDataPointer data);
  static ObjectRef ref_of(const cpShape* s) {
    return adapter::unpack(static_cast<std::uint64_t>(reinterpret_cast<std::uintptr_t>(cpShapeGetUserData(s))));
  }

  void read_options();
  void teardown();
  void build_bodies();
  void build_statics();
  cpShape* add_shape(cpShape* shape, ObjectRef ref, const StaticMaterial* m);
  void apply_external_forces();
  void destroy_bodies();
  void check_limits(double dt);

  EngineInfo info_;
  Scene scene_;
  ChipmunkOptions opt_;
  std::unique_ptr<SceneObjects> objects_;
  std::unique_ptr<ExternalForces> forces_;
  cpSpace* space_ = nullptr;
  std::vector<cpShape*> shapes_;
  std::vector<cpBody*> bodies_;           // scene order (static ones too); nullptr once destroyed
  std::vector<BodyState> final_states_;   // the last state of each destroyed body
  std::vector<double> tunnel_size_;
  double time_ = 0.0;
  double end_time_ = 0.0;
  std::vector<ContactEvent> contacts_;
  std::vector<std::uint32_t> destroyed_;
  // Touching shape pairs per physval pair: a circle rolling along a surface touches one
  // segment after another, but the pair (circle, surface) begins contact once.
  std::map<adapter::PairKey, int> touching_;
  LimitMonitor limits_;
  std::vector<BodyState> scratch_states_;
  std::vector<Vec2> scratch_forces_;
};

void ChipmunkEngine::read_options() {
  const OptionReader r(scene_, kEngineName, info_.options);
  const std::int64_t it = r.get_int("solver_iterations");
  if (it < 1 || it > 100000) throw std::invalid_argument("chipmunk.solver_iterations must be in [1, 100000]");
  opt_.iterations = static_cast<int>(it);
  opt_.collision_slop = r.get_double("collision_slop");
  opt_.collision_bias = r.get_double("collision_bias");
  const std::int64_t p = r.get_int("collision_persistence");
  if (p < 1 || p > 1000) throw std::invalid_argument("chipmunk.collision_persistence must be in [1, 1000]");
  opt_.persistence = static_cast<unsigned>(p);
  opt_.fixed_rotation = r.get_bool("fixed_rotation");
  if (!std::isfinite(opt_.collision_slop) || opt_.collision_slop < 0.0) {
    throw std::invalid_argument("chipmunk.collision_slop must be a finite length >= 0");
  }
  if (!(opt_.collision_bias >= 0.0 && opt_.collision_bias <= 1.0)) {
    throw std::invalid_argument("chipmunk.collision_bias must be in [0, 1]");
  }
}

void ChipmunkEngine::teardown() {
  if (space_ == nullptr) return;
  // Removing shapes calls separate for pairs still touching; the handler is gone first.
  for (cpShape* s : shapes_) {
    if (cpShapeGetSpace(s) != nullptr) cpSpaceRemoveShape(space_, s);
    cpShapeFree(s);
  }
  for (cpBody* b : bodies_) {
    if (b == nullptr) continue;
    if (cpBodyGetSpace(b) != nullptr) cpSpaceRemoveBody(space_, b);
    cpBodyFree(b);
  }
  cpSpaceFree(space_);
  space_ = nullptr;
  shapes_.clear();
  bodies_.clear();
}

void ChipmunkEngine::load(const Scene& scene) {
  teardown();
  scene_ = scene;
  if (const auto missing = unsupported_features(info_, scene_); !missing.empty()) {
    throw std::invalid_argument("chipmunk cannot model this scene: it uses " + missing.front());
  }
  read_options();
  adapter::require_fixed_rotation_for_rolling(scene_, opt_.fixed_rotation, "chipmunk");
  objects_ = std::make_unique<SceneObjects>(scene_);
  forces_ = std::make_unique<ExternalForces>(scene_);
  time_ = 0.0;
  contacts_.clear();
  destroyed_.clear();
  touching_.clear();
  limits_.clear();

  silence_banner_once();
  space_ = cpSpaceNew();
  cpSpaceSetGravity(space_, to_cp(scene_.world.gravity));
  cpSpaceSetIterations(space_, opt_.iterations);
  cpSpaceSetCollisionSlop(space_, opt_.collision_slop);
  cpSpaceSetCollisionBias(space_, opt_.collision_bias);
  cpSpaceSetCollisionPersistence(space_, opt_.persistence);
  cpSpaceSetDamping(space_, 1.0);                       // no damping
  cpSpaceSetSleepTimeThreshold(space_, INFINITY);       // sleeping off (Chipmunk's default)
  cpCollisionHandler* h = cpSpaceAddDefaultCollisionHandler(space_);
  h->beginFunc = &ChipmunkEngine::on_begin;
  h->preSolveFunc = &ChipmunkEngine::on_pre_solve;
  h->separateFunc = &ChipmunkEngine::on_separate;
  h->userData = this;
  build_statics();
  build_bodies();
}

cpShape* ChipmunkEngine::add_shape(cpShape* shape, ObjectRef ref, const StaticMaterial* m) {
  // Seeds only: preSolve replaces each contact's restitution and friction (Chipmunk's
  // own mixing is e1 e2, u1 u2).
  if (m != nullptr) {
    cpShapeSetElasticity(shape, m->restitution);
    cpShapeSetFriction(shape, m->friction);
  }
  cpShapeSetUserData(shape, reinterpret_cast<cpDataPointer>(static_cast<std::uintptr_t>(adapter::pack(ref))));
  cpSpaceAddShape(space_, shape);
  shapes_.push_back(shape);
  return shape;
}

void ChipmunkEngine::build_statics() {
  cpBody* ground = cpSpaceGetStaticBody(space_);
  for (std::size_t i = 0; i < scene_.walls.size(); ++i) {
    const WallDef& w = scene_.walls[i];
    if (!(length(w.to - w.from) > 0.0)) throw std::invalid_argument("wall '" + w.name + "' has zero length");
    // A two-sided segment of radius 0: circles touch it at their radius, ends included.
    add_shape(cpSegmentShapeNew(ground, to_cp(w.from), to_cp(w.to), 0.0), {ObjectRef::Kind::Wall, static_cast<std::uint32_t>(i)},
              &w.material);
  }
  for (std::size_t i = 0; i < scene_.boxes.size(); ++i) {
    const BoxDef& bx = scene_.boxes[i];
    if (!(bx.max.x > bx.min.x) || !(bx.max.y > bx.min.y)) throw std::invalid_argument("box '" + bx.name + "' has no area");
    add_shape(cpBoxShapeNew2(ground, cpBBNew(bx.min.x, bx.min.y, bx.max.x, bx.max.y), 0.0),
              {ObjectRef::Kind::Box, static_cast<std::uint32_t>(i)}, &bx.material);
  }
  for (std::size_t i = 0; i < scene_.surfaces.size(); ++i) {
    const SurfaceDef& s = scene_.surfaces[i];
    if (s.points.size() < 2) throw std::invalid_argument("surface '" + s.name + "' needs at least 2 points");
    const std::size_t n = s.points.size();
    for (std::size_t k = 0; k + 1 < n; ++k) {
      if (!(length(s.points[k + 1] - s.points[k]) > 0.0)) {
        throw std::invalid_argument("surface '" + s.name + "' repeats a point");
      }
      cpShape* seg = cpSegmentShapeNew(ground, to_cp(s.points[k]), to_cp(s.points[k + 1]), 0.0);
      // Neighbours smooth the joints: a circle sliding across one does not catch on it.
      // The end segments continue straight.
      const Vec2 prev = k > 0 ? s.points[k - 1] : s.points[0] - (s.points[1] - s.points[0]);
      const Vec2 next = k + 2 < n ? s.points[k + 2] : s.points[n - 1] + (s.points[n - 1] - s.points[n - 2]);
      cpSegmentShapeSetNeighbors(seg, to_cp(prev), to_cp(next));
      add_shape(seg, {ObjectRef::Kind::Surface, static_cast<std::uint32_t>(i)}, &s.material);
    }
  }
}

void ChipmunkEngine::build_bodies() {
  const std::size_t n = scene_.bodies.size();
  bodies_.assign(n, nullptr);
  final_states_.assign(n, BodyState{});
  auto radius = [&](std::size_t i) { return scene_.bodies[i].shape == ShapeKind::Point ? 0.0 : scene_.bodies[i].radius; };
  const bool any_static_shape = !scene_.walls.empty() || !scene_.boxes.empty() || !scene_.surfaces.empty();
  tunnel_size_.assign(n, std::numeric_limits<double>::infinity());
  for (std::size_t i = 0; i < n; ++i) {
    if (any_static_shape) tunnel_size_[i] = radius(i);   // walls may have no thickness
    for (std::size_t j = 0; j < n; ++j) {
      const double size = radius(i) + radius(j);
      if (j != i && size > 0.0) tunnel_size_[i] = std::min(tunnel_size_[i], size);
    }
  }
  for (std::size_t i = 0; i < n; ++i) {
    const BodyDef& b = scene_.bodies[i];
    const double r = radius(i);
    cpBody* body = nullptr;
    if (b.is_static) {
      body = cpBodyNewStatic();
    } else {
      // A point (r = 0) has no moment of inertia to spin with: it never spins.
      const double moment = opt_.fixed_rotation || r == 0.0 ? INFINITY : 0.5 * b.mass * r * r;
      body = cpBodyNew(b.mass, moment);
    }
    bodies_[i] = body;
    cpBodySetPosition(body, to_cp(b.position));
    cpBodySetAngle(body, b.angle);
    if (!b.is_static) {
      cpBodySetVelocity(body, to_cp(b.velocity));
      // With an infinite moment the body keeps this spin: no contact alters it.
      cpBodySetAngularVelocity(body, b.angular_velocity);
    }
    cpSpaceAddBody(space_, body);
    StaticMaterial m;
    m.restitution = b.restitution;
    m.friction = b.friction;
    add_shape(cpCircleShapeNew(body, r, cpvzero), {ObjectRef::Kind::Body, static_cast<std::uint32_t>(i)}, &m);
  }
}

cpBool ChipmunkEngine::on_begin(cpArbiter* arb, cpSpace* /*space*/, cpDataPointer data) {
  auto* self = static_cast<ChipmunkEngine*>(data);
  cpShape* sa = nullptr;
  cpShape* sb = nullptr;
  cpArbiterGetShapes(arb, &sa, &sb);
  ObjectRef a;
  ObjectRef b;
  if (!adapter::order_pair(ref_of(sa), ref_of(sb), a, b)) return cpFalse;
  const PairResponse r = self->objects_->response(a, b);
  if (!r.collide && !r.event) return cpFalse;   // "ignore": no contact, no event, until they part
  if (++self->touching_[adapter::pair_key(a, b)] == 1) {
    if (r.event) self->contacts_.push_back({a, b, self->end_time_});
    // Destroyed after the step: Chipmunk resolves this step's bounce first, as the matrix says.
    if (r.destroy_first && SceneObjects::destructible(a)) self->destroyed_.push_back(a.index);
    if (r.destroy_second && SceneObjects::destructible(b)) self->destroyed_.push_back(b.index);
  }
  // An "event" pair is reported and then passes through: Chipmunk ignores it until it separates.
  return r.collide ? cpTrue : cpFalse;
}

cpBool ChipmunkEngine::on_pre_solve(cpArbiter* arb, cpSpace* /*space*/, cpDataPointer data) {
  auto* self = static_cast<ChipmunkEngine*>(data);
  cpShape* sa = nullptr;
  cpShape* sb = nullptr;
  cpArbiterGetShapes(arb, &sa, &sb);
  const ObjectRef a = ref_of(sa);
  const ObjectRef b = ref_of(sb);
  // physval's rule replaces Chipmunk's e1 e2, u1 u2 on every contact, every step.
  cpArbiterSetRestitution(arb, self->objects_->pair_material(a, b).restitution);
  cpArbiterSetFriction(arb, self->objects_->contact_friction(a, b));   // rolling_friction: mu = c
  return cpTrue;
}

void ChipmunkEngine::on_separate(cpArbiter* arb, cpSpace* /*space*/, cpDataPointer data) {
  auto* self = static_cast<ChipmunkEngine*>(data);
  cpShape* sa = nullptr;
  cpShape* sb = nullptr;
  cpArbiterGetShapes(arb, &sa, &sb);
  ObjectRef a;
  ObjectRef b;
  if (!adapter::order_pair(ref_of(sa), ref_of(sb), a, b)) return;
  const PairResponse r = self->objects_->response(a, b);
  if (!r.collide && !r.event) return;   // begin refused it: never counted
  auto it = self->touching_.find(adapter::pair_key(a, b));
  if (it != self->touching_.end() && --it->second <= 0) self->touching_.erase(it);
}

void ChipmunkEngine::apply_external_forces() {
  if (!forces_->active()) return;
  read_states(scratch_states_);
  forces_->compute(scratch_states_, scratch_forces_);
  for (std::size_t i = 0; i < bodies_.size(); ++i) {
    if (bodies_[i] == nullptr || scene_.bodies[i].is_static) continue;
    // Chipmunk integrates x += dt v first, then v += dt (g + F / m): the force enters
    // this step's velocity. Set, not added: nothing else applies forces.
    cpBodySetForce(bodies_[i], to_cp(scratch_forces_[i]));
  }
}

void ChipmunkEngine::step(double dt) {
  if (!(dt > 0.0) || !std::isfinite(dt)) throw std::invalid_argument("chipmunk: step dt must be > 0");
  apply_external_forces();
  contacts_.clear();
  end_time_ = time_ + dt;
  cpSpaceStep(space_, dt);
  time_ += dt;
  destroy_bodies();
  check_limits(dt);
}

void ChipmunkEngine::destroy_bodies() {
  std::sort(destroyed_.begin(), destroyed_.end());
  destroyed_.erase(std::unique(destroyed_.begin(), destroyed_.end()), destroyed_.end());
  for (std::uint32_t i : destroyed_) {
    if (i >= bodies_.size() || bodies_[i] == nullptr) continue;
    cpBody* b = bodies_[i];
    final_states_[i] = {from_cp(cpBodyGetPosition(b)), from_cp(cpBodyGetVelocity(b)), cpBodyGetAngle(b),
                        cpBodyGetAngularVelocity(b), false};
    for (cpShape*& s : shapes_) {
      if (cpShapeGetBody(s) == b && cpShapeGetSpace(s) != nullptr) cpSpaceRemoveShape(space_, s);
    }
    if (cpBodyGetSpace(b) != nullptr) cpSpaceRemoveBody(space_, b);
    bodies_[i] = nullptr;
    cpBodyFree(b);
  }
  destroyed_.clear();
}

void ChipmunkEngine::check_limits(double dt) {
  for (std::size_t i = 0; i < bodies_.size(); ++i) {
    const cpBody* b = bodies_[i];
    if (b == nullptr) continue;
    const std::string& name = scene_.bodies[i].name;
    const Vec2 p = from_cp(cpBodyGetPosition(b));
    const double reach = std::max(std::fabs(p.x), std::fabs(p.y));
    if (adapter::coordinate_spacing(reach, Precision::Float64) > adapter::kPositionResolutionLimit) {
      limits_.hit("float_resolution", time_, [&] {
        return "body '" + name + "' is " + fmt(reach) + " m from the origin, where double positions are " +
               fmt(adapter::coordinate_spacing(reach, Precision::Float64)) + " m apart (limit 1e-4 m)";
      });
    }
    if (scene_.bodies[i].is_static) continue;
    const double travel = cpvlength(cpBodyGetVelocity(b)) * dt;
    if (travel > tunnel_size_[i]) {
      limits_.hit("discrete_collision", time_, [&] {
        return "body '" + name + "' moved " + fmt(travel) + " m in one step, more than the " + fmt(tunnel_size_[i]) +
               " m (its radius plus the thinnest thing it can meet) that discrete collision needs; Chipmunk "
               "has no continuous collision and can miss contacts";
      });
    }
  }
}

void ChipmunkEngine::read_states(std::vector<BodyState>& out) const {
  out.resize(bodies_.size());
  for (std::size_t i = 0; i < bodies_.size(); ++i) {
    const cpBody* b = bodies_[i];
    if (b == nullptr) {
      out[i] = final_states_[i];
      continue;
    }
    out[i] = {from_cp(cpBodyGetPosition(b)), from_cp(cpBodyGetVelocity(b)), cpBodyGetAngle(b),
              cpBodyGetAngularVelocity(b), true};
  }
}

std::vector<Setting> ChipmunkEngine::settings() const {
  auto b = [](bool v) { return std::string(v ? "true" : "false"); };
  return {
      {"version", chipmunk_version()},
      {"runtime_version", cpVersionString},
      {"precision", "float64 (cpFloat = double)"},
      {"build", "Debian's debug build: runtime assertions on (a failed one aborts); its stdout banner is discarded"},
      {"step", "one cpSpaceStep(dt) per physval step: x += dt (v + v_bias), collide, v += dt (g + F / m), solve"},
      {"integration", "positions advance with the velocity the step starts with (explicit Euler in position): a free "
                      "fall lags the closed form by g dt t / 2"},
      {"solver_iterations", std::to_string(opt_.iterations)},
      {"collision_slop", fmt(opt_.collision_slop)},
      {"collision_bias", fmt(opt_.collision_bias)},
      {"collision_persistence", std::to_string(opt_.persistence)},
      {"fixed_rotation", b(opt_.fixed_rotation)},
      {"sleep_time_threshold", "INFINITY (sleeping off)"},
      {"damping", "0 (cpSpaceSetDamping(space, 1): Chipmunk's damping is the fraction of velocity kept per second, 1 keeps it all)"},
      {"restitution_threshold", "none: Chipmunk has no restitution threshold (bounce = e v_n at every speed)"},
      {"continuous_collision", "none: Chipmunk 7 has no time of impact; missed contacts are reported in limits_hit"},
      {"material_rule",
       "default collision handler preSolve: cpArbiterSetRestitution min(e1, e2), cpArbiterSetFriction sqrt(f1 f2), "
       "per-pair overrides (Chipmunk's own: e1 e2, u1 u2)"},
      {"rolling_friction", "a pair with rolling_friction c > 0 gets contact friction mu = c (core's model for bodies "
                           "that do not spin); needs fixed_rotation"},
      {"uniform_gravity", "cpSpace gravity"},
      {"external_forces", "drag and wind, thrust, Newtonian gravity: physval forces.hpp, cpBodySetForce every step"},
      {"external_forces_evaluated", "at the start of each step, from the state the previous step left"},
      {"mass", "cpBodyNew(m, moment): moment INFINITY with fixed_rotation (and for points), else 0.5 m r^2"},
      {"circles", "cpCircleShape"},
      {"points", "cpCircleShape of radius 0"},
      {"static_bodies", "cpBodyNewStatic with a cpCircleShape"},
      {"walls", "two-sided cpSegmentShape of radius 0"},
      {"boxes", "cpBoxShapeNew2 of the scene's box, radius 0 (sharp corners)"},
      {"surfaces", "one cpSegmentShape of radius 0 per segment, neighbours set (cpSegmentShapeSetNeighbors); two-sided"},
      {"collision_matrix",
       "default collision handler: ignore: begin returns false, no event; event: begin records it and returns false "
       "(passes through until separated); destroy: removed after the step"},
      {"contact_events", "handler begin, once per physval pair, stamped with the end of the step (Chipmunk collides "
                         "the positions this step reached)"},
  };
}

}  // namespace

EngineFactory chipmunk_engine_factory() {
  EngineFactory f;
  f.info.name = kEngineName;
  f.info.version = chipmunk_version();
  f.info.precision = Precision::Float64;
  f.info.summary = "Chipmunk2D " + chipmunk_version() + " (double): circles, segments, boxes";
  f.info.features = chipmunk_features();
  f.info.options = chipmunk_options();
  f.create = [info = f.info]() -> std::unique_ptr<Engine> { return std::make_unique<ChipmunkEngine>(info); };
  return f;
}

}  // namespace physval
