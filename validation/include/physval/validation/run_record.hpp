// What one run of one scenario on one engine produced: sampled states, the contacts
// it reported, its settings, its timing, and (once compared) its metrics and checks.
#pragma once

#include <cstddef>
#include <cstdint>
#include <algorithm>
#include <cstring>
#include <initializer_list>
#include <memory>
#include <new>
#include <span>
#include <type_traits>
#include <utility>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "physval/core/engine.hpp"

namespace physval {

enum class RunStatus { Ok, Diverged, Unsupported, Error };
const char* run_status_name(RunStatus s);

// Aggregates computed from a state sample and the scene (never from what an engine
// claims): see conservation.hpp.
struct Totals {
  double kinetic = 0.0;
  double potential = 0.0;      // uniform field + Newtonian
  Vec2 momentum;               // sum m v of moving bodies
  double angular_momentum = 0.0;   // about the origin: sum m (x cross v)
  double energy() const { return kinetic + potential; }
};

// What a series keeps of a body at a sample: where it is and whether it exists (the
// comparisons, containment and plots read nothing else; totals are computed from the
// full state when the sample is taken). 24 bytes, against BodyState's 56: a run's
// series is what the harness holds per body, hundreds of samples of every body.
// The padding is a member, always zero, so that a block of samples is sent and cached as
// its bytes (run_record_io.cpp) without indeterminate ones.
struct SampleState {
  Vec2 position;
  bool alive = true;
  std::uint8_t pad[7] = {};
  SampleState() = default;
  SampleState(Vec2 p, bool a) : position(p), alive(a) {}
  SampleState(const BodyState& s) : position(s.position), alive(s.alive) {}   // NOLINT: implicit on purpose
};
static_assert(sizeof(SampleState) == 24 && std::is_trivially_copyable_v<SampleState>);

// One sample of every body, made from the engine's full states.
struct SampleRow : std::vector<SampleState> {
  using std::vector<SampleState>::vector;
  SampleRow() = default;
  SampleRow(const std::vector<BodyState>& states) : std::vector<SampleState>(states.begin(), states.end()) {}   // NOLINT
  // Back to BodyState (velocities and angles zero: a sample does not keep them).
  operator std::vector<BodyState>() const {
    std::vector<BodyState> out(size());
    for (std::size_t i = 0; i < size(); ++i) {
      out[i].position = (*this)[i].position;
      out[i].alive = (*this)[i].alive;
    }
    return out;
  }
};

// A run's samples in one block, row after row (row k: the states of every object at the
// k-th sample; rows grow when particles appear): one allocation a run instead of one a
// sample, sent between processes and cached as the block's bytes. rows[k] is a span.
class SampleRows {
 public:
  using Row = std::span<SampleState>;
  using ConstRow = std::span<const SampleState>;

  SampleRows() = default;
  SampleRows(std::initializer_list<SampleRow> rows) {
    for (const SampleRow& r : rows) push_back(ConstRow(r.data(), r.size()));
  }
  SampleRows(const SampleRows& o) : start_(o.start_) { copy_from(o.data_, o.samples()); }
  SampleRows(SampleRows&& o) noexcept
      : data_(std::exchange(o.data_, nullptr)), capacity_(std::exchange(o.capacity_, 0)), start_(std::move(o.start_)) {
    o.start_.assign(1, 0);
  }
  SampleRows& operator=(const SampleRows& o) {
    if (this != &o) {
      SampleRows copy(o);
      swap(copy);
    }
    return *this;
  }
  SampleRows& operator=(SampleRows&& o) noexcept {
    SampleRows moved(std::move(o));
    swap(moved);
    return *this;
  }
  ~SampleRows() { release(); }
  void swap(SampleRows& o) noexcept {
    std::swap(data_, o.data_);
    std::swap(capacity_, o.capacity_);
    start_.swap(o.start_);
  }

  std::size_t size() const { return start_.size() - 1; }   // rows
  bool empty() const { return size() == 0; }
  std::size_t samples() const { return start_.back(); }    // states in all rows
  Row operator[](std::size_t k) { return {data_ + start_[k], start_[k + 1] - start_[k]}; }
  ConstRow operator[](std::size_t k) const { return {data_ + start_[k], start_[k + 1] - start_[k]}; }
  Row front() { return (*this)[0]; }
  ConstRow front() const { return (*this)[0]; }
  Row back() { return (*this)[size() - 1]; }
  ConstRow back() const { return (*this)[size() - 1]; }
  SampleState* data() { return data_; }
  const SampleState* data() const { return data_; }
  std::size_t row_start(std::size_t k) const { return start_[k]; }   // k <= size()

  // Room for `rows` more rows of `samples` states in all, made at once.
  void reserve(std::size_t rows, std::size_t samples) {
    start_.reserve(start_.size() + rows);
    if (this->samples() + samples > capacity_) grow_to(this->samples() + samples);
  }
  void push_back(ConstRow row) {
    const std::size_t n = samples();
    if (n + row.size() > capacity_) grow_to(std::max(n + row.size(), 2 * capacity_));
    if (!row.empty()) std::memcpy(static_cast<void*>(data_ + n), row.data(), row.size() * sizeof(SampleState));
    start_.push_back(n + row.size());
  }
  void push_back(const SampleRow& row) { push_back(ConstRow(row.data(), row.size())); }
  void push_back(std::initializer_list<SampleState> row) { push_back(ConstRow(row.begin(), row.size())); }
  void push_back(const std::vector<BodyState>& states) {
    const std::size_t n = samples();
    if (n + states.size() > capacity_) grow_to(std::max(n + states.size(), 2 * capacity_));
    for (std::size_t i = 0; i < states.size(); ++i) new (data_ + n + i) SampleState(states[i]);
    start_.push_back(n + states.size());
  }
  // Rows of the given sizes whose states the caller writes next (run_record_io: read into
  // place): the block for them, not initialised. Only on an empty SampleRows.
  SampleState* append_uninitialised(const std::vector<std::size_t>& sizes) {
    std::size_t n = samples();
    for (const std::size_t s : sizes) n += s;
    if (n > capacity_) grow_to(samples() == 0 ? n : std::max(n, 2 * capacity_));
    SampleState* out = data_ + samples();
    start_.reserve(start_.size() + sizes.size());
    for (const std::size_t s : sizes) start_.push_back(start_.back() + s);
    return out;
  }
  // The last row made longer by n states, likewise not initialised.
  SampleState* extend_last_row_uninitialised(std::size_t n) {
    const std::size_t have = samples();
    if (have + n > capacity_) grow_to(std::max(have + n, 2 * capacity_));
    start_.back() += n;
    return data_ + have;
  }
  void clear() { start_.assign(1, 0); }

  class const_iterator {
   public:
    using value_type = ConstRow;
    using difference_type = std::ptrdiff_t;
    const_iterator() = default;
    const_iterator(const SampleRows* rows, std::size_t k) : rows_(rows), k_(k) {}
    ConstRow operator*() const { return (*rows_)[k_]; }
    const_iterator& operator++() {
      ++k_;
      return *this;
    }
    const_iterator operator++(int) {
      const_iterator old = *this;
      ++k_;
      return old;
    }
    bool operator==(const const_iterator& o) const { return k_ == o.k_; }

   private:
    const SampleRows* rows_ = nullptr;
    std::size_t k_ = 0;
  };
  const_iterator begin() const { return {this, 0}; }
  const_iterator end() const { return {this, size()}; }

 private:
  void grow_to(std::size_t capacity) {
    auto* bigger = std::allocator<SampleState>().allocate(capacity);
    if (samples() > 0) std::memcpy(static_cast<void*>(bigger), data_, samples() * sizeof(SampleState));
    release();
    data_ = bigger;
    capacity_ = capacity;
  }
  void copy_from(const SampleState* from, std::size_t n) {
    if (n == 0) return;
    data_ = std::allocator<SampleState>().allocate(n);
    capacity_ = n;
    std::memcpy(static_cast<void*>(data_), from, n * sizeof(SampleState));
  }
  void release() {
    if (data_ != nullptr) std::allocator<SampleState>().deallocate(data_, capacity_);
    data_ = nullptr;
    capacity_ = 0;
  }

  SampleState* data_ = nullptr;
  std::size_t capacity_ = 0;
  std::vector<std::size_t> start_ = {0};   // row k is [start_[k], start_[k + 1])
};

// States sampled at regular times; states[k][i] is body i at time[k].
struct Series {
  std::vector<double> time;
  std::vector<Totals> totals;
  SampleRows states;
};

struct ContactRecord {
  std::string a;       // names (bodies, walls, boxes, surfaces)
  std::string b;
  double time = 0.0;
  long step = 0;       // the step the engine reported it in (1-based)
};

// Apex and orbit probes, sampled every step for the bodies [expect] names.
struct Probe {
  std::string body;
  double max_y = -1e300;
  double max_y_time = 0.0;
  // For each `[expect] apex` of this body with a `time`: its threshold (height - tolerance)
  // and the time of the first sampled local maximum of y at or above it (NaN: none). A
  // periodic motion reaches equal maxima again and again; its apex time is the first.
  std::vector<std::pair<double, double>> apex_first;
  double revolutions = 0.0;       // accumulated angle / 2 pi around `around`
  double last_full_rev_time = 0.0;   // time of the last completed revolution
  int full_revolutions = 0;
};

struct Check {
  std::string what;     // "energy_drift", "expect.final.a.velocity", ...
  double limit = 0.0;
  std::optional<double> value;   // nullopt: could not be measured (counts as failed)
  bool pass = false;
  bool enforced = true; // false: reported only (a gate limit during `run`)
  // An expectation the engine misses, accepted up to a recorded bound
  // ([gate.<engine>] known_failures): `limit` is then that bound, not the tolerance.
  bool known_failure = false;
  // For an expectation: what was measured and what was expected, in the scene's units
  // ("measured [1.0, 0.0] m/s, expected [1.5, 0.0] m/s"), for people reading a miss.
  std::string detail;
};

using Metrics = std::map<std::string, std::optional<double>>;

// Containment, measured by the runner after every engine step (not only at samples):
// see containment.hpp and the README ("Metrics").
struct ContainmentRecord {
  bool measured = false;                    // false: the run took no step (or predates it)
  double max_penetration = 0.0;             // m, deepest overlap after any step
  std::optional<double> max_penetration_time;   // s, when it was deepest (nullopt: never > 0)
  std::string max_penetration_what;         // "a / b", "ball / wall 'floor'"
  std::optional<int> escaped_bodies;        // nullopt: no barrier any scene body collides with
  std::optional<double> first_escape_time;  // s, the end of the step the first escape happened in
  std::string first_escape;                 // "ball through wall 'left'"
  // The scene bodies counted in escaped_bodies (indices), so that a pass judged later
  // (below) counts each body once.
  std::vector<std::uint32_t> escaped_list;
  // Passes between two moving scene bodies too shallow for an escape by themselves: apart
  // at both ends of a step, each on one straight flight at an unchanged velocity (nothing
  // was exchanged in it), their straight relative path overlapping by `depth` m (more
  // than a slop of kGrazeSlop x the smaller radius). The comparator calls such a pass an
  // escape when the converged reference has a contact of that pair in that step (within a
  // step either side): the engine skipped an impact the reference makes (README
  // "Metrics", escaped_bodies). At most kMaxGrazes are kept (the first ones); the passes
  // found past them are counted in grazes_dropped (with the first one's time), and the
  // comparator does not let such a run be ok on the kept ones alone (a skipped impact among
  // the dropped ones could not be judged).
  struct Graze {
    std::uint32_t a = 0, b = 0;   // scene body indices; b past the bodies: a wall, box or surface (containment.hpp)
    double time = 0.0;            // s, the end of the step
    double step = 0.0;            // s, its length
    double depth = 0.0;           // m, the straight relative path's deepest overlap
  };
  static constexpr double kGrazeSlop = 0.02;
  static constexpr std::size_t kMaxGrazes = 10000;
  std::vector<Graze> grazes;
  std::uint64_t grazes_dropped = 0;                 // found past kMaxGrazes, not kept
  std::optional<double> first_dropped_graze_time;   // s, the end of that one's step
  // Set by the comparator (not written anywhere): the escapes it judged, the record's and
  // the skipped impacts together (the run's escaped_bodies metric), and the first's time.
  std::optional<int> judged_escaped_bodies;
  std::optional<double> judged_first_escape_time;
};

// The reference engine's (core's) run held against its own converged reference
// (comparator.cpp, judge_against_own_reference; README "The reference"): where core claims
// exact paths at the scene's step (exact impacts, velocity Verlet or RK4, no force that
// varies within a step), its run must meet the reference within the per-body limit the
// reference's two runs are held to, or it is `diverged`. Written to results.json as
// `reference_check` for the reference engine's runs only.
struct ReferenceCheck {
  bool applies = false;          // the run is the reference engine's
  bool judged = false;           // held to the reference (else `note` says why not)
  std::string note;              // why not judged, or what was measured
  std::optional<double> ratio;   // worst |x - x_ref| / limit_i over samples and scene bodies
  std::optional<double> error;   // m, the difference at the worst sample
  std::optional<double> limit;   // m, that body's limit
  std::optional<double> time;    // s, the worst sample's time
  std::string body;              // the worst body
};

struct RunRecord {
  std::string scenario;
  std::string engine;
  std::string engine_version;
  std::string precision;
  double dt = 0.0;
  long steps = 0;            // steps actually taken
  long steps_planned = 0;
  RunStatus status = RunStatus::Ok;
  std::string reason;
  std::optional<double> diverged_at;   // simulated time, s
  // Diverged only by bodies passing through barriers, no more of them than the scene's
  // [gate.<engine>] known_failures accepts (escaped_bodies = N): still `diverged`, but it
  // passes (a known failure, like a known expectation miss).
  bool known_divergence = false;
  // A bound system that came apart (energy went from below 0 to above it and stayed there,
  // in a scene that conserves or only loses energy, with no uniform field): E(end) / |E(0)|.
  // Not in results.json; the reason says it, --record-known writes it as energy_crossed_zero.
  std::optional<double> unbound_ratio;
  // A bound Newtonian system whose settled energy (the median of one of the run's quarters)
  // moved from E(0) by more than a quarter of its binding energy (conservation.hpp,
  // binding_energy): the largest |E_settled - E(0)| / E_b of the four. Not in results.json; the reason says it,
  // --record-known writes it as binding_energy_change.
  std::optional<double> binding_change;
  double wall_seconds = 0.0;           // time inside step() only
  double load_seconds = 0.0;
  // Harness accounting (`physval run --overhead FILE`; not in results.json):
  // CPU inside step(), estimated as the stepping loop's thread CPU x wall_seconds / the
  // loop's wall time (equal to wall_seconds on an idle core, less when the run shared it);
  double step_cpu_seconds = 0.0;
  // the engine child's whole CPU, fork to exit (wait4's rusage; 0 for an in-process run);
  double child_cpu_seconds = 0.0;
  // the parent thread's CPU for the run (fork, reading the record; in-process: all of it).
  double parent_cpu_seconds = 0.0;
  std::vector<Setting> settings;
  ReferenceCheck reference_check;   // set by the comparator (reference engine's runs only)
  std::vector<std::string> limits_hit;
  std::vector<BodyMeta> bodies;
  std::vector<ContactRecord> contacts;
  std::vector<Probe> probes;
  Series series;
  std::vector<BodyState> final_states;
  ContainmentRecord containment;

  Metrics metrics;
  std::vector<Check> checks;
  bool passed() const;   // status ok (or unsupported) and every enforced check passes
};

}  // namespace physval
