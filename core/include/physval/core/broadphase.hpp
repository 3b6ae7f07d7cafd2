// Broad phase: most of the time nothing collides (lecture, section 8). Each body
// registers a box that bounds everything it can touch during the step (its swept
// path plus its radius); the broad phase hands out the pairs of bodies whose boxes
// overlap, and answers "who overlaps body i" when a collision sends i on a new path.
//
// Four methods, one interface, identical answers: every method reports exactly the
// pairs whose boxes overlap (inclusive), decided by the same predicate on the same
// boxes, so they differ only in cost.
#pragma once

#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <span>
#include <string>
#include <vector>

namespace physval {

// An axis-aligned box in float, rounded outwards from the double bounds it was made
// from, so it is always conservative and half the size of a double box.
struct Aabb {
  float min_x = 0.0f, min_y = 0.0f, max_x = -1.0f, max_y = -1.0f;
};

// Double to float, rounded outwards without a branch: moving the value out by 2^-23 of
// itself (plus a tiny absolute step) before the round-to-nearest conversion keeps
// the float on the outer side (conversion errs by at most 2^-24 relative).
inline float round_down(double v) {
  return static_cast<float>(v - (std::fabs(v) * 0x1.0p-23 + 1e-30));
}
inline float round_up(double v) {
  return static_cast<float>(v + (std::fabs(v) * 0x1.0p-23 + 1e-30));
}
inline Aabb make_aabb(double min_x, double min_y, double max_x, double max_y) {
  return {round_down(min_x), round_down(min_y), round_up(max_x), round_up(max_y)};
}
inline bool overlaps(const Aabb& a, const Aabb& b) {
  return a.min_x <= b.max_x && b.min_x <= a.max_x && a.min_y <= b.max_y && b.min_y <= a.max_y;
}
inline Aabb merge(const Aabb& a, const Aabb& b) {
  return {a.min_x < b.min_x ? a.min_x : b.min_x, a.min_y < b.min_y ? a.min_y : b.min_y,
          a.max_x > b.max_x ? a.max_x : b.max_x, a.max_y > b.max_y ? a.max_y : b.max_y};
}
inline bool contains(const Aabb& outer, const Aabb& inner) {
  return outer.min_x <= inner.min_x && outer.min_y <= inner.min_y && outer.max_x >= inner.max_x &&
         outer.max_y >= inner.max_y;
}

struct BodyPair {
  std::uint32_t a = 0;   // a < b
  std::uint32_t b = 0;
  friend bool operator==(BodyPair, BodyPair) = default;
  friend bool operator<(BodyPair x, BodyPair y) { return x.a != y.a ? x.a < y.a : x.b < y.b; }
};

enum class BroadPhaseKind : std::uint8_t {
  AllPairs,       // every pair: O(N^2), the reference
  Grid,           // uniform grid, cell = the largest box, each body in the cell of its centre
  MultiGrid,      // cells of any size, each body in every cell its box touches
  SortAndSweep,   // boxes sorted along x, swept within the widest reach
};
const char* broadphase_name(BroadPhaseKind k);
// Parses a name as written in a scenario ("all_pairs", "grid", "multigrid",
// "sort_and_sweep"); false if unknown.
bool parse_broadphase(const std::string& name, BroadPhaseKind& out);

class BroadPhase {
 public:
  virtual ~BroadPhase() = default;
  virtual BroadPhaseKind kind() const = 0;

  // Storage for n boxes (one per body), to fill before build(): the broad phase owns
  // the boxes so that grow() can extend them without a second copy.
  virtual std::span<Aabb> prepare(std::size_t n) = 0;

  // Registers the prepared box of every body i with active[i] != 0 (inactive bodies
  // are never reported). Reuses its storage: no allocation once it has seen a scene
  // this big.
  virtual void build(std::span<const std::uint8_t> active) = 0;

  // Appends every pair of active bodies with overlapping boxes, once each, a < b,
  // in no particular order.
  virtual void pairs(std::vector<BodyPair>& out) = 0;

  // Appends every active body j != i whose registered box overlaps i's, once each.
  void query(std::uint32_t i, std::vector<std::uint32_t>& out) { query_box(box(i), i, out); }

  // Appends every active body j != exclude whose registered box overlaps `box`, once
  // each (one query for the two bodies of an impact).
  virtual void query_box(const Aabb& box, std::uint32_t exclude, std::vector<std::uint32_t>& out) = 0;

  // Extends body i's registered box to also cover `box` (a body whose path changed
  // mid-step). Activates i if it was inactive. Later queries see the new box.
  virtual void grow(std::uint32_t i, const Aabb& box) = 0;

  // The registered box of body i.
  virtual const Aabb& box(std::uint32_t i) const = 0;

  // Hints for a caller that knows what it will touch soon; no effect on answers.
  // prefetch(i, 0): body i's index entry; prefetch(i, 1): its box (once level 0 has
  // had time to arrive).
  virtual void prefetch(std::uint32_t i, int level) const {
    (void)i;
    (void)level;
  }

  // Bytes of storage held.
  virtual std::size_t memory_bytes() const = 0;
};

// cell_size: for Grid a lower bound (the cell is at least the largest box), for
// MultiGrid the cell edge; 0 picks one from the boxes at each build.
std::unique_ptr<BroadPhase> make_broadphase(BroadPhaseKind kind, double cell_size = 0.0);

// prepare() + copy + build(): for tests and tools that hold their own boxes.
void build_broadphase(BroadPhase& bp, std::span<const Aabb> boxes, std::span<const std::uint8_t> active);

// What `auto` picks for bodies of these radii: all pairs for a few bodies, the uniform
// grid when sizes are alike (largest <= 4x the mean), the multigrid for a moderate
// spread (<= 64x), sort and sweep beyond.
BroadPhaseKind choose_broadphase(std::span<const double> radii);

}  // namespace physval
