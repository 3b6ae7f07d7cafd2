// Time of impact: the lecture's collision steps 1 and 2 (that a collision happened,
// and when), exact for core's trajectory model. Within a step every body follows a
// parabola p(s) = p + v s + 1/2 a s^2 (a constant over the step; a = 0 for the Euler
// integrators), so a gap between two objects is a polynomial in s of degree at most
// four, and the impact is its earliest root at which the gap is closing.
#pragma once

#include <limits>

#include "physval/core/vec2.hpp"

namespace physval::toi {

inline constexpr double kNever = std::numeric_limits<double>::infinity();

// c[0] + c[1] s + c[2] s^2 + c[3] s^3 + c[4] s^4.
struct Poly {
  double c[5] = {0.0, 0.0, 0.0, 0.0, 0.0};
  int degree = 0;   // highest index with a coefficient that may be non-zero
  double eval(double s) const;
  double slope(double s) const;   // first derivative
};

// Tolerances that decide "touching now": a gap g(0) <= touch is contact, and a slope
// within +-slope counts as zero (round-off of the last resolution).
struct Tolerance {
  double touch = 0.0;
  double slope = 0.0;
};

// The earliest s in [0, T] at which the gap g enters contact: either at s = 0 when
// the objects touch (g(0) <= touch) and are closing (g'(0) < -slope, or g' ~ 0 and
// g'' < 0: pressed together), or at a root where g falls from > 0 to <= 0. Roots at
// which g rises (objects separating after a resolution) are skipped. kNever if none.
double earliest_entry(const Poly& gap, double T, Tolerance tol);

// Two circles (or a circle and a point) whose centres differ by d(s) = dp + dv s +
// 1/2 da s^2 (second minus first), touching at |d| = R. Gap |d|^2 - R^2.
double circle_circle(Vec2 dp, Vec2 dv, Vec2 da, double R, double T, Tolerance tol);
Poly circle_circle_gap(Vec2 dp, Vec2 dv, Vec2 da, double R);

// A circle of radius r (0 for a point) on the path p + v s + 1/2 a s^2 against the
// segment [from, to], which it meets on either face or at an end cap. `press`: the
// acceleration of the forces on the body, which decides the side of a point exactly on
// the line (line_side); it differs from a when the integrator's path ignores the force
// within the step (explicit Euler) or a support constrains the path.
struct SegmentHit {
  double s = kNever;   // time of impact, kNever if none within [0, T]
  Vec2 normal;         // unit, from the segment towards the circle's centre at impact
  bool cap = false;    // hit an end point rather than a face
};
SegmentHit circle_segment(Vec2 p, Vec2 v, Vec2 a, double r, Vec2 from, Vec2 to, double T,
                          double length_scale, Vec2 press);
inline SegmentHit circle_segment(Vec2 p, Vec2 v, Vec2 a, double r, Vec2 from, Vec2 to, double T,
                                 double length_scale) {
  return circle_segment(p, v, a, r, from, to, T, length_scale, a);
}

// The side (+1 or -1 along the line's normal n) of a body whose centre is at signed
// distance D from the line, with normal velocity vn = v.n and acceleration an = a.n. Off
// the line, the sign of D. Exactly on it (a point placed there: an impact leaves a point a
// hair off its face), the side its acceleration presses it from (a point on a floor under
// gravity is above it, at rest, moving down or moving up: one spot, one side); with no
// normal acceleration, the side it moves from (a zero-thickness barrier is met, never
// crossed); with neither, +1. Every test of which face a body meets uses this rule.
double line_side(double D, double vn, double an);

// Tolerances for a contact between objects at coordinates of magnitude `scale` (m)
// moving at `speed` (m/s): a few ulps of round-off, in gap units (m for a face gap,
// m^2 for a squared-distance gap of contact distance R).
Tolerance linear_tolerance(double scale, double speed);
Tolerance squared_tolerance(double scale, double speed, double R);

}  // namespace physval::toi
