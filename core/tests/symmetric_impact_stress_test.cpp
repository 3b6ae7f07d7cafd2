// Stress test of simultaneous impacts with friction (issue 9): symmetric 3- and 4-ball
// scenes over a grid of restitution e and friction mu, each run with every numbering of
// its bodies and as the mirrored scene. The answer must have the scene's symmetry to
// 1e-12, be the same (mirrored back) for every numbering and for the mirror image to
// 1e-12, keep momentum where no external force acts, and never gain energy.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <functional>
#include <numbers>
#include <numeric>
#include <string>
#include <vector>

#include "scene_fixture.hpp"

namespace physval::test {
namespace {

constexpr double g = 9.8;
constexpr double r = 0.5;

// A 2x2 linear map of the plane (a symmetry of a scene).
struct Map {
  double xx, xy, yx, yy;
  Vec2 operator()(Vec2 v) const { return {xx * v.x + xy * v.y, yx * v.x + yy * v.y}; }
};
constexpr Map kMirror{-1.0, 0.0, 0.0, 1.0};   // x -> -x

// One symmetry: body k of the answer maps to body perm[k] under `map`.
struct Symmetry {
  std::string name;
  std::vector<int> perm;
  Map map;
};

struct Config {
  std::string name;
  bool floor = false;   // gravity and a floor at y = 0 (else no force at all)
  double t_end = 1.0;
  std::function<std::vector<BodyDef>(double e)> bodies;   // canonical order
  std::vector<Symmetry> symmetries;
};

BodyDef ball(std::string name, Vec2 p, Vec2 v, double e) { return circle(std::move(name), p, v, r, 1.0, e); }

// The balls of a 120-degree converging triple: ball k at angle 90 + 120 k degrees,
// distance d from the centre, moving in at u with a swirl w (a tangential velocity
// the same way round for all three: friction acts at every contact).
std::vector<BodyDef> converging(double d, double u, double w, double e) {
  std::vector<BodyDef> b;
  for (int k = 0; k < 3; ++k) {
    const double a = std::numbers::pi / 2.0 + 2.0 * std::numbers::pi * k / 3.0;
    const Vec2 radial{std::cos(a), std::sin(a)};
    b.push_back(ball("b" + std::to_string(k), d * radial, -u * radial + w * perp(radial), e));
  }
  return b;
}

Map rotation(double deg) {
  const double a = deg * std::numbers::pi / 180.0;
  return {std::cos(a), -std::sin(a), std::sin(a), std::cos(a)};
}

std::vector<Config> configs() {
  std::vector<Config> c;
  // A ball at 2 m/s meeting two balls at rest at once, contact normals 30 degrees from
  // the vertical (no gravity): friction acts on the 1 m/s tangential approach.
  {
    Config k;
    k.name = "ball_on_two";
    k.t_end = 1.0;
    k.bodies = [](double e) {
      const double s = 0.5, cth = std::sqrt(0.75);
      return std::vector<BodyDef>{ball("top", {0.0, 2.0 * r * cth + 2.0 * 0.25}, {0.0, -2.0}, e),
                                  ball("left", {-2.0 * r * s, 0.0}, {}, e), ball("right", {2.0 * r * s, 0.0}, {}, e)};
    };
    k.symmetries = {{"mirror", {0, 2, 1}, kMirror}};
    c.push_back(k);
  }
  // The scene: dropped from (0, 3) onto two balls resting on a floor, 2 s.
  {
    Config k;
    k.name = "ball_on_two_on_floor";
    k.floor = true;
    k.t_end = 2.0;
    k.bodies = [](double e) {
      return std::vector<BodyDef>{ball("top", {0.0, 3.0}, {}, e), ball("left", {-0.5, 0.5}, {}, e),
                                  ball("right", {0.5, 0.5}, {}, e)};
    };
    k.symmetries = {{"mirror", {0, 2, 1}, kMirror}};
    c.push_back(k);
  }
  // A 4-ball stack: a ball dropped from (0, 3.5) onto one resting on two balls on the
  // floor (bodies touching at t = 0), 2 s.
  {
    Config k;
    k.name = "ball_on_stack_of_three";
    k.floor = true;
    k.t_end = 2.0;
    k.bodies = [](double e) {
      return std::vector<BodyDef>{ball("top", {0.0, 3.5}, {}, e),
                                  ball("middle", {0.0, 0.5 + std::sqrt(0.75)}, {}, e),
                                  ball("left", {-0.5, 0.5}, {}, e), ball("right", {0.5, 0.5}, {}, e)};
    };
    k.symmetries = {{"mirror", {0, 1, 3, 2}, kMirror}};
    c.push_back(k);
  }
  // Three balls converging on a centre at 120 degrees, meeting pairwise at once.
  {
    Config k;
    k.name = "triple_converging";
    k.t_end = 1.0;
    k.bodies = [](double e) { return converging(1.0 / std::sqrt(3.0) + 0.3, 1.0, 0.4, e); };
    k.symmetries = {{"rotate120", {1, 2, 0}, rotation(120.0)}, {"rotate240", {2, 0, 1}, rotation(240.0)}};
    c.push_back(k);
  }
  // The same three converging on a ball at rest at the centre (4 balls, 3 contacts).
  {
    Config k;
    k.name = "triple_on_centre";
    k.t_end = 1.0;
    k.bodies = [](double e) {
      std::vector<BodyDef> b = converging(2.0 * r + 0.3, 1.0, 0.4, e);
      b.push_back(ball("centre", {0.0, 0.0}, {}, e));
      return b;
    };
    k.symmetries = {{"rotate120", {1, 2, 0, 3}, rotation(120.0)}, {"rotate240", {2, 0, 1, 3}, rotation(240.0)}};
    c.push_back(k);
  }
  return c;
}

struct Final {
  std::vector<Vec2> p, v;   // canonical body order, mirrored back
  std::string failure;      // energy or momentum rule broken (empty: none)
  bool unjustified = false; // core reported a hold it cannot justify (the run stops there)
  bool grouped = false;     // core moved bodies in its contact-group mode
};

std::string sci(double x) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3g", x);
  return buf;
}

double energy(const std::vector<BodyState>& s, bool gravity) {
  double E = 0.0;
  for (const BodyState& b : s) E += 0.5 * length_squared(b.velocity) + (gravity ? g * b.position.y : 0.0);
  return E;
}

// Runs config c with bodies listed in `order` (a permutation of the canonical indices),
// mirrored or not; checks energy and momentum as it goes.
Final run(const Config& c, double e, double mu, const std::vector<int>& order, bool mirror) {
  const std::vector<BodyDef> canon = c.bodies(e);
  std::vector<BodyDef> bodies;
  for (int k : order) {
    BodyDef b = canon[static_cast<std::size_t>(k)];
    b.friction = mu;
    b.static_friction = mu;
    if (mirror) {
      b.position = kMirror(b.position);
      b.velocity = kMirror(b.velocity);
    }
    bodies.push_back(b);
  }
  std::vector<WallDef> walls;
  if (c.floor) walls.push_back(wall("floor", {-5.0, 0.0}, {5.0, 0.0}, e, mu));
  Sim sim(scene_of(bodies, walls, c.floor ? Vec2{0.0, -g} : Vec2{}));
  Final f;
  const double dt = 0.01;
  sim.engine.read_states(sim.states);
  const double E0 = energy(sim.states, c.floor);
  Vec2 P0;
  for (const BodyState& s : sim.states) P0 += s.velocity;
  double E_prev = E0;
  while (sim.engine.time() < c.t_end - 1e-12 && f.failure.empty()) {
    sim.step(std::min(dt, c.t_end - sim.engine.time()));
    sim.engine.read_states(sim.states);
    const double E = energy(sim.states, c.floor);
    // Energy never grows, step by step (1e-12 relative: round-off). Under gravity, but
    // for the micro-bounce of a pressed pair that nothing holds (it leaves at half the
    // rest speed v_r = g dt / 16): at most m (v_r / 2)^2 / 2 per body and step, the
    // README's stated exception (as in pile_test.cpp); and never above the start.
    const double v_r = g * dt / 16.0;
    const double micro_bounces = c.floor ? 0.5 * (0.5 * v_r) * (0.5 * v_r) * static_cast<double>(bodies.size()) : 0.0;
    if (E > E_prev + 1e-12 * std::max(1.0, std::fabs(E_prev)) + micro_bounces ||
        E > E0 + 1e-12 * std::max(1.0, std::fabs(E0))) {
      f.failure = "energy rose by " + sci(E - E_prev) + " J at t " +
                  std::to_string(sim.engine.time());
    }
    E_prev = E;
    if (!c.floor) {   // no external force: momentum kept
      Vec2 P;
      for (const BodyState& s : sim.states) P += s.velocity;
      if (length(P - P0) > 1e-12) f.failure = "momentum changed by " + std::to_string(length(P - P0));
    }
    if (const std::string b = sim.engine.broken_guarantee(); !b.empty()) {
      // (since contact12 such a component moves in the contact-group mode, which reports what
      // it does not model there the same way)
      if (b.find("cannot hold it") != std::string::npos || b.find("bodies moving in contact") != std::string::npos) {
        f.unjustified = true;
        break;
      }
      f.failure = b;
    }
  }
  for (const std::string& l : sim.engine.limits_hit()) {
    f.grouped = f.grouped || l.find("bodies moving in contact") != std::string::npos;
  }
  // Elastic and frictionless: energy kept exactly.
  if (f.failure.empty() && !c.floor && e == 1.0 && mu == 0.0 && std::fabs(E_prev - E0) > 1e-12 * E0) {
    f.failure = "elastic frictionless energy changed by " + std::to_string(E_prev - E0);
  }
  f.p.resize(canon.size());
  f.v.resize(canon.size());
  for (std::size_t k = 0; k < order.size(); ++k) {
    const BodyState& s = sim.states[k];
    const std::size_t b = static_cast<std::size_t>(order[k]);
    f.p[b] = mirror ? kMirror(s.position) : s.position;
    f.v[b] = mirror ? kMirror(s.velocity) : s.velocity;
  }
  return f;
}

double worst_difference(const Final& a, const Final& b) {
  double worst = 0.0;
  for (std::size_t k = 0; k < a.p.size(); ++k) {
    worst = std::max({worst, length(a.p[k] - b.p[k]), length(a.v[k] - b.v[k])});
  }
  return worst;
}

class SymmetricImpactStress : public ::testing::TestWithParam<std::size_t> {};

TEST_P(SymmetricImpactStress, SymmetricWhateverTheNumberingAndNoEnergyGain) {
  const Config c = configs()[GetParam()];
  const std::size_t n = c.bodies(1.0).size();
  int runs = 0;
  for (double e : {0.0, 0.3, 0.5, 0.8, 1.0}) {
    for (double mu : {0.0, 0.1, 0.3, 0.6, 1.0}) {
      const std::string what = c.name + " e " + std::to_string(e) + " mu " + std::to_string(mu);
      std::vector<int> order(n);
      std::iota(order.begin(), order.end(), 0);
      const Final ref = run(c, e, mu, order, false);
      EXPECT_TRUE(ref.failure.empty()) << what << ": " << ref.failure;
      // The stack's middle ball on two floor balls (the top still falling): every contact has
      // mu, so friction at the middle's contacts tilts their force towards the vertical by
      // atan(mu); each bottom ball is pushed out by (W / 2) tan(30 deg - atan mu) and pressed
      // on the floor by 1.5 W, so it holds iff tan(30 deg - atan mu) <= 3 mu: mu >= 0.13
      // (mu 0.1: 0.451 against 0.3). Below, the bottom balls must spread; core has no exact
      // model of that collapse yet and must say so (a broken guarantee: the run is diverged),
      // never hold it `ok`.
      const bool must_spread = c.name == "ball_on_stack_of_three" && mu < 0.13;
      // Since contact12: reported, or moved in the contact-group mode (limits_hit says so).
      EXPECT_EQ(ref.unjustified || ref.grouped, must_spread) << what;
      if (must_spread) continue;
      // On a frictionless floor (mu = 0 with gravity) too: bodies sliding on it take part in
      // the simultaneous sets (they were left out, and the answer depended on the numbering
      // by up to 2 mm here).
      // The scene's own symmetries, to 1e-12.
      for (const Symmetry& s : c.symmetries) {
        double worst = 0.0;
        for (std::size_t k = 0; k < n; ++k) {
          const std::size_t m = static_cast<std::size_t>(s.perm[k]);
          worst = std::max({worst, length(ref.p[m] - s.map(ref.p[k])), length(ref.v[m] - s.map(ref.v[k]))});
        }
        EXPECT_LE(worst, 1e-12) << what << ": " << s.name;
      }
      // Every numbering, plain and mirrored, gives the same answer (mirrored back).
      do {
        for (bool mirror : {false, true}) {
          const Final f = run(c, e, mu, order, mirror);
          ++runs;
          std::string tag = what + " order";
          for (int k : order) tag += " " + std::to_string(k);
          if (mirror) tag += " mirrored";
          EXPECT_TRUE(f.failure.empty()) << tag << ": " << f.failure;
          EXPECT_FALSE(f.unjustified) << tag;
          EXPECT_LE(worst_difference(f, ref), 1e-12) << tag;
        }
      } while (std::next_permutation(order.begin(), order.end()));
    }
  }
  RecordProperty("runs", runs);
}

INSTANTIATE_TEST_SUITE_P(Configs, SymmetricImpactStress, ::testing::Range<std::size_t>(0, 5),
                         [](const auto& param_info) { return configs()[param_info.param].name; });

// The scenes above meet their impacts together: the simultaneous set takes every ball of
// the symmetric impact (checked on the 4-ball ones: one event solves all contacts).
TEST(SymmetricImpactStress, ConvergingTripleIsOneSimultaneousImpact) {
  for (double mu : {0.0, 0.3}) {
    std::vector<BodyDef> b = converging(1.0 / std::sqrt(3.0) + 0.3, 1.0, 0.4, 1.0);
    for (BodyDef& x : b) x.friction = x.static_friction = mu;
    Sim sim(scene_of(b));
    sim.run_until(1.0, 0.01);
    // Three pairs touched at once: three contact events at the same time.
    ASSERT_EQ(sim.contacts.size(), 3u) << mu;
    for (const ContactEvent& ce : sim.contacts) EXPECT_EQ(ce.time, sim.contacts[0].time) << mu;
  }
}

}  // namespace
}  // namespace physval::test
