// Building core's world from a scene: options, bodies into arrays, static geometry
// into segments, materials and collision-matrix groups into small tables.
#include <algorithm>
#include <cmath>
#include <map>
#include <stdexcept>
#include <tuple>

#include "physval/core/options.hpp"
#include "world.hpp"

namespace physval::core_detail {

const char* integrator_name(Integrator i) {
  switch (i) {
    case Integrator::ExplicitEuler: return "explicit_euler";
    case Integrator::SemiImplicitEuler: return "semi_implicit_euler";
    case Integrator::VelocityVerlet: return "velocity_verlet";
    case Integrator::Rk4: return "rk4";
  }
  return "unknown";
}

std::vector<OptionSpec> core_option_specs() {
  std::vector<OptionSpec> s;
  s.push_back({"integrator", std::string("velocity_verlet"),
               {"explicit_euler", "semi_implicit_euler", "velocity_verlet", "rk4"},
               "time integration: the lecture's explicit Euler (x += v dt; v += a dt), "
               "semi-implicit Euler, velocity Verlet (exact for constant forces), or classic RK4"});
  s.push_back({"collision", std::string("exact"), {"exact", "lecture"},
               "exact: event-driven, advances to each impact in turn within the step; "
               "lecture: move all, find overlaps at the end of the step, back each up to its "
               "interpolated time of impact, reflect, finish the step (one pass)"});
  s.push_back({"impact_law", std::string("simultaneous"), {"simultaneous", "sequential"},
               "exact mode, impacts at the same time (to round-off) that share a body: simultaneous: "
               "Newton's restitution law at every touching contact at once (independent of body "
               "numbering); sequential: one pair at a time in body order (the lecture's answer)"});
  s.push_back({"broadphase", std::string("auto"), {"auto", "all_pairs", "grid", "multigrid", "sort_and_sweep"},
               "broad phase; all give the same pairs. auto: all_pairs below 64 bodies, grid for "
               "similar sizes, multigrid for a moderate spread of sizes, sort_and_sweep beyond"});
  s.push_back({"cell_size", 0.0, {},
               "grid cell edge in m (grid: a lower bound; multigrid: the edge); 0 picks it from the bodies",
       OptionRange::at_least(0)});
  s.push_back({"max_events_per_step", std::int64_t{0}, {},
               "exact mode: events one step may process; at the cap the rest of the step is finished "
                "by the lecture pass, impacts are no longer exact and the run stops as diverged. "
                "0: 1,000,000 + 100 per body",
        OptionRange::between(0, 1e9)});
  s.push_back({"dense_contact", std::string("granular"), {"granular", "events"},
               "exact mode: bodies in persistent contact with several others (a pile's collapse, a "
               "group its holds cannot hold, over 16 bodies) are moved by nonsmooth contact dynamics "
               "(granular: first order, said in limits_hit); events: left to exact impacts (a storm "
               "of them may be slow, a hold it cannot justify is reported diverged)"});
  s.push_back({"rest_speed", 0.0, {},
               "m/s: an impact against a surface the body is pressed into, leaving slower than this, "
               "settles into resting contact. 0: |a_n| dt / 16 (velocity_verlet, rk4) or 1.5 |a_n| dt "
               "(Euler integrators)",
       OptionRange::at_least(0)});
  return s;
}

PairMaterial World::pair_material(std::uint16_t m1, std::uint16_t m2) const {
  if (!material_table.empty()) return material_table[static_cast<std::size_t>(m1) * n_materials + m2];
  const MaterialRep& a = materials[m1];
  const MaterialRep& b = materials[m2];
  return combine_materials(override_scene, {a.name, a.restitution, a.friction, a.static_friction, a.rolling_friction},
                           {b.name, b.restitution, b.friction, b.static_friction, b.rolling_friction});
}

namespace {

template <class T>
std::size_t bytes_of(const std::vector<T>& v) {
  return v.capacity() * sizeof(T);
}

struct Builder {
  World& w;
  const Scene& scene;
  std::map<std::string, std::uint16_t> group_ids;
  std::vector<std::string> group_names;
  std::map<std::tuple<double, double, double, double>, std::uint16_t> anonymous_materials;
  std::vector<std::string> override_names;

  std::uint16_t group_id(const std::string& g) {
    auto it = group_ids.find(g);
    if (it != group_ids.end()) return it->second;
    if (group_names.size() >= 0xffff) throw std::runtime_error("core: too many collision groups");
    const auto id = static_cast<std::uint16_t>(group_names.size());
    group_ids.emplace(g, id);
    group_names.push_back(g);
    return id;
  }

  std::uint16_t material_id(const std::string& name, double e, double mu, double mus, double crr) {
    const bool named = std::find(override_names.begin(), override_names.end(), name) != override_names.end();
    if (!named) {
      const auto key = std::make_tuple(e, mu, mus, crr);
      auto it = anonymous_materials.find(key);
      if (it != anonymous_materials.end()) return it->second;
      const auto id = static_cast<std::uint16_t>(w.materials.size());
      anonymous_materials.emplace(key, id);
      w.materials.push_back({std::string(), e, mu, mus, crr});
      return id;
    }
    if (w.materials.size() >= 0xffff) throw std::runtime_error("core: too many distinct materials");
    const auto id = static_cast<std::uint16_t>(w.materials.size());
    w.materials.push_back({name, e, mu, mus, crr});
    return id;
  }

  void add_segment(Vec2 from, Vec2 to, ObjectRef owner, const std::string& name, const StaticMaterial& m,
                   Vec2 n_from = {}, Vec2 n_to = {}) {
    Segment s;
    s.from = from;
    s.to = to;
    s.length = length(to - from);
    if (!(s.length > 0.0)) return;   // a degenerate piece: nothing to hit
    s.dir = (to - from) / s.length;
    s.normal = perp(s.dir);
    s.normal_from = n_from;
    s.normal_to = n_to;
    s.owner = owner;
    s.material = material_id(name, m.restitution, m.friction, std::max(m.static_friction, m.friction),
                             m.rolling_friction);
    s.group = group_id(m.group);
    w.statics.segments.push_back(s);
  }
};

void read_options(World& w, const Scene& scene) {
  const std::vector<OptionSpec> specs = core_option_specs();
  const OptionReader opt(scene, "core", specs);
  const std::string integ = opt.get_string("integrator");
  if (integ == "explicit_euler") w.integrator = Integrator::ExplicitEuler;
  else if (integ == "semi_implicit_euler") w.integrator = Integrator::SemiImplicitEuler;
  else if (integ == "velocity_verlet") w.integrator = Integrator::VelocityVerlet;
  else if (integ == "rk4") w.integrator = Integrator::Rk4;
  else throw std::invalid_argument("core: unknown integrator '" + integ + "'");
  const std::string coll = opt.get_string("collision");
  if (coll == "exact") w.mode = CollisionMode::Exact;
  else if (coll == "lecture") w.mode = CollisionMode::Lecture;
  else throw std::invalid_argument("core: unknown collision mode '" + coll + "'");
  const std::string law = opt.get_string("impact_law");
  if (law == "simultaneous") w.impact_law = ImpactLaw::Simultaneous;
  else if (law == "sequential") w.impact_law = ImpactLaw::Sequential;
  else throw std::invalid_argument("core: unknown impact_law '" + law + "'");
  const std::string bp = opt.get_string("broadphase");
  w.broadphase_auto = bp == "auto";
  if (!w.broadphase_auto && !parse_broadphase(bp, w.broadphase)) {
    throw std::invalid_argument("core: unknown broadphase '" + bp + "'");
  }
  w.cell_size = opt.get_double("cell_size");
  if (!(w.cell_size >= 0.0) || !std::isfinite(w.cell_size)) throw std::invalid_argument("core: cell_size must be >= 0");
  w.max_events_option = opt.get_int("max_events_per_step");
  if (w.max_events_option < 0) throw std::invalid_argument("core: max_events_per_step must be >= 0");
  w.granular_enabled = opt.get_string("dense_contact") == "granular";
  w.rest_speed_option = opt.get_double("rest_speed");
  if (!(w.rest_speed_option >= 0.0) || !std::isfinite(w.rest_speed_option)) {
    throw std::invalid_argument("core: rest_speed must be >= 0");
  }
  const bool euler = w.integrator == Integrator::ExplicitEuler || w.integrator == Integrator::SemiImplicitEuler;
  w.rest_factor = euler ? 1.5 : 1.0 / 16.0;
}

}  // namespace

void load_world(World& w, const Scene& scene) {
  read_options(w, scene);
  Builder b{w, scene, {}, {}, {}, {}};
  b.group_id("");
  for (const MaterialOverride& o : scene.materials) {
    b.override_names.push_back(o.a);
    b.override_names.push_back(o.b);
  }
  w.override_scene.materials = scene.materials;

  const WorldDef& wd = scene.world;
  w.gravity = wd.gravity;
  w.wind = wd.wind;
  w.newtonian = wd.newtonian;
  w.G = wd.G;
  w.softening = wd.softening;

  bool any_drag = false, any_thrust = false;
  for (const BodyDef& d : scene.bodies) {
    any_drag = any_drag || d.drag_linear != 0.0 || d.drag_quadratic != 0.0;
    any_thrust = any_thrust || d.thrust.enabled();
  }
  const bool gravity = wd.gravity.x != 0.0 || wd.gravity.y != 0.0;
  w.varying_forces = any_drag || any_thrust || w.newtonian;
  w.any_forces = gravity || w.varying_forces;

  // Capacity for every body the run can create: the scene's and its particles.
  std::size_t particles = 0;
  for (const EmitterDef& e : scene.emitters) {
    if (e.mode == EmitterMode::Explode) particles += static_cast<std::size_t>(std::max(e.count, 0));
    else particles += static_cast<std::size_t>(std::max(0.0, e.rate * scene.duration)) + 2;
  }
  const std::size_t cap = scene.bodies.size() + particles;
  auto reserve_all = [&](auto&... v) { (v.reserve(cap), ...); };
  reserve_all(w.pos, w.vel, w.tloc, w.inv_mass, w.radius, w.version, w.flags, w.group, w.material);
  w.name_end.reserve(scene.bodies.size());
  if (w.newtonian) w.mass.reserve(cap);
  if (any_thrust) w.angle.reserve(cap);
  if (any_drag || any_thrust) w.fparams.reserve(cap);
  if (w.any_forces) reserve_all(w.acc, w.apath, w.support, w.support_n, w.dep_head, w.dep_next);
  if (w.varying_forces) reserve_all(w.vcorr, w.tsub, w.psub, w.vsub, w.ksub);

  double extent = 0.0;
  double max_radius = 0.0;
  for (const BodyDef& d : scene.bodies) {
    if (!is_finite(d.position) || !is_finite(d.velocity)) throw std::invalid_argument("core: body '" + d.name + "' is not finite");
    const bool point = d.shape == ShapeKind::Point;
    if (!point && !(d.radius > 0.0)) throw std::invalid_argument("core: circle '" + d.name + "' needs radius > 0");
    if (!d.is_static && !(d.mass > 0.0)) throw std::invalid_argument("core: body '" + d.name + "' needs mass > 0");
    w.pos.push_back(d.position);
    w.vel.push_back(d.is_static ? Vec2{} : d.velocity);
    w.tloc.push_back(0.0);
    w.inv_mass.push_back(d.is_static ? 0.0 : 1.0 / d.mass);
    w.radius.push_back(point ? 0.0 : d.radius);
    w.version.push_back(0);
    std::uint8_t f = kAlive;
    if (d.is_static) f |= kStatic;
    if (point) f |= kPoint;
    w.flags.push_back(f);
    w.group.push_back(b.group_id(d.group));
    w.material.push_back(b.material_id(d.name, d.restitution, d.friction, std::max(d.static_friction, d.friction),
                                       d.rolling_friction));
    w.name_chars += d.name;
    w.name_end.push_back(static_cast<std::uint32_t>(w.name_chars.size()));
    if (w.newtonian) w.mass.push_back(d.mass);
    if (any_thrust) w.angle.push_back(d.angle);
    if (any_drag || any_thrust) {
      ForceParams fp{d.drag_linear, d.drag_quadratic, -1};
      if (d.thrust.enabled()) {
        fp.thrust = static_cast<std::int32_t>(w.thrusts.size());
        w.thrusts.push_back(d.thrust);
      }
      w.fparams.push_back(fp);
    }
    w.push_force_state();
    extent = std::max({extent, std::fabs(d.position.x), std::fabs(d.position.y)});
    max_radius = std::max(max_radius, d.radius);
  }
  w.scene_bodies = scene.bodies.size();

  for (std::size_t k = 0; k < scene.walls.size(); ++k) {
    const WallDef& d = scene.walls[k];
    b.add_segment(d.from, d.to, {ObjectRef::Kind::Wall, static_cast<std::uint32_t>(k)}, d.name, d.material);
  }
  for (std::size_t k = 0; k < scene.boxes.size(); ++k) {
    const BoxDef& d = scene.boxes[k];
    const ObjectRef owner{ObjectRef::Kind::Box, static_cast<std::uint32_t>(k)};
    const Vec2 c[4] = {d.min, {d.max.x, d.min.y}, d.max, {d.min.x, d.max.y}};
    for (int s = 0; s < 4; ++s) b.add_segment(c[s], c[(s + 1) % 4], owner, d.name, d.material);
  }
  for (std::size_t k = 0; k < scene.surfaces.size(); ++k) {
    const SurfaceDef& d = scene.surfaces[k];
    const ObjectRef owner{ObjectRef::Kind::Surface, static_cast<std::uint32_t>(k)};
    const bool normals = d.normals.size() == d.points.size();
    for (std::size_t p = 0; p + 1 < d.points.size(); ++p) {
      b.add_segment(d.points[p], d.points[p + 1], owner, d.name, d.material, normals ? d.normals[p] : Vec2{},
                    normals ? d.normals[p + 1] : Vec2{});
    }
  }
  for (const Segment& s : w.statics.segments) {
    extent = std::max({extent, std::fabs(s.from.x), std::fabs(s.from.y), std::fabs(s.to.x), std::fabs(s.to.y)});
  }
  w.length_scale = std::max(1e-9, extent + max_radius);
  w.statics.build(std::max(2.0 * max_radius, 1e-3 * w.length_scale));

  // Emitters: particles take their parent's group.
  for (const EmitterDef& e : scene.emitters) {
    EmitterState st;
    st.def = e;
    const int p = scene.body_index(e.parent);
    if (p < 0) throw std::invalid_argument("core: emitter '" + e.name + "' has no parent body '" + e.parent + "'");
    st.parent = static_cast<std::uint32_t>(p);
    st.rng.seed(e.seed);
    st.next_emit = e.rate > 0.0 ? 1.0 / e.rate : INFINITY;
    w.emitters.push_back(std::move(st));
  }
  w.birth.reserve(particles);
  w.lifetime.reserve(particles);
  w.parent.reserve(particles);

  // Collision matrix: every group named anywhere, then a response per pair of groups.
  for (const CollisionRule& r : scene.collision_matrix) {
    b.group_id(r.a);
    b.group_id(r.b);
  }
  w.n_groups = static_cast<std::uint16_t>(b.group_names.size());
  w.responses.resize(static_cast<std::size_t>(w.n_groups) * w.n_groups);
  for (std::uint16_t g1 = 0; g1 < w.n_groups; ++g1) {
    for (std::uint16_t g2 = 0; g2 < w.n_groups; ++g2) {
      w.responses[static_cast<std::size_t>(g1) * w.n_groups + g2] =
          response_between(scene, b.group_names[g1], b.group_names[g2]);
    }
  }
  w.any_rules = !scene.collision_matrix.empty();

  // Pair materials: a table when there are few distinct materials.
  w.n_materials = static_cast<std::uint16_t>(w.materials.size());
  if (w.n_materials <= 128) {
    w.material_table.clear();
    w.material_table.reserve(static_cast<std::size_t>(w.n_materials) * w.n_materials);
    for (std::uint16_t m1 = 0; m1 < w.n_materials; ++m1) {
      for (std::uint16_t m2 = 0; m2 < w.n_materials; ++m2) {
        const World::MaterialRep& x = w.materials[m1];
        const World::MaterialRep& y = w.materials[m2];
        w.material_table.push_back(combine_materials(
            scene, {x.name, x.restitution, x.friction, x.static_friction, x.rolling_friction},
            {y.name, y.restitution, y.friction, y.static_friction, y.rolling_friction}));
      }
    }
  }

  // Broad phase.
  if (w.broadphase_auto) w.broadphase = choose_broadphase(w.radius);
  w.bp = make_broadphase(w.broadphase, w.cell_size);
  w.active.reserve(cap);
  if (w.mode == CollisionMode::Exact) w.events.reserve(cap / 4, cap / 16);
  w.contacts.reserve(std::max<std::size_t>(64, cap / 4));
  w.passing.reserve(16);
  w.time = 0.0;
  w.end_time = scene.duration;
}

std::size_t World::memory_bytes() const {
  std::size_t n = sizeof(World);
  n += bytes_of(pos) + bytes_of(vel) + bytes_of(tloc) + bytes_of(inv_mass) + bytes_of(radius) + bytes_of(version);
  n += bytes_of(flags) + bytes_of(group) + bytes_of(material) + bytes_of(mass) + bytes_of(angle);
  n += bytes_of(acc) + bytes_of(apath) + bytes_of(vcorr) + bytes_of(tsub) + bytes_of(psub) + bytes_of(vsub) + bytes_of(ksub) + bytes_of(fparams) + bytes_of(support);
  n += bytes_of(dep_head) + bytes_of(dep_next) + bytes_of(released);
  n += bytes_of(support_n) + last_touch.size() * (sizeof(std::uint64_t) + sizeof(double) + 2 * sizeof(void*)) + bytes_of(name_end) +
       bytes_of(ground_reach) + bytes_of(ground_marked);
  n += name_chars.capacity() + 1;
  n += bytes_of(birth) + bytes_of(lifetime) + bytes_of(parent) + bytes_of(emitters);
  n += statics.memory_bytes() + bytes_of(material_table) + bytes_of(responses) + bytes_of(materials);
  n += bp ? bp->memory_bytes() : 0;
  n += bytes_of(active) + bytes_of(pairs) + bytes_of(found) + bytes_of(found_static);
  n += events.memory_bytes() + bytes_of(passing) + bytes_of(scratch_p) + bytes_of(scratch_v) + bytes_of(scratch_f);
  for (const auto& s : scratch_a) n += bytes_of(s);
  n += bytes_of(cpl_x) + bytes_of(cpl_v) + bytes_of(cpl_vs);
  for (const auto& s : cpl_k) n += bytes_of(s);
  n += bytes_of(contacts);
  return n;
}

void kill_body(World& w, std::uint32_t i) {
  w.flags[i] = static_cast<std::uint8_t>(w.flags[i] & ~kAlive);
  ++w.version[i];
  if (w.supported(i)) release_support(w, i);
  if (!w.mass.empty()) w.mass[i] = 0.0;   // no longer attracts
}

}  // namespace physval::core_detail
