// Containment, from the sampled states: how deep bodies overlap each other or a wall
// (max_penetration) and which bodies left the region their walls enclose
// (escaped_bodies). Documented in the README ("Metrics").
#pragma once

#include <optional>

#include "physval/core/scene.hpp"
#include "physval/validation/run_record.hpp"

namespace physval {

struct Containment {
  double max_penetration = 0.0;             // m, deepest overlap at any sample
  std::optional<int> escaped_bodies;        // only when the walls enclose a region
  std::optional<double> first_escape_time;  // s, the first sample a body was outside
};

// The enclosed region: the walls form closed loops (every wall end meets an even number
// of wall ends, within 1e-9 m); a point is inside when a ray from it crosses the walls an
// odd number of times. A scene body inside at t = 0 escapes when, at a later sample, it
// is alive and its centre is outside.
Containment measure_containment(const Scene& scene, const Series& series);

}  // namespace physval
