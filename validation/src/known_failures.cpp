#include "physval/validation/known_failures.hpp"

#include <cmath>
#include <iomanip>
#include <sstream>
#include <vector>

namespace physval {

KnownFailures measured_known_failures(const ScenarioResult& scenario, double margin) {
  KnownFailures out;
  for (const RunRecord& r : scenario.runs) {
    if (r.status == RunStatus::Unsupported) continue;
    auto& known = out[r.engine];
    // Bodies through barriers: the count itself (a count takes no margin).
    // (as judged: skipped impacts against the reference included, README "Metrics")
    const std::optional<int> escaped = r.containment.judged_escaped_bodies ? r.containment.judged_escaped_bodies
                                                                            : r.containment.escaped_bodies;
    if (escaped && *escaped > 0) known["escaped_bodies"] = *escaped;
    // A bound system that came apart: E(end) / |E(0)|, with the margin.
    if (r.status == RunStatus::Diverged && r.unbound_ratio) known["energy_crossed_zero"] = *r.unbound_ratio * margin;
    // A bound system whose energy settled more than a quarter of its binding energy away: that
    // change / the binding energy, with the margin.
    if (r.status == RunStatus::Diverged && r.binding_change) known["binding_energy_change"] = *r.binding_change * margin;
    for (const Check& c : r.checks) {
      if (c.what.rfind("expect.", 0) != 0) continue;
      if (c.pass && !c.known_failure) continue;
      if (!c.value) {
        known[c.what] = GateDef::kKnownNotMeasured;   // the contact never happened
      } else if (std::isfinite(*c.value)) {
        known[c.what] = *c.value * margin;
      }   // NaN: no bound to record, it stays a failure
    }
  }
  return out;
}

namespace {

std::string trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \t\r");
  if (b == std::string::npos) return {};
  return s.substr(b, s.find_last_not_of(" \t\r") - b + 1);
}

bool starts_key(const std::string& line, const std::string& key) {
  const std::string t = trim(line);
  if (t.rfind(key, 0) != 0) return false;
  const std::string rest = trim(t.substr(key.size()));
  return !rest.empty() && rest[0] == '=';
}

std::string known_line(const std::map<std::string, double>& known) {
  std::ostringstream os;
  os << "known_failures = {";
  bool first = true;
  for (const auto& [name, bound] : known) {
    os << (first ? " " : ", ") << '"' << name << "\" = ";
    if (name == "escaped_bodies") {
      os << static_cast<long long>(bound);   // a count, exact
    } else if (bound == GateDef::kKnownNotMeasured) {
      os << "\"not measured\"";
    } else {
      // Three significant digits, rounded up so the bound never falls below margin x error.
      const double scale = bound > 0.0 ? std::pow(10.0, std::floor(std::log10(bound)) - 2.0) : 1.0;
      os << std::setprecision(3) << std::ceil(bound / scale) * scale;
    }
    first = false;
  }
  os << " }";
  return os.str();
}

}  // namespace

std::string rewrite_known_failures(const std::string& toml_text, const KnownFailures& known) {
  std::vector<std::string> lines;
  {
    std::istringstream in(toml_text);
    for (std::string l; std::getline(in, l);) lines.push_back(l);
  }
  for (const auto& [engine, misses] : known) {
    const std::string header = "[gate." + engine + "]";
    std::size_t at = lines.size();
    for (std::size_t i = 0; i < lines.size(); ++i) {
      if (trim(lines[i]) == header) at = i;
    }
    if (at == lines.size()) {
      if (misses.empty()) continue;
      if (!lines.empty() && !trim(lines.back()).empty()) lines.emplace_back();
      lines.push_back(header);
      lines.push_back(known_line(misses));
      continue;
    }
    std::size_t end = at + 1;
    while (end < lines.size() && trim(lines[end]).rfind('[', 0) != 0) ++end;
    for (std::size_t i = end; i-- > at + 1;) {
      if (starts_key(lines[i], "known_failures") || starts_key(lines[i], "expectation_failures")) {
        lines.erase(lines.begin() + static_cast<std::ptrdiff_t>(i));
      }
    }
    if (!misses.empty()) lines.insert(lines.begin() + static_cast<std::ptrdiff_t>(at + 1), known_line(misses));
  }
  std::string out;
  for (const std::string& l : lines) out += l + '\n';
  return out;
}

}  // namespace physval
