// Bullet 3.24 (double-precision build) behind physval's engine interface: a 3-D engine
// held in the plane z = 0. Spheres keep z = 0 (linear factor (1, 1, 0)); walls, boxes
// and surfaces are thin static boxes extruded along z. The adapter steps exactly dt,
// never sleeps, imposes physval's material rule, and writes down every choice.
#include "physval/adapters/bullet_adapter.hpp"

#include <algorithm>
#include <cmath>
#include <deque>
#include <limits>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <utility>

#include "bullet_callbacks.hpp"
#include "bullet_includes.hpp"
#include "external_forces.hpp"
#include "limit_monitor.hpp"
#include "scene_objects.hpp"

namespace physval {
namespace {

using adapter::ExternalForces;
using adapter::LimitMonitor;
using adapter::ObjectTag;
using adapter::SceneObjects;

constexpr const char* kEngineName = "bullet";
// Every overlap, however shallow, goes through the split impulse (position only): with
// Bullet's own -0.04 m, overlaps shallower than 4 cm are pushed apart through velocity
// and an elastic gas gained 500x its energy (shared/engines.md).
constexpr double kEveryPenetration = 1.0e30;
// Half-depth along z of the static boxes: any positive value works, spheres stay at z = 0.
constexpr double kHalfDepthZ = 1.0;
// Above this rotation per step btTransformUtil::integrateTransform limits the angle it
// integrates: at 100 rad/s and dt 1/60 a body turns 1.44 rad instead of 1.67.
constexpr double kAngularMotionThreshold = 0.25 * SIMD_PI;

std::string bullet_version() {
  return std::to_string(BT_BULLET_VERSION / 100) + "." + std::to_string(BT_BULLET_VERSION % 100);
}

std::vector<OptionSpec> bullet_options() {
  const btContactSolverInfo d;   // Bullet's own defaults, read from the library's headers
  return {
      {"solver_iterations", std::int64_t{d.m_numIterations}, {},
       "Sequential-impulse solver iterations per step (btContactSolverInfo::m_numIterations). Bullet's default.",
       OptionRange::between(1, 100000)},
      {"split_impulse", true, {},
       "Correct overlaps with a split impulse that moves positions without changing velocities "
       "(m_splitImpulse). Bullet's default."},
      {"split_impulse_threshold", kEveryPenetration, {},
       "Penetration (m, negative when overlapping) above which Bullet corrects an overlap through the "
       "velocity instead of the split impulse (m_splitImpulsePenetrationThreshold). Bullet's -0.04 makes "
       "an elastic gas gain energy (engines.md); physval's 1e30 splits every overlap."},
      {"erp", static_cast<double>(d.m_erp), {},
       "Error reduction of overlaps corrected through the velocity (m_erp). Bullet's default.",
       OptionRange::between(0, 1)},
      {"erp2", static_cast<double>(d.m_erp2), {},
       "Error reduction of overlaps corrected by the split impulse (m_erp2). Bullet's default.",
       OptionRange::between(0, 1)},
      {"warm_starting", true, {}, "Start each step's solver from the last step's impulses (SOLVER_USE_WARMSTARTING)."},
      {"warm_starting_factor", static_cast<double>(d.m_warmstartingFactor), {},
       "Fraction of the last step's impulse the solver starts from (m_warmstartingFactor). Bullet's default.",
       OptionRange::between(0, 1)},
      {"ccd", false, {},
       "Continuous collision: a sphere moving further than its radius in a step is swept "
       "(setCcdMotionThreshold = setCcdSweptSphereRadius = radius); needs contact_processing_threshold > 0, "
       "since its predictive contacts are points before touching. Off: a bounce loses energy with it on "
       "(engines.md: 69%; here a 10 m drop's apex fell to 9.15 m)."},
      {"restitution_threshold", 0.0, {},
       "Approach speed (m/s) below which a contact does not bounce (m_restitutionVelocityThreshold). "
       "Bullet's own default is 0.2 m/s; physval's 0 keeps an elastic scene elastic.",
       OptionRange::at_least(0)},
      {"wall_half_thickness", 0.0, {},
       "Walls are boxes this thick on each side of the segment, with that margin as rounded ends (m). "
       "0: the exact segment a circle touches at its radius.",
       OptionRange::at_least(0)},
      {"box_margin", 0.0, {},
       "Collision margin of static boxes (m): corners rounded by it, faces where the scene puts them. "
       "Bullet's own 0.04; 0 gives the scene's sharp box.",
       OptionRange::at_least(0)},
      {"surface_depth", 0.1, {},
       "Each surface segment is a box this deep behind the surface (away from its normals), its front "
       "face on the segment (m).",
       OptionRange::above(0)},
      {"fixed_rotation", true, {},
       "Bodies do not spin (lecture model, collision step 6): angular factor 0. false: spin about z "
       "only, angular factor (0, 0, 1), a uniform disc's inertia 0.5 m r^2."},
      {"contact_processing_threshold", 0.0, {},
       "Manifold points further apart than this (m) are not solved. Bullet's own (BT_LARGE_FLOAT: 1e30 in the double build) also solves points "
       "within its breaking threshold before the bodies touch, with a restitution that treats the gap as "
       "closing this step: an e = 0.5 bounce at 4 m/s left at 1.6 m/s instead of 2. 0: only touching "
       "points are solved.",
       OptionRange::at_least(0)},
      {"contact_begin", std::string("touch"), {"touch", "manifold"},
       "When a pair's contact begins: 'touch' = the first step after which the pair's manifold has a point "
       "at distance <= 0 or a normal impulse > 0; 'manifold' = its first manifold point at all "
       "(physval scans the manifolds after each step), which Bullet creates up to its breaking threshold "
       "before touching. Not gContactStartedCallback: that fires every step for a resting sphere. "
       "Bullet writes impulses back only with warm starting; without it 'touch' means distance <= 0."},
  };
}

std::vector<Feature> bullet_features() {
  // Not here: static friction distinct from kinetic (one coefficient), particles.
  // Rolling resistance is not Bullet's rolling friction (that acts on spin, and physval
  // bodies do not spin): core's model of it for bodies that do not spin is Coulomb
  // friction with mu = c, which the friction callback imposes (fixed_rotation only).
  return {Feature::Circles,          Feature::Points,        Feature::StaticBodies,
          Feature::Walls,            Feature::Boxes,         Feature::Surfaces,
          Feature::UniformGravity,   Feature::NewtonianGravity, Feature::LinearDrag,
          Feature::QuadraticDrag,    Feature::Wind,          Feature::Thrust,
          Feature::Friction,         Feature::MaterialOverrides, Feature::CollisionMatrix,
          Feature::RollingFriction};
}

btVector3 to_bt(Vec2 v) { return {static_cast<btScalar>(v.x), static_cast<btScalar>(v.y), 0.0}; }
Vec2 from_bt(const btVector3& v) { return {static_cast<double>(v.x()), static_cast<double>(v.y())}; }

// Settings print numbers the way option values print (17 significant digits), so a
// setting reads back as the option that produced it.
std::string fmt(double v) { return option_value_to_string(OptionValue{v}); }

struct BulletOptions {
  int solver_iterations = 10;
  bool split_impulse = true;
  double split_impulse_threshold = kEveryPenetration;
  double erp = 0.2;
  double erp2 = 0.2;
  bool warm_starting = true;
  double warm_starting_factor = 0.85;
  bool ccd = false;
  double restitution_threshold = 0.0;
  double wall_half_thickness = 0.0;
  double box_margin = 0.0;
  double surface_depth = 0.1;
  double contact_processing_threshold = 0.0;
  bool fixed_rotation = true;
  bool begin_at_manifold = false;
};

class BulletEngine final : public Engine {
 public:
  explicit BulletEngine(EngineInfo info) : info_(std::move(info)) {}
  ~BulletEngine() override { teardown(); }
  BulletEngine(const BulletEngine&) = delete;
  BulletEngine& operator=(const BulletEngine&) = delete;

  const EngineInfo& info() const override { return info_; }
  void load(const Scene& scene) override;
  void step(double dt) override;
  double time() const override { return time_; }
  std::size_t body_count() const override { return bodies_.size(); }
  BodyMeta body_meta(std::size_t i) const override;
  void read_states(std::vector<BodyState>& out) const override;
  void read_motion(std::vector<BodyState>& out) const override;
  const std::vector<ContactEvent>& contacts() const override { return contacts_; }
  std::vector<Setting> settings() const override;
  std::vector<std::string> limits_hit() const override { return limits_.lines(); }

 private:
  void read_options();
  void teardown();
  void build_world();
  void build_bodies();
  void build_statics();
  btRigidBody* add_static(btCollisionShape* shape, const btTransform& xf, ObjectRef ref);
  void apply_external_forces();
  void collect_contacts();
  void check_limits(double dt);
  std::vector<double> tunnel_sizes() const;

  EngineInfo info_;
  Scene scene_;
  BulletOptions opt_;
  std::unique_ptr<SceneObjects> objects_;
  std::unique_ptr<ExternalForces> forces_;

  std::unique_ptr<btDefaultCollisionConfiguration> config_;
  std::unique_ptr<adapter::PhysvalDispatcher> dispatcher_;
  std::unique_ptr<btBroadphaseInterface> broadphase_;
  std::unique_ptr<btSequentialImpulseConstraintSolver> solver_;
  std::unique_ptr<btDiscreteDynamicsWorld> world_;
  adapter::CollisionMatrixFilter matrix_filter_;
  std::vector<std::unique_ptr<btCollisionShape>> shapes_;
  std::vector<std::unique_ptr<btRigidBody>> statics_;
  std::vector<std::unique_ptr<btRigidBody>> bodies_;   // scene order; kept after destruction
  std::vector<bool> alive_;
  std::deque<ObjectTag> tags_;                          // stable addresses for user pointers

  double time_ = 0.0;
  std::vector<ContactEvent> contacts_;
  std::vector<adapter::PairKey> touching_;              // sorted: pairs in contact after the last step
  std::vector<adapter::PairKey> scratch_touching_;
  LimitMonitor limits_;
  // How far a body may move in one step before discrete collision can miss a contact:
  // its radius plus the thinnest thing it could meet (infinite: it can meet nothing).
  std::vector<double> tunnel_size_;
  std::vector<BodyState> scratch_states_;
  std::vector<Vec2> scratch_forces_;
};

void BulletEngine::read_options() {
  const OptionReader r(scene_, kEngineName, info_.options);
  const std::int64_t iterations = r.get_int("solver_iterations");
  if (iterations < 1 || iterations > 10000) throw std::invalid_argument("bullet.solver_iterations must be in [1, 10000]");
  opt_.solver_iterations = static_cast<int>(iterations);
  opt_.split_impulse = r.get_bool("split_impulse");
  opt_.split_impulse_threshold = r.get_double("split_impulse_threshold");
  opt_.erp = r.get_double("erp");
  opt_.erp2 = r.get_double("erp2");
  opt_.warm_starting = r.get_bool("warm_starting");
  opt_.warm_starting_factor = r.get_double("warm_starting_factor");
  opt_.ccd = r.get_bool("ccd");
  opt_.restitution_threshold = r.get_double("restitution_threshold");
  opt_.wall_half_thickness = r.get_double("wall_half_thickness");
  opt_.box_margin = r.get_double("box_margin");
  opt_.surface_depth = r.get_double("surface_depth");
  opt_.fixed_rotation = r.get_bool("fixed_rotation");
  opt_.contact_processing_threshold = r.get_double("contact_processing_threshold");
  const std::string begin = r.get_string("contact_begin");
  if (begin != "touch" && begin != "manifold") throw std::invalid_argument("bullet.contact_begin must be touch or manifold");
  opt_.begin_at_manifold = begin == "manifold";
  auto in = [](double v, double lo, double hi) { return std::isfinite(v) && v >= lo && v <= hi; };
  if (!in(opt_.erp, 0.0, 1.0) || !in(opt_.erp2, 0.0, 1.0)) throw std::invalid_argument("bullet.erp and erp2 must be in [0, 1]");
  if (!in(opt_.warm_starting_factor, 0.0, 1.0)) throw std::invalid_argument("bullet.warm_starting_factor must be in [0, 1]");
  if (!in(opt_.restitution_threshold, 0.0, 1e30)) throw std::invalid_argument("bullet.restitution_threshold must be >= 0");
  if (!in(opt_.wall_half_thickness, 0.0, 1e30) || !in(opt_.box_margin, 0.0, 1e30)) {
    throw std::invalid_argument("bullet.wall_half_thickness and box_margin must be >= 0");
  }
  if (!in(opt_.surface_depth, 1e-9, 1e30)) throw std::invalid_argument("bullet.surface_depth must be > 0");
  if (std::isnan(opt_.contact_processing_threshold)) throw std::invalid_argument("bullet.contact_processing_threshold is NaN");
  if (opt_.ccd && !(opt_.contact_processing_threshold > 0.0)) {
    // Bullet's continuous collision works through predictive contacts: points at a
    // positive distance, which a threshold of 0 would never solve.
    throw std::invalid_argument(
        "bullet.ccd = true needs bullet.contact_processing_threshold > 0 (e.g. 1e30, Bullet's own BT_LARGE_FLOAT in the double build): "
        "its predictive contacts are points before touching");
  }
  if (std::isnan(opt_.split_impulse_threshold)) throw std::invalid_argument("bullet.split_impulse_threshold is NaN");
}

void BulletEngine::teardown() {
  if (world_) {
    for (auto& b : bodies_) {
      if (b && b->isInWorld()) world_->removeRigidBody(b.get());
    }
    for (auto& s : statics_) world_->removeRigidBody(s.get());
  }
  world_.reset();
  solver_.reset();
  broadphase_.reset();
  dispatcher_.reset();
  config_.reset();
  bodies_.clear();
  statics_.clear();
  shapes_.clear();
  tags_.clear();
}

void BulletEngine::load(const Scene& scene) {
  teardown();
  scene_ = scene;
  if (const auto missing = unsupported_features(info_, scene_); !missing.empty()) {
    throw std::invalid_argument("bullet cannot model this scene: it uses " + missing.front());
  }
  read_options();
  adapter::require_fixed_rotation_for_rolling(scene_, opt_.fixed_rotation, "bullet");
  objects_ = std::make_unique<SceneObjects>(scene_);
  forces_ = std::make_unique<ExternalForces>(scene_);
  adapter::install_material_callbacks();
  build_world();
  build_statics();
  build_bodies();
  time_ = 0.0;
  contacts_.clear();
  touching_.clear();
  limits_.clear();
  tunnel_size_ = tunnel_sizes();
}

void BulletEngine::build_world() {
  // Bullet's pools default to 4096 persistent manifolds and 4096 collision algorithms,
  // zeroed when the world is made (about 2 ms a world, more than a small scene's whole
  // run). A pool is only a cache: when it is full, Bullet takes the memory from the heap
  // (btCollisionDispatcher's default, CD_DISABLE_CONTACTPOOL_DYNAMIC_ALLOCATION unset), so
  // its size changes no result. Each is sized to the most pairs the scene can ever have
  // (dynamic x dynamic and dynamic x static: Bullet pairs no two statics), capped at the
  // default, so a scene that could need the default pools still gets them.
  {
    std::size_t statics = scene_.walls.size() + scene_.boxes.size();
    for (const SurfaceDef& s : scene_.surfaces) statics += s.points.empty() ? 0 : s.points.size() - 1;
    const std::size_t dynamic = scene_.bodies.size();
    const std::size_t cap = 4096;
    const std::size_t pairs = dynamic > 2 * cap ? cap : dynamic * (dynamic - (dynamic > 0 ? 1 : 0)) / 2 + dynamic * std::min(statics, cap);
    btDefaultCollisionConstructionInfo info;
    info.m_defaultMaxPersistentManifoldPoolSize = static_cast<int>(std::min(cap, std::max<std::size_t>(pairs, 16)));
    info.m_defaultMaxCollisionAlgorithmPoolSize = static_cast<int>(std::min(cap, std::max<std::size_t>(2 * pairs, 16)));
    config_ = std::make_unique<btDefaultCollisionConfiguration>(info);
  }
  dispatcher_ = std::make_unique<adapter::PhysvalDispatcher>(config_.get());
  broadphase_ = std::make_unique<btDbvtBroadphase>();
  solver_ = std::make_unique<btSequentialImpulseConstraintSolver>();
  world_ = std::make_unique<btDiscreteDynamicsWorld>(dispatcher_.get(), broadphase_.get(), solver_.get(), config_.get());
  world_->setGravity(to_bt(scene_.world.gravity));
  if (!scene_.collision_matrix.empty()) world_->getPairCache()->setOverlapFilterCallback(&matrix_filter_);
  btContactSolverInfo& si = world_->getSolverInfo();
  si.m_numIterations = opt_.solver_iterations;
  si.m_splitImpulse = opt_.split_impulse ? 1 : 0;
  si.m_splitImpulsePenetrationThreshold = static_cast<btScalar>(opt_.split_impulse_threshold);
  si.m_erp = static_cast<btScalar>(opt_.erp);
  si.m_erp2 = static_cast<btScalar>(opt_.erp2);
  si.m_warmstartingFactor = static_cast<btScalar>(opt_.warm_starting_factor);
  if (opt_.warm_starting) {
    si.m_solverMode |= SOLVER_USE_WARMSTARTING;
  } else {
    si.m_solverMode &= ~SOLVER_USE_WARMSTARTING;
  }
  si.m_restitutionVelocityThreshold = static_cast<btScalar>(opt_.restitution_threshold);
}

btRigidBody* BulletEngine::add_static(btCollisionShape* shape, const btTransform& xf, ObjectRef ref) {
  btRigidBody::btRigidBodyConstructionInfo ci(0.0, nullptr, shape, btVector3(0, 0, 0));
  ci.m_startWorldTransform = xf;
  auto body = std::make_unique<btRigidBody>(ci);
  body->setContactProcessingThreshold(static_cast<btScalar>(opt_.contact_processing_threshold));
  tags_.push_back({objects_.get(), ref});
  adapter::attach_tag(*body, tags_.back());
  world_->addRigidBody(body.get());
  statics_.push_back(std::move(body));
  return statics_.back().get();
}

// A placement in the plane z = 0: origin c, rotated by `angle` about z.
btTransform planar_transform(Vec2 c, double angle) {
  btTransform xf;
  xf.setIdentity();
  xf.setOrigin(to_bt(c));
  xf.setRotation(btQuaternion(btVector3(0, 0, 1), static_cast<btScalar>(angle)));
  return xf;
}

void BulletEngine::build_statics() {
  auto box_shape = [&](double hx, double hy, double margin) {
    auto shape = std::make_unique<btBoxShape>(btVector3(static_cast<btScalar>(hx), static_cast<btScalar>(hy), kHalfDepthZ));
    shape->setMargin(static_cast<btScalar>(margin));   // keeps the outer extents
    shapes_.push_back(std::move(shape));
    return shapes_.back().get();
  };
  // Walls: the segment thickened by t on each side with rounded ends of radius t (a
  // box whose core is the segment and whose margin is t); t = 0 is the segment itself.
  // btSphereBoxCollisionAlgorithm measures the distance to it exactly.
  for (std::size_t i = 0; i < scene_.walls.size(); ++i) {
    const WallDef& w = scene_.walls[i];
    const Vec2 d = w.to - w.from;
    const double len = length(d);
    if (!(len > 0.0)) throw std::invalid_argument("wall '" + w.name + "' has zero length");
    const double t = opt_.wall_half_thickness;
    btCollisionShape* shape = box_shape(0.5 * len + t, t, t);
    add_static(shape, planar_transform(0.5 * (w.from + w.to), std::atan2(d.y, d.x)),
               {ObjectRef::Kind::Wall, static_cast<std::uint32_t>(i)});
  }
  for (std::size_t i = 0; i < scene_.boxes.size(); ++i) {
    const BoxDef& bx = scene_.boxes[i];
    const Vec2 half = 0.5 * (bx.max - bx.min);
    if (!(half.x > 0.0) || !(half.y > 0.0)) throw std::invalid_argument("box '" + bx.name + "' has no area");
    const double margin = std::min({opt_.box_margin, half.x, half.y});
    add_static(box_shape(half.x, half.y, margin), planar_transform(0.5 * (bx.min + bx.max), 0.0),
               {ObjectRef::Kind::Box, static_cast<std::uint32_t>(i)});
  }
  // Surfaces: one box per segment, behind the surface (away from its normals), its
  // front face on the segment: one-sided in effect, like Box2D's chain.
  for (std::size_t i = 0; i < scene_.surfaces.size(); ++i) {
    const SurfaceDef& s = scene_.surfaces[i];
    if (s.points.size() < 2) throw std::invalid_argument("surface '" + s.name + "' needs at least 2 points");
    for (std::size_t k = 0; k + 1 < s.points.size(); ++k) {
      const Vec2 d = s.points[k + 1] - s.points[k];
      const double len = length(d);
      if (!(len > 0.0)) throw std::invalid_argument("surface '" + s.name + "' repeats a point");
      const Vec2 given = s.normals.size() == s.points.size() ? s.normals[k] + s.normals[k + 1] : perp(d);
      const Vec2 front = normalized(dot(given, perp(d)) >= 0.0 ? perp(d) : -perp(d));
      const double h = 0.5 * opt_.surface_depth;
      add_static(box_shape(0.5 * len, h, 0.0),
                 planar_transform(0.5 * (s.points[k] + s.points[k + 1]) - h * front, std::atan2(d.y, d.x)),
                 {ObjectRef::Kind::Surface, static_cast<std::uint32_t>(i)});
    }
  }
}

void BulletEngine::build_bodies() {
  bodies_.clear();
  alive_.assign(scene_.bodies.size(), true);
  for (std::size_t i = 0; i < scene_.bodies.size(); ++i) {
    const BodyDef& b = scene_.bodies[i];
    // A point is a sphere of radius 0: it meets spheres at their radius; against static
    // shapes only when a step ends with it inside one (reported as a limit).
    const double radius = b.shape == ShapeKind::Point ? 0.0 : b.radius;
    shapes_.push_back(std::make_unique<btSphereShape>(static_cast<btScalar>(radius)));
    btCollisionShape* shape = shapes_.back().get();
    const double mass = b.is_static ? 0.0 : b.mass;
    const double disc_inertia = 0.5 * mass * radius * radius;   // uniform disc, about z
    btRigidBody::btRigidBodyConstructionInfo ci(static_cast<btScalar>(mass), nullptr, shape,
                                                btVector3(disc_inertia, disc_inertia, disc_inertia));
    ci.m_startWorldTransform = planar_transform(b.position, b.angle);
    ci.m_friction = static_cast<btScalar>(b.friction);   // replaced per contact by the combine callbacks
    ci.m_restitution = static_cast<btScalar>(b.restitution);
    ci.m_linearDamping = 0.0;
    ci.m_angularDamping = 0.0;
    auto body = std::make_unique<btRigidBody>(ci);
    // A manifold takes the smaller of its two objects' thresholds.
    body->setContactProcessingThreshold(static_cast<btScalar>(opt_.contact_processing_threshold));
    tags_.push_back({objects_.get(), {ObjectRef::Kind::Body, static_cast<std::uint32_t>(i)}});
    adapter::attach_tag(*body, tags_.back());
    if (!b.is_static) {
      body->setLinearFactor(btVector3(1, 1, 0));   // held in the plane z = 0
      body->setAngularFactor(opt_.fixed_rotation ? btVector3(0, 0, 0) : btVector3(0, 0, 1));
      body->setLinearVelocity(to_bt(b.velocity));
      // Kept unchanged with fixed rotation: no contact alters it.
      body->setAngularVelocity(btVector3(0, 0, static_cast<btScalar>(b.angular_velocity)));
      body->setActivationState(DISABLE_DEACTIVATION);   // Bullet would freeze a slow body after 2 s
      if (opt_.ccd && radius > 0.0) {
        body->setCcdMotionThreshold(static_cast<btScalar>(radius));
        body->setCcdSweptSphereRadius(static_cast<btScalar>(radius));
      }
    }
    world_->addRigidBody(body.get());
    bodies_.push_back(std::move(body));
  }
}

void BulletEngine::apply_external_forces() {
  if (!forces_->active()) return;
  read_states(scratch_states_);
  forces_->compute(scratch_states_, scratch_forces_);
  for (std::size_t i = 0; i < bodies_.size(); ++i) {
    if (!alive_[i] || scene_.bodies[i].is_static) continue;
    // Bullet integrates v += dt (F_total / m), then x += dt v: semi-implicit Euler.
    bodies_[i]->applyCentralForce(to_bt(scratch_forces_[i]));
  }
}

void BulletEngine::step(double dt) {
  if (!(dt > 0.0) || !std::isfinite(dt)) throw std::invalid_argument("bullet: step dt must be > 0");
  apply_external_forces();
  // maxSubSteps = 0: exactly one internal step of dt, no interpolation, nothing dropped.
  const int substeps = world_->stepSimulation(static_cast<btScalar>(dt), 0, static_cast<btScalar>(dt));
  if (substeps != 1) throw std::runtime_error("bullet took " + std::to_string(substeps) + " internal steps for one dt");
  time_ += dt;
  collect_contacts();
  check_limits(dt);
}

void BulletEngine::collect_contacts() {
  contacts_.clear();
  scratch_touching_.clear();
  const int n = dispatcher_->getNumManifolds();
  for (int i = 0; i < n; ++i) {
    const btPersistentManifold* m = dispatcher_->getManifoldByIndexInternal(i);
    const int points = m->getNumContacts();
    if (points == 0) continue;
    bool touch = opt_.begin_at_manifold;
    for (int k = 0; k < points && !touch; ++k) {
      const btManifoldPoint& p = m->getContactPoint(k);
      touch = p.getDistance() <= 0.0 || p.getAppliedImpulse() > 0.0;
    }
    if (!touch) continue;
    const ObjectTag* t0 = adapter::tag_of(m->getBody0());
    const ObjectTag* t1 = adapter::tag_of(m->getBody1());
    ObjectRef a;
    ObjectRef b;
    if (t0 == nullptr || t1 == nullptr || !adapter::order_pair(t0->ref, t1->ref, a, b)) continue;
    scratch_touching_.push_back(adapter::pair_key(a, b));
  }
  std::sort(scratch_touching_.begin(), scratch_touching_.end());
  scratch_touching_.erase(std::unique(scratch_touching_.begin(), scratch_touching_.end()), scratch_touching_.end());
  std::vector<std::uint32_t> destroyed;
  for (const adapter::PairKey& k : scratch_touching_) {
    if (std::binary_search(touching_.begin(), touching_.end(), k)) continue;   // already touching
    const ObjectRef a = adapter::unpack(k.a);
    const ObjectRef b = adapter::unpack(k.b);
    const PairResponse r = objects_->response(a, b);
    if (r.event) contacts_.push_back({a, b, time_});
    // The bounce was resolved in this step; destroy afterwards, as the matrix says.
    if (r.destroy_first && SceneObjects::destructible(a)) destroyed.push_back(a.index);
    if (r.destroy_second && SceneObjects::destructible(b)) destroyed.push_back(b.index);
  }
  touching_.swap(scratch_touching_);
  for (std::uint32_t i : destroyed) {
    if (i < bodies_.size() && alive_[i]) {
      world_->removeRigidBody(bodies_[i].get());
      alive_[i] = false;
    }
  }
}

std::vector<double> BulletEngine::tunnel_sizes() const {
  const double inf = std::numeric_limits<double>::infinity();
  auto radius = [&](std::size_t i) {
    return scene_.bodies[i].shape == ShapeKind::Point ? 0.0 : scene_.bodies[i].radius;
  };
  std::vector<double> out(scene_.bodies.size(), inf);
  for (std::size_t i = 0; i < out.size(); ++i) {
    // Walls may have no thickness: against a barrier only the body's own radius counts.
    if (!statics_.empty()) out[i] = radius(i);
    for (std::size_t j = 0; j < out.size(); ++j) {
      const double size = radius(i) + radius(j);
      if (j != i && size > 0.0) out[i] = std::min(out[i], size);   // two points never meet
    }
  }
  return out;
}

void BulletEngine::check_limits(double dt) {
  for (std::size_t i = 0; i < bodies_.size(); ++i) {
    if (!alive_[i]) continue;
    const btRigidBody& body = *bodies_[i];
    const std::string& name = scene_.bodies[i].name;
    const btVector3& p = body.getWorldTransform().getOrigin();
    const double reach = std::max(std::fabs(static_cast<double>(p.x())), std::fabs(static_cast<double>(p.y())));
    if (adapter::coordinate_spacing(reach, Precision::Float64) > adapter::kPositionResolutionLimit) {
      limits_.hit("float_resolution", time_, [&] {
        return "body '" + name + "' is " + fmt(reach) + " m from the origin, where double positions are " +
               fmt(adapter::coordinate_spacing(reach, Precision::Float64)) + " m apart (limit 1e-4 m)";
      });
    }
    if (scene_.bodies[i].is_static) continue;
    const double spin = std::fabs(static_cast<double>(body.getAngularVelocity().z()));
    if (spin * dt > kAngularMotionThreshold) {
      limits_.hit("spin_clamp", time_, [&] {
        return "body '" + name + "' spins at " + fmt(spin) +
               " rad/s, over pi/4 rad per step: Bullet's integrateTransform limits the rotation "
               "(ANGULAR_MOTION_THRESHOLD) and the angle no longer advances by w dt";
      });
    }
    const double travel = static_cast<double>(body.getLinearVelocity().length()) * dt;
    if (!opt_.ccd && travel > tunnel_size_[i]) {
      limits_.hit("discrete_collision", time_, [&] {
        return "body '" + name + "' moved " + fmt(travel) + " m in one step, more than the " + fmt(tunnel_size_[i]) +
               " m (its radius plus the thinnest thing it can meet) that discrete collision needs; Bullet "
               "(ccd = false) can miss contacts";
      });
    }
  }
}

BodyMeta BulletEngine::body_meta(std::size_t i) const { return objects_->body_meta(i); }

void BulletEngine::read_motion(std::vector<BodyState>& out) const {
  out.resize(bodies_.size());
  for (std::size_t i = 0; i < bodies_.size(); ++i) {
    const btRigidBody& b = *bodies_[i];
    out[i].position = from_bt(b.getWorldTransform().getOrigin());
    out[i].velocity = from_bt(b.getLinearVelocity());
    out[i].alive = static_cast<bool>(alive_[i]);
  }
}

void BulletEngine::read_states(std::vector<BodyState>& out) const {
  out.resize(bodies_.size());
  for (std::size_t i = 0; i < bodies_.size(); ++i) {
    const btRigidBody& b = *bodies_[i];
    // The body's own transform: motion states would be interpolated.
    const btTransform& xf = b.getWorldTransform();
    const btMatrix3x3& r = xf.getBasis();
    out[i] = {from_bt(xf.getOrigin()), from_bt(b.getLinearVelocity()),
              std::atan2(static_cast<double>(r[1][0]), static_cast<double>(r[0][0])),
              static_cast<double>(b.getAngularVelocity().z()), static_cast<bool>(alive_[i])};
  }
}

// The solver-mode flags as names, e.g. "SOLVER_USE_WARMSTARTING | SOLVER_SIMD (0x104)".
std::string solver_mode_names(int mode) {
  static const std::pair<int, const char*> kFlags[] = {
      {SOLVER_RANDMIZE_ORDER, "SOLVER_RANDMIZE_ORDER"},
      {SOLVER_FRICTION_SEPARATE, "SOLVER_FRICTION_SEPARATE"},
      {SOLVER_USE_WARMSTARTING, "SOLVER_USE_WARMSTARTING"},
      {SOLVER_USE_2_FRICTION_DIRECTIONS, "SOLVER_USE_2_FRICTION_DIRECTIONS"},
      {SOLVER_ENABLE_FRICTION_DIRECTION_CACHING, "SOLVER_ENABLE_FRICTION_DIRECTION_CACHING"},
      {SOLVER_DISABLE_VELOCITY_DEPENDENT_FRICTION_DIRECTION, "SOLVER_DISABLE_VELOCITY_DEPENDENT_FRICTION_DIRECTION"},
      {SOLVER_CACHE_FRIENDLY, "SOLVER_CACHE_FRIENDLY"},
      {SOLVER_SIMD, "SOLVER_SIMD"},
      {SOLVER_INTERLEAVE_CONTACT_AND_FRICTION_CONSTRAINTS, "SOLVER_INTERLEAVE_CONTACT_AND_FRICTION_CONSTRAINTS"},
      {SOLVER_ALLOW_ZERO_LENGTH_FRICTION_DIRECTIONS, "SOLVER_ALLOW_ZERO_LENGTH_FRICTION_DIRECTIONS"},
      {SOLVER_DISABLE_IMPLICIT_CONE_FRICTION, "SOLVER_DISABLE_IMPLICIT_CONE_FRICTION"},
      {SOLVER_USE_ARTICULATED_WARMSTARTING, "SOLVER_USE_ARTICULATED_WARMSTARTING"},
  };
  std::string out;
  for (const auto& [flag, name] : kFlags) {
    if ((mode & flag) != 0) out += (out.empty() ? "" : " | ") + std::string(name);
  }
  std::ostringstream hex;
  hex << " (0x" << std::hex << mode << ")";
  return (out.empty() ? std::string("0") : out) + hex.str();
}

std::vector<Setting> BulletEngine::settings() const {
  auto b = [](bool v) { return std::string(v ? "true" : "false"); };
  // The solver's own values as the world holds them (Bullet's defaults before a load).
  btContactSolverInfo defaults;
  const btContactSolverInfo& si = world_ ? world_->getSolverInfo() : defaults;
  return {
      {"version", bullet_version()},
      {"runtime_version", std::to_string(btGetVersion())},
      {"precision", "float64 (BT_USE_DOUBLE_PRECISION, bullet-float64)"},
      {"step", "stepSimulation(dt, 0, dt): one internal step of exactly dt, states from getWorldTransform"},
      {"world", "btDiscreteDynamicsWorld, btDbvtBroadphase, btSequentialImpulseConstraintSolver"},
      {"solver_iterations", std::to_string(opt_.solver_iterations)},
      {"split_impulse", b(opt_.split_impulse)},
      {"split_impulse_threshold", fmt(opt_.split_impulse_threshold)},
      {"erp", fmt(opt_.erp)},
      {"erp2", fmt(opt_.erp2)},
      {"warm_starting", b(opt_.warm_starting)},
      {"warm_starting_factor", fmt(opt_.warm_starting_factor)},
      {"ccd", b(opt_.ccd)},
      {"restitution_threshold", fmt(opt_.restitution_threshold)},
      {"wall_half_thickness", fmt(opt_.wall_half_thickness)},
      {"box_margin", fmt(opt_.box_margin)},
      {"surface_depth", fmt(opt_.surface_depth)},
      {"fixed_rotation", b(opt_.fixed_rotation)},
      {"contact_processing_threshold", fmt(opt_.contact_processing_threshold)},
      {"contact_begin", opt_.begin_at_manifold ? "manifold" : "touch"},
      {"solver_mode", solver_mode_names(si.m_solverMode)},
      {"linear_slop", fmt(static_cast<double>(si.m_linearSlop)) + " m (btContactSolverInfo::m_linearSlop)"},
      {"global_cfm", fmt(static_cast<double>(si.m_globalCfm)) + " (btContactSolverInfo::m_globalCfm)"},
      {"static_half_depth_z", fmt(static_cast<double>(kHalfDepthZ)) +
                                  " m: walls, boxes and surfaces are btBoxShapes extruded +-this along z"},
      {"damping", "0 (btRigidBodyConstructionInfo linear and angular damping)"},
      {"external_forces_evaluated", "at the start of each step, from the state the previous step left"},
      {"rolling_friction", "a pair with rolling_friction c > 0 gets contact friction mu = c (core's model for bodies "
                           "that do not spin), not Bullet's spin-based rolling friction; needs fixed_rotation"},
      {"deactivation", "DISABLE_DEACTIVATION on every dynamic body"},
      {"plane", "linear factor (1, 1, 0); angular factor " + std::string(opt_.fixed_rotation ? "0" : "(0, 0, 1)")},
      {"material_rule",
       "gCalculateCombinedRestitution/FrictionCallback: restitution min(e1, e2), friction sqrt(f1 f2), per-pair "
       "overrides (Bullet's own: e1 e2, f1 f2)"},
      {"uniform_gravity", "btDiscreteDynamicsWorld gravity"},
      {"external_forces", "drag and wind, thrust, Newtonian gravity: physval forces.hpp, applyCentralForce every step"},
      {"mass", "the scene's mass; inertia 0.5 m r^2 about z"},
      {"circles", "btSphereShape (margin = radius)"},
      {"points", "btSphereShape of radius 0"},
      {"walls", "btBoxShape: segment core, margin = wall_half_thickness, extruded +-static_half_depth_z along z"},
      {"boxes", "btBoxShape, margin = box_margin"},
      {"surfaces", "one btBoxShape per segment, surface_depth deep behind the surface"},
      {"collision_matrix",
       "ignore: btOverlapFilterCallback; event: manifold processing threshold -inf (never solved); destroy: "
       "removeRigidBody after the step"},
      {"contact_events", "dispatcher manifolds scanned after each step, once per physval pair, at the end of the step"},
      {"contact_breaking_threshold", fmt(static_cast<double>(gContactBreakingThreshold)) +
                                         " x the shape's angular motion disc, sqrt(3) r for a sphere (Bullet's default)"},
  };
}

}  // namespace

EngineFactory bullet_engine_factory() {
  EngineFactory f;
  f.info.name = kEngineName;
  f.info.version = bullet_version();
  f.info.precision = Precision::Float64;
  f.info.summary = "Bullet " + bullet_version() + " (double build) held in the plane: spheres, static boxes";
  f.info.features = bullet_features();
  f.info.options = bullet_options();
  f.create = [info = f.info]() -> std::unique_ptr<Engine> { return std::make_unique<BulletEngine>(info); };
  return f;
}

}  // namespace physval
