// `physval sweep`: one scenario over several step sizes and, where an engine declares
// them, solver settings, on every engine that can model it. Each point pairs speed
// (wall seconds per simulated second, median of several repetitions) with error
// against one common reference (position, energy, contact timing); per engine and
// setting, the observed order of convergence is the least-squares slope of
// log(position error) against log(dt).
#pragma once

#include <filesystem>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "physval/core/engine.hpp"
#include "physval/core/scene.hpp"
#include "physval/validation/run_record.hpp"
#include "physval/validation/suite.hpp"

namespace physval {

struct SweepOptions {
  std::vector<double> dts = {1.0 / 30, 1.0 / 60, 1.0 / 120, 1.0 / 240, 1.0 / 480, 1.0 / 960};
  std::vector<std::string> engines;   // empty: every engine that can model the scene
  int repetitions = 5;                // timed repetitions per point (the median is reported)
  bool settings = true;               // also vary solver settings (see sweep_variants)
  // A repetition runs the scene again and again until this much time was spent in
  // step(), so fast scenes are timed over more than a few microseconds.
  double min_seconds_per_repetition = 0.02;
  double spread_warning = 0.25;       // warn when (max - min) / median exceeds this
  double timeout_seconds = 0.0;       // the first (isolated) run of a point; 0: none. A
                                      // point that times out is an error, not timed.
  std::string reference_cache;        // reference cache folder (reference_cache.hpp); empty: none
  std::size_t jobs = 1;               // error runs at once; timing runs always one at a time
  // `--shard I/N`: only the points the split (shard.hpp) gives part I of N. Every shard
  // builds the same reference (from the cache when the shards share one).
  std::size_t shard_index = 0;
  std::size_t shard_count = 1;
};

// One engine configuration of the sweep: option overrides for the engine's table.
struct SweepVariant {
  std::string label;                  // "integrator=rk4 collision=exact"; "" when nothing is swept
  EngineOptions options;              // applied over the scene's own options
};

// The solver settings swept on an engine, from the options it declares (never from
// its name): a string option `integrator` over all its choices; every other string
// option with choices named `collision` or ending in `_mode` over its other choices
// (with the integrator at its base value); an integer option ending in `_iterations`
// at half, once and twice its base value. The base value is the scene's own setting,
// else the declared default. Without such options (or with settings = false): one
// variant, the engine's settings as the scene gives them.
std::vector<SweepVariant> sweep_variants(const EngineInfo& info, const Scene& scene, bool settings);

struct SweepPoint {
  std::string engine;
  std::string setting;                // SweepVariant::label
  double dt = 0.0;                    // s
  long steps = 0;
  double simulated_seconds = 0.0;     // steps x dt
  RunStatus status = RunStatus::Ok;
  std::string reason;
  int repetitions = 0;                // timed repetitions completed
  long runs = 0;                      // runs behind the timing (repetitions x inner runs)
  // Wall seconds spent in step() per simulated second, over the repetitions.
  double wall_per_sim_median = 0.0;
  double wall_per_sim_min = 0.0;
  double wall_per_sim_max = 0.0;
  double spread = 0.0;                // (max - min) / median
  bool spread_warning = false;        // spread > SweepOptions::spread_warning
  // Error against the reference; nullopt when it cannot be measured.
  std::optional<double> position_error;       // max position divergence, m
  std::optional<double> energy_error;         // energy divergence (relative)
  std::optional<double> contact_time_error;   // s
  bool pareto = false;                // on the speed-against-position-error front
  // The checks this point's run failed that `run` would fail on (the scenario's [expect],
  // not a recorded known failure): what each is called ("expect.final.a.velocity").
  std::vector<std::string> checks_failed;
  std::vector<Setting> engine_settings;   // every setting the engine ran with (its own report)
};

// A least-squares line through (log10 x, log10 y) of the points with x, y > 0.
struct LogLogFit {
  std::optional<double> slope;        // nullopt: fewer than two usable points
  double intercept = 0.0;             // log10 y at log10 x = 0
  double r_squared = 0.0;
  int points = 0;
};
LogLogFit fit_log_log(const std::vector<double>& x, const std::vector<std::optional<double>>& y);

// The observed order of convergence of one engine and setting.
struct ConvergenceOrder {
  std::string engine;
  std::string setting;
  LogLogFit position;                 // slope of log(position error) vs log(dt)
  LogLogFit energy;                   // the same for the energy error
  // Every measured position error is below 1e-9 m: the engine is exact here up to
  // round-off, and the slope means nothing.
  bool exact_to_round_off = false;
  std::vector<Setting> engine_settings;   // as the engine reported them (from its first run)
};

struct SweepResult {
  std::string scenario;
  double duration = 0.0;              // simulated seconds per run
  // The one reference every point is held against.
  bool reference_available = false;
  bool reference_converged = false;
  double reference_dt = 0.0;
  std::string reference_reason;
  std::vector<SweepPoint> points;     // engine, then setting, then dt (coarse to fine)
  std::vector<ConvergenceOrder> orders;   // one per engine and setting, in point order
  std::vector<std::string> notes;     // engines left out and why, timing warnings
  // A shard's sweep.json "shard" block: every point of the whole sweep with its shard,
  // and this shard's points' indices in it (`physval merge` puts them back in order);
  // null for a whole sweep.
  nlohmann::json shard;
};

// Runs the sweep. Engines that cannot model the scene are left out with a note.
// Never throws for an engine's failure: the point records status and reason.
SweepResult run_sweep(const Scene& scene, const SweepOptions& options, const Progress& progress = {});

// The note on points timed with a spread above `threshold`; "" when there are none.
std::string sweep_spread_note(const std::vector<SweepPoint>& points, double threshold);

// Fills result.orders and each point's pareto flag from the points (run_sweep calls it).
void analyse_sweep(SweepResult& result);

// "1/60" when dt is the reciprocal of a whole number (to 1e-9), else "0.0125".
std::string dt_label(double dt);

// The table on the terminal: one row per point, then the orders of convergence.
// Settings show in short form ("rk4, exact"; "4 velocity + 3 position iterations");
// the CSV and JSON keep the full "key=value" labels.
void print_sweep_table(std::ostream& os, const SweepResult& result);

std::string sweep_to_csv(const SweepResult& result);
nlohmann::json sweep_to_json(const SweepResult& result);

// DIR/sweep.csv, DIR/sweep.json, DIR/speed_vs_error.png, DIR/error_vs_dt.png.
// Throws plot::PlotError when the plots cannot be drawn (after writing CSV and JSON).
void write_sweep(const std::filesystem::path& dir, const SweepResult& result);

// Why a sweep measured nothing: no point ran whole (every one diverged, failed or timed
// out), so no speed and no error figure exists; empty when at least one point did. Such
// a sweep exits 1 (`physval sweep`, `physval merge` of sweep shards): it printed a table
// of statuses and exited 0 before, as if the figures had been measured.
std::string sweep_measured_nothing(const SweepResult& result);

// The engines of which no point (step size and setting) ran whole and held the
// scenario's expectations: every one diverged, failed, or missed an [expect] that `run`
// enforces. One setting (explicit Euler) that is never right is a finding of the sweep,
// not a failure, when another setting of the engine is right somewhere.
// Empty when each engine has such a point. Such a sweep exits 1 (`physval sweep`,
// `physval merge` of sweep shards): an engine that misses at every step size exited 0
// before, its table reading "ok" with an error figure.
std::string sweep_engines_never_right(const SweepResult& result);

}  // namespace physval
