// The four integrators, cast as one path model so that impacts can be found exactly
// whatever the scheme: within a step every body follows p(s) = p + v s + 1/2 a s^2
// with a constant path acceleration a, plus a velocity kick at the start or the end.
//
//   explicit Euler        x += v dt; v += a dt:   straight path at the old velocity,
//                         kick a dt at the end (the lecture's literal scheme)
//   semi-implicit Euler   v += a dt; x += v dt:   kick at the start, straight path
//   velocity Verlet       parabola with a(t0), end correction 1/2 (a(t1) - a(t0)) dt
//                         (exact for constant forces)
//   RK4                   parabola through the RK4 end position, a = (k1 + k2 + k3) / 3,
//                         end correction dt/6 (k4 - k1) to reach RK4's velocity
//
// Without collisions each reproduces its textbook scheme exactly; an impact changes
// the velocity at its time and the path continues from there. With forces that depend
// on the velocity, an impact under velocity Verlet or RK4 instead cuts the step into
// sub-steps, each one step of the scheme (substeps.cpp), so the scheme keeps its order.
// A body resting on a support moves with its constrained acceleration whatever the
// integrator.
#include <algorithm>

#include "world.hpp"

namespace physval::core_detail {

namespace {

// (A body riding a convex corner's cap has its own path: convex_cap.cpp.)
bool free_dynamic(const World& w, std::uint32_t i) { return w.dynamic(i) && !w.supported(i) && !w.riding(i); }

void rk4_paths(World& w, double dt) {
  const std::size_t n = w.size();
  std::vector<Vec2>& xs = w.scratch_p;
  std::vector<Vec2>& vs = w.scratch_v;
  std::vector<Vec2>& a2 = w.scratch_a[0];
  std::vector<Vec2>& a3 = w.scratch_a[1];
  std::vector<Vec2>& a4 = w.scratch_a[2];
  xs.resize(n);
  vs.resize(n);
  a2.resize(n);
  a3.resize(n);
  a4.resize(n);
  const std::vector<Vec2>& a1 = w.acc;
  // Stage states; supported and static bodies follow their own (constrained) paths.
  auto stage = [&](double h, const std::vector<Vec2>* v_prev, const std::vector<Vec2>* a_prev, std::vector<Vec2>& out) {
    for (std::uint32_t i = 0; i < n; ++i) {
      if (!free_dynamic(w, i)) {
        xs[i] = w.pos_at(i, h);
        vs[i] = w.vel_at(i, h);
        continue;
      }
      const Vec2 v = v_prev ? (*v_prev)[i] : w.vel[i];
      xs[i] = w.pos[i] + h * v;
      vs[i] = w.vel[i] + h * (*a_prev)[i];
    }
    compute_accelerations(w, xs, vs, out);
  };
  // k2 at (x + v dt/2, v + a1 dt/2); k3 at (x + v2 dt/2, v + a2 dt/2); k4 at (x + v3 dt, v + a3 dt).
  stage(0.5 * dt, nullptr, &a1, a2);
  std::vector<Vec2>& v2 = w.scratch_a[3];
  v2.assign(vs.begin(), vs.end());
  stage(0.5 * dt, &v2, &a2, a3);
  v2.assign(vs.begin(), vs.end());   // now v3
  stage(dt, &v2, &a3, a4);
  for (std::uint32_t i = 0; i < n; ++i) {
    if (!free_dynamic(w, i)) {
      w.vcorr[i] = {};
      continue;
    }
    w.apath[i] = (1.0 / 3.0) * (a1[i] + a2[i] + a3[i]);
    w.vcorr[i] = (dt / 6.0) * (a4[i] - a1[i]);
  }
}

}  // namespace

void begin_paths(World& w, const StepContext& ctx) {
  if (!w.any_forces) return;   // every path is a straight line
  const std::size_t n = w.size();
  const double dt = ctx.dt;
  if (w.varying_forces) {
    // Each body's first sub-step is the whole step (substeps.cpp: impacts cut it).
    w.tcut = 0.0;
    std::fill(w.tsub.begin(), w.tsub.end(), 0.0);
    std::copy(w.pos.begin(), w.pos.end(), w.psub.begin());
    std::copy(w.vel.begin(), w.vel.end(), w.vsub.begin());
    std::copy(w.acc.begin(), w.acc.end(), w.ksub.begin());
  }
  switch (w.integrator) {
    case Integrator::ExplicitEuler:
      for (std::uint32_t i = 0; i < n; ++i) {
        if (free_dynamic(w, i)) w.apath[i] = {};
      }
      break;
    case Integrator::SemiImplicitEuler:
      for (std::uint32_t i = 0; i < n; ++i) {
        if (!free_dynamic(w, i)) continue;
        w.vel[i] += dt * w.acc[i];
        w.apath[i] = {};
      }
      break;
    case Integrator::VelocityVerlet:
      for (std::uint32_t i = 0; i < n; ++i) {
        if (free_dynamic(w, i)) w.apath[i] = w.acc[i];
      }
      break;
    case Integrator::Rk4:
      if (w.varying_forces) {
        rk4_paths(w, dt);
      } else {
        for (std::uint32_t i = 0; i < n; ++i) {
          if (free_dynamic(w, i)) w.apath[i] = w.acc[i];   // constant forces: exact parabola
        }
      }
      break;
  }
  // A body sliding on a face under drag: its support's law integrated by the scheme too.
  for (std::uint32_t i = 0; w.varying_forces && i < n; ++i) {
    if (w.supported(i) && uses_substeps(w, i)) start_substep(w, i, 0.0, dt);
  }
}

void end_paths(World& w, const StepContext& ctx) {
  const std::size_t n = w.size();
  const double T = ctx.dt;
  for (std::uint32_t i = 0; i < n; ++i) {
    if (w.dynamic(i)) w.advance(i, T);
  }
  if (w.any_forces) {
    switch (w.integrator) {
      case Integrator::ExplicitEuler:
        for (std::uint32_t i = 0; i < n; ++i) {
          if (free_dynamic(w, i)) w.vel[i] += T * w.acc[i];
        }
        break;
      case Integrator::SemiImplicitEuler:
        break;
      case Integrator::VelocityVerlet:
        if (w.varying_forces) {
          std::vector<Vec2>& a1 = w.scratch_a[0];
          a1.resize(n);
          compute_accelerations(w, w.pos, w.vel, a1);
          for (std::uint32_t i = 0; i < n; ++i) {
            // Over the body's last sub-step (the whole step unless an impact cut it).
            if (free_dynamic(w, i)) {
              w.vel[i] += (0.5 * (T - w.tsub[i])) * (a1[i] - w.apath[i]);
            } else if (uses_substeps(w, i)) {   // sliding on a face
              w.vel[i] += (0.5 * (T - w.tsub[i])) * (substep_acceleration(w, i, w.vel[i]) - w.apath[i]);
            }
          }
        }
        break;
      case Integrator::Rk4:
        if (w.varying_forces) {
          for (std::uint32_t i = 0; i < n; ++i) {
            if (free_dynamic(w, i) || uses_substeps(w, i)) w.vel[i] += w.vcorr[i];
          }
        }
        break;
    }
  }
  for (std::uint32_t i = 0; i < n; ++i) w.tloc[i] = 0.0;
}

}  // namespace physval::core_detail
