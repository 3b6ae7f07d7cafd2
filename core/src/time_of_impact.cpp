// Exact times of impact: earliest closing root of a gap polynomial of degree <= 4.
//
// The gap is split at the roots of its derivative into monotone pieces; the first
// piece on which it falls from > 0 to <= 0 holds the impact. Degree <= 2 (every gap of
// bodies with equal accelerations, and every face gap) is solved in closed form with
// the cancellation-free quadratic formula; higher degrees by safeguarded Newton.
#include "physval/core/time_of_impact.hpp"

#include <algorithm>
#include <cmath>

namespace physval::toi {

namespace {

constexpr double kEps = 2.220446049250313e-16;

int effective_degree(const Poly& p) {
  int d = p.degree;
  while (d > 0 && p.c[d] == 0.0) --d;
  return d;
}

Poly derivative(const Poly& p) {
  Poly d;
  d.degree = std::max(p.degree - 1, 0);
  for (int k = 1; k <= p.degree; ++k) d.c[k - 1] = k * p.c[k];
  return d;
}

// Real roots of c2 s^2 + c1 s + c0, ascending; returns how many (0, 1 or 2).
int quadratic_roots(double c0, double c1, double c2, double out[2]) {
  if (c2 == 0.0) {
    if (c1 == 0.0) return 0;
    out[0] = -c0 / c1;
    return 1;
  }
  const double disc = c1 * c1 - 4.0 * c2 * c0;
  if (disc < 0.0) return 0;
  const double q = -0.5 * (c1 + std::copysign(std::sqrt(disc), c1));
  if (q == 0.0) {   // c1 == 0 and c0 == 0: a double root at 0
    out[0] = 0.0;
    out[1] = 0.0;
    return 2;
  }
  const double r1 = q / c2;
  const double r2 = c0 / q;
  out[0] = std::min(r1, r2);
  out[1] = std::max(r1, r2);
  return 2;
}

// The root of p in [l, r], where p is monotone, p(l) > 0 >= p(r). Returns a point at
// which p <= 0 (contact reached), within a few ulps of the root.
double bracketed_root(const Poly& p, double l, double r, double fl, double fr) {
  double a = l, b = r;
  double fa = fl, fb = fr;
  double s = (fa * b - fb * a) / (fa - fb);   // secant start
  if (!(s > a && s < b)) s = 0.5 * (a + b);
  for (int it = 0; it < 200; ++it) {
    const double fs = p.eval(s);
    if (fs > 0.0) {
      a = s;
      fa = fs;
    } else {
      b = s;
      fb = fs;
    }
    if (b - a <= 4.0 * kEps * std::max(std::fabs(a), std::fabs(b)) || fb == 0.0) break;
    const double d = p.slope(s);
    double next = d != 0.0 ? s - fs / d : 0.5 * (a + b);
    // Fall back to bisection when Newton leaves the bracket or crawls.
    if (!(next > a && next < b) || std::fabs(next - s) > 0.5 * (b - a)) next = 0.5 * (a + b);
    if (next == s) next = 0.5 * (a + b);
    s = next;
  }
  return b;
}

// Roots of p in the open interval (0, T), ascending; returns how many.
int roots_in(const Poly& p, double T, double out[4]) {
  const int deg = effective_degree(p);
  int n = 0;
  if (deg == 0) return 0;
  if (deg <= 2) {
    double r[2];
    const int k = quadratic_roots(p.c[0], p.c[1], deg == 2 ? p.c[2] : 0.0, r);
    for (int i = 0; i < k; ++i) {
      if (r[i] > 0.0 && r[i] < T && (n == 0 || r[i] != out[n - 1])) out[n++] = r[i];
    }
    return n;
  }
  double breaks[4];
  const int nb = roots_in(derivative(p), T, breaks);
  double lo = 0.0;
  double flo = p.c[0];
  for (int i = 0; i <= nb; ++i) {
    const double hi = i < nb ? breaks[i] : T;
    const double fhi = p.eval(hi);
    if (flo == 0.0 && lo > 0.0) {
      if (n == 0 || out[n - 1] != lo) out[n++] = lo;
    } else if ((flo > 0.0 && fhi < 0.0) || (flo < 0.0 && fhi > 0.0)) {
      // Orient so that the bracket solver sees a positive left end.
      Poly q = p;
      if (flo < 0.0) {
        for (double& c : q.c) c = -c;
      }
      out[n++] = bracketed_root(q, lo, hi, std::fabs(flo), -std::fabs(fhi));
    }
    lo = hi;
    flo = fhi;
  }
  return n;
}

// Earliest closing root; `allow_now` enables the touching-at-0 rule.
double entry(const Poly& g, double T, Tolerance tol, bool allow_now) {
  if (!(T >= 0.0)) return kNever;
  const double g0 = g.c[0];
  if (allow_now && g0 <= tol.touch) {
    const double g1 = g.c[1];
    if (g1 < -tol.slope) return 0.0;
    if (g1 <= tol.slope && g.c[2] < 0.0) return 0.0;   // pressed together
  }
  const int deg = effective_degree(g);
  if (deg == 0) return kNever;
  double breaks[4];
  const int nb = roots_in(derivative(g), T, breaks);
  double lo = 0.0;
  double flo = g0;
  for (int i = 0; i <= nb; ++i) {
    const double hi = i < nb ? breaks[i] : T;
    const double fhi = g.eval(hi);
    // Touching at 0 but not closing (just resolved): a dip within the touch tolerance
    // right after 0 is round-off, not a new impact.
    const double entry_level = (allow_now && i == 0) ? std::max(tol.touch, 0.0) : 0.0;
    // Touching at 0 and parting too little to leave the touch tolerance before turning
    // back: the pair closes again from the turn. (Without this, a pair that starts a
    // round-off overlap apart and parts slowly while pressed together is never found
    // again, and sinks into each other.)
    if (allow_now && i == 0 && g0 <= tol.touch && i < nb && fhi > flo && fhi <= tol.touch) return hi;
    if (flo > entry_level && fhi <= 0.0) {
      if (deg <= 2) {
        double r[2];
        const int k = quadratic_roots(g.c[0], g.c[1], deg == 2 ? g.c[2] : 0.0, r);
        // The falling root: the smaller for an upward parabola, the larger otherwise.
        double s = hi;
        if (k == 1) s = r[0];
        if (k == 2) s = g.c[2] > 0.0 ? r[0] : r[1];
        return std::clamp(s, lo, hi);
      }
      return bracketed_root(g, lo, hi, flo, fhi);
    }
    lo = hi;
    flo = fhi;
  }
  return kNever;
}

}  // namespace

double Poly::eval(double s) const {
  double v = c[degree];
  for (int k = degree - 1; k >= 0; --k) v = v * s + c[k];
  return v;
}

double Poly::slope(double s) const {
  if (degree == 0) return 0.0;
  double v = degree * c[degree];
  for (int k = degree - 1; k >= 1; --k) v = v * s + k * c[k];
  return v;
}

double line_side(double D, double vn, double an) {
  if (D != 0.0) return D > 0.0 ? 1.0 : -1.0;
  if (an != 0.0) return an < 0.0 ? 1.0 : -1.0;
  return vn > 0.0 ? -1.0 : 1.0;
}

double earliest_entry(const Poly& gap, double T, Tolerance tol) { return entry(gap, T, tol, true); }

Poly circle_circle_gap(Vec2 dp, Vec2 dv, Vec2 da, double R) {
  Poly g;
  g.c[0] = dot(dp, dp) - R * R;
  g.c[1] = 2.0 * dot(dp, dv);
  g.c[2] = dot(dv, dv) + dot(dp, da);
  g.c[3] = dot(dv, da);
  g.c[4] = 0.25 * dot(da, da);
  g.degree = (da.x == 0.0 && da.y == 0.0) ? 2 : 4;
  return g;
}

double circle_circle(Vec2 dp, Vec2 dv, Vec2 da, double R, double T, Tolerance tol) {
  const bool no_accel = da.x == 0.0 && da.y == 0.0;
  if (no_accel) {
    // Fast rejections for the common case: separating, or never close enough.
    const double b = dot(dp, dv);
    const double c = dot(dp, dp) - R * R;
    if (b >= 0.0 && c > tol.touch) return kNever;
    const double a = dot(dv, dv);
    if (c > tol.touch && b * b < a * c) return kNever;
  }
  return entry(circle_circle_gap(dp, dv, da, R), T, tol, true);
}

Tolerance linear_tolerance(double scale, double speed) {
  return {64.0 * kEps * scale, 64.0 * kEps * speed + 1e-300};
}

Tolerance squared_tolerance(double scale, double speed, double R) {
  return {2.0 * R * 64.0 * kEps * scale + 64.0 * kEps * R * R, 2.0 * R * (64.0 * kEps * speed) + 1e-300};
}

SegmentHit circle_segment(Vec2 p, Vec2 v, Vec2 a, double r, Vec2 from, Vec2 to, double T,
                          double length_scale, Vec2 press) {
  SegmentHit hit;
  const Vec2 e = to - from;
  const double L = length(e);
  if (L == 0.0) return hit;
  const Vec2 dir = e / L;
  const Vec2 n = perp(dir);
  const double speed = length(v) + length(a) * T;
  const Tolerance lin = linear_tolerance(length_scale, speed);

  // Faces: the gap to the line on the side the centre is on, and to the far side
  // (reached only by passing the segment's end first). A point exactly on the line is
  // on the side line_side gives: the one its force presses it from. (It was the
  // side it moves into: a point placed on a floor under gravity was held there at rest
  // but fell through it moving down, the same spot read as two sides.)
  const double D0 = dot(n, p - from);
  // Within the round-off of evaluating D0 a point is on the line, and line_side decides
  // (the side its force presses it from, else the side it moves from). By the sign of D0
  // a point that met a box's wall at its corner, 4e-16 m past the other wall's line, was
  // outside that wall and left the box through it.
  const double vn = dot(n, v);
  // The band: the coordinates' ulps, and the speed times the ulps of the step's clock (a
  // point at 5000 m/s met a wall 2.9e-15 m past a 0.3 m box's corner). A point kept on its
  // side after an impact is put further than this (exact_collisions.cpp, the hair).
  const double D_roundoff = 8.0 * kEps * (std::max(std::fabs(p.x), std::fabs(p.y)) +
                                          std::max(std::fabs(from.x), std::fabs(from.y)) + speed * T);
  const double side = line_side(std::fabs(D0) <= D_roundoff ? 0.0 : D0, vn, dot(n, press));
  for (int k = 0; k < 2; ++k) {
    const double sg = k == 0 ? side : -side;
    Poly g;
    g.c[0] = sg * D0 - r;
    g.c[1] = sg * dot(n, v);
    g.c[2] = 0.5 * sg * dot(n, a);
    g.degree = 2;
    const double s = entry(g, T, lin, k == 0);
    if (s == kNever || s >= hit.s) continue;
    const Vec2 ps = p + s * v + (0.5 * s * s) * a;
    const double u = dot(dir, ps - from);
    // At an end of the segment and moving past it, the face is left at that instant: the
    // end point (below, for a circle) decides. (A body sliding off a table's edge was
    // released there, met the face at once as "pressed" again, settled and was released,
    // for ever.)
    // Only a body touching the face now without closing on it (s = 0, g' ~ 0: pressed or
    // sliding along it) is let go there; one that strikes the face at its end point (a
    // point into a box's corner) meets it.
    const double ut = dot(dir, v + s * a);
    const double end_tol = lin.touch;
    const bool leaving_end = s == 0.0 && std::fabs(g.c[1]) <= lin.slope &&
                             ((u >= L - end_tol && ut > 0.0) || (u <= end_tol && ut < 0.0));
    // The span is closed to the coordinates' round-off too: a point sliding off one
    // segment of a floor onto the next (a junction) is released at the first one's end,
    // computed along it, a hair (1e-16 m) before the next one's start; read strictly, that
    // face was never met and the point fell through the floor at the junction (a circle
    // meets the end point instead; a point has no cap).
    if (u >= -end_tol && u <= L + end_tol && !leaving_end) {
      hit.s = s;
      hit.normal = sg * n;
      hit.cap = false;
    }
  }
  // End caps: a circle (not a point) can meet an end point outside the faces' span.
  if (r > 0.0) {
    // Whether the body closes on an end point now (g' < 0 at 0) is read from dp . dv, and
    // dp = p - q carries the coordinates' round-off (64 eps x the length scale), not only
    // the radius': a body leaving a face over its end is at the end point with dp along
    // the face's normal, dp . dv = 0, but p and the leaving time come from the position
    // along the whole segment, and dp . dv read a closing 1e-14 there (a ball sliding off
    // a table at 5 m/s got a micro-bounce off the edge where it must fly off).
    Tolerance sq = squared_tolerance(length_scale, speed, r);
    sq.slope = 2.0 * (r + length_scale) * (64.0 * kEps * speed) + 1e-300;
    for (int k = 0; k < 2; ++k) {
      const Vec2 q = k == 0 ? from : to;
      const double s = circle_circle(p - q, v, a, r, T, sq);
      if (s == kNever || s >= hit.s) continue;
      const Vec2 ps = p + s * v + (0.5 * s * s) * a;
      const double u = dot(dir, ps - from);
      if ((k == 0 && u <= 0.0) || (k == 1 && u >= L)) {
        hit.s = s;
        const Vec2 d = ps - q;
        hit.normal = length_squared(d) > 0.0 ? normalized(d) : (k == 0 ? -dir : dir);
        hit.cap = true;
      }
    }
  }
  return hit;
}

}  // namespace physval::toi
