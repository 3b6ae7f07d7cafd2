// Sort and sweep: boxes sorted by their left edge; a body can only overlap those whose
// left edge lies before its right edge, so each sweep stops early. Robust to any mix
// of sizes. A box grown mid-step keeps its sort key; the widest reach to the right and
// lead to the left of any key bound how far a query must look.
#include <algorithm>

#include "broadphase_common.hpp"

namespace physval {

namespace {

class SortSweepBroadPhase final : public bp_detail::BroadPhaseBase {
 public:
  BroadPhaseKind kind() const override { return BroadPhaseKind::SortAndSweep; }

  void build(std::span<const std::uint8_t> active) override {
    copy_active(active);
    const std::size_t n = boxes_.size();
    order_.clear();
    for (std::uint32_t i = 0; i < n; ++i) {
      if (active_[i]) order_.push_back(i);
    }
    std::sort(order_.begin(), order_.end(), [&](std::uint32_t a, std::uint32_t b) {
      const float ka = boxes_[a].min_x, kb = boxes_[b].min_x;
      return ka != kb ? ka < kb : a < b;
    });
    keys_.resize(order_.size());
    key_of_.assign(n, 0.0f);
    in_order_.assign(n, 0);
    max_reach_ = 0.0;
    max_lead_ = 0.0;
    for (std::size_t k = 0; k < order_.size(); ++k) {
      const Aabb& b = boxes_[order_[k]];
      keys_[k] = b.min_x;
      key_of_[order_[k]] = b.min_x;
      in_order_[order_[k]] = 1;
      max_reach_ = std::max(max_reach_, static_cast<double>(b.max_x) - b.min_x);
    }
    extra_.clear();
  }

  void pairs(std::vector<BodyPair>& out) override {
    const std::size_t m = order_.size();
    for (std::size_t a = 0; a < m; ++a) {
      const std::uint32_t i = order_[a];
      const Aabb& bi = boxes_[i];
      for (std::size_t b = a + 1; b < m && keys_[b] <= bi.max_x; ++b) {
        const std::uint32_t j = order_[b];
        if (overlaps(bi, boxes_[j])) out.push_back(i < j ? BodyPair{i, j} : BodyPair{j, i});
      }
    }
    for (std::size_t x = 0; x < extra_.size(); ++x) {   // activated after the build (none at build time)
      for (std::uint32_t j = 0; j < boxes_.size(); ++j) {
        if (active_[j] && j != extra_[x] && overlaps(boxes_[extra_[x]], boxes_[j])) {
          if (!in_order_[j] && j < extra_[x]) continue;
          out.push_back(extra_[x] < j ? BodyPair{extra_[x], j} : BodyPair{j, extra_[x]});
        }
      }
    }
  }

  void query_box(const Aabb& q, std::uint32_t i, std::vector<std::uint32_t>& out) override {
    const double lo = static_cast<double>(q.min_x) - max_reach_;
    const double hi = static_cast<double>(q.max_x) + max_lead_;
    auto it = std::lower_bound(keys_.begin(), keys_.end(), lo,
                               [](float k, double v) { return static_cast<double>(k) < v; });
    for (auto k = static_cast<std::size_t>(it - keys_.begin()); k < keys_.size() && keys_[k] <= hi; ++k) {
      const std::uint32_t j = order_[k];
      if (j != i && overlaps(q, boxes_[j])) out.push_back(j);
    }
    for (std::uint32_t j : extra_) {
      if (j != i && overlaps(q, boxes_[j])) out.push_back(j);
    }
  }

  void grow(std::uint32_t i, const Aabb& b) override {
    if (!active_[i]) {
      active_[i] = 1;
      boxes_[i] = b;
      extra_.push_back(i);
      return;
    }
    boxes_[i] = merge(boxes_[i], b);
    if (!in_order_[i]) return;
    const double key = key_of_[i];
    max_lead_ = std::max(max_lead_, key - static_cast<double>(boxes_[i].min_x));
    max_reach_ = std::max(max_reach_, static_cast<double>(boxes_[i].max_x) - key);
  }

  std::size_t memory_bytes() const override {
    return base_bytes() + (order_.capacity() + extra_.capacity()) * sizeof(std::uint32_t) +
           (keys_.capacity() + key_of_.capacity()) * sizeof(float) + in_order_.capacity();
  }

 private:
  std::vector<std::uint32_t> order_;   // active bodies by left edge at build
  std::vector<float> keys_;            // their left edges, ascending
  std::vector<float> key_of_;          // per body: its key
  std::vector<std::uint8_t> in_order_;
  std::vector<std::uint32_t> extra_;   // activated after the build, scanned linearly
  double max_reach_ = 0.0;             // max over keyed bodies of max_x - key
  double max_lead_ = 0.0;              // max over keyed bodies of key - min_x
};

}  // namespace

std::unique_ptr<BroadPhase> make_sort_sweep_broadphase() { return std::make_unique<SortSweepBroadPhase>(); }

}  // namespace physval
