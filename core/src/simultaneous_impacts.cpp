// Simultaneous impacts: Newton's restitution law at every touching contact at once.
//
// When an impact is found at time t, the bodies touching its pair at t (gap within
// round-off, closing or at rest) and those touching them in turn form the touching
// set. On it core solves a small linear complementarity problem for the normal
// impulses p_k:
//   p_k >= 0,   w_k+ >= target_k = max(-e_k w_k-, 0),   p_k (w_k+ - target_k) = 0,
// with w_k the relative normal velocity of contact k and w+ = w- + A p, A the
// contacts' Delassus matrix (J M^-1 J^T). The problem has a unique solution when the
// contacts are independent (A positive definite): a ball on two balls, a touching
// row. It is solved by projected Gauss-Seidel iterated to round-off, so the answer
// does not depend on the order of the contacts (that is, on the body numbering)
// beyond round-off. For e = 1 the law conserves energy: the work of impulse k is
// p_k (w_k- + w_k+) / 2, and either p_k = 0 or w_k+ = -w_k-.
//
// "At the same time" is geometric: a contact is in the set when its gap is within
// kGapUlps ulps of the scene's coordinates (the round-off of the root of a gap
// polynomial and of a few path advances), i.e. when its own impact, if any, is due
// within round-off of t. Friction, supported bodies and collision-matrix rules are
// left to the pairwise path: a set that meets any of them (or a scene with a collision
// matrix) is resolved pair by pair.
#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "world.hpp"

namespace physval::core_detail {

namespace {

constexpr double kEps = std::numeric_limits<double>::epsilon();
constexpr double kGapUlps = 1024.0;
constexpr std::size_t kMaxContacts = 256;

double inf_norm(Vec2 v) { return std::max(std::fabs(v.x), std::fabs(v.y)); }

struct Contact {
  std::uint32_t a = 0, b = 0;   // a < b; n points from a to b
  Vec2 n;
  double target = 0.0;
  double p = 0.0;
  double vscale = 0.0;   // |v_a| + |v_b| before
};

// Whether bodies i and j touch at t and are closing or at rest; fills the contact.
bool touching(const World& w, std::uint32_t i, std::uint32_t j, double t, Contact& c) {
  if (i > j) std::swap(i, j);
  const Vec2 pi = w.pos_at(i, t), pj = w.pos_at(j, t);
  const Vec2 d = pj - pi;
  const double R = w.radius[i] + w.radius[j];
  const double dl = length(d);
  if (!(dl > 0.0)) return false;
  const double scale = inf_norm(pi) + inf_norm(pj) + R;
  if (dl - R > kGapUlps * kEps * scale) return false;
  const Vec2 n = d / dl;
  const Vec2 vi = w.vel_at(i, t), vj = w.vel_at(j, t);
  const double wn = dot(vj - vi, n);
  const double vscale = length(vi) + length(vj);
  if (wn > kGapUlps * kEps * vscale) return false;   // separating: no contact
  c.a = i;
  c.b = j;
  c.n = n;
  c.vscale = vscale;
  return true;
}

bool eligible_body(const World& w, std::uint32_t i) {
  if (!w.alive(i)) return false;
  if (w.flags[i] & (kParticle | kPoint)) return false;
  if (w.supported(i)) return false;
  return true;
}

}  // namespace

bool resolve_simultaneous(World& w, std::uint32_t i0, std::uint32_t j0, double t,
                          std::vector<std::uint32_t>& bodies, std::vector<BodyPair>& impacted) {
  if (w.impact_law != ImpactLaw::Simultaneous || w.any_rules) return false;
  if (!eligible_body(w, i0) || !eligible_body(w, j0)) return false;
  // Scratch kept between calls: an isolated impact (the common case) allocates nothing.
  thread_local std::vector<Contact> contacts;
  thread_local std::vector<std::uint32_t> found;
  thread_local std::vector<double> A, w0;
  contacts.clear();
  bodies.clear();
  bodies.push_back(std::min(i0, j0));
  bodies.push_back(std::max(i0, j0));
  // Adds contact (i, j) if the two touch; false if the set must go pair by pair.
  const auto consider = [&](std::uint32_t i, std::uint32_t j) {
    if (j == i || !eligible_body(w, j)) return true;
    if (w.is_static(i) && w.is_static(j)) return true;
    Contact c;
    if (!touching(w, i, j, t, c)) return true;
    const bool known = std::any_of(contacts.begin(), contacts.end(),
                                   [&](const Contact& k) { return k.a == c.a && k.b == c.b; });
    if (known) return true;
    const PairMaterial m = w.pair_material(w.material[c.a], w.material[c.b]);
    if (m.friction > 0.0 || m.static_friction > 0.0) return false;
    const double wn = dot(w.vel_at(c.b, t) - w.vel_at(c.a, t), c.n);
    c.target = std::max(-m.restitution * wn, 0.0);
    contacts.push_back(c);
    if (contacts.size() > kMaxContacts) return false;
    if (std::find(bodies.begin(), bodies.end(), j) == bodies.end()) bodies.push_back(j);
    return true;
  };
  const auto touch_box = [&](std::uint32_t i) {
    const Vec2 p = w.pos_at(i, t);
    const double pad = kGapUlps * kEps * (inf_norm(p) + 2.0 * w.radius[i] + 1.0) + w.radius[i];
    return make_aabb(p.x - pad, p.y - pad, p.x + pad, p.y + pad);
  };
  // The impacting pair first, with one broad-phase query for both (an isolated impact,
  // the common case, pays only this); then breadth-first over the rest of the set.
  // Static bodies end the set (nothing moves them).
  const std::uint32_t first = bodies[0], second = bodies[1];
  found.clear();
  w.bp->query_box(merge(touch_box(first), touch_box(second)), kNone, found);
  std::sort(found.begin(), found.end());
  for (std::uint32_t j : found) {
    if (!w.is_static(first) && !consider(first, j)) return false;
    if (!w.is_static(second) && !consider(second, j)) return false;
  }
  for (std::size_t q = 2; q < bodies.size(); ++q) {
    const std::uint32_t i = bodies[q];
    if (w.is_static(i)) continue;
    found.clear();
    w.bp->query_box(touch_box(i), i, found);
    std::sort(found.begin(), found.end());
    for (std::uint32_t j : found) {
      if (!consider(i, j)) return false;
    }
  }
  if (contacts.size() < 2) return false;   // one contact: the pairwise law is the same

  for (std::uint32_t b : bodies) w.advance(b, t);
  // Delassus matrix, dense (the set is small).
  const std::size_t K = contacts.size();
  A.assign(K * K, 0.0);
  w0.assign(K, 0.0);
  for (std::size_t k = 0; k < K; ++k) {
    const Contact& ck = contacts[k];
    w0[k] = dot(w.vel[ck.b] - w.vel[ck.a], ck.n);
    for (std::size_t l = 0; l < K; ++l) {
      const Contact& cl = contacts[l];
      const double nn = dot(ck.n, cl.n);
      double s = 0.0;
      if (ck.a == cl.a) s += w.inv_mass[ck.a] * nn;
      if (ck.b == cl.b) s += w.inv_mass[ck.b] * nn;
      if (ck.a == cl.b) s -= w.inv_mass[ck.a] * nn;
      if (ck.b == cl.a) s -= w.inv_mass[ck.b] * nn;
      A[k * K + l] = s;
    }
  }
  // Projected Gauss-Seidel to round-off.
  double pmax = 0.0;
  for (int iter = 0; iter < 100000; ++iter) {
    double change = 0.0;
    for (std::size_t k = 0; k < K; ++k) {
      const double akk = A[k * K + k];
      if (!(akk > 0.0)) continue;
      double wk = w0[k];
      for (std::size_t l = 0; l < K; ++l) wk += A[k * K + l] * contacts[l].p;
      const double pk = std::max(0.0, contacts[k].p + (contacts[k].target - wk) / akk);
      change = std::max(change, std::fabs(pk - contacts[k].p));
      contacts[k].p = pk;
      pmax = std::max(pmax, pk);
    }
    if (change <= 4.0 * kEps * pmax) break;
  }
  impacted.clear();
  for (const Contact& c : contacts) {
    // An impact: a velocity change above round-off (a pair touching at equal speeds
    // meets again at once through round-off, and takes an impulse of that size).
    if (c.p * (w.inv_mass[c.a] + w.inv_mass[c.b]) > kGapUlps * kEps * c.vscale) impacted.push_back({c.a, c.b});
    w.vel[c.a] -= (c.p * w.inv_mass[c.a]) * c.n;
    w.vel[c.b] += (c.p * w.inv_mass[c.b]) * c.n;
  }
  w.stats.impacts += static_cast<std::int64_t>(K) - 1;
  return true;
}

}  // namespace physval::core_detail
