// A ball struck into another on a parallel face at another height (join_chain joins bodies
// on faces of one normal, not on one face): the train's closed form, the same at three
// steps. (Review of whole-chain train joining, review5.)
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "scene_fixture.hpp"

namespace physval::test {
namespace {
constexpr double g = 9.8;
}  // namespace
}  // namespace physval::test

namespace physval::test {
namespace {
// A train over two parallel faces at different heights: a ball (r 0.5, 1 kg) on a floor
// strikes one (r 0.25, 5 kg) on a platform 0.25 m high, their centres level (the contact
// normal along both faces), each with its own face's friction. join_chain takes faces of
// one normal, not one face: the pair is joined as a train (closed form below), the same at
// three steps; the struck ball never reaches the platform's corner.
std::vector<BodyState> probe_final(const Scene& sc, double dt, double T, std::string& why) {
  Sim sim(sc);
  while (sim.engine.time() < T - 1e-12) {
    sim.step(std::min(dt, T - sim.engine.time()));
    if (sim.engine.last_step_stats().event_cap_hit) why += " cap";
  }
  why += sim.engine.broken_guarantee();
  std::vector<BodyState> f;
  for (std::size_t i = 0; i < sc.bodies.size(); ++i) f.push_back(sim.state(sc.bodies[i].name));
  return f;
}
void expect_step_independent(const Scene& sc, double T, const std::string& label) {
  std::vector<std::vector<BodyState>> finals;
  for (double dt : {1.0 / 60.0, 1.0 / 97.0, 1.0 / 240.0}) {
    std::string why;
    finals.push_back(probe_final(sc, dt, T, why));
    EXPECT_EQ(why, "") << label << " dt " << dt;
  }
  for (std::size_t d = 1; d < finals.size(); ++d) {
    for (std::size_t i = 0; i < finals[0].size(); ++i) {
      EXPECT_NEAR(length(finals[d][i].position - finals[0][i].position), 0.0, 1e-9) << label << " ball " << i << " d " << d;
      EXPECT_NEAR(length(finals[d][i].velocity - finals[0][i].velocity), 0.0, 1e-9) << label << " ball " << i << " d " << d;
    }
  }
}
}  // namespace

TEST(CoreTrainJoin, ATrainOverAPlatformsStepMovesOnAsTheClosedFormSays) {
  for (double v0 : {2.0, 3.0}) {
    for (double muf : {0.3, 0.6}) {
      for (double mup : {0.1, 0.5}) {
        const double x0 = 2.0;   // the platform's left side
        std::vector<BodyDef> b = {circle("a", {1.0, 0.5}, {v0, 0.0}, 0.5, 1.0, 0.0),
                                  circle("b", {x0 + 0.2, 0.5}, {}, 0.25, 5.0, 0.0)};
        std::vector<WallDef> w = {wall("floor", {-30.0, 0.0}, {x0, 0.0}, 0.0, 0.0), wall("side", {x0, 0.0}, {x0, 0.25}, 0.0, 0.0),
                                  wall("top", {x0, 0.25}, {x0 + 30.0, 0.25}, 0.0, 0.0)};
        Scene sc = scene_of(b, w, {0.0, -g});
        sc.materials.push_back(pair_friction("a", "floor", muf));
        sc.materials.push_back(pair_friction("b", "top", mup));
        expect_step_independent(sc, 3.0, "v0 " + std::to_string(v0) + " muf " + std::to_string(muf) + " mup " + std::to_string(mup));
        // Closed form: a decelerates at muf g over 0.45 m to b; one velocity (masses 1
        // and 5); then pooled from the rear (a presses b iff it would decelerate less).
        std::string why;
        const auto f = probe_final(sc, 1.0 / 60.0, 3.0, why);
        const double d = 0.45, v1s = v0 * v0 - 2.0 * muf * g * d;
        double xa = 1.0 + v0 * v0 / (2.0 * muf * g), xb = x0 + 0.2;
        if (v1s > 0.0) {
          const double v = std::sqrt(v1s) / 6.0;
          const double aa = muf * g, ab = mup * g, blk = (muf + 5.0 * mup) * g / 6.0;
          xa = 1.0 + d + v * v / (2.0 * (aa <= ab ? blk : aa));
          xb += v * v / (2.0 * (aa <= ab ? blk : ab));
        }
        EXPECT_NEAR(f[0].position.x, xa, 1e-9) << v0 << " " << muf << " " << mup;
        EXPECT_NEAR(f[1].position.x, xb, 1e-9) << v0 << " " << muf << " " << mup;
        EXPECT_EQ(f[0].velocity, Vec2{});
        EXPECT_EQ(f[1].velocity, Vec2{});
      }
    }
  }
}

}  // namespace physval::test
