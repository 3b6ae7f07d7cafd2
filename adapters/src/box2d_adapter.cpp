// Box2D 2.4.1 behind physval's engine interface. Box2D is a float engine with its
// constants compiled in (shared/engines.md); this adapter runs the scene in Box2D's
// best honest setting, writes down every choice in settings(), and reports the limits
// Box2D imposes (speed and spin clamps, float resolution) through limits_hit().
#include "physval/adapters/box2d_adapter.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <sstream>
#include <stdexcept>

#include "box2d_contact_listener.hpp"
#include "box2d_includes.hpp"
#include "external_forces.hpp"
#include "limit_monitor.hpp"
#include "scene_objects.hpp"

namespace physval {
namespace {

using adapter::ExternalForces;
using adapter::LimitMonitor;
using adapter::SceneObjects;

constexpr const char* kEngineName = "box2d";
// The Debian package is 2.4.1; the library's own b2_version still says 2.4.0.
constexpr const char* kPackageVersion = "2.4.1";

std::vector<OptionSpec> box2d_options() {
  return {
      {"velocity_iterations", std::int64_t{8}, {},
       "Velocity solver iterations per step (b2World::Step). 8 is Box2D's recommendation.",
       OptionRange::between(1, 100000)},
      {"position_iterations", std::int64_t{3}, {},
       "Position (overlap) solver iterations per step (b2World::Step). 3 is Box2D's recommendation.",
       OptionRange::between(0, 100000)},
      {"continuous", true, {},
       "Continuous collision (time of impact) of dynamic bodies against static ones "
       "(b2World::SetContinuousPhysics). Box2D's default."},
      {"bullet", false, {},
       "Make every dynamic body a Box2D bullet: continuous collision against dynamic bodies too. "
       "Off (Box2D's default): collisions between moving bodies are discrete."},
      {"warm_starting", true, {}, "Start each step's solver from the last step's impulses. Box2D's default."},
      {"restitution_threshold", 0.0, {},
       "Approach speed (m/s) below which a contact does not bounce. Box2D's own default is 1 m/s; "
       "physval's 0 keeps an elastic scene elastic.",
       OptionRange::at_least(0)},
      {"fixed_rotation", true, {},
       "Bodies do not spin (lecture model, collision step 6): b2BodyDef::fixedRotation. false: a "
       "circle has a uniform disc's inertia 0.5 m r^2 and friction can spin it."},
  };
}

std::vector<Feature> box2d_features() {
  // Not here: static friction distinct from kinetic (Box2D has one coefficient),
  // rolling resistance (Box2D 2.4.1 has none), particles (not mapped).
  return {Feature::Circles,          Feature::Points,        Feature::StaticBodies,
          Feature::Walls,            Feature::Boxes,         Feature::Surfaces,
          Feature::UniformGravity,   Feature::NewtonianGravity, Feature::LinearDrag,
          Feature::QuadraticDrag,    Feature::Wind,          Feature::Thrust,
          Feature::Friction,         Feature::MaterialOverrides, Feature::CollisionMatrix};
}

b2Vec2 to_b2(Vec2 v) { return {static_cast<float>(v.x), static_cast<float>(v.y)}; }
Vec2 from_b2(b2Vec2 v) { return {static_cast<double>(v.x), static_cast<double>(v.y)}; }

// Settings print numbers the way option values print (17 significant digits), so a
// setting reads back as the option that produced it.
std::string fmt(double v) { return option_value_to_string(OptionValue{v}); }

struct Box2DOptions {
  int velocity_iterations = 8;
  int position_iterations = 3;
  bool continuous = true;
  bool bullet = false;
  bool warm_starting = true;
  float restitution_threshold = 0.0f;
  bool fixed_rotation = true;
};

class Box2DEngine final : public Engine {
 public:
  explicit Box2DEngine(EngineInfo info) : info_(std::move(info)) {}

  const EngineInfo& info() const override { return info_; }
  void load(const Scene& scene) override;
  void step(double dt) override;
  double time() const override { return time_; }
  std::size_t body_count() const override { return scene_.bodies.size(); }
  BodyMeta body_meta(std::size_t i) const override;
  void read_states(std::vector<BodyState>& out) const override;
  const std::vector<ContactEvent>& contacts() const override { return contacts_; }
  std::vector<Setting> settings() const override;
  std::vector<std::string> limits_hit() const override { return limits_.lines(); }

 private:
  void read_options();
  void build_bodies();
  void build_statics();
  void apply_external_forces();
  void destroy_bodies();
  void check_limits(double dt);

  EngineInfo info_;
  Scene scene_;
  Box2DOptions opt_;
  std::unique_ptr<SceneObjects> objects_;
  std::unique_ptr<ExternalForces> forces_;
  std::unique_ptr<adapter::Box2DContactListener> listener_;
  std::unique_ptr<b2World> world_;
  std::vector<b2Body*> bodies_;          // scene order; nullptr once destroyed
  std::vector<BodyState> final_states_;  // the last state of each destroyed body
  // How far a dynamic body may move in one step before Box2D's discrete collision
  // between moving bodies can miss a contact: its radius plus the smallest other moving
  // body's (infinite: no other moving body it could meet). Static shapes are swept.
  std::vector<double> tunnel_size_;
  double time_ = 0.0;
  std::vector<ContactEvent> contacts_;
  LimitMonitor limits_;
  std::vector<BodyState> scratch_states_;
  std::vector<Vec2> scratch_forces_;
};

void Box2DEngine::read_options() {
  const OptionReader r(scene_, kEngineName, info_.options);
  const std::int64_t vel = r.get_int("velocity_iterations");
  const std::int64_t pos = r.get_int("position_iterations");
  if (vel < 1 || vel > 1000) throw std::invalid_argument("box2d.velocity_iterations must be in [1, 1000]");
  if (pos < 0 || pos > 1000) throw std::invalid_argument("box2d.position_iterations must be in [0, 1000]");
  opt_.velocity_iterations = static_cast<int>(vel);
  opt_.position_iterations = static_cast<int>(pos);
  opt_.continuous = r.get_bool("continuous");
  opt_.bullet = r.get_bool("bullet");
  opt_.warm_starting = r.get_bool("warm_starting");
  const double threshold = r.get_double("restitution_threshold");
  if (!(threshold >= 0.0) || !std::isfinite(threshold)) {
    throw std::invalid_argument("box2d.restitution_threshold must be a finite speed >= 0");
  }
  opt_.restitution_threshold = static_cast<float>(threshold);
  opt_.fixed_rotation = r.get_bool("fixed_rotation");
}

void Box2DEngine::load(const Scene& scene) {
  // Box2D objects point into the world: rebuild everything from scratch.
  world_.reset();
  listener_.reset();
  scene_ = scene;
  if (const auto missing = unsupported_features(info_, scene_); !missing.empty()) {
    throw std::invalid_argument("box2d cannot model this scene: it uses " + missing.front());
  }
  read_options();
  objects_ = std::make_unique<SceneObjects>(scene_);
  forces_ = std::make_unique<ExternalForces>(scene_);
  listener_ = std::make_unique<adapter::Box2DContactListener>(*objects_, opt_.restitution_threshold);

  world_ = std::make_unique<b2World>(to_b2(scene_.world.gravity));
  world_->SetAllowSleeping(false);   // a slow body must never freeze (engines.md)
  world_->SetWarmStarting(opt_.warm_starting);
  world_->SetContinuousPhysics(opt_.continuous);
  world_->SetSubStepping(false);
  world_->SetContactListener(listener_.get());
  world_->SetContactFilter(listener_.get());

  time_ = 0.0;
  contacts_.clear();
  limits_.clear();
  build_statics();
  build_bodies();
}

void Box2DEngine::build_bodies() {
  bodies_.assign(scene_.bodies.size(), nullptr);
  final_states_.assign(scene_.bodies.size(), BodyState{});
  auto radius = [&](std::size_t i) {
    return scene_.bodies[i].shape == ShapeKind::Point ? 0.0 : scene_.bodies[i].radius;
  };
  tunnel_size_.assign(scene_.bodies.size(), std::numeric_limits<double>::infinity());
  for (std::size_t i = 0; i < scene_.bodies.size(); ++i) {
    for (std::size_t j = 0; j < scene_.bodies.size(); ++j) {
      const double size = radius(i) + radius(j);
      if (j != i && !scene_.bodies[j].is_static && size > 0.0) tunnel_size_[i] = std::min(tunnel_size_[i], size);
    }
  }
  for (std::size_t i = 0; i < scene_.bodies.size(); ++i) {
    const BodyDef& b = scene_.bodies[i];
    b2BodyDef bd;
    bd.type = b.is_static ? b2_staticBody : b2_dynamicBody;
    bd.position = to_b2(b.position);
    bd.angle = static_cast<float>(b.angle);
    if (!b.is_static) {
      bd.linearVelocity = to_b2(b.velocity);
      // With fixed rotation the body keeps this spin unchanged: no contact alters it.
      bd.angularVelocity = static_cast<float>(b.angular_velocity);
    }
    bd.allowSleep = false;
    bd.awake = true;
    bd.fixedRotation = opt_.fixed_rotation;
    bd.bullet = opt_.bullet && !b.is_static;
    bd.userData.pointer = static_cast<uintptr_t>(i);
    b2Body* body = world_->CreateBody(&bd);

    // A point is a circle of radius 0: it meets circles at their radius and static
    // shapes at Box2D's skin (b2_polygonRadius).
    b2CircleShape circle;
    circle.m_radius = b.shape == ShapeKind::Point ? 0.0f : static_cast<float>(b.radius);
    b2FixtureDef fd;
    fd.shape = &circle;
    fd.density = 0.0f;   // the scene's mass is set exactly below
    // The material rule is imposed per contact in PreSolve; these only seed new contacts.
    fd.friction = static_cast<float>(b.friction);
    fd.restitution = static_cast<float>(b.restitution);
    fd.restitutionThreshold = opt_.restitution_threshold;
    fd.userData.pointer = static_cast<uintptr_t>(adapter::pack({ObjectRef::Kind::Body, static_cast<std::uint32_t>(i)}));
    body->CreateFixture(&fd);
    if (!b.is_static) {
      b2MassData md;
      md.mass = static_cast<float>(b.mass);
      md.center.SetZero();
      md.I = static_cast<float>(0.5 * b.mass * b.radius * b.radius);   // uniform disc
      body->SetMassData(&md);
    }
    bodies_[i] = body;
  }
}

void Box2DEngine::build_statics() {
  b2BodyDef bd;   // one static body at the origin carries every barrier
  b2Body* ground = world_->CreateBody(&bd);
  auto add = [&](const b2Shape& shape, ObjectRef ref, const StaticMaterial& m) {
    b2FixtureDef fd;
    fd.shape = &shape;
    fd.friction = static_cast<float>(m.friction);
    fd.restitution = static_cast<float>(m.restitution);
    fd.restitutionThreshold = opt_.restitution_threshold;
    fd.userData.pointer = static_cast<uintptr_t>(adapter::pack(ref));
    ground->CreateFixture(&fd);
  };
  for (std::size_t i = 0; i < scene_.walls.size(); ++i) {
    const WallDef& w = scene_.walls[i];
    if (length(w.to - w.from) <= static_cast<double>(b2_linearSlop)) {
      throw std::invalid_argument("wall '" + w.name + "' is shorter than Box2D's linear slop (0.005 m)");
    }
    b2EdgeShape edge;   // two-sided; Box2D thickens it by its skin b2_polygonRadius
    edge.SetTwoSided(to_b2(w.from), to_b2(w.to));
    add(edge, {ObjectRef::Kind::Wall, static_cast<std::uint32_t>(i)}, w.material);
  }
  for (std::size_t i = 0; i < scene_.boxes.size(); ++i) {
    const BoxDef& bx = scene_.boxes[i];
    const Vec2 half = 0.5 * (bx.max - bx.min);
    if (!(half.x > 0.0) || !(half.y > 0.0)) throw std::invalid_argument("box '" + bx.name + "' has no area");
    b2PolygonShape box;
    box.SetAsBox(static_cast<float>(half.x), static_cast<float>(half.y), to_b2(0.5 * (bx.min + bx.max)), 0.0f);
    add(box, {ObjectRef::Kind::Box, static_cast<std::uint32_t>(i)}, bx.material);
  }
  for (std::size_t i = 0; i < scene_.surfaces.size(); ++i) {
    const SurfaceDef& s = scene_.surfaces[i];
    if (s.points.size() < 2) throw std::invalid_argument("surface '" + s.name + "' needs at least 2 points");
    // Box2D 2.4.1 chains are one-sided: a circle collides on the right of the chain's
    // direction. A surface faces the left of its point order (scenes with precomputed
    // normals are unsupported), so the chain runs backwards to face that side.
    int left = 0;
    int right = 0;
    for (std::size_t k = 0; k + 1 < s.points.size(); ++k) {
      const Vec2 d = s.points[k + 1] - s.points[k];
      if (length(d) <= static_cast<double>(b2_linearSlop)) {
        throw std::invalid_argument("surface '" + s.name + "' has points closer than Box2D's linear slop (0.005 m)");
      }
      const Vec2 n = s.normals.size() == s.points.size() ? s.normals[k] + s.normals[k + 1] : perp(d);
      (dot(n, perp(d)) >= 0.0 ? left : right) += 1;
    }
    if (left > 0 && right > 0) {
      throw std::invalid_argument("surface '" + s.name +
                                  "': its normals face both sides; a Box2D chain is one-sided");
    }
    std::vector<b2Vec2> v;
    for (const Vec2& p : s.points) v.push_back(to_b2(p));
    if (left > 0) std::reverse(v.begin(), v.end());
    // Ghost vertices continue the end segments straight, so the ends are smooth.
    const b2Vec2 prev = v[0] + (v[0] - v[1]);
    const b2Vec2 next = v[v.size() - 1] + (v[v.size() - 1] - v[v.size() - 2]);
    b2ChainShape chain;
    chain.CreateChain(v.data(), static_cast<int32>(v.size()), prev, next);
    add(chain, {ObjectRef::Kind::Surface, static_cast<std::uint32_t>(i)}, s.material);
  }
}

void Box2DEngine::apply_external_forces() {
  if (!forces_->active()) return;
  read_states(scratch_states_);
  forces_->compute(scratch_states_, scratch_forces_);
  for (std::size_t i = 0; i < bodies_.size(); ++i) {
    if (bodies_[i] == nullptr || scene_.bodies[i].is_static) continue;
    // Box2D integrates v += dt (g + F / m) then x += dt v: semi-implicit Euler.
    bodies_[i]->ApplyForceToCenter(to_b2(scratch_forces_[i]), false);
  }
}

void Box2DEngine::step(double dt) {
  if (!(dt > 0.0) || !std::isfinite(dt)) throw std::invalid_argument("box2d: step dt must be > 0");
  apply_external_forces();
  listener_->begin_step(time_ + dt);
  world_->Step(static_cast<float>(dt), opt_.velocity_iterations, opt_.position_iterations);
  time_ += dt;
  contacts_ = listener_->events();
  destroy_bodies();
  check_limits(dt);
}

void Box2DEngine::destroy_bodies() {
  for (std::uint32_t i : listener_->take_destroyed()) {
    if (i >= bodies_.size() || bodies_[i] == nullptr) continue;
    const b2Body* b = bodies_[i];
    final_states_[i] = {from_b2(b->GetPosition()), from_b2(b->GetLinearVelocity()),
                        static_cast<double>(b->GetAngle()), static_cast<double>(b->GetAngularVelocity()), false};
    world_->DestroyBody(bodies_[i]);
    bodies_[i] = nullptr;
  }
}

void Box2DEngine::check_limits(double dt) {
  const float h = static_cast<float>(dt);
  for (std::size_t i = 0; i < bodies_.size(); ++i) {
    const b2Body* b = bodies_[i];
    if (b == nullptr) continue;
    const std::string& name = scene_.bodies[i].name;
    const b2Vec2 p = b->GetPosition();
    const double reach = std::max(std::fabs(static_cast<double>(p.x)), std::fabs(static_cast<double>(p.y)));
    if (adapter::coordinate_spacing(reach, Precision::Float32) > adapter::kPositionResolutionLimit) {
      limits_.hit("float_resolution", time_, [&] {
        return "body '" + name + "' is " + fmt(reach) + " m from the origin, where float32 positions are " +
               fmt(adapter::coordinate_spacing(reach, Precision::Float32)) + " m apart (limit 1e-4 m)";
      });
    }
    if (b->GetType() != b2_dynamicBody) continue;
    const float speed = b->GetLinearVelocity().Length();
    // b2Island::Solve scales a velocity down to b2_maxTranslation per step; a clamped
    // body leaves the step at exactly that speed (to float rounding).
    if (speed * h >= b2_maxTranslation * (1.0f - 1e-5f)) {
      limits_.hit("speed_clamp", time_, [&] {
        return "body '" + name + "' moves at " + fmt(speed) + " m/s, Box2D's cap of b2_maxTranslation = 2 m per step (" +
               fmt(2.0 / dt) + " m/s at dt " + fmt(dt) + " s)";
      });
    }
    const float spin = std::fabs(b->GetAngularVelocity());
    if (spin * h >= b2_maxRotation * (1.0f - 1e-5f)) {
      limits_.hit("spin_clamp", time_, [&] {
        return "body '" + name + "' spins at " + fmt(spin) + " rad/s, Box2D's cap of b2_maxRotation = pi/2 per step";
      });
    }
    // Between two moving bodies Box2D's collision is discrete unless they are bullets.
    const double travel = static_cast<double>(speed) * dt;
    if (!opt_.bullet && travel > tunnel_size_[i]) {
      limits_.hit("discrete_collision", time_, [&] {
        return "body '" + name + "' moved " + fmt(travel) + " m in one step, more than the " + fmt(tunnel_size_[i]) +
               " m (its radius plus the smallest other moving body's) that discrete collision needs; "
               "between moving bodies Box2D (bullet = false) can miss contacts";
      });
    }
  }
}

BodyMeta Box2DEngine::body_meta(std::size_t i) const { return objects_->body_meta(i); }

void Box2DEngine::read_states(std::vector<BodyState>& out) const {
  out.resize(bodies_.size());
  for (std::size_t i = 0; i < bodies_.size(); ++i) {
    const b2Body* b = bodies_[i];
    if (b == nullptr) {
      out[i] = final_states_[i];
      continue;
    }
    out[i] = {from_b2(b->GetPosition()), from_b2(b->GetLinearVelocity()), static_cast<double>(b->GetAngle()),
              static_cast<double>(b->GetAngularVelocity()), true};
  }
}

std::vector<Setting> Box2DEngine::settings() const {
  std::ostringstream runtime;
  runtime << b2_version.major << '.' << b2_version.minor << '.' << b2_version.revision;
  auto b = [](bool v) { return std::string(v ? "true" : "false"); };
  return {
      {"version", kPackageVersion},
      {"runtime_b2_version", runtime.str() + " (the 2.4.1 package reports 2.4.0)"},
      {"precision", "float32"},
      {"step", "one b2World::Step(float(dt), velocity_iterations, position_iterations) per physval step"},
      {"velocity_iterations", std::to_string(opt_.velocity_iterations)},
      {"position_iterations", std::to_string(opt_.position_iterations)},
      {"continuous", b(opt_.continuous)},
      {"bullet", b(opt_.bullet)},
      {"warm_starting", b(opt_.warm_starting)},
      {"sub_stepping", "false"},
      {"allow_sleeping", "false"},
      {"restitution_threshold", fmt(static_cast<double>(opt_.restitution_threshold))},
      {"fixed_rotation", b(opt_.fixed_rotation)},
      {"material_rule",
       "PreSolve sets every contact's restitution min(e1, e2), friction sqrt(f1 f2), per-pair overrides "
       "(Box2D's own mixing: restitution max)"},
      {"uniform_gravity", "b2World gravity"},
      {"external_forces", "drag and wind, thrust, Newtonian gravity: physval forces.hpp, ApplyForceToCenter every step"},
      {"mass", "b2Body::SetMassData with the scene's mass; inertia 0.5 m r^2 (unused with fixed_rotation)"},
      {"circles", "b2CircleShape"},
      {"points", "b2CircleShape of radius 0"},
      {"walls", "two-sided b2EdgeShape (skin b2_polygonRadius: contact at distance r + 0.01 m)"},
      {"boxes", "b2PolygonShape box (skin 0.01 m)"},
      {"surfaces", "one-sided b2ChainShape facing the scene's normals; ghost vertices extend the end segments"},
      {"collision_matrix", "ignore: b2ContactFilter; event: PreSolve SetEnabled(false); destroy: DestroyBody after the step"},
      {"contact_events", "BeginContact once per physval pair, at the end of the step it fires in"},
      {"max_translation_per_step", fmt(static_cast<double>(b2_maxTranslation)) + " m (compiled in)"},
      {"max_rotation_per_step", fmt(static_cast<double>(b2_maxRotation)) + " rad (compiled in)"},
      {"linear_slop", fmt(static_cast<double>(b2_linearSlop)) + " m (compiled in)"},
      {"polygon_radius", fmt(static_cast<double>(b2_polygonRadius)) + " m (compiled in)"},
  };
}

}  // namespace

EngineFactory box2d_engine_factory() {
  EngineFactory f;
  f.info.name = kEngineName;
  f.info.version = kPackageVersion;
  f.info.precision = Precision::Float32;
  f.info.summary = "Box2D 2.4.1 (float32; b2_version reports 2.4.0): circles, edges, chains, boxes";
  f.info.features = box2d_features();
  f.info.options = box2d_options();
  f.create = [info = f.info]() -> std::unique_ptr<Engine> { return std::make_unique<Box2DEngine>(info); };
  return f;
}

}  // namespace physval
