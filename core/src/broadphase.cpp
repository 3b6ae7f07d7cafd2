// Broad phase: names, the `auto` choice, the factory, and the all-pairs reference.
#include "physval/core/broadphase.hpp"

#include <algorithm>
#include <numeric>
#include <stdexcept>
#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "broadphase_common.hpp"

namespace physval {

std::unique_ptr<BroadPhase> make_grid_broadphase(double cell_size);        // broadphase_grid.cpp
std::unique_ptr<BroadPhase> make_multigrid_broadphase(double cell_size);   // broadphase_multigrid.cpp
std::unique_ptr<BroadPhase> make_sort_sweep_broadphase();                  // broadphase_sort_sweep.cpp

const char* broadphase_name(BroadPhaseKind k) {
  switch (k) {
    case BroadPhaseKind::AllPairs: return "all_pairs";
    case BroadPhaseKind::Grid: return "grid";
    case BroadPhaseKind::MultiGrid: return "multigrid";
    case BroadPhaseKind::SortAndSweep: return "sort_and_sweep";
  }
  return "unknown";
}

bool parse_broadphase(const std::string& name, BroadPhaseKind& out) {
  for (BroadPhaseKind k : {BroadPhaseKind::AllPairs, BroadPhaseKind::Grid, BroadPhaseKind::MultiGrid,
                           BroadPhaseKind::SortAndSweep}) {
    if (name == broadphase_name(k)) {
      out = k;
      return true;
    }
  }
  return false;
}

BroadPhaseKind choose_broadphase(std::span<const double> radii) {
  if (radii.size() < 64) return BroadPhaseKind::AllPairs;
  double sum = 0.0, largest = 0.0;
  for (double r : radii) {
    sum += r;
    largest = std::max(largest, r);
  }
  const double mean = sum / static_cast<double>(radii.size());
  if (largest <= 4.0 * mean) return BroadPhaseKind::Grid;
  if (largest <= 64.0 * mean) return BroadPhaseKind::MultiGrid;
  return BroadPhaseKind::SortAndSweep;
}

void build_broadphase(BroadPhase& bp, std::span<const Aabb> boxes, std::span<const std::uint8_t> active) {
  std::span<Aabb> dst = bp.prepare(boxes.size());
  std::copy(boxes.begin(), boxes.end(), dst.begin());
  bp.build(active);
}

namespace {

// Every pair, O(N^2): the reference the others are tested against, and the cheapest
// for a handful of bodies.
class AllPairsBroadPhase final : public bp_detail::BroadPhaseBase {
 public:
  BroadPhaseKind kind() const override { return BroadPhaseKind::AllPairs; }

  void build(std::span<const std::uint8_t> active) override {
    copy_active(active);
    list_.clear();
    for (std::uint32_t i = 0; i < boxes_.size(); ++i) {
      if (active_[i]) list_.push_back(i);
    }
  }

  void pairs(std::vector<BodyPair>& out) override {
    for (std::size_t x = 0; x < list_.size(); ++x) {
      const Aabb& a = boxes_[list_[x]];
      for (std::size_t y = x + 1; y < list_.size(); ++y) {
        if (overlaps(a, boxes_[list_[y]])) out.push_back({list_[x], list_[y]});
      }
    }
  }

  void query_box(const Aabb& a, std::uint32_t exclude, std::vector<std::uint32_t>& out) override {
#if defined(__SSE2__)
    // overlaps() as one four-lane comparison: b.min <= a.max and -b.max <= -a.min (negation
    // is exact and keeps a NaN a NaN, which compares false either way).
    static_assert(sizeof(Aabb) == 4 * sizeof(float));
    const __m128 flip = _mm_castsi128_ps(_mm_set_epi32(INT32_MIN, INT32_MIN, 0, 0));
    const __m128 q = _mm_set_ps(-a.min_y, -a.min_x, a.max_y, a.max_x);
    for (const std::uint32_t j : list_) {
      const __m128 b = _mm_xor_ps(_mm_loadu_ps(&boxes_[j].min_x), flip);
      if (_mm_movemask_ps(_mm_cmple_ps(b, q)) == 0xF && j != exclude) out.push_back(j);
    }
#else
    for (std::uint32_t j : list_) {
      if (j != exclude && overlaps(a, boxes_[j])) out.push_back(j);
    }
#endif
  }

  void grow(std::uint32_t i, const Aabb& b) override {
    if (!active_[i]) {
      active_[i] = 1;
      boxes_[i] = b;
      list_.push_back(i);
    } else {
      boxes_[i] = merge(boxes_[i], b);
    }
  }

  std::size_t memory_bytes() const override { return base_bytes() + list_.capacity() * sizeof(std::uint32_t); }

 private:
  std::vector<std::uint32_t> list_;   // active bodies, ascending (then those grown in)
};

}  // namespace

std::unique_ptr<BroadPhase> make_broadphase(BroadPhaseKind kind, double cell_size) {
  switch (kind) {
    case BroadPhaseKind::AllPairs: return std::make_unique<AllPairsBroadPhase>();
    case BroadPhaseKind::Grid: return make_grid_broadphase(cell_size);
    case BroadPhaseKind::MultiGrid: return make_multigrid_broadphase(cell_size);
    case BroadPhaseKind::SortAndSweep: return make_sort_sweep_broadphase();
  }
  throw std::invalid_argument("unknown broad phase");
}

}  // namespace physval
