// The lecture's uniform grid: cell = the largest box, each body binned by the cell of
// its box centre (a counting sort, linear in N), and a body can only overlap bodies
// in its own and the eight neighbouring cells. One outlier (a bullet at 10^4 m/s)
// would make every cell huge, so the cell is capped at 4x the mean box; boxes larger
// than a cell are "oversize" and tested against every body.
#include "broadphase_common.hpp"

namespace physval {

namespace {

using bp_detail::kNil;
constexpr std::int32_t kOversize = std::numeric_limits<std::int32_t>::min();

class GridBroadPhase final : public bp_detail::BroadPhaseBase {
 public:
  explicit GridBroadPhase(double cell_size) : option_cell_(cell_size) {}

  BroadPhaseKind kind() const override { return BroadPhaseKind::Grid; }

  void build(std::span<const std::uint8_t> active) override {
    copy_active(active);
    const std::size_t n = boxes_.size();
    cx_.resize(n);
    cy_.resize(n);
    oversize_.clear();

    double sum = 0.0, largest = 0.0;
    std::size_t count = 0;
    for (std::size_t i = 0; i < n; ++i) {
      if (!active_[i]) continue;
      const double e = bp_detail::extent(boxes_[i]);
      sum += e;
      largest = std::max(largest, e);
      ++count;
    }
    const double mean = count > 0 ? sum / static_cast<double>(count) : 0.0;
    double cell = largest;
    if (mean > 0.0 && cell > 4.0 * mean) cell = 4.0 * mean;
    cell = std::max(cell, option_cell_);
    if (!(cell > 0.0)) cell = 1.0;
    cell_ = cell;
    inv_cell_ = 1.0 / cell;

    std::int32_t x_lo = std::numeric_limits<std::int32_t>::max(), x_hi = std::numeric_limits<std::int32_t>::min();
    std::int32_t y_lo = x_lo, y_hi = x_hi;
    for (std::uint32_t i = 0; i < n; ++i) {
      if (!active_[i]) continue;
      if (bp_detail::extent(boxes_[i]) > cell_) {
        cx_[i] = kOversize;
        oversize_.push_back(i);
        continue;
      }
      place(i);
      x_lo = std::min(x_lo, cx_[i]);
      x_hi = std::max(x_hi, cx_[i]);
      y_lo = std::min(y_lo, cy_[i]);
      y_hi = std::max(y_hi, cy_[i]);
    }
    const std::int64_t span_x = count > 0 ? static_cast<std::int64_t>(x_hi) - x_lo + 1 : 1;
    const std::int64_t span_y = count > 0 ? static_cast<std::int64_t>(y_hi) - y_lo + 1 : 1;
    hash_.choose(count, span_x, span_y);

    // Counting sort of the bodies by bucket.
    start_.assign(hash_.buckets + 1, 0);
    for (std::uint32_t i = 0; i < n; ++i) {
      if (active_[i] && cx_[i] != kOversize) ++start_[hash_(cx_[i], cy_[i]) + 1];
    }
    for (std::uint32_t b = 0; b < hash_.buckets; ++b) start_[b + 1] += start_[b];
    items_.resize(start_[hash_.buckets]);
    fill_.assign(start_.begin(), start_.end() - 1);
    for (std::uint32_t i = 0; i < n; ++i) {
      if (active_[i] && cx_[i] != kOversize) items_[fill_[hash_(cx_[i], cy_[i])]++] = i;
    }
    extra_head_.assign(hash_.buckets, kNil);
    extra_next_.clear();
    extra_body_.clear();
  }

  void pairs(std::vector<BodyPair>& out) override {
    static constexpr std::int32_t kForward[4][2] = {{1, 0}, {-1, 1}, {0, 1}, {1, 1}};
    for (std::uint32_t b = 0; b < hash_.buckets; ++b) {
      const std::uint32_t end = start_[b + 1];
      for (std::uint32_t k = start_[b]; k < end; ++k) {
        const std::uint32_t i = items_[k];
        const std::int32_t cx = cx_[i], cy = cy_[i];
        const Aabb& a = boxes_[i];
        for (std::uint32_t k2 = k + 1; k2 < end; ++k2) {
          const std::uint32_t j = items_[k2];
          if (cx_[j] == cx && cy_[j] == cy && overlaps(a, boxes_[j])) push(out, i, j);
        }
        for (const auto& d : kForward) {
          const std::int64_t nx = static_cast<std::int64_t>(cx) + d[0];
          const std::int64_t ny = static_cast<std::int64_t>(cy) + d[1];
          if (nx > 2147483646 || nx < -2147483647 || ny > 2147483646) continue;
          const auto ncx = static_cast<std::int32_t>(nx), ncy = static_cast<std::int32_t>(ny);
          const std::uint32_t nb = hash_(ncx, ncy);
          for (std::uint32_t k2 = start_[nb]; k2 < start_[nb + 1]; ++k2) {
            const std::uint32_t j = items_[k2];
            if (cx_[j] == ncx && cy_[j] == ncy && overlaps(a, boxes_[j])) push(out, i, j);
          }
        }
      }
    }
    for (std::uint32_t o : oversize_) {
      for (std::uint32_t j = 0; j < boxes_.size(); ++j) {
        if (!active_[j] || j == o || (cx_[j] == kOversize && j < o)) continue;
        if (overlaps(boxes_[o], boxes_[j])) push(out, o, j);
      }
    }
  }

  void query_box(const Aabb& q, std::uint32_t exclude, std::vector<std::uint32_t>& out) override {
    const std::uint32_t stamp = next_stamp();
    if (exclude < stamp_.size()) stamp_[exclude] = stamp;
    const double half = 0.5 * cell_;
    const std::int32_t x0 = bp_detail::cell_of(q.min_x - half, inv_cell_);
    const std::int32_t x1 = bp_detail::cell_of(q.max_x + half, inv_cell_);
    const std::int32_t y0 = bp_detail::cell_of(q.min_y - half, inv_cell_);
    const std::int32_t y1 = bp_detail::cell_of(q.max_y + half, inv_cell_);
    const double cells = (static_cast<double>(x1) - x0 + 1.0) * (static_cast<double>(y1) - y0 + 1.0);
    if (cells > static_cast<double>(boxes_.size())) {
      // A box wider than the whole scene's cells: test everyone.
      for (std::uint32_t j = 0; j < boxes_.size(); ++j) {
        if (active_[j] && first_visit(j, stamp) && overlaps(q, boxes_[j])) out.push_back(j);
      }
      return;
    }
    for (std::int32_t y = y0; y <= y1; ++y) {
      for (std::int32_t x = x0; x <= x1; ++x) {
        const std::uint32_t b = hash_(x, y);
        for (std::uint32_t k = start_[b]; k < start_[b + 1]; ++k) visit(items_[k], x, y, q, stamp, out);
        for (std::uint32_t e = extra_head_[b]; e != kNil; e = extra_next_[e]) visit(extra_body_[e], x, y, q, stamp, out);
        if (x == x1) break;   // guard the increment at INT32_MAX
      }
      if (y == y1) break;
    }
    for (std::uint32_t o : oversize_) {
      if (first_visit(o, stamp) && overlaps(q, boxes_[o])) out.push_back(o);
    }
  }

  void grow(std::uint32_t i, const Aabb& b) override {
    if (!active_[i]) {
      active_[i] = 1;
      boxes_[i] = b;
      cx_[i] = kOversize;   // not binned yet
      cy_[i] = 0;
      if (bp_detail::extent(b) > cell_) {
        oversize_.push_back(i);
        return;
      }
      place(i);
      add_extra(i);
      return;
    }
    boxes_[i] = merge(boxes_[i], b);
    if (cx_[i] == kOversize) return;
    if (bp_detail::extent(boxes_[i]) > cell_) {
      cx_[i] = kOversize;
      oversize_.push_back(i);
      return;
    }
    const std::int32_t ox = cx_[i], oy = cy_[i];
    place(i);
    if (cx_[i] != ox || cy_[i] != oy) add_extra(i);
  }

  std::size_t memory_bytes() const override {
    return base_bytes() + (cx_.capacity() + cy_.capacity()) * sizeof(std::int32_t) +
           (start_.capacity() + fill_.capacity() + items_.capacity() + oversize_.capacity() +
            extra_head_.capacity() + extra_next_.capacity() + extra_body_.capacity()) *
               sizeof(std::uint32_t);
  }

 private:
  static void push(std::vector<BodyPair>& out, std::uint32_t i, std::uint32_t j) {
    out.push_back(i < j ? BodyPair{i, j} : BodyPair{j, i});
  }
  void place(std::uint32_t i) {
    const Aabb& b = boxes_[i];
    cx_[i] = bp_detail::cell_of(0.5 * (static_cast<double>(b.min_x) + b.max_x), inv_cell_);
    cy_[i] = bp_detail::cell_of(0.5 * (static_cast<double>(b.min_y) + b.max_y), inv_cell_);
  }
  void add_extra(std::uint32_t i) {
    const std::uint32_t b = hash_(cx_[i], cy_[i]);
    extra_body_.push_back(i);
    extra_next_.push_back(extra_head_[b]);
    extra_head_[b] = static_cast<std::uint32_t>(extra_body_.size() - 1);
  }
  void visit(std::uint32_t j, std::int32_t x, std::int32_t y, const Aabb& q, std::uint32_t stamp,
             std::vector<std::uint32_t>& out) {
    // A body's current cell is the one that counts: entries left behind by grow() and
    // bucket collisions are filtered here.
    if (cx_[j] != x || cy_[j] != y) return;
    if (first_visit(j, stamp) && overlaps(q, boxes_[j])) out.push_back(j);
  }

  double option_cell_ = 0.0;
  double cell_ = 1.0;
  double inv_cell_ = 1.0;
  bp_detail::TileHash hash_;
  std::vector<std::int32_t> cx_, cy_;
  std::vector<std::uint32_t> start_, fill_, items_, oversize_;
  std::vector<std::uint32_t> extra_head_, extra_next_, extra_body_;
};

}  // namespace

std::unique_ptr<BroadPhase> make_grid_broadphase(double cell_size) {
  return std::make_unique<GridBroadPhase>(cell_size);
}

}  // namespace physval
