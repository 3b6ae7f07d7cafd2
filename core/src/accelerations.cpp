// Forces, as accelerations: the uniform field, drag towards the wind, thrust from a
// table, and Newtonian gravity between bodies. Every force comes from the shared
// functions of physval/core/forces.hpp, the same ones the adapters apply to Box2D and
// Bullet bodies.
#include "physval/core/forces.hpp"
#include "world.hpp"

namespace physval::core_detail {

Vec2 body_acceleration(const World& w, std::uint32_t i, Vec2 vel) {
  Vec2 a = (w.flags[i] & kNoGravity) ? Vec2{} : w.gravity;
  if (!w.fparams.empty()) {
    const ForceParams& fp = w.fparams[i];
    Vec2 f;
    if (fp.drag_linear != 0.0 || fp.drag_quadratic != 0.0) {
      f += drag_force(fp.drag_linear, fp.drag_quadratic, vel, w.wind);
    }
    if (fp.thrust >= 0) {
      f += thrust_force(w.thrusts[static_cast<std::size_t>(fp.thrust)], 1.0 / w.inv_mass[i], vel, w.angle[i]);
    }
    a += w.inv_mass[i] * f;
  }
  return a;
}

void compute_accelerations(World& w, std::span<const Vec2> pos, std::span<const Vec2> vel, std::span<Vec2> out) {
  const std::size_t n = w.size();
  for (std::uint32_t i = 0; i < n; ++i) out[i] = w.dynamic(i) ? body_acceleration(w, i, vel[i]) : Vec2{};
  if (w.newtonian) {
    // Pairwise and O(N^2), through the shared function; static bodies attract but are
    // not moved (their force is dropped), dead bodies have mass 0.
    w.scratch_f.assign(n, Vec2{});
    add_newtonian_forces(w.G, w.softening, pos.first(n), std::span<const double>(w.mass).first(n),
                         std::span<Vec2>(w.scratch_f).first(n));
    for (std::uint32_t i = 0; i < n; ++i) {
      if (w.dynamic(i)) out[i] += w.inv_mass[i] * w.scratch_f[i];
    }
  }
}

}  // namespace physval::core_detail
