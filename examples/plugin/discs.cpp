// discs: a small, complete 2-D engine as a physval plugin. Circles under a uniform field,
// colliding with each other and with static walls (segments) through restitution
// impulses. Written against the installed physval package only (physval/plugin.hpp).
//
// Each step of h = dt / substeps:
//   1. integrate: x += v h + g h^2 / 2, v += g h (velocity Verlet; exact for a uniform field);
//   2. find overlaps (circle/circle, circle/segment) and, for each approaching pair in
//      index order, apply the impulse j = -(1 + e) v_n / (1/m_a + 1/m_b) along the normal;
//   3. push overlapping pairs apart by position_correction x the overlap, split by inverse
//      mass (0: no correction, 1: separate fully).
// A contact begins when a pair touches at the end of a step and did not at the end of the
// previous one (or at load); its time is the end of that step. The pair's material is
// physval's rule, asked of the host (min restitution, overrides by name). No friction, no
// spin.
#include <physval/plugin.hpp>

#include <algorithm>
#include <cstdint>
#include <cmath>
#include <set>
#include <stdexcept>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

namespace {

struct V {
  double x = 0.0, y = 0.0;
};
V operator+(V a, V b) { return {a.x + b.x, a.y + b.y}; }
V operator-(V a, V b) { return {a.x - b.x, a.y - b.y}; }
V operator*(double s, V a) { return {s * a.x, s * a.y}; }
double dot(V a, V b) { return a.x * b.x + a.y * b.y; }
V from(physval_vec2 v) { return {v.x, v.y}; }
physval_vec2 to(V v) { return {v.x, v.y}; }

struct Disc {
  std::string name;
  V x, v;
  double r = 0.0, inv_m = 0.0, mass = 0.0, angle = 0.0;
  physval_material_view material{};
};

struct Wall {
  std::string name;
  V a, b;
  physval_material_view material{};
};

class Discs {
 public:
  static const physval_info& info() {
    static const physval_option_spec options[] = {
        {"substeps", {PHYSVAL_OPTION_INT, 0, 1, 0.0, ""}, nullptr, 0,
         "integration and collision passes per physval step", 1.0, HUGE_VAL, 0},
        {"position_correction", {PHYSVAL_OPTION_DOUBLE, 0, 0, 0.2, ""}, nullptr, 0,
         "fraction of an overlap removed after the impulses (0: none, 1: all)", 0.0, 1.0, 0},
    };
    static const physval_info i = {
        "discs", "1.0", PHYSVAL_FLOAT64, "example plugin: velocity Verlet discs with restitution impulses",
        PHYSVAL_FEATURE_BIT(PHYSVAL_FEATURE_CIRCLES) | PHYSVAL_FEATURE_BIT(PHYSVAL_FEATURE_STATIC_BODIES) |
            PHYSVAL_FEATURE_BIT(PHYSVAL_FEATURE_WALLS) | PHYSVAL_FEATURE_BIT(PHYSVAL_FEATURE_UNIFORM_GRAVITY) |
            PHYSVAL_FEATURE_BIT(PHYSVAL_FEATURE_MATERIAL_OVERRIDES),
        options, 2};
    return i;
  }

  void load(const physval_scene& s, const physval_host& host) {
    host_ = host;
    g_ = from(s.world.gravity);
    substeps_ = physval_plugin::option_int(s, "substeps", 1);
    correction_ = physval_plugin::option_double(s, "position_correction", 0.2);
    for (std::size_t i = 0; i < s.body_count; ++i) {
      const physval_body& b = s.bodies[i];
      Disc d;
      d.name = b.name;
      d.x = from(b.position);
      d.v = b.is_static ? V{} : from(b.velocity);
      d.r = b.radius;
      d.mass = b.is_static ? 0.0 : b.mass;
      d.inv_m = b.is_static ? 0.0 : 1.0 / b.mass;
      d.angle = b.angle;
      discs_.push_back(d);
    }
    for (std::size_t i = 0; i < s.wall_count; ++i) {
      const physval_wall& w = s.walls[i];
      walls_.push_back({w.name, from(w.from), from(w.to), {}});
    }
    // Material views point at the names: set them once the vectors no longer move.
    for (std::size_t i = 0; i < discs_.size(); ++i) {
      const physval_body& b = s.bodies[i];
      discs_[i].material = {discs_[i].name.c_str(), b.restitution, b.friction, b.static_friction, b.rolling_friction};
    }
    for (std::size_t i = 0; i < walls_.size(); ++i) {
      const physval_material& m = s.walls[i].material;
      walls_[i].material = {walls_[i].name.c_str(), m.restitution, m.friction, m.static_friction, m.rolling_friction};
    }
    touching_ = touching();   // pairs that touch at the start have not begun a contact
  }

  void step(double dt) {
    const double h = dt / static_cast<double>(substeps_);
    for (long long k = 0; k < substeps_; ++k) substep(h);
    t_ += dt;
    // Contact events: pairs touching now that were not at the end of the last step.
    std::set<Pair> now = touching();
    contacts_.clear();
    for (const Pair& p : now) {
      if (touching_.count(p) == 0) {
        physval_contact c{};
        c.a = {PHYSVAL_OBJECT_BODY, p.first};
        c.b = {p.wall ? PHYSVAL_OBJECT_WALL : PHYSVAL_OBJECT_BODY, p.second};
        c.time = t_;
        contacts_.push_back(c);
      }
    }
    touching_ = std::move(now);
  }

  double time() const { return t_; }
  std::size_t body_count() const { return discs_.size(); }
  physval_body_meta body_meta(std::size_t i) const {
    return {discs_[i].name.c_str(), discs_[i].mass, discs_[i].r, discs_[i].inv_m == 0.0 ? 1 : 0};
  }
  void read_states(physval_body_state* out, std::size_t n) const {
    for (std::size_t i = 0; i < n && i < discs_.size(); ++i) {
      out[i] = {to(discs_[i].x), to(discs_[i].v), discs_[i].angle, 0.0, 1};
    }
  }
  const std::vector<physval_contact>& contacts() const { return contacts_; }
  std::vector<std::pair<std::string, std::string>> settings() const {
    return {{"integrator", "velocity Verlet (x += v h + g h^2/2, v += g h)"},
            {"contacts", "one pass of restitution impulses per substep, pairs in index order, no friction"},
            {"substeps", std::to_string(substeps_)},
            {"position_correction", std::to_string(correction_)},
            {"contact_events", "begin when a pair overlaps at the end of a step; time = end of that step"}};
  }

 private:
  struct Pair {
    std::uint32_t first = 0, second = 0;
    bool wall = false;
    bool operator<(const Pair& o) const {
      return std::tie(wall, first, second) < std::tie(o.wall, o.first, o.second);
    }
  };

  // The closest point of segment ab to p.
  static V closest(V a, V b, V p) {
    const V ab = b - a;
    const double len2 = dot(ab, ab);
    const double t = len2 > 0.0 ? std::clamp(dot(p - a, ab) / len2, 0.0, 1.0) : 0.0;
    return a + t * ab;
  }

  void resolve(Disc& a, Disc* b, V n, double overlap, const physval_material_view& other) {
    // n points from the other object to a. Relative normal velocity of a away from it:
    const double inv = a.inv_m + (b != nullptr ? b->inv_m : 0.0);
    if (inv == 0.0) return;
    const V vrel = b != nullptr ? a.v - b->v : a.v;
    const double vn = dot(vrel, n);
    if (vn < 0.0) {
      const physval_pair_material m = host_.combine_materials(host_.context, &a.material, &other);
      const double j = -(1.0 + m.restitution) * vn / inv;
      a.v = a.v + (j * a.inv_m) * n;
      if (b != nullptr) b->v = b->v - (j * b->inv_m) * n;
    }
    const double push = correction_ * overlap / inv;
    a.x = a.x + (push * a.inv_m) * n;
    if (b != nullptr) b->x = b->x - (push * b->inv_m) * n;
  }

  void substep(double h) {
    for (Disc& d : discs_) {
      if (d.inv_m == 0.0) continue;
      d.x = d.x + h * d.v + (0.5 * h * h) * g_;
      d.v = d.v + h * g_;
    }
    for (std::size_t i = 0; i < discs_.size(); ++i) {
      for (std::size_t j = i + 1; j < discs_.size(); ++j) {
        Disc& a = discs_[i];
        Disc& b = discs_[j];
        const V d = a.x - b.x;
        const double dist = std::sqrt(dot(d, d));
        const double overlap = a.r + b.r - dist;
        if (overlap <= 0.0 || dist == 0.0) continue;
        resolve(a, &b, (1.0 / dist) * d, overlap, b.material);
      }
      for (const Wall& w : walls_) {
        Disc& a = discs_[i];
        const V d = a.x - closest(w.a, w.b, a.x);
        const double dist = std::sqrt(dot(d, d));
        const double overlap = a.r - dist;
        if (overlap <= 0.0 || dist == 0.0) continue;
        resolve(a, nullptr, (1.0 / dist) * d, overlap, w.material);
      }
    }
  }

  std::set<Pair> touching() const {
    std::set<Pair> out;
    for (std::size_t i = 0; i < discs_.size(); ++i) {
      for (std::size_t j = i + 1; j < discs_.size(); ++j) {
        const V d = discs_[i].x - discs_[j].x;
        const double r = discs_[i].r + discs_[j].r;
        if (dot(d, d) <= r * r) out.insert({static_cast<std::uint32_t>(i), static_cast<std::uint32_t>(j), false});
      }
      for (std::size_t w = 0; w < walls_.size(); ++w) {
        const V d = discs_[i].x - closest(walls_[w].a, walls_[w].b, discs_[i].x);
        if (dot(d, d) <= discs_[i].r * discs_[i].r) {
          out.insert({static_cast<std::uint32_t>(i), static_cast<std::uint32_t>(w), true});
        }
      }
    }
    return out;
  }

  physval_host host_{};
  V g_;
  long long substeps_ = 1;
  double correction_ = 0.2;
  double t_ = 0.0;
  std::vector<Disc> discs_;
  std::vector<Wall> walls_;
  std::set<Pair> touching_;
  std::vector<physval_contact> contacts_;
};

}  // namespace

PHYSVAL_PLUGIN_DEFINE(Discs)
