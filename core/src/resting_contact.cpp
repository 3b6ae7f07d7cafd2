// Resting contact and friction (the lecture's section 5).
//
// A body pressed into a face (wall, box side, surface piece) that arrives too slowly
// to bounce clear settles onto it: it keeps no normal velocity, the normal component
// of its acceleration is taken by the support (N = -m a.n, so on an incline
// N = m g cos(theta)), and along the face it feels Coulomb friction:
//   - at rest, it stays at rest while |a_t| <= mu_s N / m (static friction);
//   - sliding, it is decelerated by mu_k N / m (kinetic friction) until it stops;
//     the stop is an event at the exact time, so friction never reverses a velocity;
//   - a pair with rolling_friction c > 0 is a wheel: it rolls instead of sliding, held
//     and slowed by c N (rolling resistance, c << mu) instead of mu_s and mu_k.
// Bodies do not spin (lecture step 6), so a circle on an incline slides; a
// "block on an incline" is a circle on an inclined wall.
// The support holds while the force presses the body into the face and its contact
// point stays on the segment; leaving either way releases it.
//
// A body can also rest on another body that is itself at rest (stuck) on a support: a
// stack. It must be held there (pressed, slow, static friction enough); it is then
// stuck too, and it is released, with everything resting on it, the moment its
// supporter moves or the force stops pressing it down. A body that would slide off a
// body does not rest on it: it micro-bounces (exact_collisions.cpp).
#include <algorithm>
#include <cmath>
#include <numbers>
#include <span>
#include <tuple>
#include <vector>

#include "physval/core/time_of_impact.hpp"
#include "nnls.hpp"
#include "world.hpp"

namespace physval::core_detail {

namespace {

struct Coefficients {
  double moving;   // kinetic friction or rolling resistance
  double holding;  // static friction or rolling resistance
};

Coefficients coefficients(const World& w, std::uint32_t i, const Segment& s) {
  const PairMaterial m = w.pair_material(w.material[i], s.material);
  if (m.rolling_friction > 0.0) return {m.rolling_friction, m.rolling_friction};
  return {m.friction, std::max(m.static_friction, m.friction)};
}

// The face's law for a rigid block (push_trains, join_train): its total mass M, force
// along the face F, static friction H and kinetic friction K; members summed in the order
// along the face, so the sums are the same bits whatever the numbering.
struct Law {
  double M = 0.0, F = 0.0, H = 0.0, K = 0.0;
};
// Member m's own law under the force acceleration acc.
Law face_law(const World& w, std::uint32_t m, Vec2 acc) {
  const Vec2 nn = w.support_n[m], tt = perp(nn);
  const Coefficients c = coefficients(w, m, w.statics.segments[w.support[m]]);
  const double mass = 1.0 / w.inv_mass[m];
  const double N = mass * std::max(-dot(acc, nn), 0.0);
  return Law{mass, mass * dot(acc, tt), c.holding * N, c.moving * N};
}
// A block's acceleration along the face at velocity v: kinetic friction sliding, held
// from rest iff its static friction can.
double block_a(const Law& L, double v) {
  if (v == 0.0) return std::fabs(L.F) <= L.H ? 0.0 : (L.F - std::copysign(L.K, L.F)) / L.M;
  return (L.F - std::copysign(L.K, v)) / L.M;
}
// The push (per mass) giving member m (force acceleration acc) its block's a: sliding,
// the difference to its own law; at rest and held (a == 0), each member's friction taking
// its share of the block's force in proportion to what it can hold.
Vec2 block_push(const World& w, std::uint32_t m, Vec2 acc, const Law& L, double v, double a) {
  const Vec2 tt = perp(w.support_n[m]);
  const Law own = face_law(w, m, acc);
  if (v != 0.0 || a != 0.0) {
    const double own_a = (own.F - std::copysign(own.K, v != 0.0 ? v : L.F)) / own.M;
    return (a - own_a) * tt;
  }
  const double share = L.H > 0.0 ? L.F * (own.H / L.H) : 0.0;
  return ((share - own.F) / own.M) * tt;
}
// Body m's force acceleration before this step's pushes (push_trains).
Vec2 raw_acc(const World& w, std::uint32_t m) {
  return m < w.train_raw_set.size() && w.train_raw_set[m] ? w.train_raw_acc[m] : w.acc[m];
}
// Keeps body m's force acceleration before a push (once a step).
void keep_raw_acc(World& w, std::uint32_t m) {
  if (w.train_raw_set.size() < w.size()) w.train_raw_set.resize(w.size(), 0), w.train_raw_acc.resize(w.size());
  if (w.train_raw_set[m]) return;
  w.train_raw_set[m] = 1;
  w.train_raw_acc[m] = w.acc[m];
  w.train_raw_list.push_back(m);
}
// Pooling a chain (sorted along the face, all at velocity v) from the rear: a block behind
// that would accelerate faster along the face than the block in front presses it and
// joins it (a tie to round-off joins too, so the pair keeps the same bits). raw: the
// members' laws under their force accelerations before this step's pushes.
struct Pool {
  std::size_t b, e;
  Law L;
  double a;
};
void pool_blocks(const World& w, std::span<const std::uint32_t> chain, double v, bool raw, std::vector<Pool>& pools) {
  pools.clear();
  for (std::size_t x = 0; x < chain.size(); ++x) {
    const Law L = face_law(w, chain[x], raw ? raw_acc(w, chain[x]) : w.acc[chain[x]]);
    pools.push_back({x, x + 1, L, block_a(L, v)});
    while (pools.size() > 1) {
      const Pool& back = pools[pools.size() - 2];
      const Pool& front = pools.back();
      if (!(back.a - front.a > -1e-12 * (std::fabs(back.a) + std::fabs(front.a)))) break;
      Pool joined{back.b, front.e, {back.L.M + front.L.M, back.L.F + front.L.F, back.L.H + front.L.H, back.L.K + front.L.K}, 0.0};
      joined.a = block_a(joined.L, v);
      pools.pop_back();
      pools.back() = joined;
    }
  }
}

}  // namespace

void support_path(World& w, std::uint32_t i) {
  if (w.on_body(i)) {   // held in place by static friction on a body at rest
    w.vel[i] = {};
    w.apath[i] = {};
    return;
  }
  const double vt = dot(w.vel[i], perp(w.support_n[i]));
  w.vel[i] = vt * perp(w.support_n[i]);   // no normal velocity on a support
  w.apath[i] = support_acceleration(w, i, w.acc[i], vt);
}

void stopping_mates(const World& w, std::uint32_t i, std::vector<std::uint32_t>& out) {
  out.clear();
  if (std::find(w.train_stopping.begin(), w.train_stopping.end(), i) == w.train_stopping.end()) return;
  for (std::uint32_t m : w.train_stopping) {
    if (m != i && w.train_block[m] == w.train_block[i]) out.push_back(m);
  }
}

void stop_on_support(World& w, std::uint32_t i) {
  w.vel[i] = {};
  const auto it = std::find(w.train_stopping.begin(), w.train_stopping.end(), i);
  if (it == w.train_stopping.end()) {
    support_path(w, i);
    return;
  }
  w.train_stopping.erase(it);
  keep_raw_acc(w, i);
  w.acc[i] = w.train_stop_acc[i];
  support_path(w, i);
  w.apath[i] = w.train_stop_apath[i];
}

Vec2 support_acceleration(const World& w, std::uint32_t i, Vec2 a, double vt) {
  const Segment& s = w.statics.segments[w.support[i]];
  const Vec2 n = w.support_n[i];
  const Vec2 t = perp(n);
  const double normal_per_mass = -dot(a, n);   // N / m
  const double at = dot(a, t);
  const Coefficients c = coefficients(w, i, s);
  const double limit_moving = c.moving * std::max(normal_per_mass, 0.0);
  const double limit_holding = c.holding * std::max(normal_per_mass, 0.0);
  double a_t;
  if (vt == 0.0) {
    a_t = std::fabs(at) <= limit_holding ? 0.0 : at - std::copysign(limit_moving, at);
  } else {
    a_t = at - std::copysign(limit_moving, vt);
  }
  return a_t * t;
}

void release_support(World& w, std::uint32_t i) {
  if (w.is_held(i)) {   // forget its contacts
    std::erase_if(w.held, [i](const HeldContact& c) { return c.body == i; });
  } else if (w.on_body(i)) {   // unlink from the supporter's list of dependents
    const std::uint32_t j = w.support[i] & ~kBodySupport;
    std::uint32_t* link = &w.dep_head[j];
    while (*link != kNone && *link != i) link = &w.dep_next[*link];
    if (*link == i) *link = w.dep_next[i];
    w.dep_next[i] = kNone;
  }
  w.support[i] = kNone;
  w.apath[i] = w.acc[i];   // free for the rest of the step
}

bool can_rest_on(const World& w, std::uint32_t i, std::uint32_t j, Vec2 n, double rest_speed) {
  if (!w.stuck(j) || w.supported(i)) return false;
  const Vec2 a = w.acc[i];
  const double normal_per_mass = -dot(a, n);
  if (!(normal_per_mass > 0.0)) return false;
  if (length(w.vel[i]) > rest_speed) return false;
  const PairMaterial m = w.pair_material(w.material[i], w.material[j]);
  const double hold = m.rolling_friction > 0.0 ? m.rolling_friction : std::max(m.static_friction, m.friction);
  return length(a + normal_per_mass * n) <= hold * normal_per_mass;
}

void rest_on_body(World& w, std::uint32_t i, std::uint32_t j, Vec2 n) {
  w.vel[i] = {};
  w.apath[i] = {};
  w.support[i] = kBodySupport | j;
  w.support_n[i] = n;
  w.dep_next[i] = w.dep_head[j];
  w.dep_head[j] = i;
}

void collect_dependents(World& w, std::uint32_t j) {
  std::size_t k = w.released.size();
  for (std::uint32_t d = w.dep_head[j]; d != kNone; d = w.dep_next[d]) w.released.push_back(d);
  while (k < w.released.size()) {
    const std::uint32_t x = w.released[k++];
    for (std::uint32_t d = w.dep_head[x]; d != kNone; d = w.dep_next[d]) w.released.push_back(d);
  }
}

namespace {

// Whether the unit direction d lies in the convex cone spanned by the unit vectors g
// (within `tol` radians of it): some generator along d, or two generators on either side
// of d less than pi apart.
bool in_cone(Vec2 d, std::span<const Vec2> g, double tol) {
  double ccw = INFINITY, cw = -INFINITY;   // nearest generator angle on each side of d
  for (const Vec2& x : g) {
    const double phi = std::atan2(cross(d, x), dot(d, x));
    if (std::fabs(phi) <= tol) return true;
    if (phi > 0.0) {
      ccw = std::min(ccw, phi);
    } else {
      cw = std::max(cw, phi);
    }
  }
  return std::isfinite(ccw) && std::isfinite(cw) && ccw - cw < std::numbers::pi - tol;
}

bool related_bodies(const World& w, std::uint32_t i, std::uint32_t j) {
  const std::size_t s = w.scene_bodies;
  if ((w.flags[i] & kParticle) && w.parent[i - s] == j) return true;
  if ((w.flags[j] & kParticle) && w.parent[j - s] == i) return true;
  return false;
}

// Whether bodies a and b may collide and touch, within 1e-9 of contact (as
// touching_supports); n: the unit normal from b towards a.
bool in_contact(const World& w, std::uint32_t a, std::uint32_t b, Vec2& n) {
  if ((w.flags[a] & kPoint) && (w.flags[b] & kPoint)) return false;
  if (((w.flags[a] | w.flags[b]) & kParticle) && related_bodies(w, a, b)) return false;
  if (w.any_rules && !w.response(w.group[a], w.group[b]).collide) return false;
  const Vec2 d = w.pos[a] - w.pos[b];
  const double dist = length(d);
  const double R = w.radius[a] + w.radius[b];
  if (!(dist > 0.0) || std::fabs(dist - R) > 1e-9 * (R + w.length_scale)) return false;
  n = d / dist;
  return true;
}

double holding_coefficient(const PairMaterial& m) {
  return m.rolling_friction > 0.0 ? m.rolling_friction : std::max(m.static_friction, m.friction);
}

}  // namespace

double pair_collapse_speed(World& w, std::uint32_t i, std::uint32_t j, double t) {
  const double v = w.collapse_speed(i, j);
  if (!(v > 0.0) || std::isinf(v)) return v;
  // Scratch kept between calls (a pile's collapse asks this at most of its impacts).
  thread_local std::vector<std::uint32_t> cluster, near, faces;
  thread_local std::vector<Vec2> at;
  cluster.clear();
  at.clear();
  // On one face (sliding, or at rest there): its face's law says what it does; such a
  // body presses another only through its own acceleration along the face.
  const auto on_face = [&](std::uint32_t x) {
    return w.dynamic(x) && w.inv_mass[x] > 0.0 && w.supported(x) && !w.on_body(x);
  };
  const auto grounded = [&](std::uint32_t x) {
    return !w.dynamic(x) || !(w.inv_mass[x] > 0.0) || (w.supported(x) && !on_face(x)) || (w.stationary(x) && !on_face(x));
  };
  if (grounded(i) || grounded(j)) return v;
  // A member's own acceleration at t: a body on a face by its face's law (field before any
  // train's pushes, kinetic friction against its motion, held by static friction at rest),
  // a free one by its force.
  const auto own_acc = [&](std::uint32_t x) {
    if (!on_face(x)) return w.acc[x];
    return support_acceleration(w, x, raw_acc(w, x), dot(w.vel_at(x, t), perp(w.support_n[x])));
  };
  // What presses the pair of members x and y (n from x to y): how fast they accelerate
  // into each other (0 when they do not; round-off of equal laws is no pressing).
  const auto pressing = [&](Vec2 ax, Vec2 ay, Vec2 n) {
    const double an = dot(ay - ax, n);
    return an < -1e-12 * (length(ax) + length(ay)) ? -an : 0.0;
  };
  bool any_on_face = false;   // some member is on a face: the cluster is judged by pressing
  const double reach = v * w.step_dt;
  if (w.ground_time != w.time || w.ground_t != t || w.ground_reach.size() != w.size()) {
    if (w.ground_reach.size() != w.size()) {
      w.ground_reach.assign(w.size(), -1.0);
    } else {
      for (std::uint32_t x : w.ground_marked) w.ground_reach[x] = -1.0;
    }
    w.ground_marked.clear();
    w.ground_time = w.time;
    w.ground_t = t;
  }
  const auto known = [&](std::uint32_t x) { return w.ground_reach[x] >= 0.0 && w.ground_reach[x] <= reach; };
  if (known(i) || known(j)) return v;
  // A pair with a body on a face that its own laws press together (a ball landing on one on
  // the floor, a slider into one held on a slope) is pressed: no cluster to look at.
  if (on_face(i) || on_face(j)) {
    const Vec2 d = w.pos_at(j, t) - w.pos_at(i, t);
    const double dl = length(d);
    if (!(dl > 0.0) || pressing(own_acc(i), own_acc(j), d / dl) > 0.0) return v;
  }
  // Every body looked at so far rests, through the others, on what was found.
  const auto found_ground = [&]() {
    for (std::uint32_t x : cluster) {
      if (w.ground_reach[x] < 0.0) w.ground_marked.push_back(x);
      if (w.ground_reach[x] < 0.0 || w.ground_reach[x] > reach) w.ground_reach[x] = reach;
    }
    return v;
  };
  cluster.push_back(i);
  cluster.push_back(j);
  at.push_back(w.pos_at(i, t));
  at.push_back(w.pos_at(j, t));
  Vec2 lo = w.acc[i], hi = w.acc[i];
  for (std::size_t q = 0; q < cluster.size(); ++q) {
    const std::uint32_t x = cluster[q];
    const Vec2 p = at[q];
    const double r = w.radius[x];
    lo = {std::min(lo.x, w.acc[x].x), std::min(lo.y, w.acc[x].y)};
    hi = {std::max(hi.x, w.acc[x].x), std::max(hi.y, w.acc[x].y)};
    const double pad = r + reach;
    const bool x_on_face = on_face(x);
    any_on_face = any_on_face || x_on_face;
    const Vec2 ax = own_acc(x);
    // A face within reach: the cluster leans on it (a free member); a member on a face
    // leans on a face within reach (its own, a collinear piece, a wall) only if its law
    // presses it into that face.
    if (!w.statics.segments.empty()) {
      faces.clear();
      w.statics.query(make_aabb(p.x - pad, p.y - pad, p.x + pad, p.y + pad), faces);
      for (std::uint32_t k : faces) {
        const Segment& s = w.statics.segments[k];
        if (w.any_rules && !w.response(w.group[x], s.group).collide) continue;
        if (x_on_face && k == w.support[x]) continue;   // its own face: its law holds there
        const double u = std::clamp(dot(p - s.from, s.dir), 0.0, s.length);
        const Vec2 d = p - (s.from + u * s.dir);
        const double dl = length(d);
        if (dl - r > reach) continue;
        if (!x_on_face || !(dl > 0.0) || pressing(Vec2{}, ax, d / dl) > 0.0) return found_ground();
      }
    }
    near.clear();
    // (a body within reach meets this box, and so does that body's registered box)
    w.bp->query_box(make_aabb(p.x - pad, p.y - pad, p.x + pad, p.y + pad), x, near);
    for (std::uint32_t y : near) {
      if (!w.alive(y) || std::find(cluster.begin(), cluster.end(), y) != cluster.end()) continue;
      if ((w.flags[x] & kPoint) && (w.flags[y] & kPoint)) continue;
      if (((w.flags[x] | w.flags[y]) & kParticle) && related_bodies(w, x, y)) continue;
      if (w.any_rules && !w.response(w.group[x], w.group[y]).collide) continue;
      const Vec2 py = w.pos_at(y, t);
      if (length(py - p) - (r + w.radius[y]) > reach) continue;
      if (grounded(y) || known(y)) return found_ground();
      if (cluster.size() >= kMaxFreeCluster) return v;
      cluster.push_back(y);
      at.push_back(py);
    }
  }
  if (any_on_face) {
    // Members on faces (collapse3): the cluster is pressed only where two of its members,
    // or a member and a face, accelerate into each other under their own laws (field,
    // supports, friction). With no contact force needed anywhere (every such relative
    // normal acceleration >= 0), nothing presses the pair: two balls on a frictionless
    // floor, or sliding with the same kinetic friction, or down one slope, meet as without
    // a field. Else the pressed threshold, as before.
    for (std::size_t q = 0; q < cluster.size(); ++q) {
      const Vec2 aq = own_acc(cluster[q]);
      for (std::size_t s2 = q + 1; s2 < cluster.size(); ++s2) {
        const Vec2 d = at[s2] - at[q];
        const double dl = length(d);
        if (!(dl > 0.0) || dl - (w.radius[cluster[q]] + w.radius[cluster[s2]]) > reach) continue;
        if (pressing(aq, own_acc(cluster[s2]), d / dl) > 0.0) return found_ground();
      }
    }
    return 0.0;
  }
  // Falling freely: only what differs between the members presses them together (never
  // more than the pressed threshold: the rule only ever keeps a restitution).
  const double spread = length(hi - lo);
  return spread > 0.0 ? std::min(v, w.rest_speed(spread, w.step_dt)) : 0.0;
}

// The contacts that could hold body i now: faces it touches (within 1e-9 of its size
// and the scene's), and stationary bodies in `near` it touches.
static void touching_supports(World& w, std::uint32_t i, std::span<const std::uint32_t> near,
                              std::vector<HeldContact>& out, std::vector<double>& mu,
                              std::vector<double>* restitution = nullptr) {
  const double r = w.radius[i];
  const Vec2 p = w.pos[i];
  if (!w.statics.segments.empty()) {
    const double tol = 1e-9 * (r + w.length_scale);
    w.found_static.clear();
    w.statics.query(make_aabb(p.x - r - tol, p.y - r - tol, p.x + r + tol, p.y + r + tol), w.found_static);
    for (std::uint32_t k : w.found_static) {
      const Segment& s = w.statics.segments[k];
      if (w.any_rules && !w.response(w.group[i], s.group).collide) continue;
      const double u = dot(p - s.from, s.dir);
      if (u < 0.0 || u > s.length) {
        // A free end point (no other segment ends there: not a corner or a joint, which the
        // cap rides of convex_cap.cpp take): a support along the line from it to the
        // centre (the two ends of a drain narrower than the body hold it).
        const Vec2 q = u < 0.0 ? s.from : s.to;
        const Vec2 d = p - q;
        const double dl = length(d);
        if (!(dl > 0.0) || std::fabs(dl - r) > tol) continue;
        const bool shared = std::any_of(w.found_static.begin(), w.found_static.end(), [&](std::uint32_t o) {
          const Segment& t = w.statics.segments[o];
          return o != k && (length(t.from - q) <= tol || length(t.to - q) <= tol);
        });
        if (shared) continue;
        out.push_back({i, kBodySupport | k, d / dl});
        mu.push_back(holding_coefficient(w.pair_material(w.material[i], s.material)));
        if (restitution) restitution->push_back(w.pair_material(w.material[i], s.material).restitution);
        continue;
      }
      const double D = dot(p - s.from, s.normal);
      if (std::fabs(std::fabs(D) - r) > tol) continue;
      out.push_back({i, kBodySupport | k, toi::line_side(D, dot(w.vel[i], s.normal), dot(w.acc[i], s.normal)) * s.normal});
      mu.push_back(holding_coefficient(w.pair_material(w.material[i], s.material)));
      if (restitution) restitution->push_back(w.pair_material(w.material[i], s.material).restitution);
    }
  }
  for (std::uint32_t j : near) {
    if (j == i || !w.alive(j) || !w.stationary(j)) continue;
    if ((w.flags[i] & kPoint) && (w.flags[j] & kPoint)) continue;
    if (((w.flags[i] | w.flags[j]) & kParticle) && related_bodies(w, i, j)) continue;
    if (w.any_rules && !w.response(w.group[i], w.group[j]).collide) continue;
    const Vec2 d = p - w.pos[j];
    const double dist = length(d);
    const double R = r + w.radius[j];
    if (!(dist > 0.0) || std::fabs(dist - R) > 1e-9 * (R + w.length_scale)) continue;
    out.push_back({i, j, d / dist});
    mu.push_back(holding_coefficient(w.pair_material(w.material[i], w.material[j])));
    if (restitution) restitution->push_back(w.pair_material(w.material[i], w.material[j]).restitution);
  }
}

namespace {

// A constraint "body i's centre lies on": a circle (around a body it touches) or a line
// (a face moved out by i's radius).
struct Locus {
  bool line = false;
  Vec2 c;        // circle centre, or a point of the line
  double R = 0;  // circle radius
  Vec2 n;        // line normal
};

// The intersections of two loci (at most two), appended to out.
void intersect(const Locus& a, const Locus& b, std::vector<Vec2>& out) {
  if (a.line && b.line) {
    const double det = cross(a.n, b.n);
    if (det == 0.0) return;
    // n_a.x = n_a.c_a, n_b.x = n_b.c_b
    const double ra = dot(a.n, a.c), rb = dot(b.n, b.c);
    out.push_back({(ra * b.n.y - rb * a.n.y) / det, (a.n.x * rb - b.n.x * ra) / det});
    return;
  }
  if (a.line != b.line) {
    const Locus& l = a.line ? a : b;
    const Locus& c = a.line ? b : a;
    const double h = dot(l.n, c.c - l.c);
    if (std::fabs(h) > c.R) return;
    const Vec2 f = c.c - h * l.n;
    const double half = std::sqrt(c.R * c.R - h * h);
    out.push_back(f + half * perp(l.n));
    out.push_back(f - half * perp(l.n));
    return;
  }
  const Vec2 d = b.c - a.c;
  const double dl = length(d);
  if (!(dl > 0.0)) return;
  const double x = (a.R * a.R - b.R * b.R + dl * dl) / (2.0 * dl);
  const double h2 = a.R * a.R - x * x;
  if (h2 < 0.0) return;
  const Vec2 u = d / dl;
  const Vec2 f = a.c + x * u;
  const double h = std::sqrt(h2);
  out.push_back(f + h * perp(u));
  out.push_back(f - h * perp(u));
}

// The loci of body i's supports near p: faces and stationary bodies within `reach` of
// touching, with their gap.
struct NearSupport {
  Locus locus;
  double gap;
};

void near_supports(World& w, std::uint32_t i, std::span<const std::uint32_t> near, double reach,
                   std::vector<NearSupport>& out) {
  const double r = w.radius[i];
  const Vec2 p = w.pos[i];
  if (!w.statics.segments.empty()) {
    w.found_static.clear();
    const double pad = r + reach;
    w.statics.query(make_aabb(p.x - pad, p.y - pad, p.x + pad, p.y + pad), w.found_static);
    for (std::uint32_t k : w.found_static) {
      const Segment& s = w.statics.segments[k];
      if (w.any_rules && !w.response(w.group[i], s.group).collide) continue;
      const double D = dot(p - s.from, s.normal);
      const Vec2 n = D >= 0.0 ? s.normal : -s.normal;
      const double gap = std::fabs(D) - r;
      if (gap > reach) continue;
      Locus l;
      l.line = true;
      l.n = n;
      l.c = s.from + r * n;
      out.push_back({l, gap});
    }
  }
  for (std::uint32_t j : near) {
    if (j == i || !w.alive(j) || !w.stationary(j)) continue;
    if ((w.flags[i] & kPoint) && (w.flags[j] & kPoint)) continue;
    if (((w.flags[i] | w.flags[j]) & kParticle) && related_bodies(w, i, j)) continue;
    if (w.any_rules && !w.response(w.group[i], w.group[j]).collide) continue;
    const double R = r + w.radius[j];
    const double gap = length(p - w.pos[j]) - R;
    if (gap > reach) continue;
    Locus l;
    l.c = w.pos[j];
    l.R = R;
    out.push_back({l, gap});
  }
}

// Whether body i at its position overlaps any face or stationary body by more than
// round-off, or sits off the span of a face it touches.
bool clear_of_everything(World& w, std::uint32_t i, std::span<const std::uint32_t> near) {
  const double r = w.radius[i];
  const Vec2 p = w.pos[i];
  const double tol = 1e-12 * (r + w.length_scale);   // round-off only: it must not overlap
  if (!w.statics.segments.empty()) {
    w.found_static.clear();
    w.statics.query(make_aabb(p.x - r - tol, p.y - r - tol, p.x + r + tol, p.y + r + tol), w.found_static);
    for (std::uint32_t k : w.found_static) {
      const Segment& s = w.statics.segments[k];
      if (w.any_rules && !w.response(w.group[i], s.group).collide) continue;
      const double u = dot(p - s.from, s.dir);
      const double D = std::fabs(dot(p - s.from, s.normal));
      if (u >= 0.0 && u <= s.length) {
        if (D < r - tol) return false;
      } else if (length(p - (u < 0.0 ? s.from : s.to)) < r - tol) {
        return false;
      }
    }
  }
  for (std::uint32_t j : near) {
    if (j == i || !w.alive(j)) continue;
    if ((w.flags[i] & kPoint) && (w.flags[j] & kPoint)) continue;
    const double R = r + w.radius[j];
    if (length(p - w.pos_at(j, w.tloc[i])) < R - 1e-12 * (R + w.length_scale)) return false;
  }
  return true;
}

}  // namespace

namespace {

// One projected Gauss-Seidel row of an acceleration-level contact problem: a normal row's
// multiplier stays >= 0, a tangent row's within +-bound (mu times its normal's).
double projected_row(double lam, double w, double Akk, bool tangent, double bound) {
  const double l = lam - w / Akk;
  return tangent ? std::clamp(l, -bound, bound) : std::max(0.0, l);
}

// Whether body i, about to be held by `contacts` (its static friction cones hold it
// against each as against a fixed support), is still held once the non-static bodies it
// leans on are judged with its load: a body at rest on a face by its own friction, or
// held, only looks fixed; the push it takes may be more than its own friction can give
// (two balls touching on a slope, the lower stuck by its own friction, the upper not).
// The group is i and the bodies at rest on a face by their own friction that it leans on
// (a contact whose normal has a component against i's force and one along the other's
// face), and those that they lean on in turn; held bodies and bodies on bodies stay fixed
// supports (README, Known limits); every contact of
// every member (faces, static or non-leaning bodies as fixed supports, member pairs) gets
// a normal and a static friction row, and the acceleration-level contact problem is
// solved by projected Gauss-Seidel, as in try_hold_group: held iff every member ends at
// rest. A group of more than kMaxLeaning members is not judged (each member only on its
// own, as before: README, Known limits).
// `any_face`: also judge bodies at rest on frictionless faces (there at rest only because
// nothing pushed them along); used to detect a hold core cannot justify, not to decide one.
bool leaning_group_holds(World& w, std::uint32_t i, std::span<const HeldContact> contacts,
                         std::span<const double> mu, bool any_face = false, bool* braced = nullptr) {
  constexpr std::size_t kMaxLeaning = 16;
  const auto leans = [&](std::uint32_t body, Vec2 n) {   // a contact that takes part of body's force
    const Vec2 a = w.acc[body];
    const double am = length(a);
    return am > 0.0 && -dot(n, a) > 1e-12 * am;
  };
  // A body at rest on a face by its own friction, pushed with a component along that face
  // (a push along the face's normal the face takes whole: a column on a floor is not
  // judged again, nor solved at mass ratios where Gauss-Seidel crawls).
  const auto movable_along = [&](std::uint32_t other, Vec2 n) {
    if ((other & kBodySupport) || other >= w.size() || !w.dynamic(other) || !w.stuck(other) || w.on_body(other)) {
      return false;
    }
    // On a frictionless face it is at rest only because nothing pushes it along: left a
    // fixed support, as before (open: README, The hunt for wrong greens).
    if (!any_face && !(coefficients(w, other, w.statics.segments[w.support[other]]).holding > 0.0)) return false;
    return std::fabs(cross(n, w.support_n[other])) > 1e-9;
  };
  thread_local std::vector<std::uint32_t> members, all;
  members.assign(1, i);
  for (const HeldContact& c : contacts) {
    if (movable_along(c.other, c.n) && leans(i, c.n) &&
        std::find(members.begin(), members.end(), c.other) == members.end()) {
      members.push_back(c.other);
    }
  }
  if (members.size() == 1) {   // only fixed supports; those that are bodies brace it (`braced`)
    if (braced != nullptr) {
      for (const HeldContact& c : contacts) {
        if (!(c.other & kBodySupport) && c.other < w.size() && w.dynamic(c.other)) *braced = true;
      }
    }
    return true;
  }
  const std::size_t n = w.size();
  // The bodies near a member: a scan (only groups that lean on bodies at rest get here).
  const auto near_of = [&](std::uint32_t m) {
    all.clear();
    const double reach = w.radius[m] + 1e-9 * (w.radius[m] + w.length_scale);
    for (std::uint32_t j = 0; j < n; ++j) {
      if (j == m || !w.alive(j) || !w.stationary(j)) continue;
      const Vec2 d = w.pos[j] - w.pos[m];
      const double R = reach + w.radius[j];
      if (std::fabs(d.x) <= R && std::fabs(d.y) <= R) all.push_back(j);
    }
  };
  struct Row {
    std::int32_t a, b;   // member indices; a = -1: a fixed support
    Vec2 d;
    double mu;
    bool tangent;
  };
  thread_local std::vector<Row> rows;
  thread_local std::vector<HeldContact> tmp;
  thread_local std::vector<double> mus;
  rows.clear();
  const auto index_of = [&](std::uint32_t x) -> std::int32_t {
    if ((x & kBodySupport) || x >= n) return -1;
    const auto it = std::find(members.begin(), members.end(), x);
    return it == members.end() ? -1 : static_cast<std::int32_t>(it - members.begin());
  };
  const auto add = [&](std::int32_t a, std::int32_t b, Vec2 nrm, double m) {
    rows.push_back({a, b, nrm, m, false});
    if (m > 0.0) rows.push_back({a, b, perp(nrm), m, true});
  };
  // Membership first (breadth first), then every member's contacts.
  for (std::size_t q = 1; q < members.size(); ++q) {
    const std::uint32_t m = members[q];
    near_of(m);
    tmp.clear();
    mus.clear();
    touching_supports(w, m, all, tmp, mus);
    for (const HeldContact& c : tmp) {
      if (movable_along(c.other, c.n) && leans(m, c.n) && index_of(c.other) < 0) {
        members.push_back(c.other);
        if (members.size() > kMaxLeaning) {   // too many to judge here
          if (braced != nullptr) *braced = true;
          return true;
        }
      }
    }
  }
  const auto note_brace = [&](std::uint32_t other, std::int32_t o) {   // a body outside the group
    if (braced != nullptr && o < 0 && !(other & kBodySupport) && other < n) *braced = true;
  };
  for (std::size_t k = 0; k < contacts.size(); ++k) {
    note_brace(contacts[k].other, index_of(contacts[k].other));
    add(index_of(contacts[k].other), 0, contacts[k].n, mu[k]);
  }
  for (std::size_t q = 1; q < members.size(); ++q) {
    const std::uint32_t m = members[q];
    near_of(m);
    tmp.clear();
    mus.clear();
    touching_supports(w, m, all, tmp, mus);
    for (std::size_t k = 0; k < tmp.size(); ++k) {
      const std::int32_t o = index_of(tmp[k].other);
      note_brace(tmp[k].other, o);
      if (o >= 0 && static_cast<std::size_t>(o) < q) continue;   // the pair's row is there already
      add(o, static_cast<std::int32_t>(q), tmp[k].n, mus[k]);
    }
  }
  thread_local std::vector<Vec2> acc;
  thread_local std::vector<double> lam, Akk;
  const std::size_t M = members.size();
  acc.resize(M);
  for (std::size_t q = 0; q < M; ++q) acc[q] = w.acc[members[q]];
  const auto inv = [&](std::int32_t x) { return x < 0 ? 0.0 : w.inv_mass[members[static_cast<std::size_t>(x)]]; };
  lam.assign(rows.size(), 0.0);
  Akk.resize(rows.size());
  for (std::size_t k = 0; k < rows.size(); ++k) Akk[k] = inv(rows[k].a) + inv(rows[k].b);
  double amax = 0.0;
  for (std::size_t q = 0; q < M; ++q) amax = std::max(amax, length(acc[q]));
  for (int iter = 0; iter < 20000; ++iter) {
    double change = 0.0;
    for (std::size_t k = 0; k < rows.size(); ++k) {
      const Row& r = rows[k];
      if (!(Akk[k] > 0.0)) continue;
      const Vec2 ab = acc[static_cast<std::size_t>(r.b)];
      const Vec2 aa = r.a < 0 ? Vec2{} : acc[static_cast<std::size_t>(r.a)];
      const double wk = dot(ab - aa, r.d);
      const double l = projected_row(lam[k], wk, Akk[k], r.tangent, r.tangent ? r.mu * lam[k - 1] : 0.0);
      const double dl = l - lam[k];
      if (dl == 0.0) continue;
      lam[k] = l;
      if (r.a >= 0) acc[static_cast<std::size_t>(r.a)] -= (dl * inv(r.a)) * r.d;
      acc[static_cast<std::size_t>(r.b)] += (dl * inv(r.b)) * r.d;
      change = std::max(change, std::fabs(dl) * Akk[k]);
    }
    if (change <= 1e-14 * amax) break;
  }
  for (std::size_t q = 0; q < M; ++q) {
    if (length(acc[q]) > 1e-9 * length(w.acc[members[q]])) return false;
  }
  return true;
}

}  // namespace

// A free body whose only contact is one face with 0 < e < 1, frictionless, that it meets or
// leaves faster than round-off (a step that ends at a bounce of its Zeno sequence), where
// World::zeno_tails: not held at the step's start (neither alone nor as a group's pocket);
// the event loop ends its sequence at the closed-form time (zeno_tail, exact_collisions.cpp).
// Held here it stopped early (up to 2 v_r / ((1 - e) |a|)).
static bool zeno_bounce(World& w, std::uint32_t i, double dt, std::span<const std::uint32_t> near) {
  if (!w.zeno_tails() || w.supported(i) || (w.flags[i] & (kParticle | kPoint | kDestroyOnHit)) != 0) return false;
  if (w.acc.empty()) return false;
  thread_local std::vector<HeldContact> contacts;
  thread_local std::vector<double> mu, rest_e;
  contacts.clear();
  mu.clear();
  rest_e.clear();
  touching_supports(w, i, near, contacts, mu, &rest_e);
  if (contacts.size() != 1) return false;
  const Vec2 n = contacts[0].n;
  const double vn = dot(w.vel[i], n);
  const double an = dot(w.acc[i], n);
  constexpr double ulps = 64.0 * 2.220446049250313e-16;
  if (!(contacts[0].other & kBodySupport)) {
    // One static circle, met straight along its normal (circle_tail, exact_collisions.cpp:
    // the sixteenth hunt's ball bouncing on the top of a static circle).
    const std::uint32_t j = contacts[0].other;
    if (j >= w.size() || !w.firm_circle(j, n)) return false;
    const PairMaterial m = w.pair_material(w.material[i], w.material[j]);
    if (!(m.restitution > 0.0 && m.restitution < 1.0)) return false;
    if (length(w.vel[i] - vn * n) > ulps * length(w.vel[i]) || length(w.acc[i] - an * n) > ulps * length(w.acc[i])) return false;
    return an < 0.0 && std::fabs(vn) > ulps * (length(w.vel[i]) + std::fabs(an) * dt);
  }
  const Segment& s = w.statics.segments[contacts[0].other & ~kBodySupport];
  if (!World::zeno_material(w.pair_material(w.material[i], s.material), w.vel[i], w.acc[i], n)) return false;
  return an < 0.0 && std::fabs(vn) > ulps * (length(w.vel[i]) + std::fabs(an) * dt);
}

bool try_hold(World& w, std::uint32_t i, double dt, std::span<const std::uint32_t> near, bool settle_into_pocket) {
  if (!w.dynamic(i) || w.is_held(i) || w.acc.empty()) return false;
  const Vec2 a = w.acc[i];
  const double amag = length(a);
  if (!(amag > 0.0)) return false;   // nothing to hold against
  const double vr = w.rest_speed(amag, dt);
  if (length(w.vel[i]) > vr) return false;
  thread_local std::vector<HeldContact> contacts;
  thread_local std::vector<double> mu, rest_e;
  thread_local std::vector<Vec2> gens;
  thread_local std::vector<NearSupport> loci;
  thread_local std::vector<Vec2> points;
  const Vec2 d = (-1.0 / amag) * a;   // the direction the supports must push
  const auto holds_here = [&]() {
    contacts.clear();
    mu.clear();
    rest_e.clear();
    gens.clear();
    touching_supports(w, i, near, contacts, mu, &rest_e);
    if (contacts.empty()) return false;
    // An elastic face (e = 1) met or left at more than round-off bounces the body: it is
    // not at rest there (World::impact_rest_speed; a step that ends at a bounce). Only
    // faces: a body touching elastic bodies at rest keeps the hold below v_r (a row on a
    // floor with friction, struck end on, needs it; not examined further).
    for (std::size_t k = 0; k < contacts.size(); ++k) {
      if (!(contacts[k].other & kBodySupport)) continue;
      const double vn = dot(w.vel[i], contacts[k].n);
      if (rest_e[k] >= 1.0 && std::fabs(vn) > w.impact_rest_speed(dot(a, contacts[k].n), dt, rest_e[k], vn)) return false;
    }
    for (std::size_t k = 0; k < contacts.size(); ++k) {
      const Vec2 n = contacts[k].n;
      gens.push_back(n);
      if (mu[k] > 0.0) {   // the edges of the static friction cone
        const double th = std::atan(mu[k]);
        gens.push_back(std::cos(th) * n + std::sin(th) * perp(n));
        gens.push_back(std::cos(th) * n - std::sin(th) * perp(n));
      }
    }
    return in_cone(d, gens, 1e-12);
  };
  const Vec2 p_start = w.pos[i];
  const bool on_face = w.supported(i) && !w.on_body(i);
  bool held = holds_here();
  if (!held && settle_into_pocket) {
    // Inelastic collapse into a pocket: a slow body on one support that cannot hold it
    // slides and hops, ever shorter, into the pocket that a second support within
    // rest_speed x dt forms with the first: infinitely many impacts in a finite time,
    // whose limit is the pocket. Go to that limit if the two hold it there (moving
    // along the force, so no energy is gained).
    const double reach = vr * dt;
    const double tol = 1e-9 * (w.radius[i] + w.length_scale);
    loci.clear();
    near_supports(w, i, near, reach, loci);
    const Vec2 p0 = w.pos[i];
    double best = INFINITY;
    Vec2 best_p;
    for (const NearSupport& s1 : loci) {
      if (std::fabs(s1.gap) > tol) continue;   // the support it touches
      for (const NearSupport& s2 : loci) {
        if (&s1 == &s2 || std::fabs(s2.gap) <= tol) continue;
        points.clear();
        intersect(s1.locus, s2.locus, points);
        for (const Vec2& q : points) {
          const double dist = length(q - p0);
          if (dist > reach || dist >= best || dot(q - p0, a) < 0.0) continue;
          w.pos[i] = q;
          if (clear_of_everything(w, i, near) && holds_here()) {
            best = dist;
            best_p = q;
          }
          w.pos[i] = p0;
        }
      }
    }
    if (best < INFINITY) {
      w.pos[i] = best_p;
      held = holds_here();
      if (!held) w.pos[i] = p0;
    }
  }
  // Only for a body on a face (a ball pushing another along a slope): a free body held on
  // bodies at rest keeps the old test (open: a ball on two balls on a floor whose friction
  // cannot keep them from spreading is held; judged as a group it falls between them by
  // micro-bounces that gain energy, README, The hunt for wrong greens).
  if (held && on_face && !leaning_group_holds(w, i, contacts, mu)) {
    w.pos[i] = p_start;   // (back from a pocket it was moved to)
    held = false;
  }
  if (!held) return false;
  // A free body held on bodies at rest: the old test holds it (its supports taken as fixed).
  // Judged with the bodies at rest on faces it leans on (the group test, frictionless faces
  // included), the group may not hold it (a pyramid on a floor: nothing keeps the bottom balls
  // from spreading), and core has no exact model yet for the collapse; or another body touches
  // the group (`braced`: a brace, a held body, a body on a body), and the group test, taking it
  // as fixed, cannot decide. Either way it is held as before and judged once the supports of
  // the step are settled, on its whole resting component (judge_braced_holds: the bodies held
  // later in the same pass brace it too); if that cannot hold it, the run is no longer exact:
  // a broken guarantee (diverged), never `ok`.
  bool braced = false;
  if (!on_face && w.unjustified_hold == kNone && (!leaning_group_holds(w, i, contacts, mu, true, &braced) || braced) &&
      std::find(w.braced_holds.begin(), w.braced_holds.end(), i) == w.braced_holds.end()) {
    w.braced_holds.push_back(i);
  }
  release_support(w, i);
  w.vel[i] = {};
  w.apath[i] = {};
  w.support[i] = kHeld;
  w.support_n[i] = d;
  w.held.insert(w.held.end(), contacts.begin(), contacts.end());
  return true;
}

// Body j slides on a frictionless face (a face support, not stuck): nothing but a hold
// ever stops it, so a group's hold (and its pocket) takes it as a member.
bool frictionless_slider(const World& w, std::uint32_t j) {
  if (!w.supported(j) || w.on_body(j) || w.is_held(j) || w.stationary(j)) return false;
  const PairMaterial m = w.pair_material(w.material[j], w.statics.segments[w.support[j]].material);
  return m.friction == 0.0 && m.static_friction == 0.0;
}

bool try_hold_group(World& w, std::uint32_t seed, double t, double dt, const NearFn& near_fn,
                    std::vector<std::uint32_t>& members) {
  members.clear();
  if (!w.dynamic(seed) || w.acc.empty() || w.stationary(seed)) return false;
  constexpr std::size_t kMaxMembers = 64;
  thread_local std::vector<std::uint32_t> buf;
  thread_local std::vector<Vec2> pos;   // members' positions at t
  const auto slow = [&](std::uint32_t j) {
    const double a = length(w.acc[j]);
    return a > 0.0 && length(w.vel_at(j, t)) <= w.rest_speed(a, dt);
  };
  if (!slow(seed)) return false;
  members.assign(1, seed);
  pos.assign(1, w.pos_at(seed, t));
  // The slow free bodies touching the seed, and those touching them.
  for (std::size_t q = 0; q < members.size(); ++q) {
    const std::uint32_t m = members[q];
    const double r = w.radius[m];
    near_fn(pos[q], r + 1e-9 * (r + w.length_scale), buf);
    for (std::uint32_t j : buf) {
      if (j == m || !w.dynamic(j) || w.stationary(j)) continue;
      // On a face: its own path, unless it slides slowly on a frictionless face (nothing else
      // ever stops it there: the group's hold is the limit of its collapse).
      if (w.supported(j) && !w.on_body(j) && !(slow(j) && frictionless_slider(w, j))) continue;
      if ((w.flags[m] & kPoint) && (w.flags[j] & kPoint)) continue;
      if (((w.flags[m] | w.flags[j]) & kParticle) && related_bodies(w, m, j)) continue;
      if (w.any_rules && !w.response(w.group[m], w.group[j]).collide) continue;
      if (std::find(members.begin(), members.end(), j) != members.end()) continue;
      const Vec2 pj = w.pos_at(j, t);
      const double R = r + w.radius[j];
      if (std::fabs(length(pj - pos[q]) - R) > 1e-9 * (R + w.length_scale)) continue;
      if (!slow(j)) return false;   // a moving body presses on the group
      members.push_back(j);
      pos.push_back(pj);
      if (members.size() > kMaxMembers) return false;
    }
  }
  if (members.size() < 2) return false;
  // Contacts: each member's faces and stationary bodies, and member pairs.
  struct GroupContact {
    std::int32_t a;   // member index, or -1: fixed
    std::int32_t b;
    std::uint32_t other_a, other_b;   // for the record: body or kBodySupport | segment
    Vec2 n;           // from a to b
    double mu;
  };
  thread_local std::vector<GroupContact> gc;
  thread_local std::vector<HeldContact> tmp;
  thread_local std::vector<double> mus;
  gc.clear();
  for (std::size_t q = 0; q < members.size(); ++q) {
    const std::uint32_t m = members[q];
    const Vec2 saved = w.pos[m];
    w.pos[m] = pos[q];
    near_fn(pos[q], w.radius[m] + 1e-9 * (w.radius[m] + w.length_scale), buf);
    tmp.clear();
    mus.clear();
    touching_supports(w, m, buf, tmp, mus);
    w.pos[m] = saved;
    for (std::size_t k = 0; k < tmp.size(); ++k) {
      gc.push_back({-1, static_cast<std::int32_t>(q), tmp[k].other, m, tmp[k].n, mus[k]});
    }
    for (std::size_t l = q + 1; l < members.size(); ++l) {
      const std::uint32_t j = members[l];
      const Vec2 d = pos[l] - pos[q];
      const double R = w.radius[m] + w.radius[j];
      const double dl = length(d);
      if (!(dl > 0.0) || std::fabs(dl - R) > 1e-9 * (R + w.length_scale)) continue;
      gc.push_back({static_cast<std::int32_t>(q), static_cast<std::int32_t>(l), m, j, d / dl,
                    holding_coefficient(w.pair_material(w.material[m], w.material[j]))});
    }
  }
  // Forces that hold every member still: rows of normal and (with friction) tangential
  // force, an acceleration-level contact problem solved by projected Gauss-Seidel.
  struct Row {
    std::int32_t a, b;
    Vec2 d;
    std::size_t c;
    bool tangent;
  };
  thread_local std::vector<Row> rows;
  thread_local std::vector<double> lam, Akk;
  thread_local std::vector<Vec2> acc;   // members' accelerations under the current forces
  rows.clear();
  for (std::size_t k = 0; k < gc.size(); ++k) {
    rows.push_back({gc[k].a, gc[k].b, gc[k].n, k, false});
    if (gc[k].mu > 0.0) rows.push_back({gc[k].a, gc[k].b, perp(gc[k].n), k, true});
  }
  const auto inv = [&](std::int32_t x) { return x < 0 ? 0.0 : w.inv_mass[members[static_cast<std::size_t>(x)]]; };
  acc.resize(members.size());
  for (std::size_t q = 0; q < members.size(); ++q) acc[q] = w.acc[members[q]];
  lam.assign(rows.size(), 0.0);
  Akk.resize(rows.size());
  for (std::size_t k = 0; k < rows.size(); ++k) Akk[k] = inv(rows[k].a) + inv(rows[k].b);
  const auto rel = [&](const Row& r) {
    const Vec2 ab = r.b < 0 ? Vec2{} : acc[static_cast<std::size_t>(r.b)];
    const Vec2 aa = r.a < 0 ? Vec2{} : acc[static_cast<std::size_t>(r.a)];
    return dot(ab - aa, r.d);
  };
  double amax = 0.0;
  for (std::size_t q = 0; q < members.size(); ++q) amax = std::max(amax, length(acc[q]));
  for (int iter = 0; iter < 20000; ++iter) {
    double change = 0.0;
    for (std::size_t k = 0; k < rows.size(); ++k) {
      const Row& r = rows[k];
      if (!(Akk[k] > 0.0)) continue;
      const double wk = rel(r);
      const double l = projected_row(lam[k], wk, Akk[k], r.tangent, r.tangent ? gc[r.c].mu * lam[k - 1] : 0.0);
      const double dl = l - lam[k];
      if (dl == 0.0) continue;
      lam[k] = l;
      if (r.a >= 0) acc[static_cast<std::size_t>(r.a)] -= (dl * inv(r.a)) * r.d;
      if (r.b >= 0) acc[static_cast<std::size_t>(r.b)] += (dl * inv(r.b)) * r.d;
      change = std::max(change, std::fabs(dl) * Akk[k]);
    }
    if (change <= 1e-14 * amax) break;
  }
  for (std::size_t q = 0; q < members.size(); ++q) {
    if (length(acc[q]) > 1e-9 * length(w.acc[members[q]])) return false;
  }
  // Held, all of them, where they are at t.
  for (std::size_t q = 0; q < members.size(); ++q) {
    const std::uint32_t m = members[q];
    w.advance(m, t);
    release_support(w, m);
    w.vel[m] = {};
    w.apath[m] = {};
    w.support[m] = kHeld;
    w.support_n[m] = (-1.0 / length(w.acc[m])) * w.acc[m];
  }
  for (const GroupContact& c : gc) {
    w.held.push_back({c.other_b, c.other_a, c.n});
    if (c.a >= 0) w.held.push_back({c.other_a, c.other_b, -c.n});
  }
  return true;
}

bool try_hold_group_pocket(World& w, std::uint32_t seed, double t, double dt, const NearFn& near_fn,
                           std::vector<std::uint32_t>& members) {
  members.clear();
  if (!w.dynamic(seed) || w.acc.empty() || w.supported(seed)) return false;
  const auto slow = [&](std::uint32_t j) {
    const double a = length(w.acc[j]);
    return a > 0.0 && length(w.vel_at(j, t)) <= w.rest_speed(a, dt);
  };
  if (!slow(seed)) return false;
  const double reach = w.rest_speed(length(w.acc[seed]), dt) * dt;
  constexpr std::size_t kMaxMembers = 64;
  thread_local std::vector<std::uint32_t> buf, group;
  thread_local std::vector<Vec2> p0, pos, delta;
  const auto pair_ok = [&](std::uint32_t m, std::uint32_t j) {
    if (j == m || !w.alive(j)) return false;
    if ((w.flags[m] & kPoint) && (w.flags[j] & kPoint)) return false;
    if (((w.flags[m] | w.flags[j]) & kParticle) && related_bodies(w, m, j)) return false;
    if (w.any_rules && !w.response(w.group[m], w.group[j]).collide) return false;
    return true;
  };
  // The slow free bodies within reach of the seed, and of those in turn. A moving body
  // that near (or one sliding on a face) ends it: nothing is held.
  members.assign(1, seed);
  for (std::size_t q = 0; q < members.size(); ++q) {
    const std::uint32_t m = members[q];
    near_fn(w.pos_at(m, t), 2.0 * w.radius[m] + reach, buf);
    for (std::uint32_t j : buf) {
      if (!pair_ok(m, j) || w.stationary(j)) continue;
      if (std::find(members.begin(), members.end(), j) != members.end()) continue;
      if (length(w.pos_at(j, t) - w.pos_at(m, t)) - (w.radius[m] + w.radius[j]) > reach) continue;
      if (!w.dynamic(j) || (w.supported(j) && !frictionless_slider(w, j)) || !slow(j)) return false;
      members.push_back(j);
      if (members.size() > kMaxMembers) return false;
    }
  }
  // Near contacts: member pairs, and members with stationary bodies and faces.
  struct Near {
    std::int32_t a, b;   // member indices; a = -1: a fixed body (other) or face (seg)
    std::uint32_t other;
    bool face;
  };
  thread_local std::vector<Near> cs;
  cs.clear();
  const std::size_t M = members.size();
  for (std::size_t q = 0; q < M; ++q) {
    const std::uint32_t m = members[q];
    const double r = w.radius[m];
    const Vec2 p = w.pos_at(m, t);
    if (!w.statics.segments.empty()) {
      w.found_static.clear();
      const double pad = r + reach;
      w.statics.query(make_aabb(p.x - pad, p.y - pad, p.x + pad, p.y + pad), w.found_static);
      for (std::uint32_t k : w.found_static) {
        const Segment& s = w.statics.segments[k];
        if (w.any_rules && !w.response(w.group[m], s.group).collide) continue;
        if (s.normal_from.x != 0.0 || s.normal_from.y != 0.0) return false;   // a surface: its own response
        const double u = dot(p - s.from, s.dir);
        if (u < 0.0 || u > s.length) continue;   // ends: the overlap test below guards them
        if (std::fabs(dot(p - s.from, s.normal)) - r > reach) continue;
        cs.push_back({-1, static_cast<std::int32_t>(q), k, true});
      }
    }
    near_fn(p, 2.0 * r + reach, buf);
    for (std::uint32_t j : buf) {
      if (!pair_ok(m, j)) continue;
      if (length(w.pos_at(j, t) - p) - (r + w.radius[j]) > reach) continue;
      if (w.stationary(j)) {
        cs.push_back({-1, static_cast<std::int32_t>(q), j, false});
        continue;
      }
      const auto l = std::find(members.begin(), members.end(), j) - members.begin();
      if (static_cast<std::size_t>(l) > q) cs.push_back({static_cast<std::int32_t>(q), static_cast<std::int32_t>(l), j, false});
    }
  }
  if (cs.empty()) return false;
  // Close every near contact: Newton on the gaps, each step the smallest mass-weighted
  // displacement (J W J^T lambda = -gap by Gauss-Seidel, delta = W J^T lambda).
  p0.resize(M);
  pos.resize(M);
  delta.resize(M);
  for (std::size_t q = 0; q < M; ++q) p0[q] = pos[q] = w.pos_at(members[q], t);
  const double close_tol = 1e-13 * (2.0 * w.radius[seed] + w.length_scale);
  thread_local std::vector<double> gap, lam, akk;
  thread_local std::vector<Vec2> nrm;
  const std::size_t C = cs.size();
  gap.resize(C);
  lam.resize(C);
  akk.resize(C);
  nrm.resize(C);
  const auto inv = [&](std::int32_t x) { return x < 0 ? 0.0 : w.inv_mass[members[static_cast<std::size_t>(x)]]; };
  const auto measure = [&]() -> double {
    double worst = 0.0;
    for (std::size_t k = 0; k < C; ++k) {
      const Near& c = cs[k];
      const std::uint32_t mb = members[static_cast<std::size_t>(c.b)];
      const Vec2 pb = pos[static_cast<std::size_t>(c.b)];
      if (c.face) {
        const Segment& s = w.statics.segments[c.other];
        const double D = dot(pb - s.from, s.normal);
        nrm[k] = D >= 0.0 ? s.normal : -s.normal;
        gap[k] = std::fabs(D) - w.radius[mb];
      } else {
        const Vec2 pa = c.a < 0 ? w.pos_at(c.other, t) : pos[static_cast<std::size_t>(c.a)];
        const std::uint32_t ma = c.a < 0 ? c.other : members[static_cast<std::size_t>(c.a)];
        const Vec2 d = pb - pa;
        const double dl = length(d);
        if (!(dl > 0.0)) return INFINITY;
        nrm[k] = d / dl;
        gap[k] = dl - (w.radius[ma] + w.radius[mb]);
      }
      worst = std::max(worst, std::fabs(gap[k]));
    }
    return worst;
  };
  bool closed = false;
  for (int newton = 0; newton < 12; ++newton) {
    const double worst = measure();
    if (!(worst < INFINITY)) return false;
    if (worst <= close_tol) {
      closed = true;
      break;
    }
    std::fill(lam.begin(), lam.end(), 0.0);
    std::fill(delta.begin(), delta.end(), Vec2{});
    for (std::size_t k = 0; k < C; ++k) akk[k] = inv(cs[k].a) + inv(cs[k].b);
    bool converged = false;
    for (int sweep = 0; sweep < 2000 && !converged; ++sweep) {
      double resid = 0.0;
      for (std::size_t k = 0; k < C; ++k) {
        if (!(akk[k] > 0.0)) continue;
        const Near& c = cs[k];
        const Vec2 da = c.a < 0 ? Vec2{} : delta[static_cast<std::size_t>(c.a)];
        const Vec2 db = delta[static_cast<std::size_t>(c.b)];
        const double rk = gap[k] + dot(db - da, nrm[k]);
        resid = std::max(resid, std::fabs(rk));
        const double dl = -rk / akk[k];
        lam[k] += dl;
        if (c.a >= 0) delta[static_cast<std::size_t>(c.a)] -= (dl * inv(c.a)) * nrm[k];
        delta[static_cast<std::size_t>(c.b)] += (dl * inv(c.b)) * nrm[k];
      }
      converged = resid <= 0.01 * close_tol;
    }
    if (!converged) return false;   // the near contacts cannot all close at once
    for (std::size_t q = 0; q < M; ++q) {
      pos[q] += delta[q];
      if (length(pos[q] - p0[q]) > reach) return false;
    }
  }
  if (!closed) return false;
  // No energy gained: the forces' work along the move at least minus the kinetic energy.
  double work = 0.0, kinetic = 0.0;
  for (std::size_t q = 0; q < M; ++q) {
    const std::uint32_t m = members[q];
    const double mass = 1.0 / w.inv_mass[m];
    work += mass * dot(w.acc[m], pos[q] - p0[q]);
    kinetic += 0.5 * mass * length_squared(w.vel_at(m, t));
  }
  if (work + kinetic < 0.0) return false;
  // The members advance to t along their paths (nothing else changes), then move.
  for (std::size_t q = 0; q < M; ++q) {
    w.advance(members[q], t);
    w.pos[members[q]] = pos[q];
  }
  const auto restore = [&]() {
    for (std::size_t q = 0; q < M; ++q) w.pos[members[q]] = p0[q];
    return false;
  };
  for (std::size_t q = 0; q < M; ++q) {
    const std::uint32_t m = members[q];
    near_fn(w.pos[m], 2.0 * w.radius[m], buf);
    if (!clear_of_everything(w, m, buf)) return restore();
  }
  group.clear();
  if (!try_hold_group(w, seed, t, dt, near_fn, group)) return restore();
  // Held: any member left out of the held group goes back (it was only near).
  for (std::size_t q = 0; q < M; ++q) {
    if (std::find(group.begin(), group.end(), members[q]) == group.end()) {
      w.pos[members[q]] = p0[q];
    }
  }
  members = group;
  return true;
}

namespace {

// The bodies near a member of a resting component: every live body, sorted by x, so that
// those that may touch a member are a window.
struct BodiesByX {
  std::vector<std::uint32_t> order;
  double rmax = 0.0;
  void build(const World& w) {
    order.clear();
    rmax = 0.0;
    for (std::uint32_t j = 0; j < w.size(); ++j) {
      if (w.alive(j)) {
        order.push_back(j);
        rmax = std::max(rmax, w.radius[j]);
      }
    }
    std::sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) {
      return w.pos[a].x < w.pos[b].x || (w.pos[a].x == w.pos[b].x && a < b);
    });
  }
  // The bodies touching body m (as touching_supports: within 1e-9 of contact), that may
  // collide with it; out gets (body, unit normal from it towards m).
  void touching(const World& w, std::uint32_t m, std::vector<std::pair<std::uint32_t, Vec2>>& out) const {
    out.clear();
    const double reach = w.radius[m] + rmax + 1e-9 * (w.radius[m] + rmax + w.length_scale);
    auto it = std::lower_bound(order.begin(), order.end(), w.pos[m].x - reach,
                               [&](std::uint32_t a, double x) { return w.pos[a].x < x; });
    for (; it != order.end() && w.pos[*it].x <= w.pos[m].x + reach; ++it) {
      const std::uint32_t j = *it;
      if (j == m || std::fabs(w.pos[j].y - w.pos[m].y) > reach) continue;
      Vec2 nrm;
      if (!in_contact(w, m, j, nrm)) continue;
      out.push_back({j, nrm});
    }
  }
};

// The resting component of body `seed`: the dynamic bodies that touch it, and those that
// touch them in turn, all at rest or slow (|v| <= the rest speed of their force, as core
// holds bodies: a body micro-bouncing on the group presses on it); static bodies and faces
// are fixed. Sorted. False when a faster body touches a member: the component is being
// struck, not at rest, and is not judged now.
bool resting_component(World& w, const BodiesByX& bx, std::uint32_t seed, std::vector<std::uint32_t>& members) {
  thread_local std::vector<std::pair<std::uint32_t, Vec2>> touch;
  members.assign(1, seed);
  for (std::size_t q = 0; q < members.size(); ++q) {
    bx.touching(w, members[q], touch);
    for (const auto& [j, nrm] : touch) {
      if (!w.dynamic(j) || std::find(members.begin(), members.end(), j) != members.end()) continue;
      if (!w.stationary(j) && length(w.vel[j]) > w.rest_speed(length(w.acc[j]), w.step_dt)) return false;
      members.push_back(j);
    }
  }
  std::sort(members.begin(), members.end());
  return true;
}

// The least-squares contact forces of a component exactly: forces x >= 0 on its C columns
// (column k: a force along d on member b, minus it on member a; a < 0: a fixed support)
// minimising sum_q m_q |a_q|^2, a_q a member's force acceleration plus its forces over its
// mass, i.e. min |B x - y| in mass-weighted form (B's rows sqrt(1/m) d, y = -sqrt(m) a).
// Lawson and Hanson's active-set method (nnls.hpp); each unconstrained solve on the active
// columns by Householder QR. False if it does not finish (3 C + 30 additions) or an active
// set is singular.
template <class ColFn>
bool exact_least_squares(const World& w, std::span<const std::uint32_t> members, std::size_t C, ColFn col,
                         std::vector<double>& x) {
  const std::size_t M = members.size(), R = 2 * M;
  std::vector<double> B(R * C, 0.0), y(R);
  const auto at = [&](std::size_t row, std::size_t k) -> double& { return B[k * R + row]; };
  for (std::size_t k = 0; k < C; ++k) {
    const auto [a, b, d] = col(k);
    const double sb = std::sqrt(w.inv_mass[members[static_cast<std::size_t>(b)]]);
    at(2 * static_cast<std::size_t>(b), k) += sb * d.x;
    at(2 * static_cast<std::size_t>(b) + 1, k) += sb * d.y;
    if (a >= 0) {
      const double sa = std::sqrt(w.inv_mass[members[static_cast<std::size_t>(a)]]);
      at(2 * static_cast<std::size_t>(a), k) -= sa * d.x;
      at(2 * static_cast<std::size_t>(a) + 1, k) -= sa * d.y;
    }
  }
  for (std::size_t q = 0; q < M; ++q) {
    const double s = -1.0 / std::sqrt(w.inv_mass[members[q]]);
    y[2 * q] = s * w.acc[members[q]].x;
    y[2 * q + 1] = s * w.acc[members[q]].y;
  }
  return nnls(R, C, B, y, x);
}

// Whether a resting component (sorted members; faces and static bodies fixed) can be held
// by rigid Coulomb contact: a normal force >= 0 at every contact and a static friction
// force within mu times it, every member's acceleration zero. The tolerances of
// leaning_group_holds (held iff every member ends with |a| <= 1e-9 of its force
// acceleration; Gauss-Seidel stops at 1e-14 of the largest, or after 20000 sweeps), with no
// member taken as fixed. kCannotHold only with a certificate (below), else kUndecided.
// `residual`: the largest acceleration left on a member by Gauss-Seidel.
enum class Verdict { kHeld, kCannotHold, kUndecided };
constexpr std::size_t kMaxExact = 256;   // columns and members an exact solve takes on

Verdict component_holds(World& w, const BodiesByX& bx, std::span<const std::uint32_t> members, double& residual) {
  thread_local std::vector<std::pair<std::uint32_t, Vec2>> touch;
  thread_local std::vector<HeldContact> faces;
  thread_local std::vector<double> mus;
  const std::size_t M = members.size();
  // One column per edge of each contact's static friction cone (n +- mu t; n alone when
  // frictionless): a force >= 0 along each. In 2D the two edges span the Coulomb cone
  // exactly, so the members can be held iff some forces >= 0 cancel every member's force:
  // a convex problem (least squares with non-negative forces), whose projected Gauss-Seidel
  // (coordinate descent) converges to its minimum: zero iff held.
  struct Col {
    std::int32_t a, b;   // member indices; a = -1: a fixed support
    Vec2 d;              // the force on b per unit (on a: minus it)
    double height;       // of the contact, along the members' mean force (for the order)
    bool edge;           // a friction cone's edge (else a frictionless contact's normal)
  };
  thread_local std::vector<Col> cols;
  cols.clear();
  Vec2 down{};
  for (std::size_t q = 0; q < M; ++q) down += w.acc[members[q]];
  const auto add = [&](std::int32_t a, std::int32_t b, Vec2 nrm, double m, Vec2 at) {
    const double h = -dot(at, down);
    if (m > 0.0) {
      cols.push_back({a, b, nrm + m * perp(nrm), h, true});
      cols.push_back({a, b, nrm - m * perp(nrm), h, true});
    } else {
      cols.push_back({a, b, nrm, h, false});
    }
  };
  for (std::size_t q = 0; q < M; ++q) {
    const std::uint32_t m = members[q];
    const auto b = static_cast<std::int32_t>(q);
    faces.clear();
    mus.clear();
    touching_supports(w, m, {}, faces, mus);   // its faces
    for (std::size_t k = 0; k < faces.size(); ++k) add(-1, b, faces[k].n, mus[k], w.pos[m] - w.radius[m] * faces[k].n);
    bx.touching(w, m, touch);
    for (const auto& [j, nrm] : touch) {
      const double mu = holding_coefficient(w.pair_material(w.material[m], w.material[j]));
      const Vec2 at = w.pos[m] - w.radius[m] * nrm;
      if (!w.dynamic(j)) {
        add(-1, b, nrm, mu, at);
        continue;
      }
      const auto it = std::lower_bound(members.begin(), members.end(), j);
      if (it == members.end() || *it != j) continue;   // not possible: members are closed under touching
      const auto o = static_cast<std::int32_t>(it - members.begin());
      if (o < b) continue;   // the pair's column is there already
      add(o, b, nrm, mu, at);
    }
  }
  // Highest contacts first: a load is passed down a column in one sweep, not one contact a
  // sweep (a column of 50 balls reached only 3e-8 of g in 20000 sweeps in index order).
  std::stable_sort(cols.begin(), cols.end(), [](const Col& x, const Col& y) { return x.height > y.height; });
  thread_local std::vector<Vec2> acc;
  thread_local std::vector<double> lam, Akk;
  acc.resize(M);
  for (std::size_t q = 0; q < M; ++q) acc[q] = w.acc[members[q]];
  const auto inv = [&](std::int32_t x) { return x < 0 ? 0.0 : w.inv_mass[members[static_cast<std::size_t>(x)]]; };
  const std::size_t C = cols.size();
  lam.assign(C, 0.0);
  Akk.resize(C);
  for (std::size_t k = 0; k < C; ++k) Akk[k] = (inv(cols[k].a) + inv(cols[k].b)) * length_squared(cols[k].d);
  double amax = 0.0;
  for (std::size_t q = 0; q < M; ++q) amax = std::max(amax, length(acc[q]));
  bool converged = false;
  for (int iter = 0; iter < 20000 && !converged; ++iter) {
    double change = 0.0;
    for (std::size_t x = 0; x < C; ++x) {   // forward, then backward (symmetric Gauss-Seidel)
      const std::size_t k = (iter & 1) ? C - 1 - x : x;
      const Col& c = cols[k];
      if (!(Akk[k] > 0.0)) continue;
      const Vec2 ab = acc[static_cast<std::size_t>(c.b)];
      const Vec2 aa = c.a < 0 ? Vec2{} : acc[static_cast<std::size_t>(c.a)];
      const double l = projected_row(lam[k], dot(ab - aa, c.d), Akk[k], false, 0.0);
      const double dl = l - lam[k];
      if (dl == 0.0) continue;
      lam[k] = l;
      if (c.a >= 0) acc[static_cast<std::size_t>(c.a)] -= (dl * inv(c.a)) * c.d;
      acc[static_cast<std::size_t>(c.b)] += (dl * inv(c.b)) * c.d;
      change = std::max(change, std::fabs(dl) * Akk[k]);
    }
    converged = change <= 1e-14 * amax;
  }
  // At rest: within 1e-9 of its force acceleration, or within the round-off of summing its
  // contact forces (64 eps x their sum over its mass). Without the latter a ball of 1 kg
  // under one of 1e9 kg in a column (held exactly) was never "at rest": 1e-9 of g is 1e-19
  // of the forces on it, and the run was reported as a hold core could not show.
  thread_local std::vector<double> force_sum;
  // force_sum: each member's contact forces l summed as magnitudes over its mass.
  const auto sum_forces = [&](std::span<const double> l) {
    force_sum.assign(M, 0.0);
    for (std::size_t k = 0; k < C; ++k) {
      const double f = std::fabs(l[k]) * length(cols[k].d);
      if (cols[k].a >= 0) force_sum[static_cast<std::size_t>(cols[k].a)] += f * inv(cols[k].a);
      force_sum[static_cast<std::size_t>(cols[k].b)] += f * inv(cols[k].b);
    }
  };
  // out: each member's force acceleration plus its contact forces l over its mass.
  const auto accelerations = [&](std::span<const double> l, std::vector<Vec2>& out) {
    out.resize(M);
    for (std::size_t q = 0; q < M; ++q) out[q] = w.acc[members[q]];
    for (std::size_t k = 0; k < C; ++k) {
      const Col& c = cols[k];
      if (l[k] == 0.0) continue;
      if (c.a >= 0) out[static_cast<std::size_t>(c.a)] -= (l[k] * inv(c.a)) * c.d;
      out[static_cast<std::size_t>(c.b)] += (l[k] * inv(c.b)) * c.d;
    }
  };
  const auto all_at_rest = [&](std::span<const Vec2> a, std::span<const double> l) {
    sum_forces(l);
    for (std::size_t q = 0; q < M; ++q) {
      if (length(a[q]) > 1e-9 * length(w.acc[members[q]]) + 64.0 * 2.220446049250313e-16 * force_sum[q]) return false;
    }
    return true;
  };
  bool held = all_at_rest(acc, lam);
  residual = 0.0;
  for (std::size_t q = 0; q < M; ++q) residual = std::max(residual, length(acc[q]));
  for (int pass = 0; pass < 2 && !held; ++pass) {
    // Gauss-Seidel crawls along long chains (a column of 50 balls: its rate is 1 - (pi /
    // 101)^2 a sweep). Polish: keep the contacts it loads, and solve for the corrections to
    // their forces that cancel the rest exactly (least squares by conjugate gradients, CGLS,
    // in mass-weighted form: the member's sqrt(m) a). Held iff every corrected force is
    // still >= 0 and, summed afresh, leaves every member at rest within the same 1e-9.
    // A second pass takes every contact: with masses 1e9 apart Gauss-Seidel had not loaded
    // some contacts a column needs at all (a step moves the light member 1e9 times more
    // than the heavy one), and the polish over the loaded ones could not reach rest.
    thread_local std::vector<std::size_t> act;
    thread_local std::vector<double> x, pdir, sv, lam2;
    thread_local std::vector<Vec2> res, qv, acc2;
    act.clear();
    for (std::size_t k = 0; k < C; ++k) {
      if (pass == 1 || lam[k] > 0.0) act.push_back(k);
    }
    const std::size_t P = act.size();
    const auto sq = [&](std::int32_t m) { return std::sqrt(inv(m)); };
    const auto apply = [&](std::span<const double> v, std::vector<Vec2>& out) {   // out = B v
      out.assign(M, Vec2{});
      for (std::size_t z = 0; z < P; ++z) {
        const Col& c = cols[act[z]];
        if (c.a >= 0) out[static_cast<std::size_t>(c.a)] -= (v[z] * sq(c.a)) * c.d;
        out[static_cast<std::size_t>(c.b)] += (v[z] * sq(c.b)) * c.d;
      }
    };
    const auto apply_t = [&](std::span<const Vec2> r, std::vector<double>& out) {   // out = B^T r
      out.resize(P);
      for (std::size_t z = 0; z < P; ++z) {
        const Col& c = cols[act[z]];
        double v = sq(c.b) * dot(c.d, r[static_cast<std::size_t>(c.b)]);
        if (c.a >= 0) v -= sq(c.a) * dot(c.d, r[static_cast<std::size_t>(c.a)]);
        out[z] = v;
      }
    };
    res.resize(M);
    for (std::size_t q = 0; q < M; ++q) res[q] = (-1.0 / sq(static_cast<std::int32_t>(q))) * acc[q];   // -sqrt(m) a
    x.assign(P, 0.0);
    apply_t(res, sv);
    pdir = sv;
    double gamma = 0.0;
    for (double v : sv) gamma += v * v;
    const double gamma0 = gamma;
    for (std::size_t it = 0; it < 4 * P + 100 && gamma > 1e-32 * gamma0; ++it) {
      apply(pdir, qv);
      double qq = 0.0;
      for (const Vec2& v : qv) qq += length_squared(v);
      if (!(qq > 0.0)) break;
      const double alpha = gamma / qq;
      for (std::size_t z = 0; z < P; ++z) x[z] += alpha * pdir[z];
      for (std::size_t q = 0; q < M; ++q) res[q] -= alpha * qv[q];
      apply_t(res, sv);
      double gn = 0.0;
      for (double v : sv) gn += v * v;
      const double beta = gn / gamma;
      for (std::size_t z = 0; z < P; ++z) pdir[z] = sv[z] + beta * pdir[z];
      gamma = gn;
    }
    lam2 = lam;
    bool nonneg = true;
    for (std::size_t z = 0; z < P; ++z) {
      lam2[act[z]] += x[z];
      if (lam2[act[z]] < 0.0) nonneg = false;
    }
    if (nonneg) {
      accelerations(lam2, acc2);
      held = all_at_rest(acc2, lam2);
    }
  }
  if (held) return Verdict::kHeld;
  // Not held: the accelerations left are a certificate (Farkas) if they violate no contact:
  // every cone edge's relative acceleration along it >= 0 (to round-off, 1e-12 of the largest
  // force acceleration) while the forces do positive work along them (they are the least
  // mass-weighted residual, so their work is its square): a motion the contacts allow and
  // the forces drive. Else Gauss-Seidel has not converged and nothing is certain.
  //
  // The certificate is a motion: the members' accelerations under the least-squares forces,
  // which for frictionless contacts are rigid contact's own (Gauss's principle: a force >= 0
  // only where the pair's normal acceleration is 0, and >= 0 everywhere). It shows a hold
  // wrong only if it moves a body core keeps at rest (held, or stuck on its supports). If it
  // moves only members core lets move (a slow free body, or one sliding on a face, taken in
  // as it may be micro-bouncing on the others), and every force on a moving member is a
  // frictionless normal force (a cone edge's force is static friction's only between bodies
  // at rest), the forces are a rigid Coulomb solution in which every body core keeps at rest
  // is at rest: the holds are justified. (A ball falling past a held stack, touching its side
  // within 1e-9 on the way, was reported as the stack's hold failing: 9.8 m/s^2 left on the
  // falling ball, none on the stack.)
  // `exact`: forces from an exact least-squares solve (below), accurate to the round-off of
  // its largest forces (Householder QR is backward stable): a relative acceleration along an
  // edge >= -64 eps x the largest force acceleration on a member counts as >= 0 there. (A
  // member is at rest within the round-off of its own forces, as above: stricter.)
  const auto verdict_of = [&](std::span<const Vec2> a, std::span<const double> l, bool exact) {
    sum_forces(l);
    const auto slack = [&](std::int32_t x) { return x < 0 ? 0.0 : 64.0 * 2.220446049250313e-16 * force_sum[static_cast<std::size_t>(x)]; };
    const auto rel = [&](const Col& c) {
      const Vec2 aa = c.a < 0 ? Vec2{} : a[static_cast<std::size_t>(c.a)];
      return dot(a[static_cast<std::size_t>(c.b)] - aa, c.d) / length(c.d);
    };
    double solve_slack = 0.0;   // an exact solve's round-off: that of its largest forces
    for (std::size_t q = 0; q < M; ++q) solve_slack = std::max(solve_slack, slack(static_cast<std::int32_t>(q)));
    double work = 0.0;
    for (std::size_t q = 0; q < M; ++q) work += dot(w.acc[members[q]], a[q]) / inv(static_cast<std::int32_t>(q));
    if (!(work > 0.0)) return Verdict::kUndecided;
    for (const Col& c : cols) {
      if (!(rel(c) >= -1e-12 * amax - (exact ? solve_slack : 0.0))) return Verdict::kUndecided;
    }
    const auto moves = [&](std::int32_t q) {   // the certificate moves member q
      if (q < 0) return false;
      const auto u = static_cast<std::size_t>(q);
      return length(a[u]) > 1e-9 * length(w.acc[members[u]]) + slack(q);
    };
    for (std::size_t q = 0; q < M; ++q) {
      const std::uint32_t m = members[q];
      if (moves(static_cast<std::int32_t>(q)) && (w.is_held(m) || w.stationary(m))) return Verdict::kCannotHold;
    }
    for (std::size_t k = 0; k < C; ++k) {
      const Col& c = cols[k];
      if (!(l[k] > 0.0) || !(moves(c.a) || moves(c.b))) continue;
      if (c.edge) return Verdict::kCannotHold;
      // A frictionless force on a moving member: its pair's normal acceleration 0 (to the
      // at-rest bound), else the force pushes bodies that part and is no solution.
      if (rel(c) > 1e-9 * amax) return Verdict::kCannotHold;
    }
    return Verdict::kHeld;
  };
  const Verdict v = verdict_of(acc, lam, false);
  if (v != Verdict::kUndecided || C > kMaxExact || M > kMaxExact) return v;
  // Gauss-Seidel had not converged (forces 1e7 times the weights, at contacts 1e-7 rad off
  // the horizontal, crawl): the least-squares forces exactly (Lawson-Hanson's active set,
  // each solve by Householder QR), and the same verdict on them.
  thread_local std::vector<double> x;
  thread_local std::vector<Vec2> acc2;
  if (!exact_least_squares(w, members, C, [&](std::size_t k) { return std::tuple(cols[k].a, cols[k].b, cols[k].d); }, x)) {
    return Verdict::kUndecided;
  }
  accelerations(x, acc2);
  // Its forces (>= 0: NNLS keeps them so) leave every member at rest, by the same test as
  // Gauss-Seidel's: held. (Not asked before: a row struck into a wall, held exactly, where
  // Gauss-Seidel left 4e-5 m/s^2 and the exact solve 1.5e-14, was reported as a hold core
  // "could not show", since a held component has no certificate either.)
  if (all_at_rest(acc2, x)) return Verdict::kHeld;
  const Verdict ve = verdict_of(acc2, x, true);
  if (ve == Verdict::kCannotHold) {
    residual = 0.0;
    for (std::size_t q = 0; q < M; ++q) residual = std::max(residual, length(acc2[q]));
  }
  return ve;
}

}  // namespace

// The free bodies try_hold held this step on a group that other bodies brace, still held
// once the step's supports are settled: each judged on its resting component
// (component_holds). A component that cannot hold is a broken guarantee, as an unbraced
// group is in try_hold. Components found able to hold are remembered (members, positions
// and force accelerations, bit for bit): a settled pile is solved once.
void judge_braced_holds(World& w, bool engage) {
  if (w.braced_holds.empty()) return;
  thread_local BodiesByX bx;
  thread_local std::vector<std::uint32_t> members, judged;
  thread_local World::JudgedComponent key;
  judged.clear();
  bool built = false;
  for (std::uint32_t i : w.braced_holds) {
    if (w.unjustified_hold != kNone) break;
    if (!w.alive(i) || !w.is_held(i)) continue;   // core moved it: not a hold any more
    if (std::find(judged.begin(), judged.end(), i) != judged.end()) continue;   // its component is judged
    if (!built) {
      bx.build(w);
      built = true;
    }
    if (!resting_component(w, bx, i, members)) continue;   // struck: judged again next step if still held
    judged.insert(judged.end(), members.begin(), members.end());
    key.members = members;
    key.state.clear();
    for (std::uint32_t m : members) {
      key.state.push_back(w.pos[m]);
      key.state.push_back(w.acc[m]);
    }
    const auto same = [&](const World::JudgedComponent& c) { return c.members == key.members && c.state == key.state; };
    if (std::any_of(w.justified_components.begin(), w.justified_components.end(), same)) continue;
    double residual = 0.0;
    const Verdict v = component_holds(w, bx, members, residual);
    if (v == Verdict::kHeld) {
      if (w.justified_components.size() >= 8) w.justified_components.erase(w.justified_components.begin());
      w.justified_components.push_back(key);
      continue;
    }
    // A component that must move: moved by the contact-group mode where it applies (at a
    // step's start, its members all at rest), else a broken guarantee.
    if (engage && v == Verdict::kCannotHold && engage_contact_group(w, members)) continue;
    w.unjustified_hold = i;
    w.unjustified_hold_time = w.time;
    w.unjustified_component = members.size();
    w.unjustified_residual = residual;
    w.unjustified_undecided = v == Verdict::kUndecided;
  }
  w.braced_holds.clear();
}

bool hold_wedged(World& w, std::uint32_t i, double dt, std::span<const std::uint32_t> near) {
  if (!w.dynamic(i) || w.is_held(i) || w.acc.empty()) return false;
  const double amag = length(w.acc[i]);
  if (!(amag > 0.0) || length(w.vel[i]) > w.rest_speed(amag, dt)) return false;
  thread_local std::vector<HeldContact> contacts;
  thread_local std::vector<double> mu;
  contacts.clear();
  mu.clear();
  touching_supports(w, i, near, contacts, mu);
  if (contacts.empty()) return false;
  release_support(w, i);
  w.vel[i] = {};
  w.apath[i] = {};
  w.support[i] = kHeld;
  w.support_n[i] = (-1.0 / amag) * w.acc[i];
  w.held.insert(w.held.end(), contacts.begin(), contacts.end());
  return true;
}

std::vector<RestingContact> resting_contacts(const World& w) {
  std::vector<RestingContact> out;
  if (w.support.empty()) return out;
  const std::size_t n = w.size();
  for (std::uint32_t i = 0; i < n; ++i) {
    if (!w.alive(i) || !w.stuck(i) || w.is_held(i)) continue;
    out.push_back({i, w.on_body(i) ? (w.support[i] & ~kBodySupport) : (kBodySupport | w.support[i]), w.support_n[i], 0.0});
  }
  for (const HeldContact& c : w.held) {
    // A pair of held bodies appears once per body: keep the one from the larger index.
    if (!(c.other & kBodySupport) && w.is_held(c.other) && c.other > c.body) continue;
    out.push_back({c.body, c.other, c.n, 0.0});
  }
  // Accelerations of the bodies at rest under their forces and the contact forces.
  std::vector<Vec2> acc(n);
  std::vector<std::uint8_t> rest(n, 0);
  for (std::uint32_t i = 0; i < n; ++i) {
    if (w.alive(i) && w.stuck(i)) {
      rest[i] = 1;
      acc[i] = w.acc[i];
    }
  }
  const auto moving = [&](std::uint32_t x) { return !(x & kBodySupport) && x < n && rest[x]; };
  const auto inv = [&](std::uint32_t x) { return moving(x) ? w.inv_mass[x] : 0.0; };
  double amax = 0.0;
  for (std::uint32_t i = 0; i < n; ++i) amax = std::max(amax, length(acc[i]));
  for (int iter = 0; iter < 200000; ++iter) {
    double change = 0.0;
    for (RestingContact& c : out) {
      const double akk = inv(c.body) + inv(c.other);
      if (!(akk > 0.0)) continue;
      const Vec2 ao = moving(c.other) ? acc[c.other] : Vec2{};
      const double wk = dot(acc[c.body] - ao, c.n);
      const double f = std::max(0.0, c.force - wk / akk);
      const double df = f - c.force;
      if (df == 0.0) continue;
      c.force = f;
      acc[c.body] += (df * inv(c.body)) * c.n;
      if (moving(c.other)) acc[c.other] -= (df * inv(c.other)) * c.n;
      change = std::max(change, std::fabs(df) * akk);
    }
    if (change <= 1e-15 * amax) break;
  }
  return out;
}

void unhold(World& w, std::uint32_t i) { release_support(w, i); }

void held_on(const World& w, std::uint32_t j, std::vector<std::uint32_t>& out) {
  for (const HeldContact& c : w.held) {
    if (c.other == j && std::find(out.begin(), out.end(), c.body) == out.end()) out.push_back(c.body);
  }
}

namespace {

// A body touching a face, pressed into it and not moving away, settles onto it at the
// start of the step (so that even explicit Euler, which applies a force only at the
// end of a step, never pulls a resting body into its support).
void detect_support(World& w, std::uint32_t i, const StepContext& ctx) {
  const double r = w.radius[i];
  const Vec2 p = w.pos[i];
  const double tol = 1e-9 * (r + w.length_scale);
  w.found_static.clear();
  w.statics.query(make_aabb(p.x - r - tol, p.y - r - tol, p.x + r + tol, p.y + r + tol), w.found_static);
  for (std::uint32_t k : w.found_static) {
    const Segment& s = w.statics.segments[k];
    if (w.any_rules && !w.response(w.group[i], s.group).collide) continue;
    const double u = dot(p - s.from, s.dir);
    if (u < 0.0 || u > s.length) continue;
    const double D = dot(p - s.from, s.normal);
    // A point exactly on the line is on the side its force presses it from (toi::line_side).
    const Vec2 n = toi::line_side(D, dot(w.vel[i], s.normal), dot(w.acc[i], s.normal)) * s.normal;
    if (std::fabs(std::fabs(D) - r) > tol) continue;
    const double an = dot(w.acc[i], n);
    if (!(an < 0.0)) continue;
    const double vn = dot(w.vel[i], n);
    // Moving off the face only beyond the round-off of its velocity's components (a ball
    // launched at 3 m/s along a 5 degree slope read v.n = +1e-16 and was left free, met the
    // face and its neighbour as impacts at once, and never became a train).
    // Moving into it: settled below the rest speed, an elastic face (e = 1) only at
    // round-off (World::impact_rest_speed: it bounces).
    const PairMaterial m = w.pair_material(w.material[i], s.material);
    const double e = m.restitution;
    if (vn > 64.0 * 2.220446049250313e-16 * length(w.vel[i]) || -vn > w.impact_rest_speed(an, ctx.dt, e, vn)) continue;
    // A frictionless face with 0 < e < 1 met faster than round-off where World::zeno_tails (a
    // step that ends just before a bounce of a Zeno sequence): an impact, whose sequence the
    // event loop ends at its closed-form time (zeno_tail); settled here it stopped early.
    if (w.zeno_tails() && World::zeno_material(m, w.vel[i], w.acc[i], n) && (w.flags[i] & (kParticle | kPoint | kDestroyOnHit)) == 0 &&
        -vn > 64.0 * 2.220446049250313e-16 * (length(w.vel[i]) + std::fabs(an) * ctx.dt)) {
      continue;
    }
    w.support[i] = k;
    w.support_n[i] = n;
    record_contact(w, i, kNone, &s, ctx.t0, ctx.dt);
    return;
  }
}

// The stationary bodies near a point: a uniform grid over them, rebuilt per pass.
class NearGrid {
 public:
  void build(const World& w, double cell, bool stationary_only = true) {
    cell_ = cell;
    keyed_.clear();
    for (std::uint32_t j = 0; j < w.size(); ++j) {
      if (w.alive(j) && (w.stationary(j) || !stationary_only)) keyed_.push_back({key(w.pos[j]), j});
    }
    std::sort(keyed_.begin(), keyed_.end());
  }
  void query(Vec2 p, std::vector<std::uint32_t>& out) const {
    out.clear();
    const auto cx = static_cast<std::int64_t>(std::floor(p.x / cell_));
    const auto cy = static_cast<std::int64_t>(std::floor(p.y / cell_));
    for (std::int64_t dx = -1; dx <= 1; ++dx) {
      for (std::int64_t dy = -1; dy <= 1; ++dy) {
        const std::uint64_t k = pack(cx + dx, cy + dy);
        auto it = std::lower_bound(keyed_.begin(), keyed_.end(), std::pair<std::uint64_t, std::uint32_t>{k, 0});
        for (; it != keyed_.end() && it->first == k; ++it) out.push_back(it->second);
      }
    }
  }

 private:
  static std::uint64_t pack(std::int64_t x, std::int64_t y) {
    return (static_cast<std::uint64_t>(x) << 32) ^ static_cast<std::uint32_t>(y);
  }
  std::uint64_t key(Vec2 p) const {
    return pack(static_cast<std::int64_t>(std::floor(p.x / cell_)), static_cast<std::int64_t>(std::floor(p.y / cell_)));
  }
  double cell_ = 1.0;
  std::vector<std::pair<std::uint64_t, std::uint32_t>> keyed_;
};

// Two bodies on faces touching with no relative normal velocity (push_trains).
struct TrainPair {
  std::uint32_t i, j;
  Vec2 nrm;   // from i to j
  double P;   // the push between them
};

// Every pair of dynamic bodies on faces (not on bodies) touching one another with no
// relative normal velocity, pressed by their own paths or not.
void train_pairs(const World& w, std::vector<TrainPair>& pairs) {
  const std::size_t n = w.size();
  thread_local std::vector<std::uint32_t> cand;
  cand.clear();
  pairs.clear();
  for (std::uint32_t i = 0; i < n; ++i) {
    if (w.dynamic(i) && w.supported(i) && !w.on_body(i)) cand.push_back(i);
  }
  if (cand.size() < 2) return;
  std::sort(cand.begin(), cand.end(), [&](std::uint32_t a, std::uint32_t b) {
    const double la = w.pos[a].x - w.radius[a], lb = w.pos[b].x - w.radius[b];
    return la < lb || (la == lb && a < b);
  });
  for (std::size_t x = 0; x < cand.size(); ++x) {
    const std::uint32_t i = cand[x];
    const double right = w.pos[i].x + w.radius[i];
    for (std::size_t y = x + 1; y < cand.size(); ++y) {
      const std::uint32_t j = cand[y];
      const double tol_reach = 1e-9 * (w.radius[i] + w.radius[j] + w.length_scale);
      if (w.pos[j].x - w.radius[j] > right + tol_reach) break;
      Vec2 from_j;
      if (!in_contact(w, i, j, from_j)) continue;
      const Vec2 nrm = -from_j;   // from i to j
      const double vn = dot(w.vel[j] - w.vel[i], nrm);
      if (std::fabs(vn) > 1e-12 * (length(w.vel[i]) + length(w.vel[j]))) continue;
      pairs.push_back({i, j, nrm, 0.0});
    }
  }
}

// Whether a train pair lies on one line: one face normal, the pair's normal along the face.
bool straight_pair(const World& w, const TrainPair& p) {
  return w.support_n[p.i] == w.support_n[p.j] && std::fabs(dot(p.nrm, perp(w.support_n[p.i]))) >= 1.0 - 1e-12;
}

// Whether body i, on its face, touches nothing but its face and bodies that are in a
// straight train with it (`train`: members of a straight pair): push_trains judges it
// with them, as one rigid block, held or sliding.
bool only_in_train(World& w, std::uint32_t i, std::span<const std::uint32_t> near, const std::vector<char>& train) {
  if (!train[i]) return false;
  thread_local std::vector<HeldContact> contacts;
  thread_local std::vector<double> mu;
  contacts.clear();
  mu.clear();
  touching_supports(w, i, near, contacts, mu);
  for (const HeldContact& c : contacts) {
    if (c.other & kBodySupport) {
      if ((c.other & ~kBodySupport) != w.support[i]) return false;   // a second face
    } else if (!(w.dynamic(c.other) && w.supported(c.other) && !w.on_body(c.other) && train[c.other])) {
      return false;   // a held body, a body on a body, a static one
    }
  }
  return true;
}

std::uint32_t held_partner_key(const World& w, const HeldContact& c) {
  return (c.other & kBodySupport) ? static_partner_key(w.statics.segments[c.other & ~kBodySupport].owner) : c.other;
}

// Held bodies are judged again against what they touch now (their supports may have
// gone); free slow bodies that their contacts can hold are held. Returns whether any
// body changed. Bodies freed here follow their free path for the step. held_now marks
// the bodies held by an earlier pass of this step's settling: they were judged then (a
// group's members together, by try_hold_group, whose test may pass where one member's
// alone does not), so they are not judged again one by one (else a column held as a
// group, released one member at a time and held again as a group, never settles: found
// by the thirteenth hunt).
bool hold_pass(World& w, const StepContext& ctx, std::vector<char>& held_now) {
  const std::size_t n = w.size();
  double rmax = 0.0;
  bool any = false;
  for (std::uint32_t i = 0; i < n; ++i) {
    if (!w.alive(i)) continue;
    rmax = std::max(rmax, w.radius[i]);
    if (w.is_held(i) || (w.dynamic(i) && (!w.supported(i) || !w.stuck(i)))) any = true;
  }
  if (!any) return false;
  thread_local NearGrid grid, all;
  thread_local std::vector<std::uint32_t> near, group;
  bool all_built = false;
  grid.build(w, std::max(2.0 * rmax, 1e-6 * w.length_scale) * (1.0 + 1e-6));
  bool changed = false;
  for (std::uint32_t i = 0; i < n; ++i) {
    if (!w.is_held(i) || held_now[i]) continue;
    unhold(w, i);
    w.apath[i] = {};
    grid.query(w.pos[i], near);
    if (try_hold(w, i, ctx.dt, near)) {
      for (const HeldContact& c : w.held) {
        if (c.body == i) touch_contact(w, i, held_partner_key(w, c), ctx.t0);
      }
      continue;
    }
    w.apath[i] = w.acc[i];
    changed = true;
    w.released.clear();
    collect_dependents(w, i);
    for (std::uint32_t d : w.released) release_support(w, d);
  }
  if (changed) grid.build(w, std::max(2.0 * rmax, 1e-6 * w.length_scale) * (1.0 + 1e-6));
  // Bodies in a straight train on a face: judged together by push_trains, not one by one
  // (found at the first driven body).
  thread_local std::vector<char> train;
  thread_local std::vector<TrainPair> train_pair_list;
  train.clear();
  bool trains_found = w.varying_forces;
  const auto in_a_train = [&](std::uint32_t i) {
    if (!trains_found) {
      trains_found = true;
      train_pairs(w, train_pair_list);
      for (const TrainPair& p : train_pair_list) {
        if (!straight_pair(w, p)) continue;
        if (train.empty()) train.assign(n, 0);
        train[p.i] = train[p.j] = 1;
      }
    }
    if (train.empty()) return false;
    grid.query(w.pos[i], near);
    return only_in_train(w, i, near, train);
  };
  for (std::uint32_t i = 0; i < n; ++i) {
    if (!w.dynamic(i) || w.riding(i)) continue;   // a cap's rider: convex_cap.cpp
    // Free, or at rest on its face and driven along it (the face alone cannot hold it: a
    // second may). A body sliding on its face keeps sliding to its exact stop event.
    const bool driven = w.supported(i) && !w.on_body(i) && w.vel[i] == Vec2{} &&
                        (w.apath[i].x != 0.0 || w.apath[i].y != 0.0);
    if (w.supported(i) && !driven) continue;
    if (driven && in_a_train(i)) continue;   // push_trains judges it
    grid.query(w.pos[i], near);
    group.clear();
    if (zeno_bounce(w, i, ctx.dt, near)) continue;
    if (try_hold(w, i, ctx.dt, near)) {
      group.push_back(i);
    } else if (!w.supported(i)) {
      // A group of slow bodies micro-bouncing on one another (each hop too short for any
      // of them to be caught touching all its supports at once): its pocket, if it holds.
      if (!all_built) {
        double amax = 0.0;
        for (std::uint32_t j = 0; j < n; ++j) {
          if (w.alive(j)) amax = std::max(amax, length(w.acc[j]));
        }
        all.build(w, (2.0 * rmax + w.rest_speed(amax, ctx.dt) * ctx.dt + 1e-6 * w.length_scale) * (1.0 + 1e-6), false);
        all_built = true;
      }
      const NearFn near_all = [&](Vec2 q, double, std::vector<std::uint32_t>& out) { all.query(q, out); };
      if (!try_hold_group_pocket(w, i, 0.0, ctx.dt, near_all, group)) continue;
      all_built = false;   // members moved
    } else {
      continue;
    }
    changed = true;
    for (std::uint32_t b : group) {
      held_now[b] = 1;
      for (const HeldContact& c : w.held) {
        if (c.body != b) continue;
        if (c.other & kBodySupport) {
          record_contact(w, b, kNone, &w.statics.segments[c.other & ~kBodySupport], ctx.t0, ctx.dt);
        } else {
          record_contact(w, b, c.other, nullptr, ctx.t0, ctx.dt);
        }
      }
    }
  }
  return changed;
}

// Bodies on faces touching one another while they slide or rest (a ball pushing another
// down a slope, the lower one's friction too much for the upper alone and too little for
// both): rigid bodies in contact move together, so each member feels its neighbours' push
// as a force. The pairs are all those touching on faces with no relative normal velocity,
// whether or not their own paths press them (two balls sliding alike behind a slower one
// are pressed only once the front one's push slows the middle one). The pair forces
// P_k >= 0 (along each pair's normal; no friction between them) solve the linear
// complementarity problem P_k >= 0, relative normal acceleration w_k >= 0, P_k w_k = 0,
// each member's acceleration being its face's law (support_acceleration: kinetic friction
// sliding, static from rest) under its own force plus the pushes: projected Gauss-Seidel
// finds it, a pair that separates keeps P = 0. A train of bodies on one line (one face
// normal, every pressed pair's normal along the face) is then a rigid block: its
// acceleration is its face's law for the block's total force, mass and friction, summed
// in the order along the face (so the same bits whatever the numbering), and every member
// gets that acceleration and the block's velocity to the bit (else round-off reads as an
// approach and the touching pair is met as an impact at once). The pushes are added to
// the members' force accelerations for the step and their paths recomputed, so every
// later event of the step (a stop, a hold) sees them. Constant forces only (under drag a
// face's law is integrated in sub-steps).
void push_trains(World& w) {
  const std::size_t n = w.size();
  thread_local std::vector<std::uint32_t> root, members, order;
  thread_local std::vector<Vec2> push;
  thread_local std::vector<char> mixed, in_block;
  thread_local std::vector<TrainPair> pairs;
  w.train_stopping.clear();
  for (std::uint32_t m : w.train_raw_list) w.train_raw_set[m] = 0;
  w.train_raw_list.clear();
  train_pairs(w, pairs);
  if (pairs.empty()) return;
  root.resize(n);
  mixed.assign(n, 0);
  in_block.assign(n, 0);
  push.assign(n, Vec2{});
  for (const TrainPair& p : pairs) root[p.i] = p.i, root[p.j] = p.j;
  const auto find = [&](std::uint32_t m) {
    while (root[m] != m) m = root[m] = root[root[m]];
    return m;
  };
  const auto law_of = [&](std::uint32_t m) { return face_law(w, m, w.acc[m]); };
  const auto push_for = [&](std::uint32_t m, const Law& L, double v, double a) { return block_push(w, m, w.acc[m], L, v, a); };
  const auto pool = [&](std::span<const std::uint32_t> chain, double v, std::vector<Pool>& pools) {
    pool_blocks(w, chain, v, false, pools);
  };
  thread_local std::vector<Pool> rest_pools;
  // Members of a block get its velocity and acceleration to the bit. static_push: at rest and
  // held, keep the pushes the pair solver found (below). A block sliding to a stop also gets
  // its path from rest (pooled again at v = 0) for its members' stop events.
  const auto set_block = [&](std::span<const std::uint32_t> blk, const Law& L, double v, double a, bool static_push) {
    const Vec2 tt = perp(w.support_n[blk[0]]);
    if (blk.size() > 1 && v != 0.0 && a != 0.0 && (a > 0.0) != (v > 0.0)) {
      if (w.train_stop_acc.size() < n) w.train_stop_acc.resize(n), w.train_stop_apath.resize(n), w.train_block.resize(n);
      pool(blk, 0.0, rest_pools);
      for (const Pool& q : rest_pools) {
        for (std::size_t x = q.b; x < q.e; ++x) {
          const std::uint32_t m = blk[x];
          w.train_stop_acc[m] = w.acc[m] + push_for(m, q.L, 0.0, q.a);
          w.train_stop_apath[m] = q.a * tt;
          w.train_block[m] = blk[0];
          w.train_stopping.push_back(m);
        }
      }
    }
    for (std::uint32_t m : blk) {
      if (!(v == 0.0 && a == 0.0 && static_push)) push[m] = push_for(m, L, v, a);
      if (blk.size() > 1) in_block[m] = 1;
      keep_raw_acc(w, m);
      w.acc[m] += push[m];
      push[m] = {};
      w.vel[m] = v * tt;
      support_path(w, m);
      w.vel[m] = v * tt;
      w.apath[m] = a * tt;
    }
  };
  const auto along = [&](std::uint32_t a, std::uint32_t b) {
    const std::uint32_t ra = find(a), rb = find(b);
    if (ra != rb) return ra < rb;
    const Vec2 t = perp(w.support_n[a]);
    return dot(w.pos[a], t) < dot(w.pos[b], t);
  };
  const auto gather = [&](auto&& keep) {   // members of kept pairs, by component, along the face
    members.clear();
    for (const TrainPair& p : pairs) {
      if (keep(p)) members.push_back(p.i), members.push_back(p.j);
    }
    std::sort(members.begin(), members.end());
    members.erase(std::unique(members.begin(), members.end()), members.end());
    std::stable_sort(members.begin(), members.end(), along);
  };

  // Straight chains (bodies on one line, touching only one another there): exact, by
  // pooling from the rear: a block behind that would accelerate faster along the face
  // than the block in front presses it and joins it (the rigid Coulomb solution of the
  // complementarity problem; a tie to round-off joins too, so the pair keeps the same bits).
  for (const TrainPair& p : pairs) {
    if (straight_pair(w, p)) root[find(p.i)] = find(p.j);
  }
  for (const TrainPair& p : pairs) {
    if (!straight_pair(w, p) || !(w.inv_mass[p.i] > 0.0) || !(w.inv_mass[p.j] > 0.0)) {
      mixed[find(p.i)] = mixed[find(p.j)] = 1;
    }
  }
  gather([&](const TrainPair& p) { return !mixed[find(p.i)]; });
  thread_local std::vector<Pool> pools;
  for (std::size_t b = 0; b < members.size();) {
    std::size_t e = b;
    while (e < members.size() && find(members[e]) == find(members[b])) ++e;
    const Vec2 tt = perp(w.support_n[members[b]]);
    const double v = dot(w.vel[members[b]], tt);
    const std::span<const std::uint32_t> chain = std::span<const std::uint32_t>(members).subspan(b, e - b);
    pool(chain, v, pools);
    for (const Pool& q : pools) set_block(chain.subspan(q.b, q.e - q.b), q.L, v, q.a, false);
    b = e;
  }

  // Everything else (bodies of other sizes, on other faces): the pair forces P_k >= 0 by
  // projected Gauss-Seidel, pairs that separate keeping P = 0; a pressed straight run in
  // it is then a rigid block as above.
  bool pressed = false;
  const auto gs_pair = [&](const TrainPair& p) { return mixed[find(p.i)] != 0; };
  const auto acc_of = [&](std::uint32_t m) {
    const Vec2 t = perp(w.support_n[m]);
    return support_acceleration(w, m, w.acc[m] + push[m], dot(w.vel[m], t));
  };
  double amax = 0.0;
  for (const TrainPair& p : pairs) {
    if (gs_pair(p)) amax = std::max({amax, length(w.acc[p.i]), length(w.acc[p.j])});
  }
  for (int iter = 0; amax > 0.0 && iter < 100000; ++iter) {
    double change = 0.0;
    for (TrainPair& p : pairs) {
      if (!gs_pair(p)) continue;
      const double wk = dot(acc_of(p.j) - acc_of(p.i), p.nrm);
      const double ti = dot(perp(w.support_n[p.i]), p.nrm), tj = dot(perp(w.support_n[p.j]), p.nrm);
      const double K = ti * ti * w.inv_mass[p.i] + tj * tj * w.inv_mass[p.j];
      if (!(K > 1e-12 * (w.inv_mass[p.i] + w.inv_mass[p.j]))) continue;
      const double P = std::max(0.0, p.P - wk / K);
      const double dP = P - p.P;
      if (dP == 0.0) continue;
      p.P = P;
      pressed = true;
      push[p.i] -= (dP * w.inv_mass[p.i]) * p.nrm;
      push[p.j] += (dP * w.inv_mass[p.j]) * p.nrm;
      change = std::max(change, std::fabs(dP) * K);
    }
    if (change <= 1e-15 * amax) break;
  }
  if (pressed) {
    // Pressed straight runs: union-find again, over the pressed straight pairs only.
    for (const TrainPair& p : pairs) {
      if (gs_pair(p)) root[p.i] = p.i, root[p.j] = p.j;
    }
    for (const TrainPair& p : pairs) {
      if (gs_pair(p) && p.P > 0.0 && straight_pair(w, p)) root[find(p.i)] = find(p.j);
    }
    gather([&](const TrainPair& p) { return gs_pair(p) && p.P > 0.0 && straight_pair(w, p); });
    for (const TrainPair& p : pairs) {   // a member pressed off the line too is not a block's
      if (gs_pair(p) && p.P > 0.0 && !straight_pair(w, p)) mixed[p.i] = mixed[p.j] = 2;
    }
    for (std::size_t b = 0; b < members.size();) {
      std::size_t e = b;
      bool off_line = false;
      while (e < members.size() && find(members[e]) == find(members[b])) off_line |= mixed[members[e++]] == 2;
      if (!off_line) {
        const Vec2 tt = perp(w.support_n[members[b]]);
        const double v = dot(w.vel[members[b]], tt);
        Law L;
        for (std::size_t x = b; x < e; ++x) {
          const Law o = law_of(members[x]);
          L = {L.M + o.M, L.F + o.F, L.H + o.H, L.K + o.K};
        }
        set_block(std::span<const std::uint32_t>(members).subspan(b, e - b), L, v, block_a(L, v), true);
      }
      b = e;
    }
    for (const TrainPair& p : pairs) {
      if (!gs_pair(p)) continue;
      for (std::uint32_t m : {p.i, p.j}) {
        if (push[m].x == 0.0 && push[m].y == 0.0) continue;
        keep_raw_acc(w, m);
        w.acc[m] += push[m];
        push[m] = {};
        support_path(w, m);
      }
    }
  }
  // Pairs on one line that move alike (sliding alike, unpressed, or pushed off the line)
  // move as one: the same velocity and acceleration to the bit (else round-off reads as an
  // approach and the touching pair is met as an impact at once), a block's taken over by a
  // body that is in none.
  for (const TrainPair& p : pairs) {
    if (w.support_n[p.i] != w.support_n[p.j] || (in_block[p.i] && in_block[p.j])) continue;
    const Vec2 dv = w.vel[p.j] - w.vel[p.i], da = w.apath[p.j] - w.apath[p.i];
    const double vs = length(w.vel[p.i]) + length(w.vel[p.j]), as = length(w.apath[p.i]) + length(w.apath[p.j]);
    if (length(dv) > 1e-12 * vs || length(da) > 1e-12 * as) continue;
    const std::uint32_t from = in_block[p.j] ? p.j : p.i, to = from == p.i ? p.j : p.i;
    w.vel[to] = w.vel[from];
    w.apath[to] = w.apath[from];
  }
}

}  // namespace

void apply_supports(World& w, const StepContext& ctx) {
  w.step_dt = ctx.dt;
  w.cap_lifts.clear();   // lift-offs from a corner's cap (convex_cap.cpp) of the last step
  release_crowded_riders(w, ctx.t0, ctx.dt);
  w.braced_holds.clear();   // holds of the last step are judged again by hold_pass
  const std::size_t n = w.size();
  for (std::uint32_t i = 0; i < n; ++i) {
    if (w.support[i] == kNone) {
      if (w.dynamic(i) && !w.riding(i) && !w.statics.segments.empty()) {
        detect_support(w, i, ctx);
        if (w.support[i] != kNone) {
          support_path(w, i);
        } else {
          settle_on_cap(w, i, 0.0, ctx.t0, ctx.dt, false);   // at a convex corner (convex_cap.cpp)
        }
      }
      continue;
    }
    if (!w.dynamic(i)) {
      release_support(w, i);
      continue;
    }
    if (w.on_body(i)) continue;   // after every segment support is settled (below)
    const Segment& s = w.statics.segments[w.support[i]];
    const Vec2 nrm = w.support_n[i];
    const double u = dot(w.pos[i] - s.from, s.dir);
    const double gap = dot(w.pos[i] - s.from, nrm) - w.radius[i];
    const double tol = 1e-9 * (w.radius[i] + w.length_scale);
    const bool on_segment = u >= 0.0 && u <= s.length;
    const bool pressed = dot(w.acc[i], nrm) < 0.0;
    if (!on_segment || !pressed || std::fabs(gap) > tol) {
      release_support(w, i);
      continue;
    }
    support_path(w, i);
    // Still touching at the end of this step: one continuing contact.
    touch_contact(w, i, static_partner_key(s.owner), ctx.t0);
  }
  // Bodies at rest on bodies: valid while the supporter is stuck, they still touch, and
  // they are still held. A stack settles from the bottom up, one level per pass.
  thread_local std::vector<char> held_now;
  held_now.assign(n, 0);
  for (bool changed = true; changed;) {
    changed = false;
    for (std::uint32_t i = 0; i < n; ++i) {
      if (!w.on_body(i) || w.is_held(i)) continue;
      const std::uint32_t j = w.support[i] & ~kBodySupport;
      const Vec2 d = w.pos[i] - w.pos[j];
      const double dist = length(d);
      const double R = w.radius[i] + w.radius[j];
      const double tol = 1e-9 * (R + w.length_scale);
      const Vec2 nrm = dist > 0.0 ? d / dist : w.support_n[i];
      w.support[i] = kNone;   // judged as a free body pressed onto j
      const bool ok = w.alive(j) && std::fabs(dist - R) <= tol && can_rest_on(w, i, j, nrm, INFINITY);
      w.support[i] = kBodySupport | j;
      if (ok) {
        w.support_n[i] = nrm;
        support_path(w, i);
        touch_contact(w, i, j, ctx.t0);
      } else {
        release_support(w, i);
        changed = true;
      }
    }
    if (hold_pass(w, ctx, held_now)) changed = true;
  }
  judge_braced_holds(w, true);
  if (!w.varying_forces) push_trains(w);
}

bool join_train(World& w, std::span<const std::uint32_t> chain_in, std::uint32_t i, std::uint32_t j, double t, double vr,
                std::vector<std::uint32_t>& moved) {
  moved.clear();
  if (w.varying_forces || w.any_rules || chain_in.size() < 2) return false;
  const Vec2 tt = perp(w.support_n[i]);
  thread_local std::vector<std::uint32_t> chain;
  thread_local std::vector<double> along, vt;
  chain.assign(chain_in.begin(), chain_in.end());
  along.resize(w.size());
  vt.resize(w.size());
  for (std::uint32_t m : chain) {
    along[m] = dot(w.pos_at(m, t), tt);
    vt[m] = dot(w.vel_at(m, t), tt);
  }
  std::sort(chain.begin(), chain.end(), [&](std::uint32_t a, std::uint32_t b) {
    return along[a] < along[b] || (along[a] == along[b] && a < b);
  });
  // The perfectly inelastic impact of the chain: pooled from the rear by momentum (a block
  // behind moving faster than the block in front meets it; a tie to round-off joins too).
  struct Moving {
    std::size_t b, e;
    double M, P, v;
  };
  thread_local std::vector<Moving> blocks;
  blocks.clear();
  for (std::size_t x = 0; x < chain.size(); ++x) {
    const std::uint32_t m = chain[x];
    const double mass = 1.0 / w.inv_mass[m];
    blocks.push_back({x, x + 1, mass, mass * vt[m], vt[m]});
    while (blocks.size() > 1) {
      const Moving& back = blocks[blocks.size() - 2];
      const Moving& front = blocks.back();
      if (!(back.v - front.v > -1e-12 * (std::fabs(back.v) + std::fabs(front.v)))) break;
      const double M = back.M + front.M, P = back.P + front.P;
      const Moving joined{back.b, front.e, M, P, P / M};
      blocks.pop_back();
      blocks.back() = joined;
    }
  }
  const auto at = [&](std::uint32_t m) {
    return static_cast<std::size_t>(std::find(chain.begin(), chain.end(), m) - chain.begin());
  };
  const std::size_t xi = at(i), xj = at(j);
  const auto hit = std::find_if(blocks.begin(), blocks.end(), [&](const Moving& q) { return q.b <= xi && xi < q.e; });
  if (hit == blocks.end() || !(hit->b <= xj && xj < hit->e)) return false;
  const std::span<const std::uint32_t> blk = std::span<const std::uint32_t>(chain).subspan(hit->b, hit->e - hit->b);
  double vmin = INFINITY, vmax = -INFINITY;
  for (std::uint32_t m : blk) vmin = std::min(vmin, vt[m]), vmax = std::max(vmax, vt[m]);
  const double spread = vmax - vmin;
  // A slow impact onto a body at rest: its supports absorb it (as resolve_static).
  const bool slow = std::fabs(vt[i] - vt[j]) < w.collapse_speed(i, j);
  for (std::uint32_t m : blk) {
    if (slow && w.stationary(m)) return false;
  }
  // No other pair of the block may bounce: none met faster than the spread.
  for (std::size_t x = 0; x + 1 < blk.size(); ++x) {
    const std::uint32_t a = blk[x], b = blk[x + 1];
    if ((a == i && b == j) || (a == j && b == i)) continue;
    const PairMaterial m = w.pair_material(w.material[a], w.material[b]);
    const double e = spread < w.collapse_speed(a, b) ? 0.0 : m.restitution;
    if (!(e * spread < vr)) return false;
  }
  const double v = hit->P / hit->M;
  thread_local std::vector<Pool> pools, rest_pools;
  pool_blocks(w, blk, v, true, pools);
  for (std::uint32_t m : blk) {
    end_substep(w, m, t);
    std::erase(w.train_stopping, m);
    moved.push_back(m);
  }
  // Each block as push_trains' set_block: its members at its velocity and acceleration to
  // the bit, the pushes added to their force accelerations, and a block sliding to a stop
  // its members' paths from rest.
  const std::size_t n = w.size();
  for (const Pool& q : pools) {
    const std::span<const std::uint32_t> mem = blk.subspan(q.b, q.e - q.b);
    const double a = q.a;
    for (std::uint32_t m : mem) {
      keep_raw_acc(w, m);
      w.acc[m] = w.train_raw_acc[m];
    }
    if (mem.size() > 1 && v != 0.0 && a != 0.0 && (a > 0.0) != (v > 0.0)) {
      if (w.train_stop_acc.size() < n) w.train_stop_acc.resize(n), w.train_stop_apath.resize(n), w.train_block.resize(n);
      pool_blocks(w, mem, 0.0, true, rest_pools);
      for (const Pool& r : rest_pools) {
        for (std::size_t x = r.b; x < r.e; ++x) {
          const std::uint32_t m = mem[x];
          w.train_stop_acc[m] = w.acc[m] + block_push(w, m, w.acc[m], r.L, 0.0, r.a);
          w.train_stop_apath[m] = r.a * tt;
          w.train_block[m] = mem[0];
          w.train_stopping.push_back(m);
        }
      }
    }
    for (std::uint32_t m : mem) {
      w.acc[m] += block_push(w, m, w.acc[m], q.L, v, a);
      w.vel[m] = v * tt;
      support_path(w, m);
      w.vel[m] = v * tt;
      w.apath[m] = a * tt;
    }
  }
  return true;
}

double support_stop_time(const World& w, std::uint32_t i, double t, double T) {
  if (w.on_body(i)) return toi::kNever;   // stuck
  const Vec2 tang = perp(w.support_n[i]);
  const double vt = dot(w.vel_at(i, t), tang);
  const double at = dot(w.apath[i], tang);
  if (vt == 0.0 || at == 0.0 || (vt > 0.0) == (at > 0.0)) return toi::kNever;
  const double s = -vt / at;
  return t + s <= T ? t + s : toi::kNever;
}

double support_leave_time(const World& w, std::uint32_t i, double t, double T) {
  if (w.on_body(i)) return toi::kNever;
  const Segment& s = w.statics.segments[w.support[i]];
  const Vec2 p = w.pos_at(i, t);
  const Vec2 v = w.vel_at(i, t);
  const Vec2 a = w.apath[i];
  // u(s) = u0 + u1 s + u2 s^2 along the segment; it leaves at u = 0 falling or at
  // u = L rising. A supported body is on its face's span: u0 outside it is round-off
  // (a body handed over at a junction is up to an ulp of the coordinates before the next
  // piece's start), read as the end itself, so that it leaves only if it heads out.
  const double u0 = std::clamp(dot(p - s.from, s.dir), 0.0, s.length), u1 = dot(v, s.dir), u2 = 0.5 * dot(a, s.dir);
  const toi::Tolerance tol = toi::linear_tolerance(w.length_scale, length(v) + length(a) * (T - t));
  toi::Poly lo;
  lo.c[0] = u0;
  lo.c[1] = u1;
  lo.c[2] = u2;
  lo.degree = 2;
  toi::Poly hi;
  hi.c[0] = s.length - u0;
  hi.c[1] = -u1;
  hi.c[2] = -u2;
  hi.degree = 2;
  // Exactly at an end point: it leaves if moving (or accelerating) outwards, else stays.
  const double a_lo = toi::earliest_entry(lo, T - t, {0.0, tol.slope});
  const double a_hi = toi::earliest_entry(hi, T - t, {0.0, tol.slope});
  const double s_leave = std::min(a_lo, a_hi);
  return s_leave == toi::kNever ? toi::kNever : t + s_leave;
}

namespace {

// A piece other than k continuing k's line beyond k's end `end` (heading `out` away from
// k) at a junction: one of its ends within the coordinates' round-off of `end`, the rest of
// it beyond, on the same line. kNone if there is none.
std::uint32_t continuing_piece(World& w, std::uint32_t i, std::uint32_t k, Vec2 end, Vec2 out) {
  const Segment& s = w.statics.segments[k];
  const double scale = std::max(std::fabs(end.x), std::fabs(end.y)) + w.radius[i] + w.length_scale;
  const double tol = 1024.0 * 2.220446049250313e-16 * scale;
  thread_local std::vector<std::uint32_t> found;
  found.clear();
  w.statics.query(make_aabb(end.x - tol, end.y - tol, end.x + tol, end.y + tol), found);
  for (std::uint32_t o : found) {
    if (o == k) continue;
    const Segment& q = w.statics.segments[o];
    if (w.any_rules && !w.response(w.group[i], q.group).collide) continue;
    if (std::fabs(dot(q.normal, s.normal)) < 1.0 - 1e-12) continue;   // not on the same line
    const bool from_here = length(q.from - end) <= tol, to_here = length(q.to - end) <= tol;
    if (from_here == to_here) continue;
    const Vec2 onward = from_here ? q.dir : -q.dir;
    if (dot(onward, out) > 0.0) return o;
  }
  return kNone;
}

}  // namespace

// A junction: body i, on face k and leaving it over one of its ends at t (advanced
// there), where another piece starts at the same point (to the coordinates' round-off).
// The rule depends on how the next piece turns:
//   - on the same line (collinear): it is the same support; the body is handed to it
//     without an event (released, it met the next face or the first's end cap at zero
//     time and micro-bounced off it with friction-free flights, or went back and forth
//     between the two pieces at t = 0 until the event cap);
//   - turning away from the body (a convex corner): it leaves the face there and flies,
//     exactly, if it is fast enough to lift off (v^2 > r |a.n|: its gap to the corner
//     grows); slower, it would roll over the corner's cap, which core does not model (it
//     micro-bounces, README: Known limits);
//   - turning towards it (a concave corner): a circle meets the next face before the
//     junction (an impact, not a leave), with Newton's law and Coulomb's impulse there.
// Only the collinear case needs a rule here; the others are released.
bool hand_over_support(World& w, std::uint32_t i, double t_abs, double dt) {
  if (!w.supported(i) || w.on_body(i) || w.is_held(i)) return false;
  const std::uint32_t k = w.support[i];
  const Segment& s = w.statics.segments[k];
  const Vec2 p = w.pos[i];
  const Vec2 n = w.support_n[i];
  const bool at_to = dot(p - s.from, s.dir) > 0.5 * s.length;
  const Vec2 end = at_to ? s.to : s.from;
  const std::uint32_t o = continuing_piece(w, i, k, end, at_to ? s.dir : -s.dir);
  if (o == kNone) return false;
  const Segment& q = w.statics.segments[o];
  w.support[i] = o;
  w.support_n[i] = dot(q.normal, n) > 0.0 ? q.normal : -q.normal;
  support_path(w, i);
  record_contact(w, i, kNone, &q, t_abs, dt);
  return true;
}

// Whether a face or cap of segment k, met by body i, is no impact: i is on a face and k
// lies on that face's line (another piece of a slope or floor drawn in pieces), and either
// its face (which touches the body only where the support does, along the same normal)
// or an end cap of it or of the support at a junction, where another piece continues the
// line (a point inside one straight face). (Supported on the lower piece of a slope, a
// ball started on the junction met the upper piece's face at its very end at t = 0, was
// released with 1e-20 m/s, settled on the lower one again, for ever: the event cap; or
// bounced off the upper one's end cap and slid with friction-free flights, 7.6e-4 m off
// the closed form, ok; on the upper piece, it met its own end cap at t = 0, again and
// again.) Caps at a free end (a table's edge) stay impacts.
bool on_support_line(World& w, std::uint32_t i, std::uint32_t k, bool cap, Vec2 at) {
  if (!w.supported(i) || w.on_body(i) || w.is_held(i)) return false;
  const std::uint32_t f = w.support[i];
  const Segment& s = w.statics.segments[f];
  const Segment& q = w.statics.segments[k];
  if (k != f) {
    if (std::fabs(dot(q.normal, s.normal)) < 1.0 - 1e-12) return false;
    const double scale = std::max({std::fabs(s.from.x), std::fabs(s.from.y), std::fabs(s.to.x), std::fabs(s.to.y),
                                   std::fabs(q.from.x), std::fabs(q.from.y), std::fabs(q.to.x), std::fabs(q.to.y)}) +
                         w.length_scale;
    const double tol = 1024.0 * 2.220446049250313e-16 * scale;
    if (!(std::fabs(dot(q.from - s.from, s.normal)) <= tol && std::fabs(dot(q.to - s.from, s.normal)) <= tol)) return false;
    if (!cap) return true;
  }
  // The cap nearest the body's contact point (its centre at `at` at the hit), and whether the line continues past it.
  const Vec2 c = at - w.radius[i] * w.support_n[i];
  const bool at_to = length_squared(c - q.to) < length_squared(c - q.from);
  return continuing_piece(w, i, k, at_to ? q.to : q.from, at_to ? q.dir : -q.dir) != kNone;
}

// A concave corner: body i, on face f, meets face k (along its normal n, too slowly to
// bounce clear: pressed, e |vn| below the rest speed) where k turns towards it. Newton's
// law at k (e = 0 there, as any settling) with Coulomb's impulse; if the body then moves
// and is pulled along k away from f (or stays at rest on k), it leaves f and rests on k:
// true. Otherwise (it would press into f too: a V) nothing changes: false. (Released from
// f and bounced off k at half the rest speed, a ball started at rest in the pocket of two
// pieces of a slope, or sliding into it, flew free of friction for 4e-5 s and ended up to
// 2.5e-5 m off the closed form, ok.)
void settle_on_face(World& w, std::uint32_t i, std::uint32_t k, Vec2 n, const PairMaterial& m) {
  PairMaterial inelastic = m;
  inelastic.restitution = 0.0;
  resolve_static(w, i, n, inelastic, 0.0);
  w.support[i] = k;
  w.support_n[i] = n;
  support_path(w, i);
}

bool settle_on_next_face(World& w, std::uint32_t i, std::uint32_t k, Vec2 n, const PairMaterial& m) {
  if (!w.supported(i) || w.on_body(i) || w.is_held(i) || w.support[i] == k) return false;
  const std::uint32_t f = w.support[i];
  const Vec2 nf = w.support_n[i];
  if (dot(nf, n) >= 1.0 - 1e-12) return false;   // the same line: a junction, not a corner
  const Vec2 v_before = w.vel[i];
  settle_on_face(w, i, k, n, m);
  const double tol = 64.0 * 2.220446049250313e-16;
  const bool leaves = dot(w.vel[i], nf) >= -tol * length(w.vel[i]) && dot(w.apath[i], nf) >= -tol * length(w.acc[i]);
  if (leaves) return true;
  w.vel[i] = v_before;
  w.support[i] = f;
  w.support_n[i] = nf;
  support_path(w, i);
  return false;
}

}  // namespace physval::core_detail
