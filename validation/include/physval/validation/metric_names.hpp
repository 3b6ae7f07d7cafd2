// The names of the metrics physval computes for a run (results.json "metrics", and
// the keys a [gate] table may limit).
#pragma once

#include <array>
#include <string_view>

namespace physval {

inline constexpr std::array<std::string_view, 19> kMetricNames = {
    "energy_drift",
    "linear_momentum_drift",
    "angular_momentum_drift",
    "energy_divergence",
    "energy_divergence_rms",
    "linear_momentum_divergence",
    "linear_momentum_divergence_rms",
    "position_divergence",
    "position_divergence_rms",
    "first_contact_time",
    "contact_time_error",
    "contact_time_error_steps",
    "missed_contacts",
    "extra_contacts",
    "wall_seconds",
    "expectation_failures",
    "max_penetration",
    "escaped_bodies",
    "energy_gain",
};

inline bool is_metric_name(std::string_view name) {
  for (std::string_view m : kMetricNames) {
    if (m == name) return true;
  }
  return false;
}

}  // namespace physval
