// Plain 2-D vector in double precision: the one math type physval shares.
#pragma once

#include <cmath>

namespace physval {

struct Vec2 {
  double x = 0.0;
  double y = 0.0;
};

inline constexpr Vec2 operator+(Vec2 a, Vec2 b) { return {a.x + b.x, a.y + b.y}; }
inline constexpr Vec2 operator-(Vec2 a, Vec2 b) { return {a.x - b.x, a.y - b.y}; }
inline constexpr Vec2 operator-(Vec2 a) { return {-a.x, -a.y}; }
inline constexpr Vec2 operator*(double s, Vec2 a) { return {s * a.x, s * a.y}; }
inline constexpr Vec2 operator*(Vec2 a, double s) { return {s * a.x, s * a.y}; }
inline constexpr Vec2 operator/(Vec2 a, double s) { return {a.x / s, a.y / s}; }
inline constexpr Vec2& operator+=(Vec2& a, Vec2 b) { a.x += b.x; a.y += b.y; return a; }
inline constexpr Vec2& operator-=(Vec2& a, Vec2 b) { a.x -= b.x; a.y -= b.y; return a; }
inline constexpr Vec2& operator*=(Vec2& a, double s) { a.x *= s; a.y *= s; return a; }
inline constexpr bool operator==(Vec2 a, Vec2 b) { return a.x == b.x && a.y == b.y; }

inline constexpr double dot(Vec2 a, Vec2 b) { return a.x * b.x + a.y * b.y; }
// z component of the 3-D cross product: a.x b.y - a.y b.x.
inline constexpr double cross(Vec2 a, Vec2 b) { return a.x * b.y - a.y * b.x; }
inline constexpr double length_squared(Vec2 a) { return dot(a, a); }
inline double length(Vec2 a) { return std::sqrt(dot(a, a)); }
// Left-hand perpendicular (rotated +90 degrees).
inline constexpr Vec2 perp(Vec2 a) { return {-a.y, a.x}; }
inline Vec2 normalized(Vec2 a) {
  const double l = length(a);
  return l > 0.0 ? a / l : Vec2{};
}
inline bool is_finite(Vec2 a) { return std::isfinite(a.x) && std::isfinite(a.y); }

}  // namespace physval
