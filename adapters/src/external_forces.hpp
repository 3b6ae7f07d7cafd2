// The forces an adapter applies to its engine's bodies every step, computed by the very
// functions core uses (physval/core/forces.hpp): drag towards the wind, thrust tables
// and Newtonian gravity between bodies. The uniform field is not among them: each
// engine takes it as its own world gravity, the way the engine is meant to be used.
#pragma once

#include <vector>

#include "physval/core/engine.hpp"
#include "physval/core/scene.hpp"

namespace physval::adapter {

class ExternalForces {
 public:
  explicit ExternalForces(const Scene& scene);

  // False when the scene has no force beyond the uniform field: nothing to apply.
  bool active() const { return active_; }

  // forces[i] on scene body i from its state states[i] (read from the engine at the
  // start of the step: an explicit force, as in core). Zero for static and destroyed
  // bodies; destroyed bodies attract nothing. Resizes `forces` to states.size().
  void compute(const std::vector<BodyState>& states, std::vector<Vec2>& forces);

 private:
  const Scene& scene_;
  WorldDef field_free_;   // the scene's world without its uniform field
  bool active_ = false;
  bool newtonian_ = false;
  std::vector<Vec2> positions_;   // scratch for the pairwise Newtonian sum
  std::vector<double> masses_;
  std::vector<Vec2> pair_forces_;
  std::vector<std::size_t> alive_;
};

}  // namespace physval::adapter
