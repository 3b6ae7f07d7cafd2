// An impact with nothing else near skips the simultaneous law's touching-set gather
// (exact_collisions.cpp, isolated_pair / isolated_static): the pairwise response must
// then be exactly what the simultaneous law would have given. In a gas no body touches
// two at once, so the simultaneous law's run must equal the sequential law's to the
// last bit; and where a third body or a face does touch, the set must still decide.
#include <gtest/gtest.h>

#include <cmath>

#include "physval/core/scene_builders.hpp"
#include "scene_fixture.hpp"

namespace physval::test {
namespace {

TEST(CoreIsolatedImpact, GasUnderTheSimultaneousLawEqualsTheSequentialLawToTheBit) {
  const Scene gas = make_circle_gas(400, 7);
  Sim simultaneous(gas, {{"collision", std::string("exact")}});
  Sim sequential(gas, {{"collision", std::string("exact")}, {"impact_law", std::string("sequential")}});
  std::size_t wall_contacts = 0;
  for (int k = 0; k < 180; ++k) {
    simultaneous.step(gas.dt);
    sequential.step(gas.dt);
  }
  ASSERT_EQ(simultaneous.contacts.size(), sequential.contacts.size());
  for (std::size_t c = 0; c < simultaneous.contacts.size(); ++c) {
    const ContactEvent& x = simultaneous.contacts[c];
    const ContactEvent& y = sequential.contacts[c];
    EXPECT_EQ(x.a, y.a);
    EXPECT_EQ(x.b, y.b);
    EXPECT_EQ(x.time, y.time);
    if (x.b.kind == ObjectRef::Kind::Wall || x.a.kind == ObjectRef::Kind::Wall) ++wall_contacts;
  }
  // Impacts between bodies and against the walls both took place.
  EXPECT_GT(simultaneous.contacts.size(), 500u);
  EXPECT_GT(wall_contacts, 10u);
  simultaneous.engine.read_states(simultaneous.states);
  sequential.engine.read_states(sequential.states);
  ASSERT_EQ(simultaneous.states.size(), sequential.states.size());
  for (std::size_t i = 0; i < simultaneous.states.size(); ++i) {
    EXPECT_EQ(simultaneous.states[i].position.x, sequential.states[i].position.x) << i;
    EXPECT_EQ(simultaneous.states[i].position.y, sequential.states[i].position.y) << i;
    EXPECT_EQ(simultaneous.states[i].velocity.x, sequential.states[i].velocity.x) << i;
    EXPECT_EQ(simultaneous.states[i].velocity.y, sequential.states[i].velocity.y) << i;
  }
}

// No forces, so the shortcut is tried; but the ball struck rests against the floor, a
// face within contact distance at the impact instant, so the shortcut must step back
// (its pairwise response undone) and the touching set decide. Equal masses, e = 1, A
// striking B head-on along n at 45 degrees to the floor: Newton's law at both contacts
// at once gives p_AB = 4u/3, p_floor = (4u/3) cos 45, so A leaves at -(u/3) n and B
// slides along the floor at (4u/3) cos 45 (energy conserved). The pairwise law, or a
// set that saw the pairwise response, leaves A at rest and sends B off at 45 degrees.
TEST(CoreIsolatedImpact, ImpactOnABallAgainstAWallGoesToTheTouchingSet) {
  const double r = 0.5, u = 2.0, c = std::sqrt(0.5), t_hit = 0.5;
  const Vec2 n{c, -c};   // from A to B at the impact
  const Vec2 b{0.0, r};  // touching the floor y = 0
  const Vec2 a_hit = b - (2.0 * r) * n;
  Scene s = scene_of({circle("A", a_hit - (u * t_hit) * n, u * n, r), circle("B", b, {}, r)},
                     {wall("floor", {-10.0, 0.0}, {10.0, 0.0})});
  Sim sim(s, {{"collision", std::string("exact")}});
  sim.run_until(0.75, 0.01);
  ASSERT_GE(sim.contacts.size(), 1u);
  EXPECT_NEAR(sim.state("A").velocity.x, -(u / 3.0) * n.x, 1e-9);
  EXPECT_NEAR(sim.state("A").velocity.y, -(u / 3.0) * n.y, 1e-9);
  EXPECT_NEAR(sim.state("B").velocity.x, (4.0 * u / 3.0) * c, 1e-9);
  EXPECT_NEAR(sim.state("B").velocity.y, 0.0, 1e-9);
}

}  // namespace
}  // namespace physval::test
