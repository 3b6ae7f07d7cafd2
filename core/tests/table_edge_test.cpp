// A ball sliding off the end of a table (a wall's end point), the first scene of many a
// newcomer. Found by the hunt (scripts/hunt.sh, grid `edge`): core was released at the
// end, met the face at once as "pressed" again, settled on it and was released again,
// until the event cap, at every speed.
//
// Rigid-body facts (non-rotating circle of radius r, uniform g, the table's top along
// y = 0, its end at x = 0): the centre reaches the end at speed v; leaving the face, its
// free path keeps distance d(t) from the end point with d^2 = r^2 + (v^2 - g r) t^2 + O(t^4).
// So for v^2 >= g r it flies off at once, and its path from there is the projectile's.
// For v^2 < g r it must turn about the end point (a curved contact) until
// cos(phi) = (v^2 / (g r) + 2) / 3; core has no curved support yet, it micro-bounces
// around the corner (README, The hunt for wrong greens), so there only what any model
// must keep is checked: no event cap, no energy gained, and it leaves.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "scene_fixture.hpp"

namespace physval::test {
namespace {

constexpr double g = 9.8;

struct EdgeCase {
  double v0, mu, r, d;
  bool leftwards, reversed;
};

Scene edge_scene(const EdgeCase& c) {
  const double s = c.leftwards ? -1.0 : 1.0;
  BodyDef b = circle("b", {-s * c.d, c.r}, {s * c.v0, 0.0}, c.r, 1.0, 0.0);
  b.friction = b.static_friction = c.mu;
  Vec2 from{-s * 20.0, 0.0}, to{0.0, 0.0};
  if (c.reversed) std::swap(from, to);
  return scene_of({b}, {wall("table", from, to, 0.0, c.mu)}, {0.0, -g});
}

std::string where(const EdgeCase& c) {
  return "v0 " + std::to_string(c.v0) + " mu " + std::to_string(c.mu) + " r " + std::to_string(c.r) + " d " +
         std::to_string(c.d) + (c.leftwards ? " leftwards" : "") + (c.reversed ? " reversed" : "");
}

TEST(CoreTableEdge, ABallFastEnoughFliesOffTheEdgeOnTheProjectilesPath) {
  int judged = 0;
  for (double v0 : {2.5, 3.0, 5.0, 10.0}) {
    for (double mu : {0.0, 0.1}) {
      for (double r : {0.1, 0.5}) {
        for (double d : {v0 / 3.0, v0 / 3.0 + 0.013}) {   // at a step's end, and inside one
          for (bool leftwards : {false, true}) {
            for (bool reversed : {false, true}) {
              const EdgeCase c{v0, mu, r, d, leftwards, reversed};
              const double vc2 = v0 * v0 - 2.0 * mu * g * d;
              if (!(vc2 >= 1.05 * g * r)) continue;
              const double vc = std::sqrt(vc2);
              const double te = mu > 0.0 ? (v0 - vc) / (mu * g) : d / v0;
              const double T = te + 0.3;
              Sim sim(edge_scene(c));
              bool capped = false;
              while (sim.engine.time() < T - 1e-12) {
                sim.step(std::min(1.0 / 60.0, T - sim.engine.time()));
                capped = capped || sim.engine.last_step_stats().event_cap_hit;
              }
              const double s = T - te, sx = leftwards ? -1.0 : 1.0;
              const BodyState b = sim.state("b");
              EXPECT_FALSE(capped) << where(c);
              EXPECT_NEAR(b.position.x, sx * vc * s, 1e-9) << where(c);
              EXPECT_NEAR(b.position.y, r - 0.5 * g * s * s, 1e-9) << where(c);
              EXPECT_NEAR(b.velocity.x, sx * vc, 1e-9) << where(c);
              EXPECT_NEAR(b.velocity.y, -g * s, 1e-9) << where(c);
              ++judged;
            }
          }
        }
      }
    }
  }
  EXPECT_GT(judged, 100);
}

// The frictionless turn about the end point, integrated to round-off (RK4, h 1e-6 s,
// lift-off where N = m (g cos(phi) - r phi'^2) = 0 bisected), then the free flight:
// the state at T, the centre reaching the end at t_e with speed v.
BodyState turned_and_flown(double v, double r, double te, double T) {
  double phi = 0.0, w = v / r;
  const auto N = [&](double p, double om) { return g * std::cos(p) - r * om * om; };
  const auto rk4 = [&](double p, double om, double h, double& p2, double& om2) {
    const double k1p = om, k1w = g * std::sin(p) / r;
    const double k2p = om + 0.5 * h * k1w, k2w = g * std::sin(p + 0.5 * h * k1p) / r;
    const double k3p = om + 0.5 * h * k2w, k3w = g * std::sin(p + 0.5 * h * k2p) / r;
    const double k4p = om + h * k3w, k4w = g * std::sin(p + h * k3p) / r;
    p2 = p + h / 6.0 * (k1p + 2.0 * k2p + 2.0 * k3p + k4p);
    om2 = om + h / 6.0 * (k1w + 2.0 * k2w + 2.0 * k3w + k4w);
  };
  double t = 0.0;
  const double h = 1e-6;
  for (;;) {
    double p2, w2;
    rk4(phi, w, h, p2, w2);
    if (N(p2, w2) <= 0.0) {
      double lo = 0.0, hi = h;
      for (int k = 0; k < 80; ++k) {
        const double m = 0.5 * (lo + hi);
        rk4(phi, w, m, p2, w2);
        (N(p2, w2) <= 0.0 ? hi : lo) = m;
      }
      rk4(phi, w, hi, phi, w);
      t += hi;
      break;
    }
    phi = p2;
    w = w2;
    t += h;
  }
  const double s = T - te - t;
  BodyState b;
  b.velocity = {r * w * std::cos(phi), -r * w * std::sin(phi) - g * s};
  b.position = {r * std::sin(phi) + r * w * std::cos(phi) * s, r * std::cos(phi) - r * w * std::sin(phi) * s - 0.5 * g * s * s};
  return b;
}

// Too slow to fly off (v^2 < g r): the ball turns about the end point. core rides the
// corner's cap (convex_cap.cpp; it micro-bounced off the end point before, first order,
// 3 mm off at dt 1/60), so here: no event cap, it leaves and falls, on the turn's closed
// form (its own RK4 above, to ~1e-10) whatever dt.
TEST(CoreTableEdge, ABallTooSlowToFlyOffTurnsAboutTheEdgeOnTheClosedForm) {
  for (double v0 : {0.3, 1.0, 1.5, 2.0}) {
    for (double d : {v0 / 3.0, v0 / 3.0 + 0.013}) {
      for (bool leftwards : {false, true}) {
        for (bool reversed : {false, true}) {
          const EdgeCase c{v0, 0.0, 0.5, d, leftwards, reversed};
          const double te = d / v0, T = te + 1.0;
          const BodyState exact = turned_and_flown(v0, 0.5, te, T);
          double err[2] = {0.0, 0.0};
          for (int k = 0; k < 2; ++k) {
            const double dt = k == 0 ? 1.0 / 60.0 : 1.0 / 240.0;
            Sim sim(edge_scene(c));
            bool capped = false;
            while (sim.engine.time() < T - 1e-12) {
              sim.step(std::min(dt, T - sim.engine.time()));
              capped = capped || sim.engine.last_step_stats().event_cap_hit;
            }
            const BodyState b = sim.state("b");
            const double sx = leftwards ? -1.0 : 1.0;
            EXPECT_FALSE(capped) << where(c) << " dt " << dt;
            EXPECT_LT(b.position.y, -1.0) << where(c);   // it has left the table and fallen
            err[k] = std::max(std::hypot(sx * b.position.x - exact.position.x, b.position.y - exact.position.y),
                              std::hypot(sx * b.velocity.x - exact.velocity.x, b.velocity.y - exact.velocity.y));
          }
          EXPECT_LT(err[0], 1e-9) << where(c);
          EXPECT_LT(err[1], 1e-9) << where(c);
        }
      }
    }
  }
}

}  // namespace
}  // namespace physval::test
