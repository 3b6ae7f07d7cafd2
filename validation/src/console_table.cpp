#include "physval/validation/console_table.hpp"

#include <algorithm>
#include <cstdio>
#include <string>

namespace physval {

namespace {

std::string num(const std::optional<double>& v, const char* format = "%.1e") {
  if (!v) return "-";
  char buf[32];
  std::snprintf(buf, sizeof buf, format, *v);
  return buf;
}

std::string metric(const RunRecord& r, const char* name, const char* format = "%.1e") {
  auto it = r.metrics.find(name);
  return it == r.metrics.end() ? "-" : num(it->second, format);
}

// Counts stay within their column: 470400 prints as 5e+05.
std::string count(const RunRecord& r, const char* name) {
  auto it = r.metrics.find(name);
  if (it == r.metrics.end() || !it->second) return "-";
  return num(it->second, *it->second < 1e4 ? "%.0f" : "%.0e");
}

// Word-wraps a note to 100 columns, continuation lines indented further.
void note(std::ostream& os, const std::string& text) {
  constexpr std::size_t kWidth = 100;
  std::string line = "    ";
  std::size_t start = 0;
  while (start < text.size()) {
    std::size_t end = text.find(' ', start);
    if (end == std::string::npos) end = text.size();
    std::string word = text.substr(start, end - start);
    start = end + 1;
    if (line.size() + word.size() + 1 > kWidth && line.find_first_not_of(' ') != std::string::npos) {
      os << line << '\n';
      line = "        ";
    }
    while (word.size() > kWidth - line.size()) {   // a word longer than a line
      const std::size_t room = kWidth - line.size();
      os << line << word.substr(0, room) << '\n';
      word = word.substr(room);
      line = "        ";
    }
    if (line.find_first_not_of(' ') != std::string::npos) line += ' ';
    line += word;
  }
  if (line.find_first_not_of(' ') != std::string::npos) os << line << '\n';
}

std::string pad(std::string s, std::size_t w) {
  if (s.size() > w) s = s.substr(0, w);
  return s + std::string(w - s.size(), ' ');
}
std::string rpad(const std::string& s, std::size_t w) {
  return s.size() >= w ? s : std::string(w - s.size(), ' ') + s;
}

}  // namespace

void print_suite_table(std::ostream& os, const SuiteResult& result) {
  int ok = 0, diverged = 0, unsupported = 0, error = 0, checks_pass = 0, checks_fail = 0;
  for (const ScenarioResult& sr : result.scenarios) {
    const Reference& ref = sr.reference;
    os << '\n' << sr.scene.name << "  (dt " << num(sr.scene.dt, "%.4g") << " s, " << sr.scene.steps() << " steps; reference: ";
    if (!ref.available) os << "none, " << ref.reason;
    else if (ref.converged) os << "core dt " << num(ref.dt, "%.3g") << ", converged to " << num(ref.convergence_error) << " m";
    else os << ref.reason;
    os << ")\n";
    // The engine column fits the longest name (a plugin's may exceed the built-ins' 6).
    std::size_t engine_w = 7;
    for (const RunRecord& r : sr.runs) engine_w = std::max(engine_w, r.engine.size() + 1);
    os << "  " << pad("engine", engine_w) << pad("status", 12) << rpad("E drift", 8) << rpad("P drift", 8) << rpad("pos div", 9)
       << rpad("E div", 8) << rpad("contact", 11) << rpad("steps", 6) << rpad("miss", 6) << rpad("extra", 6)
       << rpad("wall ms", 9) << rpad("checks", 7) << '\n';
    for (const RunRecord& r : sr.runs) {
      int pass = 0, total = 0;
      for (const Check& c : r.checks) {
        if (!c.enforced) continue;
        ++total;
        pass += c.pass ? 1 : 0;
      }
      checks_pass += pass;
      checks_fail += total - pass;
      switch (r.status) {
        case RunStatus::Ok: ++ok; break;
        case RunStatus::Diverged: ++diverged; break;
        case RunStatus::Unsupported: ++unsupported; break;
        case RunStatus::Error: ++error; break;
      }
      std::string contact = metric(r, "contact_time_error");
      if (contact != "-") contact += " s";
      os << "  " << pad(r.engine, engine_w) << pad(run_status_name(r.status), 12) << rpad(metric(r, "energy_drift"), 8)
         << rpad(metric(r, "linear_momentum_drift"), 8) << rpad(metric(r, "position_divergence"), 9)
         << rpad(metric(r, "energy_divergence"), 8) << rpad(contact, 11)
         << rpad(metric(r, "contact_time_error_steps", "%.2f"), 6) << rpad(count(r, "missed_contacts"), 6)
         << rpad(count(r, "extra_contacts"), 6)
         << rpad(r.status == RunStatus::Unsupported || r.status == RunStatus::Error ? "-" : num(r.wall_seconds * 1e3, "%.2f"), 9)
         << rpad(total == 0 ? "-" : std::to_string(pass) + "/" + std::to_string(total), 7) << '\n';
    }
    for (const RunRecord& r : sr.runs) {
      if (r.status != RunStatus::Ok) note(os, r.engine + ": " + r.reason);
      for (const std::string& l : r.limits_hit) note(os, r.engine + " limit: " + l);
      // Failed enforced checks fail the run. Known failures ([gate.<engine>]
      // known_failures) pass within their recorded bounds and are listed under one line
      // that says so; gate limits in `run` are reported only.
      auto off = [](const Check& c) {
        if (!c.detail.empty()) return c.detail + " (off by " + (c.value ? num(c.value, "%.3g") : std::string("-"));
        return std::string(c.value ? "value " + num(c.value, "%.3g") : std::string("not measured")) + " (";
      };
      std::size_t known = 0;
      for (const Check& c : r.checks) known += c.known_failure && c.pass ? 1 : 0;
      if (known > 0) {
        note(os, r.engine + ": " + std::to_string(known) + " known failure" + (known == 1 ? "" : "s") +
                     " within the bounds recorded in [gate." + r.engine + "] known_failures:");
        for (const Check& c : r.checks) {
          if (!(c.known_failure && c.pass)) continue;
          note(os, "- " + c.what + ": " + off(c) + (c.value ? (c.detail.empty() ? "bound " : ", bound ") + num(c.limit, "%.3g") : std::string("")) + ")");
        }
      }
      for (const Check& c : r.checks) {
        if (c.pass) continue;
        const std::string limit = c.known_failure ? "bound " : c.what.rfind("expect.", 0) == 0 ? "tolerance " : "limit ";
        const std::string sep = c.detail.empty() ? "" : ", ";
        if (c.enforced) {
          note(os, r.engine + " FAILED " + c.what + ": " + off(c) + sep + limit + num(c.limit, "%.3g") + ")");
        } else {
          note(os, "- " + r.engine + " " + c.what + ": " + off(c) + sep + limit + num(c.limit, "%.3g") +
                       ", enforced by `gate`)");
        }
      }
    }
    // Containment, one line per scenario (the columns above fill the 100-character width).
    std::string containment;
    for (const RunRecord& r : sr.runs) {
      const std::string pen = metric(r, "max_penetration");
      if (pen == "-") continue;
      containment += (containment.empty() ? "" : ", ") + r.engine + " " + pen + " m";
      if (count(r, "escaped_bodies") != "-") containment += " (" + count(r, "escaped_bodies") + " escaped)";
    }
    if (!containment.empty()) note(os, "max penetration: " + containment);
    for (const PairComparison& p : sr.pairs) {
      auto m = [&](const char* k) {
        auto it = p.metrics.find(k);
        return it == p.metrics.end() ? std::string("-") : num(it->second);
      };
      note(os, p.a + " vs " + p.b + ": pos " + m("position_divergence") + " m, E " + m("energy_divergence") + ", contacts " +
                   m("contact_time_error") + " s");
    }
  }
  const int runs = ok + diverged + unsupported + error;
  os << '\n'
     << runs << " runs: " << ok << " ok, " << diverged << " diverged, " << unsupported << " unsupported, " << error
     << " error; checks: " << checks_pass << " passed, " << checks_fail << " failed\n";
}

}  // namespace physval
