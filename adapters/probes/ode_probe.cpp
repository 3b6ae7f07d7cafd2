// Standalone probe of ODE 0.16.2 (Debian libode-dev, double), against the raw library,
// each body held in the plane z = 0 by a plane-2D joint: the facts shared/engines.md
// records for Box2D and Bullet, measured the same way. Not part of physval; the README's
// traps table quotes its output (build target physval_probe_ode, run with no arguments).
#include <ode/ode.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <vector>

namespace {

const double kDt = 1.0 / 60.0;
const double kG = 9.81;
const double kSegmentRadius = 1e-9;

struct Material { double e = 1.0, mu = 0.0; };

struct World {
  dWorldID world = dWorldCreate();
  dSpaceID space = dSimpleSpaceCreate(nullptr);
  dJointGroupID contacts = dJointGroupCreate(0);
  std::vector<dBodyID> bodies;
  // Contact settings of every contact this world makes.
  int mode = dContactBounce | dContactApprox1;
  double bounce_vel = 0.0;
  bool quick = false;
  World() { dWorldSetGravity(world, 0, -kG, 0); }
  ~World() {
    dJointGroupDestroy(contacts);
    dSpaceDestroy(space);
    dWorldDestroy(world);
  }
  static Material* mat(dGeomID g) { return static_cast<Material*>(dGeomGetData(g)); }
  dBodyID ball(double x, double y, double vx, double vy, double r, Material* m, double mass = 1.0) {
    dBodyID b = dBodyCreate(world);
    dMass dm;
    dMassSetSphereTotal(&dm, mass, r);
    dBodySetMass(b, &dm);
    dBodySetPosition(b, x, y, 0);
    dBodySetLinearVel(b, vx, vy, 0);
    dGeomID g = dCreateSphere(space, r);
    dGeomSetBody(g, b);
    dGeomSetData(g, m);
    dJointID j = dJointCreatePlane2D(world, 0);
    dJointAttach(j, b, 0);
    // No spin: the joint's angular motor holds the angular velocity at 0 with unbounded torque.
    dJointSetPlane2DAngleParam(j, dParamVel, 0.0);
    dJointSetPlane2DAngleParam(j, dParamFMax, dInfinity);
    bodies.push_back(b);
    return b;
  }
  // A segment: a capsule of radius `radius` lying in the plane (static: no body). With
  // radius 0 dCollide finds its contacts, but dSpaceCollide never offers the pair (its
  // bounding box has no extent): kSegmentRadius below.
  dGeomID segment(double ax, double ay, double bx, double by, Material* m, double radius = kSegmentRadius) {
    const double len = std::hypot(bx - ax, by - ay);
    dGeomID g = dCreateCapsule(space, radius, len);
    dGeomSetPosition(g, 0.5 * (ax + bx), 0.5 * (ay + by), 0);
    dMatrix3 R;
    // The capsule's axis is its local z: turn it onto (b - a).
    dRFromZAxis(R, (bx - ax) / len, (by - ay) / len, 0);
    dGeomSetRotation(g, R);
    dGeomSetData(g, m);
    return g;
  }
  static void near(void* data, dGeomID a, dGeomID b) {
    World* w = static_cast<World*>(data);
    dContact c[4];
    const int n = dCollide(a, b, 4, &c[0].geom, sizeof(dContact));
    for (int i = 0; i < n; ++i) {
      c[i].surface.mode = w->mode;
      c[i].surface.mu = std::sqrt(mat(a)->mu * mat(b)->mu);
      c[i].surface.bounce = std::fmin(mat(a)->e, mat(b)->e);
      c[i].surface.bounce_vel = w->bounce_vel;
      dJointAttach(dJointCreateContact(w->world, w->contacts, &c[i]), dGeomGetBody(a), dGeomGetBody(b));
    }
  }
  void step() {
    dSpaceCollide(space, this, &near);
    if (quick) dWorldQuickStep(world, kDt); else dWorldStep(world, kDt);
    dJointGroupEmpty(contacts);
  }
};

double x_of(dBodyID b) { return dBodyGetPosition(b)[0]; }
double y_of(dBodyID b) { return dBodyGetPosition(b)[1]; }
double vy_of(dBodyID b) { return dBodyGetLinearVel(b)[1]; }

void defaults() {
  World w;
  int major = 0, minor = 0, patch = 0;
  std::printf("[defaults]\n");
  std::printf("configuration = %s\n", dGetConfiguration());
  std::printf("dReal = %s (%zu bytes)\n", sizeof(dReal) == 8 ? "double" : "float", sizeof(dReal));
  (void)major; (void)minor; (void)patch;
  std::printf("erp = %.17g, cfm = %.17g\n", dWorldGetERP(w.world), dWorldGetCFM(w.world));
  std::printf("quickstep iterations = %d, over-relaxation w = %.17g\n", dWorldGetQuickStepNumIterations(w.world),
              dWorldGetQuickStepW(w.world));
  std::printf("contact max correcting vel = %g, contact surface layer = %g\n", dWorldGetContactMaxCorrectingVel(w.world),
              dWorldGetContactSurfaceLayer(w.world));
  std::printf("auto-disable (sleeping) = %d; linear damping = %g, angular damping = %g; max angular speed = %g\n",
              dWorldGetAutoDisableFlag(w.world), dWorldGetLinearDamping(w.world), dWorldGetAngularDamping(w.world),
              dWorldGetMaxAngularSpeed(w.world));
  std::printf("contact surface: no defaults (dContact is filled by the near callback); surface.mode 0 = friction mu is a\n"
              "  force bound in N, not a coefficient (dContactApprox1 makes it mu * normal force); no bounce without dContactBounce\n");
  std::printf("continuous collision: none\n\n");
}

void free_fall() {
  World w;
  Material m;
  dBodyID b = w.ball(0, 0, 0, 0, 0.5, &m);
  w.step();
  const double y1 = y_of(b), v1 = vy_of(b);
  for (int i = 1; i < 60; ++i) w.step();
  const double y = y_of(b), v = vy_of(b), exact = -0.5 * kG;
  std::printf("[free_fall] g = %g, dt = 1/60, 60 steps from rest (dWorldStep)\n", kG);
  std::printf("after 1 step: y = %.17g, v = %.17g  (semi-implicit Euler: -g dt^2 = %.17g)\n", y1, v1, -kG * kDt * kDt);
  std::printf("after 1 s: y = %.17g, closed form %.17g, error %.6g m (= %.4g g dt t / 2); v = %.17g\n", y, exact, y - exact,
              (y - exact) / (0.5 * kG * kDt), v);
  std::printf("energy per unit mass after 1 s: %.6g J/kg (0 exact)\n\n", 0.5 * v * v + kG * y);
}

void drop_apexes(bool quick) {
  World w;
  w.quick = quick;
  Material m;
  w.segment(-10, 0, 10, 0, &m);
  const double r = 0.5;
  dBodyID b = w.ball(0, 10 + r, 0, 0, r, &m);
  std::printf("[drop%s] ball r = 0.5 from 10 m, e = 1, bounce_vel 0, dt = 1/60: apex heights (bottom of ball)\n",
              quick ? ", dWorldQuickStep" : ", dWorldStep");
  double prev_v = 0.0, apex = 0.0, min_gap = 1e9;
  int found = 0;
  for (int i = 0; i < 60 * 12 && found < 3; ++i) {
    w.step();
    const double y = y_of(b) - r, v = vy_of(b);
    min_gap = std::fmin(min_gap, y);
    if (prev_v > 0 && v <= 0) std::printf("apex %d: %.6f m (step %d)\n", ++found, apex, i + 1);
    if (v > 0) apex = y;
    prev_v = v;
  }
  std::printf("deepest point reached: %.6f m\n\n", min_gap);
}

void low_speed_restitution() {
  std::printf("[restitution] e = 1 ball (r = 0.5) onto a segment, no gravity: v_out / v_in\n");
  for (double bv : {0.0, 0.1}) {
    for (double v : {0.01, 0.05, 0.2, 0.5, 1.0, 5.0}) {
      World w;
      w.bounce_vel = bv;
      dWorldSetGravity(w.world, 0, 0, 0);
      Material m;
      w.segment(-10, 0, 10, 0, &m);
      dBodyID b = w.ball(0, 0.5 + 3.3 * v * kDt, 0, -v, 0.5, &m);
      for (int i = 0; i < 40; ++i) w.step();
      std::printf("bounce_vel %-4g v_in %-5g -> v_out %.9g (ratio %.6f)\n", bv, v, vy_of(b), vy_of(b) / v);
    }
  }
  std::printf("\n");
}

void resting() {
  std::printf("[rest] ball r = 0.5, m = 1 dropped 0.2 m onto a floor, e = 0, g = 9.81, 5 s\n");
  for (double layer : {0.0, 0.001}) {
    World w;
    dWorldSetContactSurfaceLayer(w.world, layer);
    Material ball{0.0, 0.0}, floor{0.0, 0.0};
    w.segment(-10, 0, 10, 0, &floor);
    dBodyID b = w.ball(0, 0.7, 0, 0, 0.5, &ball);
    double worst = 0;
    for (int i = 0; i < 300; ++i) { w.step(); worst = std::fmax(worst, 0.5 - y_of(b)); }
    std::printf("surface layer %-6g: overlap at rest %.6g m (deepest %.4g m), v = %.3g m/s\n", layer, 0.5 - y_of(b), worst,
                vy_of(b));
  }
  // ERP correction is a velocity: an e = 0 ball released 1 cm inside the floor leaves it.
  World w;
  dWorldSetGravity(w.world, 0, 0, 0);
  Material ball{0.0, 0.0};
  w.segment(-10, 0, 10, 0, &ball);
  dBodyID b = w.ball(0, 0.49, 0, 0, 0.5, &ball);
  double vmax = 0;
  for (int i = 0; i < 60; ++i) { w.step(); vmax = std::fmax(vmax, vy_of(b)); }
  std::printf("e = 0 ball released 0.01 m inside the floor, no gravity: leaves at up to %.6g m/s (erp 0.2: 0.2 * 0.01 * 60 = 0.12)\n\n", vmax);
}

void zero_radius_segment() {
  World w;
  Material m;
  w.segment(-10, 0, 10, 0, &m, 0.0);
  dBodyID b = w.ball(0, 1.0, 0, 0, 0.5, &m);
  for (int i = 0; i < 120; ++i) w.step();
  std::printf("[segment] a capsule of radius 0 as the floor: ball at y = %.6g after 2 s (fell through: dSpaceCollide\n"
              "  never pairs a geom whose bounding box has no extent); physval's segments have radius %g m\n\n",
              y_of(b), kSegmentRadius);
}

void tunnelling() {
  std::printf("[tunnel] ball r = 0.1 towards a zero-thickness wall (capsule of radius 1e-9) at x = 9.9, dt = 1/60\n");
  double first = -1;
  for (double v = 1.0; v <= 200.0; v += 1.0) {
    World w;
    dWorldSetGravity(w.world, 0, 0, 0);
    Material m;
    w.segment(9.9, -5, 9.9, 5, &m);
    dBodyID b = w.ball(0, 0, v, 0, 0.1, &m);
    for (int i = 0; i < 600 && x_of(b) < 20 && x_of(b) > -1; ++i) w.step();
    if (x_of(b) > 9.9) { first = v; break; }
  }
  std::printf("first speed (1 m/s steps) that passes through: %g m/s (%.3g m per step; radius 0.1)\n\n", first, first * kDt);
}

void slope() {
  std::printf("[slope] non-spinning ball on a 30 degree segment, g = 9.81, 1 s after release\n");
  const double th = M_PI / 6;
  for (int mode : {int{dContactBounce | dContactApprox1}, int{dContactBounce}}) {
    for (double mu : {0.3, 0.7}) {
      World w;
      w.mode = mode;
      Material floor{0.0, 1.0}, ball{0.0, mu * mu};   // sqrt(1 * mu^2) = mu
      const double dx = std::cos(th), dy = -std::sin(th);
      w.segment(-50 * dx, -50 * dy, 50 * dx, 50 * dy, &floor);
      dBodyID b = w.ball(0.5 * std::sin(th), 0.5 * std::cos(th), 0, 0, 0.5, &ball);
      for (int i = 0; i < 60; ++i) w.step();
      const double along = dBodyGetLinearVel(b)[0] * dx + dBodyGetLinearVel(b)[1] * dy;
      std::printf("%s mu %.1f: speed along slope %.9g m/s, closed form %.9g\n",
                  mode & dContactApprox1 ? "dContactApprox1" : "mode 0 (mu in N)", mu, along,
                  std::fmax(0.0, kG * (std::sin(th) - mu * std::cos(th))));
    }
  }
  std::printf("\n");
}

std::uint64_t gas_run(bool quick, bool reseed) {
  if (reseed) dRandSetSeed(0);
  World w;
  w.quick = quick;
  static Material wall{0.9, 0.2}, ballm{0.9, 0.2};
  w.segment(0, 0, 10, 0, &wall);
  w.segment(0, 0, 0, 10, &wall);
  w.segment(10, 0, 10, 10, &wall);
  w.segment(0, 10, 10, 10, &wall);
  std::uint64_t seed = 7;
  auto rnd = [&] { seed = seed * 6364136223846793005ULL + 1442695040888963407ULL; return ((seed >> 11) * 0x1.0p-53) * 2 - 1; };
  for (int i = 0; i < 100; ++i) w.ball(0.5 + (i % 10) * 0.95, 0.5 + (i / 10) * 0.95, 3 * rnd(), 3 * rnd(), 0.2, &ballm);
  for (int i = 0; i < 600; ++i) w.step();
  std::uint64_t h = 1469598103934665603ULL;
  for (dBodyID b : w.bodies) {
    double v[4] = {x_of(b), y_of(b), dBodyGetLinearVel(b)[0], vy_of(b)};
    unsigned char bytes[sizeof v];
    std::memcpy(bytes, v, sizeof v);
    for (unsigned char c : bytes) h = (h ^ c) * 1099511628211ULL;
  }
  return h;
}

void determinism() {
  std::printf("[determinism] 100 balls, 600 steps, same process twice\n");
  for (bool quick : {false, true}) {
    for (bool reseed : {false, true}) {
      const std::uint64_t a = gas_run(quick, reseed), b = gas_run(quick, reseed);
      std::printf("%s, %s: %016llx %016llx (%s)\n", quick ? "dWorldQuickStep" : "dWorldStep",
                  reseed ? "dRandSetSeed(0) before each run" : "no reseed", static_cast<unsigned long long>(a),
                  static_cast<unsigned long long>(b), a == b ? "identical" : "DIFFERENT");
    }
  }
  std::printf("\n");
}

void sleeping() {
  World w;
  dWorldSetGravity(w.world, 0, 0, 0);
  Material m;
  dBodyID b = w.ball(0, 0, 0.5, 0, 0.5, &m);
  for (int i = 0; i < 600; ++i) w.step();
  std::printf("[sleep] a free body at 0.5 m/s, default world, 600 steps: x = %.9g (5 m expected), enabled = %d\n\n", x_of(b),
              dBodyIsEnabled(b));
}

}  // namespace

int main() {
  dInitODE2(0);
  defaults();
  free_fall();
  drop_apexes(false);
  drop_apexes(true);
  low_speed_restitution();
  resting();
  zero_radius_segment();
  tunnelling();
  slope();
  determinism();
  sleeping();
  dCloseODE();
  return 0;
}
