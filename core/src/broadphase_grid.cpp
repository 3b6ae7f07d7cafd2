// The lecture's uniform grid: cell = the largest box, each body binned by the cell of
// its box centre (a counting sort, linear in N), and a body can only overlap bodies
// in its own and the eight neighbouring cells. One outlier (a bullet at 10^4 m/s)
// would make every cell huge, so the cell is capped at 4x the mean box; boxes larger
// than a cell are "oversize" and tested against every body.
//
// The boxes are stored in bucket order (gathered at the build), so a query scans
// neighbouring cells through contiguous memory; each position's box, home cell, body
// and query stamp share one 32-byte slot, so a visit costs one cache line (at a
// million bodies every visit of a query is a miss). Each body has a home
// cell, that of its box centre at the build. A box grown mid-step keeps its home while
// its centre stays within a quarter cell of it (queries look that much further);
// beyond, it moves home to its new centre's cell through an extra entry, and the
// entry it leaves behind no longer matches.
//
// A box grown past a cell mid-step (a fast body deflected: its box covers the old
// path and the new) is entered, through extra entries, in every cell it touches, so
// queries meet it where they look; only one too large for that (more than 16 cells),
// or oversize at the build, joins the list every query tests. (One list for all
// would make each query cost a share of N: quadratic at a million bodies.)
#include "broadphase_common.hpp"

namespace physval {

namespace {

using bp_detail::kNil;

// The home x of an oversize body: no cell matches it (cell_of never returns INT32_MIN);
// its home y says whether it is in the list every query tests.
constexpr std::int32_t kOversizeHome = std::numeric_limits<std::int32_t>::min();
constexpr std::int32_t kInCells = 0, kInList = 1;
// An extra entry for one cell an oversize body touches (the rest: the body's index).
constexpr std::uint32_t kTouchEntry = 0x80000000u;
constexpr std::int64_t kMaxTouchCells = 16;

// Everything a query reads about the body at one position of the bucket order.
struct alignas(32) Slot {
  Aabb box;
  std::int32_t hx = 0, hy = 0;   // home cell (hx = kOversizeHome: oversize)
  std::uint32_t body = 0;
  std::uint32_t stamp = 0;       // the last query that reported it
};

class GridBroadPhase final : public bp_detail::BroadPhaseBase {
 public:
  explicit GridBroadPhase(double cell_size) : option_cell_(cell_size) {}

  BroadPhaseKind kind() const override { return BroadPhaseKind::Grid; }

  // Filled in body order; build() gathers them into the slots, in bucket order.
  std::span<Aabb> prepare(std::size_t n) override {
    boxes_.resize(n);
    return boxes_;
  }
  const Aabb& box(std::uint32_t i) const override { return slots_[pos_of_[i]].box; }
  void prefetch(std::uint32_t i, int level) const override {
    if (i >= pos_of_.size()) return;
    if (level == 0) {
      __builtin_prefetch(&pos_of_[i]);
      __builtin_prefetch(&active_[i]);
    } else {
      __builtin_prefetch(&slots_[pos_of_[i]]);
    }
  }

  void build(std::span<const std::uint8_t> active) override {
    const std::size_t n = boxes_.size();
    active_.assign(active.begin(), active.end());
    active_.resize(n, 0);
    slots_.resize(n);
    oversize_.clear();

    // One pass for the cell size and the range of the box centres (a pass each costs
    // memory bandwidth at a million bodies).
    double sum = 0.0, largest = 0.0;
    std::size_t count = 0;
    double lo_x = std::numeric_limits<double>::infinity(), hi_x = -lo_x, lo_y = lo_x, hi_y = -lo_x;
    auto extend_centres = [&](const Aabb& b) {
      const double cx = 0.5 * (static_cast<double>(b.min_x) + b.max_x);
      const double cy = 0.5 * (static_cast<double>(b.min_y) + b.max_y);
      lo_x = std::min(lo_x, cx);
      hi_x = std::max(hi_x, cx);
      lo_y = std::min(lo_y, cy);
      hi_y = std::max(hi_y, cy);
    };
    for (std::size_t i = 0; i < n; ++i) {
      if (!active_[i]) continue;
      const Aabb& b = boxes_[i];
      const double e = bp_detail::extent(b);
      sum += e;
      largest = std::max(largest, e);
      ++count;
      extend_centres(b);
    }
    const double mean = count > 0 ? sum / static_cast<double>(count) : 0.0;
    double cell = largest;
    if (mean > 0.0 && cell > 4.0 * mean) cell = 4.0 * mean;
    cell = std::max(cell, option_cell_);
    if (!(cell > 0.0)) cell = 1.0;
    cell_ = cell;
    inv_cell_ = 1.0 / cell;

    // The occupied cells (of the binned bodies: cell_of is monotone, so the cells of
    // the extreme centres). With oversize boxes (the cell capped), a pass without them.
    if (largest > cell_) {
      lo_x = lo_y = std::numeric_limits<double>::infinity();
      hi_x = hi_y = -lo_x;
      for (std::size_t i = 0; i < n; ++i) {
        if (!active_[i] || bp_detail::extent(boxes_[i]) > cell_) continue;
        const Aabb& b = boxes_[i];
        extend_centres(b);
      }
    }
    const bool any = lo_x <= hi_x;
    const std::int64_t cells_x =
        any ? static_cast<std::int64_t>(bp_detail::cell_of(hi_x, inv_cell_)) - bp_detail::cell_of(lo_x, inv_cell_) + 1 : 1;
    const std::int64_t cells_y =
        any ? static_cast<std::int64_t>(bp_detail::cell_of(hi_y, inv_cell_)) - bp_detail::cell_of(lo_y, inv_cell_) + 1 : 1;
    hash_.choose(count, cells_x, cells_y);

    // Each body's bucket (kNil: inactive or oversize), counted.
    // (Through local pointers: the stores into one array would otherwise make the
    // compiler reload the others' and the members' values in every iteration.)
    const std::uint32_t buckets = hash_.buckets;
    const bp_detail::TileHash hash = hash_;
    const double cell_edge = cell_;
    start_.assign(buckets + 2, 0);
    pos_of_.resize(n);
    std::uint32_t* const start = start_.data();
    std::uint32_t* const pos_of = pos_of_.data();
    const Aabb* const boxes = boxes_.data();
    const std::uint8_t* const act = active_.data();
    for (std::uint32_t i = 0; i < n; ++i) {
      pos_of[i] = kNil;
      if (!act[i]) continue;
      if (bp_detail::extent(boxes[i]) > cell_edge) {
        oversize_.push_back(i);
        continue;
      }
      std::int32_t cx, cy;
      centre_cell(boxes[i], cx, cy);
      const std::uint32_t b = hash(cx, cy);
      pos_of[i] = b;
      ++start[b + 2];
    }
    // Counting sort: start_[b + 1] becomes the fill cursor of bucket b, then its end.
    // Each body's slot is written whole where it lands (stamp 0: no query has it).
    std::uint32_t running = 0;
    for (std::uint32_t b = 0; b < buckets; ++b) {
      running += start[b + 2];
      start[b + 2] = running;
    }
    std::uint32_t tail = start[buckets + 1];   // unbinned bodies after the buckets
    Slot* const slots = slots_.data();
    for (std::uint32_t i = 0; i < n; ++i) {
      const std::uint32_t k = pos_of[i] == kNil ? tail++ : start[pos_of[i] + 1]++;
      Slot s;
      s.box = boxes[i];
      centre_cell(s.box, s.hx, s.hy);
      s.body = i;
      s.stamp = 0;
      slots[k] = s;
      pos_of[i] = k;
    }
    for (std::uint32_t o : oversize_) {
      slots_[pos_of_[o]].hx = kOversizeHome;
      slots_[pos_of_[o]].hy = kInList;
    }
    stamp_value_ = 0;
    if (extra_head_.size() == hash_.buckets) {
      for (std::uint32_t b : extra_used_) extra_head_[b] = kNil;
    } else {
      extra_head_.assign(hash_.buckets, kNil);
    }
    extra_used_.clear();
    extra_next_.clear();
    extra_body_.clear();
  }

  void pairs(std::vector<BodyPair>& out) override {
    // Each body's forward neighbours: the later bodies of its own cell, the cell to its
    // right, and the three cells of the row above. With the tiling unbroken there
    // (the usual case), its own and the right cell's buckets are consecutive, and so
    // are the three above: two runs of positions, each tested without a branch per
    // box (the overlap test mostly fails, and unpredictably). Bodies of other cells
    // that share those buckets are told apart by their home cells.
    // (Local copies: the pairs' stores would otherwise make the compiler reload the
    // members after each.)
    const bp_detail::TileHash hash = hash_;
    const std::uint32_t wmask = hash.wmask, hmask = hash.hmask;
    const std::uint32_t* const start = start_.data();
    const Slot* const slots = slots_.data();
    std::size_t used = out.size();
    for (std::uint32_t b = 0; b < hash.buckets; ++b) {
      const std::uint32_t end = start[b + 1];
      for (std::uint32_t k = start[b]; k < end; ++k) {
        const Slot& sk = slots[k];
        const std::int32_t cx = sk.hx, cy = sk.hy;
        const std::uint32_t tx = static_cast<std::uint32_t>(cx) & wmask;
        if (tx == 0 || tx == wmask || (static_cast<std::uint32_t>(cy) & hmask) == hmask) {
          pairs_generic(k, end, out, used);
          continue;
        }
        const std::uint32_t up = hash(cx, cy + 1);   // the bucket above: (cx, cy + 1)
        const std::uint32_t r0 = k + 1, r1 = start[b + 2];
        const std::uint32_t u0 = start[up - 1], u1 = start[up + 2];
        const std::size_t need = used + (r1 - r0) + (u1 - u0);
        if (out.size() < need) out.resize(std::max<std::size_t>(need, 2 * out.size() + 64));
        BodyPair* o = out.data();
        const Aabb a = sk.box;
        const std::uint32_t body = sk.body;
        const auto ucx = static_cast<std::uint32_t>(cx);
        for (std::uint32_t k2 = r0; k2 < r1; ++k2) {
          const Slot& s2 = slots[k2];
          const bool hit = overlaps_nb(a, s2.box) & (s2.hy == cy) & (static_cast<std::uint32_t>(s2.hx) - ucx <= 1u);
          o[used] = ordered(body, s2.body);
          used += hit;
        }
        const std::int32_t uy = cy + 1;
        for (std::uint32_t k2 = u0; k2 < u1; ++k2) {
          const Slot& s2 = slots[k2];
          const bool hit = overlaps_nb(a, s2.box) & (s2.hy == uy) & (static_cast<std::uint32_t>(s2.hx) - ucx + 1u <= 2u);
          o[used] = ordered(body, s2.body);
          used += hit;
        }
      }
    }
    out.resize(used);
    for (std::uint32_t o : oversize_) {
      const Aabb& a = box(o);
      for (std::uint32_t j = 0; j < active_.size(); ++j) {
        if (!active_[j] || j == o) continue;
        const Aabb& bj = box(j);
        if (bp_detail::extent(bj) > cell_ && j < o) continue;   // that pair is reported from j
        if (overlaps(a, bj)) push(out, o, j);
      }
    }
  }

  void query_box(const Aabb& q, std::uint32_t exclude, std::vector<std::uint32_t>& out) override {
    const std::uint32_t stamp = next_stamp();
    if (exclude < pos_of_.size()) slots_[pos_of_[exclude]].stamp = stamp;
    const double half = 0.75 * cell_;   // half a cell, and the quarter a home may drift
    const std::int32_t x0 = bp_detail::cell_of(q.min_x - half, inv_cell_);
    const std::int32_t x1 = bp_detail::cell_of(q.max_x + half, inv_cell_);
    const std::int32_t y0 = bp_detail::cell_of(q.min_y - half, inv_cell_);
    const std::int32_t y1 = bp_detail::cell_of(q.max_y + half, inv_cell_);
    const double cells = (static_cast<double>(x1) - x0 + 1.0) * (static_cast<double>(y1) - y0 + 1.0);
    if (cells > static_cast<double>(slots_.size())) {
      // A box wider than the whole scene's cells: test everyone.
      for (std::uint32_t j = 0; j < active_.size(); ++j) {
        const std::uint32_t k = pos_of_[j];
        if (active_[j] && first_visit(k, stamp) && overlaps(q, slots_[k].box)) out.push_back(j);
      }
      return;
    }
    // A row whose cells are consecutive buckets (the tiling does not wrap within it) and
    // hold no extra entries is one run of positions: scanned without a branch per box,
    // in the order the cell-by-cell scan below reports (bucket by bucket, each in
    // position order). Any body whose home moved within the row has an extra entry
    // there, so a run's bodies are at home: in the row and within [x0, x1].
    const std::uint32_t span = static_cast<std::uint32_t>(x1) - static_cast<std::uint32_t>(x0);
    const bool runs = span < hash_.wmask + 1u &&
                      (static_cast<std::uint32_t>(x0) & hash_.wmask) <= (static_cast<std::uint32_t>(x1) & hash_.wmask);
    for (std::int32_t y = y0;; ++y) {
      if (runs) {
        const std::uint32_t b0 = hash_(x0, y), b1 = b0 + span;
        std::uint32_t extras = kNil;
        for (std::uint32_t b = b0; b <= b1; ++b) extras &= extra_head_[b];
        if (extras == kNil) {
          const std::uint32_t p0 = start_[b0], p1 = start_[b1 + 1];
          std::size_t used = out.size();
          out.resize(used + (p1 - p0));
          std::uint32_t* o = out.data();
          const auto ux0 = static_cast<std::uint32_t>(x0);
          for (std::uint32_t k = p0; k < p1; ++k) {
            Slot& sl = slots_[k];
            const bool hit = (sl.hy == y) & (static_cast<std::uint32_t>(sl.hx) - ux0 <= span) & overlaps_nb(q, sl.box) &
                             (sl.stamp != stamp);
            o[used] = sl.body;
            used += hit;
            sl.stamp = hit ? stamp : sl.stamp;
          }
          out.resize(used);
          if (y == y1) break;
          continue;
        }
      }
      for (std::int32_t x = x0;; ++x) {
        const std::uint32_t b = hash_(x, y);
        for (std::uint32_t k = start_[b]; k < start_[b + 1]; ++k) visit(k, x, y, q, stamp, out);
        for (std::uint32_t e = extra_head_[b]; e != kNil; e = extra_next_[e]) {
          const std::uint32_t body = extra_body_[e];
          if (body & kTouchEntry) {
            const std::uint32_t j = body & ~kTouchEntry;
            const std::uint32_t k = pos_of_[j];
            if (overlaps(q, slots_[k].box) && first_visit(k, stamp)) out.push_back(j);
          } else {
            visit(pos_of_[body], x, y, q, stamp, out);
          }
        }
        if (x == x1) break;
      }
      if (y == y1) break;
    }
    for (std::uint32_t o : oversize_) {
      const std::uint32_t k = pos_of_[o];
      if (first_visit(k, stamp) && overlaps(q, slots_[k].box)) out.push_back(o);
    }
  }

  void grow(std::uint32_t i, const Aabb& b) override {
    Slot& s = slots_[pos_of_[i]];
    const bool was_active = active_[i] != 0;
    const bool was_oversize = was_active && s.hx == kOversizeHome;
    if (was_oversize && s.hy == kInList) {
      s.box = merge(s.box, b);
      return;
    }
    const Aabb old = s.box;
    s.box = was_active ? merge(old, b) : b;
    active_[i] = 1;
    if (was_oversize || bp_detail::extent(s.box) > cell_) {
      // Entries in the cells the box touches now and did not before (an oversize box
      // only grows); the list if there are too many.
      const CellRange now = cells_of(s.box);
      if (now.count() > kMaxTouchCells) {
        s.hx = kOversizeHome;
        s.hy = kInList;
        oversize_.push_back(i);
        return;
      }
      const CellRange before = was_oversize ? cells_of(old) : CellRange{1, 1, 0, 0};
      s.hx = kOversizeHome;
      s.hy = kInCells;
      for (std::int32_t y = now.y0; y <= now.y1; ++y) {
        for (std::int32_t x = now.x0; x <= now.x1; ++x) {
          if (!before.has(x, y)) add_extra(hash_(x, y), i | kTouchEntry);
        }
      }
      return;
    }
    if (was_active && near_home(s)) return;
    centre_cell(s.box, s.hx, s.hy);
    add_extra(hash_(s.hx, s.hy), i);
  }

  std::size_t memory_bytes() const override {
    return base_bytes() + slots_.capacity() * sizeof(Slot) +
           (start_.capacity() + pos_of_.capacity() + oversize_.capacity() + extra_head_.capacity() +
            extra_next_.capacity() + extra_body_.capacity() + extra_used_.capacity()) *
               sizeof(std::uint32_t);
  }

 private:
  struct CellRange {
    std::int32_t x0, y0, x1, y1;   // empty when x0 > x1
    std::int64_t count() const {
      return x1 < x0 ? 0 : (static_cast<std::int64_t>(x1) - x0 + 1) * (static_cast<std::int64_t>(y1) - y0 + 1);
    }
    bool has(std::int32_t x, std::int32_t y) const { return x >= x0 && x <= x1 && y >= y0 && y <= y1; }
  };
  CellRange cells_of(const Aabb& b) const {
    return {bp_detail::cell_of(b.min_x, inv_cell_), bp_detail::cell_of(b.min_y, inv_cell_),
            bp_detail::cell_of(b.max_x, inv_cell_), bp_detail::cell_of(b.max_y, inv_cell_)};
  }
  void add_extra(std::uint32_t bucket, std::uint32_t entry) {
    if (extra_head_[bucket] == kNil) extra_used_.push_back(bucket);
    extra_body_.push_back(entry);
    extra_next_.push_back(extra_head_[bucket]);
    extra_head_[bucket] = static_cast<std::uint32_t>(extra_body_.size() - 1);
  }
  // overlaps() without the short-circuit branches.
  static bool overlaps_nb(const Aabb& a, const Aabb& b) {
    return (a.min_x <= b.max_x) & (b.min_x <= a.max_x) & (a.min_y <= b.max_y) & (b.min_y <= a.max_y);
  }
  static BodyPair ordered(std::uint32_t i, std::uint32_t j) { return i < j ? BodyPair{i, j} : BodyPair{j, i}; }
  // The forward pairs of the body at position k (its bucket ends at `end`), each
  // neighbouring cell's bucket looked up through the hash: for cells where the tiling
  // wraps (and a scene wider or taller than the tiles).
  void pairs_generic(std::uint32_t k, std::uint32_t end, std::vector<BodyPair>& out, std::size_t& used) const {
    const auto emit = [&](std::uint32_t i, std::uint32_t j) {
      if (used == out.size()) out.resize(2 * out.size() + 64);
      out[used++] = ordered(i, j);
    };
    static constexpr std::int32_t kForward[4][2] = {{1, 0}, {-1, 1}, {0, 1}, {1, 1}};
    const Slot& sk = slots_[k];
    const Aabb& a = sk.box;
    const std::int32_t cx = sk.hx, cy = sk.hy;
    for (std::uint32_t k2 = k + 1; k2 < end; ++k2) {
      const Slot& s2 = slots_[k2];
      if (overlaps(a, s2.box) && s2.hx == cx && s2.hy == cy) emit(sk.body, s2.body);
    }
    for (int d = 0; d < 4; ++d) {
      const std::int64_t nx = static_cast<std::int64_t>(cx) + kForward[d][0];
      const std::int64_t ny = static_cast<std::int64_t>(cy) + kForward[d][1];
      if (nx > 2147483646 || nx < -2147483647 || ny > 2147483646) continue;
      const auto ncx = static_cast<std::int32_t>(nx), ncy = static_cast<std::int32_t>(ny);
      const std::uint32_t nb = hash_(ncx, ncy);
      for (std::uint32_t k2 = start_[nb]; k2 < start_[nb + 1]; ++k2) {
        const Slot& s2 = slots_[k2];
        if (overlaps(a, s2.box) && s2.hx == ncx && s2.hy == ncy) emit(sk.body, s2.body);
      }
    }
  }
  static void push(std::vector<BodyPair>& out, std::uint32_t i, std::uint32_t j) {
    out.push_back(i < j ? BodyPair{i, j} : BodyPair{j, i});
  }
  void centre_cell(const Aabb& b, std::int32_t& cx, std::int32_t& cy) const {
    cx = bp_detail::cell_of(0.5 * (static_cast<double>(b.min_x) + b.max_x), inv_cell_);
    cy = bp_detail::cell_of(0.5 * (static_cast<double>(b.min_y) + b.max_y), inv_cell_);
  }
  // The centre of the slot's box is within a quarter cell of its home cell.
  bool near_home(const Slot& s) const {
    const Aabb& b = s.box;
    const double cx = 0.5 * (static_cast<double>(b.min_x) + b.max_x);
    const double cy = 0.5 * (static_cast<double>(b.min_y) + b.max_y);
    const double q = 0.25 * cell_;
    // Strictly below the upper bound, as a centre binned by floor() is: queries rely on it.
    return cx >= s.hx * cell_ - q && cx < (s.hx + 1.0) * cell_ + q && cy >= s.hy * cell_ - q &&
           cy < (s.hy + 1.0) * cell_ + q;
  }
  void visit(std::uint32_t k, std::int32_t x, std::int32_t y, const Aabb& q, std::uint32_t stamp,
             std::vector<std::uint32_t>& out) {
    // Only the body's entry in its home cell counts: entries left behind by grow(),
    // other cells sharing the bucket and oversize boxes (no home) are skipped.
    Slot& s = slots_[k];
    if (s.hx != x || s.hy != y) return;
    if (overlaps(q, s.box) && s.stamp != stamp) {
      s.stamp = stamp;
      out.push_back(s.body);
    }
  }
  // A fresh stamp for one query; the slot at k is new to it when its stamp differs.
  std::uint32_t next_stamp() {
    if (++stamp_value_ == 0) {
      for (Slot& s : slots_) s.stamp = 0;
      stamp_value_ = 1;
    }
    return stamp_value_;
  }
  bool first_visit(std::uint32_t k, std::uint32_t stamp) {
    if (slots_[k].stamp == stamp) return false;
    slots_[k].stamp = stamp;
    return true;
  }

  double option_cell_ = 0.0;
  double cell_ = 1.0;
  double inv_cell_ = 1.0;
  bp_detail::TileHash hash_;
  std::vector<std::uint32_t> start_;    // bucket b holds positions [start_[b], start_[b + 1])
  std::vector<Slot> slots_;             // one per position; boxes_: the boxes as prepared
  std::vector<std::uint32_t> pos_of_;   // position of each body (its slot)
  std::vector<std::uint32_t> oversize_;
  std::vector<std::uint32_t> extra_head_, extra_next_, extra_body_;
  std::vector<std::uint32_t> extra_used_;   // buckets whose extra_head_ is set
};

}  // namespace

std::unique_ptr<BroadPhase> make_grid_broadphase(double cell_size) {
  return std::make_unique<GridBroadPhase>(cell_size);
}

}  // namespace physval
