// The plugin loader: physval/plugin.h's C table wrapped as an Engine. The scene is
// handed over as plain C structs that point into storage this file owns for the
// duration of load(); the plugin copies what it keeps.
#include "physval/adapters/plugin_engine.hpp"

#include <dlfcn.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <memory>
#include <regex>
#include <sstream>
#include <type_traits>
#include <variant>

#include "physval/adapters/registry.hpp"
#include "physval/plugin.h"

namespace physval {

static_assert(static_cast<int>(Feature::Count) == PHYSVAL_FEATURE_COUNT,
              "plugin.h's feature numbering must follow physval::Feature");
// physval_option_type numbers OptionValue's alternatives.
static_assert(std::is_same_v<std::variant_alternative_t<PHYSVAL_OPTION_BOOL, OptionValue>, bool> &&
              std::is_same_v<std::variant_alternative_t<PHYSVAL_OPTION_INT, OptionValue>, std::int64_t> &&
              std::is_same_v<std::variant_alternative_t<PHYSVAL_OPTION_DOUBLE, OptionValue>, double> &&
              std::is_same_v<std::variant_alternative_t<PHYSVAL_OPTION_STRING, OptionValue>, std::string>);

namespace {

// One opened library: its table and its declaration, converted once.
struct PluginLibrary {
  std::string path;
  void* handle = nullptr;
  const physval_plugin_table_v1* table = nullptr;
  EngineInfo info;
};

// A plugin's text (its error, settings, limits, a broken guarantee) as valid UTF-8: a C
// library may well write Latin-1 or stray bytes, and results.json, the JUnit file and the
// report must stay valid, or one engine's message would cost every engine's results. Each
// byte that does not start a well-formed UTF-8 sequence becomes U+FFFD.
std::string utf8(const char* s) {
  std::string out;
  if (s == nullptr) return out;
  const auto* p = reinterpret_cast<const unsigned char*>(s);
  while (*p != 0) {
    const unsigned char c = *p;
    int n = c < 0x80 ? 0 : (c >= 0xC2 && c <= 0xDF) ? 1 : (c >= 0xE0 && c <= 0xEF) ? 2 : (c >= 0xF0 && c <= 0xF4) ? 3 : -1;
    bool ok = n >= 0;
    for (int k = 1; ok && k <= n; ++k) ok = (p[k] & 0xC0) == 0x80;   // stops at the terminating 0
    if (ok && n == 2) ok = !(c == 0xE0 && p[1] < 0xA0) && !(c == 0xED && p[1] > 0x9F);   // overlong, surrogates
    if (ok && n == 3) ok = !(c == 0xF0 && p[1] < 0x90) && !(c == 0xF4 && p[1] > 0x8F);   // overlong, > U+10FFFF
    if (ok) {
      out.append(reinterpret_cast<const char*>(p), static_cast<std::size_t>(n + 1));
      p += n + 1;
    } else {
      out += "\xEF\xBF\xBD";
      ++p;
    }
  }
  return out;
}

std::string str(const char* s) { return utf8(s); }

[[noreturn]] void fail(const std::string& path, const std::string& what) {
  throw PluginError("plugin " + path + ": " + what);
}

OptionValue to_option_value(const physval_option_value& v, physval_option_type type) {
  switch (type) {
    case PHYSVAL_OPTION_BOOL: return OptionValue{v.b != 0};
    case PHYSVAL_OPTION_INT: return OptionValue{static_cast<std::int64_t>(v.i)};
    case PHYSVAL_OPTION_DOUBLE: return OptionValue{v.d};
    case PHYSVAL_OPTION_STRING: return OptionValue{str(v.s)};
  }
  return OptionValue{false};
}

// The declaration, checked: a plugin's mistakes are errors naming the plugin, never a
// crash later.
EngineInfo convert_info(const std::string& path, const physval_info* ci) {
  if (ci == nullptr) fail(path, "info() returned NULL");
  static const std::regex kName("[a-z0-9_]+");
  EngineInfo info;
  info.name = str(ci->name);
  if (!std::regex_match(info.name, kName)) {
    fail(path, "its name must match [a-z0-9_]+ (it names the scenario table [<name>]), got \"" + info.name + "\"");
  }
  info.version = str(ci->version);
  if (ci->precision != PHYSVAL_FLOAT32 && ci->precision != PHYSVAL_FLOAT64) {
    fail(path, "precision must be PHYSVAL_FLOAT32 or PHYSVAL_FLOAT64");
  }
  info.precision = ci->precision == PHYSVAL_FLOAT32 ? Precision::Float32 : Precision::Float64;
  info.summary = str(ci->summary) + " (plugin " + path + ")";
  if ((ci->features >> PHYSVAL_FEATURE_COUNT) != 0) {
    fail(path, "declares features this physval does not know (bits above " + std::to_string(PHYSVAL_FEATURE_COUNT - 1) + ")");
  }
  for (int i = 0; i < PHYSVAL_FEATURE_COUNT; ++i) {
    if ((ci->features & PHYSVAL_FEATURE_BIT(i)) != 0) info.features.push_back(static_cast<Feature>(i));
  }
  if (ci->option_count > 0 && ci->options == nullptr) fail(path, "option_count > 0 but options is NULL");
  for (std::size_t i = 0; i < ci->option_count; ++i) {
    const physval_option_spec& cs = ci->options[i];
    OptionSpec s;
    s.key = str(cs.key);
    const std::string where = "option \"" + s.key + "\": ";
    if (!std::regex_match(s.key, kName)) fail(path, where + "its key must match [a-z0-9_]+");
    for (const OptionSpec& other : info.options) {
      if (other.key == s.key) fail(path, where + "declared twice");
    }
    const physval_option_type type = cs.default_value.type;
    if (type < PHYSVAL_OPTION_BOOL || type > PHYSVAL_OPTION_STRING) fail(path, where + "unknown type");
    s.default_value = to_option_value(cs.default_value, type);
    s.doc = str(cs.doc);
    if (cs.choice_count > 0) {
      if (type != PHYSVAL_OPTION_STRING) fail(path, where + "choices are for string options only");
      if (cs.choices == nullptr) fail(path, where + "choice_count > 0 but choices is NULL");
      for (std::size_t c = 0; c < cs.choice_count; ++c) s.choices.push_back(str(cs.choices[c]));
      if (std::find(s.choices.begin(), s.choices.end(), std::get<std::string>(s.default_value)) == s.choices.end()) {
        fail(path, where + "the default \"" + std::get<std::string>(s.default_value) + "\" is not one of its choices");
      }
    }
    if (type == PHYSVAL_OPTION_INT || type == PHYSVAL_OPTION_DOUBLE) {
      if (std::isnan(cs.range_lo) || std::isnan(cs.range_hi) || cs.range_lo > cs.range_hi) {
        fail(path, where + "its range is not lo <= hi");
      }
      s.range = OptionRange{cs.range_lo, cs.range_hi, cs.range_lo_open != 0};
      const double d = type == PHYSVAL_OPTION_INT ? static_cast<double>(cs.default_value.i) : cs.default_value.d;
      if (!std::isfinite(d) || !s.range.contains(d)) {
        fail(path, where + "its default " + option_value_to_string(s.default_value) + " is outside its range " +
                       s.range.describe());
      }
    }
    info.options.push_back(std::move(s));
  }
  return info;
}

std::shared_ptr<PluginLibrary> open_library(const std::string& path) {
  // RTLD_LOCAL: two plugins never see each other's symbols; RTLD_NOW: a missing symbol
  // is an error here, not a crash in the middle of a run.
  void* handle = ::dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL);
  if (handle == nullptr) fail(path, std::string("cannot be loaded: ") + ::dlerror());
  auto lib = std::make_shared<PluginLibrary>();
  lib->path = path;
  lib->handle = handle;   // never closed: forked children and static tables outlive any scope
  void* sym = ::dlsym(handle, PHYSVAL_PLUGIN_ENTRY_POINT);
  if (sym == nullptr) {
    fail(path, "not a physval plugin: it exports no function " PHYSVAL_PLUGIN_ENTRY_POINT " (see physval/plugin.h)");
  }
  physval_plugin_v1_fn entry = nullptr;
  static_assert(sizeof entry == sizeof sym);
  std::memcpy(&entry, &sym, sizeof entry);
  const physval_plugin_table_v1* t = entry(PHYSVAL_PLUGIN_ABI_VERSION);
  if (t == nullptr) {
    fail(path, "refused physval's plugin ABI version " + std::to_string(PHYSVAL_PLUGIN_ABI_VERSION) +
                   " (its " PHYSVAL_PLUGIN_ENTRY_POINT " returned NULL)");
  }
  if (t->abi_version != PHYSVAL_PLUGIN_ABI_VERSION) {
    fail(path, "built for plugin ABI version " + std::to_string(t->abi_version) + ", but this physval speaks version " +
                   std::to_string(PHYSVAL_PLUGIN_ABI_VERSION) + ": rebuild it against this physval's physval/plugin.h");
  }
  if (t->struct_size < sizeof(physval_plugin_table_v1)) {
    fail(path, "its function table is " + std::to_string(t->struct_size) + " bytes, ABI version 1 needs " +
                   std::to_string(sizeof(physval_plugin_table_v1)));
  }
  const std::pair<const char*, bool> functions[] = {
      {"info", t->info != nullptr},         {"create", t->create != nullptr},
      {"destroy", t->destroy != nullptr},   {"last_error", t->last_error != nullptr},
      {"load", t->load != nullptr},         {"step", t->step != nullptr},
      {"time", t->time != nullptr},         {"body_count", t->body_count != nullptr},
      {"body_meta", t->body_meta != nullptr}, {"read_states", t->read_states != nullptr},
      {"contacts", t->contacts != nullptr}, {"settings", t->settings != nullptr},
      {"limits_hit", t->limits_hit != nullptr}, {"broken_guarantee", t->broken_guarantee != nullptr}};
  for (const auto& [name, present] : functions) {
    if (!present) fail(path, std::string("its function table leaves ") + name + " NULL");
  }
  lib->table = t;
  lib->info = convert_info(path, t->info());
  return lib;
}

// The scene as C structs. Every pointer in `scene` points into this object's vectors
// or into the Scene it was built from; both outlive the load() call.
class CScene {
 public:
  CScene(const Scene& s, const EngineInfo& info) {
    thrusts_.reserve(s.bodies.size());
    for (const BodyDef& b : s.bodies) {
      physval_body c{};
      c.name = b.name.c_str();
      c.shape = b.shape == ShapeKind::Circle ? PHYSVAL_SHAPE_CIRCLE : PHYSVAL_SHAPE_POINT;
      c.radius = b.radius;
      c.mass = b.mass;
      c.is_static = b.is_static ? 1 : 0;
      c.position = vec(b.position);
      c.velocity = vec(b.velocity);
      c.angle = b.angle;
      c.angular_velocity = b.angular_velocity;
      c.restitution = b.restitution;
      c.friction = b.friction;
      c.static_friction = b.static_friction;
      c.rolling_friction = b.rolling_friction;
      c.drag_linear = b.drag_linear;
      c.drag_quadratic = b.drag_quadratic;
      c.group = b.group.c_str();
      std::vector<double>& accel = thrusts_.emplace_back();
      for (const std::vector<double>& row : b.thrust.accel) accel.insert(accel.end(), row.begin(), row.end());
      if (b.thrust.enabled()) {
        c.thrust.speeds = b.thrust.speeds.data();
        c.thrust.speed_count = b.thrust.speeds.size();
        c.thrust.gears = b.thrust.gears.data();
        c.thrust.gear_count = b.thrust.gears.size();
        c.thrust.accel = accel.data();
      }
      c.thrust.throttle = b.thrust.throttle;
      c.thrust.gear = b.thrust.gear;
      bodies_.push_back(c);
    }
    for (const WallDef& w : s.walls) walls_.push_back({w.name.c_str(), vec(w.from), vec(w.to), material(w.material)});
    for (const BoxDef& b : s.boxes) boxes_.push_back({b.name.c_str(), vec(b.min), vec(b.max), material(b.material)});
    points_.reserve(s.surfaces.size());
    normals_.reserve(s.surfaces.size());
    for (const SurfaceDef& sf : s.surfaces) {
      std::vector<physval_vec2>& p = points_.emplace_back();
      std::vector<physval_vec2>& n = normals_.emplace_back();
      for (Vec2 v : sf.points) p.push_back(vec(v));
      for (Vec2 v : sf.normals) n.push_back(vec(v));
      surfaces_.push_back({sf.name.c_str(), p.data(), p.size(), n.empty() ? nullptr : n.data(), material(sf.material)});
    }
    for (const MaterialOverride& m : s.materials) {
      physval_material_override c{};
      c.a = m.a.c_str();
      c.b = m.b.c_str();
      c.has_restitution = m.restitution.has_value();
      c.restitution = m.restitution.value_or(0.0);
      c.has_friction = m.friction.has_value();
      c.friction = m.friction.value_or(0.0);
      c.has_static_friction = m.static_friction.has_value();
      c.static_friction = m.static_friction.value_or(0.0);
      c.has_rolling_friction = m.rolling_friction.has_value();
      c.rolling_friction = m.rolling_friction.value_or(0.0);
      materials_.push_back(c);
    }
    for (const CollisionRule& r : s.collision_matrix) {
      rules_.push_back({r.a.c_str(), r.b.c_str(), static_cast<physval_response>(static_cast<int>(r.response))});
    }
    for (const EmitterDef& e : s.emitters) {
      physval_emitter c{};
      c.name = e.name.c_str();
      c.parent = e.parent.c_str();
      c.mode = e.mode == EmitterMode::Explode ? PHYSVAL_EMITTER_EXPLODE : PHYSVAL_EMITTER_TRAIL;
      c.at = e.at;
      c.rate = e.rate;
      c.count = e.count;
      c.speed = e.speed;
      c.lifetime = e.lifetime;
      c.mass = e.mass;
      c.destroy_on_collision = e.destroy_on_collision ? 1 : 0;
      c.gravity = e.gravity ? 1 : 0;
      c.seed = e.seed;
      emitters_.push_back(c);
    }
    // Every declared option, the scenario's value or the default, as declared.
    const auto given = s.engine_options.find(info.name);
    option_values_.reserve(info.options.size());
    for (const OptionSpec& spec : info.options) {
      OptionValue v = spec.default_value;
      if (given != s.engine_options.end()) {
        if (auto it = given->second.find(spec.key); it != given->second.end()) v = it->second;
      }
      if (spec.default_value.index() == 2) {   // a double option given as an integer
        if (const auto* i = std::get_if<std::int64_t>(&v)) v = static_cast<double>(*i);
      }
      option_values_.push_back(std::move(v));
    }
    for (std::size_t i = 0; i < info.options.size(); ++i) {
      physval_option o{};
      o.key = info.options[i].key.c_str();
      const OptionValue& v = option_values_[i];
      o.value.type = static_cast<physval_option_type>(v.index());
      o.value.s = "";
      switch (v.index()) {
        case 0: o.value.b = std::get<bool>(v) ? 1 : 0; break;
        case 1: o.value.i = std::get<std::int64_t>(v); o.value.d = static_cast<double>(o.value.i); break;
        case 2: o.value.d = std::get<double>(v); break;
        default: o.value.s = std::get<std::string>(v).c_str(); break;
      }
      options_.push_back(o);
    }

    scene.name = s.name.c_str();
    scene.source_file = s.source_file.c_str();
    scene.duration = s.duration;
    scene.dt = s.dt;
    scene.world.gravity = vec(s.world.gravity);
    scene.world.newtonian = s.world.newtonian ? 1 : 0;
    scene.world.G = s.world.G;
    scene.world.softening = s.world.softening;
    scene.world.wind = vec(s.world.wind);
    scene.bodies = bodies_.data();
    scene.body_count = bodies_.size();
    scene.walls = walls_.data();
    scene.wall_count = walls_.size();
    scene.boxes = boxes_.data();
    scene.box_count = boxes_.size();
    scene.surfaces = surfaces_.data();
    scene.surface_count = surfaces_.size();
    scene.materials = materials_.data();
    scene.material_count = materials_.size();
    scene.collision_rules = rules_.data();
    scene.collision_rule_count = rules_.size();
    scene.emitters = emitters_.data();
    scene.emitter_count = emitters_.size();
    scene.options = options_.data();
    scene.option_count = options_.size();
  }
  CScene(const CScene&) = delete;
  CScene& operator=(const CScene&) = delete;

  physval_scene scene{};

 private:
  static physval_vec2 vec(Vec2 v) { return {v.x, v.y}; }
  static physval_material material(const StaticMaterial& m) {
    return {m.restitution, m.friction, m.static_friction, m.rolling_friction, m.group.c_str()};
  }

  std::vector<physval_body> bodies_;
  std::vector<std::vector<double>> thrusts_;
  std::vector<physval_wall> walls_;
  std::vector<physval_box> boxes_;
  std::vector<std::vector<physval_vec2>> points_;
  std::vector<std::vector<physval_vec2>> normals_;
  std::vector<physval_surface> surfaces_;
  std::vector<physval_material_override> materials_;
  std::vector<physval_collision_rule> rules_;
  std::vector<physval_emitter> emitters_;
  std::vector<OptionValue> option_values_;
  std::vector<physval_option> options_;
};

// Host services: physval's own rules, applied to the scene the engine was loaded with.
physval_pair_material host_combine(void* context, const physval_material_view* a, const physval_material_view* b) {
  const Scene& scene = *static_cast<const Scene*>(context);
  const std::string na = str(a->name), nb = str(b->name);
  const PairMaterial m = combine_materials(scene, MaterialView{na, a->restitution, a->friction, a->static_friction, a->rolling_friction},
                                           MaterialView{nb, b->restitution, b->friction, b->static_friction, b->rolling_friction});
  return {m.restitution, m.friction, m.static_friction, m.rolling_friction};
}

physval_pair_response host_response(void* context, const char* first, const char* second) {
  const Scene& scene = *static_cast<const Scene*>(context);
  const PairResponse r = response_between(scene, str(first), str(second));
  return {r.collide ? 1 : 0, r.event ? 1 : 0, r.destroy_first ? 1 : 0, r.destroy_second ? 1 : 0};
}

ObjectRef object_ref(const physval_object_ref& r, const std::string& path) {
  ObjectRef o;
  switch (r.kind) {
    case PHYSVAL_OBJECT_BODY: o.kind = ObjectRef::Kind::Body; break;
    case PHYSVAL_OBJECT_WALL: o.kind = ObjectRef::Kind::Wall; break;
    case PHYSVAL_OBJECT_BOX: o.kind = ObjectRef::Kind::Box; break;
    case PHYSVAL_OBJECT_SURFACE: o.kind = ObjectRef::Kind::Surface; break;
    default: throw PluginError("plugin " + path + ": a contact names an unknown object kind " + std::to_string(r.kind));
  }
  o.index = r.index;
  return o;
}

class PluginEngine final : public Engine {
 public:
  explicit PluginEngine(std::shared_ptr<const PluginLibrary> lib) : lib_(std::move(lib)), t_(*lib_->table) {
    engine_ = t_.create();
    if (engine_ == nullptr) throw PluginError("plugin " + lib_->info.name + ": create() returned NULL");
  }
  ~PluginEngine() override {
    if (engine_ != nullptr) t_.destroy(engine_);
  }
  PluginEngine(const PluginEngine&) = delete;
  PluginEngine& operator=(const PluginEngine&) = delete;

  const EngineInfo& info() const override { return lib_->info; }

  void load(const Scene& scene) override {
    scene_ = scene;   // the host services read it for the whole run
    host_ = physval_host{PHYSVAL_PLUGIN_ABI_VERSION, &scene_, &host_combine, &host_response};
    const CScene c(scene_, lib_->info);
    if (t_.load(engine_, &c.scene, &host_) != 0) throw PluginError(what("load"));
    if (body_count() < scene_.bodies.size()) {
      throw PluginError("plugin " + lib_->info.name + ": reports " + std::to_string(body_count()) +
                        " bodies after load, but the scene has " + std::to_string(scene_.bodies.size()));
    }
    refresh_contacts();
  }

  void step(double dt) override {
    if (t_.step(engine_, dt) != 0) throw PluginError(what("step"));
    refresh_contacts();
  }

  double time() const override { return t_.time(engine_); }
  std::size_t body_count() const override { return t_.body_count(engine_); }

  BodyMeta body_meta(std::size_t i) const override {
    const physval_body_meta m = t_.body_meta(engine_, i);
    return {str(m.name), m.mass, m.radius, m.is_static != 0};
  }

  void read_states(std::vector<BodyState>& out) const override {
    const std::size_t n = body_count();
    buffer_.assign(n, physval_body_state{});
    t_.read_states(engine_, buffer_.data(), n);
    out.resize(n);
    for (std::size_t i = 0; i < n; ++i) {
      const physval_body_state& s = buffer_[i];
      out[i] = {{s.position.x, s.position.y}, {s.velocity.x, s.velocity.y}, s.angle, s.angular_velocity, s.alive != 0};
    }
  }

  const std::vector<ContactEvent>& contacts() const override { return contacts_; }

  std::vector<Setting> settings() const override {
    const physval_setting* s = nullptr;
    std::size_t n = 0;
    t_.settings(engine_, &s, &n);
    std::vector<Setting> out;
    for (std::size_t i = 0; i < n && s != nullptr; ++i) out.emplace_back(str(s[i].name), str(s[i].value));
    return out;
  }

  std::vector<std::string> limits_hit() const override {
    const char* const* s = nullptr;
    std::size_t n = 0;
    t_.limits_hit(engine_, &s, &n);
    std::vector<std::string> out;
    for (std::size_t i = 0; i < n && s != nullptr; ++i) out.push_back(str(s[i]));
    return out;
  }

  // Asked after every step: an empty answer (the usual one) without measuring it.
  std::string broken_guarantee() const override {
    const char* b = t_.broken_guarantee(engine_);
    return b == nullptr || *b == '\0' ? std::string() : utf8(b);
  }

 private:
  std::string what(const char* call) const {
    std::string e = str(t_.last_error(engine_));
    return "plugin " + lib_->info.name + ": " + call + " failed: " + (e.empty() ? "(no message)" : e);
  }

  void refresh_contacts() {
    const physval_contact* c = nullptr;
    std::size_t n = 0;
    t_.contacts(engine_, &c, &n);
    contacts_.clear();
    for (std::size_t i = 0; i < n && c != nullptr; ++i) {
      const ContactEvent e{object_ref(c[i].a, lib_->path), object_ref(c[i].b, lib_->path), c[i].time};
      check_ref(e.a);
      check_ref(e.b);
      if (e.a.kind != ObjectRef::Kind::Body) {
        throw PluginError("plugin " + lib_->info.name + ": a contact's first object must be a body");
      }
      contacts_.push_back(e);
    }
  }

  // A contact naming an object that does not exist is the plugin's error, said as such
  // (not an out-of-range read in the comparator).
  void check_ref(const ObjectRef& r) const {
    std::size_t count = 0;
    const char* what = "body";
    switch (r.kind) {
      case ObjectRef::Kind::Body: count = body_count(); break;
      case ObjectRef::Kind::Wall: count = scene_.walls.size(); what = "wall"; break;
      case ObjectRef::Kind::Box: count = scene_.boxes.size(); what = "box"; break;
      case ObjectRef::Kind::Surface: count = scene_.surfaces.size(); what = "surface"; break;
    }
    if (r.index >= count) {
      throw PluginError("plugin " + lib_->info.name + ": a contact names " + what + " " + std::to_string(r.index) +
                        ", but there are " + std::to_string(count));
    }
  }

  std::shared_ptr<const PluginLibrary> lib_;
  const physval_plugin_table_v1& t_;
  physval_engine* engine_ = nullptr;
  Scene scene_;
  physval_host host_{};
  std::vector<ContactEvent> contacts_;
  mutable std::vector<physval_body_state> buffer_;
};

}  // namespace

std::string resolve_plugin_path(const std::string& arg, const std::string& search_path) {
  namespace fs = std::filesystem;
  if (arg.empty()) throw PluginError("--plugin: empty path");
  if (arg.find('/') != std::string::npos || fs::is_regular_file(arg)) {
    if (!fs::is_regular_file(arg)) throw PluginError("--plugin " + arg + ": no such file");
    return arg;
  }
  std::vector<std::string> tried;
  std::stringstream dirs(search_path);
  std::string dir;
  while (std::getline(dirs, dir, ':')) {
    if (dir.empty()) continue;
    for (const std::string& name : {arg, "lib" + arg + ".so", arg + ".so"}) {
      const fs::path p = fs::path(dir) / name;
      if (fs::is_regular_file(p)) return p.string();
      tried.push_back(p.string());
    }
  }
  if (tried.empty()) {
    throw PluginError("--plugin " + arg + ": no such file, and PHYSVAL_PLUGIN_PATH is empty (give a path, or "
                      "set PHYSVAL_PLUGIN_PATH to the folders holding plugins)");
  }
  std::string list;
  for (const std::string& t : tried) list += (list.empty() ? "" : ", ") + t;
  throw PluginError("--plugin " + arg + ": not found in PHYSVAL_PLUGIN_PATH (tried " + list + ")");
}

EngineFactory load_plugin(const std::string& path) {
  std::shared_ptr<const PluginLibrary> lib = open_library(path);
  EngineFactory f;
  f.info = lib->info;
  f.create = [lib]() -> std::unique_ptr<Engine> { return std::make_unique<PluginEngine>(lib); };
  return f;
}

}  // namespace physval
