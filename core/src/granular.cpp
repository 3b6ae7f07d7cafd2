// Granular groups (issue 9): a pile's dense phase, moved by nonsmooth contact dynamics.
//
// Where bodies stay in contact with several others (a pile flowing, a tower leaning, the
// inelastic collapse of a heap), an event-driven engine meets an endless run of ever smaller
// impacts. Event-driven granular codes end it with a threshold or the TC model; the codes
// built for dense rigid granular matter (Moreau and Jean's nonsmooth contact dynamics,
// LMGC90, Siconos) step the contact problem in time instead. core does the latter for such a
// group: on sub-steps h = dt / kSubsteps,
//   1. every contact that can close within the sub-step (its gap below twice what the two
//      bodies' speeds and forces can cover in h) is a unilateral constraint;
//   2. the free velocities v* = v + h a take the contact impulses p that satisfy, at every
//      contact at once, Signorini at the velocity level (p_n >= 0, w_n+ >= b, complementary;
//      b = -gap / h for an open contact, so it may close exactly by the sub-step's end; for an
//      impact faster than the rest speed b = -e w_n- plus the relative force acceleration
//      over h: Newton's restitution at the sub-step's start) and Coulomb (|p_t| <= mu_s p_n
//      where the tangential speed can be brought to 0, else mu_k against it): projected
//      Gauss-Seidel with nonsmooth conjugate gradients, warm-started from the last sub-step,
//      to 1e-10 of the sub-step's speeds (it stops when its sweeps stagnate: counted);
//   3. a body that took an impulse moves by h v+ (Moreau's theta = 1: a body at rest stays
//      exactly at rest); a body that took none follows its exact parabola;
//   4. any overlap left (the contact normals turn within a sub-step) is projected off, mass
//      weighted, to 1e-12 of the scene's size.
// Energy: with restitution 0 the impulses are the kinetic-energy-metric projection of v*
// onto the admissible velocities, which contain 0, so they never add kinetic energy; where
// the bounces would (at several contacts at once, or against the field's work over the
// sub-step), or cannot all hold, the sub-step's bounces are perfectly inelastic. The sweeps
// visit contacts in an order of the geometry alone (bottom up), so no numbering or mirror
// image changes a bit. First order in time, not exact: core says so in limits_hit. A group
// whose bodies are all slower than the rest speed and whose contacts hold it (the same
// problem from rest, with static friction, leaves every body at rest) sleeps: its velocities
// are set to 0 and it is not stepped until a body joins. README, "Piles and dense groups".
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numeric>
#include <string>
#include <vector>

#include "world.hpp"

namespace physval::core_detail {

namespace {

constexpr int kSubsteps = 4;
constexpr int kMaxSubsteps = 64;
constexpr int kMaxSweeps = 1000;
constexpr double kEps = 2.220446049250313e-16;

using Group = World::ContactGroup;

struct Con {
  std::int32_t a = -1;       // member index, or -1: a fixed partner (a face or a static body)
  std::int32_t b = 0;        // member index
  std::uint32_t other = 0;   // fixed partner: segment index (seg) or static body index
  bool seg = false;
  Vec2 n;                    // unit, from a (or the fixed partner) towards b
  double gap = 0.0;
  double k = 0.0;            // 1 / effective mass along n and along the tangent (no spin)
  double mu_s = 0.0, mu_k = 0.0, e = 0.0;
  double bias = 0.0;         // the lower bound on the normal relative velocity after the sub-step
  double pn = 0.0, pt = 0.0;
  bool slide = false;
  bool bounce = false;       // takes Newton's restitution in this sub-step
  std::uint64_t key = 0;
  double level = 0.0;        // the contact point's height (against the field): the sweep order
};

struct Scratch {
  std::vector<Vec2> x, v, a, vs, x0;
  std::vector<Vec2> field;   // each member's uniform field (its potential energy's)
  std::vector<double> inv, rad;
  std::vector<std::uint32_t> order;
  std::vector<Con> cons, proj;
  std::vector<std::uint32_t> fixed;   // static bodies near the group
  std::vector<std::uint32_t> segs;
  std::vector<char> touched;
  std::vector<std::uint64_t> recorded;
  std::vector<double> boxes;   // per member: the box it swept in the step (x0, y0, x1, y1)
  bool smooth_face = false;    // a face with interpolated normals (a surface) came near
};

void pair_geo(Vec2 xa, double ra, Vec2 xb, double rb, Vec2& n, double& gap) {
  const Vec2 d = xb - xa;
  const double dist = length(d);
  n = dist > 0.0 ? (1.0 / dist) * d : Vec2{0.0, 1.0};
  gap = dist - (ra + rb);
}

void seg_geo(const Segment& s, Vec2 p, double r, Vec2& n, double& gap) {
  const double u = dot(p - s.from, s.dir);
  if (u > 0.0 && u < s.length) {   // the face: its own normal, no round-off in its direction
    const double D = dot(p - s.from, s.normal);
    n = D >= 0.0 ? s.normal : -1.0 * s.normal;
    gap = std::fabs(D) - r;
    return;
  }
  const Vec2 c = u <= 0.0 ? s.from : s.to;
  const Vec2 d = p - c;
  const double dist = length(d);
  n = dist > 0.0 ? (1.0 / dist) * d : s.normal;
  gap = dist - r;
}

// The geometry of contact c at positions x.
void con_geo(const World& w, const Scratch& s, Con& c, const std::vector<Vec2>& x) {
  const std::size_t b = static_cast<std::size_t>(c.b);
  if (c.a >= 0) {
    const std::size_t a = static_cast<std::size_t>(c.a);
    pair_geo(x[a], s.rad[a], x[b], s.rad[b], c.n, c.gap);
  } else if (c.seg) {
    seg_geo(w.statics.segments[c.other], x[b], s.rad[b], c.n, c.gap);
  } else {
    pair_geo(w.pos[c.other], w.radius[c.other], x[b], s.rad[b], c.n, c.gap);
  }
}

void set_material(const World& w, const Group& g, Con& c) {
  const std::uint32_t mb = g.members[static_cast<std::size_t>(c.b)];
  std::uint16_t other_material;
  if (c.a >= 0) {
    other_material = w.material[g.members[static_cast<std::size_t>(c.a)]];
  } else if (c.seg) {
    other_material = w.statics.segments[c.other].material;
  } else {
    other_material = w.material[c.other];
  }
  const PairMaterial m = w.pair_material(w.material[mb], other_material);
  if (m.rolling_friction > 0.0) {   // a rolling pair: c replaces mu_s and mu_k (README)
    c.mu_k = c.mu_s = m.rolling_friction;
  } else {
    c.mu_k = std::isfinite(m.friction) ? std::max(0.0, m.friction) : 0.0;
    c.mu_s = std::max(c.mu_k, std::isfinite(m.static_friction) ? m.static_friction : 0.0);
  }
  c.e = m.restitution;
}

std::uint64_t con_key(const Group& g, const Con& c) {
  const std::uint32_t mb = g.members[static_cast<std::size_t>(c.b)];
  if (c.a >= 0) return contact_key(mb, g.members[static_cast<std::size_t>(c.a)]);
  if (c.seg) return (static_cast<std::uint64_t>(mb) << 32) | 0x80000000u | c.other;
  return contact_key(mb, c.other);
}

// The contacts that can close within a sub-step of h from the state in s (positions x,
// velocities v, force accelerations a): member pairs by a sweep along x, member-face pairs
// by the static grid, member-static-body pairs from s.fixed.
void find_contacts(const World& w, const Group& g, Scratch& s, double h, double skin, std::vector<Con>& out) {
  const std::size_t M = g.members.size();
  out.clear();
  double vmax = 0.0, amax = 0.0;
  for (std::size_t q = 0; q < M; ++q) {
    vmax = std::max(vmax, length(s.v[q]));
    amax = std::max(amax, length(s.a[q]));
  }
  // (twice what the free motion covers: an impulse in the sub-step may speed a body up; a
  // contact missed all the same is projected off after it)
  const auto reach = [&](std::size_t q) { return 2.0 * (h * length(s.v[q]) + h * h * length(s.a[q])); };
  // members sorted by their left edge (insertion sort: nearly sorted from the last sub-step)
  if (s.order.size() != M) {
    s.order.resize(M);
    std::iota(s.order.begin(), s.order.end(), 0u);
  }
  const auto left = [&](std::uint32_t q) { return s.x[q].x - s.rad[q]; };
  for (std::size_t i = 1; i < M; ++i) {
    const std::uint32_t q = s.order[i];
    const double lq = left(q);
    std::size_t j = i;
    while (j > 0 && (left(s.order[j - 1]) > lq || (left(s.order[j - 1]) == lq && s.order[j - 1] > q))) {
      s.order[j] = s.order[j - 1];
      --j;
    }
    s.order[j] = q;
  }
  const double Mx = 4.0 * (h * vmax + h * h * amax) + skin;
  for (std::size_t i = 0; i < M; ++i) {
    const std::uint32_t p = s.order[i];
    const double right = s.x[p].x + s.rad[p] + Mx;
    for (std::size_t j = i + 1; j < M; ++j) {
      const std::uint32_t q = s.order[j];
      if (left(q) > right) break;
      const double R = s.rad[p] + s.rad[q];
      if (std::fabs(s.x[q].y - s.x[p].y) > R + Mx) continue;
      Con c;
      c.a = static_cast<std::int32_t>(std::min(p, q));
      c.b = static_cast<std::int32_t>(std::max(p, q));
      con_geo(w, s, c, s.x);
      if (c.gap > reach(p) + reach(q) + skin) continue;
      out.push_back(c);
    }
  }
  for (std::size_t q = 0; q < M; ++q) {
    const double pad = s.rad[q] + reach(q) + skin;
    s.segs.clear();
    w.statics.query(make_aabb(s.x[q].x - pad, s.x[q].y - pad, s.x[q].x + pad, s.x[q].y + pad), s.segs);
    for (std::uint32_t k : s.segs) {
      const Segment& sg = w.statics.segments[k];
      if (length_squared(sg.normal_from) > 0.0 || length_squared(sg.normal_to) > 0.0) s.smooth_face = true;
      Con c;
      c.b = static_cast<std::int32_t>(q);
      c.seg = true;
      c.other = k;
      con_geo(w, s, c, s.x);
      if (c.gap > reach(q) + skin) continue;
      out.push_back(c);
    }
    for (std::uint32_t j : s.fixed) {
      Con c;
      c.b = static_cast<std::int32_t>(q);
      c.other = j;
      con_geo(w, s, c, s.x);
      if (c.gap > reach(q) + skin) continue;
      out.push_back(c);
    }
  }
  for (Con& c : out) {
    c.key = con_key(g, c);
    set_material(w, g, c);
    c.k = s.inv[static_cast<std::size_t>(c.b)] + (c.a >= 0 ? s.inv[static_cast<std::size_t>(c.a)] : 0.0);
  }
  // The order of every sweep: bottom up along the field (a pile's weight is carried from its
  // supports), a function of the geometry alone, so that no numbering of the bodies and no
  // mirror image changes a bit of the answer; contacts at the same height to the bit are one
  // block, solved together (see sweep).
  const Vec2 up = length_squared(w.gravity) > 0.0 ? (-1.0 / length(w.gravity)) * w.gravity : Vec2{0.0, 1.0};
  for (Con& c : out) {
    const std::size_t b = static_cast<std::size_t>(c.b);
    Vec2 point;
    if (c.a >= 0) {
      point = 0.5 * (s.x[static_cast<std::size_t>(c.a)] + s.x[b]);
    } else if (c.seg) {
      point = s.x[b] - (c.gap + s.rad[b]) * c.n;
    } else {
      point = 0.5 * (w.pos[c.other] + s.x[b]);
    }
    c.level = dot(point, up);
  }
  std::sort(out.begin(), out.end(), [](const Con& l, const Con& r) { return l.level < r.level; });
}

void apply(Scratch& s, const Con& c, Vec2 P) {
  s.v[static_cast<std::size_t>(c.b)] += s.inv[static_cast<std::size_t>(c.b)] * P;
  if (c.a >= 0) s.v[static_cast<std::size_t>(c.a)] -= s.inv[static_cast<std::size_t>(c.a)] * P;
}

Vec2 rel(const Scratch& s, const Con& c) {
  return s.v[static_cast<std::size_t>(c.b)] - (c.a >= 0 ? s.v[static_cast<std::size_t>(c.a)] : Vec2{});
}

// Projected Gauss-Seidel on the contacts (impulses pn, pt already applied to s.v). Returns
// the last sweep's largest velocity change.
// Contact c's projected update from the current velocities (not applied): the normal
// impulse to its Signorini bound, then the tangential one to its Coulomb cone.
void update(const Scratch& s, Con& c, double& pn, double& pt) {
  const Vec2 dv = rel(s, c);
  const double wn = dot(dv, c.n);
  pn = std::max(0.0, c.pn - (wn - c.bias) / c.k);
  pt = c.pt;
  if (c.mu_s > 0.0 || c.pt != 0.0) {
    const double wt = dot(dv, perp(c.n));   // (the normal impulse does not change it)
    const double pt_try = c.pt - wt / c.k;
    double lim = (c.slide ? c.mu_k : c.mu_s) * pn;
    if (std::fabs(pt_try) > lim && !c.slide) {   // static friction gives way: kinetic from here
      c.slide = true;
      lim = c.mu_k * pn;
    }
    pt = std::clamp(pt_try, -lim, lim);
  }
}

// Velocity changes of a block, summed per body in an order of their values (not of the
// bodies' numbers): mirror images and renumberings give the same bits.
struct Kick {
  std::int32_t body;
  Vec2 dv;
};

void apply_kicks(std::vector<Vec2>& target, std::vector<Kick>& kicks) {
  std::sort(kicks.begin(), kicks.end(), [](const Kick& l, const Kick& r) {
    if (l.body != r.body) return l.body < r.body;
    const double la = std::fabs(l.dv.x), ra = std::fabs(r.dv.x);
    if (la != ra) return la < ra;
    return l.dv.y < r.dv.y;
  });
  for (std::size_t i = 0; i < kicks.size();) {
    std::size_t j = i;
    Vec2 sum{};
    while (j < kicks.size() && kicks[j].body == kicks[i].body) {
      // a pair of mirror images (equal |x|, equal y) is added first: its sum has no order
      if (j + 1 < kicks.size() && kicks[j + 1].body == kicks[i].body && std::fabs(kicks[j + 1].dv.x) == std::fabs(kicks[j].dv.x) &&
          kicks[j + 1].dv.y == kicks[j].dv.y) {
        sum += kicks[j].dv + kicks[j + 1].dv;
        j += 2;
      } else {
        sum += kicks[j].dv;
        ++j;
      }
    }
    target[static_cast<std::size_t>(kicks[i].body)] += sum;
    i = j;
  }
}

// One projected Gauss-Seidel sweep over the contacts in their order; a block of contacts at
// the same height is updated from the same velocities (projected Jacobi, relaxed by the most
// block contacts one body has). Returns the sweep's largest velocity change.
double sweep(Scratch& s) {
  thread_local std::vector<Kick> kicks;
  thread_local std::vector<double> upd;
  thread_local std::vector<std::int32_t> deg;
  double change = 0.0;
  const std::size_t n = s.cons.size();
  for (std::size_t i = 0; i < n;) {
    std::size_t j = i + 1;
    while (j < n && s.cons[j].level == s.cons[i].level) ++j;
    if (j == i + 1) {   // a contact alone at its height: Gauss-Seidel
      Con& c = s.cons[i];
      double pn, pt;
      update(s, c, pn, pt);
      const double dn = pn - c.pn, dt = pt - c.pt;
      if (dn != 0.0 || dt != 0.0) {
        apply(s, c, dn * c.n + dt * perp(c.n));
        change = std::max(change, std::max(std::fabs(dn), std::fabs(dt)) * c.k);
        c.pn = pn;
        c.pt = pt;
      }
      i = j;
      continue;
    }
    upd.resize(2 * (j - i));
    for (std::size_t q = i; q < j; ++q) update(s, s.cons[q], upd[2 * (q - i)], upd[2 * (q - i) + 1]);
    deg.assign(s.v.size(), 0);
    int most = 1;
    for (std::size_t q = i; q < j; ++q) {
      most = std::max(most, ++deg[static_cast<std::size_t>(s.cons[q].b)]);
      if (s.cons[q].a >= 0) most = std::max(most, ++deg[static_cast<std::size_t>(s.cons[q].a)]);
    }
    const double omega = 1.0 / most;
    kicks.clear();
    for (std::size_t q = i; q < j; ++q) {
      Con& c = s.cons[q];
      const double dn = omega * (upd[2 * (q - i)] - c.pn), dt = omega * (upd[2 * (q - i) + 1] - c.pt);
      if (dn == 0.0 && dt == 0.0) continue;
      c.pn += dn;
      c.pt += dt;
      const Vec2 P = dn * c.n + dt * perp(c.n);
      kicks.push_back({c.b, s.inv[static_cast<std::size_t>(c.b)] * P});
      if (c.a >= 0) kicks.push_back({c.a, -s.inv[static_cast<std::size_t>(c.a)] * P});
      change = std::max(change, std::max(std::fabs(dn), std::fabs(dt)) * c.k);
    }
    apply_kicks(s.v, kicks);
    i = j;
  }
  return change;
}

// Applies the impulse f(c) of every contact to the velocities in the sweep's order, a block of
// contacts at one height together (as `sweep` does, so that no numbering changes a bit).
template <class F>
void apply_ordered(Scratch& s, std::vector<Con>& cons, F f) {
  thread_local std::vector<Kick> kicks;
  const std::size_t n = cons.size();
  for (std::size_t i = 0; i < n;) {
    std::size_t j = i + 1;
    while (j < n && cons[j].level == cons[i].level) ++j;
    if (j == i + 1) {
      const Vec2 P = f(cons[i]);
      if (P.x != 0.0 || P.y != 0.0) apply(s, cons[i], P);
    } else {
      kicks.clear();
      for (std::size_t q = i; q < j; ++q) {
        const Vec2 P = f(cons[q]);
        if (P.x == 0.0 && P.y == 0.0) continue;
        kicks.push_back({cons[q].b, s.inv[static_cast<std::size_t>(cons[q].b)] * P});
        if (cons[q].a >= 0) kicks.push_back({cons[q].a, -s.inv[static_cast<std::size_t>(cons[q].a)] * P});
      }
      apply_kicks(s.v, kicks);
    }
    i = j;
  }
}

// Projected Gauss-Seidel accelerated by nonsmooth nonlinear conjugate gradients (Silcowitz,
// Niebe and Erleben, "A nonsmooth nonlinear conjugate gradient method for interactive contact
// force problems", 2010): each sweep's change of the impulses is a search direction, combined
// with the last one (Fletcher-Reeves, restarted when it grows), which carries information
// through a tall stack in far fewer sweeps than Gauss-Seidel alone. The impulses pn, pt are
// already applied to s.v. Returns the last sweep's largest velocity change.
double pgs(Scratch& s, double tol, int& sweeps, bool& stagnated) {
  stagnated = false;
  const std::size_t n = s.cons.size();
  thread_local std::vector<double> old, dir, step, terms;
  old.resize(2 * n);
  dir.assign(2 * n, 0.0);
  double rn_prev = 0.0;
  double change = 0.0, window = INFINITY;
  for (sweeps = 0; sweeps < kMaxSweeps; ++sweeps) {
    // stagnated: 64 sweeps took off less than a tenth of the change (an infeasible set of
    // bounces cycles for ever; the caller decides)
    if (sweeps % 64 == 0 && sweeps > 0) {
      if (change > 0.9 * window) {
        stagnated = true;
        break;
      }
      window = change;
    }
    for (std::size_t k = 0; k < n; ++k) {
      old[2 * k] = s.cons[k].pn;
      old[2 * k + 1] = s.cons[k].pt;
    }
    change = sweep(s);
    if (change <= tol) break;
    // |change|^2, summed in the sweep's order and within a block in the order of the terms'
    // values (no numbering changes a bit)
    double rn = 0.0;
    for (std::size_t i = 0; i < n;) {
      std::size_t j = i + 1;
      while (j < n && s.cons[j].level == s.cons[i].level) ++j;
      terms.clear();
      for (std::size_t k = i; k < j; ++k) {
        const double rp = s.cons[k].pn - old[2 * k], rt = s.cons[k].pt - old[2 * k + 1];
        terms.push_back(rp * rp + rt * rt);
      }
      if (terms.size() > 1) std::sort(terms.begin(), terms.end());
      for (double x : terms) rn += x;
      i = j;
    }
    const double beta = rn_prev > 0.0 ? rn / rn_prev : 0.0;
    rn_prev = rn;
    if (beta > 1.0 || beta == 0.0) {   // restart
      for (std::size_t k = 0; k < n; ++k) {
        dir[2 * k] = s.cons[k].pn - old[2 * k];
        dir[2 * k + 1] = s.cons[k].pt - old[2 * k + 1];
      }
      continue;
    }
    step.resize(2 * n);
    for (std::size_t k = 0; k < n; ++k) {
      Con& c = s.cons[k];
      step[2 * k] = beta * dir[2 * k];
      step[2 * k + 1] = beta * dir[2 * k + 1];
      dir[2 * k] = (c.pn - old[2 * k]) + step[2 * k];
      dir[2 * k + 1] = (c.pt - old[2 * k + 1]) + step[2 * k + 1];
      c.pn += step[2 * k];
      c.pt += step[2 * k + 1];
    }
    apply_ordered(s, s.cons, [&](const Con& c) {
      const std::size_t k = static_cast<std::size_t>(&c - s.cons.data());
      return step[2 * k] * c.n + step[2 * k + 1] * perp(c.n);
    });
  }
  return change;
}

double kinetic(const Scratch& s) {
  double E = 0.0;
  for (std::size_t q = 0; q < s.v.size(); ++q) {
    if (s.inv[q] > 0.0) E += 0.5 * length_squared(s.v[q]) / s.inv[q];
  }
  return E;
}

void load(const World& w, const Group& g, Scratch& s) {
  const std::size_t M = g.members.size();
  s.x.resize(M);
  s.v.resize(M);
  s.a.resize(M);
  s.field.resize(M);
  s.inv.resize(M);
  s.rad.resize(M);
  for (std::size_t q = 0; q < M; ++q) {
    const std::uint32_t m = g.members[q];
    s.x[q] = w.pos[m];
    s.v[q] = w.vel[m];
    s.a[q] = g.acc[q];
    s.field[q] = (w.flags[m] & kNoGravity) ? Vec2{} : w.gravity;
    s.inv[q] = w.inv_mass[m];
    s.rad[q] = w.radius[m];
  }
  if (s.order.size() != M) s.order.clear();
}

// The static bodies within reach of the group over the step.
void find_fixed(const World& w, const Group& g, const Scratch& s, double dt, std::vector<std::uint32_t>& out) {
  out.clear();
  // (each member's reach as the group's plan takes it: an impulse may pass a body up to twice
  // the group's fastest speed)
  double vmax = 0.0, amax = 0.0;
  for (std::size_t q = 0; q < g.members.size(); ++q) {
    vmax = std::max(vmax, length(s.v[q]));
    amax = std::max(amax, length(s.a[q]));
  }
  double x0 = INFINITY, y0 = INFINITY, x1 = -INFINITY, y1 = -INFINITY;
  for (std::size_t q = 0; q < g.members.size(); ++q) {
    const double reach = std::max(length(s.v[q]) * dt + length(s.a[q]) * dt * dt, 2.0 * vmax * dt + 5.0 * amax * dt * dt);
    const double r = s.rad[q] + reach + 1e-9 * w.length_scale;
    x0 = std::min(x0, s.x[q].x - r);
    y0 = std::min(y0, s.x[q].y - r);
    x1 = std::max(x1, s.x[q].x + r);
    y1 = std::max(y1, s.x[q].y + r);
  }
  for (std::uint32_t j = 0; j < w.size(); ++j) {
    if (!w.is_static(j) || (w.flags[j] & kAlive) == 0) continue;
    const double r = w.radius[j];
    if (w.pos[j].x + r < x0 || w.pos[j].x - r > x1 || w.pos[j].y + r < y0 || w.pos[j].y - r > y1) continue;
    out.push_back(j);
  }
}

// One sub-step of length h. t_abs: the sub-step's start (absolute time).
void substep(World& w, Group& g, Scratch& s, double h, double dt, double t_abs) {
  const std::size_t M = g.members.size();
  // forces that depend on the velocity (drag, wind, thrust): taken at the sub-step's start
  if (w.varying_forces) {
    for (std::size_t q = 0; q < M; ++q) s.a[q] = body_acceleration(w, g.members[q], s.v[q]);
  }
  const double skin = 1e-9 * w.length_scale;
  find_contacts(w, g, s, h, skin, s.cons);
  // warm start, scaled to this sub-step
  const double scale = g.warm_h > 0.0 ? h / g.warm_h : 1.0;
  for (Con& c : s.cons) {
    const auto it = std::lower_bound(g.warm.begin(), g.warm.end(), c.key,
                                     [](const World::GranularWarm& x, std::uint64_t k) { return x.key < k; });
    if (it != g.warm.end() && it->key == c.key) {
      c.pn = scale * it->pn;
      c.pt = scale * it->pt;
      c.slide = it->slide;
    }
  }
  double vmax = 0.0, amax = 0.0;
  for (std::size_t q = 0; q < M; ++q) {
    vmax = std::max(vmax, length(s.v[q]));
    amax = std::max(amax, length(s.a[q]));
  }
  // restitution: an impact faster than its rest speed (the threshold of every impact in core)
  // that the free motion closes within the sub-step
  for (Con& c : s.cons) {
    const double wn0 = dot(rel(s, c), c.n);
    const Vec2 ab = s.a[static_cast<std::size_t>(c.b)];
    const Vec2 aa = c.a >= 0 ? s.a[static_cast<std::size_t>(c.a)] : Vec2{};
    const double wnf = wn0 + h * dot(ab - aa, c.n);
    const double an = std::max(length(ab), length(aa));
    const double vr = w.impact_rest_speed(an, dt, c.e, wn0);
    // The bounce leaves at -e wn0 at the sub-step's start and is then pressed by the relative
    // force acceleration for h (the position follows v+ for the whole sub-step: a target of
    // -e wn0 at its end would add m |a| h e |wn0| of energy); no bounce is left when that is
    // not positive (shorter than a sub-step: perfectly inelastic).
    const double target = -c.e * wn0 + h * dot(ab - aa, c.n);
    c.bounce = c.e > 0.0 && -wn0 > vr && c.gap + h * std::min(wnf, wn0) <= 0.0 && target > 0.0;
    c.bias = c.bounce ? target : -std::max(c.gap, 0.0) / h;
  }
  s.vs = s.v;
  for (std::size_t q = 0; q < M; ++q) s.v[q] += h * s.a[q];
  const double E_free = kinetic(s);
  apply_ordered(s, s.cons, [](const Con& c) { return c.pn * c.n + c.pt * perp(c.n); });
  const double tol = 1e-10 * (vmax + amax * h) + 1e-300;
  int sweeps = 0;
  bool stagnated = false;
  double left = pgs(s, tol, sweeps, stagnated);
  const bool any_bounce = std::any_of(s.cons.begin(), s.cons.end(), [](const Con& c) { return c.bounce; });
  if (any_bounce && (stagnated || kinetic(s) > E_free * (1.0 + 1e-9))) {
    // Newton's law at several contacts at once raised the energy, or cannot hold at all (a
    // body bounced off two sides at once): perfectly inelastic instead
    for (Con& c : s.cons) {
      if (!c.bounce) continue;
      c.bounce = false;
      c.bias = -std::max(c.gap, 0.0) / h;
    }
    left = pgs(s, tol, sweeps, stagnated);
  }
  if (left > tol) {
    ++w.granular_unconverged;
    w.granular_worst_residual = std::max(w.granular_worst_residual, left);
  }
  // positions: theta = 1 for a body that took an impulse, its exact parabola otherwise
  s.x0 = s.x;
  const auto move = [&]() {
    s.touched.assign(M, 0);
    for (const Con& c : s.cons) {
      if (c.pn == 0.0 && c.pt == 0.0) continue;
      s.touched[static_cast<std::size_t>(c.b)] = 1;
      if (c.a >= 0) s.touched[static_cast<std::size_t>(c.a)] = 1;
    }
    for (std::size_t q = 0; q < M; ++q) {
      if (s.touched[q]) {
        s.x[q] = s.x0[q] + h * s.v[q];
      } else {
        s.x[q] = s.x0[q] + h * s.vs[q] + (0.5 * h * h) * s.a[q];
      }
    }
  };
  move();
  // The group's energy (kinetic and the field's potential), before and after the sub-step, less
  // the work of the other forces (drag, wind, thrust) over it.
  const auto energy = [&](const std::vector<Vec2>& x, const std::vector<Vec2>& v, double& mag) {
    double E = 0.0;
    mag = 0.0;
    for (std::size_t q = 0; q < M; ++q) {
      if (!(s.inv[q] > 0.0)) continue;
      const double ke = 0.5 * length_squared(v[q]) / s.inv[q], pe = -dot(s.field[q], x[q]) / s.inv[q];
      const double other = -dot(s.a[q] - s.field[q], x[q] - s.x0[q]) / s.inv[q];
      E += ke + pe + other;
      mag += ke + std::fabs(pe) + std::fabs(other);
    }
    return E;
  };
  double sc0 = 0.0, sc1 = 0.0;
  const double E0 = energy(s.x0, s.vs, sc0);
  // A bounce inside a group whose bodies are pressed by others (a ball bouncing on a ball at
  // rest on the floor) leaves at its target for the whole sub-step, which can gain energy (the
  // field's work over the sub-step is not taken off it): the group's energy may never rise in
  // a sub-step with bounces; if it would, the sub-step's bounces are perfectly inelastic.
  if (std::any_of(s.cons.begin(), s.cons.end(), [](const Con& c) { return c.bounce; })) {
    const double E1 = energy(s.x, s.v, sc1);
    if (E1 > E0 + 1e-12 * std::max(sc0, sc1)) {
      for (Con& c : s.cons) {
        if (!c.bounce) continue;
        c.bounce = false;
        c.bias = -std::max(c.gap, 0.0) / h;
      }
      left = pgs(s, tol, sweeps, stagnated);
      move();
    }
  }
  // overlaps left by the turning normals (or a contact an impulse sped up): projected off,
  // nonlinear Gauss-Seidel on positions over every touching pair found anew
  const double ptol = 1e-12 * w.length_scale;
  thread_local std::vector<Kick> kicks;
  thread_local std::vector<std::int32_t> pdeg;
  // (contacts within twice the deepest overlap join the projection from the start: pushing
  // a body out moves it by up to that much into its neighbours)
  double reach_skin = ptol;
  for (int round = 0; round < 32; ++round) {
    find_contacts(w, g, s, 0.0, reach_skin, s.proj);
    double deepest = 0.0;
    for (const Con& c : s.proj) deepest = std::max(deepest, -c.gap);
    if (2.0 * deepest > reach_skin) {
      reach_skin = 2.0 * deepest;
      find_contacts(w, g, s, 0.0, reach_skin, s.proj);
    }
    bool moved = false;
    for (int it = 0; it < 256; ++it) {
      double worst = 0.0;
      const std::size_t np = s.proj.size();
      for (std::size_t i = 0; i < np;) {   // (a block at one height together, as in `sweep`)
        std::size_t j = i + 1;
        while (j < np && s.proj[j].level == s.proj[i].level) ++j;
        kicks.clear();
        int most = 1;   // relaxed by the most block contacts one body has
        if (j > i + 1) {
          pdeg.assign(M, 0);
          for (std::size_t q = i; q < j; ++q) {
            most = std::max(most, ++pdeg[static_cast<std::size_t>(s.proj[q].b)]);
            if (s.proj[q].a >= 0) most = std::max(most, ++pdeg[static_cast<std::size_t>(s.proj[q].a)]);
          }
        }
        for (std::size_t q = i; q < j; ++q) {
          Con& c = s.proj[q];
          con_geo(w, s, c, s.x);
          if (c.gap >= -ptol) continue;
          worst = std::max(worst, -c.gap);
          moved = true;
          const double d = -c.gap / c.k / static_cast<double>(most);
          kicks.push_back({c.b, (d * s.inv[static_cast<std::size_t>(c.b)]) * c.n});
          if (c.a >= 0) kicks.push_back({c.a, (-d * s.inv[static_cast<std::size_t>(c.a)]) * c.n});
          if (j == i + 1) {
            apply_kicks(s.x, kicks);
            kicks.clear();
          }
        }
        if (!kicks.empty()) apply_kicks(s.x, kicks);
        i = j;
      }
      if (worst <= ptol) break;
    }
    if (!moved) break;   // nothing moved in this round: no new pair can overlap
  }
  // What the projection could not separate (bodies of very different masses jammed: its
  // sweeps move the heavy one by the mass ratio of the light one's push) is a broken
  // guarantee, never `ok`.
  {
    find_contacts(w, g, s, 0.0, ptol, s.proj);
    double deepest = 0.0;
    std::size_t at = 0;
    for (const Con& c : s.proj) {
      if (-c.gap > deepest) {
        deepest = -c.gap;
        at = static_cast<std::size_t>(c.b);
      }
    }
    // and energy the solve created (beyond 1e-6 of the group's energy scale; the sweeps' largest
    // rise measured in 148 piles is below 1e-7): a broken guarantee too
    const double E2 = energy(s.x, s.v, sc1);
    if (E2 > E0 + 1e-6 * std::max(sc0, sc1) && w.group_disturbed == kNone) {
      w.group_disturbed = g.members.front();
      w.group_disturbed_time = t_abs;
      w.group_why = "the granular mode's sub-step raised the group's energy by " + std::to_string(E2 - E0) +
                    " J (its contact solve did not converge)";
    }
    if (deepest > 1e-9 * w.length_scale && w.group_disturbed == kNone) {
      w.group_disturbed = g.members[at];
      w.group_disturbed_time = t_abs;
      w.group_why = "the granular mode left an overlap of " + std::to_string(deepest) +
                    " m it could not project off (its contact solve did not converge: bodies of very different "
                    "masses jammed?)";
    }
  }
  // contact events: a contact that takes an impulse begins unless the pair touched within dt
  for (const Con& c : s.cons) {
    if (!(c.pn > 0.0)) continue;
    const auto it = std::lower_bound(s.recorded.begin(), s.recorded.end(), c.key);
    if (it != s.recorded.end() && *it == c.key) continue;
    s.recorded.insert(it, c.key);
    const std::uint32_t mb = g.members[static_cast<std::size_t>(c.b)];
    if (c.a >= 0) {
      record_contact(w, mb, g.members[static_cast<std::size_t>(c.a)], nullptr, t_abs + h, dt);
    } else if (c.seg) {
      record_contact(w, mb, kNone, &w.statics.segments[c.other], t_abs + h, dt);
    } else {
      record_contact(w, mb, c.other, nullptr, t_abs + h, dt);
    }
  }
  // warm impulses for the next sub-step (cons are sorted by key)
  g.warm.clear();
  for (const Con& c : s.cons) {
    if (c.pn == 0.0 && c.pt == 0.0) continue;
    World::GranularWarm x;
    x.key = c.key;
    x.pn = c.pn;
    x.pt = c.pt;
    x.slide = c.slide && std::fabs(dot(rel(s, c), perp(c.n))) > tol;
    g.warm.push_back(x);
  }
  std::sort(g.warm.begin(), g.warm.end(),
            [](const World::GranularWarm& l, const World::GranularWarm& r) { return l.key < r.key; });
  g.warm_h = h;
  for (std::size_t q = 0; q < M; ++q) {
    const double r = s.rad[q];
    // (a body's path within a sub-step stays within the box of its two ends and what its
    // force acceleration bends it by)
    const double bend = 0.125 * h * h * length(s.a[q]);
    double* mb = &s.boxes[4 * q];
    mb[0] = std::min(mb[0], s.x[q].x - r - bend);
    mb[1] = std::min(mb[1], s.x[q].y - r - bend);
    mb[2] = std::max(mb[2], s.x[q].x + r + bend);
    mb[3] = std::max(mb[3], s.x[q].y + r + bend);
  }
}

// Whether the group's contacts hold it at rest: the same problem from rest (v = 0), every
// touching contact sticking with its static friction, leaves every body at rest.
bool holds_at_rest(World& w, Group& g, Scratch& s, double h, double dt) {
  const std::size_t M = g.members.size();
  const std::vector<Vec2> v_keep = s.v;
  std::fill(s.v.begin(), s.v.end(), Vec2{});
  const double skin = 1e-9 * w.length_scale;
  find_contacts(w, g, s, h, skin, s.cons);
  double amax = 0.0;
  for (std::size_t q = 0; q < M; ++q) amax = std::max(amax, length(s.a[q]));
  std::erase_if(s.cons, [&](const Con& c) { return c.gap > skin; });
  for (Con& c : s.cons) {
    c.slide = false;
    c.mu_k = c.mu_s;   // the static cone throughout: held iff every body stays at rest
    c.bias = 0.0;
    const auto it = std::lower_bound(g.warm.begin(), g.warm.end(), c.key,
                                     [](const World::GranularWarm& x, std::uint64_t k) { return x.key < k; });
    if (it != g.warm.end() && it->key == c.key && g.warm_h > 0.0) {
      c.pn = it->pn * h / g.warm_h;
      c.pt = it->pt * h / g.warm_h;
    }
  }
  if (w.varying_forces) {   // the forces on bodies at rest
    for (std::size_t q = 0; q < M; ++q) s.a[q] = body_acceleration(w, g.members[q], Vec2{});
  }
  for (std::size_t q = 0; q < M; ++q) s.v[q] = h * s.a[q];
  apply_ordered(s, s.cons, [](const Con& c) { return c.pn * c.n + c.pt * perp(c.n); });
  int sweeps = 0;
  bool stagnated = false;
  pgs(s, 1e-13 * amax * h + 1e-300, sweeps, stagnated);
  bool held = true;
  for (std::size_t q = 0; q < M && held; ++q) held = length(s.v[q]) <= 1e-10 * amax * h;
  (void)dt;
  s.v = v_keep;
  return held;
}

}  // namespace

void granular_step(World& w, Group& g, const StepContext& ctx, std::vector<double>& member_boxes) {
  thread_local Scratch s;
  const std::size_t M = g.members.size();
  load(w, g, s);
  s.boxes.resize(4 * M);
  for (std::size_t q = 0; q < M; ++q) {
    s.boxes[4 * q] = s.x[q].x - s.rad[q];
    s.boxes[4 * q + 1] = s.x[q].y - s.rad[q];
    s.boxes[4 * q + 2] = s.x[q].x + s.rad[q];
    s.boxes[4 * q + 3] = s.x[q].y + s.rad[q];
  }
  if (g.fresh) g.sleeping = false;
  g.fresh = false;
  if (w.granular_first_time < 0.0) w.granular_first_time = ctx.t0;
  ++w.granular_steps;
  if (!g.sleeping) {
    s.smooth_face = false;
    find_fixed(w, g, s, ctx.dt, s.fixed);
    s.recorded.clear();
    // At least kSubsteps sub-steps, more where a fast member would cross more than a quarter of
    // the smallest radius in one (a ball thrown into a pile: its impact is resolved at a
    // sub-step's resolution), at most kMaxSubsteps.
    double vmax = 0.0, amax = 0.0, rmin = INFINITY;
    for (std::size_t q = 0; q < M; ++q) {
      vmax = std::max(vmax, length(s.v[q]));
      amax = std::max(amax, length(s.a[q]));
      rmin = std::min(rmin, s.rad[q]);
    }
    int subs = kSubsteps;
    if (rmin > 0.0) {
      const double cross = (vmax + amax * ctx.dt) * ctx.dt / (0.25 * rmin);
      if (cross > kSubsteps) subs = static_cast<int>(std::min<double>(kMaxSubsteps, std::ceil(cross)));
    }
    const double h = ctx.dt / subs;
    for (int k = 0; k < subs; ++k) substep(w, g, s, h, ctx.dt, ctx.t0 + k * h);
    // a static body a member reached that was not among the group's fixed contacts (beyond
    // every reach the step was planned with): core found no contact with it, a broken guarantee
    for (std::uint32_t j = 0; j < w.size() && w.group_disturbed == kNone; ++j) {
      if (!w.is_static(j) || (w.flags[j] & kAlive) == 0) continue;
      if (std::find(s.fixed.begin(), s.fixed.end(), j) != s.fixed.end()) continue;
      const double r = w.radius[j] + 1e-9 * w.length_scale;
      for (std::size_t q = 0; q < M; ++q) {
        const double* b = &s.boxes[4 * q];
        if (w.pos[j].x + r < b[0] || w.pos[j].x - r > b[2] || w.pos[j].y + r < b[1] || w.pos[j].y - r > b[3]) continue;
        w.group_disturbed = j;
        w.group_disturbed_time = ctx.t0;
        w.group_why = "a member of the granular group reached static body '" + w.name(j) +
                      "' beyond the reach its step was planned with";
        break;
      }
    }
    if (s.smooth_face && w.group_disturbed == kNone) {   // contacts there take the faces' own normals
      w.group_disturbed = g.members.front();
      w.group_disturbed_time = ctx.t0;
      w.group_why = "a face near it has interpolated normals (a surface), which the granular mode does not model";
    }
    // asleep: every body slower than the rest speed, and the contacts hold the group at rest
    bool slow = true;
    for (std::size_t q = 0; q < M && slow; ++q) slow = length(s.v[q]) <= w.rest_speed(amax, ctx.dt);
    if (slow && amax > 0.0 && holds_at_rest(w, g, s, h, ctx.dt)) {
      g.sleeping = true;
      std::fill(s.v.begin(), s.v.end(), Vec2{});
    }
  }
  member_boxes = s.boxes;
  for (std::size_t q = 0; q < M; ++q) {
    const std::uint32_t m = g.members[q];
    w.pos[m] = s.x[q];
    w.vel[m] = s.v[q];
    w.tloc[m] = 0.0;
    w.apath[m] = group_force_acc(w, m);
    ++w.version[m];
  }
  // contacts touching at the step's end continue (no new contact event later)
  for (const World::GranularWarm& c : g.warm) {
    const std::uint32_t hi = static_cast<std::uint32_t>(c.key >> 32), lo = static_cast<std::uint32_t>(c.key);
    if (lo & 0x80000000u) {
      touch_contact(w, hi, static_partner_key(w.statics.segments[lo & 0x7fffffffu].owner), ctx.t0 + ctx.dt);
    } else {
      touch_contact(w, hi, lo, ctx.t0 + ctx.dt);
    }
  }
}

void granular_split(World& w, Group& g, double dt, std::vector<Group>& out) {
  const std::size_t M = g.members.size();
  std::vector<std::size_t> comp(M);
  std::iota(comp.begin(), comp.end(), 0);
  const auto find = [&](std::size_t a) {
    while (comp[a] != a) a = comp[a] = comp[comp[a]];
    return a;
  };
  // Members that touch, or may meet within the next step, stay together: by the reach and the
  // box test the next step's plan_group_reach takes them in with (a member it would take in
  // again is not let go: a body resting beside a sleeping pile went out and in every step and
  // woke the pile each time).
  std::vector<std::uint32_t> order(M);
  std::iota(order.begin(), order.end(), 0u);
  double ascale = 0.0, vmax = 0.0;
  for (std::size_t q = 0; q < M; ++q) {
    ascale = std::max(ascale, length(g.acc[q]));
    vmax = std::max(vmax, length(w.vel[g.members[q]]));
  }
  const auto reach = [&](std::size_t q) {
    const std::uint32_t m = g.members[q];
    const double own = length(w.vel[m]) * dt + (length(g.acc[q]) + 4.0 * ascale) * dt * dt;
    return std::max(own, 2.0 * vmax * dt + 5.0 * ascale * dt * dt) + w.radius[m];
  };
  std::sort(order.begin(), order.end(), [&](std::uint32_t l, std::uint32_t r) {
    const double xl = w.pos[g.members[l]].x - reach(l), xr = w.pos[g.members[r]].x - reach(r);
    return xl < xr || (xl == xr && l < r);
  });
  const double tol = 1e-9 * w.length_scale;
  for (std::size_t i = 0; i < M; ++i) {
    const std::uint32_t p = order[i];
    const Vec2 xp = w.pos[g.members[p]];
    const double rp = reach(p);
    for (std::size_t j = i + 1; j < M; ++j) {
      const std::uint32_t q = order[j];
      const Vec2 xq = w.pos[g.members[q]];
      const double rq = reach(q);
      if (xq.x - rq > xp.x + rp + tol) break;
      if (std::fabs(xq.x - xp.x) <= rp + rq + tol && std::fabs(xq.y - xp.y) <= rp + rq + tol) comp[find(p)] = find(q);
    }
  }
  std::vector<char> done(M, 0);
  for (std::size_t q = 0; q < M; ++q) {
    if (done[q]) continue;
    std::vector<std::size_t> part;
    for (std::size_t p = q; p < M; ++p) {
      if (!done[p] && find(p) == find(q)) {
        part.push_back(p);
        done[p] = 1;
      }
    }
    if (part.size() < 2) {   // touching no other member: the engine takes it back
      const std::uint32_t m = g.members[part.front()];
      w.flags[m] = static_cast<std::uint8_t>(w.flags[m] | kAlive);
      continue;
    }
    if (part.size() == M) {
      out.push_back(std::move(g));
      return;
    }
    Group h;
    h.granular = true;
    h.sleeping = g.sleeping;
    h.fresh = false;
    h.warm_h = g.warm_h;
    for (std::size_t p : part) {
      h.members.push_back(g.members[p]);
      h.acc.push_back(g.acc[p]);
    }
    std::vector<std::uint32_t> sorted = h.members;
    std::sort(sorted.begin(), sorted.end());
    const auto mine = [&](std::uint32_t b) { return std::binary_search(sorted.begin(), sorted.end(), b); };
    for (const World::GranularWarm& c : g.warm) {
      const std::uint32_t hi = static_cast<std::uint32_t>(c.key >> 32), lo = static_cast<std::uint32_t>(c.key);
      if (mine(hi)) h.warm.push_back(c);
      else if (!(lo & 0x80000000u) && mine(lo)) h.warm.push_back(c);
    }
    out.push_back(std::move(h));
  }
}

void note_storm_impact(World& w, std::uint32_t i, std::uint32_t j) {
  if (w.storm_count.size() != w.size()) w.storm_count.resize(w.size(), 0);
  for (std::uint32_t x : {i, j}) {
    if (w.storm_count[x]++ == 0) w.storm_bodies.push_back(x);
    if (w.storm_count[x] > kStormBail) w.storm_bail = true;
  }
}

static bool engage_storms(World& w, const StepContext& ctx, double t, bool now) {
  if (w.storm_bodies.empty()) return false;
  const double reach_dt = ctx.dt - t;   // what is left of the step (the next step's at its end)
  bool made = false;
  std::vector<std::uint32_t> hot;
  for (std::uint32_t x : w.storm_bodies) {
    if (w.storm_count[x] > kStormImpacts) hot.push_back(x);
    w.storm_count[x] = 0;
  }
  w.storm_bodies.clear();
  if (hot.empty() || !granular_allowed(w) || w.group_disturbed != kNone) return false;
  std::sort(hot.begin(), hot.end());
  std::vector<char> taken(w.size(), 0);
  for (const Group& g : w.contact_groups) {
    for (std::uint32_t m : g.members) taken[m] = 1;
  }
  for (std::uint32_t seed : hot) {
    if (taken[seed] || !w.dynamic(seed)) continue;
    if ((w.flags[seed] & (kPoint | kParticle | kDestroyOnHit)) != 0 || w.riding(seed) || seed >= w.scene_bodies) continue;
    std::vector<std::uint32_t> members{seed}, add;
    std::vector<std::size_t> merge;
    if (!plan_group_reach(w, members, now ? reach_dt : ctx.dt, static_cast<std::size_t>(-1), -1, add, merge, true)) continue;
    // (engaged now: a group already stepping in this step cannot take it; the storm goes on)
    if (now && !merge.empty()) continue;
    members.insert(members.end(), add.begin(), add.end());
    // groups it reaches: their members join this one
    std::sort(merge.begin(), merge.end());
    merge.erase(std::unique(merge.begin(), merge.end()), merge.end());
    for (std::size_t k : merge) {
      const Group& o = w.contact_groups[k];
      members.insert(members.end(), o.members.begin(), o.members.end());
    }
    std::sort(members.begin(), members.end());
    members.erase(std::unique(members.begin(), members.end()), members.end());
    if (members.size() < 2) continue;
    // a surface (faces with interpolated normals) within reach: the granular mode does not
    // model it; the event-driven engine keeps the storm
    double x0 = INFINITY, y0 = INFINITY, x1 = -INFINITY, y1 = -INFINITY;
    for (std::uint32_t m : members) {
      const double r = w.radius[m] + 2.0 * (length(w.vel[m]) * ctx.dt + length(group_force_acc(w, m)) * ctx.dt * ctx.dt);
      x0 = std::min(x0, w.pos[m].x - r);
      y0 = std::min(y0, w.pos[m].y - r);
      x1 = std::max(x1, w.pos[m].x + r);
      y1 = std::max(y1, w.pos[m].y + r);
    }
    w.found_static.clear();
    w.statics.query(make_aabb(x0, y0, x1, y1), w.found_static);
    const bool smooth = std::any_of(w.found_static.begin(), w.found_static.end(), [&](std::uint32_t k) {
      const Segment& sg = w.statics.segments[k];
      return length_squared(sg.normal_from) > 0.0 || length_squared(sg.normal_to) > 0.0;
    });
    if (smooth) continue;
    for (std::size_t k = merge.size(); k-- > 0;) {
      w.contact_groups.erase(w.contact_groups.begin() + static_cast<std::ptrdiff_t>(merge[k]));
    }
    Group g;
    g.granular = true;
    g.fresh = true;
    for (std::uint32_t m : members) {
      taken[m] = 1;
      if (w.supported(m)) release_support(w, m);
      w.released.clear();
      collect_dependents(w, m);
      for (std::uint32_t d : w.released) {
        if (w.supported(d)) release_support(w, d);
      }
      ++w.version[m];
      g.members.push_back(m);
      g.acc.push_back(group_force_acc(w, m));
    }
    if (w.group_first_time < 0.0) w.group_first_time = w.time + (now ? t : 0.0);
    if (now) {   // hidden from the rest of the step, stepped from t
      g.start = t;
      if (w.group_p0.size() != w.size()) {
        w.group_p0 = w.pos;
        w.group_v0 = w.vel;
      }
      for (std::uint32_t m : g.members) {
        w.group_p0[m] = w.pos[m];
        w.group_v0[m] = w.vel[m];
        w.flags[m] = static_cast<std::uint8_t>(w.flags[m] & ~kAlive);
      }
    }
    w.contact_groups.push_back(std::move(g));
    made = true;
  }
  return made;
}

void engage_storm_groups(World& w, const StepContext& ctx) { engage_storms(w, ctx, 0.0, false); }

bool engage_storm_groups_now(World& w, const StepContext& ctx, double t) { return engage_storms(w, ctx, t, true); }

}  // namespace physval::core_detail
