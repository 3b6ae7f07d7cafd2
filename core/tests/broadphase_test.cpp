// The four broad phases report identical pair sets, and identical answers to queries
// after boxes grow mid-step, on random scenes of mixed sizes.
#include <gtest/gtest.h>

#include <algorithm>
#include <limits>
#include <random>

#include "physval/core/broadphase.hpp"

namespace physval {

namespace {

constexpr BroadPhaseKind kKinds[] = {BroadPhaseKind::AllPairs, BroadPhaseKind::Grid, BroadPhaseKind::MultiGrid,
                                     BroadPhaseKind::SortAndSweep};

double uniform(std::mt19937_64& rng, double lo, double hi) {
  return lo + (hi - lo) * static_cast<double>(rng() >> 11) * 0x1.0p-53;
}

std::vector<Aabb> random_boxes(std::mt19937_64& rng, int n, double world, double small, double big, double big_share) {
  std::vector<Aabb> boxes;
  for (int k = 0; k < n; ++k) {
    const double size = uniform(rng, 0.0, 1.0) < big_share ? uniform(rng, small, big) : uniform(rng, 0.0, small);
    const double x = uniform(rng, -world, world), y = uniform(rng, -world, world);
    const double w = size * uniform(rng, 0.2, 1.0), h = size * uniform(rng, 0.2, 1.0);
    boxes.push_back(make_aabb(x, y, x + w, y + h));
  }
  return boxes;
}

std::vector<BodyPair> sorted_pairs(BroadPhase& bp) {
  std::vector<BodyPair> out;
  bp.pairs(out);
  std::sort(out.begin(), out.end());
  return out;
}

}  // namespace

TEST(CoreBroadPhase, IdenticalPairSetsOnRandomScenes) {
  std::mt19937_64 rng(1234);
  struct Shape {
    int n;
    double world, small, big, big_share;
  };
  const Shape shapes[] = {{300, 10.0, 0.5, 0.5, 0.0},    // uniform sizes
                          {500, 20.0, 0.3, 8.0, 0.02},   // a few large boxes among small
                          {400, 5.0, 0.2, 30.0, 0.01},   // boxes wider than the world
                          {200, 1e5, 1.0, 1.0, 0.0},     // sparse, far from the origin
                          {50, 0.5, 0.0, 0.0, 0.0}};     // points, all zero size
  for (const Shape& sh : shapes) {
    SCOPED_TRACE(sh.n);
    const std::vector<Aabb> boxes = random_boxes(rng, sh.n, sh.world, sh.small, sh.big, sh.big_share);
    std::vector<std::uint8_t> active(boxes.size(), 1);
    for (std::size_t k = 0; k < active.size(); k += 7) active[k] = 0;   // some inactive
    // The reference: every pair checked.
    std::vector<BodyPair> expected;
    for (std::uint32_t i = 0; i < boxes.size(); ++i) {
      for (std::uint32_t j = i + 1; j < boxes.size(); ++j) {
        if (active[i] && active[j] && overlaps(boxes[i], boxes[j])) expected.push_back({i, j});
      }
    }
    for (BroadPhaseKind kind : kKinds) {
      for (double cell : {0.0, 0.37}) {
        SCOPED_TRACE(std::string(broadphase_name(kind)) + " cell " + std::to_string(cell));
        auto bp = make_broadphase(kind, cell);
        build_broadphase(*bp, boxes, active);
        EXPECT_EQ(sorted_pairs(*bp), expected);
        // Build twice: reused storage gives the same answer.
        build_broadphase(*bp, boxes, active);
        EXPECT_EQ(sorted_pairs(*bp), expected);
      }
    }
  }
}

TEST(CoreBroadPhase, QueriesAfterGrowAgree) {
  std::mt19937_64 rng(99);
  std::vector<Aabb> boxes = random_boxes(rng, 400, 10.0, 0.4, 3.0, 0.05);
  std::vector<std::uint8_t> active(boxes.size(), 1);
  active[3] = active[10] = 0;
  std::vector<std::unique_ptr<BroadPhase>> all;
  for (BroadPhaseKind kind : kKinds) {
    all.push_back(make_broadphase(kind));
    build_broadphase(*all.back(), boxes, active);
  }
  // Grow some boxes (paths bent by impacts), activate an inactive one, then every
  // method must answer every query with the same set: the bodies whose current box
  // overlaps the queried body's current box.
  std::vector<Aabb> current = boxes;
  for (int step = 0; step < 200; ++step) {
    const auto i = static_cast<std::uint32_t>(rng() % boxes.size());
    const double x = uniform(rng, -10.0, 10.0), y = uniform(rng, -10.0, 10.0);
    const double s = uniform(rng, 0.0, step % 50 == 0 ? 6.0 : 0.8);
    const Aabb extra = make_aabb(x, y, x + s, y + s);
    current[i] = active[i] ? merge(current[i], extra) : extra;
    active[i] = 1;
    for (auto& bp : all) bp->grow(i, extra);
    const auto q = static_cast<std::uint32_t>(rng() % boxes.size());
    if (!active[q]) continue;
    std::vector<std::uint32_t> expected;
    for (std::uint32_t j = 0; j < current.size(); ++j) {
      if (j != q && active[j] && overlaps(current[q], current[j])) expected.push_back(j);
    }
    for (auto& bp : all) {
      SCOPED_TRACE(broadphase_name(bp->kind()));
      std::vector<std::uint32_t> got;
      bp->query(q, got);
      std::sort(got.begin(), got.end());
      EXPECT_EQ(got, expected);
    }
  }
}

TEST(CoreBroadPhase, QueriesAfterSmallGrowsAgree) {
  // Like a gas mid-step: boxes of one size, grown a little at a time, so that many
  // end up a cell or two wide (the grid enters those in every cell they touch) and a
  // few grow past that (the grid's list of oversize boxes).
  std::mt19937_64 rng(7);
  std::vector<Aabb> boxes = random_boxes(rng, 600, 4.0, 0.25, 0.25, 0.0);
  std::vector<std::uint8_t> active(boxes.size(), 1);
  active[5] = 0;
  std::vector<std::unique_ptr<BroadPhase>> all;
  for (BroadPhaseKind kind : kKinds) {
    all.push_back(make_broadphase(kind));
    build_broadphase(*all.back(), boxes, active);
  }
  std::vector<Aabb> current = boxes;
  for (int step = 0; step < 1500; ++step) {
    const auto i = static_cast<std::uint32_t>(rng() % boxes.size());
    const Aabb& c = current[i];
    const double x = (active[i] ? c.min_x : uniform(rng, -4.0, 4.0)) + uniform(rng, -0.2, 0.2);
    const double y = (active[i] ? c.min_y : uniform(rng, -4.0, 4.0)) + uniform(rng, -0.2, 0.2);
    const double s = uniform(rng, 0.0, 0.3);
    const Aabb extra = make_aabb(x, y, x + s, y + s);
    current[i] = active[i] ? merge(current[i], extra) : extra;
    active[i] = 1;
    for (auto& bp : all) bp->grow(i, extra);
    // A query for one body, and one for a box spanning two (an impact's pair).
    const auto q = static_cast<std::uint32_t>(rng() % boxes.size());
    if (!active[q]) continue;
    const Aabb pair_box = merge(current[q], current[i]);
    std::vector<std::uint32_t> expected, expected_pair;
    for (std::uint32_t j = 0; j < current.size(); ++j) {
      if (!active[j]) continue;
      if (j != q && overlaps(current[q], current[j])) expected.push_back(j);
      if (overlaps(pair_box, current[j])) expected_pair.push_back(j);
    }
    for (auto& bp : all) {
      SCOPED_TRACE(broadphase_name(bp->kind()));
      std::vector<std::uint32_t> got;
      bp->query(q, got);
      std::sort(got.begin(), got.end());
      EXPECT_EQ(got, expected);
      got.clear();
      bp->query_box(pair_box, std::numeric_limits<std::uint32_t>::max(), got);
      std::sort(got.begin(), got.end());
      EXPECT_EQ(got, expected_pair);
    }
  }
}

TEST(CoreBroadPhase, AutoChoice) {
  std::vector<double> few(10, 0.1);
  EXPECT_EQ(choose_broadphase(few), BroadPhaseKind::AllPairs);
  std::vector<double> alike(1000, 0.1);
  EXPECT_EQ(choose_broadphase(alike), BroadPhaseKind::Grid);
  std::vector<double> spread(1000, 0.1);
  spread[0] = 2.0;
  EXPECT_EQ(choose_broadphase(spread), BroadPhaseKind::MultiGrid);
  spread[0] = 50.0;
  EXPECT_EQ(choose_broadphase(spread), BroadPhaseKind::SortAndSweep);
}

}  // namespace physval
