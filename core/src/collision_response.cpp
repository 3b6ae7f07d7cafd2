// The lecture's collision steps 4 and 5: along the normal, the relative velocity is
// reversed and scaled by the restitution e (elastic at 1); across it, nothing changes
// unless the pair has friction, and then a Coulomb impulse at most mu times the normal
// impulse, which can stop the sliding (static, mu_s) but never reverse it. No spin
// (step 6). A static object has infinite mass, so against it the velocity reflects.
//
// The impulses are equal and opposite, J/m1 and J/m2, so momentum is conserved to
// round-off even at a mass ratio of 10^6 (the lecture's warning about division).
// For e = 1 and a head-on impact this is v1' = (2 m2 v2 + v1 (m1 - m2)) / (m1 + m2),
// v2' = (2 m1 v1 + v2 (m2 - m1)) / (m1 + m2).
#include <algorithm>
#include <cmath>

#include "world.hpp"

namespace physval::core_detail {

namespace {

// Coulomb friction as a change of relative tangential velocity: dvt = the whole
// tangential velocity if mu_k times the normal change stops it (stick), else mu_k times it.
double friction_change(double vt, double dvn, const PairMaterial& m) {
  if (vt <= 0.0 || dvn <= 0.0) return 0.0;
  if (m.friction <= 0.0 && m.static_friction <= 0.0) return 0.0;
  // A sliding contact slides through the impact: only kinetic friction acts while it slides, and
  // the contact sticks (static friction then holds it) only where the kinetic impulse stops it
  // within the impact. Sticking whenever vt <= mu_s dvn stopped contacts that slide through
  // (mu_s > mu_k: the tenth hunt's impactstick family).
  return std::min(m.friction * dvn, vt);
}

}  // namespace

ImpactResult resolve_pair(World& w, std::uint32_t i, std::uint32_t j, Vec2 n, const PairMaterial& m,
                          double min_separation_speed) {
  ImpactResult r;
  const double inv_i = w.inv_mass[i];
  const double inv_j = w.inv_mass[j];
  const double inv = inv_i + inv_j;
  if (inv == 0.0) return r;
  const Vec2 vrel = w.vel[j] - w.vel[i];
  const double vn = dot(vrel, n);
  r.closing_speed = std::max(0.0, -vn);
  const double target = std::max(-m.restitution * vn, min_separation_speed);
  if (target <= vn) return r;   // already separating at least that fast
  const double dvn = target - vn;   // change of relative normal velocity
  const double J = dvn / inv;
  r.normal_impulse = J;
  w.vel[i] -= (J * inv_i) * n;
  w.vel[j] += (J * inv_j) * n;
  const Vec2 vt_vec = vrel - vn * n;
  const double vt = length(vt_vec);
  const double dvt = friction_change(vt, dvn, m);
  if (dvt > 0.0) {
    const Vec2 t = vt_vec / vt;
    const double Jt = dvt / inv;
    w.vel[i] += (Jt * inv_i) * t;
    w.vel[j] -= (Jt * inv_j) * t;
  }
  return r;
}

ImpactResult resolve_static(World& w, std::uint32_t i, Vec2 n, const PairMaterial& m, double min_separation_speed) {
  ImpactResult r;
  if (w.inv_mass[i] == 0.0) return r;
  const Vec2 v = w.vel[i];
  const double vn = dot(v, n);   // n points from the static object to the body
  r.closing_speed = std::max(0.0, -vn);
  const double target = std::max(-m.restitution * vn, min_separation_speed);
  if (target <= vn) return r;
  const double dvn = target - vn;
  r.normal_impulse = dvn / w.inv_mass[i];
  const Vec2 vt_vec = v - vn * n;
  const double vt = length(vt_vec);
  Vec2 out = vt_vec + target * n;
  const double dvt = friction_change(vt, dvn, m);
  if (dvt > 0.0) out -= (dvt / vt) * vt_vec;
  w.vel[i] = out;
  return r;
}

}  // namespace physval::core_detail
