// Particle systems: explosions and trails, counts, lifetimes, colour by age, and
// destruction on collision.
#include <gtest/gtest.h>

#include <cmath>

#include "scene_fixture.hpp"

namespace physval::test {

namespace {
int alive_particles(Sim& sim) {
  sim.engine.read_states(sim.states);
  int n = 0;
  for (std::size_t i = sim.scene.bodies.size(); i < sim.states.size(); ++i) n += sim.states[i].alive ? 1 : 0;
  return n;
}
Scene rocket_with(EmitterDef e, Vec2 gravity = {}) {
  Scene s = scene_of({circle("rocket", {0.0, 10.0}, {3.0, 4.0})}, {}, gravity);
  e.parent = "rocket";
  s.emitters.push_back(e);
  s.duration = 5.0;
  return s;
}
}  // namespace

TEST(CoreParticles, ExplosionCountsLifetimeAndSpread) {
  EmitterDef e;
  e.name = "boom";
  e.mode = EmitterMode::Explode;
  e.at = 0.505;
  e.count = 200;
  e.speed = 2.0;
  e.lifetime = 1.0;
  e.gravity = false;
  e.seed = 7;
  Sim sim(rocket_with(e));
  sim.run_until(0.5, 0.01);
  EXPECT_EQ(sim.engine.body_count(), 1u);
  sim.step(0.01);   // t = 0.51: exploded at 0.505
  EXPECT_FALSE(sim.state("rocket").alive);
  ASSERT_EQ(sim.engine.body_count(), 201u);
  EXPECT_EQ(alive_particles(sim), 200);
  // Each particle started at the rocket's position at 0.505 with a velocity within 2
  // m/s of the rocket's; no gravity, so it moved in a straight line since.
  const Vec2 p_at{3.0 * 0.505, 10.0 + 4.0 * 0.505};
  for (std::size_t i = 1; i < sim.states.size(); ++i) {
    const BodyState& st = sim.states[i];
    EXPECT_LE(length(st.velocity - Vec2{3.0, 4.0}), 2.0);
    const Vec2 back = st.position - (sim.engine.time() - 0.505) * st.velocity;
    EXPECT_NEAR(back.x, p_at.x, 1e-12);
    EXPECT_NEAR(back.y, p_at.y, 1e-12);
    EXPECT_EQ(sim.engine.body_meta(i).name, "boom#" + std::to_string(i - 1));
    EXPECT_NEAR(sim.engine.body_meta(i).mass, e.mass, 1e-15);
  }
  // Colour intensity 1 - age / lifetime.
  EXPECT_NEAR(sim.engine.particle_age(1), 0.51 - 0.505, 1e-12);
  sim.run_until(1.005, 0.01);
  EXPECT_NEAR(sim.engine.particle_intensity(1), 0.5, 1e-9);
  sim.run_until(1.5, 0.01);
  EXPECT_EQ(alive_particles(sim), 200);   // age 0.995 at t = 1.5
  sim.step(0.01);
  EXPECT_EQ(alive_particles(sim), 0);     // 1.0 reached at 1.505
}

TEST(CoreParticles, TrailRateAndLifetime) {
  // 10 per second, first at 0.1 s; lifetime 0.55 s: at t = 2.0 those emitted at
  // 1.5 ... 2.0 are alive (6), 20 created in all.
  EmitterDef e;
  e.name = "smoke";
  e.mode = EmitterMode::Trail;
  e.rate = 10.0;
  e.lifetime = 0.55;
  e.speed = 0.5;
  Sim sim(rocket_with(e));
  sim.run_until(2.0, 1.0 / 64.0);
  EXPECT_EQ(sim.engine.body_count(), 21u);
  EXPECT_EQ(alive_particles(sim), 6);
}

TEST(CoreParticles, TrailParticlesStartWhereAndWhenTheyAreEmitted) {
  // The rocket falls under gravity; its trail leaves at 0.1, 0.2, ... s, inside steps of
  // 1/16 s, without gravity. Each particle, traced back along its straight line to its
  // birth time, is at the rocket's position then, with a velocity within `speed` of the
  // rocket's then; its age is the time since. (They were once placed at the rocket's
  // end-of-step position but aged from their emission time: up to |v| dt off.)
  const double g = 9.8;
  EmitterDef e;
  e.name = "smoke";
  e.mode = EmitterMode::Trail;
  e.rate = 10.0;
  e.lifetime = 5.0;
  e.speed = 0.5;
  e.gravity = false;
  Sim sim(rocket_with(e, {0.0, -g}));
  sim.run_until(1.0, 1.0 / 16.0);
  sim.engine.read_states(sim.states);
  ASSERT_EQ(sim.states.size(), 11u);
  for (std::size_t i = 1; i < sim.states.size(); ++i) {
    SCOPED_TRACE(i);
    const double tk = 0.1 * static_cast<double>(i);
    const double age = sim.engine.particle_age(i);
    EXPECT_NEAR(age, 1.0 - tk, 1e-12);
    const BodyState& st = sim.states[i];
    const Vec2 back = st.position - age * st.velocity;
    EXPECT_NEAR(back.x, 3.0 * tk, 1e-12);
    EXPECT_NEAR(back.y, 10.0 + 4.0 * tk - 0.5 * g * tk * tk, 1e-12);
    EXPECT_LE(length(st.velocity - Vec2{3.0, 4.0 - g * tk}), 0.5 + 1e-12);
  }
}

TEST(CoreParticles, DestroyedOnCollision) {
  // An explosion above a floor under gravity: every particle dies on its first impact
  // (well before its lifetime), none goes through the floor.
  EmitterDef e;
  e.name = "sparks";
  e.mode = EmitterMode::Explode;
  e.at = 0.0;
  e.count = 100;
  e.speed = 3.0;
  e.lifetime = 100.0;
  Scene s = rocket_with(e, {0.0, -9.8});
  s.walls.push_back(wall("floor", {-100.0, 0.0}, {100.0, 0.0}));
  Sim sim(s);
  sim.run_until(0.5, 1.0 / 60.0);
  EXPECT_EQ(alive_particles(sim), 100);   // nobody has reached the floor yet
  int hits = 0;
  while (sim.engine.time() < 4.0) {
    sim.step(1.0 / 60.0);
    for (const ContactEvent& c : sim.engine.contacts()) hits += c.b.kind == ObjectRef::Kind::Wall ? 1 : 0;
    sim.engine.read_states(sim.states);
    for (std::size_t i = 1; i < sim.states.size(); ++i) ASSERT_GE(sim.states[i].position.y, 0.0);
  }
  EXPECT_EQ(alive_particles(sim), 0);
  EXPECT_EQ(hits, 100);
}

TEST(CoreParticles, SameSeedSameParticles) {
  EmitterDef e;
  e.name = "boom";
  e.mode = EmitterMode::Explode;
  e.count = 50;
  e.seed = 42;
  Sim a(rocket_with(e)), b(rocket_with(e));
  a.steps(10, 0.01);
  b.steps(10, 0.01);
  a.engine.read_states(a.states);
  b.engine.read_states(b.states);
  ASSERT_EQ(a.states.size(), b.states.size());
  for (std::size_t i = 0; i < a.states.size(); ++i) {
    EXPECT_EQ(a.states[i].velocity.x, b.states[i].velocity.x);
    EXPECT_EQ(a.states[i].velocity.y, b.states[i].velocity.y);
  }
}

}  // namespace physval::test
