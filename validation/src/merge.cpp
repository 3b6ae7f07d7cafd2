#include "physval/validation/merge.hpp"

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <stdexcept>

#include "physval/validation/gate.hpp"
#include "physval/validation/plot.hpp"
#include "physval/validation/report.hpp"
#include "physval/validation/results_json.hpp"
#include "physval/validation/sweep.hpp"
#include "physval/validation/sweep_shard.hpp"

namespace physval {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

constexpr int kExitBadInput = 2;

// A refusal: the message says which folder and why.
struct Refused : std::runtime_error {
  using std::runtime_error::runtime_error;
};

json read_json(const fs::path& file) {
  std::ifstream in(file);
  if (!in) throw Refused(file.string() + ": cannot read it");
  try {
    return json::parse(in);
  } catch (const std::exception& e) {
    throw Refused(file.string() + ": not JSON: " + e.what());
  }
}

// What differs between two shards' build blocks, in words.
std::string build_difference(const json& a, const json& b) {
  if (!a.is_object() || !b.is_object()) return "one was written by a physval that does not record its build";
  if (a.value("executable", "") != b.value("executable", "")) return "another physval executable";
  if (a.value("engines", json()) != b.value("engines", json())) {
    auto list = [](const json& engines) {
      std::string text;
      for (const json& e : engines) text += (text.empty() ? "" : ", ") + e.value("name", "?") + " " + e.value("version", "?");
      return text;
    };
    return "engines " + list(a.value("engines", json::array())) + " against " + list(b.value("engines", json::array()));
  }
  return "another plugin library";
}

struct Part {
  std::string dir;
  json doc;
};

// Reads DIR/<name> of every folder and checks that they are the N parts of one job:
// the same physval version and shard block (apart from the index), each index once.
// Returns the parts ordered by index.
std::vector<Part> read_parts(const std::vector<std::string>& dirs, const std::string& name, const char* kind) {
  std::vector<Part> parts;
  for (const std::string& d : dirs) {
    const fs::path file = fs::path(d) / name;
    if (!fs::exists(file)) throw Refused(d + ": no " + name + " here (every folder must be one " + kind + " shard's --out)");
    json doc = read_json(file);
    if (!doc.contains("shard") || !doc["shard"].is_object() || !doc["shard"].contains("index") ||
        !doc["shard"].contains("count")) {
      throw Refused(file.string() + ": not a shard's output (it was not written with --shard I/N)");
    }
    parts.push_back({d, std::move(doc)});
  }
  const json& first = parts.front().doc;
  const std::string version = first.value("physval_version", first["context"].value("physval_version", ""));
  const std::size_t count = first["shard"]["count"].get<std::size_t>();
  json same = first["shard"];
  same.erase("index");
  same.erase("mine");   // a sweep shard's own points
  std::map<std::size_t, std::string> seen;
  for (const Part& p : parts) {
    const std::string v = p.doc.value("physval_version", p.doc["context"].value("physval_version", ""));
    if (v != version) {
      throw Refused(p.dir + " was written by physval " + v + ", " + parts.front().dir + " by physval " + version +
                    ": shards must come from one physval version");
    }
    json other = p.doc["shard"];
    const std::size_t index = other["index"].get<std::size_t>();
    other.erase("index");
    other.erase("mine");
    if (other["count"] != same["count"]) {
      throw Refused(p.dir + " is shard " + std::to_string(index) + "/" + other["count"].dump() + ", " +
                    parts.front().dir + " one of " + std::to_string(count) + ": the shards of one job share N");
    }
    if (other != same) {
      std::string what = "options";
      // The build first: another engine set also changes the split's costs.
      for (const char* key : {"build", "command", "options", "scenarios", "scenario", "points"}) {
        if (other.value(key, json()) != same.value(key, json())) {
          const std::string k = key;
          what = k == "scenarios" || k == "scenario" ? "scenario set (names or file contents)"
                 : k == "command"                    ? "command (run against gate)"
                 : k == "build" ? "build (physval executable, engines and their versions, or plugin libraries: " +
                                      build_difference(other.value(key, json()), same.value(key, json())) + ")"
                                : k;
          break;
        }
      }
      throw Refused(p.dir + " and " + parts.front().dir + " ran with a different " + what +
                    ": they are not shards of one job");
    }
    if (index >= count) throw Refused(p.dir + ": shard index " + std::to_string(index) + " is not below N = " + std::to_string(count));
    if (auto [it, fresh] = seen.emplace(index, p.dir); !fresh) {
      throw Refused("shard " + std::to_string(index) + "/" + std::to_string(count) + " given twice: " + it->second + " and " + p.dir);
    }
  }
  std::string missing;
  for (std::size_t i = 0; i < count; ++i) {
    if (!seen.count(i)) missing += (missing.empty() ? "" : ", ") + std::to_string(i);
  }
  if (!missing.empty()) {
    throw Refused("missing shard(s) " + missing + " of " + std::to_string(count) + " (got " + std::to_string(parts.size()) +
                  " folder(s)): nothing merged");
  }
  std::sort(parts.begin(), parts.end(), [](const Part& a, const Part& b) {
    return a.doc["shard"]["index"].get<std::size_t>() < b.doc["shard"]["index"].get<std::size_t>();
  });
  return parts;
}

RunStatus status_from_name(const std::string& s) {
  if (s == "ok") return RunStatus::Ok;
  if (s == "diverged") return RunStatus::Diverged;
  if (s == "unsupported") return RunStatus::Unsupported;
  return RunStatus::Error;
}

int merge_suite(const MergeOptions& options, std::ostream& out, std::ostream& err) {
  const std::vector<Part> parts = read_parts(options.dirs, "results.json", "run/gate");
  const json& shard = parts.front().doc["shard"];

  // Each part holds exactly the scenarios the split gave it, whole.
  std::map<std::string, std::size_t> owner;
  std::map<std::string, std::vector<std::string>> engines_of;   // the engines the split gave each scenario a run of
  for (const json& s : shard["scenarios"]) {
    owner[s["name"].get<std::string>()] = s["shard"].get<std::size_t>();
    if (s.contains("engines") && s["engines"].is_array()) {
      for (const json& e : s["engines"]) engines_of[s["name"].get<std::string>()].push_back(e.get<std::string>());
    }
  }
  std::map<std::string, json> runs, references, comparisons;   // scenario -> its entries, in run order
  for (const Part& p : parts) {
    const std::size_t index = p.doc["shard"]["index"].get<std::size_t>();
    std::set<std::string> present;
    for (const char* key : {"runs", "references", "comparisons"}) {
      for (const json& entry : p.doc.at(key)) {
        const std::string scenario = entry.at("scenario").get<std::string>();
        auto it = owner.find(scenario);
        if (it == owner.end() || it->second != index) {
          throw Refused(p.dir + ": holds scenario " + scenario + ", which the split does not give to shard " +
                        std::to_string(index));
        }
        present.insert(scenario);
        auto& bucket = std::string(key) == "runs" ? runs : std::string(key) == "references" ? references : comparisons;
        if (!bucket.count(scenario)) bucket[scenario] = json::array();
        bucket[scenario].push_back(entry);
      }
    }
    for (const auto& [scenario, i] : owner) {
      if (i == index && !references.count(scenario)) {
        throw Refused(p.dir + ": scenario " + scenario + " of shard " + std::to_string(index) + " is missing from it");
      }
      // Every engine the shard ran the scenario on has its run (a results.json that lost
      // one, edited or cut, would merge into a suite one engine short, and pass).
      if (i == index) {
        for (const std::string& engine : engines_of[scenario]) {
          const json& list = runs.count(scenario) ? runs[scenario] : json::array();
          const bool has = std::any_of(list.begin(), list.end(), [&](const json& r) { return r.value("engine", "") == engine; });
          if (!has) {
            throw Refused(p.dir + ": scenario " + scenario + " has no run of " + engine +
                          ", which the shard ran it on: the folder is not a whole shard output");
          }
        }
      }
      // Every scenario's series folder holds its scene.json: without it the folder was
      // copied in part (an artifact upload cut short), and the merge would lack its series.
      if (i == index && !fs::exists(fs::path(p.dir) / "series" / scenario / "scene.json")) {
        throw Refused(p.dir + ": the series of scenario " + scenario + " are missing (series/" + scenario +
                      "/scene.json): the folder is not a whole shard output");
      }
    }
  }

  json merged = {{"physval_version", parts.front().doc["physval_version"]},
                 {"context", parts.front().doc["context"]},
                 {"gates_enforced", parts.front().doc["gates_enforced"]},
                 {"runs", json::array()},
                 {"references", json::array()},
                 {"comparisons", json::array()}};
  for (const json& s : shard["scenarios"]) {
    const std::string name = s["name"].get<std::string>();
    for (auto [key, bucket] : {std::pair{"runs", &runs}, {"references", &references}, {"comparisons", &comparisons}}) {
      if (auto it = bucket->find(name); it != bucket->end()) {
        for (const json& e : it->second) merged[key].push_back(e);
      }
    }
  }

  const std::string out_dir = options.out.empty() ? "physval-out" : options.out;
  StagedOutputFolder staged(out_dir);
  for (const Part& p : parts) {
    const fs::path series = fs::path(p.dir) / "series";
    if (fs::is_directory(series)) {
      fs::create_directories(staged.staging() / "series");
      for (const fs::directory_entry& e : fs::directory_iterator(series)) {
        fs::copy(e.path(), staged.staging() / "series" / e.path().filename(), fs::copy_options::recursive);
      }
    }
  }
  write_file_atomically(staged.staging() / "results.json", merged.dump(2) + "\n");
  const SuiteResult result = suite_from_json(merged);
  bool plots_failed = false;
  if (options.report) {
    try {
      write_report(staged.staging());
    } catch (const plot::PlotError& e) {
      err << "physval: warning: the report's plots could not be drawn: " << e.what() << '\n';
      plots_failed = true;
    }
  }
  staged.commit();
  std::size_t run_count = 0, failed = 0;
  for (const ScenarioResult& sr : result.scenarios) {
    for (const RunRecord& r : sr.runs) {
      ++run_count;
      failed += r.passed() ? 0 : 1;
    }
  }
  out << "merged " << parts.size() << " shards: " << result.scenarios.size() << " scenarios, " << run_count << " runs, "
      << failed << " failed\n";
  out << "results: " << (fs::path(out_dir) / "results.json").string() << '\n';
  if (options.report && !plots_failed) out << "report: " << (fs::path(out_dir) / "report.html").string() << '\n';
  if (!options.junit.empty()) {
    write_file_atomically(options.junit, junit_xml(result));
    out << "junit: " << options.junit << '\n';
  }
  int status = suite_exit_status(result);
  if (result.gates_enforced && run_count > 0) {
    std::size_t checked = 0;
    for (const ScenarioResult& sr : result.scenarios) {
      for (const RunRecord& r : sr.runs) checked += r.status == RunStatus::Unsupported ? 0 : 1;
    }
    if (checked == 0) {
      err << "physval: gate: no engine ran any scenario (all unsupported or filtered out): nothing was checked\n";
      status = 1;
    }
  } else if (result.gates_enforced) {
    err << "physval: gate: no engine ran any scenario: nothing was checked\n";
    status = 1;
  }
  return status;
}

int merge_sweep(const MergeOptions& options, std::ostream& out, std::ostream& err) {
  const std::vector<Part> parts = read_parts(options.dirs, "sweep.json", "sweep");
  std::vector<json> docs;
  for (const Part& p : parts) docs.push_back(p.doc);
  SweepResult result = sweep_from_shards(docs);
  const std::string out_dir = options.out.empty() ? "physval-sweep" : options.out;
  out << "merged " << parts.size() << " sweep shards: " << result.points.size() << " points\n";
  print_sweep_table(out, result);
  try {
    write_sweep(out_dir, result);
  } catch (const plot::PlotError& e) {
    err << "physval: sweep.csv and sweep.json are written, but the plots could not be drawn: " << e.what() << '\n';
    return 1;
  }
  out << "sweep: " << (fs::path(out_dir) / "sweep.csv").string() << ", sweep.json, speed_vs_error.png, error_vs_dt.png in "
      << out_dir << '\n';
  if (const std::string nothing = sweep_measured_nothing(result); !nothing.empty()) {
    err << "physval: sweep measured nothing: " << nothing << '\n';
    return 1;
  }
  if (const std::string wrong = sweep_engines_never_right(result); !wrong.empty()) {
    err << "physval: sweep: an engine was right at no step size: " << wrong << '\n';
    return 1;
  }
  return 0;
}

}  // namespace

SuiteResult suite_from_json(const json& results) {
  SuiteResult result;
  result.gates_enforced = results.value("gates_enforced", false);
  std::map<std::string, std::size_t> index;
  auto scenario = [&](const std::string& name) -> ScenarioResult& {
    auto [it, fresh] = index.emplace(name, result.scenarios.size());
    if (fresh) {
      result.scenarios.emplace_back();
      result.scenarios.back().scene.name = name;
    }
    return result.scenarios[it->second];
  };
  for (const json& ref : results.value("references", json::array())) scenario(ref.at("scenario").get<std::string>());
  for (const json& r : results.value("runs", json::array())) {
    RunRecord run;
    run.scenario = r.at("scenario").get<std::string>();
    run.engine = r.at("engine").get<std::string>();
    run.engine_version = r.value("engine_version", "");
    run.status = status_from_name(r.at("status").get<std::string>());
    run.reason = r.value("reason", "");
    run.wall_seconds = r.value("wall_seconds", 0.0);
    run.known_divergence = r.value("known_divergence", false);   // a diverged run a gate accepts
    for (const json& c : r.value("checks", json::array())) {
      Check check;
      check.what = c.at("what").get<std::string>();
      check.limit = c.value("limit", 0.0);
      if (c.contains("value") && c["value"].is_number()) check.value = c["value"].get<double>();
      check.pass = c.value("pass", false);
      check.enforced = c.value("enforced", true);
      check.known_failure = c.value("known_failure", false);
      check.detail = c.value("detail", "");
      run.checks.push_back(std::move(check));
    }
    scenario(run.scenario).runs.push_back(std::move(run));
  }
  return result;
}

int merge_shards(const MergeOptions& options, std::ostream& out, std::ostream& err) {
  discard_earlier_junit(options.junit);   // a refused merge leaves no JUnit file, not the last one
  try {
    if (options.dirs.empty()) throw Refused("merge: no folders given");
    bool suite = false, sweep = false;
    for (const std::string& d : options.dirs) {
      if (!fs::is_directory(d)) throw Refused(d + ": no such folder");
      suite = suite || fs::exists(fs::path(d) / "results.json");
      sweep = sweep || fs::exists(fs::path(d) / "sweep.json");
    }
    if (suite && sweep) throw Refused("merge: some folders hold a suite's results.json, others a sweep.json: not one job");
    if (sweep) {
      if (!options.junit.empty() || options.report) throw Refused("merge: --junit and --report apply to run/gate shards, not sweeps");
      return merge_sweep(options, out, err);
    }
    return merge_suite(options, out, err);
  } catch (const Refused& e) {
    err << "physval: merge: " << e.what() << '\n';
    return kExitBadInput;
  } catch (const std::invalid_argument& e) {
    err << "physval: merge: " << e.what() << '\n';
    return kExitBadInput;
  } catch (const nlohmann::json::exception& e) {
    err << "physval: merge: a shard's JSON is not as physval writes it: " << e.what() << '\n';
    return kExitBadInput;
  }
}

}  // namespace physval
