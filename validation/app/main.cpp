// physval: the command. Exit status 0: everything ran and held; 1: a gate or an
// expectation failed, or an engine diverged; 2: bad input or usage, nothing was run.
#include <sys/resource.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <iostream>
#include <memory>
#include <set>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "physval/adapters/plugin_engine.hpp"
#include "physval/adapters/registry.hpp"
#include "physval/validation/console_table.hpp"
#include "physval/validation/gate.hpp"
#include "physval/validation/known_failures.hpp"
#include "physval/validation/plot.hpp"
#include "physval/validation/report.hpp"
#include "physval/validation/results_json.hpp"
#include "physval/validation/scenario_loader.hpp"
#include "physval/validation/suite.hpp"
#include "physval/validation/reference_cache.hpp"
#include "physval/validation/scheduler.hpp"
#include "physval/validation/merge.hpp"
#include "physval/validation/series_file.hpp"
#include "physval/validation/shard.hpp"
#include "physval/validation/sweep.hpp"

namespace {

using namespace physval;

constexpr int kExitFailed = 1;
constexpr int kExitBadInput = 2;

// "1/60", "0.01", "1e-3" -> seconds; nullopt when not a positive finite number.
std::optional<double> parse_seconds(const std::string& text) {
  try {
    const auto slash = text.find('/');
    std::size_t used = 0;
    double v;
    if (slash != std::string::npos) {
      const double num = std::stod(text.substr(0, slash), &used);
      if (used != slash) return std::nullopt;
      const std::string den_text = text.substr(slash + 1);
      const double den = std::stod(den_text, &used);
      if (used != den_text.size()) return std::nullopt;
      v = num / den;
    } else {
      v = std::stod(text, &used);
      if (used != text.size()) return std::nullopt;
    }
    if (!std::isfinite(v) || v <= 0.0) return std::nullopt;
    return v;
  } catch (...) {
    return std::nullopt;
  }
}

struct CommonOptions {
  std::vector<std::string> paths;
  std::vector<std::string> engines;
  std::string out = "physval-out";
  std::string overhead;   // --overhead FILE
  std::string dt;
  std::string duration;
  bool no_isolate = false;
  double timeout = 0.0;
  bool quiet = false;
  int jobs = 0;   // 0: every core
  std::string cache;
  bool no_cache = false;
  std::string shard;   // "I/N"
  double max_memory_mb = 0.0;
  std::vector<std::string> plugins;
  bool series_csv = false;   // --series-csv
};

// --max-memory MB: the limit the memory estimate of each scene is held to (0: half of the
// machine's). NaN and negative values are bad input.
bool apply_max_memory(double mb) {
  if (!(mb >= 0.0) || !std::isfinite(mb)) return false;
  if (mb > 0.0) set_memory_limit_bytes(mb * 1e6);
  return true;
}

// --plugin LIB.so (repeatable): an engine plugin, a path or a name searched in PHYSVAL_PLUGIN_PATH.
void add_plugin_option(CLI::App* cmd, std::vector<std::string>& plugins) {
  cmd->add_option("--plugin", plugins,
                  "load an engine plugin (a shared library, see physval/plugin.h): a path, or a name searched "
                  "in PHYSVAL_PLUGIN_PATH; repeatable")
      ->allow_extra_args(false);
}

void add_common(CLI::App* cmd, CommonOptions& o) {
  cmd->add_option("PATH", o.paths, "scenario files (*.toml) or folders of them (searched recursively)")->required();
  // One value per --engines (split at commas), so `--engines core FILE` leaves FILE to PATH.
  cmd->add_option("--engines", o.engines, "engines to run, comma-separated (default: all)")
      ->delimiter(',')
      ->allow_extra_args(false);
  cmd->add_option("--out", o.out, "output folder for results.json and series/")->capture_default_str();
  cmd->add_option("--dt", o.dt, "override every scenario's step, seconds (1/60 or 0.0166)");
  cmd->add_option("--duration", o.duration, "override every scenario's duration, seconds");
  cmd->add_flag("--no-isolate", o.no_isolate, "run engines in this process (debugging; a crash then ends physval)");
  cmd->add_option("--timeout", o.timeout,
                  "seconds an engine run and the reference it is compared with may take together; the run is "
                  "stopped when they exceed it (0: no limit)");
  cmd->add_flag("--quiet", o.quiet, "print only the summary line");
  cmd->add_flag("--series-csv", o.series_csv,
                "write each run's time series as CSV text (series/<scenario>/<engine>.csv) instead of the "
                "binary .bin files (`physval series-csv DIR` converts those later)");
  cmd->add_option("--cache", o.cache, "reference cache folder (default $XDG_CACHE_HOME/physval/references or ~/.cache/...)");
  cmd->add_flag("--no-cache", o.no_cache, "compute every reference, read and write no cache");
  cmd->add_option("--max-memory", o.max_memory_mb,
                  "MB a scene's estimated memory may reach (default 0: half of this machine's memory)");
  cmd->add_option("--overhead", o.overhead,
                  "also write here (JSON) the harness's CPU per scenario next to the engines' stepping "
                  "(scripts/overhead.sh prints it as a table)");
  add_plugin_option(cmd, o.plugins);
  cmd->add_option("-j,--jobs", o.jobs, "references and engine runs at once (default 0: every core); results do not depend on it");
  cmd->add_option("--shard", o.shard,
                  "run only part I of N (0 <= I < N) of the scenarios, split by estimated cost; "
                  "join the parts' --out folders with `physval merge`");
}

int bad_input(const std::string& message) {
  std::cerr << "physval: " << message << '\n';
  return kExitBadInput;
}

// Loads and validates; prints every error. Returns the scenes or nullopt.
std::optional<std::vector<Scene>> load_or_report(const std::vector<std::string>& paths) {
  SuiteLoad load = load_suite(paths);
  for (const Diagnostic& d : load.errors) std::cerr << d.str() << '\n';
  if (!load.errors.empty()) {
    std::cerr << "physval: " << load.errors.size() << " error" << (load.errors.size() == 1 ? "" : "s")
              << " in the scenario files; nothing was run\n";
    return std::nullopt;
  }
  return std::move(load.scenes);
}

Progress terminal_progress(bool quiet) {
  if (quiet || ::isatty(2) == 0) return {};
  return [](const std::string& line) { std::cerr << "\r\033[K  " << line.substr(0, 90) << std::flush; };
}

// The suite's progress: "[n/N] scenario: engine" rewritten in place on a terminal; without
// one (a CI log) one plain line per scenario as it starts, "[n/N] scenario".
Progress suite_progress(bool quiet, std::size_t scenario_count) {
  if (quiet) return {};
  const bool terminal = ::isatty(2) != 0;
  // Lines arrive as "scenario: engine", in any order under -j: a scenario counts when
  // its first run starts.
  auto seen = std::make_shared<std::set<std::string>>();
  return [terminal, scenario_count, seen](const std::string& line) {
    const std::string scenario = line.substr(0, line.find(':'));
    if (seen->insert(scenario).second && !terminal) {
      std::cerr << '[' << seen->size() << '/' << scenario_count << "] " << scenario << '\n' << std::flush;
    }
    if (terminal) {
      std::cerr << "\r\033[K  [" << seen->size() << '/' << scenario_count << "] running " << line.substr(0, 80)
                << std::flush;
    }
  };
}

void end_progress(const Progress& progress) {
  if (progress) std::cerr << "\r\033[K" << std::flush;
}

// `gate --record-known F`: writes each engine's misses, F x the measured error, into
// the scenario files' [gate.<engine>] known_failures.
void record_known_failures(const SuiteResult& result, double margin) {
  for (const ScenarioResult& sr : result.scenarios) {
    const std::string& file = sr.scene.source_file;
    std::ifstream in(file);
    if (!in) throw std::runtime_error(file + ": cannot read it to record known failures");
    std::stringstream text;
    text << in.rdbuf();
    const std::string before = text.str();
    const std::string after = rewrite_known_failures(before, measured_known_failures(sr, margin));
    if (after == before) continue;
    write_file_atomically(file, after);
    std::cout << "known failures recorded: " << file << '\n';
  }
}

int run_or_gate(const CommonOptions& o, bool gate, const std::string& junit, const std::string& baseline_path,
                double baseline_factor, bool report, double record_known = 0.0) {
  discard_earlier_junit(junit);   // a run that stops before writing it leaves none, not the last one
  RunOptions options;
  if (!o.dt.empty()) {
    options.dt = parse_seconds(o.dt);
    if (!options.dt) return bad_input("--dt: expected a positive number of seconds such as 1/60 or 0.01, got \"" + o.dt + "\"");
  }
  if (!o.duration.empty()) {
    options.duration = parse_seconds(o.duration);
    if (!options.duration) return bad_input("--duration: expected a positive number of seconds, got \"" + o.duration + "\"");
  }
  for (const std::string& e : o.engines) {
    if (find_engine(e) == nullptr) return bad_input("--engines: no engine named \"" + e + "\" (see `physval engines`)");
  }
  if (!(o.timeout >= 0.0)) return bad_input("--timeout must be a number >= 0");   // also NaN
  if (o.jobs < 0) return bad_input("--jobs must be >= 0 (0: every core)");
  std::optional<ShardSpec> shard;
  if (!o.shard.empty()) {
    std::string error;
    shard = parse_shard(o.shard, error);
    if (!shard) return bad_input(error);
  }
  options.isolate = !o.no_isolate;
  if (!o.no_cache) options.reference_cache = o.cache.empty() ? default_reference_cache_dir().string() : o.cache;
  options.timeout_seconds = o.timeout;
  nlohmann::json baseline;
  if (!baseline_path.empty()) {
    std::ifstream in(baseline_path);
    if (!in) return bad_input(baseline_path + ": cannot open the baseline");
    try {
      baseline = nlohmann::json::parse(in);
    } catch (const std::exception& e) {
      return bad_input(baseline_path + ": not a results.json: " + e.what());
    }
    if (!baseline.contains("runs")) return bad_input(baseline_path + ": not a results.json (no \"runs\")");
  }
  if (!(baseline_factor >= 1.0) || !std::isfinite(baseline_factor)) {
    return bad_input("--baseline-factor must be a finite number >= 1");   // NaN too
  }
  if (!apply_max_memory(o.max_memory_mb)) return bad_input("--max-memory must be a number of MB >= 0");
  auto scenes = load_or_report(o.paths);
  if (!scenes) return kExitBadInput;
  for (const Scene& s : *scenes) {
    const Scene effective = effective_scene(s, options);
    if (const std::string too_many = scene_steps_error(effective); !too_many.empty()) {
      return bad_input(s.source_file + ": with --duration/--dt: " + too_many);
    }
    if (options.dt || options.duration) {
      if (const std::string too_big = memory_bound_error(effective, engines_for(effective, o.engines).size());
          !too_big.empty()) {
        return bad_input(s.source_file + ": with --duration/--dt: the scene " + too_big + "; nothing was run");
      }
    }
  }
  nlohmann::json shard_block;
  if (shard) {
    // Every shard computes the same split from the whole suite; results.json records it
    // (with what the results depend on) so that `physval merge` can check the parts.
    std::vector<double> costs;
    std::vector<nlohmann::json> engine_lists;   // the engines each scenario gets a run of (unsupported included)
    for (const Scene& s : *scenes) {
      const Scene e = effective_scene(s, options);
      std::size_t runnable = 0;
      engine_lists.push_back(nlohmann::json::array());
      for (const EngineFactory* f : engines_for(e, o.engines)) {
        runnable += unsupported_features(f->info, e).empty() ? 1 : 0;
        engine_lists.back().push_back(f->info.name);
      }
      costs.push_back(scenario_cost(e, runnable));
    }
    const std::vector<std::size_t> assigned = assign_shards(costs, shard->count);
    nlohmann::json list = nlohmann::json::array();
    std::vector<Scene> mine;
    double my_cost = 0.0, total_cost = 0.0;
    for (std::size_t i = 0; i < scenes->size(); ++i) {
      const Scene& s = (*scenes)[i];
      list.push_back({{"name", s.name},
                      {"file", file_fingerprint(s.source_file)},
                      {"shard", assigned[i]},
                      {"cost", costs[i]},
                      {"engines", engine_lists[i]}});
      total_cost += costs[i];
      if (assigned[i] == shard->index) {
        mine.push_back(s);
        my_cost += costs[i];
      }
    }
    nlohmann::json run_options = {
        {"engines", o.engines},
        {"plugins", o.plugins},
        {"dt", options.dt ? nlohmann::json(*options.dt) : nlohmann::json(nullptr)},
        {"duration", options.duration ? nlohmann::json(*options.duration) : nlohmann::json(nullptr)},
        {"timeout", o.timeout},
        {"isolate", options.isolate},
        {"baseline", baseline_path.empty() ? nlohmann::json(nullptr) : nlohmann::json(file_fingerprint(baseline_path))},
        {"baseline_factor", baseline.is_null() ? nlohmann::json(nullptr) : nlohmann::json(baseline_factor)}};
    shard_block = {{"index", shard->index},   {"count", shard->count},   {"command", gate ? "gate" : "run"},
                   {"options", run_options}, {"scenarios", list}, {"build", build_identity()}};
    std::cout << "shard " << shard->index << "/" << shard->count << ": " << mine.size() << " of " << scenes->size()
              << " scenarios (" << (total_cost > 0.0 ? static_cast<int>(100.0 * my_cost / total_cost + 0.5) : 0)
              << "% of the estimated cost)\n";
    *scenes = std::move(mine);
  }
  // --out is checked (and a staging folder made beside it) before anything runs.
  std::optional<StagedOutputFolder> out;
  try {
    out.emplace(o.out);
  } catch (const std::exception& e) {
    return bad_input("--out: " + std::string(e.what()) + "; nothing was run");
  }

  const Progress progress = terminal_progress(o.quiet);
  const std::size_t jobs = o.jobs > 0 ? static_cast<std::size_t>(o.jobs) : default_jobs();
  const bool no_scenes = scenes->empty();
  const Progress suite_line = suite_progress(o.quiet, scenes->size());
  SuiteResult result = run_suite(std::move(*scenes), o.engines, options, gate, suite_line, jobs);
  end_progress(progress);
  result.shard = shard_block;
  if (!baseline_path.empty()) {
    const int matched = apply_baseline(result, baseline, baseline_factor);
    if (const int missing = add_runs_missing_from_baseline(result, baseline, o.engines); missing > 0) {
      std::cout << "baseline: " << missing << " run(s) of the baseline not run now (an engine not loaded, or left out "
                << "by a scenario's engines list): failed\n";
    }
    std::cout << "baseline: " << matched << " runs matched in " << baseline_path << " (regression factor "
              << baseline_factor << ")\n";
    if (matched == 0) return bad_input(baseline_path + ": the baseline matches no run (scenario and engine): nothing compared");
  }
  if (record_known > 0.0) {
    try {
      record_known_failures(result, record_known);
    } catch (const std::exception& e) {
      std::cerr << "physval: " << e.what() << '\n';
      return kExitBadInput;
    }
  }
  if (gate && !(shard && no_scenes)) {   // a shard may be left without scenarios (N > suite)
    std::size_t checked = 0;
    for (const ScenarioResult& sr : result.scenarios) {
      for (const RunRecord& r : sr.runs) checked += r.status == RunStatus::Unsupported ? 0 : 1;
    }
    if (checked == 0) {
      std::cerr << "physval: gate: no engine ran any scenario (all unsupported or filtered out): nothing was checked\n";
      return 1;
    }
  }
  if (o.quiet) {
    std::ostringstream sink;
    print_suite_table(sink, result);
    const std::string text = sink.str();
    const auto last = text.rfind('\n', text.size() - 2);
    std::cout << text.substr(last == std::string::npos ? 0 : last + 1);
  } else {
    print_suite_table(std::cout, result);
  }
  try {
    // Everything goes into the staging folder, which then replaces --out whole.
    write_results(out->staging(), result, o.series_csv ? SeriesFormat::Csv : SeriesFormat::Binary);
    bool report_written = false;
    if (report) {
      try {
        write_report(out->staging(), progress);
        end_progress(progress);
        report_written = true;
      } catch (const plot::PlotError& e) {
        // The results and the page are written; only plots are missing. Not bad input.
        end_progress(progress);
        std::cerr << "physval: warning: the report's plots could not be drawn: " << e.what() << '\n';
      }
    }
    out->commit();
    std::cout << "results: " << (std::filesystem::path(o.out) / "results.json").string() << '\n';
    if (report_written) std::cout << "report: " << (std::filesystem::path(o.out) / "report.html").string() << '\n';
    if (!junit.empty()) {
      write_file_atomically(junit, junit_xml(result));
      std::cout << "junit: " << junit << '\n';
    }
    if (!o.overhead.empty()) {
      // Last, after everything else this command does: its CPU so far, children included.
      rusage self{}, children{};
      ::getrusage(RUSAGE_SELF, &self);
      ::getrusage(RUSAGE_CHILDREN, &children);
      auto seconds = [](const timeval& t) { return static_cast<double>(t.tv_sec) + 1e-6 * static_cast<double>(t.tv_usec); };
      const double cpu = seconds(self.ru_utime) + seconds(self.ru_stime) + seconds(children.ru_utime) + seconds(children.ru_stime);
      write_file_atomically(o.overhead, overhead_json(result, cpu).dump(2) + "\n");
    }
  } catch (const std::exception& e) {
    std::cerr << "physval: could not write the results: " << e.what() << '\n';
    return kExitBadInput;
  }
  return suite_exit_status(result);
}

void print_engines(bool as_json) {
  if (as_json) {
    nlohmann::json out = nlohmann::json::array();
    for (const EngineFactory& f : engine_registry()) {
      nlohmann::json features = nlohmann::json::array();
      for (Feature ft : f.info.features) features.push_back(feature_name(ft));
      nlohmann::json options = nlohmann::json::array();
      for (const OptionSpec& s : f.info.options) {
        const bool numeric = s.default_value.index() == 1 || s.default_value.index() == 2;
        options.push_back({{"key", s.key}, {"type", option_type_name(s.default_value)},
                           {"default", option_value_to_string(s.default_value)}, {"choices", s.choices},
                           {"range", numeric ? nlohmann::json(s.range.describe()) : nlohmann::json(nullptr)},
                           {"doc", s.doc}});
      }
      out.push_back({{"name", f.info.name}, {"version", f.info.version}, {"precision", precision_name(f.info.precision)},
                     {"summary", f.info.summary}, {"features", features}, {"options", options},
                     {"reference", !f.reference_options.empty()}});
    }
    std::cout << out.dump(2) << '\n';
    return;
  }
  for (const EngineFactory& f : engine_registry()) {
    std::cout << f.info.name << "  " << f.info.version << "  " << precision_name(f.info.precision)
              << (f.reference_options.empty() ? "" : "  (reference engine)") << "\n  " << f.info.summary << "\n  models:";
    std::size_t col = 10;
    for (Feature ft : f.info.features) {
      const std::string name = feature_name(ft);
      if (col + name.size() + 1 > 96) {
        std::cout << "\n         ";
        col = 9;
      }
      std::cout << ' ' << name;
      col += name.size() + 1;
    }
    std::vector<std::string> lacks;
    for (int i = 0; i < static_cast<int>(Feature::Count); ++i) {
      const auto ft = static_cast<Feature>(i);
      if (std::find(f.info.features.begin(), f.info.features.end(), ft) == f.info.features.end()) {
        lacks.push_back(feature_name(ft));
      }
    }
    if (!lacks.empty()) {
      std::cout << "\n  cannot model:";
      for (const std::string& l : lacks) std::cout << ' ' << l;
    }
    std::cout << "\n  options ([" << f.info.name << "] in a scenario):\n";
    for (const OptionSpec& s : f.info.options) {
      std::cout << "    " << s.key << " = " << option_value_to_string(s.default_value) << "  (" << option_type_name(s.default_value);
      if (!s.choices.empty()) {
        std::cout << ":";
        for (std::size_t i = 0; i < s.choices.size(); ++i) std::cout << (i ? "|" : " ") << s.choices[i];
      }
      if (s.default_value.index() == 1 || s.default_value.index() == 2) std::cout << ", " << s.range.describe();
      std::cout << ")  " << s.doc << '\n';
    }
    std::cout << '\n';
  }
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"physval: runs 2-D physics scenarios on several engines and says where they disagree and by how much"};
  app.require_subcommand(1);
  app.footer(
      "Exit status: 0 everything ran and every enforced check held; 1 a gate or an expectation failed,\n"
      "or an engine diverged; 2 bad input or usage (nothing was run). README.md documents every\n"
      "scenario key, metric and option.");
  app.set_version_flag("--version", std::string("physval ") + PHYSVAL_VERSION);

  CommonOptions run_opts;
  bool run_report = false;
  auto* run = app.add_subcommand("run", "run scenarios on every engine that can model them and compare the runs");
  add_common(run, run_opts);
  run->add_flag("--report", run_report, "also write DIR/report.html with plots");

  CommonOptions gate_opts;
  std::string junit, baseline;
  double baseline_factor = 2.0;
  auto* gate = app.add_subcommand("gate", "`run` with the scenarios' [gate] limits enforced (exit 1 on any failure)");
  add_common(gate, gate_opts);
  gate->add_option("--junit", junit, "write JUnit XML here: one test case per scenario and engine");
  gate->add_option("--baseline", baseline, "an earlier results.json: fail on a regression beyond --baseline-factor");
  gate->add_option("--baseline-factor", baseline_factor, "how much worse than the baseline an error metric may get")
      ->capture_default_str();
  double record_known = 0.0;
  gate->add_option("--record-known", record_known,
                   "write every expectation an engine misses into the scenario file's [gate.<engine>] "
                   "known_failures, with this factor (>= 1) times the measured error as its bound");
  bool gate_report = false;
  gate->add_flag("--report", gate_report, "also write DIR/report.html with plots");

  std::vector<std::string> check_paths;
  double check_max_memory = 0.0;
  auto* check = app.add_subcommand("check", "parse and validate scenario files; runs nothing");
  check->add_option("PATH", check_paths, "scenario files or folders")->required();
  check->add_option("--max-memory", check_max_memory,
                    "MB a scene's estimated memory may reach (default 0: half of this machine's memory)");
  std::vector<std::string> check_plugins;
  add_plugin_option(check, check_plugins);

  std::string sweep_scenario, sweep_out = "physval-sweep", sweep_duration;
  std::vector<std::string> sweep_dts, sweep_engines;
  int sweep_repetitions = 5;
  bool sweep_no_settings = false, sweep_quiet = false;
  auto* sweep = app.add_subcommand("sweep", "speed against error: one scenario over step sizes and solver settings");
  sweep->add_option("SCENARIO", sweep_scenario, "one scenario file")->required();
  sweep->add_option("--dt", sweep_dts, "step sizes, comma-separated (default 1/30,1/60,1/120,1/240,1/480,1/960)")
      ->delimiter(',');
  sweep->add_option("--engines", sweep_engines, "engines to sweep, comma-separated (default: all that can)")
      ->delimiter(',')
      ->allow_extra_args(false);
  sweep->add_option("--out", sweep_out, "output folder: sweep.csv, sweep.json and the plots")->capture_default_str();
  sweep->add_option("--repetitions", sweep_repetitions, "timed repetitions per point (the median is reported)")
      ->capture_default_str();
  sweep->add_option("--duration", sweep_duration, "override the scenario's duration, seconds");
  sweep->add_flag("--no-settings", sweep_no_settings, "sweep step sizes only, each engine at its default settings");
  sweep->add_flag("--quiet", sweep_quiet, "no progress on the terminal");
  std::vector<std::string> sweep_plugins;
  add_plugin_option(sweep, sweep_plugins);
  double sweep_timeout = 0.0;
  std::string sweep_cache;
  bool sweep_no_cache = false;
  sweep->add_option("--cache", sweep_cache, "reference cache folder (default as for run)");
  sweep->add_flag("--no-cache", sweep_no_cache, "compute the reference, read and write no cache");
  int sweep_jobs = 0;
  sweep->add_option("-j,--jobs", sweep_jobs, "error runs at once (default 0: every core); timing runs are always alone");
  sweep->add_option("--timeout", sweep_timeout, "seconds a single measured run may take before it is stopped (0: no limit)");
  std::string sweep_shard;
  sweep->add_option("--shard", sweep_shard,
                    "sweep only part I of N (0 <= I < N) of the points, split by estimated cost; "
                    "join the parts' --out folders with `physval merge`");

  std::string report_dir;
  auto* report = app.add_subcommand("report", "write report.html with plots for a results folder of `run` or `gate`");
  report->add_option("DIR", report_dir, "the folder holding results.json and series/")->required();

  std::vector<std::string> series_csv_dirs;
  auto* series_csv = app.add_subcommand(
      "series-csv", "write series/<scenario>/<engine>.csv beside each .bin series file of results folders");
  series_csv->add_option("DIR", series_csv_dirs, "output folders of `run`, `gate` or `merge`")->required();

  MergeOptions merge_opts;
  auto* merge = app.add_subcommand("merge", "join the output folders of `--shard I/N` runs (or sweeps) into one, as a single run writes it");
  merge->add_option("DIR", merge_opts.dirs, "every shard's output folder (each holds results.json or sweep.json)")->required();
  merge->add_option("--out", merge_opts.out, "the merged folder (default: physval-out, or physval-sweep for sweeps)");
  merge->add_option("--junit", merge_opts.junit, "also write JUnit XML here, as `gate --junit` does");
  merge->add_flag("--report", merge_opts.report, "also write OUT/report.html with plots");

  bool engines_json = false;
  auto* engines = app.add_subcommand("engines", "each engine, its version, precision, options and what it can model");
  engines->add_flag("--json", engines_json, "print as JSON");
  std::vector<std::string> engines_plugins;
  add_plugin_option(engines, engines_plugins);

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e);
    return code == 0 ? 0 : kExitBadInput;
  }

  // Plugins join the registry before any scenario is read: their option tables and
  // [gate.<plugin>] tables are then validated like a built-in engine's.
  try {
    const std::vector<std::string>& plugins = *check     ? check_plugins
                                              : *sweep   ? sweep_plugins
                                              : *engines ? engines_plugins
                                              : *gate    ? gate_opts.plugins
                                                         : run_opts.plugins;
    register_plugins(plugins);
  } catch (const std::exception& e) {
    return bad_input(std::string(e.what()) + "; nothing was run");
  }

  try {
    if (*check) {
      if (!apply_max_memory(check_max_memory)) return bad_input("--max-memory must be a number of MB >= 0");
      auto scenes = load_or_report(check_paths);
      if (!scenes) return kExitBadInput;
      for (const Scene& s : *scenes) {
        std::cout << "ok  " << s.name << "  (" << s.source_file << ": " << s.bodies.size() << (s.bodies.size() == 1 ? " body, " : " bodies, ")
                  << s.walls.size() + s.boxes.size() + s.surfaces.size() << " barriers, " << s.steps() << " steps)\n";
      }
      std::cout << scenes->size() << " scenario" << (scenes->size() == 1 ? "" : "s") << " valid\n";
      return 0;
    }
    if (*merge) return merge_shards(merge_opts, std::cout, std::cerr);
    if (*series_csv) {
      for (const std::string& d : series_csv_dirs) {
        if (!std::filesystem::exists(std::filesystem::path(d) / "results.json")) {
          return bad_input(d + ": no results.json here (not an output folder of `physval run`)");
        }
      }
      for (const std::string& d : series_csv_dirs) {
        const std::size_t n = convert_series_to_csv(d);
        std::cout << d << ": " << n << " series file" << (n == 1 ? "" : "s") << " written as CSV\n";
      }
      return 0;
    }
    if (*engines) {
      print_engines(engines_json);
      return 0;
    }
    if (*run) return run_or_gate(run_opts, false, "", "", 2.0, run_report);
    if (*gate) {
      if (record_known != 0.0 && !(record_known >= 1.0 && std::isfinite(record_known))) {
        return bad_input("--record-known: the margin must be a finite number >= 1");
      }
      return run_or_gate(gate_opts, true, junit, baseline, baseline_factor, gate_report, record_known);
    }
    if (*report) {
      if (!std::filesystem::exists(std::filesystem::path(report_dir) / "results.json")) {
        return bad_input(report_dir + ": no results.json here (write one with `physval run PATH --out " + report_dir + "`)");
      }
      const Progress progress = terminal_progress(false);
      try {
        write_report(report_dir, progress);
      } catch (const plot::PlotError& e) {
        end_progress(progress);
        std::cerr << "physval: the report's plots could not be drawn: " << e.what() << '\n';
        return kExitFailed;
      }
      end_progress(progress);
      std::cout << "report: " << (std::filesystem::path(report_dir) / "report.html").string() << '\n';
      return 0;
    }
    if (*sweep) {
      SweepOptions so;
      if (!sweep_dts.empty()) {
        so.dts.clear();
        for (const std::string& d : sweep_dts) {
          auto v = parse_seconds(d);
          if (!v) return bad_input("--dt: expected positive step sizes such as 1/60 or 0.01, got \"" + d + "\"");
          so.dts.push_back(*v);
        }
      }
      for (const std::string& e : sweep_engines) {
        if (find_engine(e) == nullptr) return bad_input("--engines: no engine named \"" + e + "\" (see `physval engines`)");
      }
      if (sweep_repetitions < 1) return bad_input("--repetitions must be >= 1");
      if (sweep_timeout < 0.0) return bad_input("--timeout must be >= 0");
      so.timeout_seconds = sweep_timeout;
      if (sweep_jobs < 0) return bad_input("--jobs must be >= 0 (0: every core)");
      so.jobs = sweep_jobs > 0 ? static_cast<std::size_t>(sweep_jobs) : default_jobs();
      if (!sweep_no_cache) so.reference_cache = sweep_cache.empty() ? default_reference_cache_dir().string() : sweep_cache;
      if (!sweep_shard.empty()) {
        std::string error;
        const std::optional<ShardSpec> spec = parse_shard(sweep_shard, error);
        if (!spec) return bad_input(error);
        so.shard_index = spec->index;
        so.shard_count = spec->count;
      }
      so.engines = sweep_engines;
      so.repetitions = sweep_repetitions;
      so.settings = !sweep_no_settings;
      if (std::filesystem::is_directory(sweep_scenario)) {
        return bad_input(sweep_scenario + ": is a folder; sweep takes one scenario file (*.toml)");
      }
      ScenarioLoad load = load_scenario_file(sweep_scenario);
      for (const Diagnostic& d : load.errors) std::cerr << d.str() << '\n';
      if (!load.scene) return kExitBadInput;
      if (!sweep_duration.empty()) {
        auto d = parse_seconds(sweep_duration);
        if (!d) return bad_input("--duration: expected a positive number of seconds, got \"" + sweep_duration + "\"");
        load.scene->duration = *d;
      }
      // Every point's run, and the reference at the finest step, within the steps a run
      // takes: beyond them Scene::steps() saturates, and a run would step a billion times
      // and then cover the rest of the duration in one last step of that length.
      for (const double dt : so.dts) {
        Scene at = *load.scene;
        at.dt = dt;
        if (const std::string too_many = scene_steps_error(at); !too_many.empty()) {
          return bad_input(sweep_scenario + ": at --dt " + dt_label(dt) + (sweep_duration.empty() ? "" : " with --duration") +
                           ": " + too_many);
        }
      }
      const Progress progress = terminal_progress(sweep_quiet);
      SweepResult result = run_sweep(*load.scene, so, progress);
      end_progress(progress);
      if (so.shard_count > 1) {
        // What the points depend on, for `physval merge` to compare the shards with.
        result.shard["command"] = "sweep";
        result.shard["build"] = build_identity();
        result.shard["scenario"] = {{"name", load.scene->name}, {"file", file_fingerprint(sweep_scenario)}};
        result.shard["options"] = {{"dt", so.dts},
                                   {"engines", so.engines},
                                   {"plugins", sweep_plugins},
                                   {"repetitions", so.repetitions},
                                   {"settings", so.settings},
                                   {"duration", load.scene->duration},
                                   {"timeout", so.timeout_seconds}};
        std::cout << "shard " << so.shard_index << "/" << so.shard_count << ": " << result.points.size() << " of "
                  << result.shard["points"].size() << " points\n";
      }
      if (result.points.empty() && so.shard_count <= 1) {
        // Nothing was measured (every engine left out): no table, and not a success.
        for (const std::string& note : result.notes) std::cerr << "physval: " << note << '\n';
        std::cerr << "physval: sweep measured nothing: no engine given can model " << load.scene->name << '\n';
        return kExitFailed;
      }
      print_sweep_table(std::cout, result);
      try {
        write_sweep(sweep_out, result);
      } catch (const plot::PlotError& e) {
        std::cerr << "physval: sweep.csv and sweep.json are written, but the plots could not be drawn: " << e.what()
                  << '\n';
        return kExitFailed;
      }
      std::cout << "sweep: " << (std::filesystem::path(sweep_out) / "sweep.csv").string() << ", sweep.json, "
                << "speed_vs_error.png, error_vs_dt.png in " << sweep_out << '\n';
      if (so.shard_count <= 1) {   // a shard's points may all fail; merge decides for the whole sweep
        if (const std::string nothing = sweep_measured_nothing(result); !nothing.empty()) {
          std::cerr << "physval: sweep measured nothing: " << nothing << '\n';
          return kExitFailed;
        }
        if (const std::string wrong = sweep_engines_never_right(result); !wrong.empty()) {
          std::cerr << "physval: sweep: an engine was right at no step size: " << wrong << '\n';
          return kExitFailed;
        }
      }
      return 0;
    }
  } catch (const std::exception& e) {
    std::cerr << "physval: " << e.what() << '\n';
    return kExitBadInput;
  }
  return kExitBadInput;
}
