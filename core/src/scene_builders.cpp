// Generated scenes (see scene_builders.hpp).
#include "physval/core/scene_builders.hpp"

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

}  // namespace physval
