#include "limit_monitor.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

namespace physval::adapter {

double coordinate_spacing(double x, Precision p) {
  const double a = std::fabs(x);
  if (p == Precision::Float32) {
    const float f = static_cast<float>(a);
    return static_cast<double>(std::nextafter(f, std::numeric_limits<float>::infinity()) - f);
  }
  return std::nextafter(a, std::numeric_limits<double>::infinity()) - a;
}

void LimitMonitor::hit(const std::string& limit, double t, const std::function<std::string()>& describe) {
  auto it = std::find_if(entries_.begin(), entries_.end(), [&](const Entry& e) { return e.limit == limit; });
  if (it == entries_.end()) {
    entries_.push_back({limit, describe(), t, 0, -1.0});
    it = entries_.end() - 1;
  }
  // Count steps, not bodies: several bodies in one step are one hit.
  if (it->last_time != t) {
    ++it->count;
    it->last_time = t;
  }
}

bool LimitMonitor::was_hit(const std::string& limit) const {
  return std::any_of(entries_.begin(), entries_.end(), [&](const Entry& e) { return e.limit == limit; });
}

std::vector<std::string> LimitMonitor::lines() const {
  std::vector<std::string> out;
  for (const Entry& e : entries_) {
    std::ostringstream os;
    os.precision(6);
    os << e.limit << ": " << e.first << " (first at t = " << e.first_time << " s; hit in " << e.count
       << (e.count == 1 ? " step)" : " steps)");
    out.push_back(os.str());
  }
  return out;
}

}  // namespace physval::adapter
