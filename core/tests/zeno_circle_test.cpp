// The sixteenth hunt: a ball bouncing straight on a static circle (dropped onto its top, the
// field through its centre) was held at rest from its first slow impact, the pair's
// collapse cut (rest speed |a| dt / 16), while the same drop onto a floor took its Zeno
// sequence in closed form. At a step of 300 falls (e 0.999) the ball sat still while it
// bounces for 6.3 s, 0.67 of the drop off at 1 s; the reference (dt/8, dt/16) cut it the same
// way and converged, so core was `ok`. The same at g 9.8 and dt 1/60 for a 1 um grain on a
// 10 um bead. Now the tail on a static circle is the face's closed form (circle_tail,
// exact_collisions.cpp).
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "scene_fixture.hpp"
#include "zeno_closed_form.hpp"

namespace physval::test {

// Drops straight onto static circles: e 0.5 to 0.999, steps of 0.3 to 300 falls, the field
// down or sideways (the ball placed up the field from the circle's centre; along an axis, so
// that the doubles hold the alignment exactly: the top of a circle is unstable, and a drop off
// it by round-off walks off at the bounces, as it should), radii from 1 um to 2 m. Every step's end at the closed form to 1e-9 of the drop plus round-off, and at rest
// on the circle after the sequence's end.
TEST(CoreZenoCircle, ABallDroppedStraightOntoAStaticCircleMeetsTheClosedForm) {
  struct Size {
    double R, r, h;
  };
  int cases = 0;
  for (const Size sz : {Size{0.5, 0.1, 0.05}, Size{1e-5, 1e-6, 1.5e-8}, Size{2.0, 0.5, 1.0}}) {
    for (double e : {0.5, 0.9, 0.99, 0.999}) {
      for (double falls : {0.3, 3.0, 30.0, 300.0}) {
        for (Vec2 gdir : {Vec2{0.0, -1.0}, Vec2{1.0, 0.0}}) {
          const double g = 9.8;
          const double tf = std::sqrt(2.0 * sz.h / g);
          const double dt = falls * tf;
          const double rest = tf * (1.0 + e) / (1.0 - e);
          const Vec2 up = -1.0 * gdir;
          const Vec2 start = (sz.R + sz.r + sz.h) * up;
          BodyDef dome = circle("dome", {}, {}, sz.R, 1.0, e);
          dome.is_static = true;
          Scene s = scene_of({circle("ball", start, {}, sz.r, 1.0, e), dome}, {}, g * gdir);
          SCOPED_TRACE("R " + std::to_string(sz.R) + " e " + std::to_string(e) + " falls " + std::to_string(falls) +
                       " g (" + std::to_string(gdir.x) + ", " + std::to_string(gdir.y) + ")");
          Sim sim(s);
          const int n = static_cast<int>(std::ceil((rest * 1.2 + 2.0 * dt) / dt));
          double worst = 0.0;
          for (int k = 1; k <= std::min(n, 4000); ++k) {
            sim.step(dt);
            const BodyState b = sim.state(0);
            const double above = dot(b.position, up) - (sz.R + sz.r);
            const double want = zeno::height(sz.h, g, e, sim.engine.time());
            worst = std::max(worst, std::fabs(above - want));
            ASSERT_TRUE(sim.engine.broken_guarantee().empty()) << sim.engine.broken_guarantee();
          }
          // The drop's 1e-9, and round-off of positions at the scene's size over the steps.
          EXPECT_LE(worst, 1e-9 * sz.h + 1e-12 * (sz.R + sz.r + sz.h) * 64.0) << "worst " << worst;
          const BodyState b = sim.state(0);
          if (sim.engine.time() > rest) EXPECT_LE(length(b.velocity), 1e-9 * g * tf);
          ++cases;
        }
      }
    }
  }
  EXPECT_EQ(cases, 96);
}

// The seventeenth hunt: the same drop onto a ball resting on a level floor (bottom mass 1e-3
// to 1e6 of the top's: under the simultaneous law the floor takes each impact whole, so the
// top ball rebounds at e as off a fixed circle). Every step's end at the closed form, and the
// bottom ball never moves. Not at e 0.999 with the 1e-3 bottom: there, before the tail,
// ~4000 bounces are met one by one, each a set of three contacts with a 1000:1 mass ratio,
// and they end 2.2e-9 m off (4e-8 of the drop; measured, not traced: README, Known limits).
TEST(CoreZenoCircle, ABallDroppedStraightOntoABallRestingOnAFloorMeetsTheClosedForm) {
  const double g = 9.8, R = 0.5, r = 0.1, h = 0.05;
  for (double e : {0.5, 0.99, 0.999}) {
    for (double falls : {0.3, 3.0, 30.0, 150.0}) {
      for (double mass : {1e-3, 1.0, 1e6}) {
        if (e == 0.999 && mass == 1e-3) continue;   // above
        SCOPED_TRACE("e " + std::to_string(e) + " falls " + std::to_string(falls) + " bottom mass " + std::to_string(mass));
        const double tf = std::sqrt(2.0 * h / g), dt = falls * tf, rest = tf * (1.0 + e) / (1.0 - e);
        Scene s = scene_of({circle("top", {0.0, 2.0 * R + r + h}, {}, r, 1.0, e), circle("bottom", {0.0, R}, {}, R, mass, e)},
                           {wall("floor", {-2.0, 0.0}, {2.0, 0.0}, e)}, {0.0, -g});
        Sim sim(s);
        const int n = std::min(4000, static_cast<int>(std::ceil((rest * 1.2 + 2.0 * dt) / dt)));
        double worst = 0.0, bottom = 0.0;
        for (int k = 1; k <= n; ++k) {
          sim.step(dt);
          ASSERT_TRUE(sim.engine.broken_guarantee().empty()) << sim.engine.broken_guarantee();
          const double above = sim.state(0).position.y - (2.0 * R + r);
          worst = std::max(worst, std::fabs(above - zeno::height(h, g, e, sim.engine.time())));
          bottom = std::max(bottom, length(sim.state(1).position - Vec2{0.0, R}));
        }
        EXPECT_LE(worst, 1e-9 * h + 64e-12 * (2.0 * R + r + h)) << "worst " << worst;
        EXPECT_LE(bottom, 1e-12);
      }
    }
  }
}

// Three high (a ball on a ball on a ball on a floor, the middle one held with the bottom
// one): at steps of 150 and 300 falls the whole sequence is one tail, at the closed form. At
// finer steps (15-30 falls) the first impacts are met one by one and the middle ball is let go
// by them, after which the collapse cut takes the rest: open (README, Known limits), so not
// asserted here.
TEST(CoreZenoCircle, ABallDroppedStraightOntoAStackOfTwoAtACoarseStepMeetsTheClosedForm) {
  const double g = 9.8, R = 0.5, r = 0.1, h = 0.05;
  for (double e : {0.99, 0.999}) {
    for (double falls : {150.0, 300.0}) {
      SCOPED_TRACE("e " + std::to_string(e) + " falls " + std::to_string(falls));
      const double tf = std::sqrt(2.0 * h / g), dt = falls * tf;
      Scene s = scene_of({circle("top", {0.0, 4.0 * R + r + h}, {}, r, 1.0, e), circle("middle", {0.0, 3.0 * R}, {}, R, 1.0, e),
                          circle("bottom", {0.0, R}, {}, R, 1.0, e)},
                         {wall("floor", {-2.0, 0.0}, {2.0, 0.0}, e)}, {0.0, -g});
      Sim sim(s);
      double worst = 0.0;
      for (int k = 1; k <= 8; ++k) {
        sim.step(dt);
        ASSERT_TRUE(sim.engine.broken_guarantee().empty()) << sim.engine.broken_guarantee();
        const double above = sim.state(0).position.y - (4.0 * R + r);
        worst = std::max(worst, std::fabs(above - zeno::height(h, g, e, sim.engine.time())));
      }
      EXPECT_LE(worst, 1e-9 * h + 64e-12 * (4.0 * R + r + h)) << "worst " << worst;
    }
  }
}

// The eighteenth hunt: a ball dropped straight onto a column of 2 to 8 resting balls on a
// floor. Under the simultaneous law the column is rigid against the floor, so the top ball
// bounces as on a floor whatever the column's masses: the closed form, shifted up by the
// column. Before, the column's top ball, held on the ball under it, met the impact pair by
// pair: at e 0.5 on three balls of 1 kg the drop rose 4 mm instead of 0.25 m (all 9.8 J
// gone), `ok`, the reference making the same mistake; a 1 kg ball on two 1 g balls stopped
// dead. Steps of 0.1 to 30 falls, e 0.5, 0.99 and 1, column masses 1e-3 to 1e3 kg, the field
// along -y and tilted 0.3 rad (the column and the floor built along it, their coordinates
// rounded: a first version met a tilted column as one only for its first 1-3 impacts, and
// an elastic one reached the event cap on the column's round-off velocities). A column of 8
// balls of 1 g under the 1 kg ball went to the granular mode in its Zeno tail (said in
// limits_hit: first order) and buckled, until the twentieth hunt's round (the exact solve's
// pivoted rows and NNLS passing over a dependent column): now in. Open (README, Known
// limits): an elastic column at 30 falls a step: core comes to rest where its reference bounces
// (`diverged`, a red). A tilted column at e 0.99 (two or three balls): from about 9.5 s,
// in its slow bounces, the top ball is knocked off the line and the column topples (`ok`,
// a wrong green left open; before the fix it was 0.58 m off from the first bounces).
// Steps a drop onto a column (body 0 dropped h onto bodies 1..n, resting at R + 2 R k along
// `up`): the drop's largest distance from the closed form (its height above `top` along up),
// the column's largest move, and the drop's largest offset from the column's axis; stops at a
// broken guarantee (`broken`).
struct ColumnDrop {
  double worst = 0.0, column = 0.0, side = 0.0;
  std::string broken;
};
ColumnDrop step_column_drop(Sim& sim, int steps, double dt, Vec2 up, double top, int n, double R, double h, double g,
                            double e) {
  ColumnDrop d;
  for (int k = 1; k <= steps && d.broken.empty(); ++k) {
    sim.step(dt);
    d.broken = sim.engine.broken_guarantee();
    const BodyState t = sim.state(0);
    d.worst = std::max(d.worst, std::fabs(dot(t.position, up) - top - zeno::bounce_height(h, g, e, sim.engine.time())));
    d.side = std::max(d.side, std::fabs(cross(up, t.position)));
    for (int c = 0; c < n; ++c) {
      const BodyState b = sim.state(static_cast<std::size_t>(c + 1));
      d.column = std::max(d.column, length(b.position - (R + 2.0 * R * c) * up));
    }
  }
  return d;
}

TEST(CoreZenoCircle, ABallDroppedStraightOntoAColumnBouncesAsOnAFloor) {
  const double g = 9.8, R = 0.5, r = 0.1, h = 1.0;
  int cases = 0;
  for (double tilt : {0.0, 0.3}) {
    const Vec2 up{-std::sin(tilt), std::cos(tilt)}, along{std::cos(tilt), std::sin(tilt)};
    for (int n : {2, 3, 5, 8}) {
      for (double e : {0.5, 0.99, 1.0}) {
        for (double falls : {0.1, 3.0, 30.0}) {
          for (double mass : {1e-3, 1.0, 1e3}) {
            if (e == 1.0 && falls == 30.0) continue;   // open, above
            if (tilt > 0.0 && e == 0.99) continue;   // open, above
            SCOPED_TRACE("tilt " + std::to_string(tilt) + " column of " + std::to_string(n) + " e " + std::to_string(e) +
                         " falls " + std::to_string(falls) + " column mass " + std::to_string(mass));
            const double tf = std::sqrt(2.0 * h / g), dt = falls * tf;
            const double rest = e < 1.0 ? tf * (1.0 + e) / (1.0 - e) : 6.0 * tf;
            const double top = 2.0 * R * n + r;   // the top ball's centre at contact, along up
            std::vector<BodyDef> bodies{circle("top", (top + h) * up, {}, r, 1.0, e)};
            for (int k = 0; k < n; ++k) bodies.push_back(circle("c" + std::to_string(k), (R + 2.0 * R * k) * up, {}, R, mass, e));
            Sim sim(scene_of(bodies, {wall("floor", -3.0 * along, 3.0 * along, e)}, -g * up));
            const int steps = std::min(600, static_cast<int>(std::ceil((rest * 1.2 + 2.0 * dt) / dt)));
            const ColumnDrop d = step_column_drop(sim, steps, dt, up, top, n, R, h, g, e);
            ASSERT_EQ(d.broken, "");
            EXPECT_LE(d.worst, 1e-9 * h + 64e-12 * (top + h)) << "worst " << d.worst;
            EXPECT_LE(d.column, 1e-12);
            EXPECT_TRUE(sim.engine.limits_hit().empty());
            ++cases;
          }
        }
      }
    }
  }
  EXPECT_EQ(cases, 156);
}

}  // namespace physval::test

namespace physval::test {

// The nineteenth and twentieth hunts: the same drop onto a column standing in a box exactly
// one ball wide, its walls touching every column ball. Frictionless or not, the walls take
// no impulse (the column does not move along them), so the closed form is the floor's and
// the scene's mirror symmetry keeps every body on x = 0 exactly. Before, (1) the exact
// impact solve's projection (Householder QR) was pivoted on a body's x row, so the walls'
// contacts in the set (impulse 0) gave the top ball -4e-16 m/s sideways; the top of a
// column is unstable (the offset grew about 13-fold a bounce) and a column of three 10 g
// balls at e 0.99 toppled at 7.4 s, `ok`, its reference toppling alike; and (2) with
// friction, the hold check's exact least squares gave up when a seventh cone edge entered
// a set of six rows (a 1 kg ball at rest on two 1 g balls: a hold core "could not show",
// `diverged`, a false red).
TEST(CoreZenoCircle, ABallDroppedOntoAColumnBetweenTouchingWallsBouncesAsOnAFloor) {
  const double g = 9.8, R = 0.5, r = 0.1, h = 1.0;
  int cases = 0;
  for (int n : {2, 3, 5}) {
    for (double e : {0.5, 0.9, 0.99}) {
      for (double mass : {1e-3, 1e-2, 1.0, 1e3}) {
        for (double mu : {0.0, 0.5}) {
          for (double falls : {0.1, 3.0}) {
            SCOPED_TRACE("column of " + std::to_string(n) + " e " + std::to_string(e) + " column mass " +
                         std::to_string(mass) + " mu " + std::to_string(mu) + " falls " + std::to_string(falls));
            const double tf = std::sqrt(2.0 * h / g), dt = falls * tf;
            const double rest = tf * (1.0 + e) / (1.0 - e);
            const double top = 2.0 * R * n + r;
            std::vector<BodyDef> bodies{circle("top", {0.0, top + h}, {}, r, 1.0, e)};
            for (int k = 0; k < n; ++k) bodies.push_back(circle("c" + std::to_string(k), {0.0, R + 2.0 * R * k}, {}, R, mass, e));
            for (BodyDef& b : bodies) b.friction = b.static_friction = mu;
            const double H = top + 2.0 * h;
            Sim sim(scene_of(bodies,
                             {wall("floor", {-R - 1.0, 0.0}, {R + 1.0, 0.0}, e, mu), wall("left", {-R, 0.0}, {-R, H}, e, mu),
                              wall("right", {R, 0.0}, {R, H}, e, mu)},
                             {0.0, -g}));
            const int steps = std::min(600, static_cast<int>(std::ceil((rest * 1.2 + 2.0 * dt) / dt)));
            const ColumnDrop d = step_column_drop(sim, steps, dt, {0.0, 1.0}, top, n, R, h, g, e);
            ASSERT_EQ(d.broken, "");
            EXPECT_LE(d.worst, 1e-9 * h + 64e-12 * (top + h)) << "worst " << d.worst;
            EXPECT_EQ(d.side, 0.0);   // a mirror-symmetric scene: exactly on its axis
            EXPECT_LE(d.column, 1e-12);
            ++cases;
          }
        }
      }
    }
  }
  EXPECT_EQ(cases, 144);
}

}  // namespace physval::test

namespace physval::test {

// The nineteenth hunt's tall columns: 12 to 30 balls under the drop, met as a column at
// their first 1-3 impacts only in the version it hunted (then pair by pair: rebounds at
// e^2 u, or a 1 g column stopping the drop dead, `ok`, up to 0.96 of the drop off); right
// since the column's line test is to 1e-6 rad (README, the nineteenth hunt). The closed form
// at every step's end, the column still. Its Zeno tail in closed form needs the column found
// firm down to its foot: that search stopped at 16 bodies, and on 20 and 30 balls at e 0.9,
// 3 falls a step, the pair's collapse ended the tail 0.45 s early (0.0027 m off, `ok`).
TEST(CoreZenoCircle, ABallDroppedOntoATallColumnBouncesAsOnAFloor) {
  const double g = 9.8, R = 0.5, r = 0.1, h = 1.0;
  int cases = 0;
  for (int n : {12, 20, 30}) {
    for (double e : {0.9, 0.99}) {
      for (double mass : {1e-3, 1.0}) {
        for (double falls : {0.1, 3.0}) {
          SCOPED_TRACE("column of " + std::to_string(n) + " e " + std::to_string(e) + " column mass " + std::to_string(mass) +
                       " falls " + std::to_string(falls));
          const double tf = std::sqrt(2.0 * h / g), dt = falls * tf;
          const double top = 2.0 * R * n + r;
          std::vector<BodyDef> bodies{circle("top", {0.0, top + h}, {}, r, 1.0, e)};
          for (int k = 0; k < n; ++k) bodies.push_back(circle("c" + std::to_string(k), {0.0, R + 2.0 * R * k}, {}, R, mass, e));
          Sim sim(scene_of(bodies, {wall("floor", {-3.0, 0.0}, {3.0, 0.0}, e)}, {0.0, -g}));
          const int steps = static_cast<int>(std::ceil(8.0 / dt));   // 8 s: 9 bounces at e 0.99
          const ColumnDrop d = step_column_drop(sim, steps, dt, {0.0, 1.0}, top, n, R, h, g, e);
          ASSERT_EQ(d.broken, "");
          EXPECT_LE(d.worst, 1e-9 * h + 64e-12 * (top + h)) << "worst " << d.worst;
          EXPECT_LE(d.column, 1e-12);
          EXPECT_TRUE(sim.engine.limits_hit().empty());
          ++cases;
        }
      }
    }
  }
  EXPECT_EQ(cases, 24);
}

}  // namespace physval::test

namespace physval::test {

// The twentieth hunt: a ball dropped on the top of a pyramid that cannot move under it (2
// balls under 1, or 3 under 2 under 1, in a box whose walls touch the bottom row; or 2 under 1
// in a V of two walls). Newton's law at every contact at once has one answer there: the
// striker rebounds at e u and nothing else moves (the hunt's own LCP of every contact says
// so). Before, a body resting on several bodies was a leaf of the set, the impulse went on
// pair by pair, and the striker lost most of its bounce (a 10 kg ball at e 0.5 stopped dead),
// judged `ok` against a reference that did the same, and the answer followed the numbering.
// Every step's end at the floor's closed form, the pyramid still, and the same run to the
// last bit with the bodies listed in reverse.
TEST(CoreZenoCircle, ABallDroppedOnABracedPyramidBouncesAsOnAFloor) {
  const double g = 9.8, R = 0.5, rs = 0.3, S3 = std::sqrt(3.0);
  const auto height = [&](double h, double e, double t) { return zeno::bounce_height(h, g, e, t); };
  int cases = 0;
  // kind 0: 2-1 in a box; 1: 3-2-1 in a box; 2, 3: 2-1 in a V of half-angle 30 and 60 degrees.
  for (int kind : {0, 1, 2, 3}) {
    for (double ms : {0.1, 1.0, 10.0}) {
      for (double e : {0.3, 0.9, 1.0}) {
        for (double mu : {0.0, 0.3}) {
          for (double h : {1.0, 0.2}) {
            SCOPED_TRACE("kind " + std::to_string(kind) + " striker " + std::to_string(ms) + " kg e " + std::to_string(e) +
                         " mu " + std::to_string(mu) + " h " + std::to_string(h));
            std::vector<BodyDef> bodies;
            std::vector<WallDef> walls;
            double top = 0.0;
            if (kind <= 1) {
              const double W = kind == 0 ? 2.0 * R : 3.0 * R;
              if (kind == 0) {
                bodies = {circle("bl", {-R, R}, {}, R, 1.0, e), circle("br", {R, R}, {}, R, 1.0, e),
                          circle("t", {0.0, R + S3 * R}, {}, R, 1.0, e)};
                top = R + S3 * R + R;
              } else {
                bodies = {circle("b1", {-2.0 * R, R}, {}, R, 1.0, e), circle("b2", {0.0, R}, {}, R, 1.0, e),
                          circle("b3", {2.0 * R, R}, {}, R, 1.0, e), circle("m1", {-R, R + S3 * R}, {}, R, 1.0, e),
                          circle("m2", {R, R + S3 * R}, {}, R, 1.0, e), circle("t", {0.0, R + 2.0 * S3 * R}, {}, R, 1.0, e)};
                top = R + 2.0 * S3 * R + R;
              }
              walls = {wall("floor", {-W - 1.0, 0.0}, {W + 1.0, 0.0}, e, mu), wall("wl", {-W, 8.0}, {-W, 0.0}, e, mu),
                       wall("wr", {W, 0.0}, {W, 8.0}, e, mu)};
            } else {
              const double a = (kind == 2 ? 30.0 : 60.0) * std::acos(-1.0) / 180.0;
              const double yb = R * (1.0 + std::cos(a)) / std::sin(a);
              bodies = {circle("bl", {-R, yb}, {}, R, 1.0, e), circle("br", {R, yb}, {}, R, 1.0, e),
                        circle("t", {0.0, yb + S3 * R}, {}, R, 1.0, e)};
              top = yb + S3 * R + R;
              const double L = 8.0;
              walls = {wall("wl", {-L * std::sin(a), L * std::cos(a)}, {0.0, 0.0}, e, mu),
                       wall("wr", {0.0, 0.0}, {L * std::sin(a), L * std::cos(a)}, e, mu)};
            }
            bodies.push_back(circle("s", {0.0, top + rs + h}, {}, rs, ms, e));
            for (BodyDef& b : bodies) b.friction = b.static_friction = mu;
            const double tf = std::sqrt(2.0 * h / g), dt = 1.0 / 60.0;
            const double dur = e < 1.0 ? std::min(3.0, tf * (1.0 + e) / (1.0 - e) * 1.1) : 4.0 * tf;
            const int steps = static_cast<int>(std::ceil(dur / dt));
            std::vector<BodyDef> reversed(bodies.rbegin(), bodies.rend());
            Sim sim(scene_of(bodies, walls, {0.0, -g}));
            Sim rev(scene_of(reversed, walls, {0.0, -g}));
            const std::size_t n = bodies.size();
            double worst = 0.0, still = 0.0, renumbered = 0.0;
            for (int k = 1; k <= steps; ++k) {
              sim.step(dt);
              rev.step(dt);
              ASSERT_TRUE(sim.engine.broken_guarantee().empty()) << sim.engine.broken_guarantee();
              const BodyState s = sim.state(n - 1);
              worst = std::max(worst, std::fabs(s.position.y - (top + rs) - height(h, e, sim.engine.time())));
              for (std::size_t q = 0; q < n; ++q) {
                const BodyState b = sim.state(q);
                if (q + 1 < n) still = std::max(still, length(b.position - bodies[q].position));
                renumbered = std::max(renumbered, length(b.position - rev.state(n - 1 - q).position));
              }
            }
            EXPECT_LE(worst, 1e-9 * h + 64e-12 * (top + rs + h)) << "worst " << worst;
            EXPECT_LE(still, 1e-12);
            EXPECT_LE(renumbered, 1e-12);
            ++cases;
          }
        }
      }
    }
  }
  EXPECT_EQ(cases, 144);
}

}  // namespace physval::test

#include <random>

namespace physval::test {

// The twentieth hunt: a striker into a touching row of mixed masses on a frictionless floor,
// e 0: all move on at the common velocity m0 u / sum m, whatever it is, slower than the rest
// speed or not (the floor takes no horizontal impulse). Before, the exact solve left the row
// at one velocity but for a few ulps, the striker "closed" on the ball ahead at 3e-17 m/s, the
// same set was met 64 times at one instant and then taken as a collapse that held the back of
// the row at rest: 1.85% of the momentum gone (one of the random rows below, kept first), and
// in the hunt a 1.17 g pellet at 90 m/s lost 99.9%. The hunt's reproducer first, then 40 random
// rows (3-8 balls and 1-3 touching strikers of 1e-3 to 1e3 kg), each run 2 s at dt 1/60.
TEST(CoreRow, APerfectlyInelasticRowOnAFrictionlessFloorKeepsItsMomentum) {
  struct Row {
    std::vector<double> m;
    int strikers;
    double u;
  };
  std::vector<Row> rows{{{0.26926782330794835, 5.877060886910641, 3.3076501486511445, 437.77868236274713, 43.390761613711035,
                          0.09533089927280076, 20.914342224871515},
                         1,
                         0.1249375624260917}};
  std::mt19937_64 rng(20);
  std::uniform_real_distribution<double> logm(-3.0, 3.0), logu(-3.0, 0.0);
  std::uniform_int_distribution<int> count(3, 8), strikers(1, 3);
  for (int r = 0; r < 40; ++r) {
    Row row;
    row.strikers = strikers(rng);
    const int n = count(rng) + row.strikers;
    for (int k = 0; k < n; ++k) row.m.push_back(std::pow(10.0, logm(rng)));
    row.u = std::pow(10.0, logu(rng));
    rows.push_back(row);
  }
  int cases = 0;
  for (const Row& row : rows) {
    SCOPED_TRACE("row " + std::to_string(cases));
    const double R = 0.5, gap = 0.3 * row.u;
    std::vector<BodyDef> bodies;
    double msum = 0.0, p = 0.0;
    for (std::size_t k = 0; k < row.m.size(); ++k) {
      const bool striker = static_cast<int>(k) < row.strikers;
      const double x = static_cast<double>(k) * 2.0 * R - (striker ? gap : 0.0);
      bodies.push_back(circle("b" + std::to_string(k), {x, R}, {striker ? row.u : 0.0, 0.0}, R, row.m[k], 0.0));
      msum += row.m[k];
      if (striker) p += row.m[k] * row.u;
    }
    Sim sim(scene_of(bodies, {wall("floor", {-60.0, 0.0}, {60.0, 0.0}, 0.0)}, {0.0, -9.8}));
    for (int k = 0; k < 120; ++k) sim.step(1.0 / 60.0);
    ASSERT_TRUE(sim.engine.broken_guarantee().empty()) << sim.engine.broken_guarantee();
    const double V = p / msum;
    for (std::size_t k = 0; k < row.m.size(); ++k) {
      const BodyState b = sim.state(k);
      EXPECT_NEAR(b.velocity.x, V, 1e-9 * row.u) << "body " << k;
      EXPECT_EQ(b.velocity.y, 0.0) << "body " << k;
    }
    ++cases;
  }
  EXPECT_EQ(cases, 41);
}

}  // namespace physval::test
