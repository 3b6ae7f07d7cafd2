// Contact matching by pair and time: the indexed matcher in the comparator must give
// exactly what the plain all-against-all greedy scan gives (kept here as the oracle).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <optional>
#include <random>

#include "physval/validation/comparator.hpp"

namespace physval {
namespace {

struct OracleMatch {
  std::optional<double> max_error;
  int missed = 0;
  int extra = 0;
};

std::pair<std::string, std::string> ordered(const std::string& a, const std::string& b) {
  return a < b ? std::pair{a, b} : std::pair{b, a};
}

// The comparator's rule, written the slow obvious way: each reference contact, in
// order, takes the earliest unused run contact of its pair within the window; the scan
// of that pair stops at its first contact later than the window.
OracleMatch all_against_all(const std::vector<ContactRecord>& run, const std::vector<ContactRecord>& ref,
                            double window) {
  OracleMatch m;
  std::vector<bool> used(run.size(), false);
  for (const ContactRecord& r : ref) {
    std::optional<std::size_t> best;
    for (std::size_t j = 0; j < run.size(); ++j) {
      if (used[j] || ordered(run[j].a, run[j].b) != ordered(r.a, r.b)) continue;
      if (std::abs(run[j].time - r.time) <= window) {
        best = j;
        break;
      }
      if (run[j].time > r.time + window) break;
    }
    if (best) {
      used[*best] = true;
      m.max_error = std::max(m.max_error.value_or(0.0), std::abs(run[*best].time - r.time));
    } else {
      ++m.missed;
    }
  }
  m.extra = static_cast<int>(std::count(used.begin(), used.end(), false));
  return m;
}

RunRecord record_with(const std::string& engine, double dt, std::vector<ContactRecord> contacts) {
  RunRecord r;
  r.engine = engine;
  r.dt = dt;
  r.status = RunStatus::Ok;
  r.contacts = std::move(contacts);
  return r;
}

// Contacts among `bodies` bodies; times mostly increasing with some jitter so that a
// pair's contacts are sometimes out of order, as an event-driven engine can report them.
std::vector<ContactRecord> random_contacts(std::mt19937& rng, int count, int bodies, double span, double jitter) {
  std::uniform_int_distribution<int> body(0, bodies - 1);
  std::uniform_real_distribution<double> noise(-jitter, jitter);
  std::vector<ContactRecord> out;
  for (int k = 0; k < count; ++k) {
    int a = body(rng), b = body(rng);
    if (a == b) b = (b + 1) % bodies;
    const double t = span * k / count + noise(rng);
    // Both name orders occur: a pair is the same whichever body is named first.
    if (k % 3 == 0) std::swap(a, b);
    out.push_back({std::string(1, 'c').append(std::to_string(a)), std::string(1, 'c').append(std::to_string(b)), t, k});
  }
  return out;
}

TEST(ContactMatching, IndexedMatcherEqualsAllAgainstAllOnRandomContacts) {
  std::mt19937 rng(20261123);
  Scene scene;
  scene.name = "contacts";
  scene.dt = 0.01;
  int checked_with_misses = 0;
  for (int trial = 0; trial < 60; ++trial) {
    const int bodies = 2 + trial % 7;
    const double jitter = (trial % 4) * 0.03;
    const std::vector<ContactRecord> a = random_contacts(rng, 30 + trial * 3, bodies, 5.0, jitter);
    const std::vector<ContactRecord> b = random_contacts(rng, 25 + trial * 3, bodies, 5.0, jitter);
    const double dt = 0.002 * (1 + trial % 5);
    const PairComparison pc = compare_pair(record_with("x", dt, a), record_with("y", dt, b), scene);
    const OracleMatch want = all_against_all(b, a, std::max(5.0 * dt, 0.05));
    ASSERT_EQ(pc.metrics.at("missed_contacts"), std::optional<double>(want.missed)) << "trial " << trial;
    ASSERT_EQ(pc.metrics.at("extra_contacts"), std::optional<double>(want.extra)) << "trial " << trial;
    ASSERT_EQ(pc.metrics.at("contact_time_error"), want.max_error) << "trial " << trial;
    if (want.missed > 0 && want.max_error) ++checked_with_misses;
  }
  EXPECT_GT(checked_with_misses, 10);   // the trials exercise both matches and misses
}

// The pair ids remember the last few (a, b) met, and a list that does not go back and
// forth stops looking at them after its first 256 contacts: long lists of each kind (two
// or three pairs alternating, pi_billiard's; a gas of many pairs; one that turns from the
// first kind to the second after the trial) match as the oracle does.
TEST(ContactMatching, LongListsOfFewAndOfManyPairsMatchAsAllAgainstAll) {
  std::mt19937 rng(20261124);
  Scene scene;
  scene.name = "contacts";
  scene.dt = 0.01;
  const double dt = 0.002;
  std::uniform_real_distribution<double> noise(-0.04, 0.04);
  auto alternating = [&](int count, int pairs, int swap_every) {
    const char* names[4][2] = {{"light", "heavy"}, {"light", "wall"}, {"heavy", "wall"}, {"light", "floor"}};
    std::vector<ContactRecord> out;
    for (int k = 0; k < count; ++k) {
      const auto& n = names[k % pairs];
      const bool swap = swap_every > 0 && k % swap_every == 0;
      out.push_back({swap ? n[1] : n[0], swap ? n[0] : n[1], 20.0 * k / count + noise(rng), k});
    }
    return out;
  };
  int missed = 0, matched_pairs = 0;
  for (int trial = 0; trial < 12; ++trial) {
    std::vector<ContactRecord> a, b;
    if (trial % 3 == 0) {
      a = alternating(900 + trial, 2 + trial % 3, trial % 2 == 0 ? 0 : 7);
      b = alternating(880, 2 + trial % 3, 5);
    } else if (trial % 3 == 1) {
      a = random_contacts(rng, 700, 60, 20.0, 0.04);
      b = random_contacts(rng, 650, 60, 20.0, 0.04);
    } else {
      a = alternating(300, 2, 0);
      b = alternating(290, 2, 3);
      const std::vector<ContactRecord> ga = random_contacts(rng, 500, 40, 20.0, 0.04), gb = random_contacts(rng, 480, 40, 20.0, 0.04);
      a.insert(a.end(), ga.begin(), ga.end());
      b.insert(b.end(), gb.begin(), gb.end());
    }
    const PairComparison pc = compare_pair(record_with("x", dt, a), record_with("y", dt, b), scene);
    const OracleMatch want = all_against_all(b, a, std::max(5.0 * dt, 0.05));
    ASSERT_EQ(pc.metrics.at("missed_contacts"), std::optional<double>(want.missed)) << "trial " << trial;
    ASSERT_EQ(pc.metrics.at("extra_contacts"), std::optional<double>(want.extra)) << "trial " << trial;
    ASSERT_EQ(pc.metrics.at("contact_time_error"), want.max_error) << "trial " << trial;
    missed += want.missed;
    matched_pairs += static_cast<int>(b.size()) - want.missed;
  }
  EXPECT_GT(missed, 0);
  EXPECT_GT(matched_pairs, 0);
}

TEST(ContactMatching, MatchesSamePairWhicheverNameComesFirstAndCountsTheRest) {
  Scene scene;
  scene.name = "contacts";
  scene.dt = 0.01;
  const RunRecord ref = record_with("ref", 0.01, {{"a", "b", 1.0, 100}, {"b", "c", 2.0, 200}, {"a", "b", 3.0, 300}});
  const RunRecord run =
      record_with("run", 0.01, {{"b", "a", 1.02, 102}, {"a", "c", 2.0, 200}, {"a", "b", 3.0, 300}, {"a", "b", 4.0, 400}});
  const PairComparison pc = compare_pair(ref, run, scene);
  EXPECT_EQ(pc.metrics.at("missed_contacts"), std::optional<double>(1));   // (b,c) at 2.0
  EXPECT_EQ(pc.metrics.at("extra_contacts"), std::optional<double>(2));    // (a,c) and (a,b) at 4.0
  ASSERT_TRUE(pc.metrics.at("contact_time_error"));
  EXPECT_NEAR(*pc.metrics.at("contact_time_error"), 0.02, 1e-12);
}

}  // namespace
}  // namespace physval
