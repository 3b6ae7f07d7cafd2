// The core hunt against closed forms (scripts/corehunt.py; README "The core hunt against
// closed forms"): each test holds one finding of that hunt, a scene with its closed form.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "scene_fixture.hpp"

namespace physval::test {
namespace {

// The pi billiard with e < 1 (a 1 kg circle at rest between a wall and an M kg circle
// coming at 1 m/s, every restitution e). The exact map of its impacts (wall: v1 -> -e v1;
// pair: Newton's law) never ends for M = 1e6, 1e8 at e = 0.99: it is inelastic collapse,
// the gaps shrink to nothing and both velocities fall to 0 (after 2e6 impacts of the map
// they are 5e-86 m/s at M = 1e6). Its zero-time cycle at round-off gaps (wall | light |
// heavy) was solved with the separating wall contact taking an impulse that held the
// light circle at the wall while the heavy one bounced off at their relative speed: the
// heavy circle left at +76 m/s (M = 1e6) with 5,800 times the scene's energy, status ok.
Scene squeezed_billiard(double M, double e) {
  Scene s = scene_of({circle("light", {1.0, 0.0}, {0.0, 0.0}, 0.1, 1.0, e),
                      circle("heavy", {2.0, 0.0}, {-1.0, 0.0}, 0.1, M, e)},
                     {wall("wall", {0.0, -1.0}, {0.0, 1.0}, e)});
  return s;
}

TEST(CoreHunt, SqueezedBilliardCollapsesWithoutGainingEnergy) {
  for (const double M : {1e6, 1e8}) {
    SCOPED_TRACE("M = " + std::to_string(M));
    Sim sim(squeezed_billiard(M, 0.99));
    const double e0 = 0.5 * M;
    for (int k = 0; k < 800; ++k) {
      sim.step(0.01);
      ASSERT_EQ(sim.engine.broken_guarantee(), "") << "step " << k;
      const BodyState l = sim.state("light"), h = sim.state("heavy");
      const double ke = 0.5 * (l.velocity.x * l.velocity.x) + 0.5 * M * (h.velocity.x * h.velocity.x);
      ASSERT_LE(ke, e0 * (1.0 + 1e-12)) << "step " << k;
      // wall | light | heavy, in that order
      ASSERT_GE(l.position.x, 0.1 - 1e-9) << "step " << k;
      ASSERT_GE(h.position.x - l.position.x, 0.2 - 1e-9) << "step " << k;
    }
    // The collapse's limit: both at rest, squeezed against the wall.
    const BodyState l = sim.state("light"), h = sim.state("heavy");
    EXPECT_LT(std::fabs(l.velocity.x), 1e-6);
    EXPECT_LT(std::fabs(h.velocity.x), 1e-6);
    EXPECT_NEAR(h.position.x, 0.3, 1e-6);
  }
}

}  // namespace
}  // namespace physval::test
