// The lecture's grid for many sizes: cells of any edge (default twice the mean box),
// each body in every cell its box touches. A pair is reported only from the cell that
// holds the lower-left corner of the two boxes' intersection, so exactly once. Boxes
// covering more than 16 cells are "oversize" and tested against every body.
#include "broadphase_common.hpp"

namespace physval {

namespace {

using bp_detail::kNil;
constexpr std::int64_t kMaxCells = 16;

struct Entry {
  std::uint32_t body;
  std::int32_t cx, cy;
};

struct CellRange {
  std::int32_t x0, y0, x1, y1;
  std::int64_t count() const {
    return (static_cast<std::int64_t>(x1) - x0 + 1) * (static_cast<std::int64_t>(y1) - y0 + 1);
  }
  bool has(std::int32_t x, std::int32_t y) const { return x >= x0 && x <= x1 && y >= y0 && y <= y1; }
};

class MultiGridBroadPhase final : public bp_detail::BroadPhaseBase {
 public:
  explicit MultiGridBroadPhase(double cell_size) : option_cell_(cell_size) {}

  BroadPhaseKind kind() const override { return BroadPhaseKind::MultiGrid; }

  void build(std::span<const std::uint8_t> active) override {
    copy_active(active);
    const std::size_t n = boxes_.size();
    big_.assign(n, 0);
    oversize_.clear();
    double sum = 0.0;
    std::size_t count = 0;
    for (std::size_t i = 0; i < n; ++i) {
      if (!active_[i]) continue;
      sum += bp_detail::extent(boxes_[i]);
      ++count;
    }
    double cell = option_cell_ > 0.0 ? option_cell_ : (count > 0 ? 2.0 * sum / static_cast<double>(count) : 1.0);
    if (!(cell > 0.0)) cell = 1.0;
    inv_cell_ = 1.0 / cell;

    std::int32_t x_lo = std::numeric_limits<std::int32_t>::max(), x_hi = std::numeric_limits<std::int32_t>::min();
    std::int32_t y_lo = x_lo, y_hi = x_hi;
    std::size_t entries = 0;
    for (std::uint32_t i = 0; i < n; ++i) {
      if (!active_[i]) continue;
      const CellRange r = range(boxes_[i]);
      if (r.count() > kMaxCells) {
        big_[i] = 1;
        oversize_.push_back(i);
        continue;
      }
      entries += static_cast<std::size_t>(r.count());
      x_lo = std::min(x_lo, r.x0);
      x_hi = std::max(x_hi, r.x1);
      y_lo = std::min(y_lo, r.y0);
      y_hi = std::max(y_hi, r.y1);
    }
    const bool any = entries > 0;
    hash_.choose(entries, any ? static_cast<std::int64_t>(x_hi) - x_lo + 1 : 1,
                 any ? static_cast<std::int64_t>(y_hi) - y_lo + 1 : 1);

    start_.assign(hash_.buckets + 1, 0);
    for_each_cell([&](std::uint32_t, std::int32_t x, std::int32_t y) { ++start_[hash_(x, y) + 1]; });
    for (std::uint32_t b = 0; b < hash_.buckets; ++b) start_[b + 1] += start_[b];
    items_.resize(start_[hash_.buckets]);
    fill_.assign(start_.begin(), start_.end() - 1);
    for_each_cell([&](std::uint32_t i, std::int32_t x, std::int32_t y) { items_[fill_[hash_(x, y)]++] = {i, x, y}; });
    extra_head_.assign(hash_.buckets, kNil);
    extra_.clear();
    extra_next_.clear();
  }

  void pairs(std::vector<BodyPair>& out) override {
    for (std::uint32_t b = 0; b < hash_.buckets; ++b) {
      const std::uint32_t end = start_[b + 1];
      for (std::uint32_t k = start_[b]; k < end; ++k) {
        const Entry e = items_[k];
        const Aabb& a = boxes_[e.body];
        for (std::uint32_t k2 = k + 1; k2 < end; ++k2) {
          const Entry f = items_[k2];
          if (f.cx != e.cx || f.cy != e.cy) continue;
          const Aabb& c = boxes_[f.body];
          if (!overlaps(a, c)) continue;
          // Report from the cell of the intersection's lower-left corner only.
          const float mx = a.min_x > c.min_x ? a.min_x : c.min_x;
          const float my = a.min_y > c.min_y ? a.min_y : c.min_y;
          if (bp_detail::cell_of(mx, inv_cell_) != e.cx || bp_detail::cell_of(my, inv_cell_) != e.cy) continue;
          out.push_back(e.body < f.body ? BodyPair{e.body, f.body} : BodyPair{f.body, e.body});
        }
      }
    }
    for (std::uint32_t o : oversize_) {
      for (std::uint32_t j = 0; j < boxes_.size(); ++j) {
        if (!active_[j] || j == o || (big_[j] && j < o)) continue;
        if (overlaps(boxes_[o], boxes_[j])) out.push_back(o < j ? BodyPair{o, j} : BodyPair{j, o});
      }
    }
  }

  void query_box(const Aabb& q, std::uint32_t exclude, std::vector<std::uint32_t>& out) override {
    const std::uint32_t stamp = next_stamp();
    if (exclude < stamp_.size()) stamp_[exclude] = stamp;
    const CellRange r = range(q);
    if (r.count() > std::max<std::int64_t>(kMaxCells, static_cast<std::int64_t>(boxes_.size()))) {
      for (std::uint32_t j = 0; j < boxes_.size(); ++j) {
        if (active_[j] && first_visit(j, stamp) && overlaps(q, boxes_[j])) out.push_back(j);
      }
      return;
    }
    for (std::int32_t y = r.y0;; ++y) {
      for (std::int32_t x = r.x0;; ++x) {
        const std::uint32_t b = hash_(x, y);
        for (std::uint32_t k = start_[b]; k < start_[b + 1]; ++k) visit(items_[k], x, y, q, stamp, out);
        for (std::uint32_t e = extra_head_[b]; e != kNil; e = extra_next_[e]) visit(extra_[e], x, y, q, stamp, out);
        if (x == r.x1) break;
      }
      if (y == r.y1) break;
    }
    for (std::uint32_t o : oversize_) {
      if (first_visit(o, stamp) && overlaps(q, boxes_[o])) out.push_back(o);
    }
  }

  void grow(std::uint32_t i, const Aabb& b) override {
    const bool was_active = active_[i] != 0;
    const CellRange old_r = was_active ? range(boxes_[i]) : CellRange{1, 1, 0, 0};
    if (was_active) {
      boxes_[i] = merge(boxes_[i], b);
    } else {
      active_[i] = 1;
      boxes_[i] = b;
      big_[i] = 0;
    }
    if (big_[i]) return;
    const CellRange r = range(boxes_[i]);
    if (r.count() > kMaxCells) {
      big_[i] = 1;
      oversize_.push_back(i);
      return;
    }
    for (std::int32_t y = r.y0;; ++y) {
      for (std::int32_t x = r.x0;; ++x) {
        if (!(was_active && old_r.has(x, y))) {
          const std::uint32_t bucket = hash_(x, y);
          extra_.push_back({i, x, y});
          extra_next_.push_back(extra_head_[bucket]);
          extra_head_[bucket] = static_cast<std::uint32_t>(extra_.size() - 1);
        }
        if (x == r.x1) break;
      }
      if (y == r.y1) break;
    }
  }

  std::size_t memory_bytes() const override {
    return base_bytes() + big_.capacity() + (items_.capacity() + extra_.capacity()) * sizeof(Entry) +
           (start_.capacity() + fill_.capacity() + oversize_.capacity() + extra_head_.capacity() +
            extra_next_.capacity()) *
               sizeof(std::uint32_t);
  }

 private:
  CellRange range(const Aabb& b) const {
    return {bp_detail::cell_of(b.min_x, inv_cell_), bp_detail::cell_of(b.min_y, inv_cell_),
            bp_detail::cell_of(b.max_x, inv_cell_), bp_detail::cell_of(b.max_y, inv_cell_)};
  }
  template <class F>
  void for_each_cell(F&& f) {
    for (std::uint32_t i = 0; i < boxes_.size(); ++i) {
      if (!active_[i] || big_[i]) continue;
      const CellRange r = range(boxes_[i]);
      for (std::int32_t y = r.y0;; ++y) {
        for (std::int32_t x = r.x0;; ++x) {
          f(i, x, y);
          if (x == r.x1) break;
        }
        if (y == r.y1) break;
      }
    }
  }
  void visit(const Entry& e, std::int32_t x, std::int32_t y, const Aabb& q, std::uint32_t stamp,
             std::vector<std::uint32_t>& out) {
    if (e.cx != x || e.cy != y) return;   // another cell sharing the bucket
    if (first_visit(e.body, stamp) && overlaps(q, boxes_[e.body])) out.push_back(e.body);
  }

  double option_cell_ = 0.0;
  double inv_cell_ = 1.0;
  bp_detail::TileHash hash_;
  std::vector<std::uint8_t> big_;
  std::vector<std::uint32_t> start_, fill_, oversize_;
  std::vector<Entry> items_;
  std::vector<std::uint32_t> extra_head_, extra_next_;
  std::vector<Entry> extra_;
};

}  // namespace

std::unique_ptr<BroadPhase> make_multigrid_broadphase(double cell_size) {
  return std::make_unique<MultiGridBroadPhase>(cell_size);
}

}  // namespace physval
