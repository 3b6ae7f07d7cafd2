// The lecture's collision scheme, one pass: move every body for the whole step, find
// the overlaps at the end, back each pair up to the time of impact interpolated
// between the old and new separations (tc = ti + dt (xh - x1) / (x2 - x1)), reflect
// there, and finish the step from the impact point at the new velocity. No re-check:
// a body pushed into a third one stays there until the next step, and a body fast
// enough to cross a wall within one step is not seen (tunnelling). That is the point:
// `collision = "lecture"` shows what the cheap scheme costs and what it misses.
//
// Also the fallback of exact mode at its event cap (from t_from instead of 0).
#include <algorithm>
#include <cmath>

#include "world.hpp"

namespace physval::core_detail {

namespace {

double separation_fraction(double g_old, double g_new) {
  // Gaps (distance minus contact distance) at the start and end of the pass.
  if (g_old <= 0.0) return 0.0;            // overlapping already: reflect where it starts
  if (g_old <= g_new) return 1.0;
  return std::clamp(g_old / (g_old - g_new), 0.0, 1.0);
}

Vec2 closest_on(const Segment& s, Vec2 p) {
  const double u = std::clamp(dot(p - s.from, s.dir), 0.0, s.length);
  return s.from + u * s.dir;
}

}  // namespace

void collide_lecture(World& w, StepContext& ctx, double t_from) {
  const double T = ctx.dt;
  const std::size_t n = w.size();
  const double span = T - t_from;
  std::vector<Vec2>& old = w.scratch_p;
  old.resize(n);
  for (std::uint32_t i = 0; i < n; ++i) {
    if (w.dynamic(i)) w.advance(i, t_from);
    old[i] = w.pos[i];
    if (w.dynamic(i)) w.advance(i, T);
  }
  if (t_from == 0.0) prune_passing(w);

  // Overlaps at the end of the step.
  std::span<Aabb> boxes = w.bp->prepare(n);
  w.active.resize(n);
  for (std::uint32_t i = 0; i < n; ++i) {
    w.active[i] = w.alive(i) ? 1 : 0;
    const double r = w.radius[i];
    const Vec2 p = w.pos[i];
    if (w.active[i]) boxes[i] = make_aabb(p.x - r, p.y - r, p.x + r, p.y + r);
  }
  w.bp->build(w.active);
  w.pairs.clear();
  w.bp->pairs(w.pairs);
  w.stats.candidate_pairs += static_cast<std::int64_t>(w.pairs.size());
  // Keep the overlapping pairs, in index order (the same whatever the broad phase).
  auto keep = [&](const BodyPair& p) {
    const std::uint8_t fa = w.flags[p.a], fb = w.flags[p.b];
    if ((fa & kStatic) && (fb & kStatic)) return false;
    if ((fa & kPoint) && (fb & kPoint)) return false;
    const std::size_t s = w.scene_bodies;
    if ((fa & kParticle) && w.parent[p.a - s] == p.b) return false;
    if ((fb & kParticle) && w.parent[p.b - s] == p.a) return false;
    const double R = w.radius[p.a] + w.radius[p.b];
    return length_squared(w.pos[p.b] - w.pos[p.a]) < R * R;
  };
  w.pairs.erase(std::remove_if(w.pairs.begin(), w.pairs.end(), [&](const BodyPair& p) { return !keep(p); }),
                w.pairs.end());
  std::sort(w.pairs.begin(), w.pairs.end());

  auto finish = [&](std::uint32_t i, Vec2 at, double tc) { w.pos[i] = at + (T - tc) * w.vel[i]; };

  for (const BodyPair& p : w.pairs) {
    const std::uint32_t i = p.a, j = p.b;
    if (!w.alive(i) || !w.alive(j)) continue;
    const double R = w.radius[i] + w.radius[j];
    const double g_new = length(w.pos[j] - w.pos[i]) - R;
    if (g_new >= 0.0) continue;   // an earlier reflection already moved them apart
    const PairResponse& r = w.response(w.group[i], w.group[j]);
    if (!r.collide && !r.event) continue;
    const double g_old = length(old[j] - old[i]) - R;
    const double f = separation_fraction(g_old, g_new);
    const double tc = t_from + f * span;
    const Vec2 pi = old[i] + f * (w.pos[i] - old[i]);
    const Vec2 pj = old[j] + f * (w.pos[j] - old[j]);
    if (!r.collide) {
      const std::uint64_t key = pair_key(i, j);
      if (!is_passing(w, key)) {
        record_contact(w, i, j, nullptr, ctx.t0 + tc, ctx.dt);
        add_passing(w, key);
        ++w.stats.impacts;
      }
      continue;
    }
    const Vec2 d = pj - pi;
    const double dl = length(d);
    const Vec2 nrm = dl > 0.0 ? d / dl : Vec2{1.0, 0.0};
    if (dot(w.vel[j] - w.vel[i], nrm) >= 0.0) continue;   // separating already
    resolve_pair(w, i, j, nrm, w.pair_material(w.material[i], w.material[j]), 0.0);
    if (!w.is_static(i)) finish(i, pi, tc);
    if (!w.is_static(j)) finish(j, pj, tc);
    ++w.stats.impacts;
    if (r.event) record_contact(w, i, j, nullptr, ctx.t0 + tc, ctx.dt);
    if (r.destroy_first || (w.flags[i] & kDestroyOnHit)) kill_body(w, i);
    if (r.destroy_second || (w.flags[j] & kDestroyOnHit)) kill_body(w, j);
  }

  // Static geometry, body by body.
  if (w.statics.segments.empty()) return;
  for (std::uint32_t i = 0; i < n; ++i) {
    if (!w.dynamic(i)) continue;
    const double rad = w.radius[i];
    const Vec2 lo{std::min(old[i].x, w.pos[i].x), std::min(old[i].y, w.pos[i].y)};
    const Vec2 hi{std::max(old[i].x, w.pos[i].x), std::max(old[i].y, w.pos[i].y)};
    w.found_static.clear();
    w.statics.query(make_aabb(lo.x - rad, lo.y - rad, hi.x + rad, hi.y + rad), w.found_static);
    std::sort(w.found_static.begin(), w.found_static.end());
    for (std::uint32_t k : w.found_static) {
      if (!w.alive(i)) break;
      const Segment& s = w.statics.segments[k];
      const Vec2 p_old = old[i], p_new = w.pos[i];
      const double D_old = dot(p_old - s.from, s.normal);
      const double D_new = dot(p_new - s.from, s.normal);
      const bool overlap = length(p_new - closest_on(s, p_new)) < rad;
      bool crossed = false;
      if ((D_old > 0.0) != (D_new > 0.0) && D_old != D_new) {
        const double f = D_old / (D_old - D_new);
        const double u = dot(p_old + f * (p_new - p_old) - s.from, s.dir);
        crossed = u >= 0.0 && u <= s.length;
      }
      if (!overlap && !crossed) continue;
      const PairResponse& r = w.response(w.group[i], s.group);
      if (!r.collide && !r.event) continue;
      const double side = D_old > 0.0 ? 1.0 : (D_old < 0.0 ? -1.0 : (dot(w.vel[i], s.normal) < 0.0 ? 1.0 : -1.0));
      const double f = separation_fraction(side * D_old - rad, side * D_new - rad);
      const double tc = t_from + f * span;
      Vec2 pc = p_old + f * (p_new - p_old);
      if (!r.collide) {
        const std::uint64_t key = static_key(i, k);
        if (!is_passing(w, key)) {
          record_contact(w, i, kNone, &s, ctx.t0 + tc, ctx.dt);
          add_passing(w, key);
          ++w.stats.impacts;
        }
        continue;
      }
      Vec2 nrm = pc - closest_on(s, pc);
      nrm = length_squared(nrm) > 0.0 ? normalized(nrm) : side * s.normal;
      if (rad == 0.0) {
        nrm = side * s.normal;
        pc += (64.0 * 2.220446049250313e-16 * w.length_scale) * nrm;   // stay on its side
      }
      if (dot(w.vel[i], nrm) >= 0.0) continue;
      resolve_static(w, i, nrm, w.pair_material(w.material[i], s.material), 0.0);
      finish(i, pc, tc);
      ++w.stats.impacts;
      if (r.event) record_contact(w, i, kNone, &s, ctx.t0 + tc, ctx.dt);
      if (r.destroy_first || (w.flags[i] & kDestroyOnHit)) kill_body(w, i);
    }
  }
}

}  // namespace physval::core_detail
