#include "physval/validation/gate.hpp"

#include "markup_escape.hpp"
#include "physval/adapters/registry.hpp"
#include "physval/validation/runner.hpp"

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <ctime>
#include <iomanip>
#include <map>
#include <sstream>
#include <vector>

namespace physval {

namespace {

std::string xml_escape(const std::string& s) { return markup_escape(s); }

std::string json_text_default() { return std::string(); }

std::string g(double v) {
  std::ostringstream os;
  os.precision(4);
  os << v;
  return os.str();
}

// Metrics where bigger is worse and a baseline comparison makes sense. The contact
// counts, the penetration and the energy gain are among them: a contact an engine now
// misses leaves contact_time_error smaller (it is the error of the contacts matched), and
// an overlap 100x deeper changed no other metric.
constexpr const char* kErrorMetrics[] = {
    "energy_drift", "linear_momentum_drift", "angular_momentum_drift", "energy_divergence",
    "linear_momentum_divergence", "position_divergence", "contact_time_error",
    "missed_contacts", "extra_contacts", "max_penetration", "energy_gain"};

// JUnit's timestamp: ISO 8601 without a zone (the Jenkins/Surefire schema's xs:dateTime
// pattern), in UTC.
std::string junit_timestamp() {
  const std::time_t now = std::chrono::system_clock::to_time_t(std::chrono::system_clock::now());
  std::tm tm{};
  gmtime_r(&now, &tm);
  std::ostringstream os;
  os << std::put_time(&tm, "%Y-%m-%dT%H:%M:%S");
  return os.str();
}

std::string junit_hostname() {
  char host[256] = {};
  if (::gethostname(host, sizeof host - 1) != 0 || host[0] == '\0') return "localhost";
  return host;
}

// Every enforced check that failed, with its value and limit: "energy_drift = 0.3 > limit 1e-09".
std::vector<std::string> failed_checks(const RunRecord& r) {
  std::vector<std::string> out;
  for (const Check& c : r.checks) {
    if (c.pass || !c.enforced) continue;
    if (!c.value && !c.detail.empty()) {
      out.push_back(c.what + ": " + c.detail);   // a check with nothing to measure says why it failed
      continue;
    }
    out.push_back(c.what + " = " + (c.value ? g(*c.value) : std::string("not measured")) + " > limit " + g(c.limit));
  }
  return out;
}

// The failed check of a run the baseline ran and this one did not (unsupported now, or
// its engine not run at all): every regression the baseline would catch is hidden.
Check baseline_status_failure(const std::string& before, const std::string& reason) {
  Check c;
  c.what = "baseline.status";
  c.limit = 0.0;
  c.value.reset();
  c.pass = false;
  c.enforced = true;
  c.detail = "the baseline ran it (status " + before + "); this run did not (" + reason + ")";
  return c;
}

}  // namespace

void discard_earlier_junit(const std::string& file) {
  if (file.empty()) return;
  std::error_code ec;
  if (std::filesystem::is_regular_file(std::filesystem::symlink_status(file, ec)) ||
      std::filesystem::is_symlink(std::filesystem::symlink_status(file, ec))) {
    std::filesystem::remove(file, ec);
  }
}

std::string junit_xml(const SuiteResult& result) {
  int tests = 0, failures = 0, errors = 0, skipped = 0;
  double total_time = 0.0;
  std::ostringstream cases;
  for (const ScenarioResult& sr : result.scenarios) {
    for (const RunRecord& r : sr.runs) {
      ++tests;
      total_time += r.wall_seconds;
      cases << "    <testcase classname=\"physval." << xml_escape(sr.scene.name) << "\" name=\"" << xml_escape(r.engine)
            << "\" time=\"" << r.wall_seconds << "\">\n";
      if (r.status == RunStatus::Unsupported && r.passed()) {
        ++skipped;
        cases << "      <skipped message=\"" << xml_escape(r.reason) << "\"/>\n";
      } else if (r.status == RunStatus::Error) {
        // The run did not finish (crash, timeout, exception): a JUnit error, not a failure.
        ++errors;
        const bool timeout = r.reason.rfind("timed out", 0) == 0;
        cases << "      <error message=\"" << xml_escape(r.reason) << "\" type=\"" << (timeout ? "timeout" : "crash")
              << "\">" << xml_escape(r.reason) << "</error>\n";
      } else if (!r.passed()) {
        ++failures;
        std::vector<std::string> parts;
        if (r.status != RunStatus::Ok) parts.push_back(std::string(run_status_name(r.status)) + ": " + r.reason);
        for (std::string& f : failed_checks(r)) parts.push_back(std::move(f));
        std::string message, detail;
        for (std::size_t i = 0; i < parts.size(); ++i) {
          message += (i ? "; " : "") + parts[i];
          detail += parts[i] + '\n';
        }
        cases << "      <failure message=\"" << xml_escape(message) << "\" type=\"physval\">" << xml_escape(detail)
              << "</failure>\n";
      }
      cases << "    </testcase>\n";
    }
  }
  std::ostringstream os;
  os << "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
     << "<testsuites name=\"physval\" tests=\"" << tests << "\" failures=\"" << failures << "\" errors=\"" << errors
     << "\" skipped=\"" << skipped << "\" time=\"" << total_time << "\">\n"
     << "  <testsuite name=\"physval\" tests=\"" << tests << "\" failures=\"" << failures << "\" errors=\"" << errors
     << "\" skipped=\"" << skipped << "\" time=\"" << total_time << "\" timestamp=\"" << junit_timestamp()
     << "\" hostname=\"" << xml_escape(junit_hostname()) << "\">\n"
     << "    <properties/>\n"
     << cases.str() << "    <system-out/>\n    <system-err/>\n  </testsuite>\n</testsuites>\n";
  return os.str();
}

int apply_baseline(SuiteResult& result, const nlohmann::json& baseline, double factor, double floor) {
  std::map<std::pair<std::string, std::string>, const nlohmann::json*> old;
  if (baseline.contains("runs") && baseline["runs"].is_array()) {
    for (const nlohmann::json& r : baseline["runs"]) {
      if (r.contains("scenario") && r.contains("engine")) {
        old[{r["scenario"].get<std::string>(), r["engine"].get<std::string>()}] = &r;
      }
    }
  }
  int matched = 0;
  for (ScenarioResult& sr : result.scenarios) {
    for (RunRecord& r : sr.runs) {
      auto it = old.find({r.scenario, r.engine});
      if (it == old.end() || !it->second->contains("metrics")) continue;
      ++matched;
      // An engine that ran the scenario in the baseline and now cannot model it (a plugin
      // that dropped a feature, a scene that gained one) checks nothing: every regression
      // the baseline would catch is hidden, so the run fails (it passed as "unsupported").
      if (r.status == RunStatus::Unsupported) {
        const nlohmann::json& old_run = *it->second;
        const std::string before = old_run.contains("status") && old_run["status"].is_string()
                                       ? old_run["status"].get<std::string>() : std::string("unsupported");
        if (before != "unsupported") r.checks.push_back(baseline_status_failure(before, r.reason));
        continue;
      }
      // A baseline measured at another dt is not this run's: its numbers mean nothing here.
      if (const nlohmann::json& old_run = *it->second; old_run.contains("dt") && old_run["dt"].is_number()) {
        const double old_dt = old_run["dt"].get<double>();
        if (!(std::abs(old_dt - r.dt) <= 1e-12 * std::max(old_dt, r.dt))) {
          Check c;
          c.what = "baseline.dt (the baseline ran at dt " + g(old_dt) + " s, this run at " + g(r.dt) + " s)";
          c.limit = r.dt;
          c.value = old_dt;
          c.pass = false;
          c.enforced = true;
          r.checks.push_back(c);
          continue;
        }
      }
      const nlohmann::json& om = (*it->second)["metrics"];
      for (const char* name : kErrorMetrics) {
        if (!om.contains(name) || !om[name].is_number()) continue;
        auto mine = r.metrics.find(name);
        const double before = om[name].get<double>();
        Check c;
        c.what = std::string("baseline.") + name;
        c.limit = factor * before + floor;
        if (mine == r.metrics.end() || !mine->second) {
          // The baseline measured it and this run could not (its reference stopped
          // converging, say): the regression it would show is hidden, so the check fails.
          c.value.reset();
          c.pass = false;
          c.detail = "not measured in this run; the baseline measured " + g(before);
          c.enforced = true;
          r.checks.push_back(c);
          continue;
        }
        c.value = *mine->second;
        c.pass = std::isfinite(*c.value) && *c.value <= c.limit;
        c.enforced = true;
        r.checks.push_back(c);
      }
    }
  }
  return matched;
}

int add_runs_missing_from_baseline(SuiteResult& result, const nlohmann::json& baseline,
                                   const std::vector<std::string>& wanted) {
  if (!baseline.contains("runs") || !baseline["runs"].is_array()) return 0;
  int added = 0;
  for (ScenarioResult& sr : result.scenarios) {
    for (const nlohmann::json& old : baseline["runs"]) {
      if (!old.is_object() || old.value("scenario", json_text_default()) != sr.scene.name) continue;
      const std::string engine = old.value("engine", json_text_default());
      const std::string before = old.contains("status") && old["status"].is_string() ? old["status"].get<std::string>()
                                                                                    : std::string("unsupported");
      if (engine.empty() || before == "unsupported") continue;
      if (!wanted.empty() && std::find(wanted.begin(), wanted.end(), engine) == wanted.end()) continue;   // left out
      const bool ran = std::any_of(sr.runs.begin(), sr.runs.end(), [&](const RunRecord& r) { return r.engine == engine; });
      if (ran) continue;
      EngineInfo info;
      info.name = engine;
      info.version = old.value("engine_version", json_text_default());
      info.precision = old.value("precision", json_text_default()) == "float32" ? Precision::Float32 : Precision::Float64;
      RunRecord r = unsupported_run(sr.scene, info, {});
      r.reason = find_engine(engine) == nullptr
                     ? "not run: no engine named " + engine + " is loaded in this physval (a plugin not found or not given)"
                     : "not run: the scenario's own engines list leaves " + engine + " out";
      r.checks.push_back(baseline_status_failure(before, r.reason));
      sr.runs.push_back(std::move(r));
      ++added;
    }
  }
  return added;
}

}  // namespace physval
