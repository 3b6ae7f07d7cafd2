#include "containment.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <numeric>
#include <utility>
#include <vector>

namespace physval {

namespace {

bool walls_closed(const Scene& scene) {
  if (scene.walls.size() < 3) return false;
  std::vector<Vec2> ends;
  for (const WallDef& w : scene.walls) {
    ends.push_back(w.from);
    ends.push_back(w.to);
  }
  for (const Vec2& p : ends) {
    int meet = 0;
    for (const Vec2& q : ends) meet += length(p - q) <= 1e-9 ? 1 : 0;
    if (meet % 2 != 0) return false;
  }
  return true;
}

// Even-odd rule over the wall segments.
bool inside(const Scene& scene, Vec2 p) {
  bool in = false;
  for (const WallDef& w : scene.walls) {
    const Vec2 a = w.from, b = w.to;
    if ((a.y > p.y) != (b.y > p.y)) {
      const double x = a.x + (p.y - a.y) / (b.y - a.y) * (b.x - a.x);
      if (x > p.x) in = !in;
    }
  }
  return in;
}

double segment_distance(Vec2 p, Vec2 a, Vec2 b) {
  const Vec2 ab = b - a;
  const double len2 = dot(ab, ab);
  const double t = len2 > 0.0 ? std::clamp(dot(p - a, ab) / len2, 0.0, 1.0) : 0.0;
  return length(p - (a + ab * t));
}

}  // namespace

Containment measure_containment(const Scene& scene, const Series& series) {
  Containment c;
  const std::size_t nb = scene.bodies.size();
  const bool closed = walls_closed(scene);
  std::vector<char> was_inside(nb, 0), escaped(nb, 0);
  if (closed) {
    for (std::size_t i = 0; i < nb; ++i) was_inside[i] = inside(scene, scene.bodies[i].position) ? 1 : 0;
    c.escaped_bodies = 0;
  }
  std::vector<std::size_t> order;
  for (std::size_t k = 0; k < series.states.size(); ++k) {
    const SampleRow& s = series.states[k];
    const std::size_t n = std::min(s.size(), nb);
    // Pairs, swept over x.
    order.resize(n);
    std::iota(order.begin(), order.end(), std::size_t{0});
    auto lo = [&](std::size_t i) { return s[i].position.x - scene.bodies[i].radius; };
    std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return lo(a) < lo(b); });
    for (std::size_t p = 0; p < n; ++p) {
      const std::size_t i = order[p];
      if (!s[i].alive) continue;
      const double hi = s[i].position.x + scene.bodies[i].radius;
      for (std::size_t q = p + 1; q < n && lo(order[q]) <= hi; ++q) {
        const std::size_t j = order[q];
        if (!s[j].alive) continue;
        if (!response_between(scene, scene.bodies[i].group, scene.bodies[j].group).collide) continue;
        const double depth = scene.bodies[i].radius + scene.bodies[j].radius - length(s[i].position - s[j].position);
        c.max_penetration = std::max(c.max_penetration, depth);
      }
      bool walls_hold = true;   // a body its walls let through (collision matrix) cannot escape
      for (const WallDef& w : scene.walls) {
        if (!response_between(scene, scene.bodies[i].group, w.material.group).collide) {
          walls_hold = false;
          continue;
        }
        const double depth = scene.bodies[i].radius - segment_distance(s[i].position, w.from, w.to);
        c.max_penetration = std::max(c.max_penetration, depth);
      }
      if (closed && walls_hold && was_inside[i] && !escaped[i] && !inside(scene, s[i].position)) {
        escaped[i] = 1;
        ++*c.escaped_bodies;
        if (!c.first_escape_time && k < series.time.size()) c.first_escape_time = series.time[k];
      }
    }
  }
  return c;
}

}  // namespace physval
