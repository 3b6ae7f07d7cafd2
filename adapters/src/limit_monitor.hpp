// Limits an engine imposes on a run (a speed clamp, float resolution far from the
// origin, a step too long for discrete collision), recorded when first hit and counted
// after that, so a run reports them instead of hiding them (Engine::limits_hit).
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "physval/core/engine.hpp"

namespace physval::adapter {

// The coarsest position resolution physval accepts without a report: 1e-4 m. A float
// coordinate is coarser than that from |x| >= 1024 m (spacing 2^-13 m = 1.2e-4 m); a
// double one from |x| >= 2^39 m (5.5e11 m).
inline constexpr double kPositionResolutionLimit = 1e-4;

// Spacing between adjacent representable values at x in the engine's precision.
double coordinate_spacing(double x, Precision p);

class LimitMonitor {
 public:
  // Records one occurrence of `limit` at time t. `describe` is called only for the
  // first occurrence: it says what happened, to which body, and why it matters.
  void hit(const std::string& limit, double t, const std::function<std::string()>& describe);
  bool was_hit(const std::string& limit) const;
  // One line each: "<limit>: <first description> (first at t = ... s; hit in N steps)".
  std::vector<std::string> lines() const;
  void clear() { entries_.clear(); }

 private:
  struct Entry {
    std::string limit;
    std::string first;
    double first_time = 0.0;
    std::uint64_t count = 0;
    double last_time = -1.0;
  };
  std::vector<Entry> entries_;
};

}  // namespace physval::adapter
