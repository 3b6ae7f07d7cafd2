// ODE 0.16.2 (Debian libode-dev, double) behind physval's engine interface: a 3-D engine
// whose spheres are held in the plane z = 0 by ODE's plane-2D joint. The adapter imposes
// physval's material rule and collision matrix where ODE is meant to be steered, in the
// contact joints its near callback creates, never sleeps, and writes down every choice.
// Measured traps of the raw library: adapters/probes/ode_probe.cpp and the README.
#include "physval/adapters/ode_adapter.hpp"

#include <ode/ode.h>

#include <algorithm>
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <limits>
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

constexpr const char* kEngineName = "ode";
// Half-depth along z of static boxes (spheres stay at z = 0: any positive value works).
constexpr double kHalfDepthZ = 1.0;
// max_correcting_velocity at or above this is ODE's own dInfinity.
constexpr double kUnbounded = 1e30;
// Contacts dCollide may return for one pair (a sphere makes one with anything).
constexpr int kMaxContacts = 4;

std::string ode_version() {
  // ODE has no version macro or call; pkg-config's version, passed by CMake.
#ifdef PHYSVAL_ODE_VERSION
  return PHYSVAL_ODE_VERSION;
#else
  return "0.16";
#endif
}

// ODE prints its messages (e.g. "LCP internal error, s <= 0" when dWorldStep's Dantzig
// solver meets a degenerate contact set) on stderr and goes on. The adapter stepping on
// this thread collects them instead, as a limit of the run.
thread_local LimitMonitor* t_step_limits = nullptr;
thread_local double t_step_time = 0.0;

void ode_message(int errnum, const char* msg, va_list ap) {
  char text[512];
  std::vsnprintf(text, sizeof text, msg, ap);
  if (t_step_limits == nullptr) {
    std::fprintf(stderr, "ODE Message %d: %s\n", errnum, text);
    return;
  }
  const std::string line = text;
  t_step_limits->hit("ode_message", t_step_time, [&] {
    return "ODE reported \"" + line + "\" (message " + std::to_string(errnum) +
           "; dWorldStep's LCP solver failed on this step's contacts and went on with what it had)";
  });
}

void init_ode() {
  static std::once_flag once;
  std::call_once(once, [] {
    dInitODE2(0);
    dSetMessageHandler(&ode_message);
  });
  dAllocateODEDataForThread(dAllocateMaskAll);   // per thread; cheap when done already
}

struct OdeDefaults {
  double erp = 0.2;
  double cfm = 1e-10;
  int quick_iterations = 20;
  double quick_w = 1.3;
};
OdeDefaults ode_defaults() {
  init_ode();
  dWorldID w = dWorldCreate();
  OdeDefaults d{static_cast<double>(dWorldGetERP(w)), static_cast<double>(dWorldGetCFM(w)),
                dWorldGetQuickStepNumIterations(w), static_cast<double>(dWorldGetQuickStepW(w))};
  dWorldDestroy(w);
  return d;
}

std::vector<OptionSpec> ode_options() {
  const OdeDefaults d = ode_defaults();
  return {
      {"step_mode", std::string("step"), {"step", "quickstep"},
       "'step': dWorldStep, a direct (Dantzig) LCP solve of all contacts at once; 'quickstep': dWorldQuickStep, "
       "iterative (SOR), ODE's choice for large scenes."},
      {"quickstep_iterations", std::int64_t{d.quick_iterations}, {},
       "dWorldSetQuickStepNumIterations (step_mode = quickstep). ODE's default.", OptionRange::between(1, 100000)},
      {"quickstep_w", d.quick_w, {}, "SOR over-relaxation (dWorldSetQuickStepW). ODE's default.",
       OptionRange::between(0, 2)},
      {"erp", d.erp, {},
       "Error reduction per step (dWorldSetERP): an overlap d is corrected through the velocity at erp d / dt "
       "(real velocity: it can add energy). ODE's default.",
       OptionRange::between(0, 1)},
      {"cfm", d.cfm, {}, "Constraint force mixing (dWorldSetCFM): softness of every contact. ODE's default (double build).",
       OptionRange::at_least(0)},
      {"restitution_threshold", 0.0, {},
       "Approach speed (m/s) below which a contact does not bounce (dSurfaceParameters::bounce_vel). ODE has no "
       "default (its demos use 0.1); physval's 0 keeps an elastic scene elastic.",
       OptionRange::at_least(0)},
      {"contact_surface_layer", 0.0, {},
       "Overlap (m) left uncorrected (dWorldSetContactSurfaceLayer). ODE's default.", OptionRange::at_least(0)},
      {"max_correcting_velocity", kUnbounded, {},
       "Largest velocity (m/s) the overlap correction may give (dWorldSetContactMaxCorrectingVel). 1e30 and above: "
       "unbounded, ODE's default dInfinity (an option's default must be finite).",
       OptionRange::at_least(0)},
      {"segment_radius", 1e-9, {},
       "Walls and surface segments are capsules of this radius (m), and points spheres of it. ODE's broad phase "
       "never pairs a geom whose bounding box has no extent (probe: a radius-0 capsule floor let a ball fall "
       "through), so 0 is refused.",
       OptionRange::above(0)},
      {"fixed_rotation", true, {},
       "Bodies do not spin (lecture model, collision step 6): the plane-2D joint's angular motor holds the "
       "angular velocity at its initial value with unbounded torque. false: the motor is off; a circle has a "
       "uniform disc's inertia 0.5 m r^2 about z."},
  };
}

std::vector<Feature> ode_features() {
  // Not here: static friction above kinetic (one coefficient per contact), particles (not
  // mapped), precomputed surface normals. Rolling resistance: core's model of it for
  // bodies that do not spin is Coulomb friction with mu = c, set in the contact joint.
  return {Feature::Circles,          Feature::Points,        Feature::StaticBodies,
          Feature::Walls,            Feature::Boxes,         Feature::Surfaces,
          Feature::UniformGravity,   Feature::NewtonianGravity, Feature::LinearDrag,
          Feature::QuadraticDrag,    Feature::Wind,          Feature::Thrust,
          Feature::Friction,         Feature::MaterialOverrides, Feature::CollisionMatrix,
          Feature::RollingFriction};
}

std::string fmt(double v) { return option_value_to_string(OptionValue{v}); }

struct OdeOptions {
  bool quickstep = false;
  int quick_iterations = 20;
  double quick_w = 1.3;
  double erp = 0.2;
  double cfm = 1e-10;
  double restitution_threshold = 0.0;
  double surface_layer = 0.0;
  double max_correcting_velocity = kUnbounded;
  double segment_radius = 1e-9;
  bool fixed_rotation = true;
};

class OdeEngine final : public Engine {
 public:
  explicit OdeEngine(EngineInfo info) : info_(std::move(info)) {}
  ~OdeEngine() override { teardown(); }
  OdeEngine(const OdeEngine&) = delete;
  OdeEngine& operator=(const OdeEngine&) = delete;

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
  static void near_callback(void* data, dGeomID g1, dGeomID g2);
  static ObjectRef ref_of(dGeomID g) {
    return adapter::unpack(static_cast<std::uint64_t>(reinterpret_cast<std::uintptr_t>(dGeomGetData(g))));
  }
  void read_options();
  void teardown();
  void build_statics();
  void build_bodies();
  dGeomID add_segment(Vec2 a, Vec2 b, ObjectRef ref);
  void collide(double stamp, std::vector<ContactEvent>& events);
  void apply_external_forces();
  void destroy(std::uint32_t i);
  void check_limits(double dt);

  EngineInfo info_;
  Scene scene_;
  OdeOptions opt_;
  std::unique_ptr<SceneObjects> objects_;
  std::unique_ptr<ExternalForces> forces_;
  dWorldID world_ = nullptr;
  dSpaceID space_ = nullptr;
  dJointGroupID contact_group_ = nullptr;
  std::vector<dBodyID> bodies_;        // scene order; nullptr for static bodies and destroyed ones
  std::vector<dGeomID> body_geoms_;    // scene order; nullptr once destroyed
  std::vector<bool> alive_;
  std::vector<BodyState> final_states_;
  std::vector<double> tunnel_size_;
  double time_ = 0.0;
  std::vector<ContactEvent> contacts_;
  std::vector<ContactEvent> pending_;   // seen in the starting positions, reported with the first step
  std::vector<adapter::PairKey> touching_;
  std::vector<adapter::PairKey> scratch_touching_;
  std::vector<std::uint32_t> destroy_next_;   // destroyed after the step that resolves their bounce
  std::vector<std::uint32_t> destroy_seen_;
  LimitMonitor limits_;
  std::vector<BodyState> scratch_states_;
  std::vector<Vec2> scratch_forces_;
};

void OdeEngine::read_options() {
  const OptionReader r(scene_, kEngineName, info_.options);
  const std::string stepper = r.get_string("step_mode");
  if (stepper != "step" && stepper != "quickstep") throw std::invalid_argument("ode.step_mode must be step or quickstep");
  opt_.quickstep = stepper == "quickstep";
  const std::int64_t it = r.get_int("quickstep_iterations");
  if (it < 1 || it > 100000) throw std::invalid_argument("ode.quickstep_iterations must be in [1, 100000]");
  opt_.quick_iterations = static_cast<int>(it);
  opt_.quick_w = r.get_double("quickstep_w");
  opt_.erp = r.get_double("erp");
  opt_.cfm = r.get_double("cfm");
  opt_.restitution_threshold = r.get_double("restitution_threshold");
  opt_.surface_layer = r.get_double("contact_surface_layer");
  opt_.max_correcting_velocity = r.get_double("max_correcting_velocity");
  opt_.segment_radius = r.get_double("segment_radius");
  opt_.fixed_rotation = r.get_bool("fixed_rotation");
  auto in = [](double v, double lo, double hi) { return !std::isnan(v) && v >= lo && v <= hi; };
  if (!in(opt_.quick_w, 0.0, 2.0)) throw std::invalid_argument("ode.quickstep_w must be in [0, 2]");
  if (!in(opt_.erp, 0.0, 1.0)) throw std::invalid_argument("ode.erp must be in [0, 1]");
  if (!in(opt_.cfm, 0.0, 1e30)) throw std::invalid_argument("ode.cfm must be >= 0");
  if (!in(opt_.restitution_threshold, 0.0, 1e30)) throw std::invalid_argument("ode.restitution_threshold must be >= 0");
  if (!in(opt_.surface_layer, 0.0, 1e30)) throw std::invalid_argument("ode.contact_surface_layer must be >= 0");
  if (!(opt_.max_correcting_velocity >= 0.0)) throw std::invalid_argument("ode.max_correcting_velocity must be >= 0");
  if (!(opt_.segment_radius > 0.0) || !std::isfinite(opt_.segment_radius)) {
    throw std::invalid_argument("ode.segment_radius must be > 0 (ODE's broad phase drops geoms without extent)");
  }
}

void OdeEngine::teardown() {
  if (contact_group_ != nullptr) dJointGroupDestroy(contact_group_);
  if (space_ != nullptr) dSpaceDestroy(space_);   // destroys every geom in it (cleanup on)
  if (world_ != nullptr) dWorldDestroy(world_);   // destroys bodies and joints
  contact_group_ = nullptr;
  space_ = nullptr;
  world_ = nullptr;
  bodies_.clear();
  body_geoms_.clear();
}

void OdeEngine::load(const Scene& scene) {
  teardown();
  scene_ = scene;
  if (const auto missing = unsupported_features(info_, scene_); !missing.empty()) {
    throw std::invalid_argument("ode cannot model this scene: it uses " + missing.front());
  }
  read_options();
  adapter::require_fixed_rotation_for_rolling(scene_, opt_.fixed_rotation, "ode");
  objects_ = std::make_unique<SceneObjects>(scene_);
  forces_ = std::make_unique<ExternalForces>(scene_);
  init_ode();
  // dWorldQuickStep reorders constraints with ODE's global random generator: reseeded at
  // every load, a run is repeatable (probe: without it two runs differ).
  dRandSetSeed(0);
  world_ = dWorldCreate();
  dWorldSetGravity(world_, scene_.world.gravity.x, scene_.world.gravity.y, 0.0);
  dWorldSetERP(world_, opt_.erp);
  dWorldSetCFM(world_, opt_.cfm);
  dWorldSetQuickStepNumIterations(world_, opt_.quick_iterations);
  dWorldSetQuickStepW(world_, opt_.quick_w);
  dWorldSetContactSurfaceLayer(world_, opt_.surface_layer);
  dWorldSetContactMaxCorrectingVel(world_, opt_.max_correcting_velocity >= kUnbounded ? dInfinity
                                                                                     : opt_.max_correcting_velocity);
  dWorldSetAutoDisableFlag(world_, 0);   // sleeping off (ODE's default)
  dWorldSetDamping(world_, 0.0, 0.0);
  space_ = dSimpleSpaceCreate(nullptr);
  contact_group_ = dJointGroupCreate(0);
  time_ = 0.0;
  contacts_.clear();
  pending_.clear();
  touching_.clear();
  destroy_next_.clear();
  limits_.clear();
  build_statics();
  build_bodies();
  // Contacts of the starting positions: solved by the first step, reported with it.
  collide(0.0, pending_);
}

dGeomID OdeEngine::add_segment(Vec2 a, Vec2 b, ObjectRef ref) {
  const Vec2 d = b - a;
  const double len = length(d);
  // A capsule: the segment with rounded ends of segment_radius. Its axis is its local z.
  dGeomID g = dCreateCapsule(space_, opt_.segment_radius, len);
  const Vec2 c = 0.5 * (a + b);
  dGeomSetPosition(g, c.x, c.y, 0.0);
  dMatrix3 R;
  dRFromZAxis(R, d.x / len, d.y / len, 0.0);
  dGeomSetRotation(g, R);
  dGeomSetData(g, reinterpret_cast<void*>(static_cast<std::uintptr_t>(adapter::pack(ref))));
  return g;
}

void OdeEngine::build_statics() {
  for (std::size_t i = 0; i < scene_.walls.size(); ++i) {
    const WallDef& w = scene_.walls[i];
    if (!(length(w.to - w.from) > 0.0)) throw std::invalid_argument("wall '" + w.name + "' has zero length");
    add_segment(w.from, w.to, {ObjectRef::Kind::Wall, static_cast<std::uint32_t>(i)});
  }
  for (std::size_t i = 0; i < scene_.boxes.size(); ++i) {
    const BoxDef& bx = scene_.boxes[i];
    const Vec2 size = bx.max - bx.min;
    if (!(size.x > 0.0) || !(size.y > 0.0)) throw std::invalid_argument("box '" + bx.name + "' has no area");
    dGeomID g = dCreateBox(space_, size.x, size.y, 2.0 * kHalfDepthZ);
    const Vec2 c = 0.5 * (bx.min + bx.max);
    dGeomSetPosition(g, c.x, c.y, 0.0);
    dGeomSetData(g, reinterpret_cast<void*>(static_cast<std::uintptr_t>(
                        adapter::pack({ObjectRef::Kind::Box, static_cast<std::uint32_t>(i)}))));
  }
  for (std::size_t i = 0; i < scene_.surfaces.size(); ++i) {
    const SurfaceDef& s = scene_.surfaces[i];
    if (s.points.size() < 2) throw std::invalid_argument("surface '" + s.name + "' needs at least 2 points");
    for (std::size_t k = 0; k + 1 < s.points.size(); ++k) {
      if (!(length(s.points[k + 1] - s.points[k]) > 0.0)) {
        throw std::invalid_argument("surface '" + s.name + "' repeats a point");
      }
      add_segment(s.points[k], s.points[k + 1], {ObjectRef::Kind::Surface, static_cast<std::uint32_t>(i)});
    }
  }
}

void OdeEngine::build_bodies() {
  const std::size_t n = scene_.bodies.size();
  bodies_.assign(n, nullptr);
  body_geoms_.assign(n, nullptr);
  alive_.assign(n, true);
  final_states_.assign(n, BodyState{});
  auto radius = [&](std::size_t i) { return scene_.bodies[i].shape == ShapeKind::Point ? 0.0 : scene_.bodies[i].radius; };
  const bool any_static_shape = !scene_.walls.empty() || !scene_.boxes.empty() || !scene_.surfaces.empty();
  tunnel_size_.assign(n, std::numeric_limits<double>::infinity());
  for (std::size_t i = 0; i < n; ++i) {
    if (any_static_shape) tunnel_size_[i] = radius(i);
    for (std::size_t j = 0; j < n; ++j) {
      const double size = radius(i) + radius(j);
      if (j != i && size > 0.0) tunnel_size_[i] = std::min(tunnel_size_[i], size);
    }
  }
  for (std::size_t i = 0; i < n; ++i) {
    const BodyDef& b = scene_.bodies[i];
    // A point is a sphere of segment_radius: ODE's broad phase drops geoms without extent.
    const double r = b.shape == ShapeKind::Point ? opt_.segment_radius : b.radius;
    dGeomID g = dCreateSphere(space_, r);
    dGeomSetData(g, reinterpret_cast<void*>(static_cast<std::uintptr_t>(
                        adapter::pack({ObjectRef::Kind::Body, static_cast<std::uint32_t>(i)}))));
    body_geoms_[i] = g;
    dMatrix3 R;
    dRFromAxisAndAngle(R, 0.0, 0.0, 1.0, b.angle);
    if (b.is_static) {   // a geom without a body is static
      dGeomSetPosition(g, b.position.x, b.position.y, 0.0);
      dGeomSetRotation(g, R);
      continue;
    }
    dBodyID body = dBodyCreate(world_);
    dMass m;
    // The scene's mass; a uniform disc's inertia 0.5 m r^2 about every axis (only z turns).
    const double inertia = 0.5 * b.mass * radius(i) * radius(i);
    const double I = inertia > 0.0 ? inertia : 1e-12 * b.mass;   // ODE needs a positive definite inertia
    dMassSetParameters(&m, b.mass, 0.0, 0.0, 0.0, I, I, I, 0.0, 0.0, 0.0);
    dBodySetMass(body, &m);
    dBodySetPosition(body, b.position.x, b.position.y, 0.0);
    dBodySetRotation(body, R);
    dBodySetLinearVel(body, b.velocity.x, b.velocity.y, 0.0);
    dBodySetAngularVel(body, 0.0, 0.0, b.angular_velocity);
    dBodySetAutoDisableFlag(body, 0);
    dBodySetGyroscopicMode(body, 0);   // a disc about its axis: no gyroscopic term to integrate
    dGeomSetBody(g, body);
    // Held in the plane z = 0: the plane-2D joint fixes z and the rotation about x and y.
    dJointID plane = dJointCreatePlane2D(world_, nullptr);
    dJointAttach(plane, body, nullptr);
    if (opt_.fixed_rotation || b.shape == ShapeKind::Point) {
      // Its angular motor keeps the spin the body starts with: no contact alters it.
      dJointSetPlane2DAngleParam(plane, dParamVel, b.angular_velocity);
      dJointSetPlane2DAngleParam(plane, dParamFMax, dInfinity);
    }
    bodies_[i] = body;
  }
}

void OdeEngine::near_callback(void* data, dGeomID g1, dGeomID g2) {
  auto* self = static_cast<OdeEngine*>(data);
  ObjectRef a;
  ObjectRef b;
  if (!adapter::order_pair(ref_of(g1), ref_of(g2), a, b)) return;
  const PairResponse r = self->objects_->response(a, b);
  if (!r.collide && !r.event) return;   // "ignore"
  dContact c[kMaxContacts];
  const int n = dCollide(g1, g2, kMaxContacts, &c[0].geom, sizeof(dContact));
  if (n <= 0) return;
  self->scratch_touching_.push_back(adapter::pair_key(a, b));
  if (!r.collide) return;   // "event": reported, never solved
  const PairMaterial m = self->objects_->pair_material(a, b);
  for (int k = 0; k < n; ++k) {
    // physval's material rule, in the contact joint: Coulomb friction proportional to the
    // normal force (dContactApprox1; without it mu would be a force bound in N), restitution
    // with physval's threshold.
    c[k].surface.mode = dContactBounce | dContactApprox1;
    c[k].surface.mu = self->objects_->contact_friction(a, b);   // rolling_friction: mu = c
    c[k].surface.bounce = m.restitution;
    c[k].surface.bounce_vel = self->opt_.restitution_threshold;
    dJointID j = dJointCreateContact(self->world_, self->contact_group_, &c[k]);
    dJointAttach(j, dGeomGetBody(g1), dGeomGetBody(g2));
  }
}

void OdeEngine::collide(double stamp, std::vector<ContactEvent>& events) {
  scratch_touching_.clear();
  dSpaceCollide(space_, this, &OdeEngine::near_callback);
  std::sort(scratch_touching_.begin(), scratch_touching_.end());
  scratch_touching_.erase(std::unique(scratch_touching_.begin(), scratch_touching_.end()), scratch_touching_.end());
  for (const adapter::PairKey& k : scratch_touching_) {
    if (std::binary_search(touching_.begin(), touching_.end(), k)) continue;
    const ObjectRef a = adapter::unpack(k.a);
    const ObjectRef b = adapter::unpack(k.b);
    const PairResponse r = objects_->response(a, b);
    if (r.event) events.push_back({a, b, stamp});
    // The contact joint just made resolves the bounce in the next step; destroy after it.
    if (r.destroy_first && SceneObjects::destructible(a)) destroy_next_.push_back(a.index);
    if (r.destroy_second && SceneObjects::destructible(b)) destroy_next_.push_back(b.index);
  }
  touching_.swap(scratch_touching_);
}

void OdeEngine::apply_external_forces() {
  if (!forces_->active()) return;
  read_states(scratch_states_);
  forces_->compute(scratch_states_, scratch_forces_);
  for (std::size_t i = 0; i < bodies_.size(); ++i) {
    if (bodies_[i] == nullptr || !alive_[i]) continue;
    // ODE integrates v += dt (F + constraint forces) / m, then x += dt v; it clears
    // accumulated forces after each step.
    dBodyAddForce(bodies_[i], scratch_forces_[i].x, scratch_forces_[i].y, 0.0);
  }
}

void OdeEngine::step(double dt) {
  if (!(dt > 0.0) || !std::isfinite(dt)) throw std::invalid_argument("ode: step dt must be > 0");
  apply_external_forces();
  // Only the first step has events before it: those of the starting positions.
  contacts_.swap(pending_);
  pending_.clear();
  destroy_seen_.swap(destroy_next_);
  destroy_next_.clear();
  t_step_limits = &limits_;
  t_step_time = time_ + dt;
  const int stepped = opt_.quickstep ? dWorldQuickStep(world_, dt) : dWorldStep(world_, dt);
  t_step_limits = nullptr;
  if (stepped == 0) throw std::runtime_error("ode: the step failed (out of memory)");
  dJointGroupEmpty(contact_group_);
  time_ += dt;
  std::sort(destroy_seen_.begin(), destroy_seen_.end());
  destroy_seen_.erase(std::unique(destroy_seen_.begin(), destroy_seen_.end()), destroy_seen_.end());
  for (std::uint32_t i : destroy_seen_) destroy(i);
  // The contacts of the positions this step reached: they began during this step. Their
  // joints are solved by the next one.
  collide(time_, contacts_);
  check_limits(dt);
}

void OdeEngine::destroy(std::uint32_t i) {
  if (i >= alive_.size() || !alive_[i]) return;
  std::vector<BodyState> now;
  read_states(now);
  final_states_[i] = now[i];
  final_states_[i].alive = false;
  alive_[i] = false;
  if (body_geoms_[i] != nullptr) {
    dGeomDestroy(body_geoms_[i]);
    body_geoms_[i] = nullptr;
  }
  if (bodies_[i] != nullptr) {
    dBodyDestroy(bodies_[i]);   // its plane-2D joint goes with it
    bodies_[i] = nullptr;
  }
}

void OdeEngine::check_limits(double dt) {
  for (std::size_t i = 0; i < bodies_.size(); ++i) {
    if (!alive_[i]) continue;
    const std::string& name = scene_.bodies[i].name;
    const dReal* p = bodies_[i] != nullptr ? dBodyGetPosition(bodies_[i]) : dGeomGetPosition(body_geoms_[i]);
    const double reach = std::max(std::fabs(static_cast<double>(p[0])), std::fabs(static_cast<double>(p[1])));
    if (adapter::coordinate_spacing(reach, Precision::Float64) > adapter::kPositionResolutionLimit) {
      limits_.hit("float_resolution", time_, [&] {
        return "body '" + name + "' is " + fmt(reach) + " m from the origin, where double positions are " +
               fmt(adapter::coordinate_spacing(reach, Precision::Float64)) + " m apart (limit 1e-4 m)";
      });
    }
    if (bodies_[i] == nullptr) continue;
    const dReal* v = dBodyGetLinearVel(bodies_[i]);
    const double travel = std::hypot(static_cast<double>(v[0]), static_cast<double>(v[1])) * dt;
    if (travel > tunnel_size_[i]) {
      limits_.hit("discrete_collision", time_, [&] {
        return "body '" + name + "' moved " + fmt(travel) + " m in one step, more than the " + fmt(tunnel_size_[i]) +
               " m (its radius plus the thinnest thing it can meet) that discrete collision needs; ODE has no "
               "continuous collision and can miss contacts";
      });
    }
    const double drift = std::fabs(static_cast<double>(dBodyGetPosition(bodies_[i])[2]));
    if (drift > adapter::kPositionResolutionLimit) {
      limits_.hit("plane_drift", time_, [&] {
        return "body '" + name + "' left the plane z = 0 by " + fmt(drift) + " m (the plane-2D joint is a soft constraint)";
      });
    }
  }
}

void OdeEngine::read_states(std::vector<BodyState>& out) const {
  out.resize(scene_.bodies.size());
  for (std::size_t i = 0; i < out.size(); ++i) {
    if (!alive_[i]) {
      out[i] = final_states_[i];
      continue;
    }
    const BodyDef& def = scene_.bodies[i];
    if (bodies_[i] == nullptr) {   // static
      out[i] = {def.position, {}, def.angle, 0.0, true};
      continue;
    }
    const dReal* p = dBodyGetPosition(bodies_[i]);
    const dReal* v = dBodyGetLinearVel(bodies_[i]);
    const dReal* R = dBodyGetRotation(bodies_[i]);   // 3x4, row-major
    const dReal* w = dBodyGetAngularVel(bodies_[i]);
    out[i] = {{static_cast<double>(p[0]), static_cast<double>(p[1])},
              {static_cast<double>(v[0]), static_cast<double>(v[1])},
              std::atan2(static_cast<double>(R[4]), static_cast<double>(R[0])),
              static_cast<double>(w[2]),
              true};
  }
}

std::vector<Setting> OdeEngine::settings() const {
  auto b = [](bool v) { return std::string(v ? "true" : "false"); };
  return {
      {"version", ode_version()},
      {"configuration", dGetConfiguration()},
      {"precision", "float64 (dDOUBLE)"},
      {"step_mode", opt_.quickstep ? "quickstep" : "step"},
      {"step", std::string(opt_.quickstep ? "dWorldQuickStep(dt)" : "dWorldStep(dt)") +
                   " per physval step, with the contact joints of the positions the step starts from; "
                   "semi-implicit Euler: v += dt a, x += dt v"},
      {"quickstep_iterations", std::to_string(opt_.quick_iterations)},
      {"quickstep_w", fmt(opt_.quick_w)},
      {"random_seed", "dRandSetSeed(0) at every load (dWorldQuickStep reorders constraints randomly)"},
      {"erp", fmt(opt_.erp)},
      {"cfm", fmt(opt_.cfm)},
      {"restitution_threshold", fmt(opt_.restitution_threshold)},
      {"bounce_vel", fmt(opt_.restitution_threshold) + " m/s in every contact (dSurfaceParameters::bounce_vel)"},
      {"contact_surface_layer", fmt(opt_.surface_layer)},
      {"max_correcting_velocity", fmt(opt_.max_correcting_velocity)},
      {"contact_max_correcting_vel", opt_.max_correcting_velocity >= kUnbounded
                                         ? std::string("dInfinity (unbounded, ODE's default)")
                                         : fmt(opt_.max_correcting_velocity) + " m/s"},
      {"segment_radius", fmt(opt_.segment_radius)},
      {"fixed_rotation", b(opt_.fixed_rotation)},
      {"contact_mode", "dContactBounce | dContactApprox1 (Coulomb friction mu N; the second friction direction "
                       "is z, held by the plane-2D joint)"},
      {"auto_disable", "0 (sleeping off, ODE's default)"},
      {"damping", "0 (dWorldSetDamping linear and angular)"},
      {"continuous_collision", "none: ODE has no time of impact; missed contacts are reported in limits_hit"},
      {"plane", "dJointCreatePlane2D on every dynamic body; with fixed_rotation its angle motor (dParamVel = the "
                "initial spin, dParamFMax = dInfinity)"},
      {"material_rule",
       "near callback: every contact joint gets bounce min(e1, e2), mu sqrt(f1 f2), per-pair overrides (ODE has "
       "no mixing of its own: dContact is the user's)"},
      {"rolling_friction", "a pair with rolling_friction c > 0 gets contact friction mu = c (core's model for bodies "
                           "that do not spin); needs fixed_rotation"},
      {"uniform_gravity", "dWorldSetGravity"},
      {"external_forces", "drag and wind, thrust, Newtonian gravity: physval forces.hpp, dBodyAddForce every step"},
      {"external_forces_evaluated", "at the start of each step, from the state the previous step left"},
      {"mass", "dMassSetParameters: the scene's mass, inertia 0.5 m r^2"},
      {"circles", "dCreateSphere"},
      {"points", "dCreateSphere of segment_radius"},
      {"static_bodies", "a sphere geom without a body"},
      {"walls", "dCreateCapsule of segment_radius along the segment (two-sided, rounded ends)"},
      {"boxes", "dCreateBox of the scene's box, extruded +-1 m along z"},
      {"surfaces", "one capsule of segment_radius per segment (two-sided)"},
      {"space", "dSimpleSpace (every pair tested)"},
      {"collision_matrix",
       "near callback: ignore: no contact joint, no event; event: reported, no contact joint; destroy: removed "
       "after the step that resolves the bounce"},
      {"contact_events", "pairs dCollide finds after a step (first touching), once per physval pair, stamped with "
                         "the end of that step"},
  };
}

}  // namespace

EngineFactory ode_engine_factory() {
  EngineFactory f;
  f.info.name = kEngineName;
  f.info.version = ode_version();
  f.info.precision = Precision::Float64;
  f.info.summary = "ODE " + ode_version() + " (double) held in the plane by plane-2D joints: spheres, capsules, boxes";
  f.info.features = ode_features();
  f.info.options = ode_options();
  f.create = [info = f.info]() -> std::unique_ptr<Engine> { return std::make_unique<OdeEngine>(info); };
  return f;
}

}  // namespace physval
