// Contact-begin events are per pair: a pair that keeps touching (resting, sliding,
// micro-bouncing under a pressing force) begins once, however many partners a body has.
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <utility>

#include "scene_fixture.hpp"

namespace physval::test {

namespace {
constexpr double r = 0.5;
// Two balls on the floor, touching, and a third resting on both. `boxed`: a side wall
// touches each bottom ball, so the pyramid holds (seven touching pairs); otherwise the
// frictionless floor lets it spread and the top ball falls and bounces on the floor.
Scene pyramid(double e, bool boxed) {
  const double top = r + 2.0 * r * std::sqrt(0.75);
  std::vector<WallDef> walls = {wall("floor", {-10.0, 0.0}, {10.0, 0.0}, e)};
  if (boxed) {
    walls.push_back(wall("left_wall", {-2 * r, 0.0}, {-2 * r, 5.0}, e));
    walls.push_back(wall("right_wall", {2 * r, 0.0}, {2 * r, 5.0}, e));
  }
  return scene_of({circle("left", {-r, r}, {}, r, 1.0, e), circle("right", {r, r}, {}, r, 1.0, e),
                   circle("top", {0.0, top}, {}, r, 1.0, e)},
                  walls, {0.0, -9.8});
}
using PairBegins = std::map<std::pair<std::uint32_t, std::uint32_t>, std::vector<double>>;
PairBegins begins_by_pair(const std::vector<ContactEvent>& contacts) {
  PairBegins out;
  for (const ContactEvent& c : contacts) {
    const std::uint32_t b = c.b.kind == ObjectRef::Kind::Body ? c.b.index : 1000u + c.b.index;
    out[{c.a.index, b}].push_back(c.time);
  }
  return out;
}
}  // namespace

TEST(CoreContactEvents, HeldPyramidBeginsEachPairAtMostOnce) {
  // Before contacts were per pair, the top ball (touching two balls) forgot one partner
  // at each impact with the other and every impact began a contact: 2,227 in 2 s.
  // Short run: this scene chatters at ~1e5 impacts per step (a ball resting in a V of
  // two bodies is not yet a resting contact; see the README's core limits).
  Sim sim(pyramid(0.5, true));
  sim.run_until(0.1, 1.0 / 60.0);
  EXPECT_LE(sim.contacts.size(), 7u);
  for (const auto& [pair, times] : begins_by_pair(sim.contacts))
    EXPECT_EQ(times.size(), 1u) << pair.first << "-" << pair.second;
}

TEST(CoreContactEvents, SpreadingPyramidBeginsAgainOnlyAfterAFlight) {
  // The open pyramid spreads (frictionless floor); the top ball falls to the floor and
  // bounces (e = 0.5): each bounce after a flight longer than a step is a new contact,
  // nothing else begins twice.
  const double dt = 1.0 / 60.0;
  Sim sim(pyramid(0.5, false));
  sim.run_until(2.0, dt);
  for (const auto& [pair, times] : begins_by_pair(sim.contacts)) {
    SCOPED_TRACE(std::to_string(pair.first) + "-" + std::to_string(pair.second));
    if (pair != std::pair<std::uint32_t, std::uint32_t>{2u, 1000u}) {
      EXPECT_EQ(times.size(), 1u);
    }
    for (std::size_t k = 1; k < times.size(); ++k) EXPECT_GT(times[k] - times[k - 1], dt);
  }
  EXPECT_LE(sim.contacts.size(), 12u);
}

TEST(CoreContactEvents, ABounceAfterAFlightIsANewContact) {
  // e = 1 ball dropped 1 m onto the floor beside a resting ball: every bounce is a new
  // contact with the floor (flights of 0.9 s), while the resting one begins once.
  Sim sim(scene_of({circle("bouncer", {0.0, 1.5}, {}, 0.5, 1.0, 1.0), circle("sitter", {3.0, 0.5}, {}, 0.5, 1.0, 0.0)},
                   {wall("floor", {-10.0, 0.0}, {10.0, 0.0}, 1.0)}, {0.0, -9.8}));
  sim.run_until(4.0, 1.0 / 60.0);
  int bouncer = 0, sitter = 0;
  for (const ContactEvent& c : sim.contacts) (c.a.index == 0 ? bouncer : sitter) += 1;
  // First impact at sqrt(2/9.8) = 0.4518 s, then every 0.9035 s: 0.45, 1.36, 2.26, 3.16.
  EXPECT_EQ(bouncer, 4);
  EXPECT_LE(sitter, 1);
}

}  // namespace physval::test
