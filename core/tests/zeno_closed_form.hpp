// The closed form of a Zeno bounce, shared by core's tests (zeno_circle_test.cpp) and the
// hunts' tests through `physval run` (validation/tests/hunt16_test.cpp).
#pragma once

#include <algorithm>
#include <cmath>

namespace physval::zeno {

// Height above the contact of a ball released at rest h above it, under |g|, restitution e,
// at time t: free fall, then bounces k = 0, 1, ... leaving at t_f + D (1 - e^k) with speed
// v0 e^k (v0 = e g t_f, D = 2 v0 / (g (1 - e))), at rest from t_f + D.
inline double height(double h, double g, double e, double t) {
  const double tf = std::sqrt(2.0 * h / g);
  if (t <= tf) return h - 0.5 * g * t * t;
  const double v0 = e * g * tf, D = 2.0 * v0 / (g * (1.0 - e));
  const double u = t - tf;
  if (u >= D) return 0.0;
  int k = 0;
  while (D * (1.0 - std::pow(e, k + 1)) <= u) ++k;
  const double s = u - D * (1.0 - std::pow(e, k));
  const double vk = v0 * std::pow(e, k);
  return std::max(0.0, s * (vk - 0.5 * g * s));
}

// The same for any e in (0, 1], e = 1 being the same drop for ever (period 2 t_f).
inline double bounce_height(double h, double g, double e, double t) {
  if (e < 1.0) return height(h, g, e, t);
  const double tf = std::sqrt(2.0 * h / g);
  if (t <= tf) return h - 0.5 * g * t * t;
  const double u = std::fmod(t - tf, 2.0 * tf);
  return u * (g * tf - 0.5 * g * u);
}

}  // namespace physval::zeno
