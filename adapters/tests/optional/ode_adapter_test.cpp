// ODE 0.16 behind physval: the adapter reproduces the raw library bit for bit (the same
// world built by hand, with plane-2D joints and contact joints carrying physval's rule),
// and publishes its settings.
#include <ode/ode.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "../adapter_test_scenes.hpp"

namespace physval::test {
namespace {

Scene two_balls_on_a_slope() {
  Scene s = empty_scene("slope", 1.0 / 60.0, 3.0);
  s.world.gravity = {0.0, -9.81};
  BodyDef a = circle("a", 0.5, 1.0, {0.0, 3.0}, {0.5, 0.0}, 0.9);
  a.friction = a.static_friction = 0.3;
  BodyDef b = circle("b", 0.3, 2.0, {0.2, 5.0}, {0.0, -1.0}, 0.6);
  b.friction = b.static_friction = 0.5;
  s.bodies = {a, b};
  const double th = 20.0 * M_PI / 180.0;
  WallDef floor = wall("floor", {-10.0 * std::cos(th), 10.0 * std::sin(th)}, {10.0 * std::cos(th), -10.0 * std::sin(th)}, 0.8);
  floor.material.friction = floor.material.static_friction = 0.4;
  s.walls = {floor};
  return s;
}

struct Mat {
  double e;
  double mu;
};

// The same scene in raw ODE: the calls the README's adapter table lists.
struct RawOde {
  dWorldID world = dWorldCreate();
  dSpaceID space = dSimpleSpaceCreate(nullptr);
  dJointGroupID group = dJointGroupCreate(0);
  std::vector<dBodyID> bodies;
  std::vector<Mat> mats;   // stable: reserved
  bool quick = false;
  static void near(void* data, dGeomID a, dGeomID b) {
    auto* self = static_cast<RawOde*>(data);
    dContact c[4];
    const int n = dCollide(a, b, 4, &c[0].geom, sizeof(dContact));
    const Mat* ma = static_cast<const Mat*>(dGeomGetData(a));
    const Mat* mb = static_cast<const Mat*>(dGeomGetData(b));
    for (int k = 0; k < n; ++k) {
      c[k].surface.mode = dContactBounce | dContactApprox1;
      c[k].surface.mu = std::sqrt(ma->mu * mb->mu);
      c[k].surface.bounce = std::min(ma->e, mb->e);
      c[k].surface.bounce_vel = 0.0;
      dJointAttach(dJointCreateContact(self->world, self->group, &c[k]), dGeomGetBody(a), dGeomGetBody(b));
    }
  }
  explicit RawOde(const Scene& s) {
    dInitODE2(0);
    dRandSetSeed(0);
    mats.reserve(s.walls.size() + s.bodies.size());
    dWorldSetGravity(world, s.world.gravity.x, s.world.gravity.y, 0.0);
    for (const WallDef& w : s.walls) {
      const Vec2 d = w.to - w.from;
      const double len = length(d);
      dGeomID g = dCreateCapsule(space, 1e-9, len);
      dGeomSetPosition(g, 0.5 * (w.from.x + w.to.x), 0.5 * (w.from.y + w.to.y), 0.0);
      dMatrix3 R;
      dRFromZAxis(R, d.x / len, d.y / len, 0.0);
      dGeomSetRotation(g, R);
      mats.push_back({w.material.restitution, w.material.friction});
      dGeomSetData(g, &mats.back());
    }
    for (const BodyDef& b : s.bodies) {
      dGeomID g = dCreateSphere(space, b.radius);
      dBodyID body = dBodyCreate(world);
      dMass m;
      const double I = 0.5 * b.mass * b.radius * b.radius;
      dMassSetParameters(&m, b.mass, 0, 0, 0, I, I, I, 0, 0, 0);
      dBodySetMass(body, &m);
      dBodySetPosition(body, b.position.x, b.position.y, 0.0);
      dMatrix3 R;
      dRFromAxisAndAngle(R, 0, 0, 1, b.angle);
      dBodySetRotation(body, R);
      dBodySetLinearVel(body, b.velocity.x, b.velocity.y, 0.0);
      dBodySetAngularVel(body, 0, 0, b.angular_velocity);
      dBodySetGyroscopicMode(body, 0);
      dGeomSetBody(g, body);
      dJointID j = dJointCreatePlane2D(world, nullptr);
      dJointAttach(j, body, nullptr);
      dJointSetPlane2DAngleParam(j, dParamVel, b.angular_velocity);
      dJointSetPlane2DAngleParam(j, dParamFMax, dInfinity);
      mats.push_back({b.restitution, b.friction});
      dGeomSetData(g, &mats.back());
      bodies.push_back(body);
    }
  }
  // ODE's loop: collide, step, empty the contact group.
  void step(double dt) {
    dSpaceCollide(space, this, &near);
    if (quick) dWorldQuickStep(world, dt); else dWorldStep(world, dt);
    dJointGroupEmpty(group);
  }
  ~RawOde() {
    dJointGroupDestroy(group);
    dSpaceDestroy(space);
    dWorldDestroy(world);
  }
};

// The adapter's run first, then the raw one: dWorldQuickStep draws on ODE's one global
// random generator, so the two runs must not interleave (each reseeds it at its start).
void expect_same_bits(const Scene& s, bool quick, int min_contact_steps) {
  auto e = make_engine("ode", s);
  std::vector<std::vector<BodyState>> adapter_states;
  int contact_steps = 0;
  for (int n = 0; n < s.steps(); ++n) {
    e->step(s.dt);
    adapter_states.push_back(states(*e));
    if (!e->contacts().empty()) ++contact_steps;
  }
  RawOde raw(s);
  raw.quick = quick;
  for (int n = 0; n < s.steps(); ++n) {
    raw.step(s.dt);
    const auto& st = adapter_states[static_cast<std::size_t>(n)];
    for (std::size_t i = 0; i < raw.bodies.size(); ++i) {
      const dReal* p = dBodyGetPosition(raw.bodies[i]);
      const dReal* v = dBodyGetLinearVel(raw.bodies[i]);
      ASSERT_EQ(st[i].position.x, p[0]) << "step " << n << " body " << i;
      ASSERT_EQ(st[i].position.y, p[1]) << "step " << n << " body " << i;
      ASSERT_EQ(st[i].velocity.x, v[0]) << "step " << n << " body " << i;
      ASSERT_EQ(st[i].velocity.y, v[1]) << "step " << n << " body " << i;
    }
  }
  // The scene is not trivial: bodies met.
  EXPECT_GE(contact_steps, min_contact_steps);
}

TEST(OdeAdapter, ReproducesTheRawLibraryBitForBit) { expect_same_bits(two_balls_on_a_slope(), false, 2); }

TEST(OdeAdapter, ReproducesTheRawLibraryBitForBitWithQuickStep) {
  Scene s = two_balls_on_a_slope();
  s.engine_options["ode"]["step_mode"] = std::string("quickstep");
  expect_same_bits(s, true, 2);
}

TEST(OdeAdapter, ReproducesAHeadOnCollisionBitForBit) {
  Scene s = head_on(1.0, 3.0, 2.0, -1.0, 1.0 / 60.0);
  s.bodies[0].restitution = 0.7;
  expect_same_bits(s, false, 1);
}

TEST(OdeAdapter, QuickStepRunsAreRepeatable) {
  // dWorldQuickStep reorders constraints with ODE's global generator; the adapter reseeds
  // it at every load, so the same scene gives the same bits twice.
  Scene s = two_balls_on_a_slope();
  s.engine_options["ode"]["step_mode"] = std::string("quickstep");
  auto first = make_engine("ode", s);
  run(*first, s, s.steps());
  auto second = make_engine("ode", s);
  run(*second, s, s.steps());
  const auto a = states(*first);
  const auto b = states(*second);
  for (std::size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].position.x, b[i].position.x);
    EXPECT_EQ(a[i].position.y, b[i].position.y);
  }
}

TEST(OdeAdapter, FrictionIsCoulombNotAForceBound) {
  // A non-spinning ball on a 30 degree slope with mu = 0.3 slides at g (sin - mu cos):
  // dContactApprox1. (Mode 0 would read mu as a force bound in N: probe.)
  Scene s = empty_scene("slope", 1.0 / 60.0, 1.0);
  s.world.gravity = {0.0, -9.81};
  const double th = M_PI / 6.0;
  const Vec2 dir{std::cos(th), -std::sin(th)};
  const Vec2 n{std::sin(th), std::cos(th)};
  BodyDef ball = circle("ball", 0.5, 1.0, 0.5 * n, {0.0, 0.0}, 0.0);
  ball.friction = ball.static_friction = 0.3;
  s.bodies.push_back(ball);
  WallDef floor = wall("slope", -50.0 * dir, 50.0 * dir, 0.0);
  floor.material.friction = floor.material.static_friction = 0.3;
  s.walls.push_back(floor);
  auto e = make_engine("ode", s);
  run(*e, s, 60);
  const BodyState st = states(*e)[0];
  EXPECT_NEAR(dot(st.velocity, dir), 9.81 * (std::sin(th) - 0.3 * std::cos(th)), 1e-6);
}

TEST(OdeAdapter, PublishesItsSettings) {
  auto e = make_engine("ode", two_balls_on_a_slope());
  const auto set = e->settings();
  EXPECT_EQ(setting(set, "version"), "0.16.2");
  EXPECT_EQ(setting(set, "step_mode"), "step");
  EXPECT_EQ(setting(set, "erp"), "0.2");
  EXPECT_EQ(setting(set, "cfm"), "1e-10");
  EXPECT_NE(setting(set, "configuration").find("ODE_double_precision"), std::string::npos);
  for (const char* key : {"quickstep_iterations", "restitution_threshold", "contact_surface_layer",
                          "max_correcting_velocity", "segment_radius", "auto_disable", "damping", "contact_mode",
                          "continuous_collision", "material_rule", "external_forces_evaluated", "random_seed"}) {
    EXPECT_TRUE(has_setting(set, key)) << key;
  }
  EXPECT_EQ(find_engine("ode")->info.precision, Precision::Float64);
}

TEST(OdeAdapter, ZeroSegmentRadiusIsRefused) {
  Scene s = two_balls_on_a_slope();
  s.engine_options["ode"]["segment_radius"] = 0.0;
  try {
    make_engine("ode", s);
    FAIL() << "loaded with segment_radius 0";
  } catch (const std::exception& err) {   // through the plugin: the loader's PluginError
    EXPECT_NE(std::string(err.what()).find("segment_radius must be > 0"), std::string::npos) << err.what();
  }
}

}  // namespace
}  // namespace physval::test
