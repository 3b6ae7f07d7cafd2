// A thin plugin wrapper around an adapter written against physval's C++ Engine
// interface: the scene arrives as physval/plugin.h's plain C structs and becomes the
// same physval::Scene a built-in engine gets; every call goes to the adapter, every
// answer goes back as plugin.h's structs. The plugin's behaviour is therefore the
// built-in adapter's, bit for bit (adapters/tests/optional/engine_plugins_test.cpp).
//
// Use: one .cpp per plugin library,
//   struct Traits { static physval::EngineFactory factory() { return physval::chipmunk_engine_factory(); } };
//   PHYSVAL_PLUGIN_DEFINE(physval::plugin_bridge::BridgedEngine<Traits>)
#pragma once

#include <memory>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "physval/engine/engine.hpp"
#include "physval/plugin.hpp"

namespace physval::plugin_bridge {

inline Vec2 vec(physval_vec2 v) { return {v.x, v.y}; }
inline std::string str(const char* s) { return s == nullptr ? std::string() : std::string(s); }

inline StaticMaterial material(const physval_material& m) {
  StaticMaterial out;
  out.restitution = m.restitution;
  out.friction = m.friction;
  out.static_friction = m.static_friction;
  out.rolling_friction = m.rolling_friction;
  out.group = str(m.group);
  return out;
}

// The plain C scene as physval's own scene model (defaults are already applied by the host).
inline Scene to_scene(const physval_scene& c, const std::string& engine) {
  Scene s;
  s.name = str(c.name);
  s.source_file = str(c.source_file);
  s.duration = c.duration;
  s.dt = c.dt;
  s.world.gravity = vec(c.world.gravity);
  s.world.newtonian = c.world.newtonian != 0;
  s.world.G = c.world.G;
  s.world.softening = c.world.softening;
  s.world.wind = vec(c.world.wind);
  for (std::size_t i = 0; i < c.body_count; ++i) {
    const physval_body& b = c.bodies[i];
    BodyDef d;
    d.name = str(b.name);
    d.shape = b.shape == PHYSVAL_SHAPE_POINT ? ShapeKind::Point : ShapeKind::Circle;
    d.radius = b.radius;
    d.mass = b.mass;
    d.is_static = b.is_static != 0;
    d.position = vec(b.position);
    d.velocity = vec(b.velocity);
    d.angle = b.angle;
    d.angular_velocity = b.angular_velocity;
    d.restitution = b.restitution;
    d.friction = b.friction;
    d.static_friction = b.static_friction;
    d.rolling_friction = b.rolling_friction;
    d.drag_linear = b.drag_linear;
    d.drag_quadratic = b.drag_quadratic;
    d.group = str(b.group);
    const physval_thrust& t = b.thrust;
    if (t.speed_count > 0) {
      d.thrust.speeds.assign(t.speeds, t.speeds + t.speed_count);
      if (t.gear_count > 0) d.thrust.gears.assign(t.gears, t.gears + t.gear_count);
      const std::size_t rows = t.gear_count > 0 ? t.gear_count : 1;
      for (std::size_t r = 0; r < rows; ++r) {
        d.thrust.accel.emplace_back(t.accel + r * t.speed_count, t.accel + (r + 1) * t.speed_count);
      }
      d.thrust.throttle = t.throttle;
      d.thrust.gear = t.gear;
    }
    s.bodies.push_back(std::move(d));
  }
  for (std::size_t i = 0; i < c.wall_count; ++i) {
    s.walls.push_back({str(c.walls[i].name), vec(c.walls[i].from), vec(c.walls[i].to), material(c.walls[i].material), 0});
  }
  for (std::size_t i = 0; i < c.box_count; ++i) {
    s.boxes.push_back({str(c.boxes[i].name), vec(c.boxes[i].min), vec(c.boxes[i].max), material(c.boxes[i].material), 0});
  }
  for (std::size_t i = 0; i < c.surface_count; ++i) {
    const physval_surface& f = c.surfaces[i];
    SurfaceDef d;
    d.name = str(f.name);
    for (std::size_t k = 0; k < f.point_count; ++k) d.points.push_back(vec(f.points[k]));
    if (f.normals != nullptr) {
      for (std::size_t k = 0; k < f.point_count; ++k) d.normals.push_back(vec(f.normals[k]));
    }
    d.material = material(f.material);
    s.surfaces.push_back(std::move(d));
  }
  for (std::size_t i = 0; i < c.material_count; ++i) {
    const physval_material_override& m = c.materials[i];
    MaterialOverride o;
    o.a = str(m.a);
    o.b = str(m.b);
    if (m.has_restitution) o.restitution = m.restitution;
    if (m.has_friction) o.friction = m.friction;
    if (m.has_static_friction) o.static_friction = m.static_friction;
    if (m.has_rolling_friction) o.rolling_friction = m.rolling_friction;
    s.materials.push_back(std::move(o));
  }
  for (std::size_t i = 0; i < c.collision_rule_count; ++i) {
    const physval_collision_rule& r = c.collision_rules[i];
    CollisionResponse resp = CollisionResponse::Bounce;
    switch (r.response) {
      case PHYSVAL_RESPONSE_BOUNCE: resp = CollisionResponse::Bounce; break;
      case PHYSVAL_RESPONSE_DESTROY_A: resp = CollisionResponse::DestroyA; break;
      case PHYSVAL_RESPONSE_DESTROY_B: resp = CollisionResponse::DestroyB; break;
      case PHYSVAL_RESPONSE_DESTROY_BOTH: resp = CollisionResponse::DestroyBoth; break;
      case PHYSVAL_RESPONSE_IGNORE: resp = CollisionResponse::Ignore; break;
      case PHYSVAL_RESPONSE_EVENT: resp = CollisionResponse::Event; break;
      default: throw std::invalid_argument("collision rule " + str(r.a) + "/" + str(r.b) + ": unknown response");
    }
    s.collision_matrix.push_back({str(r.a), str(r.b), resp});
  }
  for (std::size_t i = 0; i < c.emitter_count; ++i) {
    const physval_emitter& e = c.emitters[i];
    EmitterDef d;
    d.name = str(e.name);
    d.parent = str(e.parent);
    d.mode = e.mode == PHYSVAL_EMITTER_TRAIL ? EmitterMode::Trail : EmitterMode::Explode;
    d.at = e.at;
    d.rate = e.rate;
    d.count = e.count;
    d.speed = e.speed;
    d.lifetime = e.lifetime;
    d.mass = e.mass;
    d.destroy_on_collision = e.destroy_on_collision != 0;
    d.gravity = e.gravity != 0;
    d.seed = e.seed;
    s.emitters.push_back(std::move(d));
  }
  EngineOptions& opts = s.engine_options[engine];
  for (std::size_t i = 0; i < c.option_count; ++i) {
    const physval_option& o = c.options[i];
    switch (o.value.type) {
      case PHYSVAL_OPTION_BOOL: opts[str(o.key)] = OptionValue{o.value.b != 0}; break;
      case PHYSVAL_OPTION_INT: opts[str(o.key)] = OptionValue{static_cast<std::int64_t>(o.value.i)}; break;
      case PHYSVAL_OPTION_DOUBLE: opts[str(o.key)] = OptionValue{o.value.d}; break;
      case PHYSVAL_OPTION_STRING: opts[str(o.key)] = OptionValue{str(o.value.s)}; break;
    }
  }
  return s;
}

// The adapter's declaration as plugin.h's, kept for the life of the library.
struct InfoStore {
  EngineInfo info;
  std::vector<std::vector<const char*>> choices;
  std::vector<physval_option_spec> specs;
  physval_info c{};

  explicit InfoStore(EngineInfo i) : info(std::move(i)) {
    choices.resize(info.options.size());
    for (std::size_t k = 0; k < info.options.size(); ++k) {
      const OptionSpec& o = info.options[k];
      for (const std::string& ch : o.choices) choices[k].push_back(ch.c_str());
      physval_option_spec s{};
      s.key = o.key.c_str();
      s.default_value = c_value(o.default_value);
      s.choices = choices[k].empty() ? nullptr : choices[k].data();
      s.choice_count = choices[k].size();
      s.doc = o.doc.c_str();
      s.range_lo = o.range.lo;
      s.range_hi = o.range.hi;
      s.range_lo_open = o.range.lo_open ? 1 : 0;
      specs.push_back(s);
    }
    c.name = info.name.c_str();
    c.version = info.version.c_str();
    c.precision = info.precision == Precision::Float32 ? PHYSVAL_FLOAT32 : PHYSVAL_FLOAT64;
    c.summary = info.summary.c_str();
    c.features = 0;
    // physval::Feature's order is the ABI's numbering (plugin.h).
    for (Feature f : info.features) c.features |= PHYSVAL_FEATURE_BIT(static_cast<unsigned>(f));
    c.options = specs.data();
    c.option_count = specs.size();
  }
  static physval_option_value c_value(const OptionValue& v) {
    physval_option_value out{};
    if (const bool* b = std::get_if<bool>(&v)) {
      out.type = PHYSVAL_OPTION_BOOL;
      out.b = *b ? 1 : 0;
    } else if (const std::int64_t* i = std::get_if<std::int64_t>(&v)) {
      out.type = PHYSVAL_OPTION_INT;
      out.i = *i;
      out.d = static_cast<double>(*i);
    } else if (const double* d = std::get_if<double>(&v)) {
      out.type = PHYSVAL_OPTION_DOUBLE;
      out.d = *d;
    } else {
      out.type = PHYSVAL_OPTION_STRING;
      out.s = std::get<std::string>(v).c_str();   // the spec's string lives in `info`
    }
    out.s = out.type == PHYSVAL_OPTION_STRING ? out.s : "";
    return out;
  }
};

template <class Traits>
class BridgedEngine {
 public:
  static const EngineFactory& factory() {
    static const EngineFactory f = Traits::factory();
    return f;
  }
  static InfoStore& store() {
    static InfoStore s(factory().info);
    return s;
  }
  static const physval_info& info() { return store().c; }

  void load(const physval_scene& scene, const physval_host& /*host*/) {
    // The host's material rule and collision matrix are physval's own, which the adapter
    // applies from the same scene (physval/engine/scene.hpp: combine_materials,
    // response_between): the answers are the same.
    const EngineFactory& f = factory();
    engine_ = f.create();
    engine_->load(to_scene(scene, f.info.name));
    metas_.clear();
  }
  void step(double dt) {
    engine_->step(dt);
    contacts_.clear();
    for (const ContactEvent& e : engine_->contacts()) contacts_.push_back({ref(e.a), ref(e.b), e.time});
  }
  double time() const { return engine_->time(); }
  std::size_t body_count() const { return engine_->body_count(); }
  physval_body_meta body_meta(std::size_t i) const {
    while (metas_.size() <= i) metas_.push_back(engine_->body_meta(metas_.size()));
    const BodyMeta& m = metas_[i];
    return {m.name.c_str(), m.mass, m.radius, m.is_static ? 1 : 0};
  }
  void read_states(physval_body_state* out, std::size_t n) const {
    engine_->read_states(states_);
    for (std::size_t i = 0; i < n && i < states_.size(); ++i) {
      const BodyState& s = states_[i];
      out[i] = {{s.position.x, s.position.y}, {s.velocity.x, s.velocity.y}, s.angle, s.angular_velocity, s.alive ? 1 : 0};
    }
  }
  const std::vector<physval_contact>& contacts() const { return contacts_; }
  std::vector<std::pair<std::string, std::string>> settings() const { return engine_->settings(); }
  std::vector<std::string> limits_hit() const { return engine_->limits_hit(); }
  std::string broken_guarantee() const { return engine_->broken_guarantee(); }

 private:
  static physval_object_ref ref(ObjectRef r) {
    physval_object_kind k = PHYSVAL_OBJECT_BODY;
    switch (r.kind) {
      case ObjectRef::Kind::Body: k = PHYSVAL_OBJECT_BODY; break;
      case ObjectRef::Kind::Wall: k = PHYSVAL_OBJECT_WALL; break;
      case ObjectRef::Kind::Box: k = PHYSVAL_OBJECT_BOX; break;
      case ObjectRef::Kind::Surface: k = PHYSVAL_OBJECT_SURFACE; break;
    }
    return {k, r.index};
  }

  std::unique_ptr<Engine> engine_;
  std::vector<physval_contact> contacts_;
  mutable std::vector<BodyMeta> metas_;
  mutable std::vector<BodyState> states_;
};

}  // namespace physval::plugin_bridge
