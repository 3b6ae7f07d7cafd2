// Standalone probe of Chipmunk2D 7.0.3 (Debian libchipmunk-dev), against the raw library:
// the facts shared/engines.md records for Box2D and Bullet, measured the same way. Not
// part of physval; the README's traps table quotes its output (build target
// physval_probe_chipmunk, run with no arguments).
#include <chipmunk/chipmunk.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <vector>

namespace {

const double kDt = 1.0 / 60.0;
const double kG = 9.81;

struct World {
  cpSpace* space = cpSpaceNew();
  std::vector<cpBody*> bodies;
  std::vector<cpShape*> shapes;
  World() { cpSpaceSetGravity(space, cpv(0, -kG)); }
  ~World() {
    for (cpShape* s : shapes) { cpSpaceRemoveShape(space, s); cpShapeFree(s); }
    for (cpBody* b : bodies) { cpSpaceRemoveBody(space, b); cpBodyFree(b); }
    cpSpaceFree(space);
  }
  // A disc of radius r and mass m; moment INFINITY: it does not spin (lecture model).
  cpBody* ball(cpVect p, cpVect v, double r, double m = 1.0, double e = 1.0, double mu = 0.0, bool spin = false) {
    cpBody* b = cpSpaceAddBody(space, cpBodyNew(m, spin ? cpMomentForCircle(m, 0, r, cpvzero) : INFINITY));
    cpBodySetPosition(b, p);
    cpBodySetVelocity(b, v);
    bodies.push_back(b);
    cpShape* s = cpSpaceAddShape(space, cpCircleShapeNew(b, r, cpvzero));
    cpShapeSetElasticity(s, e);
    cpShapeSetFriction(s, mu);
    shapes.push_back(s);
    return b;
  }
  cpShape* segment(cpVect a, cpVect b, double e = 1.0, double mu = 0.0, double radius = 0.0) {
    cpShape* s = cpSpaceAddShape(space, cpSegmentShapeNew(cpSpaceGetStaticBody(space), a, b, radius));
    cpShapeSetElasticity(s, e);
    cpShapeSetFriction(s, mu);
    shapes.push_back(s);
    return s;
  }
};

void defaults() {
  World w;
  std::printf("[defaults]\n");
  std::printf("version = %s (CP_VERSION %d.%d.%d)\n", cpVersionString, CP_VERSION_MAJOR, CP_VERSION_MINOR,
              CP_VERSION_RELEASE);
  std::printf("cpFloat = %s (%zu bytes)\n", sizeof(cpFloat) == 8 ? "double" : "float", sizeof(cpFloat));
  std::printf("iterations = %d\n", cpSpaceGetIterations(w.space));
  std::printf("collision_slop = %.17g m\n", cpSpaceGetCollisionSlop(w.space));
  std::printf("collision_bias = %.17g (fraction of overlap left after 1 s: pow(1 - 0.1, 60))\n",
              cpSpaceGetCollisionBias(w.space));
  std::printf("collision_persistence = %u steps\n", static_cast<unsigned>(cpSpaceGetCollisionPersistence(w.space)));
  std::printf("damping = %.17g\n", cpSpaceGetDamping(w.space));
  std::printf("sleep_time_threshold = %g (INFINITY: sleeping off)\n", cpSpaceGetSleepTimeThreshold(w.space));
  std::printf("idle_speed_threshold = %g (0: estimated from gravity)\n", cpSpaceGetIdleSpeedThreshold(w.space));
  cpShape* s = cpCircleShapeNew(nullptr, 1, cpvzero);
  std::printf("shape elasticity = %g, friction = %g; mixing e1*e2, u1*u2 (cpArbiterUpdate)\n",
              cpShapeGetElasticity(s), cpShapeGetFriction(s));
  cpShapeFree(s);
  std::printf("continuous collision: none (no time of impact in Chipmunk 7)\n\n");
}

// Free fall from rest, 60 steps of 1/60: which scheme, and its error against y = -g t^2/2.
void free_fall() {
  World w;
  cpSpaceSetGravity(w.space, cpv(0, -kG));
  cpBody* b = w.ball(cpv(0, 0), cpvzero, 0.5);
  cpSpaceStep(w.space, kDt);
  const double y1 = cpBodyGetPosition(b).y, v1 = cpBodyGetVelocity(b).y;
  for (int i = 1; i < 60; ++i) cpSpaceStep(w.space, kDt);
  const double y = cpBodyGetPosition(b).y, v = cpBodyGetVelocity(b).y;
  const double exact = -0.5 * kG;
  std::printf("[free_fall] g = %g, dt = 1/60, 60 steps from rest\n", kG);
  std::printf("after 1 step: y = %.17g, v = %.17g  (semi-implicit Euler would give y = %.17g; explicit Euler 0)\n", y1,
              v1, -kG * kDt * kDt);
  std::printf("after 1 s: y = %.17g, closed form %.17g, error %.6g m (= %.4g g dt t / 2); v = %.17g (exact %.17g)\n", y,
              exact, y - exact, (y - exact) / (0.5 * kG * kDt), v, -kG);
  std::printf("energy per unit mass after 1 s: %.6g J/kg (0 exact)\n\n", 0.5 * v * v + kG * y);
}

// A ball dropped from 10 m onto a floor, e = 1: apex heights of three bounces.
void drop_apexes() {
  World w;
  w.segment(cpv(-10, 0), cpv(10, 0));
  const double r = 0.5;
  cpBody* b = w.ball(cpv(0, 10 + r), cpvzero, r);
  std::printf("[drop] ball r = 0.5 from 10 m, e = 1, dt = 1/60: apex heights (bottom of ball)\n");
  double prev_v = 0.0, apex = 0.0;
  int found = 0;
  double min_gap = 1e9;
  for (int i = 0; i < 60 * 12 && found < 3; ++i) {
    cpSpaceStep(w.space, kDt);
    const double y = cpBodyGetPosition(b).y - r, v = cpBodyGetVelocity(b).y;
    min_gap = std::fmin(min_gap, y);
    if (prev_v > 0 && v <= 0) { std::printf("apex %d: %.6f m (step %d)\n", ++found, apex, i + 1); }
    apex = std::fmax(y, v > 0 ? y : 0.0);
    if (v > 0) apex = y;
    prev_v = v;
  }
  std::printf("deepest point reached: %.6f m (negative: inside the floor at a step's end)\n\n", min_gap);
}

// Low-speed bounces without gravity: outgoing / incoming speed for e = 1.
void low_speed_restitution() {
  std::printf("[restitution] e = 1 ball (r = 0.5) onto a segment, no gravity: v_out / v_in\n");
  for (double v : {0.01, 0.05, 0.2, 0.5, 1.0, 5.0}) {
    World w;
    cpSpaceSetGravity(w.space, cpvzero);
    w.segment(cpv(-10, 0), cpv(10, 0));
    // Start 3.3 steps of travel above: the step it touches in is not on the grid.
    cpBody* b = w.ball(cpv(0, 0.5 + 3.3 * v * kDt), cpv(0, -v), 0.5);
    for (int i = 0; i < 40; ++i) cpSpaceStep(w.space, kDt);
    std::printf("v_in %-5g -> v_out %.9g (ratio %.6f)\n", v, cpBodyGetVelocity(b).y, cpBodyGetVelocity(b).y / v);
  }
  std::printf("\n");
}

// A ball resting on a floor under gravity: its steady overlap.
void resting() {
  std::printf("[rest] ball r = 0.5, m = 1 dropped 0.2 m onto a floor, e = 0, g = 9.81, 5 s: overlap at rest\n");
  for (double slop : {-1.0, 0.0}) {
    World w;
    if (slop >= 0) cpSpaceSetCollisionSlop(w.space, slop);
    w.segment(cpv(-10, 0), cpv(10, 0), 0.0);
    cpBody* b = w.ball(cpv(0, 0.7), cpvzero, 0.5, 1.0, 0.0);
    for (int i = 0; i < 300; ++i) cpSpaceStep(w.space, kDt);
    std::printf("collision_slop %-8g: overlap %.6g m, v = %.3g m/s\n", cpSpaceGetCollisionSlop(w.space),
                0.5 - cpBodyGetPosition(b).y, cpBodyGetVelocity(b).y);
  }
  std::printf("\n");
}

// The lowest speed at which a ball passes a zero-thickness segment (wall at x = 9.9).
void tunnelling() {
  std::printf("[tunnel] ball r = 0.1 towards a zero-thickness wall at x = 9.9, no gravity, dt = 1/60\n");
  double first = -1;
  for (double v = 1.0; v <= 200.0; v += 1.0) {
    World w;
    cpSpaceSetGravity(w.space, cpvzero);
    w.segment(cpv(9.9, -5), cpv(9.9, 5));
    cpBody* b = w.ball(cpv(0, 0), cpv(v, 0), 0.1);
    for (int i = 0; i < 600 && cpBodyGetPosition(b).x < 20 && cpBodyGetPosition(b).x > -1; ++i) cpSpaceStep(w.space, kDt);
    if (cpBodyGetPosition(b).x > 9.9) { first = v; break; }
  }
  std::printf("first speed (1 m/s steps) that passes through: %g m/s (%.3g m per step; radius 0.1)\n\n", first,
              first * kDt);
}

// A block-less slope: a non-spinning ball on a 30 degree segment.
void slope() {
  std::printf("[slope] non-spinning ball on a 30 degree segment, g = 9.81, 1 s after release\n");
  const double th = M_PI / 6;
  for (double mu : {0.3, 0.7}) {
    World w;
    const cpVect dir = cpv(std::cos(th), -std::sin(th));
    w.segment(cpv(-50 * dir.x, -50 * dir.y), cpv(50 * dir.x, 50 * dir.y), 0.0, 1.0);
    const cpVect n = cpv(std::sin(th), std::cos(th));
    cpBody* b = w.ball(cpvmult(n, 0.5), cpvzero, 0.5, 1.0, 0.0, mu);
    for (int i = 0; i < 60; ++i) cpSpaceStep(w.space, kDt);
    const double along = cpvdot(cpBodyGetVelocity(b), dir);
    const double a_exact = std::fmax(0.0, kG * (std::sin(th) - mu * std::cos(th)));
    std::printf("mu %.1f: speed along slope %.9g m/s, closed form %.9g (friction mu_s = mu_k = mu)\n", mu, along,
                a_exact * 1.0);
  }
  std::printf("\n");
}

std::uint64_t hash_states(World& w) {
  std::uint64_t h = 1469598103934665603ULL;
  for (cpBody* b : w.bodies) {
    const double v[4] = {cpBodyGetPosition(b).x, cpBodyGetPosition(b).y, cpBodyGetVelocity(b).x, cpBodyGetVelocity(b).y};
    unsigned char bytes[sizeof v];
    std::memcpy(bytes, v, sizeof v);
    for (unsigned char c : bytes) h = (h ^ c) * 1099511628211ULL;
  }
  return h;
}

// 100 balls in a box, 600 steps, twice: identical bits?
std::uint64_t gas_run() {
  World w;
  cpSpaceSetGravity(w.space, cpv(0, -kG));
  w.segment(cpv(0, 0), cpv(10, 0));
  w.segment(cpv(0, 0), cpv(0, 10));
  w.segment(cpv(10, 0), cpv(10, 10));
  w.segment(cpv(0, 10), cpv(10, 10));
  std::uint64_t seed = 7;
  auto rnd = [&] { seed = seed * 6364136223846793005ULL + 1442695040888963407ULL; return ((seed >> 11) * 0x1.0p-53) * 2 - 1; };
  for (int i = 0; i < 100; ++i) w.ball(cpv(0.5 + (i % 10) * 0.95, 0.5 + (i / 10) * 0.95), cpv(3 * rnd(), 3 * rnd()), 0.2, 1.0, 0.9, 0.2);
  for (int i = 0; i < 600; ++i) cpSpaceStep(w.space, kDt);
  return hash_states(w);
}

void determinism() {
  const std::uint64_t a = gas_run(), b = gas_run();
  std::printf("[determinism] 100 balls, 600 steps, same process twice: %016llx %016llx (%s)\n\n",
              static_cast<unsigned long long>(a), static_cast<unsigned long long>(b), a == b ? "identical" : "DIFFERENT");
}

void sleeping() {
  std::printf("[sleep] a free body at 0.5 m/s, no gravity, default space, 600 steps\n");
  World w;
  cpSpaceSetGravity(w.space, cpvzero);
  cpBody* b = w.ball(cpv(0, 0), cpv(0.5, 0), 0.5);
  for (int i = 0; i < 600; ++i) cpSpaceStep(w.space, kDt);
  std::printf("x = %.9g (5 m expected), sleeping = %d\n\n", cpBodyGetPosition(b).x, cpBodyIsSleeping(b));
}

}  // namespace

int main() {
  defaults();
  free_fall();
  drop_apexes();
  low_speed_restitution();
  resting();
  tunnelling();
  slope();
  determinism();
  sleeping();
  return 0;
}
