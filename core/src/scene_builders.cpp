// Generated scenes (see scene_builders.hpp).
#include "physval/core/scene_builders.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>
#include <string>

namespace physval {

namespace {

constexpr double kGasRadius = 0.05;
constexpr double kGasPacking = 0.30;

double uniform01(std::mt19937_64& rng) { return static_cast<double>(rng() >> 11) * 0x1.0p-53; }

}  // namespace

double circle_gas_box_side(int n) {
  return std::sqrt(static_cast<double>(n) * std::numbers::pi * kGasRadius * kGasRadius / kGasPacking);
}

Scene make_circle_gas(int n, std::uint64_t seed) {
  Scene s;
  s.name = "circle_gas_" + std::to_string(n);
  s.description = "circle gas: radius 0.05, 30% packing, walled box, elastic, no gravity";
  s.dt = 1.0 / 60.0;
  s.duration = 10.0;
  const double side = circle_gas_box_side(n);
  const int per_row = static_cast<int>(std::ceil(std::sqrt(static_cast<double>(n))));
  const double spacing = side / per_row;
  const double jitter = 0.45 * (spacing - 2.0 * kGasRadius);   // keeps neighbours apart
  std::mt19937_64 rng(seed);
  s.bodies.reserve(static_cast<std::size_t>(n));
  for (int k = 0; k < n; ++k) {
    BodyDef b;
    b.name = std::to_string(k);
    b.name.insert(b.name.begin(), 'g');   // (not "g" + ...: a GCC 12 -Wrestrict false positive)
    b.radius = kGasRadius;
    b.mass = 1.0;
    b.restitution = 1.0;
    const int row = k / per_row, col = k % per_row;
    b.position = {(col + 0.5) * spacing + jitter * (2.0 * uniform01(rng) - 1.0),
                  (row + 0.5) * spacing + jitter * (2.0 * uniform01(rng) - 1.0)};
    const double angle = 2.0 * std::numbers::pi * uniform01(rng);
    const double speed = 2.0 * uniform01(rng);
    b.velocity = {speed * std::cos(angle), speed * std::sin(angle)};
    s.bodies.push_back(std::move(b));
  }
  const Vec2 c[4] = {{0.0, 0.0}, {side, 0.0}, {side, side}, {0.0, side}};
  const char* names[4] = {"bottom", "right", "top", "left"};
  for (int k = 0; k < 4; ++k) {
    WallDef w;
    w.name = names[k];
    w.from = c[k];
    w.to = c[(k + 1) % 4];
    w.material.restitution = 1.0;
    s.walls.push_back(w);
  }
  return s;
}

Scene make_circle_pile(int n, double restitution, double friction, std::uint64_t seed) {
  constexpr double r = 0.1, spacing = 0.25;
  Scene s;
  s.name = "circle_pile_" + std::to_string(n);
  s.description = "circle pile: radius 0.1, dropped into a closed box under gravity";
  s.dt = 1.0 / 60.0;
  s.duration = 10.0;
  s.world.gravity = {0.0, -9.8};
  const int cols = std::max(4, static_cast<int>(std::lround(std::sqrt(static_cast<double>(n)))));
  const int rows = (n + cols - 1) / cols;
  const double width = spacing * cols;
  const double height = 0.15 + spacing * rows + 0.5;
  const double jitter = 0.4 * (spacing - 2.0 * r);
  std::mt19937_64 rng(seed);
  for (int k = 0; k < n; ++k) {
    BodyDef b;
    b.name = std::to_string(k);
    b.name.insert(b.name.begin(), 'p');
    b.radius = r;
    b.mass = 1.0;
    b.restitution = restitution;
    b.friction = friction;
    b.static_friction = friction;
    const int row = k / cols, col = k % cols;
    b.position = {(col + 0.5) * spacing + jitter * (2.0 * uniform01(rng) - 1.0),
                  0.15 + (row + 0.5) * spacing + jitter * (2.0 * uniform01(rng) - 1.0)};
    b.velocity = {uniform01(rng) - 0.5, uniform01(rng) - 0.5};
    s.bodies.push_back(std::move(b));
  }
  const Vec2 c[4] = {{0.0, 0.0}, {width, 0.0}, {width, height}, {0.0, height}};
  const char* names[4] = {"floor", "right", "lid", "left"};
  for (int k = 0; k < 4; ++k) {
    WallDef w;
    w.name = names[k];
    w.from = c[k];
    w.to = c[(k + 1) % 4];
    w.material.restitution = restitution;
    w.material.friction = friction;
    w.material.static_friction = friction;
    s.walls.push_back(w);
  }
  return s;
}

}  // namespace physval
