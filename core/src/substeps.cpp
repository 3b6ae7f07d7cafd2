// Sub-steps: an impact inside a step keeps the integrator's order when forces depend
// on the velocity (drag, wind, thrust).
//
// Within a step every body follows the integrator's path model (integrators.cpp): a
// parabola through the step's end position, and an end-of-step velocity correction.
// For constant forces that path is exact and an impact may simply change the velocity
// on it. With drag it is not: the parabola's acceleration and the correction were
// computed from the velocity before the impact, so the rest of the step would be
// integrated with the drag of the wrong velocity (first order, whatever the scheme),
// and RK4's parabola meets the state RK4 gives at the impact time only to O(h^3).
//
// So an impact ends the body's sub-step and starts a new one, exactly as if the step
// had been cut at the impact:
//   1. the impact's time is the root of the gap along the integrator's own path,
//      Phi(t) = one step of the integrator from the sub-step's start (t_s, x_s, v_s)
//      with step t - t_s (RK4: Phi differs from the parabola by O(h^3), so the time
//      found on the parabola is refined by a bracketed secant on Phi; velocity Verlet's
//      position is the parabola itself);
//   2. the body is put at Phi(t), position and velocity (RK4's four stages, or
//      Verlet's end correction, for the step t - t_s);
//   3. the impulse is applied;
//   4. a new sub-step of length T - t starts from the new state: its path and end
//      correction are the integrator's for that step.
// A body sliding on a face follows the same rule with the support's law in the
// stages (friction against the sliding direction of the sub-step's start, so the law
// is smooth on it); its stop and its leaving the face's end are found on Phi too.
// Every piece is then one step of the integrator between events, so the error after
// any number of impacts shrinks at the integrator's order. The cost: per impact of a
// body with such forces, 4 acceleration evaluations for the new sub-step, and for
// RK4 2 per gap evaluation of the refinement (typically 4 of them).
// Explicit and semi-implicit Euler are first order with or without an impact inside
// a step and keep their lecture paths.
//
// Newtonian gravity couples every body's path: each body's stages depend on every
// other body's stage positions, so no body can be cut alone (integrating one to its
// impact with the others frozen, or on their parabolas, is first order). There the
// whole system is cut (coupled sub-steps, below, driven by the exact loop): every free
// body's sub-step starts at one time tcut; an event that changes a path (an impact, a
// settle, a release, a particle's death) is found on the paths, its time moved to the
// root of the gap on Phi of the whole system (RK4: one RK4 step of all bodies from tcut
// to t, 2 N-body acceleration evaluations per gap evaluation; Verlet: its parabolas),
// every free body is put at Phi(t), the event is processed, and the system starts a new
// sub-step at t to the step's end (its stages over T - t, new paths, every body's events
// found again). Each piece is one step of the scheme for the whole system, so the order
// holds. Cost, per such event: the gap evaluations of the search (RK4), 3 (RK4) or 1 (Verlet)
// N-body evaluations for the cut, 4 (RK4) or 1 (Verlet) for the new sub-step, and a
// broad-phase rebuild; scenes without Newtonian gravity pay one branch per event.
#include <algorithm>
#include <cmath>
#include <limits>

#include "physval/core/time_of_impact.hpp"
#include "world.hpp"

namespace physval::core_detail {

namespace {

constexpr double kEps = std::numeric_limits<double>::epsilon();
// A gap (or a velocity) within this many ulps of its scale is zero: the round-off of
// evaluating it on the path, far below anything the scheme resolves.
constexpr double kTolUlps = 4.0;

double inf_norm(Vec2 v) { return std::max(std::fabs(v.x), std::fabs(v.y)); }

bool on_face(const World& w, std::uint32_t i) { return w.supported(i) && !w.on_body(i); }

// RK4 from (x_s, v_s) with k1 over step h; forces depend on the velocity only (no
// Newtonian gravity on sub-steps). With want_velocity false k4 is skipped.
PathState rk4_state(const World& w, std::uint32_t i, double h, bool want_velocity) {
  const Vec2 x = w.psub[i], v = w.vsub[i], k1 = w.ksub[i];
  const Vec2 k2 = substep_acceleration(w, i, v + (0.5 * h) * k1);
  const Vec2 k3 = substep_acceleration(w, i, v + (0.5 * h) * k2);
  PathState s;
  s.p = x + h * v + (h * h / 6.0) * (k1 + k2 + k3);
  if (want_velocity) {
    const Vec2 k4 = substep_acceleration(w, i, v + h * k3);
    s.v = v + (h / 6.0) * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
  }
  return s;
}

Vec2 position_on_path(const World& w, std::uint32_t i, double t) {
  if (needs_impact_refinement(w, i)) return rk4_state(w, i, t - w.tsub[i], false).p;
  return w.pos_at(i, t);
}

// A root of f near t0 in [lo, hi]: searched outward from t0 (later if f(t0) > 0, else
// earlier) with growing strides, then closed by a bracketed secant (Illinois) with
// bisection when it crawls. Returns a point where |f| <= ftol (f's round-off), else
// the bracket's end with f <= 0 (contact reached); t0 when no sign change is found (a
// graze the two paths see differently).
template <class F>
double root_near(F&& f, double t0, double lo, double hi, double ftol) {
  const double f0 = f(t0);
  if (std::fabs(f0) <= ftol || !(hi > lo)) return t0;
  const double dir = f0 > 0.0 ? 1.0 : -1.0;
  const double limit = dir > 0.0 ? hi : lo;
  double stride = std::max(std::ldexp(hi - lo, -34), 4.0 * kEps * std::max(std::fabs(t0), hi - lo));
  double a = t0, fa = f0, b = t0, fb = f0;
  for (int k = 0; k < 64; ++k) {
    double tn = t0 + dir * stride;
    if (dir > 0.0 ? tn >= limit : tn <= limit) tn = limit;
    const double fn = f(tn);
    if ((fn > 0.0) != (f0 > 0.0)) {
      b = tn;
      fb = fn;
      break;
    }
    if (tn == limit) return t0;
    // The next stride at least doubles, and reaches past where the secant through the
    // last two samples puts the root (usually bracketing it at the next sample).
    double next = 2.0 * stride;
    if (fn != fa) {
      const double dist = dir * (tn - fn * (tn - a) / (fn - fa) - t0);
      if (std::isfinite(dist)) next = std::max(next, 1.25 * dist);
    }
    a = tn;
    fa = fn;
    stride = next;
  }
  if ((fb > 0.0) == (f0 > 0.0)) return t0;
  // Orient: p on the f > 0 side, q on the f <= 0 side.
  double p = a, fp = fa, q = b, fq = fb;
  if (fp <= 0.0) {
    std::swap(p, q);
    std::swap(fp, fq);
  }
  int side = 0;
  for (int it = 0; it < 200; ++it) {
    if (std::fabs(q - p) <= 4.0 * kEps * std::max(std::fabs(p), std::fabs(q)) || fq == 0.0) break;
    double s = (fp * q - fq * p) / (fp - fq);
    const double mid = 0.5 * (p + q);
    if (!(std::min(p, q) < s && s < std::max(p, q))) s = mid;
    if (it % 8 == 7) s = mid;   // a guaranteed halving now and then
    const double fs = f(s);
    if (std::fabs(fs) <= ftol) return s;
    if (fs > 0.0) {
      p = s;
      fp = fs;
      if (side == 1) fq *= 0.5;   // Illinois: the stale end's weight halves
      side = 1;
    } else {
      q = s;
      fq = fs;
      if (side == -1) fp *= 0.5;
      side = -1;
    }
  }
  return q;
}

}  // namespace

bool uses_substeps(const World& w, std::uint32_t i) {
  return w.varying_forces && !w.newtonian && w.dynamic(i) && (!w.supported(i) || on_face(w, i)) && !w.riding(i) &&
         (w.integrator == Integrator::VelocityVerlet || w.integrator == Integrator::Rk4);
}

Vec2 substep_acceleration(const World& w, std::uint32_t i, Vec2 v) {
  const Vec2 a = body_acceleration(w, i, v);
  if (!w.supported(i)) return a;
  // Friction keeps the direction it had at the sub-step's start: a body does not turn
  // back without a stop event, so the law is smooth on every sub-step.
  return support_acceleration(w, i, a, dot(w.vsub[i], perp(w.support_n[i])));
}

Vec2 impact_acceleration(const World& w, std::uint32_t i) {
  return uses_substeps(w, i) && !w.supported(i) ? body_acceleration(w, i, w.vel[i]) : w.effective_acc(i);
}

bool needs_impact_refinement(const World& w, std::uint32_t i) {
  return w.integrator == Integrator::Rk4 && uses_substeps(w, i);
}

PathState integrator_state(const World& w, std::uint32_t i, double t) {
  if (!uses_substeps(w, i)) return {w.pos_at(i, t), w.vel_at(i, t)};
  const double h = t - w.tsub[i];
  if (w.integrator == Integrator::Rk4) return rk4_state(w, i, h, true);
  // Velocity Verlet: the parabola with a(t_s), then 1/2 h (a(x, v_pred) - a(t_s)).
  const Vec2 k1 = w.ksub[i];
  const Vec2 v_pred = w.vsub[i] + h * k1;
  PathState s;
  s.p = w.psub[i] + h * w.vsub[i] + (0.5 * h * h) * k1;
  s.v = v_pred + (0.5 * h) * (substep_acceleration(w, i, v_pred) - k1);
  return s;
}

void end_substep(World& w, std::uint32_t i, double t) {
  if (!uses_substeps(w, i)) {
    w.advance(i, t);
    return;
  }
  const PathState s = integrator_state(w, i, t);
  w.pos[i] = s.p;
  w.vel[i] = s.v;
  w.tloc[i] = t;
}

void start_substep(World& w, std::uint32_t i, double t, double T) {
  if (!w.alive(i) || !uses_substeps(w, i)) return;
  w.advance(i, t);
  const double h = T - t;
  w.tsub[i] = t;
  w.psub[i] = w.pos[i];
  w.vsub[i] = w.vel[i];
  const Vec2 v = w.vel[i];
  const Vec2 k1 = substep_acceleration(w, i, v);
  w.ksub[i] = k1;
  if (w.integrator == Integrator::VelocityVerlet) {
    w.apath[i] = k1;   // end_paths adds 1/2 (T - t) (a(end) - k1)
    return;
  }
  const Vec2 k2 = substep_acceleration(w, i, v + (0.5 * h) * k1);
  const Vec2 k3 = substep_acceleration(w, i, v + (0.5 * h) * k2);
  const Vec2 k4 = substep_acceleration(w, i, v + h * k3);
  w.apath[i] = (1.0 / 3.0) * (k1 + k2 + k3);
  w.vcorr[i] = (h / 6.0) * (k4 - k1);
}

double refine_static_impact(const World& w, std::uint32_t i, const Segment& seg, bool cap, double t, double t_min,
                            double T) {
  if (!needs_impact_refinement(w, i)) return t;
  const double r = w.radius[i];
  const Vec2 pt = w.pos_at(i, t);
  const double ftol = kTolUlps * kEps * (inf_norm(pt) + r);
  if (cap) {
    const Vec2 q = length_squared(pt - seg.from) <= length_squared(pt - seg.to) ? seg.from : seg.to;
    return root_near([&](double s) { return length(position_on_path(w, i, s) - q) - r; }, t, t_min, T, ftol);
  }
  // The side the body is on before the impact (a point on the line: toi::line_side).
  const double D = dot(w.pos[i] - seg.from, seg.normal);
  const double side = toi::line_side(D, dot(w.vel[i], seg.normal), dot(w.force_acc(i), seg.normal));
  return root_near([&](double s) { return side * dot(position_on_path(w, i, s) - seg.from, seg.normal) - r; }, t,
                   t_min, T, ftol);
}

double refine_pair_impact(const World& w, std::uint32_t i, std::uint32_t j, double t, double t_min, double T) {
  if (!needs_impact_refinement(w, i) && !needs_impact_refinement(w, j)) return t;
  const double R = w.radius[i] + w.radius[j];
  const double ftol = kTolUlps * kEps * (inf_norm(w.pos_at(i, t)) + inf_norm(w.pos_at(j, t)) + R);
  return root_near([&](double s) { return length(position_on_path(w, j, s) - position_on_path(w, i, s)) - R; }, t,
                   t_min, T, ftol);
}

double refine_stop(const World& w, std::uint32_t i, double t, double t_min, double T) {
  if (!uses_substeps(w, i) || !on_face(w, i)) return t;
  const Vec2 tang = perp(w.support_n[i]);
  // The direction it slides in: its velocity's (at its last event), or from rest the
  // direction its acceleration took it.
  const double vt = dot(w.vel[i], tang);
  const double dir = (vt != 0.0 ? vt : dot(w.apath[i], tang)) > 0.0 ? 1.0 : -1.0;
  const double ftol = kTolUlps * kEps * inf_norm(w.vsub[i]);
  return root_near([&](double s) { return dir * dot(integrator_state(w, i, s).v, tang); }, t, t_min, T, ftol);
}

double refine_leave(const World& w, std::uint32_t i, double t, double t_min, double T) {
  if (!needs_impact_refinement(w, i) || !on_face(w, i)) return t;
  const Segment& seg = w.statics.segments[w.support[i]];
  // Off the end it is heading for: u < 0 at `from`, u > L at `to`.
  const Vec2 pt = w.pos_at(i, t);
  const bool at_from = dot(pt - seg.from, seg.dir) < 0.5 * seg.length;
  const double ftol = kTolUlps * kEps * inf_norm(pt);
  return root_near(
      [&](double s) {
        const double u = dot(position_on_path(w, i, s) - seg.from, seg.dir);
        return at_from ? u : seg.length - u;
      },
      t, t_min, T, ftol);
}

// ---- Coupled sub-steps: Newtonian gravity (every body's acceleration depends on every
// body's position). One body cannot be cut alone: the step of the whole system is cut.

namespace {

bool free_body(const World& w, std::uint32_t i) { return w.dynamic(i) && !w.supported(i); }

// The accelerations of every body at the stage state (w.cpl_x, w.cpl_v) into out.
void coupled_stage(World& w, std::vector<Vec2>& out) {
  out.resize(w.size());
  compute_accelerations(w, w.cpl_x, w.cpl_v, out);
}

// Stage state at time ts + c h: free bodies from their sub-step start with the stage
// velocity `vstage` (position x + c h vstage, velocity v + c h kprev); the others on
// their own (constrained) paths.
void set_stage(World& w, double ts, double ch, const std::vector<Vec2>* vprev, const std::vector<Vec2>& kprev) {
  const std::size_t n = w.size();
  w.cpl_x.resize(n);
  w.cpl_v.resize(n);
  for (std::uint32_t i = 0; i < n; ++i) {
    if (!free_body(w, i)) {
      w.cpl_x[i] = w.pos_at(i, ts + ch);
      w.cpl_v[i] = w.vel_at(i, ts + ch);
      continue;
    }
    const Vec2 v = vprev ? (*vprev)[i] : w.vsub[i];
    w.cpl_x[i] = w.psub[i] + ch * v;
    w.cpl_v[i] = w.vsub[i] + ch * kprev[i];
  }
}

// The stages k2, k3 (and k4 if wanted) of RK4 for the whole system over step h from
// its sub-step start, into w.cpl_k[0..2].
void coupled_rk4_stages(World& w, double h, bool want_k4) {
  const double ts = w.tcut;
  std::vector<Vec2>& k2 = w.cpl_k[0];
  std::vector<Vec2>& k3 = w.cpl_k[1];
  std::vector<Vec2>& k4 = w.cpl_k[2];
  set_stage(w, ts, 0.5 * h, nullptr, w.ksub);
  coupled_stage(w, k2);
  // v2 = v + h/2 k1 is what set_stage put in cpl_v; the next stage's position uses it.
  w.cpl_vs.assign(w.cpl_v.begin(), w.cpl_v.end());
  set_stage(w, ts, 0.5 * h, &w.cpl_vs, k2);
  coupled_stage(w, k3);
  if (!want_k4) return;
  w.cpl_vs.assign(w.cpl_v.begin(), w.cpl_v.end());   // v3
  set_stage(w, ts, h, &w.cpl_vs, k3);
  coupled_stage(w, k4);
}

// The system's integrator position of free body i at time t (stages already computed
// for h = t - tcut under RK4).
Vec2 coupled_position(const World& w, std::uint32_t i, double h) {
  if (w.integrator == Integrator::Rk4) {
    return w.psub[i] + h * w.vsub[i] + (h * h / 6.0) * (w.ksub[i] + w.cpl_k[0][i] + w.cpl_k[1][i]);
  }
  return w.psub[i] + h * w.vsub[i] + (0.5 * h * h) * w.ksub[i];
}

// Positions of bodies i and j (j may be kNone) at time t on the system's integrator step.
void coupled_positions(World& w, std::uint32_t i, std::uint32_t j, double t, Vec2& pi, Vec2& pj) {
  const double h = t - w.tcut;
  if (w.integrator == Integrator::Rk4) coupled_rk4_stages(w, h, false);
  pi = free_body(w, i) ? coupled_position(w, i, h) : w.pos_at(i, t);
  if (j != kNone) pj = free_body(w, j) ? coupled_position(w, j, h) : w.pos_at(j, t);
}

}  // namespace

double refine_coupled_pair(World& w, std::uint32_t i, std::uint32_t j, double t, double t_min, double T) {
  // Verlet's positions are its parabolas, the paths the impact was found on.
  if (w.integrator != Integrator::Rk4 || (!free_body(w, i) && !free_body(w, j))) return t;
  const double R = w.radius[i] + w.radius[j];
  const double ftol = kTolUlps * kEps * (inf_norm(w.pos_at(i, t)) + inf_norm(w.pos_at(j, t)) + R);
  return root_near(
      [&](double s) {
        Vec2 pi, pj;
        coupled_positions(w, i, j, s, pi, pj);
        return length(pj - pi) - R;
      },
      t, std::max(t_min, w.tcut), T, ftol);
}

double refine_coupled_static(World& w, std::uint32_t i, const Segment& seg, bool cap, double t, double t_min,
                             double T) {
  if (w.integrator != Integrator::Rk4 || !free_body(w, i)) return t;
  const double r = w.radius[i];
  const Vec2 pt = w.pos_at(i, t);
  const double ftol = kTolUlps * kEps * (inf_norm(pt) + r);
  const auto at = [&](double s) {
    Vec2 p, unused;
    coupled_positions(w, i, kNone, s, p, unused);
    return p;
  };
  t_min = std::max(t_min, w.tcut);
  if (cap) {
    const Vec2 q = length_squared(pt - seg.from) <= length_squared(pt - seg.to) ? seg.from : seg.to;
    return root_near([&](double s) { return length(at(s) - q) - r; }, t, t_min, T, ftol);
  }
  const double D = dot(w.pos[i] - seg.from, seg.normal);
  const double side = toi::line_side(D, dot(w.vel[i], seg.normal), dot(w.force_acc(i), seg.normal));
  return root_near([&](double s) { return side * dot(at(s) - seg.from, seg.normal) - r; }, t, t_min, T, ftol);
}

void coupled_cut(World& w, double t) {
  const std::size_t n = w.size();
  const double h = t - w.tcut;
  if (h == 0.0) return;   // every free body is there already (restarted at t)
  if (w.integrator == Integrator::Rk4) {
    coupled_rk4_stages(w, h, true);
    for (std::uint32_t i = 0; i < n; ++i) {
      if (!free_body(w, i)) continue;
      w.pos[i] = coupled_position(w, i, h);
      w.vel[i] = w.vsub[i] + (h / 6.0) * (w.ksub[i] + 2.0 * w.cpl_k[0][i] + 2.0 * w.cpl_k[1][i] + w.cpl_k[2][i]);
      w.tloc[i] = t;
    }
    return;
  }
  // Velocity Verlet: the parabola, then 1/2 h (a(x(t), v_pred) - a(t_s)).
  w.cpl_x.resize(n);
  w.cpl_v.resize(n);
  for (std::uint32_t i = 0; i < n; ++i) {
    if (free_body(w, i)) {
      w.cpl_x[i] = coupled_position(w, i, h);
      w.cpl_v[i] = w.vsub[i] + h * w.ksub[i];
    } else {
      w.cpl_x[i] = w.pos_at(i, t);
      w.cpl_v[i] = w.vel_at(i, t);
    }
  }
  coupled_stage(w, w.cpl_k[0]);
  for (std::uint32_t i = 0; i < n; ++i) {
    if (!free_body(w, i)) continue;
    w.pos[i] = w.cpl_x[i];
    w.vel[i] = w.cpl_v[i] + (0.5 * h) * (w.cpl_k[0][i] - w.ksub[i]);
    w.tloc[i] = t;
  }
}

void coupled_restart(World& w, double t, double T) {
  const std::size_t n = w.size();
  w.cpl_x.resize(n);
  w.cpl_v.resize(n);
  for (std::uint32_t i = 0; i < n; ++i) {
    w.cpl_x[i] = w.pos_at(i, t);
    w.cpl_v[i] = w.vel_at(i, t);
  }
  std::vector<Vec2>& k1 = w.cpl_k[2];
  coupled_stage(w, k1);
  w.tcut = t;
  for (std::uint32_t i = 0; i < n; ++i) {
    if (!free_body(w, i)) continue;
    w.advance(i, t);
    w.acc[i] = k1[i];
    w.tsub[i] = t;
    w.psub[i] = w.pos[i];
    w.vsub[i] = w.vel[i];
    w.ksub[i] = k1[i];
    w.apath[i] = k1[i];
    w.vcorr[i] = {};
  }
  if (w.integrator != Integrator::Rk4) return;   // Verlet: end_paths corrects from tsub
  const double h = T - t;
  coupled_rk4_stages(w, h, true);
  for (std::uint32_t i = 0; i < n; ++i) {
    if (!free_body(w, i)) continue;
    w.apath[i] = (1.0 / 3.0) * (w.ksub[i] + w.cpl_k[0][i] + w.cpl_k[1][i]);
    w.vcorr[i] = (h / 6.0) * (w.cpl_k[2][i] - w.ksub[i]);
  }
}

}  // namespace physval::core_detail
