// Newtonian gravity plus impacts: an impact inside a step must keep the integrator's
// order although every body's acceleration depends on every other body's position.
//
// The closed form: two bodies released at rest at distance d0 fall head-on (the Kepler
// radial orbit, mu = G (m1 + m2)): d = d0 cos^2(theta), t = sqrt(d0^3 / (2 mu))
// (theta + sin(theta) cos(theta)), d' = -sqrt(2 mu / d0) tan(theta). They touch at
// d = r1 + r2 at t_c; an elastic impact reverses their relative velocity, so the motion
// is the fall played backwards: at rest at d0 at 2 t_c, touching again at 3 t_c, and
// so on. Their centre of mass drifts uniformly. Scenes without a closed form (three
// bodies, a wall, a uniform field as well) are held against a run at a much finer dt.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "physval/engine/forces.hpp"
#include "scene_fixture.hpp"

namespace physval::test {

namespace {

struct HeadOn {
  double G = 1.0, m1 = 1.0, m2 = 3.0, d0 = 4.0, r1 = 0.8, r2 = 1.2;
  Vec2 u{std::cos(0.3), std::sin(0.3)};   // from body 1 towards body 2
  Vec2 c0{0.5, -0.25}, vc{0.2, -0.1};     // centre of mass: position at 0, velocity

  double mu() const { return G * (m1 + m2); }
  double scale() const { return std::sqrt(d0 * d0 * d0 / (2.0 * mu())); }
  double theta_c() const { return std::acos(std::sqrt((r1 + r2) / d0)); }
  double t_c() const {
    const double th = theta_c();
    return scale() * (th + std::sin(th) * std::cos(th));
  }
  // theta of the free fall at time s in [0, t_c] (Newton on t(theta), monotone).
  double theta_at(double s) const {
    double th = theta_c() * s / t_c();
    for (int it = 0; it < 100; ++it) {
      const double f = scale() * (th + std::sin(th) * std::cos(th)) - s;
      const double df = scale() * 2.0 * std::cos(th) * std::cos(th);
      const double step = f / df;
      th -= step;
      if (std::fabs(step) < 1e-17) break;
    }
    return th;
  }
  // Separation and its rate at time t (any number of bounces).
  void separation(double t, double& d, double& ddot) const {
    const double period = 2.0 * t_c();
    double tau = std::fmod(t, period);
    const bool back = tau > t_c();
    if (back) tau = period - tau;
    const double th = theta_at(tau);
    d = d0 * std::cos(th) * std::cos(th);
    ddot = -std::sqrt(2.0 * mu() / d0) * std::tan(th);
    if (back) ddot = -ddot;
  }
  Scene scene() const {
    const double M = m1 + m2;
    BodyDef a = circle("a", c0 - (m2 / M * d0) * u, vc, r1, m1, 1.0);
    BodyDef b = circle("b", c0 + (m1 / M * d0) * u, vc, r2, m2, 1.0);
    Scene s = scene_of({a, b});
    s.world.newtonian = true;
    s.world.G = G;
    return s;
  }
  // Exact states of both bodies at t.
  void exact(double t, BodyState& a, BodyState& b) const {
    const double M = m1 + m2;
    double d, ddot;
    separation(t, d, ddot);
    const Vec2 c = c0 + t * vc;
    a.position = c - (m2 / M * d) * u;
    b.position = c + (m1 / M * d) * u;
    a.velocity = vc - (m2 / M * ddot) * u;
    b.velocity = vc + (m1 / M * ddot) * u;
  }
};

// A run of `steps` steps of dt; the states after every `every`-th step go to `samples`.
struct RunResult {
  std::vector<std::vector<BodyState>> samples;
  std::vector<ContactEvent> contacts;
};
RunResult run(const Scene& s, const char* integrator, double dt, long steps, long every) {
  Sim sim(s, options(integrator));
  RunResult r;
  for (long k = 1; k <= steps; ++k) {
    sim.step(dt);
    if (k % every == 0) {
      sim.engine.read_states(sim.states);
      r.samples.push_back(sim.states);
    }
  }
  r.contacts = sim.contacts;
  return r;
}

double position_error(const std::vector<BodyState>& x, const std::vector<BodyState>& y) {
  double e = 0.0;
  for (std::size_t i = 0; i < x.size(); ++i) e = std::max(e, length(x[i].position - y[i].position));
  return e;
}

// Energy (kinetic, Newtonian and uniform-field potential) and momentum of a state.
double energy(const Scene& s, const std::vector<BodyState>& x) {
  double e = 0.0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    const double m = s.bodies[i].mass;
    e += 0.5 * m * length_squared(x[i].velocity) - m * dot(s.world.gravity, x[i].position);
    for (std::size_t j = i + 1; j < x.size(); ++j) {
      e += newtonian_potential(s.world.G, s.world.softening, m, s.bodies[j].mass, x[i].position, x[j].position);
    }
  }
  return e;
}
Vec2 momentum(const Scene& s, const std::vector<BodyState>& x) {
  Vec2 p;
  for (std::size_t i = 0; i < x.size(); ++i) p += s.bodies[i].mass * x[i].velocity;
  return p;
}
std::vector<BodyState> initial(const Scene& s) {
  std::vector<BodyState> x(s.bodies.size());
  for (std::size_t i = 0; i < x.size(); ++i) {
    x[i].position = s.bodies[i].position;
    x[i].velocity = s.bodies[i].velocity;
  }
  return x;
}

struct Scheme {
  const char* name;
  double dt0;
  double ratio;   // 2^p per halving
};

}  // namespace

// The closed form itself: the exact states conserve energy and momentum, and the
// bodies touch at t_c.
TEST(CoreNewtonianContact, HeadOnClosedFormIsConsistent) {
  const HeadOn h;
  const Scene s = h.scene();
  const double e0 = energy(s, initial(s));
  for (double t : {0.3 * h.t_c(), h.t_c(), 1.7 * h.t_c(), 3.4 * h.t_c()}) {
    std::vector<BodyState> x(2);
    h.exact(t, x[0], x[1]);
    EXPECT_NEAR(energy(s, x), e0, 1e-12 * std::fabs(e0)) << t;
    EXPECT_NEAR(length(momentum(s, x) - momentum(s, initial(s))), 0.0, 1e-13) << t;
  }
  std::vector<BodyState> x(2);
  h.exact(h.t_c(), x[0], x[1]);
  EXPECT_NEAR(length(x[1].position - x[0].position), h.r1 + h.r2, 1e-13);
}

// The largest position error over the samples, and the largest energy error.
struct Errors {
  double position = 0.0, energy = 0.0;
};

// Two bodies fall together under their mutual gravity and bounce elastically, the
// impact inside a step, and fly apart to rest and back. Sampled every 0.1 s,
// the largest error against the closed form falls 16x per halving of dt under RK4 and
// 4x under velocity Verlet (asserted: at least 12x and 3x per halving, 16^3 and 4^3
// within a factor 1.5 over three); so does the impact time's. Momentum is kept to
// round-off, energy to the integrator's accuracy (its error shrinks at the same order).
TEST(CoreNewtonianContact, HeadOnFallKeepsTheIntegratorsOrder) {
  const HeadOn h;
  const Scene s = h.scene();
  const double dt0 = 0.1;   // the sampling interval; RK4's coarsest step
  const long coarse_steps = std::lround(2.4 * h.t_c() / dt0);   // past the impact and the turning point (2 t_c)
  const double e0 = energy(s, initial(s));
  const Vec2 p0 = momentum(s, initial(s));
  for (const Scheme& sc : {Scheme{"rk4", dt0, 16.0}, Scheme{"velocity_verlet", dt0 / 4.0, 4.0}}) {
    SCOPED_TRACE(sc.name);
    std::vector<Errors> errs;
    std::vector<double> terrs;
    for (int k = 0; k < 4; ++k) {
      const double dt = sc.dt0 / (1 << k);
      // Off the grid: the impacts fall inside steps.
      ASSERT_GT(std::fabs(std::remainder(h.t_c(), dt)), 0.05 * dt);
      const long every = std::lround(dt0 / dt);
      const RunResult r = run(s, sc.name, dt, coarse_steps * every, every);
      ASSERT_EQ(r.contacts.size(), 1u) << "dt " << dt;
      Errors e;
      for (std::size_t m = 0; m < r.samples.size(); ++m) {
        std::vector<BodyState> exact(2);
        h.exact(static_cast<double>(m + 1) * dt0, exact[0], exact[1]);
        e.position = std::max(e.position, position_error(r.samples[m], exact));
        e.energy = std::max(e.energy, std::fabs(energy(s, r.samples[m]) - e0));
        EXPECT_LT(length(momentum(s, r.samples[m]) - p0), 1e-13) << "dt " << dt;
      }
      errs.push_back(e);
      terrs.push_back(std::fabs(r.contacts[0].time - h.t_c()));
    }
    const double low = sc.ratio == 16.0 ? 12.0 : 3.0;
    for (std::size_t k = 1; k < errs.size(); ++k) {
      SCOPED_TRACE("dt/" + std::to_string(1 << k));
      EXPECT_GT(errs[k - 1].position / errs[k].position, low) << errs[k - 1].position << " -> " << errs[k].position;
      EXPECT_GT(terrs[k - 1] / terrs[k], low) << "impact times " << terrs[k - 1] << " -> " << terrs[k];
      EXPECT_GT(errs[k - 1].energy / errs[k].energy, low) << "energy " << errs[k - 1].energy << " -> " << errs[k].energy;
    }
    const double over3 = errs[0].position / errs[3].position, cube = sc.ratio * sc.ratio * sc.ratio;
    EXPECT_GT(over3, cube / 1.5);
    EXPECT_LT(over3, cube * 1.5);
  }
}

namespace {

// Three bodies under mutual gravity (and a uniform field), with a floor and a wall:
// they fall, hit each other, the wall and the floor (elastic), impacts inside steps.
Scene three_body_scene(bool uniform) {
  BodyDef a = circle("a", {0.0, 2.0}, {1.5, 0.3}, 0.5, 2.0, 1.0);
  BodyDef b = circle("b", {1.6, 2.35}, {-0.4, 0.1}, 0.4, 1.0, 1.0);
  BodyDef c = circle("c", {0.7, 3.6}, {0.2, -0.6}, 0.6, 1.5, 1.0);
  Scene s = scene_of({a, b, c}, {wall("floor", {-10.0, 0.0}, {10.0, 0.0}), wall("wall", {2.6, -1.0}, {2.6, 10.0})},
                     uniform ? Vec2{0.0, -1.5} : Vec2{});
  s.world.newtonian = true;
  s.world.G = 1.0;
  return s;
}

}  // namespace

// Three bodies, mutual gravity with and without a uniform field, impacts with each
// other and with walls inside steps: sampled every coarse step, the largest error
// against a run at 1/256 of the coarsest dt falls at the integrator's order (>= 12x
// per halving under RK4, >= 3x under Verlet), and so does the energy's error.
TEST(CoreNewtonianContact, ThreeBodiesWithWallsKeepTheIntegratorsOrder) {
  const double duration = 4.0;
  for (bool uniform : {false, true}) {
    const Scene s = three_body_scene(uniform);
    const double e0 = energy(s, initial(s));
    for (const Scheme& sc : {Scheme{"rk4", 0.025, 16.0}, Scheme{"velocity_verlet", 0.0125, 4.0}}) {
      SCOPED_TRACE(std::string(sc.name) + (uniform ? " with a uniform field" : " mutual gravity only"));
      const long coarse_steps = std::lround(duration / sc.dt0);
      const RunResult ref = run(s, sc.name, sc.dt0 / 256.0, coarse_steps * 256, 256);
      ASSERT_GE(ref.contacts.size(), 3u);
      std::vector<Errors> errs;
      for (int k = 0; k < 4; ++k) {
        const long every = 1L << k;
        const RunResult r = run(s, sc.name, sc.dt0 / static_cast<double>(every), coarse_steps * every, every);
        ASSERT_EQ(r.contacts.size(), ref.contacts.size()) << "dt/" << every;
        Errors e;
        for (std::size_t m = 0; m < r.samples.size(); ++m) {
          e.position = std::max(e.position, position_error(r.samples[m], ref.samples[m]));
          e.energy = std::max(e.energy, std::fabs(energy(s, r.samples[m]) - e0));
        }
        errs.push_back(e);
      }
      const double low = sc.ratio == 16.0 ? 12.0 : 3.0;
      for (std::size_t k = 1; k < errs.size(); ++k) {
        SCOPED_TRACE("dt/" + std::to_string(1 << k));
        EXPECT_GT(errs[k - 1].position / errs[k].position, low) << errs[k - 1].position << " -> " << errs[k].position;
        EXPECT_GT(errs[k - 1].energy / errs[k].energy, low) << "energy " << errs[k - 1].energy << " -> " << errs[k].energy;
      }
    }
  }
}

}  // namespace physval::test

namespace physval::test {

// Inelastic bodies attracting each other in a uniform field come to rest on a floor
// and on each other (micro-bounces, settling, a stack): every event cuts the whole
// system's step, and the run still ends at rest, without overlap, never at the event cap.
TEST(CoreNewtonianContact, InelasticBodiesSettleOnAFloor) {
  for (const char* integrator : {"rk4", "velocity_verlet"}) {
    SCOPED_TRACE(integrator);
    BodyDef a = circle("a", {0.0, 1.0}, {0.5, 0.0}, 0.3, 1.0, 0.3);
    BodyDef b = circle("b", {1.2, 1.8}, {-0.3, 0.0}, 0.4, 2.0, 0.3);
    BodyDef c = circle("c", {0.5, 2.8}, {0.0, 0.0}, 0.25, 0.5, 0.3);
    for (BodyDef* x : {&a, &b, &c}) {
      x->friction = 0.5;
      x->static_friction = 0.5;
    }
    Scene s = scene_of({a, b, c},
                       {wall("floor", {-5.0, 0.0}, {5.0, 0.0}, 0.3, 0.5), wall("left", {-1.0, 0.0}, {-1.0, 5.0}, 0.3, 0.5),
                        wall("right", {2.5, 0.0}, {2.5, 5.0}, 0.3, 0.5)},
                       {0.0, -9.8});
    s.world.newtonian = true;
    s.world.G = 0.5;
    Sim sim(s, options(integrator));
    long impacts = 0;
    for (int k = 0; k < 600; ++k) {
      sim.step(1.0 / 60.0);
      ASSERT_EQ(sim.engine.broken_guarantee(), "") << "step " << k;
      impacts += sim.engine.last_step_stats().impacts;
    }
    EXPECT_GT(impacts, 20);   // they did bounce, settle and meet
    sim.engine.read_states(sim.states);
    for (std::size_t i = 0; i < 3; ++i) {
      EXPECT_LT(length(sim.states[i].velocity), 1e-3) << s.bodies[i].name;
      EXPECT_GE(sim.states[i].position.y, s.bodies[i].radius - 1e-9) << s.bodies[i].name;
      for (std::size_t j = i + 1; j < 3; ++j) {
        EXPECT_GE(length(sim.states[j].position - sim.states[i].position),
                  s.bodies[i].radius + s.bodies[j].radius - 1e-9);
      }
    }
  }
}

}  // namespace physval::test
