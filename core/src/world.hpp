// core's world: every body in structure-of-arrays form, the static geometry, the
// tables built from the scene, and the scratch storage the step reuses. Private to
// core/src; the step's stages are free functions over it, one file each.
#pragma once

#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>
#include <unordered_map>
#include <memory>
#include <random>
#include <span>
#include <string>
#include <vector>

#include "physval/core/broadphase.hpp"
#include "physval/core/core_engine.hpp"
#include "physval/core/scene.hpp"
#include "physval/core/vec2.hpp"
#include "event_queue.hpp"

namespace physval::core_detail {

enum class Integrator : std::uint8_t { ExplicitEuler, SemiImplicitEuler, VelocityVerlet, Rk4 };
enum class CollisionMode : std::uint8_t { Exact, Lecture };
enum class ImpactLaw : std::uint8_t { Simultaneous, Sequential };
const char* integrator_name(Integrator i);

inline constexpr std::uint32_t kNone = std::numeric_limits<std::uint32_t>::max();
// support[i] names a segment, or with this bit a body (a body at rest on a body).
inline constexpr std::uint32_t kBodySupport = 0x80000000u;
// support[i] == kHeld: at rest, held by several contacts at once (World::held). It has
// the body bit, so on_body() and stuck() treat it as a body at rest on bodies.
inline constexpr std::uint32_t kHeld = 0xFFFFFFFEu;

// One contact of a held body: `other` is a body, or kBodySupport | segment index.
struct HeldContact {
  std::uint32_t body = 0;
  std::uint32_t other = 0;
  Vec2 n;   // unit, from the other towards the body
};

enum BodyFlag : std::uint8_t {
  kAlive = 1,
  kStatic = 2,
  kPoint = 4,
  kParticle = 8,
  kDestroyOnHit = 16,   // particles with destroy_on_collision
  kNoGravity = 32,      // particles of an emitter with gravity = false
};

// A piece of static geometry: a wall, one side of a box, or one piece of a surface.
struct Segment {
  Vec2 from, to;
  Vec2 dir;              // unit, from -> to
  Vec2 normal;           // unit, perp(dir)
  double length = 0.0;
  Vec2 normal_from, normal_to;   // response normals at the ends (surfaces); zero: geometric
  ObjectRef owner;
  std::uint16_t material = 0;
  std::uint16_t group = 0;
};

// Static geometry with a hashed uniform grid for "which segments can this box touch".
class StaticGeometry {
 public:
  std::vector<Segment> segments;
  void build(double typical_body_size);
  // Appends the segments whose (radius-free) boxes overlap `box`, once each.
  void query(const Aabb& box, std::vector<std::uint32_t>& out) const;
  std::size_t memory_bytes() const;

 private:
  std::vector<Aabb> boxes_;
  bool use_grid_ = false;
  double cell_ = 1.0;
  std::uint32_t mask_ = 0;
  std::vector<std::uint32_t> start_;   // CSR over hash buckets
  std::vector<std::uint32_t> items_;
  mutable std::vector<std::uint32_t> stamp_;
  mutable std::uint32_t stamp_value_ = 0;
};

struct ForceParams {
  double drag_linear = 0.0;
  double drag_quadratic = 0.0;
  std::int32_t thrust = -1;   // index into World::thrusts
};

struct EmitterState {
  EmitterDef def;
  std::uint32_t parent = kNone;
  std::mt19937_64 rng;
  double next_emit = 0.0;   // trail: absolute time of the next particle
  bool exploded = false;
  std::uint32_t serial = 0;
  // Trail emissions recorded during the step (exact mode): the parent's position and
  // velocity at each emission time, spawned at the step's end.
  struct Emission {
    Vec2 position, velocity;
    double time = 0.0;
  };
  std::vector<Emission> emitted;
  // An explosion recorded during the step, spawned at its end.
  bool pending = false;
  Vec2 at_position, at_velocity;
  double at_time = 0.0;
};

// Events one step may process before core gives up on exact impacts (the step is then
// finished by the lecture pass and broken_guarantee() says so). Large enough that the
// 1e8 and 1e9 mass-ratio billiards (about pi sqrt(M/m) impacts: 31,415 and ~99,000)
// finish exactly even when all their impacts
// fall in one step. A Zeno cascade that reaches it ends the run as diverged.
inline std::int64_t default_event_cap(std::size_t bodies) {
  return 1000000 + 100 * static_cast<std::int64_t>(bodies);
}

struct StepContext {
  double t0 = 0.0;     // simulated time at the start of the step
  double dt = 0.0;
  std::int64_t event_cap = 0;
  std::int64_t events = 0;
};

struct World {
  // ---- settings (EngineInfo options, after defaults)
  Integrator integrator = Integrator::VelocityVerlet;
  CollisionMode mode = CollisionMode::Exact;
  ImpactLaw impact_law = ImpactLaw::Simultaneous;
  // Set by the event loop while a body cycles through impacts at one instant: the
  // simultaneous set then takes its touching contacts that separate too (the LCP gives
  // them no impulse unless the others' impulses would close them).
  bool sim_with_separating = false;
  // resolve_simultaneous seeded by an impact on a segment's end point: the set's bodies
  // touch end points (convex caps) as well as faces (touching_face).
  bool sim_caps = false;
  // Set by the event loop to solve such a cycling set again perfectly inelastically (every
  // contact's restitution 0, collapse_speed infinite) when Newton's law with the
  // separating contacts would raise its kinetic energy (see exact_collisions.cpp).
  bool sim_inelastic = false;
  // Set by the event loop to try a set's law without changing a velocity: the velocities it
  // would set go to sim_trial (body, velocity after), w.vel and the stats are left as they
  // were (its bodies are advanced to the impact's time, as the solve that follows would).
  bool sim_dry_run = false;
  std::vector<std::pair<std::uint32_t, Vec2>> sim_trial;
  BroadPhaseKind broadphase = BroadPhaseKind::Grid;
  bool broadphase_auto = true;
  double cell_size = 0.0;
  std::int64_t max_events_option = 0;
  double rest_speed_option = 0.0;

  // ---- world-wide models
  Vec2 gravity;
  Vec2 wind;
  bool newtonian = false;
  double G = 0.0;
  double softening = 0.0;
  bool any_forces = false;       // acc / apath exist (something accelerates a body)
  bool varying_forces = false;   // drag, thrust or Newtonian: a depends on the state
  double time = 0.0;
  double end_time = 0.0;         // the scene's duration: its run's last step ends there
  double length_scale = 1.0;     // extent of the scene, for round-off tolerances
  // Where core's working origin sits in scene coordinates (core_engine.cpp, working_origin):
  // 0 but for a scene far from the origin next to its size, which core runs in coordinates
  // from its centre; read_states adds it back.
  Vec2 origin;
  double rest_factor = 1.0 / 16.0;   // auto rest speed = rest_factor |a_n| dt

  // ---- bodies (structure of arrays). Optional arrays are empty when unused.
  std::size_t scene_bodies = 0;
  std::vector<Vec2> pos, vel;
  std::vector<double> tloc;          // time within the step up to which pos/vel hold
  std::vector<double> inv_mass;      // 0 for static bodies
  std::vector<double> radius;
  std::vector<std::uint32_t> version;
  std::vector<std::uint8_t> flags;
  std::vector<std::uint16_t> group, material;
  std::vector<double> mass;          // newtonian only (static bodies attract)
  std::vector<double> angle;         // thrust only (heading)
  std::vector<Vec2> acc;             // any_forces: force / mass at the step start
  std::vector<Vec2> apath;           // any_forces: the path's acceleration this step
  std::vector<Vec2> vcorr;           // varying_forces: end-of-step velocity correction
  // push_trains: a member of a block sliding to a stop, its force acceleration and path
  // once the block has stopped this step (the block judged again from rest).
  std::vector<Vec2> train_stop_acc, train_stop_apath;
  std::vector<std::uint32_t> train_stopping;   // the bodies that have them
  std::vector<std::uint32_t> train_block;      // their block (its first member), to stop as one
  // push_trains adds pushes to acc for the step: each pushed body's force acceleration
  // before them (train_raw_set: it has one this step; train_raw_list: those bodies), so
  // that join_train can judge a block again from the members' own laws.
  std::vector<Vec2> train_raw_acc;
  std::vector<char> train_raw_set;
  std::vector<std::uint32_t> train_raw_list;
  // varying_forces: each body's current sub-step. A step is one sub-step unless an
  // impact (or a lift-off) changes the body's velocity inside it; the integrator then
  // starts a new sub-step there (substeps.cpp). Its start time, state and acceleration:
  std::vector<double> tsub;
  std::vector<Vec2> psub, vsub, ksub;
  // coupled(): the whole system's current sub-step started at tcut (every free body's
  // tsub, psub, vsub, ksub are its state there); scratch for its stages.
  double tcut = 0.0;
  std::vector<Vec2> cpl_x, cpl_v, cpl_vs, cpl_k[3];
  std::vector<ForceParams> fparams;  // drag or thrust only
  std::vector<ThrustDef> thrusts;
  std::vector<std::uint32_t> support;   // any_forces: segment (or kBodySupport | body) a body rests on, or kNone
  std::vector<Vec2> support_n;          // unit, from the support towards the body
  std::vector<std::uint32_t> dep_head, dep_next;   // any_forces: bodies resting on each body (a list)
  std::vector<std::uint32_t> released;             // scratch: bodies freed by their support moving
  std::vector<HeldContact> held;                   // any_forces: the contacts of every held body
  // any_forces: contact continuity, per pair: contact_key(i, partner) -> the last time
  // the pair touched (an impact, or resting on each other at a step's end).
  std::unordered_map<std::uint64_t, double> last_touch;
  // Names of the scene's bodies, packed: body i is name_chars[name_end[i-1], name_end[i])
  // (particles are named on demand).
  std::string name_chars;
  std::vector<std::uint32_t> name_end;
  std::string name(std::size_t i) const {
    const std::uint32_t b = i == 0 ? 0 : name_end[i - 1];
    return name_chars.substr(b, name_end[i] - b);
  }

  // ---- particles (index i - scene_bodies)
  std::vector<EmitterState> emitters;
  std::vector<double> birth, lifetime;
  std::vector<std::uint32_t> parent;
  std::vector<std::uint16_t> emitter_of;
  std::vector<std::uint32_t> serial;

  // ---- static geometry, materials, collision matrix
  StaticGeometry statics;
  std::uint16_t n_materials = 0;
  Scene override_scene;   // only .materials: the per-pair overrides by name
  struct MaterialRep {
    std::string name;   // non-empty when an override names it
    double restitution, friction, static_friction, rolling_friction;
  };
  std::vector<MaterialRep> materials;
  std::vector<PairMaterial> material_table;   // n_materials^2 when small, else empty
  std::uint16_t n_groups = 0;
  std::vector<PairResponse> responses;        // n_groups^2
  bool any_rules = false;

  // ---- broad phase and scratch
  std::unique_ptr<BroadPhase> bp;
  std::vector<std::uint8_t> active;
  std::vector<BodyPair> pairs;
  std::vector<std::uint32_t> found;
  std::vector<std::uint32_t> found_static;
  EventQueue events;
  std::vector<Event> scratch_events;
  std::vector<std::uint64_t> passing;   // pass-through pairs now overlapping, sorted
  std::vector<Vec2> scratch_p, scratch_v, scratch_a[4], scratch_f;   // rk4, verlet, lecture

  // ---- output
  std::vector<ContactEvent> contacts;
  CoreStepStats stats;
  std::int64_t cap_hits = 0;
  double first_cap_time = -1.0;
  // The first body held on bodies that, judged with it, cannot hold it (a ball on two
  // balls whose floor cannot keep them from spreading): core has no model for the
  // collapse that follows, so the run reports a broken guarantee (try_hold).
  std::uint32_t unjustified_hold = kNone;
  double unjustified_hold_time = -1.0;
  // Judged on its whole resting component (every body at rest transitively touching it,
  // faces and static bodies fixed): its size, and the largest acceleration left on a member
  // (m/s^2).
  std::size_t unjustified_component = 0;
  double unjustified_residual = 0.0;
  // Whether that judgement was left undecided (Gauss-Seidel did not converge and no
  // certificate that the component must move was found): reported all the same.
  bool unjustified_undecided = false;
  // Free bodies held by try_hold whose group test cannot justify the hold (it fails, or bodies
  // outside the group brace it): judged at the end of apply_supports on their resting
  // component (judge_braced_holds, resting_contact.cpp).
  std::vector<std::uint32_t> braced_holds;
  // Components found able to hold (members sorted, then their positions and force
  // accelerations, bit for bit): a settled pile is solved once, not every step.
  struct JudgedComponent {
    std::vector<std::uint32_t> members;
    std::vector<Vec2> state;
  };
  std::vector<JudgedComponent> justified_components;
  std::int64_t max_events_seen = 0;

  // ---- bodies moving in contact (contact_group.cpp): groups of free bodies that a hold could
  // not justify, moved on the acceleration-level contact problem between events (RK4 on
  // sub-steps, projected onto the active constraints). Their members are hidden from the rest
  // of the step (not alive) and advanced after it.
  struct GroupContact {
    std::int32_t a = -1, b = 0;   // member indices; a = -1: segment seg
    std::uint32_t seg = 0;
    double mu_k = 0.0, mu_s = 0.0, e = 0.0;
    bool active = false, sticking = false;
    double slip = 0.0;   // a sliding contact's direction of slip along perp(n), +-1; 0: none
  };
  // A contact's impulses of a granular group's last sub-step (granular.cpp), by contact key:
  // the next sub-step's projected Gauss-Seidel starts from them (warm start).
  struct GranularWarm {
    std::uint64_t key = 0;
    double pn = 0.0, pt = 0.0;
    bool slide = false;
  };
  struct ContactGroup {
    std::vector<std::uint32_t> members;
    std::vector<Vec2> acc;   // the members' force accelerations (constant: no varying forces)
    std::vector<GroupContact> contacts;
    bool fresh = true;       // its active set is chosen at its next step's start
    // Granular: moved by nonsmooth contact dynamics on sub-steps (granular.cpp) instead of
    // the exact event-driven group solve: a group over kMaxMembers, one whose events cycle,
    // or one engaged on an impact storm (a pile's inelastic collapse). `contacts` is unused.
    bool granular = false;
    bool sleeping = false;   // granular, at rest and held by its contacts: not stepped
    std::vector<GranularWarm> warm;   // sorted by key
    double warm_h = 0.0;              // the sub-step the warm impulses were found at
    double start = 0.0;               // engaged inside the current step: steps from here (s)
  };
  std::vector<ContactGroup> contact_groups;
  double group_dt = 0.0;
  std::vector<Vec2> group_p0, group_v0;   // every body's state at the step's start (scratch)
  std::int64_t group_steps = 0, group_events = 0;
  double group_first_time = -1.0;
  // Something the group mode does not model: another body within reach of a group, an impact
  // with friction on a sliding contact, or more events than a step may take. A broken guarantee.
  std::uint32_t group_disturbed = kNone;
  double group_disturbed_time = -1.0;
  std::string group_why;   // what it did not model
  // Granular groups (granular.cpp): steps taken, sub-steps whose solve stopped at its
  // sweep limit, the largest such residual (m/s), and the bodies whose pressed, slow pair
  // impacts in the current step mark an impact storm (engage_storm_groups).
  std::int64_t granular_steps = 0, granular_unconverged = 0;
  double granular_first_time = -1.0, granular_worst_residual = 0.0;
  std::vector<std::uint32_t> storm_count;   // per body, this step; empty when unused
  std::vector<std::uint32_t> storm_bodies;  // bodies with a count to reset
  bool storm_bail = false;   // a count passed kStormBail in this step: engaged at once
  bool granular_enabled = true;   // [core] dense_contact = "granular" (default) or "events"

  // ---- convex corners (convex_cap.cpp): bodies riding a segment end's cap, the circle of
  // radius r about the corner their centre moves on (a curved support), by body index.
  struct CapRide {
    Vec2 V;          // the corner
    Vec2 nA, dA;     // the face it came from: normal towards the body, direction out over V
    Vec2 nB;         // the normal where the cap hands over to the next face (or the back of A)
    double Phi = 0.0;              // the cap's arc from nA to nB, rotating towards dA
    std::uint32_t face = 0, next = 0;   // segments: the face it came from, the next face (A's back: face)
    double phi = 0.0, omega = 0.0;      // its angle on the cap and the angle's rate
  };
  std::unordered_map<std::uint32_t, CapRide> caps;
  // Lift-offs from a cap in this step (body, corner, time in the step, the window after it
  // in which the corner is no impact: the flight leaves the cap's circle at third order).
  struct CapLift {
    std::uint32_t body = 0;
    Vec2 V;
    double t = 0.0, window = 0.0;
  };
  std::vector<CapLift> cap_lifts;
  // Bodies too slow to lift off at a convex corner that the cap model could not take
  // (other geometry or bodies within reach of the cap, Newtonian gravity, particles): they
  // micro-bounce there, first order (limits_hit names the first).
  std::int64_t cap_unmodelled = 0;
  double cap_unmodelled_time = -1.0;
  // A body came within reach of a body riding a cap (core does not find impacts with a
  // curved path): a broken guarantee.
  std::uint32_t cap_disturbed = kNone;
  double cap_disturbed_time = -1.0;

  // ---- helpers
  std::size_t size() const { return pos.size(); }
  bool alive(std::uint32_t i) const { return (flags[i] & kAlive) != 0; }
  bool is_static(std::uint32_t i) const { return (flags[i] & kStatic) != 0; }
  bool dynamic(std::uint32_t i) const { return (flags[i] & (kAlive | kStatic)) == kAlive; }
  bool supported(std::uint32_t i) const { return !support.empty() && support[i] != kNone; }
  bool on_body(std::uint32_t i) const { return supported(i) && (support[i] & kBodySupport) != 0; }
  bool is_held(std::uint32_t i) const { return !support.empty() && support[i] == kHeld; }
  // On a convex corner's cap (convex_cap.cpp): its path is not a parabola.
  bool riding(std::uint32_t i) const { return !caps.empty() && caps.count(i) != 0; }
  // Does not move for the rest of the step: static, or at rest on its supports.
  bool stationary(std::uint32_t i) const { return is_static(i) || stuck(i); }
  // At rest on a support: not moving, and held there for the rest of the step.
  bool stuck(std::uint32_t i) const {
    return supported(i) && vel[i].x == 0.0 && vel[i].y == 0.0 && apath[i].x == 0.0 && apath[i].y == 0.0;
  }
  // A circle a body bouncing straight along n (unit, from it towards the bouncer) meets as
  // if it were fixed: a static circle, or a body stuck on one face whose normal is n (to 64
  // ulps: a ball resting on a level floor under a ball dropped onto its top). Each impact
  // presses the latter into its face, which takes it whole (the simultaneous law: the face's
  // contact, at rest, stays at rest), so the bouncer rebounds at e exactly as off a fixed
  // circle (exact_collisions.cpp, circle_tail).
  bool firm_circle(std::uint32_t j, Vec2 n, int depth = 0) const {
    if (!(radius[j] > 0.0)) return false;
    if (is_static(j)) return true;
    // Down a column at most kFirmDepth bodies (one body under another at each level, found
    // by a query at its foot: linear in the column). At 16, a Zeno tail on columns of 20 and
    // 30 balls was not taken and the pair's collapse ended it 0.45 s early (0.0027 m off at
    // e 0.9, `ok`; twentieth hunt's test).
    constexpr int kFirmDepth = 1024;
    if (!stuck(j) || depth > kFirmDepth) return false;
    constexpr double ulps = 64.0 * 2.220446049250313e-16;
    const auto along = [&](Vec2 u) { return dot(u, n) > 0.0 && std::fabs(cross(u, n)) <= ulps; };
    if (!on_body(j) && support[j] < statics.segments.size()) return along(support_n[j]);
    // On one body (a stack): firm when that body is, along the same line.
    if (on_body(j) && !is_held(j)) return along(support_n[j]) && firm_circle(support[j] & ~kBodySupport, n, depth + 1);
    if (!is_held(j)) return false;
    // Held on its supports together (kHeld): firm along n when one of them is under it along
    // n, touching: a face with normal n, or a body that is firm along n itself (the others
    // can only add to what it takes).
    const Vec2 foot = pos[j] - radius[j] * n;
    const double tol = 1e-9 * (radius[j] + length_scale);
    std::vector<std::uint32_t> found;
    statics.query(make_aabb(foot.x - tol, foot.y - tol, foot.x + tol, foot.y + tol), found);
    for (std::uint32_t k : found) {
      const Segment& s = statics.segments[k];
      const Vec2 sn = dot(s.normal, n) >= 0.0 ? s.normal : -1.0 * s.normal;
      const double u = dot(foot - s.from, s.dir);
      if (std::fabs(cross(sn, n)) <= ulps && u >= 0.0 && u <= s.length &&
          std::fabs(dot(pos[j] - s.from, sn) - radius[j]) <= tol) {
        return true;
      }
    }
    found.clear();
    bp->query_box(make_aabb(foot.x - tol, foot.y - tol, foot.x + tol, foot.y + tol), j, found);
    for (std::uint32_t k : found) {
      if (k == j || !alive(k) || !(radius[k] > 0.0)) continue;
      const Vec2 d = pos[j] - pos[k];
      const double dl = length(d);
      if (!(dl > 0.0) || std::fabs(dl - (radius[j] + radius[k])) > tol) continue;
      if (along(d / dl) && firm_circle(k, n, depth + 1)) return true;
    }
    return false;
  }
  Vec2 path_acc(std::uint32_t i) const { return apath.empty() ? Vec2{} : apath[i]; }
  Vec2 force_acc(std::uint32_t i) const { return acc.empty() ? Vec2{} : acc[i]; }
  // The acceleration that presses contacts: the constrained one for a supported body.
  Vec2 effective_acc(std::uint32_t i) const { return supported(i) ? apath[i] : force_acc(i); }
  Vec2 pos_at(std::uint32_t i, double t) const {
    const double s = t - tloc[i];
    return pos[i] + s * vel[i] + (0.5 * s * s) * path_acc(i);
  }
  Vec2 vel_at(std::uint32_t i, double t) const { return vel[i] + (t - tloc[i]) * path_acc(i); }
  void advance(std::uint32_t i, double t) {
    const double s = t - tloc[i];
    if (s == 0.0) return;
    const Vec2 a = path_acc(i);
    pos[i] += s * vel[i] + (0.5 * s * s) * a;
    vel[i] += s * a;
    tloc[i] = t;
  }
  const PairResponse& response(std::uint16_t g1, std::uint16_t g2) const {
    return responses[static_cast<std::size_t>(g1) * n_groups + g2];
  }
  PairMaterial pair_material(std::uint16_t m1, std::uint16_t m2) const;
  // Appends a new body's force and contact state, present only when the scene has
  // forces (scene bodies at load, particles when they are born).
  void push_force_state() {
    if (any_forces) {
      acc.push_back({});
      apath.push_back({});
      support.push_back(kNone);
      support_n.push_back({});
      dep_head.push_back(kNone);
      dep_next.push_back(kNone);
    }
    if (varying_forces) {
      vcorr.push_back({});
      tsub.push_back(0.0);
      psub.push_back({});
      vsub.push_back({});
      ksub.push_back({});
    }
  }
  // The rest speed for a contact pressed together with normal acceleration a_n.
  double rest_speed(double a_n, double dt) const {
    return rest_speed_option > 0.0 ? rest_speed_option : rest_factor * std::abs(a_n) * dt;
  }
  // The rest speed of an impact whose restitution is e, the normal speed v_n, pressed with
  // a_n. An elastic impact (e >= 1) cannot collapse (its bounces do not shorten: a ball
  // dropped on a floor at e = 1 is periodic at any step): with the automatic rest speed it
  // settles only a normal speed at round-off of |v_n| and |a_n| dt (the zero-time impacts of
  // a body resting with a speed of 1e-16 m/s), not one below |a_n| dt / 16 (hugedt).
  double impact_rest_speed(double a_n, double dt, double e, double v_n) const {
    if (e >= 1.0 && !(rest_speed_option > 0.0)) {
      return 64.0 * 2.220446049250313e-16 * (std::abs(v_n) + std::abs(a_n) * dt);
    }
    return rest_speed(a_n, dt);
  }
  // A lone body's Zeno sequence on one face (its bounces after a slow impact, restitution
  // 0 < e < 1, frictionless) is taken in closed form by the event loop (exact_collisions.cpp,
  // zeno_tail) where its acceleration is constant over the tail: uniform gravity only (no
  // drag, wind, thrust or Newtonian gravity: varying_forces), no collision rules, no
  // emitters, an integrator exact for constant forces, exact impacts.
  bool zeno_tails() const {
    return mode == CollisionMode::Exact && !varying_forces && !any_rules && !newtonian && emitters.empty() &&
           (integrator == Integrator::VelocityVerlet || integrator == Integrator::Rk4);
  }
  // The tail takes friction too (branch zeno12): the impacts' kinetic friction (mu_k, the
  // pair's `friction`, finite and >= 0) with motion along the face, the slip summed in closed
  // form phase by phase (zeno_tail's SlipPhase).
  static bool zeno_material(const PairMaterial& m, Vec2 v, Vec2 a, Vec2 n) {
    (void)v, (void)a, (void)n;
    if (!(m.restitution > 0.0 && m.restitution < 1.0)) return false;
    return std::isfinite(m.friction) && m.friction >= 0.0;
  }
  // The tail without friction impulses (the branch zeno10 form: along the face the body moves
  // with constant acceleration throughout): no friction, or friction where the body has no
  // motion along the face (its tangential velocity and acceleration at round-off of |v| and
  // |a|: a ball dropped straight onto a level floor): no friction impulse acts at any impact of
  // its tail, and at its end nothing pushes it along.
  static bool zeno_frictionless(const PairMaterial& m, Vec2 v, Vec2 a, Vec2 n) {
    if (!(m.friction > 0.0) && !(m.static_friction > 0.0)) return true;
    const double eps = 64.0 * 2.220446049250313e-16;
    return length(v - dot(v, n) * n) <= eps * length(v) && length(a - dot(a, n) * n) <= eps * length(a);
  }
  // Inelastic collapse: an impact of bodies i and j closing slower than this is
  // perfectly inelastic (restitution falls to 0): the rest speed of the larger of their
  // accelerations. 0 in a scene without forces. This is the speed for a pair whose
  // cluster rests on something (a face, a static body, a body at rest or on a face);
  // an impact of two free bodies takes pair_collapse_speed, which asks whether it does.
  double step_dt = 0.0;   // the current step's dt (set by apply_supports)
  // pair_collapse_speed's memory of one instant (the step's start `time`, t within it):
  // the bodies found in a cluster that rests on something, with the reach it was found
  // at (a set's contacts ask about the same bodies again and again at one instant).
  double ground_time = -1.0, ground_t = -1.0;
  std::vector<double> ground_reach;
  std::vector<std::uint32_t> ground_marked;
  double collapse_speed(std::uint32_t i, std::uint32_t j) const {
    if (sim_inelastic) return std::numeric_limits<double>::infinity();
    if (acc.empty() || step_dt == 0.0) return 0.0;
    return rest_speed(std::max(length(acc[i]), length(acc[j])), step_dt);
  }
  // Newtonian gravity couples every body's path: under velocity Verlet or RK4 with
  // exact impacts, a path-changing event cuts the whole system's step (substeps.cpp).
  bool coupled() const {
    return newtonian && mode == CollisionMode::Exact &&
           (integrator == Integrator::VelocityVerlet || integrator == Integrator::Rk4);
  }
  std::size_t memory_bytes() const;
};

// ---- loading (world_load.cpp)
void load_world(World& w, const Scene& scene);
std::vector<OptionSpec> core_option_specs();

// ---- stages of the step, in pipeline order
void compute_accelerations(World& w, std::span<const Vec2> pos, std::span<const Vec2> vel,
                           std::span<Vec2> out);                 // accelerations.cpp
// One body's acceleration from its own forces (field, drag, thrust; not Newtonian
// gravity, which needs every body) at velocity vel (accelerations.cpp).
Vec2 body_acceleration(const World& w, std::uint32_t i, Vec2 vel);
void apply_supports(World& w, const StepContext& ctx);          // resting_contact.cpp
void judge_braced_holds(World& w, bool engage = false);                              // resting_contact.cpp
void begin_paths(World& w, const StepContext& ctx);             // integrators.cpp
void collide_exact(World& w, StepContext& ctx);                 // exact_collisions.cpp
void collide_lecture(World& w, StepContext& ctx, double t_from);   // lecture_collisions.cpp
void end_paths(World& w, const StepContext& ctx);               // integrators.cpp
void finish_particles(World& w, const StepContext& ctx);        // particles.cpp
// Particles (particles.cpp): explosion events for the exact loop, and the one that
// kills a parent at its explosion time.
void schedule_explosions(World& w, const StepContext& ctx, std::vector<Event>& out);
void explode_parent(World& w, std::uint32_t emitter, double t_abs);
// Exact mode: an Emit event for each trail particle due in the step, and its record.
void schedule_trail_emissions(World& w, const StepContext& ctx, std::vector<Event>& out);
void record_emission(World& w, std::uint32_t emitter, Vec2 position, Vec2 velocity, double t_abs);

// ---- convex corners (convex_cap.cpp)
// Body i (on its face, or riding a cap) at time t within the step [0, T]: on its face at a
// leave event over a convex corner (no collinear piece continues it) and too slow to lift
// off (N > 0 on the corner's cap), it rides the cap from t; riding, it goes on. Returns -1
// when it does not ride (it flies: the exact lift-off, or an unmodelled case, counted);
// else the time <= T its path left the cap (lifted off, handed over onto the next face or
// back onto its own; advanced there, its new support set), or T still riding (its state
// at T, tloc = T). t_abs0: the step's start time.
double ride_cap(World& w, std::uint32_t i, double t, double T, double t_abs0, double dt);
// Free body i (its state at t in the step) touching the end point of a segment at a convex
// corner (no face holds it), pressed onto it, slower than the rest speed towards it (at a
// step's start) or meeting it too slowly to bounce clear (impact: e |vn| below the rest
// speed, as settling on a face) and too slow to lift off: its normal velocity goes
// (Coulomb's impulse with it) and it rides that corner's cap from t (true).
bool settle_on_cap(World& w, std::uint32_t i, double t, double t_abs0, double dt, bool impact);
// At a step's start: riders that another body can reach within the step leave the cap
// (free, touching the corner: they micro-bounce, counted as unmodelled).
void release_crowded_riders(World& w, double t_abs0, double dt);
// Another body's path came within reach of riding body i's cap at t_abs (its impacts are
// not found): the run's broken guarantee.
void note_cap_disturbed(World& w, std::uint32_t i, double t_abs);
// The box a riding body can reach (its cap's disc, grown by its radius).
Aabb cap_box(const World& w, std::uint32_t i);
// Whether body i touching the end point `corner` at time t (in the step) is no impact: an
// end of the face it is on (it touches it only tangentially at the end, where its leave
// event takes it), or the corner it has just left the cap of (it leaves the cap's circle at
// third order lifting off, N being 0, at second order onto a face).
bool corner_of_support(const World& w, std::uint32_t i, Vec2 corner, double t);

// ---- shared pieces
// Path acceleration of a supported body: the normal component removed and Coulomb
// friction (or rolling resistance) along the support (resting_contact.cpp).
void support_path(World& w, std::uint32_t i);
// Body i on a face comes to rest (its friction stop): its path from rest (a train's
// member: the one push_trains found for its block from rest).
void stop_on_support(World& w, std::uint32_t i);
// A slow, pressed impact of bodies i and j (touching at t, both on faces of one normal,
// the pair's normal along the face; vr: the pair's rest speed) that `chain` (i, j and
// every body touching them along the face, transitively; all on faces of that normal,
// free, touching nothing else) would set moving as one: the members that the perfectly
// inelastic impact gives one velocity (pooled from the rear as momentum: a block behind
// moving faster than the one in front joins it) share their momentum and move on as
// push_trains' blocks for the rest of the step (pooled from the rear by the face's law
// at that velocity, each block's members at its velocity and acceleration to the bit,
// with their paths from rest if it stops). False, nothing changed, when some pair of
// them would bounce (restitution above the rest speed), a body at rest would be met
// slower than the collapse speed (its supports absorb it), or the forces vary. Else
// true, `moved` the members (advanced to t) whose paths changed.
bool join_train(World& w, std::span<const std::uint32_t> chain, std::uint32_t i, std::uint32_t j, double t, double vr,
                std::vector<std::uint32_t>& moved);
// The other members of body i's block sliding to a stop (they stop with it, at once).
void stopping_mates(const World& w, std::uint32_t i, std::vector<std::uint32_t>& out);
// The support's law for body i on its segment: the acceleration along the face under
// the force acceleration a (its normal part taken by the support), with kinetic
// friction against the sign of vt, or at vt == 0 held by static friction up to its limit.
Vec2 support_acceleration(const World& w, std::uint32_t i, Vec2 a, double vt);
// Releases body i from its support.
void release_support(World& w, std::uint32_t i);
// Body i comes to rest on body j (stuck there), along n from j to i.
void rest_on_body(World& w, std::uint32_t i, std::uint32_t j, Vec2 n);
// Whether body i, pressed onto the stuck body j along n (from j to i), would stay put:
// pressed, slow, and held by static friction.
bool can_rest_on(const World& w, std::uint32_t i, std::uint32_t j, Vec2 n, double rest_speed);
// The inelastic-collapse threshold for an impact of bodies i and j at time t (within the
// step; resting_contact.cpp). What presses a pair together is its relative acceleration,
// and, in a cluster that rests on something, the contact forces that hold the cluster up
// (on average a body in a settling pile does not fall: the pair's relative acceleration
// is then of the order of the field's). So: when the free bodies touching i or j,
// transitively, within the collapse speed times dt (the cluster), reach a face, a static
// body, a body at rest or on a face, or number more than kMaxFreeCluster, it is
// World::collapse_speed (the larger of the two accelerations); when they reach none (the
// cluster falls freely), the rest speed of the spread of the members' force accelerations
// (|(range of a_x, range of a_y)|, at most World::collapse_speed): 0 in a uniform field,
// which in the cluster's free-falling frame is no force at all, as in a scene without
// forces. A body sliding or at rest on one face is not a support by itself (collapse3):
// a cluster with such members is pressed (World::collapse_speed) only where two members,
// or a member and a face other than its own, accelerate into each other under their own
// laws (field, the face's support and friction); else 0 (two balls along a floor).
inline constexpr std::size_t kMaxFreeCluster = 64;
double pair_collapse_speed(World& w, std::uint32_t i, std::uint32_t j, double t);
// Whether an impact of bodies i and j at t closing at `closing` (normal speed, > 0 when
// they approach) is slower than pair_collapse_speed: its cluster is looked at only when
// it is slower than World::collapse_speed (never more than that).
inline bool collapses(World& w, std::uint32_t i, std::uint32_t j, double t, double closing) {
  return closing < w.collapse_speed(i, j) && closing < pair_collapse_speed(w, i, j, t);
}
// Appends the bodies resting on j, and on those in turn, to w.released.
void collect_dependents(World& w, std::uint32_t j);
// Several supports at once (resting_contact.cpp). Body i, slow (|v| <= the rest speed
// of its acceleration), is held at rest if the stationary bodies and faces it touches
// can balance its force: -a lies in the cone spanned by their normals widened by their
// static friction cones. Then its velocity goes to 0, support[i] = kHeld and its
// contacts are recorded. `near`: bodies that may touch it (others are ignored).
// With settle_into_pocket, a body touching one support and within rest_speed x dt of a
// second is also held where the two meet, if they hold it there (the limit of its
// inelastic collapse into that pocket).
bool try_hold(World& w, std::uint32_t i, double dt, std::span<const std::uint32_t> near,
              bool settle_into_pocket = false);
// A group: the slow free bodies touching body `seed` at time t (within the step), and
// those touching them, held at rest together if forces within their static friction
// cones (normal forces >= 0) can hold every one of them still (an acceleration-level
// contact problem, projected Gauss-Seidel). near_fn(p, pad, out) lists the bodies whose
// boxes meet the square of half-side pad around p.
using NearFn = std::function<void(Vec2, double, std::vector<std::uint32_t>&)>;
bool try_hold_group(World& w, std::uint32_t seed, double t, double dt, const NearFn& near_fn,
                    std::vector<std::uint32_t>& members);
// A group's pocket (the limit of its inelastic collapse): the slow free bodies within
// rest_speed x dt of the seed (and of each other), with their faces and stationary
// bodies that near, moved (each at most rest_speed x dt, by the smallest mass-weighted
// displacement) to where all those near contacts touch, then held there by
// try_hold_group. Only when that gains no energy (the work of their forces along the
// move is at least minus their kinetic energy), overlaps nothing and holds them all;
// otherwise nothing changes (but the members' advance to t along their paths).
// near_fn(p, pad, out): every body (stationary or not) whose box meets the square of
// half-side pad around p.
bool try_hold_group_pocket(World& w, std::uint32_t seed, double t, double dt, const NearFn& near_fn,
                           std::vector<std::uint32_t>& members);
// A slow body wedged among stationary bodies and faces (no impulse moves it, so the
// same impact would recur at the same instant for ever) is held where it is, whether
// or not its contacts balance its force exactly; the next step judges it again.
bool hold_wedged(World& w, std::uint32_t i, double dt, std::span<const std::uint32_t> near);
// The contacts of all bodies at rest (held, or stuck on a face or a body) with their
// normal forces from the equilibrium of all at once (frictionless normal forces >= 0,
// projected Gauss-Seidel to round-off).
struct RestingContact {
  std::uint32_t body = 0;
  std::uint32_t other = 0;   // a body, or kBodySupport | segment
  Vec2 n;                    // towards body
  double force = 0.0;
};
std::vector<RestingContact> resting_contacts(const World& w);
// Forgets a held body's contacts and makes it free (its path: a = acc).
void unhold(World& w, std::uint32_t i);
// Appends the held bodies with a contact on body j to `out`.
void held_on(const World& w, std::uint32_t j, std::vector<std::uint32_t>& out);
// Time within the step at which a supported body stops sliding or leaves its
// segment, from time t (toi::kNever if not in [t, T]).
double support_stop_time(const World& w, std::uint32_t i, double t, double T);
double support_leave_time(const World& w, std::uint32_t i, double t, double T);
// Body i, leaving its face k over one of its ends (advanced to that moment), where a
// collinear piece continues the face: handed over to it (true), else nothing changes.
bool hand_over_support(World& w, std::uint32_t i, double t_abs, double dt);
// Whether segment k is another piece on the line of body i's supporting face.
// Its face, or a cap at a junction of pieces on that line (cap; i's centre at `at` when it
// meets it), is no impact for i.
bool on_support_line(World& w, std::uint32_t i, std::uint32_t k, bool cap, Vec2 at);
// A concave corner: body i, on a face, meets face k slowly along n; if after Newton's
// law at k (e = 0, Coulomb) it moves along k away from its face, it rests on k (true).
bool settle_on_next_face(World& w, std::uint32_t i, std::uint32_t k, Vec2 n, const PairMaterial& m);
// Settles body i on face k (normal n) at once: the normal velocity goes (friction impulse
// included, Newton e = 0) and the body rests on the face, its path along it.
void settle_on_face(World& w, std::uint32_t i, std::uint32_t k, Vec2 n, const PairMaterial& m);

// Sub-steps (substeps.cpp): an impact inside a step keeps the integrator's order.
// Whether body i follows sub-steps of its integrator, so that a velocity change inside
// a step starts a new one: state-dependent forces, velocity Verlet or RK4, no Newtonian
// gravity (there the whole system is cut: coupled sub-steps, below), free or sliding on
// a face (not at rest on bodies).
bool uses_substeps(const World& w, std::uint32_t i);
// The acceleration of body i on sub-steps at velocity v: its forces', or on a face the
// support's law with friction against the sliding direction of the sub-step's start.
Vec2 substep_acceleration(const World& w, std::uint32_t i, Vec2 v);
// The acceleration that presses body i's contacts at an impact: effective_acc, except that a
// free body on sub-steps (forces depending on the velocity: drag, wind, thrust) has its forces
// at its velocity now; acc[i] is its step start's, stale after an earlier impact in the step.
Vec2 impact_acceleration(const World& w, std::uint32_t i);
// Body i's state at time t of the step as its integrator gives it: one step of the
// integrator from the start of its current sub-step to t. Off sub-steps: its path.
struct PathState {
  Vec2 p, v;
};
PathState integrator_state(const World& w, std::uint32_t i, double t);
// Whether an impact of body i needs its time found on the integrator's own path
// (RK4: its path through the sub-step's end differs from the step cut at the impact).
bool needs_impact_refinement(const World& w, std::uint32_t i);
// Moves body i to its integrator state at t (the sub-step ends there).
void end_substep(World& w, std::uint32_t i, double t);
// Body i's velocity changed at t (T: the step's length): a new sub-step from its state at t.
void start_substep(World& w, std::uint32_t i, double t, double T);
// The time of an impact found at t on the paths, moved to the root of the gap on the
// integrator's own path (within [t_min, T]); t itself when nothing needs refining.
double refine_static_impact(const World& w, std::uint32_t i, const Segment& seg, bool cap, double t, double t_min,
                            double T);
double refine_pair_impact(const World& w, std::uint32_t i, std::uint32_t j, double t, double t_min, double T);
// The same for a sliding body's stop (its velocity along the face reaches 0) and for
// its leaving the end of its segment.
double refine_stop(const World& w, std::uint32_t i, double t, double t_min, double T);
double refine_leave(const World& w, std::uint32_t i, double t, double t_min, double T);
// Coupled sub-steps (w.coupled(), substeps.cpp): every free body follows one step of
// the integrator of the whole system from w.tcut. An impact at t found on the paths is
// moved to the root of its gap on that step (RK4; Verlet's positions are its paths);
// coupled_cut puts every free body at the system's integrator state at t; after the
// event, coupled_restart starts the system's next sub-step there, to T.
double refine_coupled_pair(World& w, std::uint32_t i, std::uint32_t j, double t, double t_min, double T);
double refine_coupled_static(World& w, std::uint32_t i, const Segment& seg, bool cap, double t, double t_min,
                             double T);
void coupled_cut(World& w, double t);
void coupled_restart(World& w, double t, double T);

// Box bounding body i's path from t to T (swept), plus its radius.
Aabb path_box(const World& w, std::uint32_t i, double t, double T);

// Impulse resolution (collision_response.cpp). n points from the first object to the
// second. Returns the normal impulse magnitude.
struct ImpactResult {
  double normal_impulse = 0.0;
  double closing_speed = 0.0;   // -(relative normal velocity) before, >= 0
};
ImpactResult resolve_pair(World& w, std::uint32_t i, std::uint32_t j, Vec2 n, const PairMaterial& m,
                          double min_separation_speed);
// Simultaneous impacts (simultaneous_impacts.cpp): if the pair (i, j) impacting at t
// belongs to a touching set of two or more contacts, solves Newton's law on all of
// them at once, leaves every body of the set advanced to t in `bodies` and the pairs
// that took an impulse in `impacted`, returns true.
// Otherwise (one contact, sequential law, friction, supports, rules) changes nothing.
// j may also be kSimultaneousFace | k: body i's impact on face k of segment k; the set
// then includes the faces its bodies touch, and `impacted` names a face the same way.
inline constexpr std::uint32_t kSimultaneousFace = 0x80000000u;
// seed_min_sep: the pair (i, j) leaves at least this fast (a micro-bounce).
bool resolve_simultaneous(World& w, std::uint32_t i, std::uint32_t j, double t, std::vector<std::uint32_t>& bodies,
                          std::vector<BodyPair>& impacted, double seed_min_sep = 0.0);
ImpactResult resolve_static(World& w, std::uint32_t i, Vec2 n, const PairMaterial& m,
                            double min_separation_speed);
// Records a contact event if the contact begins (see exact_collisions.cpp) at absolute
// time t. partner: a body index, or static_partner_key(segment owner).
void record_contact(World& w, std::uint32_t i, std::uint32_t partner_body, const Segment* seg,
                    double t_abs, double window);
std::uint32_t static_partner_key(const ObjectRef& owner);
// The key of a touching pair: body i and a body or a static_partner_key (either order).
std::uint64_t contact_key(std::uint32_t i, std::uint32_t partner);
// Marks the pair as touching at time t (a continuing contact, no event).
void touch_contact(World& w, std::uint32_t i, std::uint32_t partner, double t_abs);
// Forgets pairs that last touched more than one step before t0 (they cannot continue).
void forget_old_contacts(World& w, double t0, double dt);

void kill_body(World& w, std::uint32_t i);

// Bodies moving in contact (contact_group.cpp). A resting component that cannot hold
// (members at rest) becomes a contact group, moved by advance_contact_groups at each step's
// end; false (nothing changed) where the mode does not apply.
bool engage_contact_group(World& w, std::span<const std::uint32_t> members);
void hide_contact_groups(World& w, const StepContext& ctx);
void advance_contact_groups(World& w, const StepContext& ctx);
// A body's force acceleration where contact groups are allowed (constant forces): w.acc is 0
// for a body hidden in a group when the step's forces were computed, so groups take it here.
inline Vec2 group_force_acc(const World& w, std::uint32_t i) {
  return w.dynamic(i) || (w.flags[i] & (kAlive | kStatic)) == 0 ? body_acceleration(w, i, w.vel[i]) : Vec2{};
}
// Whether the scene allows contact groups at all (exact impacts, constant forces, no rules,
// emitters or Newtonian gravity).
bool contact_groups_allowed(const World& w);
// Whether it allows granular groups (granular.cpp): the same but forces may depend on the
// velocity (drag, wind, thrust, taken at each sub-step's start), and not with
// [core] dense_contact = "events".
bool granular_allowed(const World& w);

// Granular groups (granular.cpp): nonsmooth contact dynamics (Moreau-Jean time stepping) on
// sub-steps, the velocity-level Signorini-Coulomb problem solved by projected Gauss-Seidel to
// round-off, positions projected off every overlap. Moves group g over the step, writes its
// members' states to w, and the box each member swept to member_boxes (x0, y0, x1, y1 each).
void granular_step(World& w, World::ContactGroup& g, const StepContext& ctx, std::vector<double>& member_boxes);
// Splits a granular group after its step: members touching (transitively, within one step's
// reach) stay together; a member touching no other leaves to the engine. Appends the groups
// that stay to `out` (warm impulses kept).
void granular_split(World& w, World::ContactGroup& g, double dt, std::vector<World::ContactGroup>& out);
// An impact storm: a body met more than kStormImpacts times in one step by pressed, slow pair
// impacts (the inelastic collapse of a pile) makes the bodies touching it, transitively, a
// granular group at the step's end (where groups are allowed).
inline constexpr std::uint32_t kStormImpacts = 24;
// A storm this fierce within one step (a collapse that would run to the event cap) is engaged
// at once, for the rest of the step (engage_storm_groups_now, from the event loop).
inline constexpr std::uint32_t kStormBail = 8 * kStormImpacts;
void note_storm_impact(World& w, std::uint32_t i, std::uint32_t j);
void engage_storm_groups(World& w, const StepContext& ctx);
// The same at time t within the step (every body advanced to t): the new groups are hidden and
// step from t (ContactGroup::start). True if a group was made.
bool engage_storm_groups_now(World& w, const StepContext& ctx, double t);
// The bodies that may meet a group (members `members`) within a step of dt, transitively:
// appended to `add`; groups within reach to `merge` (indices into w.contact_groups). False
// where one cannot join (a particle or point, a body on a corner's cap, or, when `limit` is
// reached, too many). `exclude_group`: the group's own index (or -1).
bool plan_group_reach(const World& w, const std::vector<std::uint32_t>& members, double dt, std::size_t limit,
                      std::ptrdiff_t exclude_group, std::vector<std::uint32_t>& add, std::vector<std::size_t>& merge,
                      bool statics_ok);

// Pass-through pairs (collision matrix "event" and overlap tracking).
std::uint64_t pair_key(std::uint32_t i, std::uint32_t j);
std::uint64_t static_key(std::uint32_t i, std::uint32_t segment);
bool is_passing(const World& w, std::uint64_t key);
void add_passing(World& w, std::uint64_t key);
void prune_passing(World& w);   // drops pairs that no longer overlap

}  // namespace physval::core_detail
