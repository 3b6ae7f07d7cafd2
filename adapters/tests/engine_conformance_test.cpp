// The same physics asked of both adapters (issue 6): each test runs on Box2D and on
// Bullet and compares with the analytic answer, with a tolerance derived from what the
// engine is (its precision, its integrator, its contact distance) and stated here.
#include <cmath>
#include <string>

#include <gtest/gtest.h>

#include "adapter_test_scenes.hpp"
#include "physval/core/forces.hpp"

namespace physval::test {
namespace {

// What a test needs to know of an engine to predict it.
struct EngineTraits {
  std::string name;
  double unit_roundoff;   // half the spacing of floating-point numbers near 1
  bool float32;
  // How far from touching (gap between the surfaces, m) the engine can begin a contact
  // of a circle of radius r with a wall: Box2D thickens edges by its skin
  // b2_polygonRadius = 0.01 m; Bullet keeps manifold points up to its breaking
  // threshold, gContactBreakingThreshold (0.02) times the sphere's angular motion
  // disc (sqrt(3) r).
  double reach(double r) const { return name == "box2d" ? 0.01 : 0.02 * std::sqrt(3.0) * r; }
  // Chipmunk moves positions with the velocity a step starts with, then updates the
  // velocity (x += h v; v += h a); the others update the velocity first (semi-implicit).
  bool positions_first = false;
  // Relative shortfall of a bounce speed beyond rounding: ODE's CFM (1e-10) softens a
  // contact by cfm * lambda with lambda = m (1 + e) v / dt, relative cfm m (1 + e) / dt:
  // at most 1e-10 * 1 * 2 * 60 = 1.2e-8 for the unit mass at dt 1/60 (measured: e = 0.5
  // at 4 m/s leaves 3.6e-8 m/s short, exactly 1e-10 * 1.5 * 4 * 60).
  double bounce_softness = 0.0;
};

void PrintTo(const EngineTraits& t, std::ostream* os) { *os << t.name; }

std::string traits_name(const ::testing::TestParamInfo<EngineTraits>& info) { return info.param.name; }

class Conformance : public ::testing::TestWithParam<EngineTraits> {
 protected:
  const EngineTraits& traits() const { return GetParam(); }
  // A value as the engine stores it: rounded to float for Box2D.
  double stored(double v) const { return traits().float32 ? static_cast<double>(static_cast<float>(v)) : v; }
};

// --- collisions between bodies --------------------------------------------------

// v1' = (2 m2 v2 + v1 (m1 - m2)) / (m1 + m2), v2' = (2 m1 v1 + v2 (m2 - m1)) / (m1 + m2).
TEST_P(Conformance, HeadOnElasticUnequalMasses) {
  for (double dt : {0.001, 1.0 / 60.0}) {
    const Scene s = head_on(1.0, 3.0, 2.0, -1.0, dt);
    auto e = make_engine(traits().name, s);
    const auto events = run(*e, s, s.steps());
    const auto st = states(*e);
    // 1e-6 m/s: the bound. Both engines meet it with room: an elastic pair's
    // impulse is solved exactly to the float (Box2D, ~1e-7 relative) or double rounding.
    EXPECT_NEAR(st[0].velocity.x, -2.5, 1e-6) << "dt " << dt;
    EXPECT_NEAR(st[1].velocity.x, 0.5, 1e-6) << "dt " << dt;
    EXPECT_NEAR(st[0].velocity.y, 0.0, 1e-12);
    // Momentum 1*2 + 3*(-1) = -1 kg m/s: to the same 1e-6 (both velocities carry it).
    EXPECT_NEAR(1.0 * st[0].velocity.x + 3.0 * st[1].velocity.x, -1.0, 1e-6);
    // The pair touches at t = 1 s (gap 3 m closing at 3 m/s). Events are stamped with
    // the end of the step the engine sees them in: at the earliest the step holding
    // t = 1 s, at the latest the next (detection at the start of the following step).
    ASSERT_FALSE(events.empty());
    EXPECT_EQ(events[0].a, (ObjectRef{ObjectRef::Kind::Body, 0}));
    EXPECT_EQ(events[0].b, (ObjectRef{ObjectRef::Kind::Body, 1}));
    EXPECT_GE(events[0].time, 1.0 - 1e-9) << "dt " << dt;
    EXPECT_LE(events[0].time, 1.0 + 2.0 * dt + 1e-9) << "dt " << dt;
    EXPECT_EQ(events.size(), 1u) << "one collision, one event";
  }
}

TEST_P(Conformance, EqualMassesSwapVelocities) {
  const Scene s = head_on(2.0, 2.0, 1.5, -0.5, 1.0 / 60.0);
  auto e = make_engine(traits().name, s);
  run(*e, s, s.steps());
  const auto st = states(*e);
  EXPECT_NEAR(st[0].velocity.x, -0.5, 1e-6);
  EXPECT_NEAR(st[1].velocity.x, 1.5, 1e-6);

  // A moving ball hitting one at rest stops dead; the other leaves with its velocity.
  const Scene rest = head_on(1.0, 1.0, 2.0, 0.0, 1.0 / 60.0);
  auto e2 = make_engine(traits().name, rest);
  run(*e2, rest, rest.steps());
  const auto st2 = states(*e2);
  EXPECT_NEAR(st2[0].velocity.x, 0.0, 1e-6);
  EXPECT_NEAR(st2[1].velocity.x, 2.0, 1e-6);
}

// --- free flight ---------------------------------------------------------------------

// Semi-implicit Euler from y0, v0 under g: v_k = v0 + k h g, y_n = y0 + h sum v_k =
// y0 + n h v0 + g h^2 n (n + 1) / 2. Its error against the parabola (g h^2 n / 2 in y)
// is the integrator's, not the engine's, so the engine is held to the closed form.
double euler_y(double y0, double v0, double g, double h, int n, bool positions_first = false) {
  const double nn = static_cast<double>(n);
  // Positions first: y_n = y0 + h sum_{k<n} v_k = y0 + n h v0 + g h^2 n (n - 1) / 2.
  return y0 + nn * h * v0 + g * h * h * nn * (positions_first ? nn - 1.0 : nn + 1.0) / 2.0;
}

// First-order bound on the rounding of n steps with unit roundoff u: each velocity
// update v += h (m^-1 (m g)) rounds about 3 operations, each position update y += h v
// two; the velocity error carries into y through h.
double euler_rounding_bound(double y0, double v0, double g, double h, int n, double u) {
  double v = v0;
  double y = y0;
  double ev = u * std::fabs(v0);
  double ey = u * std::fabs(y0);
  for (int k = 1; k <= n; ++k) {
    v += g * h;
    y += h * v;
    ev += u * (std::fabs(v) + 3.0 * std::fabs(g * h));
    ey += h * ev + u * (std::fabs(y) + 2.0 * std::fabs(h * v));
  }
  return ey;
}

// Semi-implicit Euler (Box2D, Bullet, ODE) or its positions-first twin (Chipmunk).
TEST_P(Conformance, ProjectileFollowsTheEnginesEulerScheme) {
  Scene s = empty_scene("projectile", 1.0 / 60.0, 2.0);
  s.world.gravity = {0.0, -9.81};
  s.bodies.push_back(circle("shell", 0.1, 1.7, {0.3, 1.1}, {3.0, 10.0}));
  auto e = make_engine(traits().name, s);
  // The closed form with the inputs the engine actually holds (float for Box2D).
  const double h = stored(s.dt);
  const double g = stored(-9.81);
  const double x0 = stored(0.3), y0 = stored(1.1), vx = stored(3.0), vy = stored(10.0);
  const double u = traits().unit_roundoff;
  double worst = 0.0;
  for (int n = 1; n <= s.steps(); ++n) {
    e->step(s.dt);
    const BodyState st = states(*e)[0];
    const double y = euler_y(y0, vy, g, h, n, traits().positions_first);
    const double x = euler_y(x0, vx, 0.0, h, n, traits().positions_first);
    const double tol_y = euler_rounding_bound(y0, vy, g, h, n, u);
    const double tol_x = euler_rounding_bound(x0, vx, 0.0, h, n, u);
    ASSERT_NEAR(st.position.y, y, tol_y) << "step " << n;
    ASSERT_NEAR(st.position.x, x, tol_x) << "step " << n;
    ASSERT_NEAR(st.velocity.y, vy + n * h * g, 4.0 * n * u * (std::fabs(vy) + std::fabs(n * h * g)) + u) << "step " << n;
    worst = std::max(worst, std::fabs(st.position.y - y));
  }
  // The integrator's own error against the true parabola is far larger than the
  // rounding: what the comparator will see is the scheme, not the engine.
  const double t = s.steps() * s.dt;
  const double parabola = 1.1 + 10.0 * t - 0.5 * 9.81 * t * t;
  EXPECT_GT(std::fabs(euler_y(y0, vy, g, h, s.steps(), traits().positions_first) - parabola), 100.0 * worst);
}

TEST_P(Conformance, SlowFreeBodyNeverSleeps) {
  // Bullet froze a free body at 0.5 m/s after 121 steps; Box2D sleeps after 0.5 s
  // under its sleep tolerance. 10 s at 0.5 m/s must cover 5 m.
  Scene s = empty_scene("slow", 1.0 / 60.0, 10.0);
  s.bodies.push_back(circle("slow", 0.5, 1.0, {0.0, 0.0}, {0.5, 0.0}));
  auto e = make_engine(traits().name, s);
  for (int n = 1; n <= s.steps(); ++n) {
    e->step(s.dt);
    ASSERT_EQ(states(*e)[0].velocity.x, stored(0.5)) << "step " << n;   // no force: unchanged, exactly
  }
  // x_n = n h v with the h and v the engine holds (float(1/60) alone moves 5 m by
  // 2e-7 m); each of the 600 steps rounds the product h v and the sum x + h v, the
  // latter by at most u |x| <= 5 u.
  const double expected = s.steps() * stored(s.dt) * stored(0.5);
  const double tol = s.steps() * (5.0 + stored(s.dt) * 0.5) * traits().unit_roundoff;
  EXPECT_NEAR(states(*e)[0].position.x, expected, tol);
  EXPECT_NEAR(expected, 5.0, traits().float32 ? 1e-6 : 1e-12);
}

// --- contact with a wall ------------------------------------------------------------

TEST_P(Conformance, DropFirstContactStep) {
  const double r = 0.5;
  const double g = -9.81;
  for (double dt : {1.0 / 30.0, 1.0 / 60.0, 1.0 / 120.0, 0.001}) {
    for (double y0 : {10.0, 5.0, 2.0, 1.0}) {
      Scene s = empty_scene("drop", dt, 3.0);
      s.world.gravity = {0.0, g};
      s.bodies.push_back(circle("ball", r, 1.0, {0.0, y0}, {0.0, 0.0}));
      s.walls.push_back(wall("floor", {-10.0, 0.0}, {10.0, 0.0}));
      auto e = make_engine(traits().name, s);
      int event_step = -1;
      for (int n = 1; n <= s.steps() && event_step < 0; ++n) {
        e->step(dt);
        if (!e->contacts().empty()) {
          event_step = n;
          EXPECT_EQ(e->contacts()[0].a, (ObjectRef{ObjectRef::Kind::Body, 0}));
          EXPECT_EQ(e->contacts()[0].b, (ObjectRef{ObjectRef::Kind::Wall, 0}));
          EXPECT_NEAR(e->contacts()[0].time, n * dt, 1e-9);
        }
      }
      ASSERT_GT(event_step, 0) << "no contact: dt " << dt << " y0 " << y0;
      // The engine's own trajectory is semi-implicit Euler: the ball's centre reaches
      // y = r at the end of step n_touch, and comes within the engine's contact reach
      // at the end of step n_reach <= n_touch. The contact begins no earlier than the
      // step after n_reach - 1 (a manifold found at the start of a step, or within it by
      // Box2D's time of impact) and no later than the step after n_touch (found at the
      // start of the next step).
      const double h = stored(dt);
      int n_touch = 0;
      int n_reach = 0;
      for (int n = 1; n_touch == 0; ++n) {
        const double y = euler_y(y0, 0.0, g, h, n);
        if (n_reach == 0 && y <= r + traits().reach(r)) n_reach = n;
        if (y <= r) n_touch = n;
      }
      EXPECT_GE(event_step, n_reach) << "dt " << dt << " y0 " << y0;
      EXPECT_LE(event_step, n_touch + 1) << "dt " << dt << " y0 " << y0;
      // Against the exact time t* = sqrt(2 (y0 - r) / g): the canonical case,
      // the 10 m drop at 1/60 s, begins in the step t* falls in or the next.
      if (y0 == 10.0 && dt == 1.0 / 60.0) {
        const int n_exact = static_cast<int>(std::ceil(std::sqrt(2.0 * (y0 - r) / -g) / dt));
        EXPECT_GE(event_step, n_exact);
        EXPECT_LE(event_step, n_exact + 1);
      }
    }
  }
}

// --- materials -------------------------------------------------------------------

// physval's rule: restitution min(e1, e2). Box2D's own would bounce at max (0.9 here),
// Bullet's own at the product (0.45): both must give 0.5.
TEST_P(Conformance, MaterialRuleSetsBounceSpeed) {
  struct Case {
    double ball_e, wall_e;
    std::optional<double> override_e;
    double expected;
  };
  for (const Case& c : {Case{0.9, 0.5, std::nullopt, 0.5}, Case{0.3, 0.8, std::nullopt, 0.3},
                        Case{0.9, 0.5, 0.75, 0.75}}) {
    Scene s = empty_scene("bounce", 1.0 / 60.0, 1.0);
    s.bodies.push_back(circle("ball", 0.5, 1.0, {0.0, 1.6}, {0.0, -4.0}, c.ball_e));
    s.walls.push_back(wall("floor", {-10.0, 0.0}, {10.0, 0.0}, c.wall_e));
    if (c.override_e) {
      MaterialOverride o;
      o.a = "floor";
      o.b = "ball";
      o.restitution = c.override_e;
      s.materials.push_back(o);
    }
    auto e = make_engine(traits().name, s);
    run(*e, s, s.steps());
    // No gravity: the bounce speed is e * 4 m/s exactly up to the engine's rounding
    // (float: 1e-6 relative covers the few operations of one contact impulse).
    EXPECT_NEAR(states(*e)[0].velocity.y, 4.0 * c.expected,
                4.0 * (traits().float32 ? 1e-6 : std::max(1e-12, traits().bounce_softness)))
        << c.ball_e << " vs " << c.wall_e;
  }
  // Two bodies of different restitution, head-on: 1.0 and 0.6 give e = 0.6;
  // equal masses 1 m/s each way leave at 0.6 m/s each way.
  Scene s = head_on(1.0, 1.0, 1.0, -1.0, 1.0 / 60.0);
  s.bodies[1].restitution = 0.6;
  auto e = make_engine(traits().name, s);
  run(*e, s, s.steps());
  EXPECT_NEAR(states(*e)[0].velocity.x, -0.6, 1e-6);
  EXPECT_NEAR(states(*e)[1].velocity.x, 0.6, 1e-6);
}

// --- what an engine cannot model -------------------------------------------------

TEST_P(Conformance, MissingFeaturesAreUnsupportedByName) {
  const EngineFactory* f = find_engine(traits().name);
  ASSERT_NE(f, nullptr);
  Scene base = head_on(1.0, 1.0, 1.0, -1.0, 1.0 / 60.0);
  EXPECT_TRUE(unsupported_features(f->info, base).empty());

  Scene rolling = base;
  rolling.walls.push_back(wall("floor", {-5.0, -1.0}, {5.0, -1.0}));
  rolling.bodies[0].rolling_friction = 0.02;
  rolling.walls[0].material.rolling_friction = 0.02;
  // Every adapter maps rolling_friction to contact friction mu = c (core's model for
  // bodies that do not spin); adapter_fairness_test checks the deceleration.
  EXPECT_TRUE(unsupported_features(f->info, rolling).empty());

  Scene sticky = base;
  sticky.bodies[0].friction = 0.3;
  sticky.bodies[0].static_friction = 0.5;
  EXPECT_EQ(unsupported_features(f->info, sticky), std::vector<std::string>{"static_friction"});

  Scene sparks = base;
  EmitterDef em;
  em.name = "sparks";
  em.parent = "a";
  em.count = 10;
  sparks.emitters.push_back(em);
  EXPECT_EQ(unsupported_features(f->info, sparks), std::vector<std::string>{"particles"});

  // Loading one anyway fails loudly, naming the feature: never a silent drop.
  auto e = f->create();
  try {
    e->load(sparks);
    FAIL() << "loaded a scene with particles";
  } catch (const std::exception& ex) {
    EXPECT_NE(std::string(ex.what()).find("particles"), std::string::npos) << ex.what();
  }
}

TEST_P(Conformance, EveryOptionIsDocumentedAndReportedInSettings) {
  const EngineFactory* f = find_engine(traits().name);
  ASSERT_NE(f, nullptr);
  const Scene s = head_on(1.0, 1.0, 1.0, -1.0, 1.0 / 60.0);
  auto e = make_engine(traits().name, s);
  const auto settings = e->settings();
  for (const OptionSpec& o : f->info.options) {
    EXPECT_FALSE(o.doc.empty()) << o.key;
    EXPECT_TRUE(has_setting(settings, o.key)) << o.key;
    EXPECT_EQ(setting(settings, o.key), option_value_to_string(o.default_value)) << o.key;
  }
  EXPECT_EQ(setting(settings, "version"), f->info.version);
}

// --- forces applied from forces.hpp -----------------------------------------------

// Semi-implicit Euler in double with the forces of forces.hpp: what core computes and
// what each adapter hands its engine every step as an external force.
std::vector<BodyState> predict_free_flight(const Scene& s, int steps, bool positions_first = false) {
  std::vector<BodyState> st;
  for (const BodyDef& b : s.bodies) st.push_back({b.position, b.velocity, b.angle, b.angular_velocity, true});
  WorldDef field_free = s.world;
  field_free.gravity = {};
  std::vector<Vec2> f(st.size());
  std::vector<Vec2> pos(st.size());
  std::vector<double> mass(st.size());
  for (int n = 0; n < steps; ++n) {
    for (std::size_t i = 0; i < st.size(); ++i) {
      f[i] = body_force(s.bodies[i], field_free, st[i].velocity, st[i].angle);
      pos[i] = st[i].position;
      mass[i] = s.bodies[i].mass;
    }
    if (s.world.newtonian) add_newtonian_forces(s.world.G, s.world.softening, pos, mass, f);
    for (std::size_t i = 0; i < st.size(); ++i) {
      if (s.bodies[i].is_static) continue;
      if (positions_first) st[i].position += s.dt * st[i].velocity;
      st[i].velocity += s.dt * (s.world.gravity + f[i] / s.bodies[i].mass);
      if (!positions_first) st[i].position += s.dt * st[i].velocity;
    }
  }
  return st;
}

TEST_P(Conformance, ExternalForcesFollowTheSharedForceModels) {
  // Drag towards a wind (linear and quadratic), a thrust table along the heading, and
  // Newtonian attraction between two heavy bodies (a static one attracts, takes nothing).
  Scene s = empty_scene("forces", 1.0 / 60.0, 2.0);
  s.world.gravity = {0.0, -9.81};
  s.world.wind = {2.0, 0.5};
  s.world.newtonian = true;
  s.world.G = 1.0;   // a toy constant so that the attraction is of the other forces' size
  s.world.softening = 0.1;
  BodyDef kite = circle("kite", 0.1, 0.5, {0.0, 0.0}, {1.0, 4.0});
  kite.drag_linear = 0.3;
  kite.drag_quadratic = 0.05;
  BodyDef car = circle("car", 0.2, 2.0, {0.0, -20.0}, {0.5, 0.0});
  car.angle = 0.3;
  car.thrust.speeds = {0.0, 5.0, 10.0};
  car.thrust.gears = {1.0, 2.0};
  car.thrust.accel = {{3.0, 2.0, 0.5}, {2.0, 2.5, 1.5}};
  car.thrust.gear = 1.4;
  car.thrust.throttle = 0.8;
  BodyDef sun = circle("sun", 0.3, 5.0, {6.0, -10.0}, {0.0, 0.0});
  sun.is_static = true;
  s.bodies = {kite, car, sun};
  auto e = make_engine(traits().name, s);
  run(*e, s, s.steps());
  const auto got = states(*e);
  const auto want = predict_free_flight(s, s.steps(), traits().positions_first);
  // Bullet runs the very recursion in double: 1e-9 m. Box2D holds states and forces in
  // float: each of the 120 steps rounds about 8 operations at relative 2^-24, on
  // positions up to ~30 m and velocities up to ~20 m/s: 120 * 8 * 6e-8 * 30 = 2e-3 m.
  const double pos_tol = traits().float32 ? 120 * 8 * traits().unit_roundoff * 30.0 : 1e-9;
  const double vel_tol = traits().float32 ? 120 * 8 * traits().unit_roundoff * 20.0 : 1e-9;
  for (std::size_t i = 0; i < 3; ++i) {
    EXPECT_NEAR(got[i].position.x, want[i].position.x, pos_tol) << s.bodies[i].name;
    EXPECT_NEAR(got[i].position.y, want[i].position.y, pos_tol) << s.bodies[i].name;
    EXPECT_NEAR(got[i].velocity.x, want[i].velocity.x, vel_tol) << s.bodies[i].name;
    EXPECT_NEAR(got[i].velocity.y, want[i].velocity.y, vel_tol) << s.bodies[i].name;
  }
  // The forces mattered: without them the kite would have flown elsewhere.
  Scene bare = s;
  bare.world.newtonian = false;
  bare.bodies[0].drag_linear = bare.bodies[0].drag_quadratic = 0.0;
  bare.bodies[1].thrust = {};
  const auto without = predict_free_flight(bare, s.steps());
  EXPECT_GT(length(without[0].position - want[0].position), 1.0);
  EXPECT_GT(length(without[1].position - want[1].position), 1.0);
}

// --- static shapes ----------------------------------------------------------------

TEST_P(Conformance, BoxesSurfacesAndPointsBounce) {
  // A ball onto a box's top face, a ball onto a surface from its normals' side, and a
  // point onto a static circle: each bounces (e = 1, 3 m/s) and reports its pair.
  Scene s = empty_scene("statics", 1.0 / 120.0, 1.0);
  s.bodies.push_back(circle("on_box", 0.25, 1.0, {-6.0, 1.63}, {0.0, -3.0}));
  s.bodies.push_back(circle("on_surface", 0.25, 1.0, {0.0, 1.63}, {0.0, -3.0}));
  BodyDef point = circle("point", 0.0, 0.1, {6.0, 1.63}, {0.0, -3.0});
  point.shape = ShapeKind::Point;
  s.bodies.push_back(point);
  BodyDef post = circle("post", 0.5, 1.0, {6.0, 0.0}, {0.0, 0.0});
  post.is_static = true;
  s.bodies.push_back(post);
  BoxDef box;
  box.name = "block";
  box.min = {-7.0, -1.0};
  box.max = {-5.0, 0.5};
  s.boxes.push_back(box);
  SurfaceDef surf;
  surf.name = "ramp";
  // A valley with a flat floor, facing up (the left of the point order).
  surf.points = {{-3.0, 0.8}, {-1.0, 0.5}, {1.0, 0.5}, {3.0, 0.8}};
  s.surfaces.push_back(surf);
  auto e = make_engine(traits().name, s);
  const auto events = run(*e, s, s.steps());
  const auto st = states(*e);
  auto saw = [&](std::uint32_t body, ObjectRef other) {
    for (const ContactEvent& c : events) {
      if (c.a == ObjectRef{ObjectRef::Kind::Body, body} && c.b == other) return true;
    }
    return false;
  };
  EXPECT_TRUE(saw(0, {ObjectRef::Kind::Box, 0}));
  EXPECT_TRUE(saw(1, {ObjectRef::Kind::Surface, 0}));
  EXPECT_TRUE(saw(2, {ObjectRef::Kind::Body, 3}));
  // Elastic, frictionless, head-on onto horizontal faces: they leave upwards at 3 m/s.
  EXPECT_NEAR(st[0].velocity.y, 3.0, 1e-5);
  EXPECT_NEAR(st[1].velocity.y, 3.0, 1e-5);
  EXPECT_NEAR(st[2].velocity.y, 3.0, 1e-5);
  EXPECT_EQ(st[3].position, (Vec2{6.0, 0.0}));   // a static body stays put
  EXPECT_EQ(e->body_meta(3).mass, 0.0);
  EXPECT_TRUE(e->body_meta(3).is_static);
}

// --- the collision matrix ----------------------------------------------------------

TEST_P(Conformance, CollisionMatrixIgnoreEventDestroy) {
  auto scene_with = [](CollisionResponse response) {
    Scene s = head_on(1.0, 1.0, 1.0, -1.0, 1.0 / 60.0);
    s.bodies[0].group = "ball";
    s.bodies[1].group = "brick";
    s.collision_matrix.push_back({"ball", "brick", response});
    return s;
  };
  {  // ignore: they pass through each other, nothing reported
    const Scene s = scene_with(CollisionResponse::Ignore);
    auto e = make_engine(traits().name, s);
    EXPECT_TRUE(run(*e, s, s.steps()).empty());
    EXPECT_EQ(states(*e)[0].velocity.x, 1.0);
    EXPECT_EQ(states(*e)[1].velocity.x, -1.0);
  }
  {  // event: they pass through, one contact reported
    const Scene s = scene_with(CollisionResponse::Event);
    auto e = make_engine(traits().name, s);
    EXPECT_EQ(run(*e, s, s.steps()).size(), 1u);
    EXPECT_EQ(states(*e)[0].velocity.x, 1.0);
    EXPECT_EQ(states(*e)[1].velocity.x, -1.0);
  }
  {  // destroy the brick (group b): the ball bounces off it, the brick is gone
    const Scene s = scene_with(CollisionResponse::DestroyB);
    auto e = make_engine(traits().name, s);
    EXPECT_EQ(run(*e, s, s.steps()).size(), 1u);
    const auto st = states(*e);
    EXPECT_TRUE(st[0].alive);
    EXPECT_FALSE(st[1].alive);
    EXPECT_NEAR(st[0].velocity.x, -1.0, 1e-6);
    EXPECT_EQ(e->body_count(), 2u);
  }
}

// Chipmunk2D and ODE when they were built in (their Debian packages found).
std::vector<EngineTraits> engines_under_test() {
  std::vector<EngineTraits> all = {EngineTraits{"box2d", 0x1p-24, true}, EngineTraits{"bullet", 0x1p-53, false}};
#ifdef PHYSVAL_HAVE_CHIPMUNK
  all.push_back(EngineTraits{"chipmunk", 0x1p-53, false, true, 0.0});
#endif
#ifdef PHYSVAL_HAVE_ODE
  all.push_back(EngineTraits{"ode", 0x1p-53, false, false, 1.2e-8});
#endif
  return all;
}

INSTANTIATE_TEST_SUITE_P(Adapters, Conformance, ::testing::ValuesIn(engines_under_test()), traits_name);

}  // namespace
}  // namespace physval::test
