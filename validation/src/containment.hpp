// Containment, measured after every engine step by the runner (inside the engine's child
// process): how deep bodies overlap each other or a barrier (max_penetration) and which
// bodies passed through a barrier they collide with (escaped_bodies). Documented in the
// README ("Metrics").
//
// Barriers are every static thing a scene can describe: walls, the four sides of each box,
// each segment of each surface, and static bodies (circles). A body escapes when the
// straight path of its centre from one step to the next crosses a barrier segment (from
// more than eps on one side of its line to more than eps on the other, at a point of the
// segment, within eps of its ends; a body that lands within eps of the line and later
// leaves it to the other side crosses too) or enters a static body's circle (the path,
// starting outside it, comes closer than its radius - eps to its centre), eps = 1e-9 x the
// scene's extent (at least 1 m). A closed container of any shape (a loop of walls, a box,
// closed surfaces, a mix) can be left only that way, and a body stepping over a thin wall
// is caught the same way. Pairs the collision matrix lets through (ignore, event) are left
// out. Particles (bodies created while the scene runs, points of their parent's group, which
// do not collide with their parent) are followed against the barriers the same way: a
// particle through a wall is an escape (before the seventh hunt they were not followed, and
// core's lecture mode let an explosion's particles out of a closed box, `ok`).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>
#include <unordered_map>
#include <vector>

#include "physval/core/scene.hpp"
#include "physval/validation/run_record.hpp"

namespace physval {

class ContainmentMonitor {
 public:
  explicit ContainmentMonitor(const Scene& scene);

  // The state at t = 0 (every body's starting point).
  void start(const std::vector<BodyState>& states);
  // The state after a step that ended at time t.
  void observe(double t, const std::vector<BodyState>& states);

  const ContainmentRecord& record() const { return record_; }

  // The name of object i (a particle, i >= the scene's bodies: "emitter#k"), read once when
  // it first appears, to find its emitter (its parent and group). Without it (or for a name
  // no emitter owns), a particle is taken as the first emitter's.
  void set_object_names(std::function<std::string(std::size_t)> name_of) { name_of_ = std::move(name_of); }

  // Tests and benchmarks only: the moving pairs by the plain x sweep, never through
  // horizontal strips, or through the strips from 32 bodies on (by default from 512) (both
  // must find the same pairs in the same order: test Containment.StripsEqualPlainSweep*).
  void use_plain_sweep(bool plain) { plain_sweep_ = plain; }
  void use_strips(bool strips) { force_strips_ = strips; }
  // Tests only: every moving pair the filters pass goes through the full tests, none is left
  // out as apart all step (both must give the same record: test Containment.FarPairSkip*);
  // and how many were left out.
  void use_full_pair_tests(bool full) { full_pair_tests_ = full; }
  std::uint64_t far_pairs_skipped() const { return far_pairs_skipped_; }

 private:
  struct Barrier {
    bool circle = false;
    Vec2 a, b;        // segment ends; a circle's centre is a
    Vec2 dir;         // unit, a -> b
    double len = 0.0;
    double radius = 0.0;   // circles
    double eps = 1e-9;     // round-off of tests against it: eps_at(a, b, radius)
    std::size_t group = 0;   // index into barrier groups
    std::size_t body = static_cast<std::size_t>(-1);   // a static body's index
    // A segment's barrier: its index among the walls, then the boxes, then the surfaces
  // (scene.walls.size() + k for box k, and past those for surface k): a skipped impact names
  // it to the comparator, past the bodies.
  std::size_t owner = static_cast<std::size_t>(-1);
    std::string what;      // "wall 'left'"
    // A pinch: the narrowest span between two barriers that do not touch (the gap of a drain
    // between two floor pieces, two pegs, a peg and a wall), a and b its ends on them. No
    // barrier itself: a body wider than it (2 r (1 - kGrazeSlop) > width) that crosses it
    // went through an opening narrower than itself, an escape as through a wall.
    bool pinch = false;
    double width = 0.0;
    std::size_t group2 = 0;   // the second barrier's group (both must block the body)
  };
  void add_pinches(double max_radius);
  void candidates(Vec2 lo, Vec2 hi);
  void track_particles(std::size_t count);
  std::string name(std::size_t i) const;   // a scene body's or a particle's
  // A particle's parent (none for a scene body: -1, matching no barrier's body).
  std::size_t parent_of(std::size_t i) const { return i < parent_.size() ? parent_[i] : static_cast<std::size_t>(-1); }
  void penetration(double depth, double t, const std::string& what);
  // A graze for the comparator: kept while fewer than ContainmentRecord::kMaxGrazes are,
  // else counted as dropped (the comparator then does not let the run be ok on the kept).
  void keep_graze(const ContainmentRecord::Graze& g) {
    if (record_.grazes.size() < ContainmentRecord::kMaxGrazes) {
      record_.grazes.push_back(g);
      return;
    }
    if (record_.grazes_dropped++ == 0) record_.first_dropped_graze_time = g.time;
  }

  const Scene& scene_;
  std::vector<Barrier> barriers_;
  std::vector<std::vector<char>> blocks_;   // [body group][barrier group]: they collide
  std::vector<std::size_t> body_group_;     // scene body -> body group
  std::vector<char> pair_collides_;         // [body group x body group]
  std::size_t n_body_groups_ = 0;
  std::vector<std::size_t> moving_;         // scene bodies that are not static
  std::vector<std::size_t> order_;          // moving_, kept sorted by x - radius
  // Per scene body, filled once (radius) or at each observe (the rest): compact arrays
  // the sweep reads instead of the scene's BodyDefs and the engine's BodyStates.
  std::vector<double> radius_;
  std::vector<double> lo_;                  // left end of the box swept over the step
  std::vector<Vec2> pos_;
  std::vector<char> alive_;
  // lo_ and the y interval swept over the step (NaN: not alive), in order_'s order
  std::vector<double> sorted_lo_;
  struct YRange {
    double lo, hi;
  };
  std::vector<YRange> sorted_y_;
  std::vector<YRange> strip_y_;
  std::vector<std::uint32_t> near_;           // observe's scratch: one body's candidates
  // Horizontal strips over the swept y intervals' lower ends (observe): per strip, its
  // bodies' positions in x order, their left ends and y intervals, and a cursor past those
  // already swept; strip_of_ per x-order position.
  bool plain_sweep_ = false;
  bool force_strips_ = false;
  bool full_pair_tests_ = false;
  std::uint64_t far_pairs_skipped_ = 0;
  std::vector<std::uint32_t> strip_of_, strip_start_, strip_cursor_, strip_item_;
  std::vector<double> strip_lo_;
  double max_radius_ = 0.0;                    // of the moving bodies
  bool pairs_possible_ = true;                 // false: every moving body is a point (radius 0)
  std::vector<std::uint32_t> on_line_count_;   // on_line_ entries of the body
  // Each barrier's bounding box, widened by 2 eps: a body's path whose box misses it
  // can neither touch nor cross it (see observe).
  std::vector<Vec2> barrier_lo_, barrier_hi_;
  // Few barriers: an open box that overlaps none of the barrier boxes above (for each,
  // beyond one of its sides); a body whose swept box lies strictly inside it skips them.
  Vec2 open_lo_{0.0, 0.0}, open_hi_{0.0, 0.0};   // empty unless open_lo_ < open_hi_
  // 1e-9 of the largest coordinate among p and q, grown by r (at least 1e-9 m): the
  // round-off allowed a test that subtracts those points' coordinates.
  static double eps_at(Vec2 p, Vec2 q, double r) {
    return 1e-9 * std::max({1.0, std::fabs(p.x) + r, std::fabs(p.y) + r, std::fabs(q.x) + r, std::fabs(q.y) + r});
  }

  // A uniform grid over the barriers (used when there are many).
  bool use_grid_ = false;
  double cell_ = 1.0;
  std::unordered_map<std::uint64_t, std::vector<std::uint32_t>> grid_;
  std::vector<std::uint32_t> always_;       // barriers too large for the grid
  std::vector<std::uint32_t> stamp_;
  std::uint32_t query_ = 0;
  std::vector<std::uint32_t> found_;

  // (body, barrier segment) -> the side a body came from when it landed within eps of
  // the segment's line: leaving to the other side later is a crossing too.
  std::unordered_map<std::uint64_t, signed char> on_line_;
  std::vector<Vec2> previous_, previous_velocity_;
  double previous_time_ = 0.0;
  std::vector<char> previous_alive_, escaped_;
  ContainmentRecord record_;
  // Particles: object indices from scene.bodies.size() on, as they appear; each one's parent
  // (a scene body index: a static parent's circle is no barrier to its own particles).
  std::function<std::string(std::size_t)> name_of_;
  std::vector<std::size_t> parent_;   // per object index (scene bodies: unused)
  std::size_t tracked_ = 0;           // objects the arrays hold
};

}  // namespace physval
