// What the broad phases share: box storage, activity flags, the per-query stamp that
// reports each body once, and the tiled cell hash of the two grids.
#pragma once

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <span>
#include <vector>

#include "physval/core/broadphase.hpp"

namespace physval::bp_detail {

inline constexpr std::uint32_t kNil = std::numeric_limits<std::uint32_t>::max();

class BroadPhaseBase : public BroadPhase {
 public:
  std::span<Aabb> prepare(std::size_t n) override {
    boxes_.resize(n);
    return boxes_;
  }
  const Aabb& box(std::uint32_t i) const override { return boxes_[i]; }

 protected:
  void copy_active(std::span<const std::uint8_t> active) {
    active_.assign(active.begin(), active.end());
    active_.resize(boxes_.size(), 0);
    if (stamp_.size() < boxes_.size()) {
      stamp_.assign(boxes_.size(), 0);
      stamp_value_ = 0;
    }
  }
  // A fresh stamp for one query; body j is new to it when stamp_[j] != value.
  std::uint32_t next_stamp() {
    if (++stamp_value_ == 0) {
      std::fill(stamp_.begin(), stamp_.end(), 0u);
      stamp_value_ = 1;
    }
    return stamp_value_;
  }
  bool first_visit(std::uint32_t j, std::uint32_t stamp) {
    if (stamp_[j] == stamp) return false;
    stamp_[j] = stamp;
    return true;
  }
  std::size_t base_bytes() const {
    return boxes_.capacity() * sizeof(Aabb) + active_.capacity() + stamp_.capacity() * sizeof(std::uint32_t);
  }

  std::vector<Aabb> boxes_;
  std::vector<std::uint8_t> active_;
  std::vector<std::uint32_t> stamp_;
  std::uint32_t stamp_value_ = 0;
};

inline double extent(const Aabb& b) {
  return std::max(static_cast<double>(b.max_x) - b.min_x, static_cast<double>(b.max_y) - b.min_y);
}

// Cell coordinate of x for cells of edge `cell`, clamped to int32 (clamping is
// monotone, so neighbours stay neighbours: far-away bodies only cost extra tests).
inline std::int32_t cell_of(double x, double inv_cell) {
  const double c = x * inv_cell;
  if (!(c > -2147483647.0)) return -2147483647;   // (also NaN)
  if (!(c < 2147483646.0)) return 2147483646;
  const auto i = static_cast<std::int32_t>(c);   // floor without a libm call
  return c < static_cast<double>(i) ? i - 1 : i;
}

// Maps cells to buckets by tiling: bucket = (iy mod H) * W + (ix mod W), W and H
// powers of two chosen from the occupied cell range, so a compact scene maps without
// collisions and neighbouring cells are neighbours in memory.
struct TileHash {
  std::uint32_t wbits = 0;
  std::uint32_t wmask = 0;
  std::uint32_t hmask = 0;
  std::uint32_t buckets = 1;

  void choose(std::size_t min_buckets, std::int64_t cells_x, std::int64_t cells_y) {
    const std::uint64_t b = std::bit_ceil(std::max<std::uint64_t>(min_buckets, 16));
    std::uint64_t w = std::bit_ceil(static_cast<std::uint64_t>(std::max<std::int64_t>(cells_x, 1)));
    w = std::min(w, b);
    std::uint64_t h = b / w;
    const std::uint64_t hneed = std::bit_ceil(static_cast<std::uint64_t>(std::max<std::int64_t>(cells_y, 1)));
    if (h > hneed) {   // a wide, flat scene: give the spare buckets back to x
      h = hneed;
      w = std::min<std::uint64_t>(b / h, std::bit_ceil(static_cast<std::uint64_t>(std::max<std::int64_t>(cells_x, 1))) * 2);
    }
    wbits = static_cast<std::uint32_t>(std::countr_zero(w));
    wmask = static_cast<std::uint32_t>(w - 1);
    hmask = static_cast<std::uint32_t>(h - 1);
    buckets = static_cast<std::uint32_t>(w * h);
  }
  std::uint32_t operator()(std::int32_t ix, std::int32_t iy) const {
    return ((static_cast<std::uint32_t>(iy) & hmask) << wbits) | (static_cast<std::uint32_t>(ix) & wmask);
  }
};

}  // namespace physval::bp_detail
