// Exact (event-driven) collisions: within a step, advance to the earliest impact,
// resolve it, and continue for the rest of the step from there, so nothing tunnels at
// any speed and a contact's time is the root of its gap polynomial, not the step's end.
//
// Every body keeps its own clock (tloc) and is advanced lazily, only when an event
// involves it. Candidate events sit in a queue ordered by (time, kind, bodies), so
// the order is total and runs are bit-identical (event_queue.cpp). An event is stale once a body it
// names has changed its path since (each body carries a version). After an impact the
// bodies involved register a box over their new path with the broad phase and are
// tested against whatever it overlaps.
//
// Termination: an impact leaves its pair separating; pressing contacts settle into
// resting contact on a face or micro-bounce with a flight of at least 1/8 step; a
// step processes at most max_events_per_step events, and at the cap the rest of the
// step is finished with the lecture pass (reported in limits_hit).
#include <algorithm>
#include <cmath>

#include "physval/core/time_of_impact.hpp"
#include "world.hpp"

namespace physval::core_detail {

Aabb path_box(const World& w, std::uint32_t i, double t, double T) {
  if (w.riding(i)) return cap_box(w, i);   // on a convex corner's cap (convex_cap.cpp)
  const double r = w.radius[i];
  const Vec2 p = w.pos_at(i, t);
  if (w.is_static(i)) return make_aabb(p.x - r, p.y - r, p.x + r, p.y + r);
  const Vec2 v = w.vel_at(i, t);
  const Vec2 a = w.path_acc(i);
  const double s = T - t;
  const Vec2 e = p + s * v + (0.5 * s * s) * a;
  double lo_x = std::min(p.x, e.x), hi_x = std::max(p.x, e.x);
  double lo_y = std::min(p.y, e.y), hi_y = std::max(p.y, e.y);
  // A parabola can turn back within the step: include its extremum on each axis.
  if (a.x != 0.0) {
    const double sx = -v.x / a.x;
    if (sx > 0.0 && sx < s) {
      const double x = p.x + sx * v.x + 0.5 * sx * sx * a.x;
      lo_x = std::min(lo_x, x);
      hi_x = std::max(hi_x, x);
    }
  }
  if (a.y != 0.0) {
    const double sy = -v.y / a.y;
    if (sy > 0.0 && sy < s) {
      const double y = p.y + sy * v.y + 0.5 * sy * sy * a.y;
      lo_y = std::min(lo_y, y);
      hi_y = std::max(hi_y, y);
    }
  }
  return make_aabb(lo_x - r, lo_y - r, hi_x + r, hi_y + r);
}

namespace {

double inf_norm(Vec2 v) { return std::max(std::fabs(v.x), std::fabs(v.y)); }

class EventLoop {
 public:
  EventLoop(World& w, StepContext& ctx)
      : w_(w),
        ctx_(ctx),
        T_(ctx.dt),
        coupled_(w.coupled()),
        fast_isolated_(w.impact_law == ImpactLaw::Simultaneous && !w.any_rules && !w.any_forces && !w.varying_forces &&
                       !w.coupled()),
        zeno_tails_(w.zeno_tails()),
        storms_(granular_allowed(w)) {
    // A few faces: their boxes, as StaticGeometry builds them, to skip its query for
    // a box that meets none (most bodies of a walled gas, away from the walls).
    if (w.statics.segments.size() <= kFewFaces) {
      for (const Segment& s : w.statics.segments) {
        face_boxes_[face_count_++] = make_aabb(std::min(s.from.x, s.to.x), std::min(s.from.y, s.to.y),
                                               std::max(s.from.x, s.to.x), std::max(s.from.y, s.to.y));
      }
    } else {
      face_count_ = kManyFaces;
    }
  }

  void run() {
    prune_passing(w_);
    w_.events.start(T_);
    schedule_all(0.0);
    w_.stats.candidate_pairs = static_cast<std::int64_t>(w_.pairs.size());
    if (!w_.emitters.empty()) {
      w_.scratch_events.clear();
      schedule_explosions(w_, ctx_, w_.scratch_events);
      schedule_trail_emissions(w_, ctx_, w_.scratch_events);
      for (const Event& e : w_.scratch_events) push(e);
    }

    w_.events.seal();
    while (!w_.events.empty()) {
      const Event e = w_.events.pop();
      if (const Event* next = w_.events.next()) prefetch(*next);
      w_.bp->prefetch(e.a, 1);   // its index entry was asked for one event ago
      if (e.kind() == EventKind::Pair) w_.bp->prefetch(e.b, 1);
      if (!valid(e)) continue;
      if (ctx_.events >= ctx_.event_cap) {
        finish_with_lecture_pass(e.time);
        return;
      }
      ++ctx_.events;
      if (coupled_) {
        process_coupled(e);
      } else {
        process(e);
      }
      if (w_.storm_bail) storm_now(e.time);
    }
  }

 private:
  void push(const Event& e) { w_.events.push(e); }

  // Every body's path registered with the broad phase from t, and its events found.
  void schedule_all(double t) {
    const std::size_t n = w_.size();
    std::span<Aabb> boxes = w_.bp->prepare(n);
    w_.active.resize(n);
    for (std::uint32_t i = 0; i < n; ++i) {
      w_.active[i] = w_.alive(i) ? 1 : 0;
      if (w_.active[i]) boxes[i] = path_box(w_, i, t, T_);
    }
    w_.bp->build(w_.active);
    w_.pairs.clear();
    w_.bp->pairs(w_.pairs);
    for (const BodyPair& p : w_.pairs) schedule_pair(p.a, p.b, t);
    for (std::uint32_t i = 0; i < n; ++i) {
      if (!w_.dynamic(i)) continue;
      schedule_statics(i, t, boxes[i]);   // (its registered box: none has grown yet)
      schedule_body(i, t);
    }
  }

  // Newtonian gravity (w.coupled()): an event that changes a path cuts the step of the
  // whole system (substeps.cpp). Its time is refined on the system's integrator step,
  // every free body is put at its state there, the event is processed as usual, and
  // the system's next sub-step starts there: new paths, every body's events found
  // again (the old ones go stale with a new version).
  void process_coupled(Event e) {
    bool cuts = e.kind() != EventKind::Emit;
    if (e.kind() == EventKind::Pair) {
      if (w_.response(w_.group[e.a], w_.group[e.b]).collide) {
        e.time = refine_coupled_pair(w_, e.a, e.b, e.time, std::max(w_.tloc[e.a], w_.tloc[e.b]), T_);
      } else {
        cuts = false;   // passes through: no path changes
      }
    } else if (e.kind() == EventKind::Static) {
      const Segment& seg = w_.statics.segments[e.b];
      if (w_.response(w_.group[e.a], seg.group).collide) {
        e.time = refine_coupled_static(w_, e.a, seg, e.feature() != 0, e.time, w_.tloc[e.a], T_);
      } else {
        cuts = false;
      }
    }
    if (!cuts) {
      process(e);
      return;
    }
    coupled_cut(w_, e.time);
    process(e);
    coupled_restart(w_, e.time, T_);
    for (std::uint32_t i = 0; i < w_.size(); ++i) ++w_.version[i];
    schedule_all(e.time);
  }

  // Asks for the memory the next event will read while this one is processed.
  void prefetch(const Event& e) const {
    prefetch_body(e.a);
    if (e.kind() == EventKind::Pair) prefetch_body(e.b);
  }
  void prefetch_body(std::uint32_t i) const {
    __builtin_prefetch(&w_.flags[i]);
    __builtin_prefetch(&w_.version[i]);
    __builtin_prefetch(&w_.pos[i]);
    __builtin_prefetch(&w_.vel[i]);
    __builtin_prefetch(&w_.tloc[i]);
    __builtin_prefetch(&w_.radius[i]);
    __builtin_prefetch(&w_.inv_mass[i]);
    __builtin_prefetch(&w_.group[i]);
    __builtin_prefetch(&w_.material[i]);
    w_.bp->prefetch(i, 0);
  }

  bool valid(const Event& e) const {
    if (!w_.alive(e.a)) return false;
    switch (e.kind()) {
      case EventKind::Pair:
        return w_.alive(e.b) && w_.version[e.a] == e.va && (w_.version[e.b] & Event::kVersionMask) == e.vb();
      case EventKind::Static:
      case EventKind::Stop:
      case EventKind::Leave: return w_.version[e.a] == e.va;
      case EventKind::Explode:
      case EventKind::Expire:
      case EventKind::Emit: return true;
    }
    return false;
  }

  bool related(std::uint32_t i, std::uint32_t j) const {
    // A particle never collides with the body that emitted it.
    const std::size_t s = w_.scene_bodies;
    if ((w_.flags[i] & kParticle) && w_.parent[i - s] == j) return true;
    if ((w_.flags[j] & kParticle) && w_.parent[j - s] == i) return true;
    return false;
  }

  void schedule_pair(std::uint32_t i, std::uint32_t j, double t) {
    if (i == j) return;
    if (!tails_.empty()) {   // a body met inside its Zeno tail: back to its state at t (zeno_tail)
      unwind_tail(i, t);
      unwind_tail(j, t);
    }
    const std::uint8_t fi = w_.flags[i], fj = w_.flags[j];
    if (!(fi & kAlive) || !(fj & kAlive)) return;
    if ((fi & kStatic) && (fj & kStatic)) return;
    if ((fi & kPoint) && (fj & kPoint)) return;
    if (((fi | fj) & kParticle) && related(i, j)) return;
    if (i > j) std::swap(i, j);
    if (w_.any_rules) {
      const PairResponse& r = w_.response(w_.group[i], w_.group[j]);
      if (!r.collide && !r.event) return;
      if (!r.collide && is_passing(w_, pair_key(i, j))) return;
    }
    // A body riding a corner's cap has no parabola to meet (convex_cap.cpp): said, not met.
    if (!w_.caps.empty() && (w_.riding(i) || w_.riding(j))) {
      note_cap_disturbed(w_, w_.riding(i) ? i : j, ctx_.t0 + t);
      return;
    }
    const Vec2 pi = w_.pos_at(i, t), pj = w_.pos_at(j, t);
    const Vec2 vi = w_.vel_at(i, t), vj = w_.vel_at(j, t);
    const Vec2 dv = vj - vi;
    const Vec2 da = w_.path_acc(j) - w_.path_acc(i);
    const double R = w_.radius[i] + w_.radius[j];
    // Apart (or just touching), not approaching and not accelerating together: with
    // d = pj - pi, |d + dv s + da s^2 / 2|^2 >= |d|^2 >= R^2 for every s >= 0, so no
    // impact this step. (A touching pair sliding side by side, d.dv = d.da = 0, was
    // otherwise read as an impact at once, again and again, by the gap's tolerance.)
    const Vec2 d0 = pj - pi;
    if (dot(d0, dv) >= 0.0 && dot(d0, da) >= 0.0 && length_squared(d0) >= R * R) return;
    const double scale = inf_norm(pi) + inf_norm(pj) + R;
    if (da.x == 0.0 && da.y == 0.0) {
      // toi::circle_circle's own rejections (separating, or never close enough), before
      // the speed its tolerance needs costs two square roots: its touch tolerance is
      // toi::squared_tolerance's, computed the same way.
      const double b = dot(d0, dv);
      const double c = dot(d0, d0) - R * R;
      const double touch = 2.0 * R * 64.0 * 2.220446049250313e-16 * scale + 64.0 * 2.220446049250313e-16 * R * R;
      if (b >= 0.0 && c > touch) return;
      if (c > touch && b * b < dot(dv, dv) * c) return;
    }
    // Round-off in dv is that of the bodies' own velocities, not of their difference: two
    // touching bodies moving together (an inelastic pair) approach at ~1e-17 m/s, an
    // impulse that small changes no velocity, and the same impact would fire forever.
    const double speed = length(vi) + length(vj) + (length(w_.path_acc(i)) + length(w_.path_acc(j))) * (T_ - t);
    const double s = toi::circle_circle(pj - pi, dv, da, R, T_ - t, toi::squared_tolerance(scale, speed, R));
    if (s == toi::kNever) return;
    push(Event::make(t + s, i, j, w_.version[i], w_.version[j], EventKind::Pair));
  }

  // Whether a face's box may overlap `box` (false: StaticGeometry::query finds none).
  [[gnu::always_inline]] bool may_meet_faces(const Aabb& box) const {
    if (face_count_ == kManyFaces) return true;
    bool any = false;
    for (std::uint32_t k = 0; k < face_count_; ++k) any |= overlaps(box, face_boxes_[k]);
    return any;
  }

  // (The test inline, the rest a call: most bodies of a walled gas meet no face.)
  [[gnu::always_inline]] void schedule_statics(std::uint32_t i, double t, const Aabb& box) {
    if (w_.riding(i)) return;   // its cap is its constraint (convex_cap.cpp)
    if (may_meet_faces(box)) schedule_faces(i, t, box);
  }
  [[gnu::noinline]] void schedule_faces(std::uint32_t i, double t, const Aabb& box) {
    w_.found_static.clear();
    w_.statics.query(box, w_.found_static);
    if (w_.found_static.empty()) return;
    const Vec2 p = w_.pos_at(i, t), v = w_.vel_at(i, t), a = w_.path_acc(i);
    // A body on a face moves along it (support_path removed its normal velocity and
    // acceleration): that face is a constraint, not an impact to find. Testing it
    // anyway met round-off (a normal velocity or acceleration of ~1e-16 read as
    // "pressed together") and reported an impact at once, again and again.
    const std::uint32_t own_face = w_.supported(i) && !w_.on_body(i) ? w_.support[i] : kNone;
    for (std::uint32_t k : w_.found_static) {
      const Segment& seg = w_.statics.segments[k];
      if (w_.any_rules) {
        const PairResponse& r = w_.response(w_.group[i], seg.group);
        if (!r.collide && !r.event) continue;
        if (!r.collide && is_passing(w_, static_key(i, k))) continue;
      }
      const toi::SegmentHit hit =
          toi::circle_segment(p, v, a, w_.radius[i], seg.from, seg.to, T_ - t, w_.length_scale, w_.force_acc(i));
      if (hit.s == toi::kNever || (k == own_face && !hit.cap)) continue;
      // The corner a body has just lifted off from its cap (convex_cap.cpp).
      // An end point of its own face is no impact either: it touches it only at the end,
      // tangentially, where its leave event rides the corner's cap or lifts off.
      if (hit.cap && (own_face != kNone || !w_.cap_lifts.empty())) {
        const Vec2 at = p + hit.s * v + (0.5 * hit.s * hit.s) * a;
        if (corner_of_support(w_, i, at - w_.radius[i] * hit.normal, t + hit.s)) continue;
      }
      // Another piece on the support's line, or a cap at a junction on it, is the same
      // constraint (resting_contact.cpp).
      if (own_face != kNone && on_support_line(w_, i, k, hit.cap, p + hit.s * v + (0.5 * hit.s * hit.s) * a)) continue;
      // A face's event carries the side it is met from (in b's unused version bits).
      const std::uint32_t from_back = !hit.cap && dot(hit.normal, seg.normal) < 0.0 ? 1u : 0u;
      push(Event::make(t + hit.s, i, k, w_.version[i], from_back, EventKind::Static, hit.cap ? 1 : 0));
    }
  }

  void schedule_body(std::uint32_t i, double t) {
    if (w_.riding(i)) {   // riding a convex corner's cap: its ride goes on at t (convex_cap.cpp)
      push(Event::make(t, i, 0, w_.version[i], 0, EventKind::Leave));
      return;
    }
    if (w_.supported(i)) {
      const double stop = support_stop_time(w_, i, t, T_);
      if (stop != toi::kNever) push(Event::make(stop, i, 0, w_.version[i], 0, EventKind::Stop));
      const double leave = support_leave_time(w_, i, t, T_);
      if (leave != toi::kNever) push(Event::make(leave, i, 0, w_.version[i], 0, EventKind::Leave));
    }
    if (w_.flags[i] & kParticle) {
      const std::size_t k = i - w_.scene_bodies;
      const double death = w_.birth[k] + w_.lifetime[k] - ctx_.t0;
      if (death <= T_) push(Event::make(std::max(death, t), i, 0, w_.version[i], 0, EventKind::Expire));
    }
  }

  // Body i's path changed at time t: register its new path and find its next events.
  // found: w_.found holds already every other body whose registered box overlaps the new
  // path's (isolated_static asked for a box containing it; the others are filtered out).
  void reschedule(std::uint32_t i, double t, bool found = false) {
    if (!w_.alive(i)) return;
    start_substep(w_, i, t, T_);
    // Others find i through its registered box (grown to cover the new path); i's own
    // new events can only be with bodies whose registered boxes meet its new path.
    const Aabb box = found ? found_box_i_ : path_box(w_, i, t, T_);
    w_.bp->grow(i, box);
    if (found) {
      for (std::uint32_t j : w_.found) {
        if (overlaps(box, w_.bp->box(j))) schedule_pair(i, j, t);
      }
    } else {
      w_.found.clear();
      w_.bp->query_box(box, i, w_.found);
      for (std::uint32_t j : w_.found) prefetch_body(j);
      for (std::uint32_t j : w_.found) schedule_pair(i, j, t);
    }
    if (w_.dynamic(i)) schedule_statics(i, t, box);
    schedule_body(i, t);
  }

  // Both bodies of an impact changed their paths: one broad-phase query for the two.
  // found: w_.found holds already every body whose registered box overlaps the new paths'
  // (isolated_pair asked for a box containing them; the others are filtered out below).
  void reschedule_pair(std::uint32_t i, std::uint32_t j, double t, bool found = false) {
    const bool ai = w_.alive(i), aj = w_.alive(j);
    if (!ai || !aj) {
      if (ai) reschedule(i, t);
      if (aj) reschedule(j, t);
      return;
    }
    start_substep(w_, i, t, T_);
    start_substep(w_, j, t, T_);
    // (found: isolated_pair has the boxes already; no sub-steps there, nothing changed since)
    const Aabb box_i = found ? found_box_i_ : path_box(w_, i, t, T_);
    const Aabb box_j = found ? found_box_j_ : path_box(w_, j, t, T_);
    w_.bp->grow(i, box_i);
    w_.bp->grow(j, box_j);
    if (!found) {
      w_.found.clear();
      w_.bp->query_box(merge(box_i, box_j), kNone, w_.found);
      for (std::uint32_t k : w_.found) prefetch_body(k);   // all misses at once, not one by one
    }
    for (std::uint32_t k : w_.found) {
      const Aabb& reg_k = w_.bp->box(k);
      if (k != i && overlaps(box_i, reg_k)) schedule_pair(i, k, t);   // includes (i, j)
      if (k != i && k != j && overlaps(box_j, reg_k)) schedule_pair(j, k, t);
    }
    if (w_.dynamic(i)) schedule_statics(i, t, box_i);
    if (w_.dynamic(j)) schedule_statics(j, t, box_j);
    schedule_body(i, t);
    schedule_body(j, t);
  }

  // Whether the simultaneous law can be skipped for the impact of i and j at t (both
  // advanced to t, their pairwise response applied): no other body and no face within
  // contact distance of either at t. A superset of the touching set's test: its
  // candidates are the registered boxes meeting its touch boxes (ours are wider) and
  // its contacts have gaps within 1024 ulps of the coordinates (ours: 1e-9 of them,
  // closing or not), so when nothing is near here, its set holds the pair's own
  // contact only and it defers to the pairwise law. Leaves in w_.found the bodies whose
  // registered boxes meet the pair's new paths' boxes (and more), for reschedule_pair.
  bool isolated_pair(std::uint32_t i, std::uint32_t j, double t) {
    const Aabb box_i = found_box_i_ = path_box(w_, i, t, T_);
    const Aabb box_j = found_box_j_ = path_box(w_, j, t, T_);
    const Vec2 pi = w_.pos_at(i, t), pj = w_.pos_at(j, t);
    const Aabb q = merge(merge(box_i, box_j), merge(near_box(pi, w_.radius[i]), near_box(pj, w_.radius[j])));
    w_.found.clear();
    w_.bp->query_box(q, kNone, w_.found);
    // The pair itself, whose grown boxes the query after the growth always meets.
    bool has_i = false, has_j = false;
    for (std::uint32_t k : w_.found) {
      prefetch_body(k);
      has_i = has_i || k == i;
      has_j = has_j || k == j;
    }
    if (!has_i) w_.found.push_back(i);
    if (!has_j) w_.found.push_back(j);
    for (std::uint32_t k : w_.found) {
      if (k == i || k == j) continue;
      const Vec2 pk = w_.pos_at(k, t);
      if (near_body(pi, w_.radius[i], pk, w_.radius[k]) || near_body(pj, w_.radius[j], pk, w_.radius[k])) return false;
    }
    return !near_face(pi, w_.radius[i], kNone) && !near_face(pj, w_.radius[j], kNone);
  }
  // isolated_pair for body i meeting face k at t (advanced to t, its response applied).
  // Leaves in w_.found the other bodies whose registered boxes meet its new path's box
  // (and more), for reschedule.
  bool isolated_static(std::uint32_t i, std::uint32_t k, double t) {
    const Vec2 p = w_.pos_at(i, t);
    const double r = w_.radius[i];
    w_.found.clear();
    found_box_i_ = path_box(w_, i, t, T_);
    w_.bp->query_box(merge(found_box_i_, near_box(p, r)), i, w_.found);
    for (std::uint32_t x : w_.found) prefetch_body(x);
    for (std::uint32_t x : w_.found) {
      if (near_body(p, r, w_.pos_at(x, t), w_.radius[x])) return false;
    }
    return !near_face(p, r, k);
  }
  // The touching set's box around a body at p (touch_box in simultaneous_impacts.cpp:
  // r + 1024 ulps of |p| + 2r + 1), widened to r + 1e-9 (|p| + 2r + 1).
  static Aabb near_box(Vec2 p, double r) {
    const double pad = r + 1e-9 * (inf_norm(p) + 2.0 * r + 1.0);
    return make_aabb(p.x - pad, p.y - pad, p.x + pad, p.y + pad);
  }
  // Circles at p (radius r) and q (radius s) closer than contact distance plus 1e-9 of
  // the coordinates (the touching set's test allows 1024 ulps of them).
  static bool near_body(Vec2 p, double r, Vec2 q, double s) {
    const double R = r + s;
    const double reach = R + 1e-9 * (inf_norm(p) + inf_norm(q) + R);
    return !(length_squared(q - p) > reach * reach);
  }
  // A face other than `except` within contact distance of the circle at p, with the same
  // slack (the touching set's faces: its pad is r (1 + 1e-9) + 1024 ulps).
  bool near_face(Vec2 p, double r, std::uint32_t except) {
    if (w_.statics.segments.empty()) return false;
    const double pad = r * (1.0 + 1e-6) + 1e-9 * (inf_norm(p) + w_.length_scale);
    const Aabb box = make_aabb(p.x - pad, p.y - pad, p.x + pad, p.y + pad);
    if (!may_meet_faces(box)) return false;
    w_.found_static.clear();
    w_.statics.query(box, w_.found_static);
    for (std::uint32_t k : w_.found_static) {
      if (k == except) continue;
      const Segment& s = w_.statics.segments[k];
      const double slack = 1e-9 * (inf_norm(p) + r + inf_norm(s.from) + inf_norm(s.to));
      const double u = dot(p - s.from, s.dir);
      if (u < -slack || u > s.length + slack) continue;
      if (!(std::fabs(dot(p - s.from, s.normal)) - r > slack)) return true;
    }
    return false;
  }

  // A velocity change by another body: a supported body lifted off (or driven into)
  // its support is released; otherwise its friction is re-evaluated.
  void after_velocity_change(std::uint32_t i) {
    if (!w_.supported(i)) return;
    if (w_.on_body(i)) {   // held still on a body: any velocity frees it
      if (w_.vel[i].x != 0.0 || w_.vel[i].y != 0.0) release_support(w_, i);
      return;
    }
    const double vn = dot(w_.vel[i], w_.support_n[i]);
    const double tol = 1e-12 * (length(w_.vel[i]) + 1e-300);
    if (std::fabs(vn) > tol) {
      release_support(w_, i);
    } else {
      support_path(w_, i);
    }
  }

  // Body x's path changed at time t: whatever rested on it (and on those) is free.
  // A body held on x is judged again without it: still held by its other contacts,
  // or free (and then whatever rested on it in turn).
  void free_dependents(std::uint32_t x, double t) {
    if (w_.dep_head.empty() || (w_.alive(x) && w_.stationary(x))) return;   // x did not move
    if (w_.dep_head[x] != kNone) {
      w_.released.clear();
      collect_dependents(w_, x);
      for (std::uint32_t d : w_.released) {
        w_.advance(d, t);
        release_support(w_, d);
        ++w_.version[d];
      }
      // (copied: reschedule may free more bodies, reusing w_.released)
      std::vector<std::uint32_t> freed(w_.released);
      for (std::uint32_t d : freed) reschedule(d, t);
      for (std::uint32_t d : freed) free_held_on(d, t);
    }
    free_held_on(x, t);
  }

  void free_held_on(std::uint32_t x, double t) {
    if (w_.held.empty() || (w_.alive(x) && w_.stationary(x))) return;
    std::vector<std::uint32_t> on;
    held_on(w_, x, on);
    for (std::uint32_t k : on) {
      if (!w_.is_held(k)) continue;
      w_.advance(k, t);
      unhold(w_, k);
      w_.apath[k] = {};
      if (hold(k)) continue;   // its other contacts hold it
      w_.apath[k] = w_.acc[k];
      ++w_.version[k];
      reschedule(k, t);
      free_dependents(k, t);
    }
  }

  // Body i (advanced to now) held at rest by the stationary bodies and faces it touches.
  bool hold(std::uint32_t i) {
    const double r = w_.radius[i];
    const double pad = r + w_.rest_speed(length(w_.acc[i]), ctx_.dt) * ctx_.dt + 1e-9 * (r + w_.length_scale);
    const Vec2 p = w_.pos[i];
    near_.clear();
    w_.bp->query_box(make_aabb(p.x - pad, p.y - pad, p.x + pad, p.y + pad), i, near_);
    if (try_hold(w_, i, ctx_.dt, near_, true)) return true;
    const double t = w_.tloc[i];
    const NearFn near = [this](Vec2 q, double h, std::vector<std::uint32_t>& out) {
      out.clear();
      w_.bp->query_box(make_aabb(q.x - h, q.y - h, q.x + h, q.y + h), kNone, out);
    };
    if (!try_hold_group(w_, i, t, ctx_.dt, near, group_) && !try_hold_group_pocket(w_, i, t, ctx_.dt, near, group_)) {
      return false;
    }
    // The other members' paths changed too (now at rest): new versions, no events.
    for (std::uint32_t m : group_) {
      if (m == i) continue;
      ++w_.version[m];
      reschedule(m, t);
    }
    return true;
  }
  // i, slow and free, pressed onto a slow free body: the pocket of the group they form
  // with the slow bodies near them (try_hold_group_pocket), others rescheduled.
  bool hold_pocket(std::uint32_t i) {
    if (w_.stationary(i) || w_.supported(i)) return false;
    const double t = w_.tloc[i];
    const NearFn near = [this](Vec2 q, double h, std::vector<std::uint32_t>& out) {
      out.clear();
      w_.bp->query_box(make_aabb(q.x - h, q.y - h, q.x + h, q.y + h), kNone, out);
    };
    if (!try_hold_group_pocket(w_, i, t, ctx_.dt, near, group_)) return false;
    for (std::uint32_t m : group_) {
      if (m == i) continue;
      ++w_.version[m];
      reschedule(m, t);
    }
    return true;
  }
  bool force_hold(std::uint32_t i) {
    const double r = w_.radius[i];
    const double pad = r + 1e-9 * (r + w_.length_scale);
    const Vec2 p = w_.pos[i];
    near_.clear();
    w_.bp->query_box(make_aabb(p.x - pad, p.y - pad, p.x + pad, p.y + pad), i, near_);
    return hold_wedged(w_, i, ctx_.dt, near_);
  }
  // i, pressed slowly onto the stationary j, held at rest by j and its other contacts.
  bool hold_against(std::uint32_t i, std::uint32_t j) {
    if (w_.stationary(i) || !w_.stationary(j)) return false;
    return hold(i);
  }

  // i and j, on faces of one normal and touching along it, met slowly and pressed together
  // at t: with every body touching them along the face (transitively), if none of those
  // touches anything else, joined as one train (join_train); the others' new paths
  // scheduled here (i's and j's by the caller).
  bool join_chain(std::uint32_t i, std::uint32_t j, Vec2 n, double t, double vr) {
    if (w_.varying_forces || w_.any_rules) return false;
    const Vec2 nn = w_.support_n[i];
    const auto on_line = [&](std::uint32_t x) {
      return w_.alive(x) && w_.dynamic(x) && (w_.flags[x] & (kParticle | kPoint)) == 0 && w_.supported(x) &&
             !w_.on_body(x) && !w_.is_held(x) && w_.support_n[x] == nn;
    };
    if (!on_line(i) || !on_line(j) || std::fabs(dot(n, nn)) > 1e-9) return false;
    chain_.clear();
    chain_.push_back(i);
    chain_.push_back(j);
    for (std::size_t q = 0; q < chain_.size(); ++q) {
      const std::uint32_t m = chain_[q];
      const Vec2 p = w_.pos_at(m, t);
      const double r = w_.radius[m];
      const double pad = r + 1e-9 * (r + w_.length_scale);
      // Every face it touches but its own ends the chain's case (a wall, a step).
      w_.found_static.clear();
      w_.statics.query(make_aabb(p.x - pad, p.y - pad, p.x + pad, p.y + pad), w_.found_static);
      for (std::uint32_t k : w_.found_static) {
        if (k == w_.support[m]) continue;
        const Segment& s = w_.statics.segments[k];
        const double u = std::clamp(dot(p - s.from, s.dir), 0.0, s.length);
        if (length(p - (s.from + u * s.dir)) <= pad) return false;
      }
      near_.clear();
      // (a body touching it meets its box, and so does that body's registered box)
      w_.bp->query_box(make_aabb(p.x - pad, p.y - pad, p.x + pad, p.y + pad), m, near_);
      for (std::uint32_t k : near_) {
        if (std::find(chain_.begin(), chain_.end(), k) != chain_.end()) continue;
        const Vec2 d = w_.pos_at(k, t) - p;
        const double dist = length(d);
        const double R = r + w_.radius[k];
        const double tol = 1e-9 * (R + w_.length_scale);
        if (dist - R > tol) continue;   // apart
        // Touching: on the line, along the face, not overlapping; else not a train's case.
        if (!on_line(k) || !(dist > 0.0) || R - dist > tol || std::fabs(dot(d / dist, nn)) > 1e-9) return false;
        if (chain_.size() >= kMaxChain) return false;
        chain_.push_back(k);
      }
    }
    if (!join_train(w_, chain_, i, j, t, vr, moved_)) return false;
    for (std::uint32_t m : moved_) {
      if (m == i || m == j) continue;
      ++w_.version[m];
      reschedule(m, t);
    }
    return true;
  }

  void destroy_after(std::uint32_t i, bool by_rule) {
    if (by_rule || (w_.flags[i] & kDestroyOnHit)) kill_body(w_, i);
  }

  void process(const Event& e) {
    const double t_abs = ctx_.t0 + e.time;
    switch (e.kind()) {
      case EventKind::Pair: process_pair(e.a, e.b, e.time, t_abs); break;
      case EventKind::Static: process_static(e.a, e.b, e.feature(), e.time, t_abs, e.vb() != 0u); break;
      case EventKind::Stop: {
        // On the integrator's own path, which ends a sub-step (substeps.cpp).
        const double t = refine_stop(w_, e.a, e.time, w_.tloc[e.a], T_);
        // A block of a train stops as one (its members' stops are the same instant; one
        // by one, a member still moving would be met by the stopped one as an impact).
        thread_local std::vector<std::uint32_t> mates;
        stopping_mates(w_, e.a, mates);
        end_substep(w_, e.a, t);
        stop_on_support(w_, e.a);
        ++w_.version[e.a];
        reschedule(e.a, t);
        for (std::uint32_t m : mates) {
          end_substep(w_, m, t);
          stop_on_support(w_, m);
          ++w_.version[m];
          reschedule(m, t);
        }
        break;
      }
      case EventKind::Leave: {
        const bool rode = w_.riding(e.a);
        double t = rode ? e.time : refine_leave(w_, e.a, e.time, w_.tloc[e.a], T_);
        if (!rode) end_substep(w_, e.a, t);
        // At a junction with a collinear piece the support carries on on that piece; at a
        // convex corner too slow to lift off, the body rides the corner's cap
        // (convex_cap.cpp) until it leaves it (t: then) or the step ends.
        if (rode || !hand_over_support(w_, e.a, ctx_.t0 + t, ctx_.dt)) {
          const double te = ride_cap(w_, e.a, t, T_, ctx_.t0, ctx_.dt);
          if (te < 0.0) {
            release_support(w_, e.a);
          } else {
            t = te;
          }
        }
        ++w_.version[e.a];
        if (w_.riding(e.a)) {
          w_.bp->grow(e.a, cap_box(w_, e.a));
        } else {
          reschedule(e.a, t);
        }
        free_dependents(e.a, t);
        break;
      }
      case EventKind::Expire:
        w_.advance(e.a, e.time);
        kill_body(w_, e.a);
        free_dependents(e.a, e.time);
        break;
      case EventKind::Explode:
        w_.advance(e.a, e.time);
        explode_parent(w_, e.b, t_abs);
        free_dependents(e.a, e.time);
        break;
      case EventKind::Emit:   // reads the parent's path; its state is not touched
        record_emission(w_, e.b, w_.pos_at(e.a, e.time), w_.vel_at(e.a, e.time), t_abs);
        break;
    }
  }

  void process_pair(std::uint32_t i, std::uint32_t j, double t, double t_abs) {
    const PairResponse& r = w_.response(w_.group[i], w_.group[j]);
    if (r.collide) {   // on the integrator's own path, which ends a sub-step (substeps.cpp)
      t = refine_pair_impact(w_, i, j, t, std::max(w_.tloc[i], w_.tloc[j]), T_);
      t_abs = ctx_.t0 + t;
      end_substep(w_, i, t);
      end_substep(w_, j, t);
    } else {
      w_.advance(i, t);
      w_.advance(j, t);
    }
    ++w_.stats.impacts;
    if (!r.collide) {   // "event": pass through, report once
      if (r.event) record_contact(w_, i, j, nullptr, t_abs, ctx_.dt);
      add_passing(w_, pair_key(i, j));
      return;
    }
    const Vec2 d = w_.pos[j] - w_.pos[i];
    const double dl = length(d);
    const Vec2 n = dl > 0.0 ? d / dl : Vec2{1.0, 0.0};
    PairMaterial m = w_.pair_material(w_.material[i], w_.material[j]);
    // Inelastic collapse: below the collapse speed an impact is perfectly inelastic (for
    // a pair whose cluster rests on something; a freely falling one keeps e).
    // An elastic pair (e = 1) never collapses (impact_rest_speed).
    const double e0 = m.restitution;
    const bool slow = e0 < 1.0 && collapses(w_, i, j, t, -dot(w_.vel[j] - w_.vel[i], n));
    if (slow) m.restitution = 0.0;
    double min_sep = 0.0;
    bool settled = false;
    double closing = 0.0, rest_vr = 0.0;   // the pair's closing speed and rest speed, when pressed
    bool noted = false;                     // counted as a storm's impact
    if (w_.any_forces) {
      const double an = dot(impact_acceleration(w_, j) - impact_acceleration(w_, i), n);   // (the face's case, below)
      const double vn = dot(w_.vel[j] - w_.vel[i], n);
      if (an < 0.0) {
        const double vr = w_.impact_rest_speed(an, ctx_.dt, e0, vn);
        closing = -vn;
        rest_vr = vr;
        if (m.restitution * std::max(0.0, -vn) < vr) {
          // A lone ball bouncing straight on a static circle: its Zeno sequence in closed form.
          if (circle_tail(i, j, -1.0 * n, e0, t, t_abs, r.event) || circle_tail(j, i, n, e0, t, t_abs, r.event)) return;
          if (storms_) note_storm_impact(w_, i, j), noted = true;   // an impact storm makes a granular group
          // Pressed together and too slow to bounce clear. Onto a body at rest: come to
          // rest on it (a stack). Otherwise a micro-bounce with a flight of at least
          // ~1/8 step instead of endless impacts.
          if (can_rest_on(w_, i, j, -n, vr)) {
            rest_on_body(w_, i, j, -n);
            settled = true;
          } else if (can_rest_on(w_, j, i, n, vr)) {
            rest_on_body(w_, j, i, n);
            settled = true;
          } else if (hold_against(i, j) || hold_against(j, i)) {
            settled = true;   // at rest on several supports
          } else if (hold_pocket(i) || hold_pocket(j)) {
            settled = true;   // a group micro-bouncing on its supports: its pocket
          } else if (join_chain(i, j, n, t, vr)) {
            settled = true;   // bodies on a face pressed together: one train, joined whole
          } else {
            min_sep = 0.5 * vr;
          }
        }
      }
    }
    const Vec2 vi_before = w_.vel[i], vj_before = w_.vel[j];
    // Impacts of each body at this very instant: a slow body met again and again at one
    // instant (a cycle of impacts among wedged bodies) is wedged too.
    if (t != instant_) {
      for (std::uint32_t x : counted_) same_instant_[x] = 0;
      counted_.clear();
      instant_ = t;
    }
    if (same_instant_.size() < w_.size()) same_instant_.resize(w_.size(), 0);
    for (std::uint32_t x : {i, j}) {
      if (same_instant_[x]++ == 0) counted_.push_back(x);
    }
    const bool cycling = same_instant_[i] > kCycle || same_instant_[j] > kCycle;
    // A pair met again and again at one instant is an impact storm whether or not the field
    // presses it (a row of balls, some sliding and some in flight, pressed together by the
    // sliders' friction alone: the fourteenth hunt's row of six met one set of four at one
    // instant for ever, each set ~3.5 ms), so it counts towards the granular mode as a
    // pressed slow impact does (once).
    if (storms_ && cycling && !noted) note_storm_impact(w_, i, j);
    // A pressed, slow body that the impulses leave exactly as it was would meet the same
    // impact at the same instant for ever: wedged, it is held where it is.
    const auto wedged = [&]() {
      const bool unchanged = w_.vel[i] == vi_before && w_.vel[j] == vj_before;
      if (!(min_sep > 0.0 && unchanged) && !cycling) return false;
      for (std::uint32_t x : {i, j}) {
        if (!w_.stationary(x) && force_hold(x)) return true;
      }
      return false;
    };
    // A body met again and again at one instant by contacts that each look separating
    // once the other has been resolved (a body falling into a slot between two at rest):
    // its set takes every touching contact, separating or not, so that all are solved
    // at once.
    w_.sim_with_separating = cycling;
    // A gas's impact: free bodies, no forces, nothing else near. The pairwise response is
    // found first and the broad-phase query for the pair's new paths is asked once, wide
    // enough to prove that no third body or face touches the pair (then the simultaneous
    // law would find one contact and defer to the pairwise law): no touching-set gather.
    bool isolated = false;
    if (!settled && fast_isolated_ && !cycling && !w_.stationary(i) && !w_.stationary(j)) {
      resolve_pair(w_, i, j, n, m, min_sep);
      isolated = isolated_pair(i, j, t);
      if (!isolated) {   // undone: the touching set decides, as without this shortcut
        w_.vel[i] = vi_before;
        w_.vel[j] = vj_before;
      }
    }
    if (cycling) cycle_vel_.assign(w_.vel.begin(), w_.vel.end());
    bool stopped = false;
    if (!settled && !isolated && !cycling && min_sep > 0.0 && closing > rest_vr &&
        (m.friction > 0.0 || m.static_friction > 0.0) && stopped_and_held(i, j, t, t_abs)) {
      settled = true;   // stopped by the impact, held where it stopped
      stopped = true;   // its set's contacts recorded as a set's are
    }
    bool simultaneous = !settled && !isolated && resolve_simultaneous(w_, i, j, t, set_, impacted_, min_sep);
    if (simultaneous && cycling && set_gained_energy()) {
      // A zero-time cycle is inelastic collapse (infinitely many impacts in no time, the
      // gaps at round-off). Its separating contacts may take an impulse (w+ = 0 where
      // w- > 0), which does positive work p w- / 2: a light ball squeezed between a wall
      // and a 1e6 times heavier one was held at the wall while the heavy one bounced off
      // it at their relative speed, 5,800 times the scene's energy. The limit of the
      // collapse is the perfectly inelastic answer: the same set solved with every
      // restitution 0, which is the kinetic-energy-norm projection of the velocities onto
      // w+ >= 0, so it never raises the energy.
      for (std::uint32_t b : set_) w_.vel[b] = cycle_vel_[b];
      w_.sim_inelastic = true;
      simultaneous = resolve_simultaneous(w_, i, j, t, set_, impacted_, min_sep);
      w_.sim_inelastic = false;
    }
    w_.sim_with_separating = false;
    if (simultaneous) {
      if (wedged()) ++w_.stats.wedged;
      finish_simultaneous(t, t_abs);
      return;
    }
    if (!settled) {
      if (isolated) {
        // resolved above (resolve_pair: neither body is stationary)
      } else if (slow && w_.stationary(j) && !w_.stationary(i)) {
        resolve_static(w_, i, -n, m, min_sep);   // its supports absorb a slow impact
      } else if (slow && w_.stationary(i) && !w_.stationary(j)) {
        resolve_static(w_, j, n, m, min_sep);
      } else {
        resolve_pair(w_, i, j, n, m, min_sep);
      }
      if (wedged()) {
        ++w_.stats.wedged;
      } else {
        after_velocity_change(i);
        after_velocity_change(j);
      }
    }
    if (r.event && !stopped) record_contact(w_, i, j, nullptr, t_abs, ctx_.dt);
    ++w_.version[i];
    ++w_.version[j];
    destroy_after(i, r.destroy_first);
    destroy_after(j, r.destroy_second);
    reschedule_pair(i, j, t, isolated);
    if (!settled) {
      free_dependents(i, t);
      free_dependents(j, t);
    }
  }

  // A fast impact (closing faster than the rest speed) of a pair pressed together that no
  // hold takes as it comes (the falling body is too fast) and that the impact law stops:
  // its set's law without a micro-bounce target (min_sep 0) leaves every body of the set at
  // rest, and the body that moved is then held by its supports (hold_against). Then that is
  // the answer, as rigid Coulomb says: the impact stops it and the contacts hold it. With
  // the micro-bounce target instead (min_sep = v_r / 2, raised on the seed pair), the set
  // must part the pair, and where the pair's own friction couples it to a body whose face
  // friction would hold it, that body had to slide: a 0.1 kg ball dropped 0.2 m into the
  // notch between a wall and a 1 kg ball on a floor, e 0, mu 0.5, moved the resting ball
  // 1.46e-3 m/s, 2.2e-7 m (CoreWedge.LightBallInTheNotchWithModerateFriction...). Otherwise
  // (the set does not come to rest, or no hold takes it) nothing has changed, and the
  // micro-bounce law decides as before. Returns whether it was so settled. Only for a pair
  // with friction: without it the target is met along the normals, the least-energy
  // separation (the documented micro-bounce exception), and no body's contact state is
  // forced to change; tried on frictionless pairs too, the 50-circle frictionless pile at
  // e 0.9 (seed 3) crawled for minutes (1 s before: CorePileSettles ... n50_e9_seed3_mu0).
  bool stopped_and_held(std::uint32_t i, std::uint32_t j, double t, double t_abs) {
    // Only a free body striking one at rest can be so held (checked first: the dry run is a
    // whole set solve).
    const bool free_on_resting = (w_.stationary(j) && !w_.stationary(i) && !w_.supported(i)) ||
                                 (w_.stationary(i) && !w_.stationary(j) && !w_.supported(j));
    if (!free_on_resting) return false;
    w_.sim_trial.clear();
    w_.sim_dry_run = true;
    const bool solved = resolve_simultaneous(w_, i, j, t, set_, impacted_, 0.0);
    w_.sim_dry_run = false;
    if (!solved) return false;
    std::uint32_t moved = kNone;
    for (const auto& [b, v] : w_.sim_trial) {
      if (v.x != 0.0 || v.y != 0.0) return false;   // not at rest: no stop
      if (w_.vel[b].x == 0.0 && w_.vel[b].y == 0.0) continue;
      if (moved != kNone) return false;   // two bodies stopped: not one held on the others
      moved = b;
    }
    if (moved != i && moved != j) return false;
    const std::uint32_t other = moved == i ? j : i;
    // The body stopped, its velocity 0 now, on supports that stay (every other body of the
    // set kept its velocity, 0): a free body held where it is by what it touches (try_hold,
    // no pocket), only if its group test justifies the hold now (a hold left to the braced
    // judgement is dropped: a ball landing on two balls that the frictionless faces under
    // them let spread must push them apart, the micro-bounces' answer).
    if (w_.supported(moved) || !w_.stationary(other) || w_.stationary(moved)) return false;
    const double r = w_.radius[moved];
    const double pad = r + 1e-9 * (r + w_.length_scale);
    const Vec2 q = w_.pos[moved];
    near_.clear();
    w_.bp->query_box(make_aabb(q.x - pad, q.y - pad, q.x + pad, q.y + pad), moved, near_);
    const std::size_t braced = w_.braced_holds.size();
    const Vec2 v_moved = w_.vel[moved], a_moved = w_.apath[moved];
    w_.vel[moved] = {};   // the set's answer
    if (!try_hold(w_, moved, ctx_.dt, near_, false)) {
      w_.vel[moved] = v_moved;
      return false;
    }
    if (w_.braced_holds.size() != braced) {   // undone: free, as it was
      w_.braced_holds.resize(braced);
      release_support(w_, moved);
      w_.vel[moved] = v_moved;
      w_.apath[moved] = a_moved;
      return false;
    }
    for (const BodyPair& p : impacted_) {   // as finish_simultaneous records them, in order
      if (p.a & kSimultaneousFace) {
        record_contact(w_, p.b, kNone, &w_.statics.segments[p.a & ~kSimultaneousFace], t_abs, ctx_.dt);
      } else {
        record_contact(w_, p.a, p.b, nullptr, t_abs, ctx_.dt);
      }
    }
    return true;
  }

  // Whether the last simultaneous solve raised its set's kinetic energy beyond round-off
  // (cycle_vel_: the velocities before it).
  bool set_gained_energy() const {
    double before = 0.0, after = 0.0;
    for (std::uint32_t b : set_) {
      if (w_.is_static(b) || !(w_.inv_mass[b] > 0.0)) continue;
      const double m = 1.0 / w_.inv_mass[b];
      before += 0.5 * m * dot(cycle_vel_[b], cycle_vel_[b]);
      after += 0.5 * m * dot(w_.vel[b], w_.vel[b]);
    }
    return after > before * (1.0 + 1e-12);
  }

  // Every body of a touching set resolved at once (resolve_simultaneous): new paths
  // for all, contacts recorded per pair that took an impulse, dependents freed.
  void finish_simultaneous(double t, double t_abs) {
    for (std::uint32_t b : set_) {
      if (w_.is_static(b)) continue;
      after_velocity_change(b);
      ++w_.version[b];
    }
    for (const BodyPair& p : impacted_) {
      if (p.a & kSimultaneousFace) {
        record_contact(w_, p.b, kNone, &w_.statics.segments[p.a & ~kSimultaneousFace], t_abs, ctx_.dt);
      } else {
        record_contact(w_, p.a, p.b, nullptr, t_abs, ctx_.dt);
      }
    }
    for (std::uint32_t b : set_) {
      if (!w_.is_static(b)) reschedule(b, t);
    }
    for (std::uint32_t b : set_) {
      if (!w_.is_static(b)) free_dependents(b, t);
    }
  }

  // Body i meets end point k at t: resolved with every other end point and face it touches
  // then, as one set (resolve_simultaneous with end points); false when it touches no other.
  bool cap_set(std::uint32_t i, std::uint32_t k, double t) {
    w_.sim_caps = true;
    const bool done = resolve_simultaneous(w_, i, kSimultaneousFace | k, t, set_, impacted_);
    w_.sim_caps = false;
    return done;
  }

  void process_static(std::uint32_t i, std::uint32_t k, std::uint8_t feature, double t, double t_abs,
                      bool from_back) {
    const Segment& seg = w_.statics.segments[k];
    const PairResponse& r = w_.response(w_.group[i], seg.group);
    if (r.collide) {   // on the integrator's own path, which ends a sub-step (substeps.cpp)
      t = refine_static_impact(w_, i, seg, feature != 0, t, w_.tloc[i], T_);
      t_abs = ctx_.t0 + t;
      end_substep(w_, i, t);
    } else {
      w_.advance(i, t);
    }
    ++w_.stats.impacts;
    if (!r.collide) {
      if (r.event) record_contact(w_, i, kNone, &seg, t_abs, ctx_.dt);
      add_passing(w_, static_key(i, k));
      return;
    }
    const Vec2 p = w_.pos[i];
    const bool face = feature == 0;
    Vec2 n;
    if (face) {
      // The side the face was met from, as the event was found (the root of that side's
      // gap). Read from the position at impact instead, a point's side was the sign of a
      // round-off: a point at 5000 m/s in a 4 m box met a wall at x = -2 - 4.4e-15, was
      // taken as coming from outside, kept its velocity and left the box.
      n = (from_back ? -1.0 : 1.0) * seg.normal;
    } else {
      const double u = dot(p - seg.from, seg.dir);
      const Vec2 q = u <= 0.0 ? seg.from : seg.to;
      n = normalized(p - q);
      if (length_squared(n) == 0.0) n = u <= 0.0 ? -seg.dir : seg.dir;
    }
    // The response normal: a surface's precomputed normals, interpolated along the piece.
    Vec2 n_resp = n;
    if (face && (seg.normal_from.x != 0.0 || seg.normal_from.y != 0.0)) {
      const double f = std::clamp(dot(p - seg.from, seg.dir) / seg.length, 0.0, 1.0);
      Vec2 nn = normalized((1.0 - f) * seg.normal_from + f * seg.normal_to);
      if (dot(nn, n) < 0.0) nn = -nn;
      if (length_squared(nn) > 0.0) n_resp = nn;
    }
    const PairMaterial m = w_.pair_material(w_.material[i], seg.material);
    const double vn = dot(w_.vel[i], n);
    // The acceleration pressing it now. A free body on sub-steps (drag, wind, thrust) has
    // forces that depend on its velocity, and acc[i] is the step start's: after an impact
    // inside the step it is stale. A body arriving at 12 m/s where its thrust table gives 0
    // and stopped by an e = 0 wall is pushed back into it at once by the table's 4 m/s^2 at
    // rest; read with the arrival's 0, that zero-speed impact was never "pressed", never
    // settled, and repeated until the event cap (core diverged, no reference).
    const double an = dot(impact_acceleration(w_, i), n);
    const bool pressed = w_.any_forces && an < 0.0;
    const double vr = pressed ? w_.impact_rest_speed(an, ctx_.dt, m.restitution, vn) : 0.0;
    const bool slow = pressed && m.restitution * std::max(0.0, -vn) < vr;
    const bool own_support = w_.supported(i) && w_.support[i] == k;
    // A lone body's slow impact on one face: its whole Zeno sequence in closed form.
    if (slow && face && zeno_tails_ && !own_support && zeno_tail(i, k, n, n_resp, m, vn, an, t, t_abs, r.event)) return;
    // A gas's wall impact with nothing else near: the pairwise response, its new path's
    // broad-phase query asked once, wide enough to prove that the touching set would
    // hold this face's contact only (isolated_static).
    bool isolated = false;
    if (fast_isolated_ && !slow && face && !w_.supported(i) && !w_.stationary(i) && w_.radius[i] > 0.0) {
      const Vec2 v_before = w_.vel[i];
      resolve_static(w_, i, n_resp, m, 0.0);
      if (dot(w_.vel[i], n) < 0.0) resolve_static(w_, i, n, m, 0.0);
      isolated = isolated_static(i, k, t);
      if (!isolated) w_.vel[i] = v_before;
    }
    if (isolated) {
      after_velocity_change(i);   // resolved above, as the last branch below does
    } else if (slow && face && !own_support && !w_.stationary(i) && hold(i)) {
      // Pressed into a second face (a corner, a V) or a face beside bodies at rest:
      // held at rest there if its contacts together can hold it.
    } else if (slow && face && !w_.supported(i) && !w_.any_rules && touches_another_face(i, k, n) &&
               resolve_simultaneous(w_, i, kSimultaneousFace | k, t, set_, impacted_)) {
      // A free body meeting two faces at one instant (a V, a corner) too slowly to bounce
      // clear: Newton's law at both at once (settling on the first face found and then
      // meeting the second sent a ball dropped into a V at e = 0 sideways out of it, to the
      // side the wall order gave; at once it stops in the pocket, where the hold takes it).
      finish_simultaneous(t, t_abs);
      return;
    } else if (slow && face && !own_support && w_.supported(i) && settle_on_next_face(w_, i, k, n, m)) {
      // A concave corner: from its face onto the next one (resting_contact.cpp).
    } else if (slow && face && (!w_.supported(i) || own_support)) {
      // Settle: the normal velocity goes (friction impulse included), and the body
      // rests on this face until it is lifted, pulled away or slides off its end.
      settle_on_face(w_, i, k, n, m);
    } else if (!slow && face && !own_support && !w_.any_rules &&
               resolve_simultaneous(w_, i, kSimultaneousFace | k, t, set_, impacted_)) {
      // Body i touches other bodies or faces at this instant: Newton's law at all of
      // its contacts at once (a ball wedged between a wall and another ball).
        finish_simultaneous(t, t_abs);
      return;
    } else if (slow && !face && !w_.supported(i) && !w_.stationary(i) && hold(i)) {
      // Pressed onto an end point and something else (the other end of a drain narrower
      // than it): held at rest there if its contacts together can hold it.
    } else if (!face && !w_.supported(i) && !w_.any_rules && cap_set(i, k, t)) {
      // A free body meeting an end point and, at the same instant, another end point or a
      // face (a ball dropped onto a drain narrower than it lands on both of its ends):
      // Newton's law at all of them at once. One at a time, the end listed first took the
      // whole impact and a ball dropped square onto a drain left it 60 degrees off the
      // vertical, to the side the walls' order gave (the fourteenth hunt).
      finish_simultaneous(t, t_abs);
      return;
    } else if (slow && !face && !w_.supported(i) && settle_on_cap(w_, i, t, ctx_.t0, ctx_.dt, true)) {
      // A free body meeting a convex corner too slowly to bounce clear rides its cap
      // (convex_cap.cpp; it micro-bounced there, first order).
      ++w_.version[i];
      const double te = ride_cap(w_, i, t, T_, ctx_.t0, ctx_.dt);
      if (w_.riding(i)) {
        w_.bp->grow(i, cap_box(w_, i));
      } else {
        reschedule(i, te);
      }
      free_dependents(i, t);
      return;
    } else {
      resolve_static(w_, i, n_resp, m, slow ? 0.5 * vr : 0.0);
      // An interpolated normal must still send the body away from the segment.
      if (dot(w_.vel[i], n) < 0.0) resolve_static(w_, i, n, m, 0.0);
      if (own_support) release_support(w_, i);
      after_velocity_change(i);
    }
    if (w_.radius[i] == 0.0 && face) {
      // A point sits on the line at impact: keep it a hair on its own side, so that
      // the next face test knows which side it is on.
      // Beyond the band in which the face test reads a point's side from its motion
      // (toi::circle_segment: 8 eps x (coordinates + speed x step)).
      const double D = dot(w_.pos[i] - seg.from, n);
      const double coords = std::max(std::fabs(p.x), std::fabs(p.y)) + std::max(std::fabs(seg.from.x), std::fabs(seg.from.y));
      const double delta = 2.220446049250313e-16 *
                           std::max(64.0 * w_.length_scale, 32.0 * (coords + (length(w_.vel[i]) + length(w_.effective_acc(i)) * ctx_.dt) * ctx_.dt));
      if (D < delta) w_.pos[i] += (delta - D) * n;
    }
    if (r.event) record_contact(w_, i, kNone, &seg, t_abs, ctx_.dt);
    ++w_.version[i];
    destroy_after(i, r.destroy_first);
    reschedule(i, t, isolated);
    free_dependents(i, t);
  }

  // A Zeno tail taken in closed form (zeno_tail): body i left face `face` at t0 from p with
  // normal speed v0 along n (restitution e, normal acceleration -a), tangential velocity vt
  // and acceleration at; at rest at t0 + D, D = 2 v0 / (a (1 - e)). The body was put at its
  // state at t_end (the rest, or the step's end) with version `version`.
  struct Tail {
    std::uint32_t body, face, version;   // face kNone: on static body `partner` (circle_tail)
    double t0, t_end, D, v0, a, e;
    Vec2 p, vt, at, n;
    // With friction impulses (slide): the slip along `dir` (signed), after impact j (j = 0 the
    // tail's first, at t0) of phase q (phase[q].m <= j < phase[q + 1].m) is A + B e^j; x: the
    // displacement along dir at impact m from p. T0 = 2 v0 / a: flight j lasts T0 e^j.
    bool slide = false;
    int phases = 0;
    double at_s = 0.0, T0 = 0.0;
    Vec2 dir{};
    struct SlipPhase {
      double m, A, B, x;
    } phase[6]{};
    std::uint32_t partner = kNone;
  };

  // The displacement along the face over flights j in [m, n) of a phase (n may be infinite):
  // sum of (A + B e^j) T0 e^j + at T0^2 e^(2j) / 2.
  static double slide_disp(const Tail& z, const Tail::SlipPhase& f, double n) {
    const double em = std::pow(z.e, f.m), en = std::isinf(n) ? 0.0 : std::pow(z.e, n);
    return f.A * z.T0 * (em - en) / (1.0 - z.e) +
           (f.B * z.T0 + 0.5 * z.at_s * z.T0 * z.T0) * (em * em - en * en) / (1.0 - z.e * z.e);
  }
  // Position along the face and slip at u (time since t0) of a sliding tail, in bounce k (k
  // from tail_state), or the limit at the tail's end (k < 0).
  static void slide_state(const Tail& z, double k, double sig, double& x, double& s) {
    int q = z.phases - 1;
    if (k >= 0.0) {
      while (q > 0 && z.phase[q].m > k) --q;
    }
    const Tail::SlipPhase& f = z.phase[q];
    if (k < 0.0) {
      x = f.x + slide_disp(z, f, INFINITY);
      s = f.A;
      return;
    }
    const double sk = f.A + f.B * std::pow(z.e, k);
    x = f.x + slide_disp(z, f, k) + sk * sig + 0.5 * z.at_s * sig * sig;
    s = sk + z.at_s * sig;
  }

  // The slip's phases of a sliding tail (Tail::slide): impact j has normal change (1 + e) w e^j
  // (w the first impact's closing speed) and takes min(mu (1 + e) w e^j, |u_j|) off the slip
  // u_j before it (collision_response.cpp's Coulomb impulse: kinetic only, never reversing),
  // flight j adds at T0 e^j. Phase from impact m on, sliding through in direction sig (sig u_j
  // > beta e^j, beta = mu (1 + e) w): s_j = A + B e^j with B = (sig beta e - gamma) / (1 - e),
  // gamma = at T0, and it slides through impact j > m iff sig (A + B e^j) > 0 (monotone in
  // e^j: its end is a logarithm). A stop at impact m (|u_m| <= beta e^m) leaves the slip 0:
  // stopped at every later impact if |gamma| <= beta e, else sliding along at through impact
  // m + 1 for ever. Against at the slip may turn within a flight and slide through the next
  // impact the other way. At most: against at, with at, a stop, with at again. False when it
  // needs more phases (not expected).
  static bool slide_phases(Tail& z, double u0, double beta) {
    const double e = z.e, gamma = z.at_s * z.T0;
    double m = 0.0, u = u0, x = 0.0;   // impact m, the slip before it, its displacement
    z.phases = 0;
    while (z.phases < 6) {
      Tail::SlipPhase& f = z.phase[z.phases++];
      f.m = m;
      f.x = x;
      const double em = std::pow(e, m);
      if (std::fabs(u) <= beta * em) {   // stopped at impact m
        if (std::fabs(gamma) <= beta * e) {
          f.A = f.B = 0.0;   // stopped at every impact from m on
          return true;
        }
        f.A = 0.0;   // one flight from rest, then sliding along at through impact m + 1
        f.B = 0.0;
        x += slide_disp(z, f, m + 1.0);
        u = gamma * em;
        m += 1.0;
        continue;
      }
      const double sig = u > 0.0 ? 1.0 : -1.0;
      const double s_m = u - sig * beta * em;
      f.B = (sig * beta * e - gamma) / (1.0 - e);
      f.A = s_m - f.B * em;
      const auto through = [&](double j) { return sig * (f.A + f.B * std::pow(e, j)) > 0.0; };
      // The first impact after m it does not slide through: sig A + sig B e^j <= 0.
      if (!(sig * f.B > 0.0) || !(sig * f.A < 0.0)) return true;   // slides through every impact
      double j = std::ceil(std::log(-f.A / f.B) / std::log(e));
      if (!std::isfinite(j)) return true;
      j = std::max(j, m + 1.0);
      while (j > m + 1.0 && !through(j - 1.0)) j -= 1.0;
      while (through(j)) j += 1.0;
      x += slide_disp(z, f, j);
      u = f.A + (f.B + gamma) * std::pow(e, j - 1.0);   // the slip before impact j
      m = j;
    }
    return false;
  }

  // The closed form of a Zeno tail at time s (z.t0 <= s): position and velocity. Bounce k
  // (k = 0, 1, ...) leaves the face at t0 + D (1 - e^k) with normal speed v0 e^k; from
  // t0 + D the body rests on the face (normal speed 0, the tangential motion goes on).
  static void tail_state(const Tail& z, double s, Vec2& pos, Vec2& vel) {
    const double u = std::max(0.0, s - z.t0);
    Vec2 along = z.p + u * z.vt + (0.5 * u * u) * z.at;
    Vec2 vt = z.vt + u * z.at;
    if (u >= z.D) {
      if (z.slide) {
        double x, sl;
        slide_state(z, -1.0, 0.0, x, sl);
        along = z.p + x * z.dir;
        vt = sl * z.dir;
      }
      pos = along;   // at rest on the face (moving along it)
      vel = vt;
      return;
    }
    // The bounce in progress: the last k with D (1 - e^k) <= u, i.e. e^k >= 1 - u / D.
    const double left = 1.0 - u / z.D;   // in (0, 1]
    int k = left < 1.0 ? static_cast<int>(std::floor(std::log(left) / std::log(z.e))) : 0;
    k = std::max(k, 0);
    const auto start = [&](int q) { return z.D * (1.0 - std::pow(z.e, q)); };
    while (k > 0 && start(k) > u) --k;
    while (start(k + 1) <= u && z.D * std::pow(z.e, k + 1) > 0.0) ++k;
    const double sig = u - start(k);
    const double vk = z.v0 * std::pow(z.e, k);
    const double h = std::max(0.0, sig * (vk - 0.5 * z.a * sig));
    if (z.slide) {
      double x, sl;
      slide_state(z, static_cast<double>(k), sig, x, sl);
      along = z.p + x * z.dir;
      vt = sl * z.dir;
    }
    pos = along + h * z.n;
    vel = vt + (vk - z.a * sig) * z.n;
  }

  // The last impact of a tail at or before s (step time).
  static double tail_last_impact(const Tail& z, double s) {
    const double u = s - z.t0;
    if (u >= z.D) return z.t0 + z.D;
    const double left = 1.0 - u / z.D;
    int k = left < 1.0 ? std::max(0, static_cast<int>(std::floor(std::log(left) / std::log(z.e)))) : 0;
    while (k > 0 && z.D * (1.0 - std::pow(z.e, k)) > u) --k;
    while (z.D * (1.0 - std::pow(z.e, k + 1)) <= u) ++k;
    return z.t0 + z.D * (1.0 - std::pow(z.e, k));
  }

  // Body i, free, meets face k at t slowly enough to collapse (`slow`: its rebound e |v_n|
  // below the rest speed v_r): the rest of its Zeno sequence there is geometric. With
  // nothing else within reach of the tail (no other body's registered path, no other face),
  // a static face, constant acceleration a_n < 0 along n (World::zeno_tails) and a
  // frictionless impact with 0 < e < 1 (World::zeno_material), bounce k lasts 2 v e^k / a
  // (v = e |v_n|, a = |a_n|) and the body comes to rest at t + 2 v / (a (1 - e)) exactly;
  // across the face it moves with constant acceleration throughout. It is put there at
  // once (at rest on the face from then), or, when the step ends inside the tail, at the
  // closed form's state at the step's end (free, in bounce n). Before, the body was held at
  // once (up to 2 v_r / ((1 - e) a) early: at a step of many falls, a rebound whose apex is
  // a large fraction of the drop). A body that another's new path reaches inside the tail
  // is put back at its closed-form state then (unwind_tail) and goes on bounce by bounce.
  // Contacts: the tail's impacts continue this one's contact (record_contact), except an
  // impact after a flight longer than the contact window (only with a fixed rest_speed),
  // which is recorded at its time; the pair's last touch is the tail's last impact in the
  // step. stats.impacts counts the tail as this one impact. Returns false (nothing changed)
  // when a condition fails: the caller's collapse decides as before.
  bool zeno_tail(std::uint32_t i, std::uint32_t k, Vec2 n, Vec2 n_resp, const PairMaterial& m, double vn, double an,
                 double t, double t_abs, bool event) {
    if (!World::zeno_material(m, w_.vel[i], w_.acc[i], n) || !(vn < 0.0) || !(an < 0.0) || n_resp != n) return false;
    if (w_.supported(i) || w_.stationary(i) || !(w_.radius[i] > 0.0) || !(w_.inv_mass[i] > 0.0)) return false;
    if (w_.flags[i] & (kParticle | kPoint | kDestroyOnHit)) return false;
    if (!w_.dep_head.empty() && w_.dep_head[i] != kNone) return false;
    const Segment& seg = w_.statics.segments[k];
    const double e = m.restitution, a = -an;
    const Vec2 v = w_.vel[i], p = w_.pos[i];
    const double v0 = e * -vn;
    if (!(v0 > 0.0)) return false;
    const double D = 2.0 * v0 / (a * (1.0 - e));
    if (!std::isfinite(D)) return false;
    const Vec2 vt = v - vn * n, at = w_.acc[i] - an * n;
    const double S = std::min(D, T_ - t);   // the tail's part in this step
    Tail z{i, k, 0u, t, t + S, D, v0, a, e, p, vt, at, n};
    // With friction and motion along the face: the slip's phases (slide_phases).
    z.slide = !World::zeno_frictionless(m, v, w_.acc[i], n);
    if (z.slide) {
      z.dir = seg.dir;
      z.at_s = dot(at, seg.dir);
      z.T0 = 2.0 * v0 / a;
      if (!slide_phases(z, dot(vt, seg.dir), m.friction * (1.0 + e) * -vn)) return false;
    }
    // The box of the centre's path over the tail: along the face a parabola, across it at
    // most v0^2 / (2 a) from the contact. Sliding: within |u| S + |at| S^2 / 2 of p along the
    // face (the impacts never raise the slip's size, the flights by at most |at| per second).
    double lo_x = p.x, hi_x = p.x, lo_y = p.y, hi_y = p.y;
    const auto take = [&](double s) {
      const Vec2 q = p + s * vt + (0.5 * s * s) * at;
      lo_x = std::min(lo_x, q.x);
      hi_x = std::max(hi_x, q.x);
      lo_y = std::min(lo_y, q.y);
      hi_y = std::max(hi_y, q.y);
    };
    const double reach_along = length(vt) * S + 0.5 * length(at) * S * S;
    if (z.slide) {
      const Vec2 ends[2] = {p - reach_along * seg.dir, p + reach_along * seg.dir};
      for (const Vec2& q : ends) {
        lo_x = std::min(lo_x, q.x);
        hi_x = std::max(hi_x, q.x);
        lo_y = std::min(lo_y, q.y);
        hi_y = std::max(hi_y, q.y);
      }
    } else {
      take(S);
      if (at.x != 0.0 && -vt.x / at.x > 0.0 && -vt.x / at.x < S) take(-vt.x / at.x);
      if (at.y != 0.0 && -vt.y / at.y > 0.0 && -vt.y / at.y < S) take(-vt.y / at.y);
    }
    const Vec2 up = (v0 * v0 / (2.0 * a)) * n;
    lo_x += std::min(0.0, up.x);
    hi_x += std::max(0.0, up.x);
    lo_y += std::min(0.0, up.y);
    hi_y += std::max(0.0, up.y);
    // Its contact stays on the face's interior throughout (its projection is a parabola in
    // time: checked at both ends and at its turn; sliding, its whole reach along the face).
    const double ud = dot(vt, seg.dir), ua = dot(at, seg.dir), u0 = dot(p - seg.from, seg.dir);
    const auto on_face = [&](double s) {
      const double u = u0 + s * ud + 0.5 * s * s * ua;
      return u >= 0.0 && u <= seg.length;
    };
    if (z.slide) {
      if (!(u0 - reach_along >= 0.0 && u0 + reach_along <= seg.length)) return false;
    } else {
      if (!on_face(0.0) || !on_face(S)) return false;
      if (ua != 0.0 && -ud / ua > 0.0 && -ud / ua < S && !on_face(-ud / ua)) return false;
    }
    const double r = w_.radius[i];
    const double tol = 1e-9 * (r + w_.length_scale + inf_norm(p));
    const Aabb tail_box = make_aabb(lo_x - r - tol, lo_y - r - tol, hi_x + r + tol, hi_y + r + tol);
    // Alone: no other body's registered path box and no other face within reach of the tail
    // (widened by the rest speed's reach, the holds' query pad, so that no other body's
    // touching-set or hold query at the tail's times can find this one).
    const double reach = r + w_.rest_speed(length(w_.acc[i]), ctx_.dt) * ctx_.dt + tol;
    const Aabb wide = make_aabb(lo_x - reach, lo_y - reach, hi_x + reach, hi_y + reach);
    near_.clear();
    w_.bp->query_box(wide, i, near_);
    for (std::uint32_t x : near_) {
      if (x != i && w_.alive(x)) return false;
    }
    w_.found_static.clear();
    w_.statics.query(wide, w_.found_static);
    for (std::uint32_t o : w_.found_static) {
      if (o != k) return false;
    }
    // Taken. At rest on the face from t + D (the normal speed is 0 there: settle_on_face
    // removes only round-off).
    take_tail(z, kNone, &seg, t_abs, tail_box, event, [&] { settle_on_face(w_, i, k, n, m); });
    return true;
  }

  // Puts body z.body on its Zeno tail z (from z.t0 to z.t_end, this step's part): the
  // tail's contacts with its partner (face `seg`, or static body `partner_body` with seg
  // null): this impact, and any after a flight longer than the window; its closed-form
  // state at z.t_end, its broad-phase box grown to tail_box; from z.t0 + z.D, when the step
  // holds it, at rest on the partner (rest()), else free in its bounce at the step's end.
  // Keeps z for unwind_tail.
  template <class Rest>
  void take_tail(Tail& z, std::uint32_t partner_body, const Segment* seg, double t_abs, const Aabb& tail_box, bool event,
                 Rest rest) {
    const std::uint32_t i = z.body;
    if (event) {
      record_contact(w_, i, partner_body, seg, t_abs, ctx_.dt);
      double tk = z.t0, vk = z.v0;
      for (int q = 0; q < 64; ++q) {   // flights shrink: only the first few can exceed dt
        const double flight = 2.0 * vk / z.a;
        if (!(flight > ctx_.dt) || tk + flight > z.t_end) break;
        tk += flight;
        vk *= z.e;
        record_contact(w_, i, partner_body, seg, ctx_.t0 + tk, ctx_.dt);
      }
    }
    Vec2 pos, vel;
    tail_state(z, z.t_end, pos, vel);
    if (event) {
      touch_contact(w_, i, seg ? static_partner_key(seg->owner) : partner_body, ctx_.t0 + tail_last_impact(z, z.t_end));
    }
    w_.pos[i] = pos;
    w_.vel[i] = vel;
    w_.tloc[i] = z.t_end;
    ++w_.version[i];
    w_.bp->grow(i, tail_box);
    if (z.D <= T_ - z.t0) {
      rest();
      ++w_.version[i];
      reschedule(i, z.t0 + z.D);
    } else {
      w_.apath[i] = w_.acc[i];   // free, in bounce n at the step's end
    }
    z.version = w_.version[i];
    tails_.push_back(z);
  }

  // The same Zeno tail on a static circle (the sixteenth hunt), or on a ball resting on a
  // level floor (the seventeenth: World::firm_circle): body i, free and alone, meets that
  // body j at t slowly enough to collapse, with its velocity and acceleration
  // along the contact normal nb (from j's centre to i's) to round-off (64 ulps of |v| and
  // |a|: dropped straight onto the top of the circle, the field through its centre), e0 in
  // (0, 1). Every bounce then leaves and returns along nb to the same contact point, so the
  // sequence is the face's: bounce k lasts 2 v e^k / a, at rest on j from t + D, D = 2 v /
  // (a (1 - e)). Before, the pair's collapse held it at once: at a step of 300 falls, e
  // 0.999, the ball sat still from its first impact while it bounces for 6.3 s, 0.67 of the
  // drop off at 1 s, and the reference (dt/8, dt/16) cut it the same way and converged:
  // `ok`. Off the normal (a drop beside the top) the bounces walk off the circle and the
  // collapse decides as before (README, Known limits). False when a condition fails.
  bool circle_tail(std::uint32_t i, std::uint32_t j, Vec2 nb, double e0, double t, double t_abs, bool event) {
    if (!zeno_tails_ || !(e0 > 0.0 && e0 < 1.0) || !w_.firm_circle(j, nb)) return false;
    if (w_.supported(i) || w_.stationary(i) || !(w_.radius[i] > 0.0) || !(w_.inv_mass[i] > 0.0)) return false;
    if (w_.flags[i] & (kParticle | kPoint | kDestroyOnHit)) return false;
    if (!w_.dep_head.empty() && w_.dep_head[i] != kNone) return false;
    const Vec2 v = w_.vel[i], acc = w_.acc[i], p = w_.pos[i];
    const double vn = dot(v, nb), an = dot(acc, nb);
    if (!(vn < 0.0) || !(an < 0.0)) return false;
    const double ulps = 64.0 * 2.220446049250313e-16;
    const Vec2 vt = v - vn * nb, at = acc - an * nb;
    if (!(length(vt) <= ulps * length(v)) || !(length(at) <= ulps * length(acc))) return false;
    const double e = e0, a = -an, v0 = e * -vn;
    if (!(v0 > 0.0)) return false;
    const double D = 2.0 * v0 / (a * (1.0 - e));
    if (!std::isfinite(D)) return false;
    const double S = std::min(D, T_ - t);
    // Alone: the tail's box (the contact point and the apex v0^2 / 2a up nb), widened as the
    // face's tail widens it, meets no other body and no face.
    const Vec2 up = (v0 * v0 / (2.0 * a)) * nb;
    const double r = w_.radius[i];
    const double tol = 1e-9 * (r + w_.length_scale + inf_norm(p));
    const double lo_x = std::min(p.x, p.x + up.x), hi_x = std::max(p.x, p.x + up.x);
    const double lo_y = std::min(p.y, p.y + up.y), hi_y = std::max(p.y, p.y + up.y);
    const Aabb tail_box = make_aabb(lo_x - r - tol, lo_y - r - tol, hi_x + r + tol, hi_y + r + tol);
    const double reach = r + w_.rest_speed(length(acc), ctx_.dt) * ctx_.dt + tol;
    const Aabb wide = make_aabb(lo_x - reach, lo_y - reach, hi_x + reach, hi_y + reach);
    near_.clear();
    w_.bp->query_box(wide, i, near_);
    for (std::uint32_t x : near_) {
      if (x == i || x == j || !w_.alive(x)) continue;
      // A body at rest that does not reach the tail's own box (the balls under j in a
      // stack) can neither meet the ball nor be met by it.
      if (w_.stationary(x) && !overlaps(w_.bp->box(x), tail_box)) continue;
      return false;
    }
    // No face within touch of the tail's path (the partner's own floor, 2 R below, is not).
    w_.found_static.clear();
    w_.statics.query(tail_box, w_.found_static);
    if (!w_.found_static.empty()) return false;
    Tail z{i, kNone, 0u, t, t + S, D, v0, a, e, p, vt, at, nb};
    z.partner = j;
    take_tail(z, j, nullptr, t_abs, tail_box, event, [&] { rest_on_body(w_, i, j, nb); });   // at rest on its top
    return true;
  }

  // Body x, inside a Zeno tail taken in closed form whose state is set at a later time than
  // t: put back at its closed-form state at t, free, and (resched) its events found from
  // there (the next impact of its bounce is an event again).
  void unwind_tail(std::uint32_t x, double t, bool resched = true) {
    if (!(t < w_.tloc[x])) return;
    for (std::size_t q = 0; q < tails_.size(); ++q) {
      Tail& z = tails_[q];
      if (z.body != x) continue;
      const bool live = z.version == w_.version[x] && t >= z.t0;
      const Tail keep = z;
      tails_.erase(tails_.begin() + static_cast<std::ptrdiff_t>(q));
      if (!live) return;
      Vec2 pos, vel;
      tail_state(keep, t, pos, vel);
      if (w_.supported(x)) release_support(w_, x);
      w_.pos[x] = pos;
      w_.vel[x] = vel;
      w_.tloc[x] = t;
      w_.apath[x] = w_.acc[x];
      ++w_.version[x];
      if (keep.face == kNone) {
        if (w_.response(w_.group[x], w_.group[keep.partner]).event) {
          touch_contact(w_, x, keep.partner, ctx_.t0 + tail_last_impact(keep, t));
        }
      } else {
        const Segment& seg = w_.statics.segments[keep.face];
        if (w_.response(w_.group[x], seg.group).event) {
          touch_contact(w_, x, static_partner_key(seg.owner), ctx_.t0 + tail_last_impact(keep, t));
        }
      }
      if (resched) reschedule(x, t);
      return;
    }
  }

  // Whether body i (advanced to now) touches a face other than k, at rest or closing (the
  // same round-off window as the simultaneous set's contacts), along another normal than
  // k's contact normal `nk`: the next piece of a floor drawn in pieces (a junction) is the
  // same support, not a V. (Taken as a V, a ball sliding across a junction met both at
  // once, the simultaneous law changed nothing and left it free, the next piece was met
  // again at the same instant, for ever: the event cap.)
  bool touches_another_face(std::uint32_t i, std::uint32_t k, Vec2 nk) {
    const Vec2 p = w_.pos[i];
    const double r = w_.radius[i];
    const double pad = r * (1.0 + 1e-9) + 1024.0 * 2.220446049250313e-16 * (std::max(std::fabs(p.x), std::fabs(p.y)) + w_.length_scale);
    w_.found_static.clear();
    w_.statics.query(make_aabb(p.x - pad, p.y - pad, p.x + pad, p.y + pad), w_.found_static);
    for (std::uint32_t o : w_.found_static) {
      if (o == k) continue;
      const Segment& s = w_.statics.segments[o];
      if (!w_.response(w_.group[i], s.group).collide) continue;
      const double u = dot(p - s.from, s.dir);
      if (u < 0.0 || u > s.length) continue;
      const double D = dot(p - s.from, s.normal);
      const double scale = std::max(std::fabs(p.x), std::fabs(p.y)) + r + std::max(std::fabs(s.from.x), std::fabs(s.from.y)) +
                           std::max(std::fabs(s.to.x), std::fabs(s.to.y));
      if (std::fabs(D) - r > 1024.0 * 2.220446049250313e-16 * scale) continue;
      const Vec2 n = D >= 0.0 ? s.normal : -s.normal;
      if (dot(n, nk) >= 1.0 - 1e-12) continue;
      if (dot(w_.vel[i], n) <= 1024.0 * 2.220446049250313e-16 * length(w_.vel[i])) return true;
    }
    return false;
  }

  // An impact storm inside this step (a body met more than kStormBail times by pressed, slow pair
  // impacts: a pile's collapse that would run to the event cap): every body is put at t, the
  // storm's bodies become a granular group that takes the rest of the step (granular.cpp), and
  // the event loop goes on without them, every other body's events found again from t.
  void storm_now(double t) {
    w_.storm_bail = false;
    for (std::uint32_t i = 0; i < w_.size(); ++i) {
      if (!tails_.empty()) unwind_tail(i, t, false);
      if (w_.dynamic(i)) w_.advance(i, t);
    }
    if (!engage_storm_groups_now(w_, ctx_, t)) return;
    for (std::uint32_t i = 0; i < w_.size(); ++i) ++w_.version[i];
    schedule_all(t);
  }

  void finish_with_lecture_pass(double t) {
    w_.stats.event_cap_hit = true;
    if (w_.cap_hits == 0) w_.first_cap_time = ctx_.t0 + t;
    ++w_.cap_hits;
    w_.events.clear();
    for (std::uint32_t i = 0; i < w_.size(); ++i) {
      if (!tails_.empty()) unwind_tail(i, t, false);
      if (w_.dynamic(i)) w_.advance(i, t);
    }
    collide_lecture(w_, ctx_, t);
  }

  World& w_;
  StepContext& ctx_;
  const double T_;
  const bool coupled_;   // Newtonian gravity: events cut the whole system's step
  // Free flight, no collision rules, the simultaneous law: an impact with nothing else
  // near is the pairwise law's, proven without the touching set (isolated_pair).
  const bool fast_isolated_;
  const bool zeno_tails_;   // World::zeno_tails
  const bool storms_;       // contact groups allowed: pressed slow pair impacts are counted
  std::vector<Tail> tails_;
  Aabb found_box_i_, found_box_j_;   // the new paths' boxes isolated_pair/_static found
  static constexpr std::uint32_t kFewFaces = 8, kManyFaces = 0xffffffffu;
  Aabb face_boxes_[kFewFaces];       // the faces' boxes, when there are few (face_count_)
  std::uint32_t face_count_ = 0;     // kManyFaces: ask StaticGeometry every time
  std::vector<std::uint32_t> set_;      // the touching set of a simultaneous impact
  std::vector<BodyPair> impacted_;      // its pairs that took an impulse
  std::vector<Vec2> cycle_vel_;         // velocities before a cycling set's solve
  std::vector<std::uint32_t> near_;     // bodies near one being held
  std::vector<std::uint32_t> group_;    // a group held at once
  std::vector<std::uint32_t> chain_, moved_;   // a train joined at an impact (join_chain)
  static constexpr std::size_t kMaxChain = 64;
  static constexpr std::uint32_t kCycle = 64;
  double instant_ = -1.0;                      // the time of the last pair impact
  std::vector<std::uint32_t> same_instant_;    // per body: its impacts at that time
  std::vector<std::uint32_t> counted_;         // bodies with a count to reset
};

}  // namespace

void collide_exact(World& w, StepContext& ctx) {
  EventLoop loop(w, ctx);
  loop.run();
  w.stats.events = ctx.events;
  w.max_events_seen = std::max(w.max_events_seen, ctx.events);
}

}  // namespace physval::core_detail
