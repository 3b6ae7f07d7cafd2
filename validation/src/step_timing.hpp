// The stepping loop's clock (runner.cpp): which steps are timed, and the time inside
// step() over a whole loop from those that were (README "Harness overhead").
#pragma once

#include <chrono>
#include <cstdint>

#if defined(__x86_64__)
#include <x86intrin.h>
#endif

namespace physval {

// The clock around each step(): the time-stamp counter on x86-64 (a few ns to read,
// where the monotonic clock took 60; on a long run of a small scene two reads a step
// were a fifth of the harness), converted to seconds by the monotonic clock over the
// whole stepping loop; elsewhere the monotonic clock itself.
#if defined(__x86_64__)
using StepTicks = std::uint64_t;
inline StepTicks step_ticks() { return __rdtsc(); }
#else
using StepTicks = std::int64_t;
inline StepTicks step_ticks() { return std::chrono::steady_clock::now().time_since_epoch().count(); }
#endif

// Which steps' time inside step() is read (two counter reads around it, and one after the
// harness's work on it), the rest estimated (README "Harness overhead"): on orbit-sized
// steps (0.1 us) the two reads a step were half the harness's per-step cost. Every step is
// timed while the run is short (the first kExactSteps) and while the steps are long (a
// timed step and its checks took kLongTicks or more: reading then costs 2% at most; stays
// so until a timed one is short again); otherwise one step in 16, drawn at random (a fixed
// seed, so no period of the scene's can line up with it). The untimed steps' whole time is
// known (the loop's ticks less the timed steps' own), and is split between stepping and the
// harness in the ratio the randomly drawn steps had.
class StepTiming {
 public:
  static constexpr long kExactSteps = 256;
  static constexpr StepTicks kLongTicks = 4096;
  // Whether to read the clock around step k (1-based).
  bool timed(long k) {
    random_ = false;
    if (k <= kExactSteps || long_) return true;
    rng_ ^= rng_ << 13;
    rng_ ^= rng_ >> 7;
    rng_ ^= rng_ << 17;
    random_ = (rng_ & 15) == 0;
    return random_;
  }
  // A timed step: ticks inside step(), and from before it to after the checks that follow.
  void add(StepTicks in_step, StepTicks whole) {
    step_ += in_step;
    whole_ += whole;
    if (random_) {
      drawn_step_ += in_step;
      drawn_whole_ += whole;
    }
    long_ = whole >= kLongTicks;
  }
  // Ticks inside step() over a loop of `loop` ticks: the timed steps' own, and the rest of
  // the loop in the drawn steps' ratio (all timed steps' when none was drawn).
  double step_ticks(StepTicks loop) const {
    const double rest = loop > whole_ ? static_cast<double>(loop - whole_) : 0.0;
    const StepTicks num = drawn_whole_ > 0 ? drawn_step_ : step_;
    const StepTicks den = drawn_whole_ > 0 ? drawn_whole_ : whole_;
    const double share = den > 0 ? static_cast<double>(num) / static_cast<double>(den) : 0.0;
    return static_cast<double>(step_) + rest * share;
  }

 private:
  std::uint64_t rng_ = 0x9e3779b97f4a7c15ULL;
  bool random_ = false;
  bool long_ = false;
  StepTicks step_ = 0, whole_ = 0, drawn_step_ = 0, drawn_whole_ = 0;
};

}  // namespace physval
