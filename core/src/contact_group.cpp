// The third contact mode (issue 9): a group of free bodies moving in persistent contact with
// each other and with the faces they touch, on the acceleration-level contact problem,
// between events. Engaged only where core's hold of a resting component cannot be justified
// (judge_braced_holds: rigid Coulomb says the component must move, e.g. a ball on two balls
// on a floor that cannot keep them from spreading), where core used to report a broken
// guarantee. Not exact: integrated by RK4 on sub-steps of dt / kSubsteps (order 4), each
// sub-step's end projected back onto the active constraints (positions, then velocities, to
// round-off). Events, located by bisection on the sub-step's own RK4 state: a contact's force
// reaching 0 (lift-off), a sticking contact's friction reaching its cone (slip), a sliding
// contact's slip reaching 0 (stop), and a gap closing (an impact: Newton's law on the touching
// contacts at once, frictionless; the contact joins the group if it stays closed). README,
// *Several supports and inelastic collapse*, "Bodies moving in contact".
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numeric>
#include <vector>

#include "world.hpp"

namespace physval::core_detail {

namespace {

constexpr int kSubsteps = 8;
constexpr std::size_t kMaxMembers = 16;
constexpr int kMaxEventsPerStep = 256;

using Group = World::ContactGroup;
using GC = World::GroupContact;

struct Geo {
  Vec2 n;            // unit, from a (or the face) towards b
  double gap = 0.0;
  double dist = 0.0;
  bool curved = false;   // a pair or a segment's end: the normal turns as they move
};

struct Ctx {
  World& w;
  Group& g;
  std::vector<double> inv, rad;
  double scale = 1.0;   // lengths
  double ascale = 0.0;  // the members' largest force acceleration
  double fscale = 0.0;  // the largest weight (m |a|)
};

Geo geometry(const Ctx& c, const GC& k, const std::vector<Vec2>& x) {
  Geo g;
  Vec2 d;
  double R = 0.0;
  const Vec2 pb = x[static_cast<std::size_t>(k.b)];
  if (k.a >= 0) {
    d = pb - x[static_cast<std::size_t>(k.a)];
    R = c.rad[static_cast<std::size_t>(k.a)] + c.rad[static_cast<std::size_t>(k.b)];
    g.curved = true;
  } else {
    const Segment& s = c.w.statics.segments[k.seg];
    const double u = dot(pb - s.from, s.dir);
    const double uc = std::clamp(u, 0.0, s.length);
    d = pb - (s.from + uc * s.dir);
    R = c.rad[static_cast<std::size_t>(k.b)];
    g.curved = !(u > 0.0 && u < s.length);
    if (!g.curved) {   // the face's own normal (no round-off in its direction)
      const double D = dot(d, s.normal);
      g.n = D >= 0.0 ? s.normal : -1.0 * s.normal;
      g.dist = std::fabs(D);
      g.gap = g.dist - R;
      return g;
    }
  }
  g.dist = length(d);
  g.n = g.dist > 0.0 ? (1.0 / g.dist) * d : Vec2{0.0, 1.0};
  g.gap = g.dist - R;
  return g;
}

Vec2 rel_vel(const GC& k, const std::vector<Vec2>& v) {
  return v[static_cast<std::size_t>(k.b)] - (k.a >= 0 ? v[static_cast<std::size_t>(k.a)] : Vec2{});
}

// Dense solve K u = r (n x n, row-major) by Gaussian elimination with partial pivoting; an
// unknown whose pivot vanishes (a redundant constraint) is 0.
void dense_solve(std::size_t n, std::vector<double>& K, std::vector<double>& r, std::vector<double>& u) {
  u.assign(n, 0.0);
  double kmax = 0.0;
  for (double x : K) kmax = std::max(kmax, std::fabs(x));
  std::vector<std::size_t> col_of_row(n, n);
  std::vector<char> used(n, 0);
  std::vector<std::size_t> order;
  // elimination by columns, pivot row chosen among unused rows
  for (std::size_t col = 0; col < n; ++col) {
    std::size_t best = n;
    double bv = 1e-12 * kmax;
    for (std::size_t row = 0; row < n; ++row) {
      if (used[row]) continue;
      if (std::fabs(K[row * n + col]) > bv) {
        bv = std::fabs(K[row * n + col]);
        best = row;
      }
    }
    if (best == n) continue;   // redundant: u[col] = 0
    used[best] = 1;
    col_of_row[best] = col;
    order.push_back(best);
    for (std::size_t row = 0; row < n; ++row) {
      if (row == best || used[row]) continue;
      const double f = K[row * n + col] / K[best * n + col];
      if (f == 0.0) continue;
      for (std::size_t j = col; j < n; ++j) K[row * n + j] -= f * K[best * n + j];
      r[row] -= f * r[best];
    }
  }
  for (std::size_t q = order.size(); q-- > 0;) {
    const std::size_t row = order[q];
    const std::size_t col = col_of_row[row];
    double s = r[row];
    for (std::size_t j = col + 1; j < n; ++j) s -= K[row * n + j] * u[j];
    u[col] = s / K[row * n + col];
  }
}

// The unknowns of a solve: contact index and whether tangential.
struct Unk {
  std::size_t k;
  bool tangent;
};

struct Solution {
  std::vector<Vec2> acc;
  std::vector<double> fn, ft;   // per contact: normal force, sticking friction (0 if none)
};

// Force direction (on b) of unknown u, and the row direction of unknown u.
Vec2 force_dir(const GC& k, const Geo& g, bool tangent) {
  const Vec2 t = perp(g.n);
  if (tangent) return t;
  if (!k.sticking && k.mu_k > 0.0 && k.slip != 0.0) return g.n - (k.mu_k * k.slip) * t;
  return g.n;
}

// The bilateral solve: every active contact closed (normal acceleration 0), every sticking
// one's tangential acceleration 0; sliding ones take mu_k f against their slip.
void bilateral(const Ctx& c, const std::vector<Vec2>& x, const std::vector<Vec2>& v, Solution& s) {
  const std::vector<GC>& ks = c.g.contacts;
  const std::size_t M = c.g.members.size();
  s.acc.assign(c.g.acc.begin(), c.g.acc.end());
  s.fn.assign(ks.size(), 0.0);
  s.ft.assign(ks.size(), 0.0);
  std::vector<Unk> us;
  std::vector<Geo> geo(ks.size());
  for (std::size_t k = 0; k < ks.size(); ++k) {
    if (!ks[k].active) continue;
    geo[k] = geometry(c, ks[k], x);
    us.push_back({k, false});
    if (ks[k].sticking) us.push_back({k, true});
  }
  const std::size_t n = us.size();
  if (n == 0) return;
  (void)M;
  std::vector<double> K(n * n), r(n), u;
  for (std::size_t row = 0; row < n; ++row) {
    const GC& kr = ks[us[row].k];
    const Geo& gr = geo[us[row].k];
    const Vec2 rd = us[row].tangent ? perp(gr.n) : gr.n;
    const Vec2 vr = rel_vel(kr, v);
    double curv = 0.0;
    if (gr.curved && gr.dist > 0.0) {
      const double vn = dot(vr, gr.n);
      const Vec2 ndot = (1.0 / gr.dist) * (vr - vn * gr.n);
      curv = us[row].tangent ? dot(perp(ndot), vr) : (length_squared(vr) - vn * vn) / gr.dist;
    }
    const Vec2 a0 = c.g.acc[static_cast<std::size_t>(kr.b)] - (kr.a >= 0 ? c.g.acc[static_cast<std::size_t>(kr.a)] : Vec2{});
    r[row] = -(dot(rd, a0) + curv);
    for (std::size_t col = 0; col < n; ++col) {
      const GC& kc = ks[us[col].k];
      const Vec2 D = force_dir(kc, geo[us[col].k], us[col].tangent);
      const auto effect = [&](std::int32_t body) {
        Vec2 e;
        if (body < 0) return e;
        const double im = c.inv[static_cast<std::size_t>(body)];
        if (body == kc.b) e += im * D;
        if (body == kc.a) e -= im * D;
        return e;
      };
      K[row * n + col] = dot(rd, effect(kr.b) - effect(kr.a));
    }
  }
  dense_solve(n, K, r, u);
  for (std::size_t q = 0; q < n; ++q) {
    const GC& kc = ks[us[q].k];
    const Vec2 D = u[q] * force_dir(kc, geo[us[q].k], us[q].tangent);
    s.acc[static_cast<std::size_t>(kc.b)] += c.inv[static_cast<std::size_t>(kc.b)] * D;
    if (kc.a >= 0) s.acc[static_cast<std::size_t>(kc.a)] -= c.inv[static_cast<std::size_t>(kc.a)] * D;
    (us[q].tangent ? s.ft : s.fn)[us[q].k] = u[q];
  }
}

double gap_tol(const Ctx& c) { return 1e-12 * c.scale; }

// The normal relative acceleration of contact k under accelerations acc (with its curvature).
double normal_acc(const Ctx& c, const GC& k, const std::vector<Vec2>& x, const std::vector<Vec2>& v,
                  const std::vector<Vec2>& acc) {
  const Geo g = geometry(c, k, x);
  const Vec2 vr = rel_vel(k, v);
  const double vn = dot(vr, g.n);
  const double curv = g.curved && g.dist > 0.0 ? (length_squared(vr) - vn * vn) / g.dist : 0.0;
  const Vec2 ar = acc[static_cast<std::size_t>(k.b)] - (k.a >= 0 ? acc[static_cast<std::size_t>(k.a)] : Vec2{});
  return dot(ar, g.n) + curv;
}

// Chooses the active contacts at a state (after an event): the touching, non-separating
// contacts, the rigid Coulomb LCP among them solved by projected Gauss-Seidel, then its active
// set made exact by the bilateral solve (contacts whose force comes out negative leave it,
// contacts the others would close join it). `exclude`: a contact that just lifted off.
void select_active(Ctx& c, const std::vector<Vec2>& x, const std::vector<Vec2>& v, std::size_t exclude) {
  std::vector<GC>& ks = c.g.contacts;
  double vmax = 0.0;
  for (const Vec2& q : v) vmax = std::max(vmax, length(q));
  const double vtol = 1e-9 * (vmax + c.ascale * c.w.group_dt) + 1e-15;
  std::vector<std::size_t> cand;
  std::vector<Geo> geo(ks.size());
  for (std::size_t k = 0; k < ks.size(); ++k) {
    ks[k].active = false;
    ks[k].sticking = false;
    if (k == exclude) continue;
    geo[k] = geometry(c, ks[k], x);
    const Vec2 vr = rel_vel(ks[k], v);
    if (geo[k].gap > 1e-9 * c.scale || dot(vr, geo[k].n) > vtol) continue;
    const double vt = dot(vr, perp(geo[k].n));
    if (std::fabs(vt) > vtol && ks[k].mu_k > 0.0) {
      ks[k].slip = vt > 0.0 ? 1.0 : -1.0;
    } else {
      ks[k].slip = 0.0;
    }
    cand.push_back(k);
  }
  if (cand.empty()) return;
  // Projected Gauss-Seidel on the candidates (normal rows; a tangential row boxed by mu_s f
  // where the contact does not slip).
  std::vector<double> fn(ks.size(), 0.0), ft(ks.size(), 0.0);
  std::vector<Vec2> acc(c.g.acc.begin(), c.g.acc.end());
  const auto apply = [&](const GC& k, Vec2 D) {
    acc[static_cast<std::size_t>(k.b)] += c.inv[static_cast<std::size_t>(k.b)] * D;
    if (k.a >= 0) acc[static_cast<std::size_t>(k.a)] -= c.inv[static_cast<std::size_t>(k.a)] * D;
  };
  const auto ainv = [&](const GC& k) {
    return c.inv[static_cast<std::size_t>(k.b)] + (k.a >= 0 ? c.inv[static_cast<std::size_t>(k.a)] : 0.0);
  };
  for (int it = 0; it < 20000; ++it) {
    double change = 0.0;
    for (std::size_t k : cand) {
      GC& kk = ks[k];
      const Geo& g = geo[k];
      const Vec2 t = perp(g.n);
      const Vec2 vr = rel_vel(kk, v);
      const double vn = dot(vr, g.n);
      const double curv = g.curved && g.dist > 0.0 ? (length_squared(vr) - vn * vn) / g.dist : 0.0;
      Vec2 ar = acc[static_cast<std::size_t>(kk.b)] - (kk.a >= 0 ? acc[static_cast<std::size_t>(kk.a)] : Vec2{});
      const Vec2 D = kk.slip != 0.0 ? g.n - (kk.mu_k * kk.slip) * t : g.n;
      const double nf = std::max(0.0, fn[k] - (dot(ar, g.n) + curv) / ainv(kk));
      if (nf != fn[k]) {
        apply(kk, (nf - fn[k]) * D);
        change = std::max(change, std::fabs(nf - fn[k]) * ainv(kk));
        fn[k] = nf;
      }
      if (kk.slip == 0.0 && kk.mu_s > 0.0) {
        ar = acc[static_cast<std::size_t>(kk.b)] - (kk.a >= 0 ? acc[static_cast<std::size_t>(kk.a)] : Vec2{});
        const double lim = kk.mu_s * fn[k];
        const double nt = std::clamp(ft[k] - dot(ar, t) / ainv(kk), -lim, lim);
        if (nt != ft[k]) {
          apply(kk, (nt - ft[k]) * t);
          change = std::max(change, std::fabs(nt - ft[k]) * ainv(kk));
          ft[k] = nt;
        }
      }
    }
    if (change <= 1e-15 * (c.ascale + 1e-300)) break;
  }
  const double ftol = 1e-9 * c.fscale;
  for (std::size_t k : cand) {
    GC& kk = ks[k];
    if (!(fn[k] > ftol)) continue;
    kk.active = true;
    if (kk.slip == 0.0 && kk.mu_s > 0.0) {
      if (std::fabs(ft[k]) < kk.mu_s * fn[k] * (1.0 - 1e-9)) {
        kk.sticking = true;
      } else {
        kk.slip = ft[k] > 0.0 ? -1.0 : 1.0;   // it slips against its friction
      }
    }
  }
  // The active set made exact.
  Solution s;
  for (std::size_t round = 0; round < 4 * ks.size() + 4; ++round) {
    bilateral(c, x, v, s);
    bool changed = false;
    for (std::size_t k : cand) {
      GC& kk = ks[k];
      if (kk.active && s.fn[k] < -ftol) {
        kk.active = false;
        kk.sticking = false;
        changed = true;
      } else if (kk.active && kk.sticking && std::fabs(s.ft[k]) > kk.mu_s * s.fn[k] + ftol) {
        kk.sticking = false;
        kk.slip = s.ft[k] > 0.0 ? -1.0 : 1.0;
        changed = true;
      } else if (!kk.active && normal_acc(c, kk, x, v, s.acc) < -1e-9 * (c.ascale + 1e-300)) {
        kk.active = true;
        kk.slip = kk.mu_k > 0.0 ? kk.slip : 0.0;
        changed = true;
      }
    }
    if (!changed) break;
  }
}

struct State {
  std::vector<Vec2> x, v;
};

// One RK4 step of length h from s (active set and slip directions fixed).
State rk4(const Ctx& c, const State& s, double h) {
  Solution a1, a2, a3, a4;
  bilateral(c, s.x, s.v, a1);
  const std::size_t M = s.x.size();
  State s2 = s, s3 = s, s4 = s, out = s;
  for (std::size_t i = 0; i < M; ++i) {
    s2.x[i] = s.x[i] + (0.5 * h) * s.v[i];
    s2.v[i] = s.v[i] + (0.5 * h) * a1.acc[i];
  }
  bilateral(c, s2.x, s2.v, a2);
  for (std::size_t i = 0; i < M; ++i) {
    s3.x[i] = s.x[i] + (0.5 * h) * s2.v[i];
    s3.v[i] = s.v[i] + (0.5 * h) * a2.acc[i];
  }
  bilateral(c, s3.x, s3.v, a3);
  for (std::size_t i = 0; i < M; ++i) {
    s4.x[i] = s.x[i] + h * s3.v[i];
    s4.v[i] = s.v[i] + h * a3.acc[i];
  }
  bilateral(c, s4.x, s4.v, a4);
  for (std::size_t i = 0; i < M; ++i) {
    out.x[i] = s.x[i] + (h / 6.0) * (s.v[i] + 2.0 * s2.v[i] + 2.0 * s3.v[i] + s4.v[i]);
    out.v[i] = s.v[i] + (h / 6.0) * (a1.acc[i] + 2.0 * a2.acc[i] + 2.0 * a3.acc[i] + a4.acc[i]);
  }
  return out;
}

// Projects positions (Newton on the active gaps, mass-weighted) and velocities (active normal
// speeds and sticking tangential speeds to 0, mass-weighted: kinetic energy never rises).
void project(const Ctx& c, State& s) {
  const std::vector<GC>& ks = c.g.contacts;
  std::vector<std::size_t> act;
  for (std::size_t k = 0; k < ks.size(); ++k) {
    if (ks[k].active) act.push_back(k);
  }
  if (act.empty()) return;
  const auto ainv_pair = [&](const GC& p, const GC& q, Vec2 dp, Vec2 dq) {
    double s2 = 0.0;
    if (p.b == q.b) s2 += c.inv[static_cast<std::size_t>(p.b)] * dot(dp, dq);
    if (p.a >= 0 && p.a == q.b) s2 -= c.inv[static_cast<std::size_t>(p.a)] * dot(dp, dq);
    if (q.a >= 0 && p.b == q.a) s2 -= c.inv[static_cast<std::size_t>(p.b)] * dot(dp, dq);
    if (p.a >= 0 && p.a == q.a) s2 += c.inv[static_cast<std::size_t>(p.a)] * dot(dp, dq);
    return s2;
  };
  const std::size_t n = act.size();
  std::vector<double> K(n * n), r(n), u;
  for (int it = 0; it < 4; ++it) {
    std::vector<Geo> g(n);
    double worst = 0.0;
    for (std::size_t q = 0; q < n; ++q) {
      g[q] = geometry(c, ks[act[q]], s.x);
      worst = std::max(worst, std::fabs(g[q].gap));
    }
    if (worst <= 4.0 * 2.220446049250313e-16 * c.scale) break;
    for (std::size_t p = 0; p < n; ++p) {
      r[p] = -g[p].gap;
      for (std::size_t q = 0; q < n; ++q) K[p * n + q] = ainv_pair(ks[act[p]], ks[act[q]], g[p].n, g[q].n);
    }
    dense_solve(n, K, r, u);
    for (std::size_t q = 0; q < n; ++q) {
      const GC& k = ks[act[q]];
      s.x[static_cast<std::size_t>(k.b)] += (u[q] * c.inv[static_cast<std::size_t>(k.b)]) * g[q].n;
      if (k.a >= 0) s.x[static_cast<std::size_t>(k.a)] -= (u[q] * c.inv[static_cast<std::size_t>(k.a)]) * g[q].n;
    }
  }
  // velocities
  std::vector<std::pair<std::size_t, Vec2>> rows;
  for (std::size_t k : act) {
    const Geo g = geometry(c, ks[k], s.x);
    rows.push_back({k, g.n});
    if (ks[k].sticking) rows.push_back({k, perp(g.n)});
  }
  const std::size_t m = rows.size();
  K.assign(m * m, 0.0);
  r.assign(m, 0.0);
  for (std::size_t p = 0; p < m; ++p) {
    r[p] = -dot(rel_vel(ks[rows[p].first], s.v), rows[p].second);
    for (std::size_t q = 0; q < m; ++q) {
      K[p * m + q] = ainv_pair(ks[rows[p].first], ks[rows[q].first], rows[p].second, rows[q].second);
    }
  }
  dense_solve(m, K, r, u);
  for (std::size_t q = 0; q < m; ++q) {
    const GC& k = ks[rows[q].first];
    s.v[static_cast<std::size_t>(k.b)] += (u[q] * c.inv[static_cast<std::size_t>(k.b)]) * rows[q].second;
    if (k.a >= 0) s.v[static_cast<std::size_t>(k.a)] -= (u[q] * c.inv[static_cast<std::size_t>(k.a)]) * rows[q].second;
  }
}

// Events: which have happened by a state (the sub-step's end).
enum class Ev { LiftOff, Slip, Stop, Impact };
struct GEvent {
  Ev kind;
  std::size_t k;
};

void events_at(const Ctx& c, const State& s, const std::vector<double>& gap0, std::vector<GEvent>& out) {
  out.clear();
  Solution sol;
  bilateral(c, s.x, s.v, sol);
  const std::vector<GC>& ks = c.g.contacts;
  const double ftol = 1e-9 * c.fscale;
  for (std::size_t k = 0; k < ks.size(); ++k) {
    const GC& kk = ks[k];
    if (kk.active) {
      if (sol.fn[k] < -ftol) out.push_back({Ev::LiftOff, k});
      if (kk.sticking) {
        if (kk.mu_s * sol.fn[k] - std::fabs(sol.ft[k]) < -ftol) out.push_back({Ev::Slip, k});
      } else if (kk.slip != 0.0) {
        const Geo g = geometry(c, kk, s.x);
        if (kk.slip * dot(rel_vel(kk, s.v), perp(g.n)) < 0.0) out.push_back({Ev::Stop, k});
      }
    } else {
      const Geo g = geometry(c, kk, s.x);
      // an impact: the gap closes below its value at the sub-step's start (and below 0)
      if (g.gap < -gap_tol(c) && g.gap < gap0[k]) out.push_back({Ev::Impact, k});
    }
  }
}

// Whether event e has happened by state s.
bool happened(const Ctx& c, const State& s, GEvent e) {
  const GC& kk = c.g.contacts[e.k];
  if (e.kind == Ev::Impact) return geometry(c, kk, s.x).gap < -0.5 * gap_tol(c);
  if (e.kind == Ev::Stop) return kk.slip * dot(rel_vel(kk, s.v), perp(geometry(c, kk, s.x).n)) < 0.0;
  Solution sol;
  bilateral(c, s.x, s.v, sol);
  if (e.kind == Ev::LiftOff) return sol.fn[e.k] < 0.0;
  return kk.mu_s * sol.fn[e.k] - std::fabs(sol.ft[e.k]) < 0.0;
}

// Newton's law on the touching contacts at once (frictionless), after contact `seed` closed.
// Returns false where friction would act on a sliding contact taking an impulse (not modelled).
bool impact(Ctx& c, State& s, std::size_t seed) {
  std::vector<GC>& ks = c.g.contacts;
  double vmax = 0.0;
  for (const Vec2& q : s.v) vmax = std::max(vmax, length(q));
  const double vtol = 1e-9 * (vmax + c.ascale * c.w.group_dt) + 1e-15;
  std::vector<std::size_t> set;
  std::vector<Geo> geo(ks.size());
  std::vector<double> target(ks.size(), 0.0), P(ks.size(), 0.0);
  for (std::size_t k = 0; k < ks.size(); ++k) {
    geo[k] = geometry(c, ks[k], s.x);
    if (k != seed && !ks[k].active && geo[k].gap > 1e-9 * c.scale) continue;
    const double vn = dot(rel_vel(ks[k], s.v), geo[k].n);
    if (k != seed && !ks[k].active && vn >= -vtol) continue;
    set.push_back(k);
  }
  for (std::size_t k : set) {
    const double vn = dot(rel_vel(ks[k], s.v), geo[k].n);
    // Newton's restitution only for a lone contact: on several at once it can raise the
    // energy (the engine's simultaneous law guards that; here they meet perfectly inelastically)
    double e = set.size() == 1 ? ks[k].e : 0.0;
    // slower than the rest speed of its pressing acceleration: perfectly inelastic (the
    // collapse threshold of every impact in core)
    const double an = std::fabs(dot(c.g.acc[static_cast<std::size_t>(ks[k].b)], geo[k].n));
    if (-vn < c.w.rest_speed(std::max(an, c.ascale), c.w.group_dt) && e < 1.0) e = 0.0;
    target[k] = vn < -vtol ? -e * vn : 0.0;
  }
  const auto ainv = [&](const GC& k) {
    return c.inv[static_cast<std::size_t>(k.b)] + (k.a >= 0 ? c.inv[static_cast<std::size_t>(k.a)] : 0.0);
  };
  for (int it = 0; it < 20000; ++it) {
    double change = 0.0;
    for (std::size_t k : set) {
      const GC& kk = ks[k];
      const double vn = dot(rel_vel(kk, s.v), geo[k].n);
      const double np = std::max(0.0, P[k] + (target[k] - vn) / ainv(kk));
      const double d = np - P[k];
      if (d == 0.0) continue;
      P[k] = np;
      s.v[static_cast<std::size_t>(kk.b)] += (d * c.inv[static_cast<std::size_t>(kk.b)]) * geo[k].n;
      if (kk.a >= 0) s.v[static_cast<std::size_t>(kk.a)] -= (d * c.inv[static_cast<std::size_t>(kk.a)]) * geo[k].n;
      change = std::max(change, std::fabs(d) * ainv(kk));
    }
    if (change <= 1e-15 * (vmax + 1e-300)) break;
  }
  for (std::size_t k : set) {
    const GC& kk = ks[k];
    if (P[k] > 0.0 && kk.mu_k > 0.0 && std::fabs(dot(rel_vel(kk, s.v), perp(geo[k].n))) > vtol) return false;
  }
  return true;
}

void load_state(const Group& g, const World& w, State& s) {
  s.x.clear();
  s.v.clear();
  for (std::uint32_t m : g.members) {
    s.x.push_back(w.pos[m]);
    s.v.push_back(w.vel[m]);
  }
}

// The group's contacts with the faces near box (kept active/sticking where they were).
// False where a face near the group has interpolated normals (a surface's smooth normals,
// which the mode does not model).
bool refresh_faces(World& w, Group& g, Aabb box) {
  std::vector<GC> keep;
  for (const GC& k : g.contacts) {
    if (k.a >= 0 || k.active) keep.push_back(k);
  }
  w.found_static.clear();
  w.statics.query(box, w.found_static);
  std::sort(w.found_static.begin(), w.found_static.end());
  for (std::uint32_t s : w.found_static) {
    for (std::size_t q = 0; q < g.members.size(); ++q) {
      const bool have = std::any_of(keep.begin(), keep.end(), [&](const GC& k) {
        return k.a < 0 && k.seg == s && k.b == static_cast<std::int32_t>(q);
      });
      if (have) continue;
      const PairMaterial m = w.pair_material(w.material[g.members[q]], w.statics.segments[s].material);
      GC k;
      k.a = -1;
      k.b = static_cast<std::int32_t>(q);
      k.seg = s;
      k.mu_k = m.friction;
      k.mu_s = std::max(m.friction, m.static_friction);
      k.e = m.restitution;
      keep.push_back(k);
    }
  }
  g.contacts = std::move(keep);
  for (std::uint32_t k : w.found_static) {
    const Segment& sg = w.statics.segments[k];
    if (length_squared(sg.normal_from) > 0.0 || length_squared(sg.normal_to) > 0.0) return false;
  }
  return true;
}

struct Box {
  double x0 = INFINITY, y0 = INFINITY, x1 = -INFINITY, y1 = -INFINITY;
  void add(Box b) {
    x0 = std::min(x0, b.x0);
    y0 = std::min(y0, b.y0);
    x1 = std::max(x1, b.x1);
    y1 = std::max(y1, b.y1);
  }
  bool contains(Box b) const { return b.x0 >= x0 && b.y0 >= y0 && b.x1 <= x1 && b.y1 <= y1; }
  bool overlaps(Box b) const { return x0 <= b.x1 && b.x0 <= x1 && y0 <= b.y1 && b.y0 <= y1; }
};

Box box_of(const World& w, const std::vector<std::uint32_t>& members, const State& s, double pad) {
  Box b;
  for (std::size_t q = 0; q < members.size(); ++q) {
    const double r = w.radius[members[q]] + pad;
    b.add({s.x[q].x - r, s.x[q].y - r, s.x[q].x + r, s.x[q].y + r});
  }
  return b;
}

Ctx make_ctx(World& w, Group& g) {
  Ctx c{w, g, {}, {}};
  for (std::uint32_t m : g.members) {
    c.inv.push_back(w.inv_mass[m]);
    c.rad.push_back(w.radius[m]);
  }
  c.scale = w.length_scale;
  for (std::size_t q = 0; q < g.members.size(); ++q) {
    c.scale = std::max(c.scale, c.rad[q]);
    c.ascale = std::max(c.ascale, length(g.acc[q]));
    c.fscale = std::max(c.fscale, length(g.acc[q]) / c.inv[q]);
  }
  return c;
}

void set_alive(World& w, const Group& g, bool alive) {
  for (std::uint32_t m : g.members) {
    w.flags[m] = static_cast<std::uint8_t>(alive ? (w.flags[m] | kAlive) : (w.flags[m] & ~kAlive));
  }
}

}  // namespace

static void apply_absorb(World& w, Group& g, const std::vector<std::uint32_t>& add);

bool contact_groups_allowed(const World& w) {
  return w.mode == CollisionMode::Exact && !w.varying_forces && !w.any_rules && w.emitters.empty() && !w.acc.empty() &&
         !w.newtonian;
}

bool granular_allowed(const World& w) {
  return w.mode == CollisionMode::Exact && !w.any_rules && w.emitters.empty() && !w.acc.empty() && !w.newtonian &&
         w.granular_enabled;
}

// How far body i can go in a step of dt (its speed, its force and a contact's push).
static double reach_of(const World& w, std::uint32_t i, double dt, double ascale) {
  const double a = w.acc.empty() ? 0.0 : length(group_force_acc(w, i));
  return length(w.vel[i]) * dt + (a + 4.0 * ascale) * dt * dt;
}

static void to_granular(Group& g) {
  g.granular = true;
  g.contacts.clear();
  g.sleeping = false;
  g.fresh = true;
}

// Takes group o's members (and warm impulses) into g, which becomes granular.
static void merge_into(Group& g, Group& o) {
  to_granular(g);
  g.members.insert(g.members.end(), o.members.begin(), o.members.end());
  g.acc.insert(g.acc.end(), o.acc.begin(), o.acc.end());
  g.warm.insert(g.warm.end(), o.warm.begin(), o.warm.end());
  std::sort(g.warm.begin(), g.warm.end(),
            [](const World::GranularWarm& l, const World::GranularWarm& r) { return l.key < r.key; });
  if (g.warm_h == 0.0) g.warm_h = o.warm_h;
  o.members.clear();
  o.acc.clear();
}

bool plan_group_reach(const World& w, const std::vector<std::uint32_t>& members, double dt, std::size_t limit,
                      std::ptrdiff_t exclude_group, std::vector<std::uint32_t>& add, std::vector<std::size_t>& merge,
                      bool statics_ok) {
  add.clear();
  merge.clear();
  const std::size_t N = w.size();
  thread_local std::vector<std::int32_t> gid;
  thread_local std::vector<char> in;
  gid.assign(N, -1);
  in.assign(N, 0);
  for (std::size_t k = 0; k < w.contact_groups.size(); ++k) {
    for (std::uint32_t m : w.contact_groups[k].members) gid[m] = static_cast<std::int32_t>(k);
  }
  double ascale = 0.0, vmax = 0.0;
  for (std::uint32_t m : members) {
    in[m] = 1;
    ascale = std::max(ascale, w.acc.empty() ? 0.0 : length(group_force_acc(w, m)));
    vmax = std::max(vmax, length(w.vel[m]));
  }
  // A member's reach: its own (speed, force, a contact's push); in a granular group an impulse
  // may pass a body up to twice the group's fastest speed, so every member gets that.
  const auto member_reach = [&](std::uint32_t m) {
    const double own = reach_of(w, m, dt, ascale);
    return statics_ok ? std::max(own, 2.0 * vmax * dt + 5.0 * ascale * dt * dt) : own;
  };
  std::size_t total = members.size();
  const double tol = 1e-9 * w.length_scale;
  std::vector<std::uint32_t> frontier = members, next;
  while (!frontier.empty()) {
    double x0 = INFINITY, y0 = INFINITY, x1 = -INFINITY, y1 = -INFINITY;
    for (std::uint32_t m : frontier) {
      const double r = w.radius[m] + member_reach(m);
      x0 = std::min(x0, w.pos[m].x - r);
      y0 = std::min(y0, w.pos[m].y - r);
      x1 = std::max(x1, w.pos[m].x + r);
      y1 = std::max(y1, w.pos[m].y + r);
    }
    next.clear();
    for (std::uint32_t j = 0; j < N; ++j) {
      if (in[j]) continue;
      const bool other = gid[j] >= 0 && gid[j] != exclude_group;
      if (!w.alive(j) && !other) continue;
      const double rj = w.radius[j] + reach_of(w, j, dt, ascale) + tol;
      const Vec2 pj = w.pos[j];
      if (pj.x + rj < x0 || pj.x - rj > x1 || pj.y + rj < y0 || pj.y - rj > y1) continue;
      // (boxes, not circles: the check after the step, check_reach, compares boxes)
      bool near = false;
      for (std::uint32_t m : frontier) {
        const double rm = w.radius[m] + member_reach(m);
        if (std::fabs(pj.x - w.pos[m].x) <= rm + rj && std::fabs(pj.y - w.pos[m].y) <= rm + rj) {
          near = true;
          break;
        }
      }
      if (!near) continue;
      if (w.is_static(j)) {   // a fixed contact of a granular group; the exact mode has none
        if (statics_ok) continue;
        return false;
      }
      if (other) {   // a group within reach: merged whole
        const std::size_t k = static_cast<std::size_t>(gid[j]);
        merge.push_back(k);
        for (std::uint32_t m : w.contact_groups[k].members) {
          in[m] = 1;
          next.push_back(m);
          ++total;
        }
        if (total > limit) return false;
        continue;
      }
      if (!w.dynamic(j) || j >= w.scene_bodies || (w.flags[j] & (kPoint | kParticle | kDestroyOnHit)) != 0) return false;
      if (w.riding(j)) return false;
      in[j] = 1;
      add.push_back(j);
      next.push_back(j);
      if (++total > limit) return false;
    }
    frontier.swap(next);
  }
  return true;
}

bool engage_contact_group(World& w, std::span<const std::uint32_t> members) {
  const bool exact_ok = contact_groups_allowed(w);
  if (!exact_ok && !granular_allowed(w)) return false;
  if (members.size() < 2) return false;
  for (std::uint32_t m : members) {
    if (!w.dynamic(m) || m >= w.scene_bodies || (w.flags[m] & (kPoint | kParticle | kDestroyOnHit)) != 0) return false;
    if (w.riding(m)) return false;
    if (!(length(w.vel[m]) == 0.0)) return false;   // at rest (held or stuck)
  }
  if (w.group_disturbed != kNone) return false;   // once the mode failed, the old report
  Group g;
  g.members.assign(members.begin(), members.end());
  std::vector<std::uint32_t> add;
  std::vector<std::size_t> merge;
  // The exact group mode up to kMaxMembers bodies, nothing static or another group within
  // reach; a larger group is granular (granular.cpp).
  bool granular = !exact_ok || members.size() > kMaxMembers ||
                  !plan_group_reach(w, g.members, w.group_dt, kMaxMembers, -1, add, merge, false) || !merge.empty();
  if (granular && (!granular_allowed(w) ||
                   !plan_group_reach(w, g.members, w.group_dt, static_cast<std::size_t>(-1), -1, add, merge, true))) {
    return false;
  }
  for (std::uint32_t m : g.members) {
    release_support(w, m);
    // bodies resting on a member are released too (judged free next step)
    w.released.clear();
    collect_dependents(w, m);
    for (std::uint32_t d : w.released) {
      if (std::find(g.members.begin(), g.members.end(), d) == g.members.end() && w.supported(d)) release_support(w, d);
    }
    ++w.version[m];
    g.acc.push_back(group_force_acc(w, m));
  }
  if (granular) {
    to_granular(g);
  } else {
    for (std::size_t p = 0; p < g.members.size(); ++p) {
      for (std::size_t q = p + 1; q < g.members.size(); ++q) {
        const PairMaterial m = w.pair_material(w.material[g.members[p]], w.material[g.members[q]]);
        GC k;
        k.a = static_cast<std::int32_t>(p);
        k.b = static_cast<std::int32_t>(q);
        k.mu_k = m.friction;
        k.mu_s = std::max(m.friction, m.static_friction);
        k.e = m.restitution;
        g.contacts.push_back(k);
      }
    }
  }
  g.fresh = true;
  if (w.group_p0.size() != w.size()) {   // engaged at the step's start: nobody has moved yet
    w.group_p0 = w.pos;
    w.group_v0 = w.vel;
  }
  if (w.group_first_time < 0.0) w.group_first_time = w.time;
  apply_absorb(w, g, add);   // free bodies that may meet it in this step join it
  std::sort(merge.begin(), merge.end());
  for (std::size_t k = merge.size(); k-- > 0;) {
    merge_into(g, w.contact_groups[merge[k]]);
    w.contact_groups.erase(w.contact_groups.begin() + static_cast<std::ptrdiff_t>(merge[k]));
  }
  w.contact_groups.push_back(std::move(g));
  set_alive(w, w.contact_groups.back(), false);
  return true;
}

static void apply_absorb(World& w, Group& g, const std::vector<std::uint32_t>& add) {
  for (std::uint32_t j : add) {
    if (w.supported(j)) release_support(w, j);
    w.released.clear();
    collect_dependents(w, j);
    for (std::uint32_t d : w.released) {
      if (w.supported(d)) release_support(w, d);
    }
    ++w.version[j];
    if (!g.granular) {
      const std::int32_t nj = static_cast<std::int32_t>(g.members.size());
      for (std::size_t p = 0; p < g.members.size(); ++p) {
        const PairMaterial mat = w.pair_material(w.material[g.members[p]], w.material[j]);
        GC k;
        k.a = static_cast<std::int32_t>(p);
        k.b = nj;
        k.mu_k = mat.friction;
        k.mu_s = std::max(mat.friction, mat.static_friction);
        k.e = mat.restitution;
        g.contacts.push_back(k);
      }
    }
    g.members.push_back(j);
    g.acc.push_back(group_force_acc(w, j));
    g.fresh = true;
  }
}

void hide_contact_groups(World& w, const StepContext& ctx) {
  w.group_dt = ctx.dt;
  // A body that may meet a group in this step joins it (a group within reach merges with it);
  // where one cannot, the group is given back to the engine (its members free, at their
  // state) and the run reports a broken guarantee: core cannot run that group.
  std::vector<std::uint32_t> add;
  std::vector<std::size_t> merge;
  for (Group& g : w.contact_groups) set_alive(w, g, true);
  std::vector<char> gone(w.contact_groups.size(), 0);
  const std::size_t unlimited = static_cast<std::size_t>(-1);
  for (std::size_t q = 0; q < w.contact_groups.size(); ++q) {
    if (gone[q]) continue;
    Group& g = w.contact_groups[q];
    const auto self = static_cast<std::ptrdiff_t>(q);
    bool ok = false;
    if (w.group_disturbed == kNone) {
      ok = plan_group_reach(w, g.members, ctx.dt, g.granular ? unlimited : kMaxMembers, self, add, merge, g.granular);
      if (!ok && !g.granular && granular_allowed(w) &&
          plan_group_reach(w, g.members, ctx.dt, unlimited, self, add, merge, true)) {
        to_granular(g);   // over kMaxMembers, or something static within reach: granular from here
        ok = true;
      }
      if (ok && !merge.empty() && !w.granular_enabled) ok = false;   // (exact groups do not merge)
    }
    if (ok) {
      if (!merge.empty()) to_granular(g);
      apply_absorb(w, g, add);
      for (std::size_t k : merge) {
        if (k == q || gone[k]) continue;
        merge_into(g, w.contact_groups[k]);
        gone[k] = 1;
      }
      continue;
    }
    gone[q] = 1;
    if (w.group_disturbed == kNone) {
      w.group_disturbed = g.members.front();
      w.group_disturbed_time = ctx.t0;
      w.group_why = "a body that may meet it cannot join it (a particle or point, or on a corner's cap)";
    }
  }
  std::vector<Group> keep;
  for (std::size_t q = 0; q < w.contact_groups.size(); ++q) {
    if (!gone[q]) keep.push_back(std::move(w.contact_groups[q]));
  }
  w.contact_groups = std::move(keep);
  for (const Group& g : w.contact_groups) set_alive(w, g, false);
  w.group_p0 = w.pos;
  w.group_v0 = w.vel;
}

// Anything else within reach of a group's swept box after its step: core does not find
// impacts of other bodies with a group (a broken guarantee, as for a body riding a corner's cap).
// With member_boxes (a granular group's, 4 numbers a member), a body must reach one member's box.
static void check_reach(World& w, const Box& swept, const StepContext& ctx, double scale,
                        const std::vector<double>* member_boxes = nullptr) {
  const double tol = 1e-9 * scale;
  for (std::uint32_t j = 0; j < w.size() && w.group_disturbed == kNone; ++j) {
    if (!w.alive(j)) continue;
    // a granular group's static neighbours are its fixed contacts (granular_step checks them)
    if (member_boxes != nullptr && w.is_static(j)) continue;
    const Vec2 p0 = w.group_p0[j], p1 = w.pos[j];
    const Vec2 p2 = p0 + ctx.dt * w.group_v0[j];
    const double r = w.radius[j] + (w.acc.empty() ? 0.0 : length(group_force_acc(w, j))) * ctx.dt * ctx.dt + tol;
    const Box bj{std::min({p0.x, p1.x, p2.x}) - r, std::min({p0.y, p1.y, p2.y}) - r,
                 std::max({p0.x, p1.x, p2.x}) + r, std::max({p0.y, p1.y, p2.y}) + r};
    bool hit = bj.overlaps(swept);
    if (hit && member_boxes != nullptr) {
      hit = false;
      for (std::size_t q = 0; 4 * q < member_boxes->size() && !hit; ++q) {
        const double* b = &(*member_boxes)[4 * q];
        hit = bj.overlaps(Box{b[0], b[1], b[2], b[3]});
      }
    }
    if (hit) {
      w.group_disturbed = j;
      w.group_disturbed_time = ctx.t0;
      w.group_why = "body '" + w.name(j) + "' came within reach of it (core finds no impacts of other bodies with a group)";
    }
  }
}

// A granular group's step (granular.cpp), then its split.
static void advance_granular(World& w, Group& g, const StepContext& ctx_step, std::vector<Group>& next, Box& swept) {
  // a group engaged inside this step (an impact storm) takes what is left of it
  StepContext ctx = ctx_step;
  if (g.start > 0.0) {
    ctx.t0 += g.start;
    ctx.dt -= g.start;
    g.start = 0.0;
  }
  std::vector<Vec2> p0, v0;
  for (std::uint32_t m : g.members) {
    p0.push_back(w.pos[m]);
    v0.push_back(w.vel[m]);
  }
  std::vector<double> boxes;
  const bool was_disturbed = w.group_disturbed != kNone;
  granular_step(w, g, ctx, boxes);
  swept = Box{};
  for (std::size_t q = 0; 4 * q < boxes.size(); ++q) swept.add(Box{boxes[4 * q], boxes[4 * q + 1], boxes[4 * q + 2], boxes[4 * q + 3]});
  check_reach(w, swept, ctx, w.length_scale, &boxes);
  if (!was_disturbed && w.group_disturbed != kNone) {   // undone: the engine takes them back
    for (std::size_t q = 0; q < g.members.size(); ++q) {
      w.pos[g.members[q]] = p0[q];
      w.vel[g.members[q]] = v0[q];
    }
  }
  granular_split(w, g, ctx.dt, next);
}

// One group's step (exact or granular); the groups it splits into are appended to `next`,
// the box its members swept to swept_out.
static void step_group(World& w, Group& g, const StepContext& ctx, std::vector<Group>& next, Box& swept_out) {
  if (g.granular) {
    advance_granular(w, g, ctx, next, swept_out);
    return;
  }
  bool convert = false;   // the exact mode cannot take this step: granular from here
  Ctx c = make_ctx(w, g);
  State s;
  load_state(g, w, s);
  const State s_start = s;
  const bool was_disturbed = w.group_disturbed != kNone;
  double vmax = 0.0;
  for (const Vec2& q : s.v) vmax = std::max(vmax, length(q));
  double pad = vmax * ctx.dt + 4.0 * c.ascale * ctx.dt * ctx.dt + 1e-9 * c.scale;
  Box swept;
  std::vector<double> mboxes;   // each member's swept box (x0, y0, x1, y1)
  std::vector<GEvent> evs;
  for (int attempt = 0; attempt < 8; ++attempt) {
    s = s_start;
    const Box qbox = box_of(w, g.members, s, pad);
    if (!refresh_faces(w, g, make_aabb(qbox.x0, qbox.y0, qbox.x1, qbox.y1)) && w.group_disturbed == kNone) {
      w.group_disturbed = g.members.front();
      w.group_disturbed_time = ctx.t0;
      w.group_why = "a face near it has interpolated normals (a surface), which the mode does not model";
    }
    if (g.fresh || attempt > 0) {
      select_active(c, s.x, s.v, g.contacts.size());
      g.fresh = false;
    }
    swept = box_of(w, g.members, s, 0.0);
    mboxes.assign(4 * g.members.size(), 0.0);
    for (std::size_t q = 0; q < g.members.size(); ++q) {
      const double r = w.radius[g.members[q]];
      mboxes[4 * q] = s.x[q].x - r;
      mboxes[4 * q + 1] = s.x[q].y - r;
      mboxes[4 * q + 2] = s.x[q].x + r;
      mboxes[4 * q + 3] = s.x[q].y + r;
    }
    const double h0 = ctx.dt / kSubsteps;
    double t = 0.0;
    int events = 0;
    for (int sub = 1; sub <= kSubsteps && !convert; ++sub) {
      const double t_end = ctx.dt * sub / kSubsteps;
      while (t < t_end && !convert) {
        const double h = t_end - t;
        std::vector<double> gap0(g.contacts.size());
        for (std::size_t k = 0; k < g.contacts.size(); ++k) gap0[k] = geometry(c, g.contacts[k], s.x).gap;
        State e = rk4(c, s, h);
        events_at(c, e, gap0, evs);
        double tau = h;
        GEvent first{Ev::Impact, g.contacts.size()};
        if (!evs.empty() && events < kMaxEventsPerStep) {
          for (const GEvent& ev : evs) {   // the earliest, by bisection on the sub-step's RK4 state
            double lo = 0.0, hi = tau;
            if (!happened(c, rk4(c, s, hi), ev)) continue;
            for (int it = 0; it < 200 && hi - lo > 1e-15 * h0; ++it) {
              const double mid = 0.5 * (lo + hi);
              if (happened(c, rk4(c, s, mid), ev)) {
                hi = mid;
              } else {
                lo = mid;
              }
            }
            if (hi < tau || first.k == g.contacts.size()) {
              tau = hi;
              first = ev;
            }
          }
          e = rk4(c, s, tau);
        } else if (!evs.empty()) {
          convert = true;   // more events than a step may take (impacts that cycle)
        }
        double vm = 0.0;
        for (const Vec2& q : e.v) vm = std::max(vm, length(q));
        swept.add(box_of(w, g.members, e, vm * tau));
        for (std::size_t q = 0; q < g.members.size(); ++q) {   // each member's own box too
          const double r = w.radius[g.members[q]] + vm * tau;
          mboxes[4 * q] = std::min(mboxes[4 * q], e.x[q].x - r);
          mboxes[4 * q + 1] = std::min(mboxes[4 * q + 1], e.x[q].y - r);
          mboxes[4 * q + 2] = std::max(mboxes[4 * q + 2], e.x[q].x + r);
          mboxes[4 * q + 3] = std::max(mboxes[4 * q + 3], e.x[q].y + r);
        }
        project(c, e);
        s = e;
        t = tau >= h ? t_end : t + tau;
        if (first.k < g.contacts.size()) {
          ++events;
          ++w.group_events;
          std::size_t exclude = g.contacts.size();
          if (first.kind == Ev::LiftOff) exclude = first.k;
          if (first.kind == Ev::Stop) g.contacts[first.k].slip = 0.0;
          if (first.kind == Ev::Impact) {   // a contact begins (or continues, within a step)
            const GC& kk = g.contacts[first.k];
            const std::uint32_t mb = g.members[static_cast<std::size_t>(kk.b)];
            if (kk.a >= 0) {
              record_contact(w, mb, g.members[static_cast<std::size_t>(kk.a)], nullptr, ctx.t0 + t, ctx.dt);
            } else {
              record_contact(w, mb, kNone, &w.statics.segments[kk.seg], ctx.t0 + t, ctx.dt);
            }
          }
          if (first.kind == Ev::Impact && !impact(c, s, first.k)) {
            convert = true;   // an impulse on a sliding contact with friction: not modelled here
          }
          select_active(c, s.x, s.v, exclude);
        }
      }
    }
    if (convert || qbox.contains(swept)) break;
    pad *= 4.0;
  }
  if (convert && granular_allowed(w)) {   // the step again, granular (nothing written yet)
    to_granular(g);
    advance_granular(w, g, ctx, next, swept_out);
    return;
  }
  if (convert && w.group_disturbed == kNone) {
    w.group_disturbed = g.members.front();
    w.group_disturbed_time = ctx.t0;
    w.group_why = "the exact group mode could not take its step (impacts that cycle, or an impulse on a sliding "
                  "contact with friction)";
  }
  check_reach(w, swept, ctx, c.scale, &mboxes);
  swept_out = swept;
  // The mode failed in this step (a broken guarantee is reported): the group's step is undone
  // (its members at their state at the step's start, which overlaps nothing) and the engine
  // takes them back at the step's end.
  if (!was_disturbed && w.group_disturbed != kNone) {
    s = s_start;
  } else if (w.group_disturbed == kNone) {
    ++w.group_steps;
  }
  // Contacts touching at the step's end continue (no new contact event when the engine
  // takes the bodies back).
  for (const GC& k : g.contacts) {
    if (!k.active && geometry(c, k, s.x).gap > 1e-9 * c.scale) continue;
    const std::uint32_t mb = g.members[static_cast<std::size_t>(k.b)];
    touch_contact(w, mb, k.a >= 0 ? g.members[static_cast<std::size_t>(k.a)]
                                  : static_partner_key(w.statics.segments[k.seg].owner),
                  ctx.t0 + ctx.dt);
  }
  for (std::size_t q = 0; q < g.members.size(); ++q) {
    const std::uint32_t m = g.members[q];
    w.pos[m] = s.x[q];
    w.vel[m] = s.v[q];
    w.tloc[m] = 0.0;
    w.apath[m] = group_force_acc(w, m);
    ++w.version[m];
  }
  // Split: members touching (transitively) stay a group; a member touching none leaves it.
  // A group at rest (every speed 0 and its contacts hold it) leaves whole, to the hold.
  const std::size_t M = g.members.size();
  std::vector<std::size_t> comp(M);
  std::iota(comp.begin(), comp.end(), 0);
  const auto find = [&](std::size_t a) {
    while (comp[a] != a) a = comp[a] = comp[comp[a]];
    return a;
  };
  for (const GC& k : g.contacts) {
    if (k.a < 0) continue;
    // members that may meet within the next step stay together (its reach from their state now)
    const std::uint32_t ma = g.members[static_cast<std::size_t>(k.a)], mb = g.members[static_cast<std::size_t>(k.b)];
    const double reach = reach_of(w, ma, ctx.dt, c.ascale) + reach_of(w, mb, ctx.dt, c.ascale) + 1e-9 * c.scale;
    if (k.active || geometry(c, k, s.x).gap <= reach) {
      comp[find(static_cast<std::size_t>(k.a))] = find(static_cast<std::size_t>(k.b));
    }
  }
  bool at_rest = true;
  for (const Vec2& q : s.v) at_rest = at_rest && length(q) <= 1e-12 * (c.ascale * ctx.dt + 1e-300);
  if (at_rest) {
    Solution sol;
    bilateral(c, s.x, s.v, sol);
    for (const Vec2& a : sol.acc) at_rest = at_rest && length(a) <= 1e-9 * c.ascale;
  }
  std::vector<char> done(M, 0);
  for (std::size_t q = 0; q < M; ++q) {
    if (done[q]) continue;
    std::vector<std::size_t> part;
    for (std::size_t p = 0; p < M; ++p) {
      if (find(p) == find(q)) {
        part.push_back(p);
        done[p] = 1;
      }
    }
    if (part.size() < 2 || at_rest) {
      for (std::size_t p : part) {
        const std::uint32_t m = g.members[p];
        w.flags[m] = static_cast<std::uint8_t>(w.flags[m] | kAlive);
        if (at_rest) w.vel[m] = {};
      }
      continue;
    }
    Group h;
    std::vector<std::int32_t> map(M, -1);
    for (std::size_t p : part) {
      map[p] = static_cast<std::int32_t>(h.members.size());
      h.members.push_back(g.members[p]);
      h.acc.push_back(g.acc[p]);
    }
    for (GC k : g.contacts) {
      if (map[static_cast<std::size_t>(k.b)] < 0) continue;
      if (k.a >= 0 && map[static_cast<std::size_t>(k.a)] < 0) continue;
      k.b = map[static_cast<std::size_t>(k.b)];
      if (k.a >= 0) k.a = map[static_cast<std::size_t>(k.a)];
      h.contacts.push_back(k);
    }
    h.fresh = part.size() != M;
    next.push_back(std::move(h));
  }
}

void advance_contact_groups(World& w, const StepContext& ctx) {
  w.group_dt = ctx.dt;
  std::vector<Group> next;
  // Each group steps alone, hidden from the others: two whose members came within reach of
  // each other in the step (an impulse sped one up past the reach they were planned with) are
  // taken back to the step's start and stepped again as one granular group.
  struct Stepped {
    std::vector<std::uint32_t> members;
    bool midstep = false;   // engaged inside the step: its members' step-start state is not in group_p0
    std::size_t first = 0, end = 0;          // its groups in `next`
    std::size_t ev_first = 0, ev_end = 0;    // its contact events in w.contacts
    Box swept;
    bool live = true;
  };
  std::vector<Stepped> done;
  const auto run = [&](Group& g) {
    Stepped st;
    st.members = g.members;
    st.midstep = g.start > 0.0;
    st.first = next.size();
    st.ev_first = w.contacts.size();
    step_group(w, g, ctx, next, st.swept);
    st.end = next.size();
    st.ev_end = w.contacts.size();
    done.push_back(std::move(st));
  };
  for (Group& g : w.contact_groups) run(g);
  std::vector<char> drop_event;
  const double tol = 1e-9 * w.length_scale;
  for (std::size_t guard = 0; guard < 4 * done.size() + 4 && w.group_disturbed == kNone; ++guard) {
    std::size_t i = done.size(), j = done.size();
    for (std::size_t p = 0; p < done.size() && i == done.size(); ++p) {
      if (!done[p].live) continue;
      for (std::size_t q = p + 1; q < done.size(); ++q) {
        if (!done[q].live) continue;
        const Box& A = done[p].swept;
        const Box& B = done[q].swept;
        if (A.x0 <= B.x1 + tol && B.x0 <= A.x1 + tol && A.y0 <= B.y1 + tol && B.y0 <= A.y1 + tol) {
          i = p;
          j = q;
          break;
        }
      }
    }
    if (i == done.size()) break;
    if (!w.granular_enabled || done[i].midstep || done[j].midstep) {
      // [core] dense_contact = "events": no granular group to take both; or one of them began
      // inside the step (no common start to step them again from)
      w.group_disturbed = done[i].members.front();
      w.group_disturbed_time = ctx.t0;
      w.group_why = "another group came within reach of it in the step (dense_contact = \"events\")";
      break;
    }
    Group merged;
    merged.granular = true;
    merged.fresh = true;
    for (std::size_t k : {i, j}) {
      Stepped& st = done[k];
      st.live = false;
      for (std::size_t c = st.first; c < st.end; ++c) next[c].members.clear();   // undone
      if (drop_event.size() < w.contacts.size()) drop_event.resize(w.contacts.size(), 0);
      for (std::size_t e = st.ev_first; e < st.ev_end; ++e) drop_event[e] = 1;
      for (std::uint32_t m : st.members) {
        w.pos[m] = w.group_p0[m];
        w.vel[m] = w.group_v0[m];
        w.tloc[m] = 0.0;
        w.apath[m] = group_force_acc(w, m);
        ++w.version[m];
        merged.members.push_back(m);
        merged.acc.push_back(group_force_acc(w, m));
      }
    }
    set_alive(w, merged, false);   // (a member its first step let go is hidden again)
    run(merged);
  }
  if (!drop_event.empty()) {
    std::size_t k = 0;
    std::erase_if(w.contacts, [&](const ContactEvent&) { return k < drop_event.size() && drop_event[k++] != 0; });
  }
  std::erase_if(next, [](const Group& g) { return g.members.empty(); });
  w.contact_groups = std::move(next);
  for (const Group& g : w.contact_groups) set_alive(w, g, true);   // seen as alive between steps
  // The mode failed (a broken guarantee is reported): the engine takes the members back.
  if (w.group_disturbed != kNone) w.contact_groups.clear();
  w.group_p0.clear();
  w.group_v0.clear();
}

}  // namespace physval::core_detail
