// What a scene conserves, and the totals and scales to measure it with. Everything is
// computed from sampled states and the scene, never from what an engine reports.
#pragma once

#include <string>
#include <vector>

#include "physval/core/engine.hpp"
#include "physval/validation/run_record.hpp"

namespace physval {

// Kinetic energy, potential energy (uniform field: -m g.x; Newtonian: -G mi mj / r),
// linear momentum, angular momentum about the origin, over live moving bodies.
Totals compute_totals(const Scene& scene, const std::vector<BodyMeta>& bodies,
                      const std::vector<BodyState>& states);

struct Conserved {
  bool energy = false;
  bool linear_momentum = false;
  bool angular_momentum = false;
  // Energy can only be lost: no thrust, no wind, no emitter (an explosion gives its
  // particles energy), no destroy rule (a destroyed body takes away its potential energy,
  // which may be negative). Friction, drag towards still air and restitution below 1 only
  // take energy away, so E(t) <= E(0) for a correct engine.
  bool energy_non_increasing = false;
  std::string energy_why;     // the rule that decided, for the README and reports
  std::string momentum_why;
};

// The rules (README, "Conservation"): see conservation.cpp. A scenario's
// [conserves] table overrides each.
Conserved conserved_quantities(const Scene& scene);

// The binding energy of the scene's bound Newtonian system, from its initial state (J):
// the largest of -E(0) (the whole system, when E(0) < 0, `initial_energy`) and of every
// bound pair's -(1/2 mu |vi - vj|^2 + U_ij) (a moving body and a static one: mu = m of the
// moving body). A binary that is bound while the whole scene is not (an intruder with more
// kinetic energy than the binary's binding; a binary whose centre of mass moves) has its
// own. 0 when the scene is not Newtonian or nothing in it is bound.
double binding_energy(const Scene& scene, double initial_energy);

// Characteristic values of a scene that drifts and divergences are divided by. None
// of them can be near zero while the scene moves (a resting pile's energy can).
struct Scales {
  double length = 1.0;            // m: the extent of bodies and barriers, or how far bodies travel
  double energy = 1.0;            // J: max(KE0 + M |g| H + |U_newton(0)|, max KE + range of PE), H: extent along g
  double momentum = 1.0;          // kg m/s: max(sum m |v0|, sqrt(2 M E))
  double angular_momentum = 1.0;  // kg m^2/s: sum m |x0| |v0| + P L
};
// From the scene's initial state, and when `motion` is given (the reference run's
// samples) also from how the scene moves: the largest kinetic energy, the range the
// potential energy spans and the farthest any body travels.
Scales characteristic_scales(const Scene& scene, const Series* motion = nullptr);

}  // namespace physval
