// StepTiming (step_timing.hpp): which steps the stepping loop reads the clock around, and
// the time inside step() it reports for a whole loop from the steps it timed.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "../src/step_timing.hpp"

namespace physval {
namespace {

// A loop of n steps, step k taking step_of(k) ticks inside step() and harness_of(k) after
// it, driven through StepTiming as runner.cpp drives it. Returns {estimated, exact} ticks
// inside step(), and counts the steps timed.
template <class Step, class Harness>
std::pair<double, double> loop(long n, Step step_of, Harness harness_of, long& timed_steps) {
  StepTiming timing;
  StepTicks total = 0, exact = 0;
  timed_steps = 0;
  for (long k = 1; k <= n; ++k) {
    const StepTicks s = step_of(k), h = harness_of(k);
    if (timing.timed(k)) {
      timing.add(s, s + h);
      ++timed_steps;
    }
    total += s + h;
    exact += s;
  }
  return {timing.step_ticks(total), static_cast<double>(exact)};
}

TEST(StepTiming, ShortRunsAndLongStepsAreTimedEveryStep) {
  long timed = 0;
  auto [est, exact] = loop(StepTiming::kExactSteps, [](long k) { return StepTicks(100 + k % 7); },
                           [](long) { return StepTicks(50); }, timed);
  EXPECT_EQ(timed, StepTiming::kExactSteps);
  EXPECT_EQ(est, exact);
  // Long steps (each with its checks at least kLongTicks): every one timed, the sum exact.
  std::tie(est, exact) = loop(100000, [](long k) { return StepTiming::kLongTicks + StepTicks(k % 1000); },
                              [](long k) { return StepTicks(k % 3 == 0 ? 5000 : 10); }, timed);
  EXPECT_EQ(timed, 100000);
  EXPECT_EQ(est, exact);
}

TEST(StepTiming, ShortStepsAreDrawnAboutOneInSixteenAndTheSumIsEstimatedClosely) {
  long timed = 0;
  // Cheap steps whose cost varies (a period of 7, and every 100th step three times dearer)
  // beside a harness with its own period (a sample every 10 steps).
  auto step = [](long k) { return StepTicks(k % 100 == 0 ? 300 : 90 + 3 * (k % 7)); };
  auto harness = [](long k) { return StepTicks(k % 10 == 0 ? 400 : 60); };
  const long n = 2'000'000;
  const auto [est, exact] = loop(n, step, harness, timed);
  const double drawn = static_cast<double>(timed - StepTiming::kExactSteps) / static_cast<double>(n - StepTiming::kExactSteps);
  EXPECT_NEAR(drawn, 1.0 / 16.0, 0.002);
  EXPECT_NEAR(est / exact, 1.0, 0.005) << est << " vs " << exact;
}

// A run whose steps turn long part way (a gas that starts colliding): timed every step
// from soon after, so the estimate stays close even though the two phases' splits differ.
TEST(StepTiming, AStretchOfLongStepsIsTimedFromSoonAfterItStarts) {
  long timed = 0;
  const long n = 400'000, turn = 200'000;
  auto step = [&](long k) { return StepTicks(k < turn ? 100 : 20000); };
  auto harness = [&](long k) { return StepTicks(k < turn ? 60 : 100); };
  const auto [est, exact] = loop(n, step, harness, timed);
  EXPECT_GE(timed, n - turn);
  EXPECT_NEAR(est / exact, 1.0, 0.002) << est << " vs " << exact;
}

TEST(StepTiming, NothingTimedGivesZeroAndTheRestIsSplitInTheTimedRatio) {
  StepTiming none;
  EXPECT_EQ(none.step_ticks(0), 0.0);
  EXPECT_EQ(none.step_ticks(1000), 0.0);   // no timed step: no share to split by
  StepTiming one;
  ASSERT_TRUE(one.timed(1));
  one.add(30, 40);
  EXPECT_EQ(one.step_ticks(40), 30.0);
  EXPECT_EQ(one.step_ticks(80), 60.0);   // the untimed 40 ticks in the timed step's ratio
}

}  // namespace
}  // namespace physval
