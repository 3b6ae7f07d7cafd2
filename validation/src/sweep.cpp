// Running a sweep: which settings each engine is swept over, one reference for all
// points, and the timed repetitions behind each point. The analysis (orders of
// convergence, Pareto front) and the outputs live in sweep_output.cpp.
#include "physval/validation/sweep.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <exception>
#include <mutex>
#include <set>
#include <stdexcept>

#include "physval/validation/comparator.hpp"
#include "physval/validation/reference_cache.hpp"
#include "physval/validation/runner.hpp"
#include "physval/validation/scheduler.hpp"
#include "physval/validation/shard.hpp"

namespace physval {

namespace {

bool ends_with(const std::string& s, const std::string& suffix) {
  return s.size() >= suffix.size() && s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

// One swept option: its key, the value the other variants hold it at, the values it takes.
struct Axis {
  std::string key;
  OptionValue base;
  std::vector<OptionValue> values;
};

std::vector<Axis> sweep_axes(const EngineInfo& info, const Scene& scene) {
  const EngineOptions* given = nullptr;
  if (auto it = scene.engine_options.find(info.name); it != scene.engine_options.end()) {
    given = &it->second;
  }
  auto base_of = [&](const OptionSpec& spec) {
    if (given != nullptr) {
      if (auto it = given->find(spec.key); it != given->end()) return it->second;
    }
    return spec.default_value;
  };

  std::vector<Axis> axes;
  // The integrator first: its variants lead the list, the way users read it.
  for (const OptionSpec& spec : info.options) {
    if (spec.key == "integrator" && std::holds_alternative<std::string>(spec.default_value) &&
        !spec.choices.empty()) {
      Axis a{spec.key, base_of(spec), {}};
      for (const std::string& c : spec.choices) a.values.emplace_back(c);
      axes.push_back(std::move(a));
    }
  }
  for (const OptionSpec& spec : info.options) {
    const bool mode = spec.key == "collision" || ends_with(spec.key, "_mode");
    if (mode && std::holds_alternative<std::string>(spec.default_value) && !spec.choices.empty()) {
      Axis a{spec.key, base_of(spec), {}};
      for (const std::string& c : spec.choices) a.values.emplace_back(c);
      axes.push_back(std::move(a));
    }
  }
  for (const OptionSpec& spec : info.options) {
    if (ends_with(spec.key, "_iterations") && std::holds_alternative<std::int64_t>(spec.default_value)) {
      Axis a{spec.key, base_of(spec), {}};
      if (const auto* b = std::get_if<std::int64_t>(&a.base)) {
        const std::int64_t half = std::max<std::int64_t>(1, *b / 2);
        for (std::int64_t v : {half, *b, 2 * *b}) {
          if (a.values.empty() || std::get<std::int64_t>(a.values.back()) != v) a.values.emplace_back(v);
        }
      } else {
        a.values.push_back(a.base);   // a scene gave it another type: hold it as given
      }
      axes.push_back(std::move(a));
    }
  }
  return axes;
}

std::string format_seconds(double s) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3g", s);
  return buf;
}

std::optional<double> metric(const RunRecord& run, const char* name) {
  auto it = run.metrics.find(name);
  if (it == run.metrics.end() || !it->second || !std::isfinite(*it->second)) return std::nullopt;
  return it->second;
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 == 1 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

// Times one point: `repetitions` values of wall seconds per simulated second, each
// over as many runs as it takes to spend min_seconds in step() (bounded in real time,
// for scenes whose runs cost more outside step() than in it).
void time_point(SweepPoint& p, const Scene& scene, const EngineFactory& engine, const RunOptions& ro,
                const SweepOptions& opt) {
  using clock = std::chrono::steady_clock;
  const double min_seconds = std::max(0.0, opt.min_seconds_per_repetition);
  const auto real_limit = std::chrono::duration<double>(std::max(3.0 * min_seconds, 1e-3));
  constexpr long kMaxRunsPerRepetition = 10000;
  std::vector<double> values;
  for (int rep = 0; rep < std::max(1, opt.repetitions); ++rep) {
    double wall = 0.0;
    double simulated = 0.0;
    long runs = 0;
    const auto start = clock::now();
    do {
      const RunRecord r = run_engine(scene, engine, ro);
      if (r.status != RunStatus::Ok) {
        p.status = r.status;
        p.reason = "repetition " + std::to_string(rep + 1) + ": " + r.reason;
        return;
      }
      wall += r.wall_seconds;
      simulated += static_cast<double>(r.steps) * r.dt;
      ++runs;
    } while (wall < min_seconds && clock::now() - start < real_limit && runs < kMaxRunsPerRepetition);
    p.runs += runs;
    if (simulated > 0.0) values.push_back(wall / simulated);
    ++p.repetitions;
  }
  if (values.empty()) return;
  p.wall_per_sim_median = median(values);
  p.wall_per_sim_min = *std::min_element(values.begin(), values.end());
  p.wall_per_sim_max = *std::max_element(values.begin(), values.end());
  p.spread = p.wall_per_sim_median > 0.0 ? (p.wall_per_sim_max - p.wall_per_sim_min) / p.wall_per_sim_median : 0.0;
  p.spread_warning = p.spread > opt.spread_warning;
}

}  // namespace

std::string sweep_spread_note(const std::vector<SweepPoint>& points, double threshold) {
  const auto wide = std::count_if(points.begin(), points.end(), [](const SweepPoint& p) { return p.spread_warning; });
  if (wide == 0) return "";
  return std::to_string(wide) + " point(s) timed with a spread above " + std::to_string(static_cast<int>(threshold * 100)) +
         "% (marked !): a busy machine; rerun with more --repetitions";
}

std::vector<SweepVariant> sweep_variants(const EngineInfo& info, const Scene& scene, bool settings) {
  const std::vector<Axis> axes = settings ? sweep_axes(info, scene) : std::vector<Axis>{};
  if (axes.empty()) return {SweepVariant{}};

  // Every axis through all its values with the others at their base values; the base
  // variant appears once, where it first comes up.
  std::vector<SweepVariant> out;
  std::set<std::string> seen;
  for (std::size_t i = 0; i < axes.size(); ++i) {
    for (const OptionValue& v : axes[i].values) {
      SweepVariant variant;
      for (std::size_t j = 0; j < axes.size(); ++j) {
        const OptionValue& value = i == j ? v : axes[j].base;
        variant.options[axes[j].key] = value;
        if (!variant.label.empty()) variant.label += ' ';
        variant.label += axes[j].key + "=" + option_value_to_string(value);
      }
      if (seen.insert(variant.label).second) out.push_back(std::move(variant));
    }
  }
  return out;
}

SweepResult run_sweep(const Scene& scene, const SweepOptions& options, const Progress& progress) {
  auto say = [&](const std::string& line) {
    if (progress) progress(line);
  };

  std::vector<double> dts;
  for (double dt : options.dts) {
    if (!std::isfinite(dt) || dt <= 0.0) {
      throw std::invalid_argument("sweep: step sizes must be positive and finite (got " + format_seconds(dt) + ")");
    }
    dts.push_back(dt);
  }
  if (dts.empty()) throw std::invalid_argument("sweep: no step sizes given");
  std::sort(dts.begin(), dts.end(), std::greater<>());   // coarse to fine
  dts.erase(std::unique(dts.begin(), dts.end()), dts.end());

  SweepResult result;
  result.scenario = scene.name;
  result.duration = scene.duration;

  // Every run samples its states at the same times, multiples of the coarsest step
  // (about 400 samples), so each point is compared with the reference at the same
  // instants. Step sizes that divide each other (the default halvings) align exactly.
  Scene sampled = scene;
  if (sampled.sample_interval <= 0.0) {
    const double coarse = dts.front();
    const double per_sample = std::max(1.0, std::ceil(scene.duration / (400.0 * coarse) - 1e-9));
    sampled.sample_interval = per_sample * coarse;
  }

  // One reference for every point, at least as fine as the finest step swept.
  RunOptions ref_options;
  ref_options.dt = std::min(scene.dt, dts.back());
  ref_options.reference_cache = options.reference_cache;
  const Scene ref_scene = effective_scene(sampled, ref_options);
  say("sweep " + scene.name + ": building the reference (dt " + dt_label(ref_scene.dt) + ")");
  Reference reference;
  try {
    reference = cached_reference(ref_scene, ref_options).reference;
  } catch (const std::exception& e) {
    reference = Reference{};
    reference.reason = e.what();
  }
  result.reference_available = reference.available;
  result.reference_converged = reference.converged;
  result.reference_dt = reference.dt;
  result.reference_reason = reference.reason;
  if (!reference.available) {
    result.notes.push_back("no reference (" + (reference.reason.empty() ? std::string("unknown reason") : reference.reason) +
                           "): errors are not measured");
  } else if (!reference.converged) {
    result.notes.push_back("the reference did not converge (" + reference.reason +
                           "): errors against it are not measured (contact timing only against [expect] contacts)");
  }

  // What runs: engine x setting x dt.
  struct Plan {
    const EngineFactory* engine;
    std::vector<SweepVariant> variants;
  };
  std::vector<Plan> plans;
  std::size_t total = 0;
  std::vector<const EngineFactory*> engines;
  try {
    engines = engines_for(scene, options.engines);
  } catch (const std::exception& e) {
    result.notes.push_back(std::string("no engines: ") + e.what());
  }
  for (const EngineFactory* engine : engines) {
    const std::vector<std::string> missing = unsupported_features(engine->info, scene);
    if (!missing.empty()) {
      std::string list;
      for (const std::string& m : missing) list += (list.empty() ? "" : ", ") + m;
      result.notes.push_back(engine->info.name + " left out: it cannot model " + list);
      continue;
    }
    plans.push_back({engine, sweep_variants(engine->info, scene, options.settings)});
    total += plans.back().variants.size() * dts.size();
  }

  // Every point first gets its error run, in a child process (up to options.jobs at
  // once: no timing is taken from them); then the points are timed one after another in
  // this process, with nothing else of the sweep running, so timing runs never share a
  // core with each other or with the error runs.
  struct Work {
    const EngineFactory* engine;
    const SweepVariant* variant;
    double dt;
    Scene scene;
    RunOptions ro;
    std::string what;
  };
  std::vector<Work> work;
  for (const Plan& plan : plans) {
    for (const SweepVariant& variant : plan.variants) {
      Scene configured = sampled;
      for (const auto& [key, value] : variant.options) configured.engine_options[plan.engine->info.name][key] = value;
      for (double dt : dts) {
        RunOptions ro;
        ro.dt = dt;
        ro.isolate = false;   // timing runs in this process (no fork in the measurement)
        Scene run_scene = effective_scene(configured, ro);
        const std::string what = "[" + std::to_string(work.size() + 1) + "/" + std::to_string(total) + "] " +
                                 plan.engine->info.name + (variant.label.empty() ? "" : " " + variant.label) + " dt " +
                                 dt_label(dt) + ": ";
        work.push_back({plan.engine, &variant, dt, std::move(run_scene), ro, what});
      }
    }
  }
  std::vector<double> costs;
  for (const Work& w : work) costs.push_back(static_cast<double>(w.scene.steps()));
  std::vector<std::size_t> global_index(work.size());
  for (std::size_t i = 0; i < work.size(); ++i) global_index[i] = i;
  if (options.shard_count > 1) {
    // The points split by cost: steps times bodies (every point runs the same scene), so
    // step counts decide, and the timing runs (a fixed minimum each) roughly follow.
    const double bodies = static_cast<double>(std::max<std::size_t>(1, sampled.bodies.size()));
    std::vector<double> shard_costs;
    for (double c : costs) shard_costs.push_back(c * bodies);
    const std::vector<std::size_t> assigned = assign_shards(shard_costs, options.shard_count);
    nlohmann::json all = nlohmann::json::array(), mine = nlohmann::json::array();
    std::vector<Work> kept;
    std::vector<double> kept_costs;
    std::vector<std::size_t> kept_index;
    for (std::size_t i = 0; i < work.size(); ++i) {
      all.push_back({{"engine", work[i].engine->info.name}, {"setting", work[i].variant->label}, {"dt", work[i].dt},
                     {"shard", assigned[i]}});
      if (assigned[i] != options.shard_index) continue;
      kept.push_back(std::move(work[i]));
      kept_costs.push_back(costs[i]);
      kept_index.push_back(i);
    }
    work = std::move(kept);
    costs = std::move(kept_costs);
    global_index = std::move(kept_index);
    result.shard = {{"index", options.shard_index},
                    {"count", options.shard_count},
                    {"points", all},
                    {"spread_warning", options.spread_warning},
                    {"mine", nlohmann::json::array()}};
  }
  std::vector<SweepPoint> points(work.size());
  std::mutex say_mutex;
  run_tasks(costs, std::max<std::size_t>(1, options.jobs), [&](std::size_t i) {
    const Work& w = work[i];
    const EngineFactory& engine = *w.engine;
    SweepPoint& p = points[i];
    p.engine = engine.info.name;
    p.setting = w.variant->label;
    p.dt = w.dt;
    p.steps = w.scene.steps();
    p.simulated_seconds = static_cast<double>(p.steps) * w.dt;
    {
      const std::lock_guard<std::mutex> lock(say_mutex);
      say(w.what + "error run");
    }
    // The first run, in a child process, is the one measured for error: an engine
    // that crashes costs its point, not the sweep. Only a run that came back whole
    // is repeated in this process for timing (engines are deterministic). The
    // comparison may still find it diverged (energy running away).
    RunOptions isolated = w.ro;
    isolated.isolate = true;
    isolated.timeout_seconds = options.timeout_seconds;
    RunRecord first = run_engine_isolated(w.scene, engine, isolated);
    if (first.status == RunStatus::Ok) {
      try {
        compare_run(first, w.scene, reference, false);
        p.position_error = metric(first, "position_divergence");
        p.energy_error = metric(first, "energy_divergence");
        p.contact_time_error = metric(first, "contact_time_error");
        for (const Check& check : first.checks) {
          if (check.enforced && !check.pass) p.checks_failed.push_back(check.what);
        }
      } catch (const std::exception& e) {
        first.reason = std::string("comparison failed: ") + e.what();
      }
    }
    p.status = first.status;
    p.reason = first.reason;
    p.engine_settings = first.settings;
  });
  for (std::size_t i = 0; i < work.size(); ++i) {
    SweepPoint& p = points[i];
    const Work& w = work[i];
    if (p.status == RunStatus::Ok) {
      say(w.what + "timing");
      time_point(p, w.scene, *w.engine, w.ro, options);
    }
    std::string line = w.what;
    if (p.status != RunStatus::Ok) {
      line += std::string(run_status_name(p.status)) + " (" + p.reason + ")";
    } else {
      line += format_seconds(p.wall_per_sim_median) + " s per simulated s";
      if (p.position_error) line += ", position error " + format_seconds(*p.position_error) + " m";
      if (p.spread_warning) line += " (timing spread " + std::to_string(static_cast<int>(p.spread * 100)) + "%)";
    }
    say(line);
    if (!result.shard.is_null()) {
      nlohmann::json settings = nlohmann::json::array();   // in the engine's order
      for (const auto& [key, value] : p.engine_settings) settings.push_back({key, value});
      result.shard["mine"].push_back({{"index", global_index[i]}, {"engine_settings", settings}});
    }
    result.points.push_back(std::move(p));
  }

  if (!result.shard.is_null()) result.shard["notes"] = result.notes;   // the notes before the timing's own
  if (std::string note = sweep_spread_note(result.points, options.spread_warning); !note.empty()) {
    result.notes.push_back(std::move(note));
  }
  analyse_sweep(result);
  return result;
}

}  // namespace physval
