// The force models of the lecture, as small inline functions. core/ uses them in its
// step, and the adapters apply the very same functions as external forces to Box2D
// and Bullet bodies, so a difference between engines is never a difference in how a
// force was written.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <span>

#include "physval/engine/scene.hpp"
#include "physval/engine/vec2.hpp"

namespace physval {

// Drag towards the wind: F = -k1 (v - w) - k2 |v - w| (v - w), in newtons.
inline Vec2 drag_force(double k_linear, double k_quadratic, Vec2 velocity, Vec2 wind) {
  const Vec2 rel = velocity - wind;
  const double speed = length(rel);
  return -(k_linear + k_quadratic * speed) * rel;
}

// Index of the interval [xs[i], xs[i+1]] holding x, and the fraction within it;
// clamped at the ends (t = 0 or 1). xs must be strictly increasing, size >= 1.
struct TableCoord {
  std::size_t i = 0;
  double t = 0.0;
};
inline TableCoord table_coord(std::span<const double> xs, double x) {
  if (xs.size() < 2 || x <= xs.front()) return {0, 0.0};
  if (x >= xs.back()) return {xs.size() - 2, 1.0};
  const auto it = std::upper_bound(xs.begin(), xs.end(), x);
  const std::size_t i = static_cast<std::size_t>(it - xs.begin()) - 1;
  return {i, (x - xs[i]) / (xs[i + 1] - xs[i])};
}

// The thrust table's acceleration, m/s^2, before the throttle: piecewise linear in
// speed (and in gear when the table has gear rows), clamped at the table's edges.
inline double thrust_table_value(const ThrustDef& t, double speed) {
  auto row_value = [&](std::size_t row) {
    const std::vector<double>& r = t.accel[row];
    if (r.size() == 1) return r[0];
    const TableCoord c = table_coord(t.speeds, speed);
    return r[c.i] + c.t * (r[c.i + 1] - r[c.i]);
  };
  if (t.gears.size() < 2) return row_value(0);
  const TableCoord g = table_coord(t.gears, t.gear);
  const double lo = row_value(g.i);
  const double hi = row_value(g.i + 1);
  return lo + g.t * (hi - lo);
}

// Thrust force in newtons along the heading `angle`: m * table(speed, gear) * throttle.
inline Vec2 thrust_force(const ThrustDef& t, double mass, Vec2 velocity, double angle) {
  if (!t.enabled()) return {};
  const double a = thrust_table_value(t, length(velocity)) * t.throttle;
  return {mass * a * std::cos(angle), mass * a * std::sin(angle)};
}

// Every force on one free body that does not come from another body or a contact:
// the uniform field, drag and wind, thrust. Newtonian gravity is pairwise (below).
inline Vec2 body_force(const BodyDef& b, const WorldDef& w, Vec2 velocity, double angle) {
  Vec2 f = b.mass * w.gravity;
  if (b.drag_linear != 0.0 || b.drag_quadratic != 0.0) {
    f += drag_force(b.drag_linear, b.drag_quadratic, velocity, w.wind);
  }
  f += thrust_force(b.thrust, b.mass, velocity, angle);
  return f;
}

// Newtonian attraction on body i from body j: G mi mj (pj - pi) / (D^2 + eps^2)^(3/2).
// Equal and opposite: the force on j is the negative.
inline Vec2 newtonian_force(double G, double softening, double mi, double mj, Vec2 pi, Vec2 pj) {
  const Vec2 d = pj - pi;
  const double r2 = length_squared(d) + softening * softening;
  if (r2 == 0.0) return {};
  const double inv_r = 1.0 / std::sqrt(r2);
  return (G * mi * mj * inv_r * inv_r * inv_r) * d;
}

// Adds the pairwise Newtonian forces between all bodies to `forces` (O(N^2), exact).
// Static bodies attract but take no force (pass is_static[i] = true).
inline void add_newtonian_forces(double G, double softening, std::span<const Vec2> positions,
                                 std::span<const double> masses, std::span<Vec2> forces) {
  const std::size_t n = positions.size();
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t j = i + 1; j < n; ++j) {
      const Vec2 f = newtonian_force(G, softening, masses[i], masses[j], positions[i], positions[j]);
      forces[i] += f;
      forces[j] -= f;
    }
  }
}

// Potential energy of the pairwise Newtonian field: -G mi mj / sqrt(D^2 + eps^2).
inline double newtonian_potential(double G, double softening, double mi, double mj, Vec2 pi, Vec2 pj) {
  const double r = std::sqrt(length_squared(pj - pi) + softening * softening);
  return r > 0.0 ? -G * mi * mj / r : 0.0;
}

// The lecture's centre of mass of a polygon with a mass at each vertex:
// xc = sum(xi mi) / sum(mi), yc = sum(yi mi) / sum(mi).
inline Vec2 centre_of_mass(std::span<const Vec2> vertices, std::span<const double> masses) {
  Vec2 acc;
  double m = 0.0;
  for (std::size_t i = 0; i < vertices.size(); ++i) {
    acc += masses[i] * vertices[i];
    m += masses[i];
  }
  return m > 0.0 ? acc / m : Vec2{};
}

}  // namespace physval
