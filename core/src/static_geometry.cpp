// Static geometry: walls, box sides and surface pieces as segments, with a hashed
// uniform grid (built once at load) for scenes with many of them. A few segments are
// simply all tested.
#include <algorithm>
#include <cmath>

#include "world.hpp"

namespace physval::core_detail {

namespace {

constexpr std::size_t kBruteForceLimit = 8;

std::int32_t cell_of(double x, double inv) {
  const double c = std::clamp(x * inv, -2147483647.0, 2147483646.0);
  const auto i = static_cast<std::int32_t>(c);   // floor without a libm call
  return c < static_cast<double>(i) ? i - 1 : i;
}

std::uint32_t bucket(std::int32_t x, std::int32_t y, std::uint32_t mask) {
  std::uint64_t k = (static_cast<std::uint64_t>(static_cast<std::uint32_t>(x)) << 32) | static_cast<std::uint32_t>(y);
  k *= 0x9E3779B97F4A7C15ull;
  return static_cast<std::uint32_t>(k >> 32) & mask;
}

// Distance from the segment [a, b] to the square cell [x0, x0 + c] x [y0, y0 + c] is
// at most half its diagonal from the centre when the segment touches the cell.
bool segment_near_cell(const Segment& s, double x0, double y0, double c) {
  const Vec2 centre{x0 + 0.5 * c, y0 + 0.5 * c};
  const Vec2 d = centre - s.from;
  const double u = std::clamp(dot(d, s.dir), 0.0, s.length);
  const Vec2 closest = s.from + u * s.dir;
  return length(centre - closest) <= 0.7072 * c;
}

}  // namespace

void StaticGeometry::build(double typical_body_size) {
  boxes_.clear();
  for (const Segment& s : segments) {
    boxes_.push_back(make_aabb(std::min(s.from.x, s.to.x), std::min(s.from.y, s.to.y), std::max(s.from.x, s.to.x),
                               std::max(s.from.y, s.to.y)));
  }
  stamp_.assign(segments.size(), 0);
  use_grid_ = segments.size() > kBruteForceLimit;
  if (!use_grid_) return;
  // Cells about the size of a segment or a few bodies, whichever is larger.
  double total = 0.0;
  for (const Segment& s : segments) total += s.length;
  const double mean = total / static_cast<double>(segments.size());
  cell_ = std::max(mean, 4.0 * typical_body_size);
  if (!(cell_ > 0.0)) cell_ = 1.0;
  const double inv = 1.0 / cell_;
  std::uint32_t buckets = 16;
  while (buckets < 4 * segments.size()) buckets <<= 1;
  mask_ = buckets - 1;
  std::vector<std::uint32_t> count(buckets + 1, 0);
  std::vector<std::pair<std::uint32_t, std::uint32_t>> entries;   // (bucket, segment)
  for (std::uint32_t k = 0; k < segments.size(); ++k) {
    const Aabb& b = boxes_[k];
    const std::int32_t x0 = cell_of(b.min_x, inv), x1 = cell_of(b.max_x, inv);
    const std::int32_t y0 = cell_of(b.min_y, inv), y1 = cell_of(b.max_y, inv);
    for (std::int32_t y = y0; y <= y1; ++y) {
      for (std::int32_t x = x0; x <= x1; ++x) {
        if (segment_near_cell(segments[k], x * cell_, y * cell_, cell_)) entries.push_back({bucket(x, y, mask_), k});
      }
    }
  }
  std::sort(entries.begin(), entries.end());
  entries.erase(std::unique(entries.begin(), entries.end()), entries.end());
  for (const auto& e : entries) ++count[e.first + 1];
  for (std::uint32_t b = 0; b < buckets; ++b) count[b + 1] += count[b];
  start_ = std::move(count);
  items_.clear();
  for (const auto& e : entries) items_.push_back(e.second);
}

void StaticGeometry::query(const Aabb& box, std::vector<std::uint32_t>& out) const {
  if (!use_grid_) {
    for (std::uint32_t k = 0; k < segments.size(); ++k) {
      if (overlaps(box, boxes_[k])) out.push_back(k);
    }
    return;
  }
  if (++stamp_value_ == 0) {
    std::fill(stamp_.begin(), stamp_.end(), 0u);
    stamp_value_ = 1;
  }
  const double inv = 1.0 / cell_;
  const std::int32_t x0 = cell_of(box.min_x, inv), x1 = cell_of(box.max_x, inv);
  const std::int32_t y0 = cell_of(box.min_y, inv), y1 = cell_of(box.max_y, inv);
  const double cells = (static_cast<double>(x1) - x0 + 1.0) * (static_cast<double>(y1) - y0 + 1.0);
  if (cells > 4.0 * static_cast<double>(segments.size())) {
    for (std::uint32_t k = 0; k < segments.size(); ++k) {
      if (overlaps(box, boxes_[k])) out.push_back(k);
    }
    return;
  }
  for (std::int32_t y = y0;; ++y) {
    for (std::int32_t x = x0;; ++x) {
      const std::uint32_t b = bucket(x, y, mask_);
      for (std::uint32_t e = start_[b]; e < start_[b + 1]; ++e) {
        const std::uint32_t k = items_[e];
        if (stamp_[k] == stamp_value_) continue;
        stamp_[k] = stamp_value_;
        if (overlaps(box, boxes_[k])) out.push_back(k);
      }
      if (x == x1) break;
    }
    if (y == y1) break;
  }
}

std::size_t StaticGeometry::memory_bytes() const {
  return segments.capacity() * sizeof(Segment) + boxes_.capacity() * sizeof(Aabb) +
         (start_.capacity() + items_.capacity() + stamp_.capacity()) * sizeof(std::uint32_t);
}

}  // namespace physval::core_detail
