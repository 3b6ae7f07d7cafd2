#include "containment.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <tuple>

namespace physval {

namespace {

constexpr std::size_t kBruteForceBarriers = 16;
// Fewer moving bodies: the plain sweep. Its x windows hold about 10 bodies in circle_gas
// (200), where the strips' own passes cost more than they save (BM_ContainmentCircleGasRun
// 4.1-4.7 against 4.8-5.2 ms for core's run, 4.5-5.2 against 5.0-5.7 ms for Box2D's,
// alternated, load 3-9); at 1,000 (BM_ContainmentObserveGas/1000) neither wins clearly.
constexpr std::size_t kMinStripBodies = 512;
constexpr std::size_t kMinForcedStripBodies = 32;
constexpr double kMaxCellsPerBarrier = 4096.0;

std::int64_t cell_index(double x, double inv) {
  return static_cast<std::int64_t>(std::floor(std::clamp(x * inv, -1e9, 1e9)));
}

std::uint64_t cell_key(std::int64_t x, std::int64_t y) {
  return (static_cast<std::uint64_t>(static_cast<std::uint32_t>(x)) << 32) | static_cast<std::uint32_t>(y);
}

double segment_distance(Vec2 p, Vec2 a, Vec2 dir, double len) {
  const double u = std::clamp(dot(p - a, dir), 0.0, len);
  return length(p - (a + dir * u));
}

}  // namespace

ContainmentMonitor::ContainmentMonitor(const Scene& scene) : scene_(scene) {
  std::map<std::string, std::size_t> barrier_groups, body_groups;
  auto group_of = [](std::map<std::string, std::size_t>& m, const std::string& g) {
    return m.emplace(g, m.size()).first->second;
  };
  auto add_segment = [&](Vec2 a, Vec2 b, const StaticMaterial& m, const std::string& what,
                         std::size_t owner) {
    Barrier s;
    s.a = a;
    s.b = b;
    s.len = length(b - a);
    if (!(s.len > 0.0)) return;
    s.dir = (b - a) / s.len;
    s.group = group_of(barrier_groups, m.group);
    s.what = what;
    s.owner = owner;
    barriers_.push_back(std::move(s));
  };
  for (std::size_t k = 0; k < scene.walls.size(); ++k) {
    const WallDef& w = scene.walls[k];
    add_segment(w.from, w.to, w.material, "wall '" + w.name + "'", k);
  }
  for (std::size_t j = 0; j < scene.boxes.size(); ++j) {
    const BoxDef& b = scene.boxes[j];
    const Vec2 c[4] = {b.min, {b.max.x, b.min.y}, b.max, {b.min.x, b.max.y}};
    for (int k = 0; k < 4; ++k) add_segment(c[k], c[(k + 1) % 4], b.material, "box '" + b.name + "'", scene.walls.size() + j);
  }
  for (std::size_t j = 0; j < scene.surfaces.size(); ++j) {
    const SurfaceDef& s = scene.surfaces[j];
    for (std::size_t k = 0; k + 1 < s.points.size(); ++k) {
      add_segment(s.points[k], s.points[k + 1], s.material, "surface '" + s.name + "'",
                  scene.walls.size() + scene.boxes.size() + j);
    }
  }
  double extent = 1.0, max_radius = 0.0;
  for (std::size_t i = 0; i < scene.bodies.size(); ++i) {
    const BodyDef& d = scene.bodies[i];
    const double r = d.shape == ShapeKind::Point ? 0.0 : d.radius;
    extent = std::max({extent, std::fabs(d.position.x) + r, std::fabs(d.position.y) + r});
    body_group_.push_back(group_of(body_groups, d.group));
    if (d.is_static) {
      if (!(r > 0.0)) continue;   // a static point is nothing to pass through
      Barrier c;
      c.circle = true;
      c.a = c.b = d.position;
      c.radius = r;
      c.body = i;
      c.group = group_of(barrier_groups, d.group);
      c.what = "static body '" + d.name + "'";
      barriers_.push_back(std::move(c));
    } else {
      moving_.push_back(i);
      max_radius = std::max(max_radius, r);
    }
  }
  // Round-off is local: a test between a body and a barrier, or two bodies, is as exact as
  // the coordinates it subtracts, so each barrier carries 1e-9 of its own coordinates (at
  // least 1e-9 m) and each test takes the larger of that and its bodies' (eps_at). One
  // scale for the whole scene let a far object blind every test: a ball tunnelling out of
  // a 2 m box was not an escape in a scene that also held the Sun 1 AU away (the tolerance
  // 150 m), nor beside a body parked at 1e11 m (the fifteenth hunt).
  for (Barrier& b : barriers_) {
    b.eps = eps_at(b.a, b.b, b.circle ? b.radius : 0.0);
    extent = std::max({extent, std::fabs(b.a.x), std::fabs(b.a.y), std::fabs(b.b.x), std::fabs(b.b.y)});
  }
  for (const BodyDef& d : scene.bodies) radius_.push_back(d.shape == ShapeKind::Point ? 0.0 : d.radius);
  pairs_possible_ = std::any_of(moving_.begin(), moving_.end(), [&](std::size_t i) { return radius_[i] != 0.0; });
  max_radius_ = max_radius;
  add_pinches(max_radius);
  for (const Barrier& b : barriers_) {
    const double r = b.circle ? b.radius : 0.0;
    barrier_lo_.push_back({std::min(b.a.x, b.b.x) - r - 2.0 * b.eps, std::min(b.a.y, b.b.y) - r - 2.0 * b.eps});
    barrier_hi_.push_back({std::max(b.a.x, b.b.x) + r + 2.0 * b.eps, std::max(b.a.y, b.b.y) + r + 2.0 * b.eps});
  }

  // The open box, grown from the moving bodies' mean position: each barrier box is left
  // out by the side of it that leaves the most room around that point (the inside of a
  // walled box is the box less 2 eps). Only the skip below reads it, and only to skip what
  // the barrier boxes' own test would skip, so a poor box costs speed, never a check.
  if (!barriers_.empty() && !moving_.empty()) {
    Vec2 seed{0.0, 0.0};
    for (const std::size_t i : moving_) seed = seed + scene.bodies[i].position;
    seed = seed / static_cast<double>(moving_.size());
    constexpr double kInf = std::numeric_limits<double>::infinity();
    Vec2 lo{-kInf, -kInf}, hi{kInf, kInf};
    bool open = std::isfinite(seed.x) && std::isfinite(seed.y);
    for (std::size_t k = 0; k < barriers_.size() && open; ++k) {
      const Vec2 blo = barrier_lo_[k], bhi = barrier_hi_[k];
      // The room each side leaves around the seed (negative: the seed is not beyond it).
      const double room[4] = {blo.x - seed.x, seed.x - bhi.x, blo.y - seed.y, seed.y - bhi.y};
      const int side = static_cast<int>(std::max_element(room, room + 4) - room);
      if (!(room[side] > 0.0)) open = false;   // the seed is inside this box (or it is NaN)
      else if (side == 0) hi.x = std::min(hi.x, blo.x);
      else if (side == 1) lo.x = std::max(lo.x, bhi.x);
      else if (side == 2) hi.y = std::min(hi.y, blo.y);
      else lo.y = std::max(lo.y, bhi.y);
    }
    if (open && lo.x < hi.x && lo.y < hi.y) {
      open_lo_ = lo;
      open_hi_ = hi;
    }
  }

  std::vector<std::string> bg_names(barrier_groups.size()), mg_names(body_groups.size());
  for (const auto& [name, id] : barrier_groups) bg_names[id] = name;
  for (const auto& [name, id] : body_groups) mg_names[id] = name;
  n_body_groups_ = mg_names.size();
  blocks_.assign(n_body_groups_, std::vector<char>(bg_names.size(), 0));
  pair_collides_.assign(n_body_groups_ * n_body_groups_, 0);
  for (std::size_t g = 0; g < n_body_groups_; ++g) {
    for (std::size_t h = 0; h < bg_names.size(); ++h) blocks_[g][h] = response_between(scene, mg_names[g], bg_names[h]).collide;
    for (std::size_t h = 0; h < n_body_groups_; ++h) {
      pair_collides_[g * n_body_groups_ + h] = response_between(scene, mg_names[g], mg_names[h]).collide;
    }
  }
  // Escapes apply when some moving body collides with some barrier.
  bool any = false;
  for (std::size_t i : moving_) {
    for (const Barrier& b : barriers_) any = any || blocks_[body_group_[i]][b.group];
  }
  // So do passes between moving bodies (one centre inside the other) when any two collide.
  for (std::size_t p = 0; p < moving_.size() && !any; ++p) {
    for (std::size_t q = p + 1; q < moving_.size() && !any; ++q) {
      any = pair_collides_[body_group_[moving_[p]] * n_body_groups_ + body_group_[moving_[q]]] != 0;
    }
  }
  // Or particles: an emitter's particles are points of its parent's group.
  for (const EmitterDef& e : scene.emitters) {
    const int found = scene.body_index(e.parent);
    if (found < 0) continue;
    const auto parent = static_cast<std::size_t>(found);
    for (const Barrier& b : barriers_) {
      any = any || (blocks_[body_group_[parent]][b.group] && !(b.circle && b.body == parent));
    }
  }
  if (any) record_.escaped_bodies = 0;

  use_grid_ = barriers_.size() > kBruteForceBarriers;
  stamp_.assign(barriers_.size(), 0);
  if (use_grid_) {
    double total = 0.0;
    for (const Barrier& b : barriers_) total += b.circle ? 2.0 * b.radius : b.len;
    cell_ = std::max({total / static_cast<double>(barriers_.size()), 4.0 * max_radius, 1e-6 * extent});
    const double inv = 1.0 / cell_;
    for (std::uint32_t k = 0; k < barriers_.size(); ++k) {
      const Barrier& b = barriers_[k];
      const double r = b.circle ? b.radius : 0.0;
      const std::int64_t x0 = cell_index(std::min(b.a.x, b.b.x) - r, inv), x1 = cell_index(std::max(b.a.x, b.b.x) + r, inv);
      const std::int64_t y0 = cell_index(std::min(b.a.y, b.b.y) - r, inv), y1 = cell_index(std::max(b.a.y, b.b.y) + r, inv);
      if (static_cast<double>(x1 - x0 + 1) * static_cast<double>(y1 - y0 + 1) > kMaxCellsPerBarrier) {
        always_.push_back(k);
        continue;
      }
      for (std::int64_t y = y0; y <= y1; ++y) {
        for (std::int64_t x = x0; x <= x1; ++x) grid_[cell_key(x, y)].push_back(k);
      }
    }
  }
}

// The pinches: for each two barriers that do not touch (apart by more than eps) but come
// closer than the widest moving body's diameter, their closest points. Two segments that do
// not cross are closest at an end point of one; a circle's closest point to a segment is
// along the normal from the segment's closest point. Found by a sweep over the barriers'
// boxes in x (each box grown by the widest diameter), so a long surface costs its
// neighbours, not its square.
void ContainmentMonitor::add_pinches(double max_radius) {
  const double reach = 2.0 * max_radius * (1.0 - ContainmentRecord::kGrazeSlop);
  if (!(reach > 0.0) || barriers_.size() < 2) return;
  const std::size_t nb = barriers_.size();
  std::vector<Vec2> lo(nb), hi(nb);
  std::vector<std::size_t> order(nb);
  for (std::size_t k = 0; k < nb; ++k) {
    const Barrier& b = barriers_[k];
    const double r = b.circle ? b.radius : 0.0;
    lo[k] = {std::min(b.a.x, b.b.x) - r, std::min(b.a.y, b.b.y) - r};
    hi[k] = {std::max(b.a.x, b.b.x) + r, std::max(b.a.y, b.b.y) + r};
    order[k] = k;
  }
  std::sort(order.begin(), order.end(), [&](std::size_t x, std::size_t y) { return lo[x].x < lo[y].x || (lo[x].x == lo[y].x && x < y); });
  auto closest_on = [](const Barrier& s, Vec2 p) { return s.a + s.dir * std::clamp(dot(p - s.a, s.dir), 0.0, s.len); };
  auto crosses = [&](const Barrier& s, const Barrier& o) {   // the segments meet (within eps)
    const double a0 = cross(s.dir, o.a - s.a), a1 = cross(s.dir, o.b - s.a);
    const double b0 = cross(o.dir, s.a - o.a), b1 = cross(o.dir, s.b - o.a);
    const double e = std::max(s.eps, o.eps);
    return ((a0 > e && a1 < -e) || (a0 < -e && a1 > e)) && ((b0 > e && b1 < -e) || (b0 < -e && b1 > e));
  };
  std::vector<Barrier> found;
  for (std::size_t x = 0; x < nb; ++x) {
    const std::size_t k = order[x];
    for (std::size_t y = x + 1; y < nb && lo[order[y]].x <= hi[k].x + reach; ++y) {
      const std::size_t l = order[y];
      if (lo[l].y > hi[k].y + reach || hi[l].y < lo[k].y - reach) continue;
      const Barrier& A = barriers_[k];
      const Barrier& B = barriers_[l];
      Vec2 pa, pb;   // the closest points, on A and on B
      double width;
      if (A.circle && B.circle) {
        const Vec2 d = B.a - A.a;
        const double dl = length(d);
        if (!(dl > 0.0)) continue;
        width = dl - A.radius - B.radius;
        pa = A.a + d * (A.radius / dl);
        pb = B.a - d * (B.radius / dl);
      } else if (A.circle || B.circle) {
        const Barrier& C = A.circle ? A : B;
        const Barrier& S = A.circle ? B : A;
        const Vec2 q = closest_on(S, C.a);
        const Vec2 d = q - C.a;
        const double dl = length(d);
        if (!(dl > 0.0)) continue;
        width = dl - C.radius;
        const Vec2 on_c = C.a + d * (C.radius / dl);
        pa = A.circle ? on_c : q;
        pb = A.circle ? q : on_c;
      } else {
        if (crosses(A, B)) continue;
        width = std::numeric_limits<double>::infinity();
        for (const auto& [p, s, from_a] : {std::tuple{A.a, &B, true}, std::tuple{A.b, &B, true},
                                           std::tuple{B.a, &A, false}, std::tuple{B.b, &A, false}}) {
          const Vec2 q = closest_on(*s, p);
          const double dl = length(q - p);
          if (dl < width) {
            width = dl;
            pa = from_a ? p : q;
            pb = from_a ? q : p;
          }
        }
      }
      if (!(width > std::max(A.eps, B.eps)) || !(width < reach)) continue;   // touching, joined, or wide enough for every body
      Barrier g;
      g.pinch = true;
      g.a = pa;
      g.b = pb;
      g.len = length(pb - pa);
      if (!(g.len > 0.0)) continue;
      g.dir = (pb - pa) / g.len;
      g.width = width;
      g.eps = std::max(A.eps, B.eps);
      g.group = A.group;
      g.group2 = B.group;
      g.what = "the gap between " + A.what + " and " + B.what;
      found.push_back(std::move(g));
    }
  }
  for (Barrier& g : found) barriers_.push_back(std::move(g));
}

void ContainmentMonitor::candidates(Vec2 lo, Vec2 hi) {
  found_.clear();
  if (!use_grid_) {
    for (std::uint32_t k = 0; k < barriers_.size(); ++k) found_.push_back(k);
    return;
  }
  const double inv = 1.0 / cell_;
  const double pad = eps_at(lo, hi, 0.0);   // the body's own round-off; each barrier's box carries its own
  const std::int64_t x0 = cell_index(lo.x - pad, inv), x1 = cell_index(hi.x + pad, inv);
  const std::int64_t y0 = cell_index(lo.y - pad, inv), y1 = cell_index(hi.y + pad, inv);
  if (static_cast<double>(x1 - x0 + 1) * static_cast<double>(y1 - y0 + 1) > static_cast<double>(barriers_.size())) {
    for (std::uint32_t k = 0; k < barriers_.size(); ++k) found_.push_back(k);   // a long path: test them all
    return;
  }
  if (++query_ == 0) {
    std::fill(stamp_.begin(), stamp_.end(), 0);
    query_ = 1;
  }
  for (std::uint32_t k : always_) {
    stamp_[k] = query_;
    found_.push_back(k);
  }
  for (std::int64_t y = y0; y <= y1; ++y) {
    for (std::int64_t x = x0; x <= x1; ++x) {
      const auto it = grid_.find(cell_key(x, y));
      if (it == grid_.end()) continue;
      for (std::uint32_t k : it->second) {
        if (stamp_[k] == query_) continue;
        stamp_[k] = query_;
        found_.push_back(k);
      }
    }
  }
}

void ContainmentMonitor::track_particles(std::size_t count) {
  if (count <= tracked_) return;
  previous_.resize(count, Vec2{});
  previous_velocity_.resize(count, Vec2{});
  previous_alive_.resize(count, 0);
  escaped_.resize(count, 0);
  pos_.resize(count, Vec2{});
  alive_.resize(count, 0);
  lo_.resize(count, 0.0);
  radius_.resize(count, 0.0);
  on_line_count_.resize(count, 0);
  parent_.resize(count, static_cast<std::size_t>(-1));
  body_group_.resize(count, 0);
  for (std::size_t i = tracked_; i < count; ++i) {
    // Its emitter by its name ("emitter#k"); the first emitter without one.
    const EmitterDef* em = scene_.emitters.empty() ? nullptr : &scene_.emitters.front();
    if (name_of_) {
      const std::string name = name_of_(i);
      const std::string emitter = name.substr(0, name.rfind('#'));
      for (const EmitterDef& e : scene_.emitters) {
        if (e.name == emitter) em = &e;
      }
    }
    const int parent = em ? scene_.body_index(em->parent) : -1;
    if (parent >= 0) {
      parent_[i] = static_cast<std::size_t>(parent);
      body_group_[i] = body_group_[parent_[i]];
    }
  }
  tracked_ = count;
}

std::string ContainmentMonitor::name(std::size_t i) const {
  if (i < scene_.bodies.size()) return scene_.bodies[i].name;
  return name_of_ ? name_of_(i) : "particle " + std::to_string(i - scene_.bodies.size());
}

void ContainmentMonitor::penetration(double depth, double t, const std::string& what) {
  if (depth > record_.max_penetration) {
    record_.max_penetration = depth;
    record_.max_penetration_time = t;
    record_.max_penetration_what = what;
  }
}

void ContainmentMonitor::start(const std::vector<BodyState>& states) {
  const std::size_t nb = std::min(states.size(), scene_.bodies.size());
  previous_.assign(scene_.bodies.size(), Vec2{});
  previous_velocity_.assign(scene_.bodies.size(), Vec2{});
  previous_time_ = 0.0;
  previous_alive_.assign(scene_.bodies.size(), 0);
  escaped_.assign(scene_.bodies.size(), 0);
  for (std::size_t i = 0; i < nb; ++i) {
    previous_[i] = states[i].position;
    previous_velocity_[i] = states[i].velocity;
    previous_alive_[i] = states[i].alive ? 1 : 0;
  }
  // A body that starts within eps of a segment's line (a point put on a floor up to
  // round-off) is on the side its offset says: leaving the line to the other side later is
  // a crossing, as for one that landed there. Exactly on the line says no side; left out.
  for (std::size_t i : moving_) {
    if (i >= nb || !states[i].alive) continue;
    const Vec2 p = states[i].position;
    for (std::size_t k = 0; k < barriers_.size(); ++k) {
      const Barrier& b = barriers_[k];
      if (b.circle || !blocks_[body_group_[i]][b.group]) continue;
      const double d = cross(b.dir, p - b.a), u = dot(p - b.a, b.dir);
      const double e = std::max(b.eps, eps_at(p, p, 0.0));
      if (d != 0.0 && std::abs(d) <= e && u >= -e && u <= b.len + e) {
        on_line_[static_cast<std::uint64_t>(i) * barriers_.size() + k] = static_cast<signed char>(d > 0.0 ? 1 : -1);
      }
    }
  }
  order_ = moving_;
  lo_.assign(scene_.bodies.size(), 0.0);
  pos_.assign(scene_.bodies.size(), Vec2{});
  alive_.assign(scene_.bodies.size(), 0);
  on_line_count_.assign(scene_.bodies.size(), 0);
  tracked_ = scene_.bodies.size();
  record_.measured = true;
  observe(0.0, states);
}

void ContainmentMonitor::observe(double t, const std::vector<BodyState>& states) {
  const std::size_t nb = std::min(states.size(), scene_.bodies.size());
  // Where body i was after the step before (its position now if it just appeared).
  auto before = [&](std::size_t i) { return previous_alive_[i] ? previous_[i] : pos_[i]; };
  // The moving bodies' positions, liveness and the left ends of their boxes swept over the
  // step, read once into compact arrays.
  for (const std::size_t i : moving_) {
    const Vec2 x = i < nb ? states[i].position : scene_.bodies[i].position;
    pos_[i] = x;
    alive_[i] = i < nb && states[i].alive && is_finite(states[i].position);
    lo_[i] = std::min(x.x, before(i).x) - radius_[i];
  }
  // Particles (objects beyond the scene's bodies), against the barriers only.
  const std::size_t n_objects = scene_.emitters.empty() ? scene_.bodies.size() : std::max(states.size(), scene_.bodies.size());
  track_particles(n_objects);
  for (std::size_t i = scene_.bodies.size(); i < n_objects; ++i) {
    pos_[i] = states[i].position;
    alive_[i] = states[i].alive && is_finite(states[i].position);
  }
  // How far body i's path can have strayed from its chord in the step: at most the smaller
  // of |dx - v0 h| and |dx - v1 h| (0 for a flight at either velocity, explicit or
  // semi-implicit Euler's; for one bounce at time s, |dv| (h - s) and |dv| s, while the
  // path's corner is |dv| s (h - s) / h from the chord). Until the eighteenth hunt the mean
  // velocity's reading (Verlet's flight) was taken too, and a bounce in mid-step reads 0
  // there though its corner is |dv| h / 4 off the chord: core's exact runs of 40 circles of
  // 5 and 30 cm at 10-30 m/s in a box, at dt 1/60 and 1/20, were `diverged` with 2-8 bodies
  // "passed into" others they had bounced off (max penetration 0).
  const double h = t - previous_time_;
  auto bend = [&](std::size_t i) {
    if (!previous_alive_[i] || i >= nb) return 0.0;
    const Vec2 dx = pos_[i] - previous_[i], v0 = previous_velocity_[i], v1 = states[i].velocity;
    return std::min(length(dx - v0 * h), length(dx - v1 * h));
  };
  // How far a body's step is from one straight flight at an unchanged velocity: its
  // displacement against both the velocity it started and the one it ended with (a
  // collision inside the step changes the velocity, so this is at least |dv| h / 2).
  // The uniform field is taken out first: every moving scene body feels it, and a free
  // flight under it changes the velocity by g h and moves the body by v0 h + c g h^2 with
  // c = 0, 1/2 or 1 (explicit Euler, Verlet and the exact flight, semi-implicit Euler), so
  // a step that met nothing has no kink under any of them. Without this, a free flight's
  // own fall (g h^2 / 2) read as a kink and no pass between bodies was judged in a field
  // at a coarse step or between small balls (two 0.5 m balls 0.6 m apart at dt 0.25 s,
  // 1 cm balls at dt 1/60: Bullet, Chipmunk and ODE let them through, `ok`; the same
  // scenes without gravity were `diverged`). With no field it is the test it was.
  // A body on a support does not fall: its step is straight as it is, so the smaller of the
  // two readings is the step's kink (a collision changes the velocity by far more than g h,
  // and shows in both).
  const Vec2 gh = scene_.world.gravity * h;
  auto kink = [&](std::size_t i) {
    if (!previous_alive_[i] || i >= nb) return 0.0;
    const Vec2 dx = pos_[i] - previous_[i], v0 = previous_velocity_[i], v1 = states[i].velocity;
    double best = std::max(length(dx - v0 * h), length(dx - v1 * h));
    if (gh.x == 0.0 && gh.y == 0.0) return best;
    for (const double c : {0.0, 0.5, 1.0}) {
      const Vec2 d = dx - gh * (c * h);
      best = std::min(best, std::max(length(d - v0 * h), length(d - (v1 - gh) * h)));
    }
    return best;
  };

  // A step is also one straight flight when the body moved at the velocity it ended with
  // (x1 = x0 + v1 h: Box2D, ODE and semi-implicit Euler move each step at the new velocity,
  // so a velocity changed at the step's start, by a contact or Box2D's speed cap, leaves the
  // chord its path); a collision inside the step matches neither this nor kink.
  auto straight_either = [&](std::size_t i) {
    if (!previous_alive_[i] || i >= nb) return 0.0;
    return std::min(kink(i), length(pos_[i] - previous_[i] - states[i].velocity * h));
  };

  // Moving pairs: a sweep over x of each body's box swept over the step (a pair that
  // passed right through each other within one step overlaps there, not at its ends), the
  // order kept from the step before (insertion sort is linear on an almost sorted list).
  // The sort compares the left ends laid out in the order's order (sorted_lo_, gathered
  // first), moving them with the order: the same comparisons on the same values as
  // reading lo_ through the order, without the indirection.
  // Only points move (orbits, projectiles): no pair of them can overlap or count as passed
  // into each other (the pair test below leaves every such pair at once), so the sweep is
  // skipped as a whole; the barriers are still checked for every body.
  const std::size_t n = pairs_possible_ ? order_.size() : 0;
  sorted_lo_.resize(n);
  for (std::size_t p = 0; p < n; ++p) sorted_lo_[p] = lo_[order_[p]];
  for (std::size_t p = 1; p < n; ++p) {
    const std::size_t v = order_[p];
    const double key = sorted_lo_[p];
    std::size_t q = p;
    while (q > 0 && sorted_lo_[q - 1] > key) {
      order_[q] = order_[q - 1];
      sorted_lo_[q] = sorted_lo_[q - 1];
      --q;
    }
    order_[q] = v;
    sorted_lo_[q] = key;
  }
  // The sweep reads the bodies in x order from arrays laid out in that order: left ends,
  // and the y interval the centre swept (NaN for a body that is not alive).
  sorted_y_.resize(n);
  if (near_.size() < n) near_.resize(n);
  constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
  for (std::size_t p = 0; p < n; ++p) {
    const std::size_t i = order_[p];
    const double y0 = before(i).y, y1 = pos_[i].y;
    sorted_y_[p] = alive_[i] ? YRange{std::min(y0, y1), std::max(y0, y1)} : YRange{kNaN, kNaN};
  }
  // Horizontal strips, when the order is a clean sort (every left end finite, so the sweep
  // below stops for each body exactly at the first box starting after its own ends): a
  // strip is at least as tall as the y filter below can reach (the radii together, the
  // largest y swept over the step) plus a margin, so every pair the filter can pass has its
  // bodies' swept y intervals starting in the same strip or in neighbouring ones. Each
  // body then scans its own strip and the two beside it, where the whole sweep scanned
  // every body in its x range (in a 1k-body gas about 17, of which one or two pass).
  std::uint32_t strips = 0;
  bool use_strips = !plain_sweep_ && n >= (force_strips_ ? kMinForcedStripBodies : kMinStripBodies);
  if (use_strips) {
    double ymin = std::numeric_limits<double>::infinity(), ymax = -ymin, swept = 0.0;
    bool clean = true;
    for (std::size_t p = 0; p < n; ++p) {
      clean = clean && std::isfinite(sorted_lo_[p]);
      const YRange y = sorted_y_[p];
      if (y.lo == y.lo) {   // alive
        ymin = std::min(ymin, y.lo);
        ymax = std::max(ymax, y.lo);
        swept = std::max(swept, y.hi - y.lo);
      }
    }
    const double span = ymax - ymin;
    double height = (2.0 * max_radius_ * (1.0 + 1e-9) + swept) * 1.01 + 1e-9 * (std::fabs(ymin) + std::fabs(ymax));
    if (clean && std::isfinite(span) && std::isfinite(height) && height > 0.0) {
      height = std::max(height, span / static_cast<double>(n) * 1.01);   // at most about n strips
      const double inv = 1.0 / height;
      strips = static_cast<std::uint32_t>(span * inv) + 1;
      strip_start_.assign(static_cast<std::size_t>(strips) + 1, 0);
      strip_of_.resize(n);
      for (std::size_t p = 0; p < n; ++p) {
        const YRange y = sorted_y_[p];
        if (y.lo != y.lo) continue;   // not alive: in no strip, never anyone's neighbour
        const auto s = std::min(static_cast<std::uint32_t>((y.lo - ymin) * inv), strips - 1);
        strip_of_[p] = s;
        ++strip_start_[s + 1];
      }
      for (std::uint32_t s = 0; s < strips; ++s) strip_start_[s + 1] += strip_start_[s];
      strip_cursor_.assign(strip_start_.begin(), strip_start_.end() - 1);
      const std::size_t members = strip_start_[strips];
      strip_item_.resize(members);
      strip_lo_.resize(members);
      strip_y_.resize(members);
      for (std::size_t p = 0; p < n; ++p) {   // in x order: each strip's members stay sorted
        const YRange y = sorted_y_[p];
        if (y.lo != y.lo) continue;
        const std::uint32_t c = strip_cursor_[strip_of_[p]]++;
        strip_item_[c] = static_cast<std::uint32_t>(p);
        strip_lo_[c] = sorted_lo_[p];
        strip_y_[c] = y;
      }
      strip_cursor_.assign(strip_start_.begin(), strip_start_.end() - 1);
    } else {
      use_strips = false;
    }
  }
  for (std::size_t p = 0; p < n; ++p) {
    const std::size_t i = order_[p];
    if (!alive_[i]) continue;
    const Vec2 xi = pos_[i];
    const double ri = radius_[i];
    const double hi = std::max(xi.x, before(i).x) + ri;
    const double ylo = sorted_y_[p].lo, yhi = sorted_y_[p].hi;
    const std::size_t gi = body_group_[i] * n_body_groups_;
    // The bodies after i in x order whose box starts before i's ends, filtered by the swept
    // y intervals: farther apart than the radii together could be (max_radius_ bounds rj)
    // or j not alive (NaN) is skipped without touching anything else of j. The filter is
    // branch-free (each index is written, the count advanced by the test), since in a gas
    // it fails unpredictably for most of the x neighbours; the survivors are then taken
    // in the same order as before.
    const double reach = (ri + max_radius_) * (1.0 + 1e-9);
    const double y_lo = ylo - reach, y_hi = yhi + reach;
    std::size_t found = 0;
    if (use_strips) {
      // The same neighbours from the strips within one of i's: each strip's bodies after
      // i (its cursor), up to the first whose box starts after i's ends, then in x order.
      const std::uint32_t own = strip_of_[p];
      ++strip_cursor_[own];   // i itself was the next of its strip
      const std::uint32_t first = own > 0 ? own - 1 : 0, last = std::min<std::uint32_t>(own + 1, strips - 1);
      for (std::uint32_t s = first; s <= last; ++s) {
        const std::uint32_t end = strip_start_[s + 1];
        for (std::uint32_t c = strip_cursor_[s]; c < end && strip_lo_[c] <= hi; ++c) {
          near_[found] = strip_item_[c];
          found += static_cast<std::size_t>((strip_y_[c].lo <= y_hi) & (strip_y_[c].hi >= y_lo));
        }
      }
      for (std::size_t f = 1; f < found; ++f) {   // three short runs in x order, merged
        const std::uint32_t v = near_[f];
        std::size_t g = f;
        for (; g > 0 && near_[g - 1] > v; --g) near_[g] = near_[g - 1];
        near_[g] = v;
      }
    } else {
      for (std::size_t q = p + 1; q < n && sorted_lo_[q] <= hi; ++q) {
        near_[found] = static_cast<std::uint32_t>(q);
        found += static_cast<std::size_t>((sorted_y_[q].lo <= y_hi) & (sorted_y_[q].hi >= y_lo));
      }
    }
    for (std::size_t f = 0; f < found; ++f) {
      const std::size_t q = near_[f];
      const std::size_t j = order_[q];
      const double rj = radius_[j];
      // The same with j's own radius (a margin far above rounding): the centres stayed
      // farther apart in y than the radii together all step long, so nothing below happens.
      const double reach_j = (ri + rj) * (1.0 + 1e-9);
      if (sorted_y_[q].lo > yhi + reach_j || sorted_y_[q].hi < ylo - reach_j) continue;
      if (!pair_collides_[gi + body_group_[j]]) continue;
      // Two points: no overlap can be deeper than 0 (max_penetration starts there), and they
      // are never counted as passed into each other (that wants a radius, see below).
      if (ri == 0.0 && rj == 0.0) continue;
      const Vec2 xj = pos_[j];
      // A pair whose straight relative path (from the step before to now) stays farther
      // apart than the radii together, by a margin far above the rounding of the tests below,
      // can do nothing below: every outcome there (an overlap deeper than max_penetration,
      // which is >= 0; a pass into each other; a skipped impact) needs the path's closest
      // approach, or its end, nearer than the radii together. Most pairs the filters above
      // pass are such neighbours (a gas's: about 130 an observe on core's circle_gas run, all
      // but a few apart), and the tests below take several square roots each. The
      // closest approach squared, without a root: at an end when the path moves away from
      // there, else the distance to the path's line (cross(d0, dd)^2 / |dd|^2).
      if (!full_pair_tests_) {
        const Vec2 d0 = before(i) - before(j), d1 = xi - xj, dd = d1 - d0;
        const double apart_at = (ri + rj) * (1.0 + 1e-6) +
                             1e-9 * (std::fabs(d0.x) + std::fabs(d0.y) + std::fabs(dd.x) + std::fabs(dd.y));
        const double reach2 = apart_at * apart_at;
        bool apart;
        if (dot(d0, dd) >= 0.0) {
          apart = dot(d0, d0) > reach2;
        } else if (dot(d1, dd) <= 0.0) {
          apart = dot(d1, d1) > reach2;
        } else {
          const double c = cross(d0, dd);
          apart = c * c > reach2 * dot(dd, dd);
        }
        if (apart) {
          ++far_pairs_skipped_;
          continue;
        }
      }
      const double depth = ri + rj - length(xi - xj);
      if (depth > record_.max_penetration) {
        penetration(depth, t, scene_.bodies[std::min(i, j)].name + " / " + scene_.bodies[std::max(i, j)].name);
      }
      // Passed into each other: the centres closer than the smaller radius (each centre
      // inside the other body; overlap deeper than the larger radius). No solver's slop
      // comes near it: the pair has gone through, or is on its way. Judged along the step:
      // the straight path of one centre relative to the other, from the step before to now
      // (a 300 m/s ball through a resting one in one step is at neither end inside it),
      // when both steps were straight (neither body met anything in it), each bend added.
      // A point (radius 0) has passed into a circle when it gets half-way to its centre.
      const double smaller = std::min(ri, rj) > 0.0 ? std::min(ri, rj) : 0.5 * std::max(ri, rj);
      // Two points (no radius either, or a radius that is not a number) are never counted as
      // passed into each other (the test at the end wants smaller > 0): nothing below for them.
      if (!(smaller > 0.0)) continue;
      // Of two circles of unequal size, the small one has gone into the large one when it
      // is wholly inside it (centres closer than the difference of the radii: an overlap
      // deeper than the small one's diameter): a 1 cm ball at 10-300 m/s went 0.5 m deep
      // into a resting 1 m ball, or right through it off its centre, on Box2D, Bullet,
      // Chipmunk and ODE, never within 1 cm of its centre, and every run was `ok`.
      const double into = std::min(ri, rj) > 0.0 ? std::max(smaller, std::max(ri, rj) - smaller) : smaller;
      // The bends (six square roots) are worked out only when they can decide: the path's
      // closest approach plus a bend (>= 0) is never below the approach alone, so when the
      // centres are inside now, or the path never comes inside, the answer is the same.
      double closest = ri + rj - depth;
      const double eps = eps_at(xi, xj, 0.0);
      const double inside = into - eps;
      bool into_each_other = closest < inside;
      if (!into_each_other) {
        const Vec2 d0 = before(i) - before(j), dd = (xi - xj) - d0;
        const double len2 = dot(dd, dd);
        const double u = len2 > 0.0 ? std::clamp(-dot(d0, dd) / len2, 0.0, 1.0) : 1.0;
        const double along = length(d0 + dd * u);
        if (along < inside) {
          // Judged when the steps bent by less than half the smaller radius. (Allowing half
          // the depth tested, the difference of the radii for a small circle in a large one,
          // caught Box2D throwing a stack's 0.5 m bottom ball 2 m up through the 0.1 m top one
          // at dt 15 s, but read core's exact gases, a 2 cm ball bouncing 3-4 times on a 0.4 m
          // one within a step, as passes: the bend bounds one bounce's corner, not several.
          // The eighteenth hunt; left open, README Known limits.)
          if (const double off = bend(i) + bend(j); off < 0.5 * smaller) into_each_other = along + off < inside;
        }
        // Apart at both ends of the step and overlapping on the straight path between, by
        // more than half the smaller radius (a point: a tenth of the circle's): a collision
        // missed, the pair went through each other within the step however far off centre
        // (two 0.5 m balls passing 0.7 m apart at 300 m/s; a point 0.7 m off a 1 m ball's
        // centre, never half-way in). A shallower graze is not counted (Box2D's bullets in
        // a 400-body gas miss a few, on straight paths, by an eighth of a radius). Only for
        // steps that are one straight flight each, to a quarter of that depth: the
        // displacement agrees with both the velocity the step started with and the one it
        // ended with (a collision resolved inside the step bends the path, and a chord
        // across the bend cuts the corner: core's exact runs in a box were reported with
        // the end-state test's looser bend). At a step's end a point may sit inside by a
        // solver's slop, so ends still need half the radius.
        if (!into_each_other && length(d0) >= ri + rj - eps && closest >= ri + rj - eps) {
          const double seen = std::min(ri, rj) == 0.0 ? 0.1 * (ri + rj) : 0.5 * std::min(ri, rj);
          if (along < ri + rj - seen) {
            const double off = kink(i) + kink(j);
            into_each_other = off < 0.25 * seen && along + off < ri + rj - seen;
          }
        }
        // The same pass when a body's step is straight at one of its velocities only, or
        // when the pair overlaps at an end (the chord deeper in between than there): Box2D caps a step at
        // 2 m (an 80 m/s ball moves at 60 m/s), and in that step took a 0.5 m ball through a
        // resting one 0.45 m deep on its chord, ending 0.19 m into it on the far side; b
        // never moved, `ok` (the seventh hunt's `graze`: x1 = x0 + v1 h, not v0 h, so the
        // test above left it).
        if (!into_each_other) {
          const double start_depth = ri + rj - length(d0), end_depth = ri + rj - closest;
          const double ends = start_depth <= eps && end_depth <= eps ? 0.0 : std::max(start_depth, end_depth);
          const double seen = std::min(ri, rj) == 0.0 ? 0.1 * (ri + rj) : 0.5 * std::min(ri, rj);
          // Deeper than half the smaller radius at a point of the chord deeper than both its
          // ends (a contact being resolved is deepest at an end).
          const double limit = std::min(ri + rj - seen, ri + rj - ends - eps);
          if (along < limit) {
            const double off = straight_either(i) + straight_either(j);
            into_each_other = off < 0.25 * seen && along + off < limit;
          }
        }
      }
      // Shallower than that: a pass in one step, each body on one straight flight (at an
      // unchanged velocity, or at its end velocity from the step's start: Box2D's speed cap;
      // an impact resolved inside the step bends it, and one resolved at its start leaves the
      // chord deepest there), whose straight relative path overlaps in between by more than
      // a slop beyond both ends: kept for the comparator, which calls it a
      // skipped impact when the converged reference has a contact of this pair in this step
      // (the seventh hunt's glancing miss, 0.4 of the radius deep, was `ok`). A gas whose
      // trajectories left the reference's is not judged on contacts that no longer match.
      if (!into_each_other && h > 0.0 && std::min(ri, rj) > 0.0) {
        const Vec2 d0 = before(i) - before(j);
        const double slop = ContainmentRecord::kGrazeSlop * std::min(ri, rj);
        // Past the closest approach at the end (u <= 1: separating or tangent there) and
        // deeper in between than both ends by more than the slop: an end that overlaps is what
        // a discrete engine sees and resolves (ODE in a 0.5 m/s gas of 3 cm balls found a
        // pair 1 mm into each other, already separating, and pushed it apart), so only what
        // the chord adds beyond it counts.
        const double ends = std::max({0.0, ri + rj - length(d0), ri + rj - closest});
        {
          const Vec2 dd = (xi - xj) - d0;
          const double len2 = dot(dd, dd);
          const double closest_at = len2 > 0.0 ? -dot(d0, dd) / len2 : 1.0;   // 1: at the end
          const double u = std::clamp(closest_at, 0.0, 1.0);
          const double along = length(d0 + dd * u);
          const double limit = ri + rj - ends - slop;
          // (at the end itself, up to round-off, is tangent there: no impulse either)
          if (along < limit && closest_at <= 1.0 + 1e-9 && u > 0.0) {
            const double off = straight_either(i) + straight_either(j);
            if (off < 0.25 * slop && along + off < limit) {
              keep_graze({static_cast<std::uint32_t>(std::min(i, j)), static_cast<std::uint32_t>(std::max(i, j)),
                          t, h, ri + rj - along});
            }
          }
        }
      }
      if (into_each_other && smaller > 0.0) {
        for (const std::size_t k : {i, j}) {
          if (escaped_[k]) continue;
          escaped_[k] = 1;
          record_.escaped_list.push_back(static_cast<std::uint32_t>(k));
          ++*record_.escaped_bodies;
          if (!record_.first_escape_time) {
            record_.first_escape_time = t;
            record_.first_escape = scene_.bodies[k].name + " into body '" + scene_.bodies[k == i ? j : i].name + "'";
          }
        }
      }
    }
  }

  // Each moving body against the barriers near its path since the last step (with none,
  // only the step's end is remembered, as at the end of the loop below).
  if (barriers_.empty()) {
    for (const std::size_t i : moving_) {
      if (!alive_[i]) {
        previous_alive_[i] = 0;
        continue;
      }
      previous_[i] = pos_[i];
      previous_velocity_[i] = states[i].velocity;
      previous_alive_[i] = 1;
    }
    previous_time_ = t;
    return;
  }
  auto against_barriers = [&](std::size_t i) {
    if (!alive_[i]) {
      previous_alive_[i] = 0;
      return;
    }
    const double r = radius_[i];
    const Vec2 p1 = pos_[i];
    const Vec2 p0 = previous_alive_[i] ? previous_[i] : p1;
    const Vec2 lo_corner{std::min(p0.x, p1.x) - r, std::min(p0.y, p1.y) - r};
    const Vec2 hi_corner{std::max(p0.x, p1.x) + r, std::max(p0.y, p1.y) + r};
    const std::vector<char>& blocks = blocks_[body_group_[i]];
    auto check = [&](std::uint32_t k) {
      const Barrier& b = barriers_[k];
      if (!blocks[b.group] || (b.circle && b.body == parent_of(i))) return;
      if (b.pinch && (!blocks[b.group2] || 2.0 * r * (1.0 - ContainmentRecord::kGrazeSlop) <= b.width)) return;   // it fits
      if (b.pinch) {
        // no barrier: its barriers' own tests give the penetration
      } else if (b.circle) {
        const double depth = r + b.radius - length(p1 - b.a);
        if (depth > record_.max_penetration) penetration(depth, t, name(i) + " / " + b.what);
      } else {
        const double depth = r - segment_distance(p1, b.a, b.dir, b.len);
        if (depth > record_.max_penetration) penetration(depth, t, name(i) + " / " + b.what);
      }
      if (escaped_[i] || p0 == p1) return;
      const double eps = std::max(b.eps, eps_at(p0, p1, 0.0));
      bool through = false;
      if (b.circle) {
        const Vec2 d = p1 - p0;
        const double len2 = dot(d, d);
        const double u = std::clamp(dot(b.a - p0, d) / len2, 0.0, 1.0);
        // Into a static body's circle (the centre closer to its centre than its radius):
        // deeper than the moving body's own radius, through or on its way through.
        through = length(p0 - b.a) >= b.radius - eps && length(p0 + d * u - b.a) < b.radius - eps;
      } else {
        const double d0 = cross(b.dir, p0 - b.a), d1 = cross(b.dir, p1 - b.a);
        const int s0 = d0 > eps ? 1 : d0 < -eps ? -1 : 0;
        const int s1 = d1 > eps ? 1 : d1 < -eps ? -1 : 0;
        auto within = [&](Vec2 q) {
          const double u = dot(q - b.a, b.dir);
          return u >= -eps && u <= b.len + eps;
        };
        const std::uint64_t key = static_cast<std::uint64_t>(i) * barriers_.size() + k;
        if (s0 != 0 && s1 == -s0) {
          through = within(p0 + (p1 - p0) * (d0 / (d0 - d1)));
        } else if (s0 != 0 && s1 == 0) {
          if (within(p1)) {   // landed on the line: remember whence
            if (on_line_.insert_or_assign(key, static_cast<signed char>(s0)).second) ++on_line_count_[i];
          }
        } else if (s0 == 0) {
          // Left the line it had landed on: through it when to the other side of where it came from.
          if (auto it = on_line_.find(key); it != on_line_.end() && s1 != 0) {
            through = s1 == -it->second && within(p0);
            on_line_.erase(it);
            --on_line_count_[i];
          }
        }
      }
      // graze3: a skipped impact on a static body or a wall's end point, kept for the
      // comparator as between moving bodies: the body on one straight flight, apart at
      // both ends of the step (an overlap there, with the circle or anywhere on the wall, is
      // what a discrete engine sees and resolves), past its closest approach at the end,
      // and its straight path deeper in between than both ends by more than 2% of its
      // radius (a ball passing 0.3 m off a thin wall's end, 0.2 m into it, and one passing
      // a static ball 0.2 m into it, velocity unchanged, were `ok` on Bullet, Chipmunk and
      // ODE). Since the eighth hunt a box's corners and a surface's end points and joints
      // too (a 0.5 m ball at 80 m/s past a thin post's corner or a surface's end 0.25 m
      // deep was `ok` on the same three, while the same pass at a wall's end was diverged).
      // The other side is the static body's index, or the segment's owner past the bodies'
      // (walls, then boxes, then surfaces).
      // (A straight path's distance to a line is linear: between its ends it comes closer
      // to a segment only near an end point, or by crossing it, an escape above.)
      if (!through && i < nb && r > 0.0 && h > 0.0 && previous_alive_[i] &&
          (b.circle ? b.body < scene_.bodies.size() : b.owner != static_cast<std::size_t>(-1))) {
        const double slop = ContainmentRecord::kGrazeSlop * r;
        const double reach = b.circle ? r + b.radius : r;
        auto overlap = [&](Vec2 q) {
          return b.circle ? reach - length(q - b.a) : r - segment_distance(q, b.a, b.dir, b.len);
        };
        const double ends = std::max({0.0, overlap(p0), overlap(p1)});
        const Vec2 d = p1 - p0;
        const double len2 = dot(d, d);
        const Vec2 points[2] = {b.a, b.b};   // a circle's centre; a segment's end points
        for (int e = 0; e < (b.circle ? 1 : 2); ++e) {
          const Vec2 c = points[e];
          const double closest_at = dot(c - p0, d) / len2;   // 1: at the end
          const double u = std::clamp(closest_at, 0.0, 1.0);
          const double along = length(p0 + d * u - c);
          double limit = reach - ends - slop;
          if (along < limit && !b.circle) {
            // An end point shared with another segment (a ledge's corner, a loop's): the
            // ends' overlap with that one counts too (a ball resting a slop deep on a floor
            // rolls over its corner with the wall below: the floor is being resolved).
            // A box's other sides count at the ends too: apart at both ends means from the
            // whole box (a ball over a wide block's top at the step's end is being resolved
            // against it).
            const bool box = b.owner >= scene_.walls.size() && b.owner < scene_.walls.size() + scene_.boxes.size();
            for (const Barrier& o : barriers_) {
              if (o.circle || o.pinch || ((o.a != c && o.b != c) && !(box && o.owner == b.owner))) continue;
              for (const Vec2 q : {p0, p1}) limit = std::min(limit, reach - slop - (r - segment_distance(q, o.a, o.dir, o.len)));
            }
          }
          if (along < limit && closest_at <= 1.0 + 1e-9 && u > 0.0) {
            const double off = straight_either(i);
            if (off < 0.25 * slop && along + off < limit) {
              const std::size_t other = b.circle ? b.body : scene_.bodies.size() + b.owner;
              // One record a step for a barrier: a box's corner ends two of its sides (the
              // deeper one kept). Past the cap a corner's second side counts as dropped too.
              ContainmentRecord::Graze* last = record_.grazes.empty() ? nullptr : &record_.grazes.back();
              if (last && last->a == i && last->b == other && last->time == t) {
                last->depth = std::max(last->depth, reach - along);
              } else {
                keep_graze({static_cast<std::uint32_t>(i), static_cast<std::uint32_t>(other), t, h, reach - along});
              }
              break;
            }
          }
        }
      }
      if (through) {
        escaped_[i] = 1;
        if (i < scene_.bodies.size()) record_.escaped_list.push_back(static_cast<std::uint32_t>(i));
        ++*record_.escaped_bodies;
        if (!record_.first_escape_time) {
          record_.first_escape_time = t;
          record_.first_escape = name(i) + " through " + b.what;
          if (b.pinch) {
            char text[96];
            std::snprintf(text, sizeof text, " (%.6g m wide, narrower than its %.6g m diameter)", b.width, 2.0 * r);
            record_.first_escape += text;
          }
        }
      }
    };
    if (use_grid_) {
      candidates(lo_corner, hi_corner);
      for (const std::uint32_t k : found_) check(k);
    } else {
      // Few barriers: all of them, but a barrier whose box (widened by 2 eps) the path's
      // box misses is skipped: the body's end point is farther than r from it (no
      // penetration) and the path can neither cross it nor land on or leave its line
      // within eps of it. A body with a remembered landing on some line checks every
      // barrier, so that leaving that line is seen wherever it happens.
      const bool all = on_line_count_[i] != 0;
      // Inside the open box: beyond one side of every barrier box, so the test below
      // would skip every barrier (the box is empty when open_lo_ == open_hi_ == 0).
      if (!all && lo_corner.x > open_lo_.x && hi_corner.x < open_hi_.x && lo_corner.y > open_lo_.y &&
          hi_corner.y < open_hi_.y) {
        previous_[i] = p1;
        previous_velocity_[i] = states[i].velocity;
        previous_alive_[i] = 1;
        return;
      }
      for (std::uint32_t k = 0; k < barriers_.size(); ++k) {
        if (!all && (hi_corner.x < barrier_lo_[k].x || lo_corner.x > barrier_hi_[k].x ||
                     hi_corner.y < barrier_lo_[k].y || lo_corner.y > barrier_hi_[k].y)) {
          continue;
        }
        check(k);
      }
    }
    previous_[i] = p1;
    previous_velocity_[i] = states[i].velocity;
    previous_alive_[i] = 1;
  };
  for (const std::size_t i : moving_) against_barriers(i);
  for (std::size_t i = scene_.bodies.size(); i < n_objects; ++i) against_barriers(i);
  previous_time_ = t;
}

}  // namespace physval
