// TOML scenario files -> Scene. The reader walks each table with a TableReader that
// records which keys it consumed, so every key it did not expect is reported with its
// line, and every error in a file is collected before giving up.
#include "physval/validation/scenario_loader.hpp"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <functional>
#include <regex>
#include <set>
#include <sstream>

#include <toml++/toml.h>

#include "physval/adapters/registry.hpp"
#include "physval/core/forces.hpp"
#include "physval/validation/metric_names.hpp"
#include "physval/validation/reference_cache.hpp"
#include "physval/validation/runner.hpp"

namespace physval {

std::string Diagnostic::str() const {
  std::ostringstream os;
  os << file;
  if (line > 0) {
    os << ':' << line;
    if (column > 0) os << ':' << column;
  }
  os << ": ";
  if (!key.empty()) os << key << ": ";
  os << message;
  return os.str();
}

namespace {

const char* type_name(const toml::node& n) {
  switch (n.type()) {
    case toml::node_type::table: return "a table";
    case toml::node_type::array: return "an array";
    case toml::node_type::string: return "a string";
    case toml::node_type::integer: return "an integer";
    case toml::node_type::floating_point: return "a float";
    case toml::node_type::boolean: return "a boolean";
    case toml::node_type::date:
    case toml::node_type::time:
    case toml::node_type::date_time: return "a date/time";
    default: return "nothing";
  }
}

std::string format_number(double v) {
  std::ostringstream os;
  os.precision(10);
  os << v;
  return os.str();
}

// Bounds checked before anything runs (README: "Bounds").
constexpr double kMaxEmitterCount = 1e6;   // particles one explode emitter makes
constexpr double kMaxObjects = 2e5;        // bodies plus every particle emitters can make

// A user's text shown in a message: printable ASCII as is, anything else as \xNN, so a
// name holding a newline or a terminal escape cannot garble the terminal.
std::string shown(const std::string& text) {
  std::string out;
  for (unsigned char c : text) {
    if (c >= 0x20 && c < 0x7f && c != '"' && c != '\\') {
      out += static_cast<char>(c);
    } else {
      static const char* hex = "0123456789abcdef";
      out += "\\x";
      out += hex[c >> 4];
      out += hex[c & 15];
    }
  }
  return out;
}

// "1/120" -> 1/120; nullopt unless the text is NUMBER/NUMBER with a non-zero divisor.
std::optional<double> parse_fraction(const std::string& text) {
  const auto slash = text.find('/');
  if (slash == std::string::npos) return std::nullopt;
  try {
    std::size_t used = 0;
    const std::string a = text.substr(0, slash), b = text.substr(slash + 1);
    const double num = std::stod(a, &used);
    if (used != a.size() || a.empty() || std::isspace(static_cast<unsigned char>(a[0]))) return std::nullopt;
    const double den = std::stod(b, &used);
    if (used != b.size() || b.empty() || std::isspace(static_cast<unsigned char>(b[0])) || den == 0.0) return std::nullopt;
    return num / den;
  } catch (...) {
    return std::nullopt;
  }
}

struct Context {
  std::string file;
  Diagnostics errors;

  void error(const toml::source_region& where, const std::string& key, const std::string& message) {
    errors.push_back({file, static_cast<int>(where.begin.line), static_cast<int>(where.begin.column), key, message});
  }
};

// Reads one TOML table, tracking the keys it used; finish() reports the rest.
class TableReader {
 public:
  TableReader(Context& ctx, const toml::table& table, std::string path)
      : ctx_(ctx), table_(table), path_(std::move(path)) {}
  TableReader(const TableReader&) = delete;
  TableReader& operator=(const TableReader&) = delete;
  ~TableReader() { finish(); }

  const toml::table& table() const { return table_; }
  const std::string& path() const { return path_; }
  std::string key_path(std::string_view key) const {
    return path_.empty() ? std::string(key) : path_ + "." + std::string(key);
  }

  // The node for key (marking it used), or nullptr.
  const toml::node* node(std::string_view key) {
    used_.insert(std::string(key));
    return table_.get(key);
  }
  bool has(std::string_view key) const { return table_.contains(key); }

  void error_at(const toml::node& n, std::string_view key, const std::string& message) {
    ctx_.error(n.source(), key_path(key), message);
  }
  void error_here(std::string_view key, const std::string& message) {
    ctx_.error(table_.source(), key_path(key), message);
  }

  void missing(std::string_view key) { error_here(key, "required key is missing"); }

  std::optional<double> number(std::string_view key, bool required = false) {
    const toml::node* n = node(key);
    if (n == nullptr) {
      if (required) missing(key);
      return std::nullopt;
    }
    return to_number(*n, key_path(key));
  }

  std::optional<double> to_number(const toml::node& n, const std::string& kp) {
    double v;
    if (const auto* f = n.as_floating_point()) {
      v = f->get();
    } else if (const auto* i = n.as_integer()) {
      v = static_cast<double>(i->get());
    } else if (const auto* str = n.as_string(); str != nullptr && parse_fraction(str->get())) {
      v = *parse_fraction(str->get());   // a fraction in quotes: dt = "1/120"
    } else if (n.is_string()) {
      ctx_.error(n.source(), kp, "expected a number, got a string \"" + shown(n.as_string()->get()) +
                                     "\" (a fraction is written in quotes: \"1/120\")");
      return std::nullopt;
    } else {
      ctx_.error(n.source(), kp, std::string("expected a number, got ") + type_name(n));
      return std::nullopt;
    }
    if (!std::isfinite(v)) {
      ctx_.error(n.source(), kp, "must be a finite number, got " + format_number(v));
      return std::nullopt;
    }
    return v;
  }

  // A number with a range check: pred returns "" when fine, else what it must be.
  void read(std::string_view key, double& out, const char* must = nullptr,
            const std::function<bool(double)>& ok = {}) {
    const toml::node* n = node(key);
    if (n == nullptr) return;
    if (auto v = to_number(*n, key_path(key))) {
      if (ok && !ok(*v)) {
        error_at(*n, key, std::string("must be ") + must + ", got " + format_number(*v));
        return;
      }
      out = *v;
    }
  }
  void read_required(std::string_view key, double& out, const char* must = nullptr,
                     const std::function<bool(double)>& ok = {}) {
    if (!has(key)) {
      node(key);
      missing(key);
      return;
    }
    read(key, out, must, ok);
  }
  void read_non_negative(std::string_view key, double& out) {
    read(key, out, ">= 0", [](double v) { return v >= 0.0; });
  }

  void read(std::string_view key, bool& out) {
    const toml::node* n = node(key);
    if (n == nullptr) return;
    if (const auto* b = n->as_boolean()) {
      out = b->get();
    } else {
      error_at(*n, key, std::string("expected a boolean, got ") + type_name(*n));
    }
  }

  void read(std::string_view key, std::optional<bool>& out) {
    bool v = false;
    const toml::node* n = table_.get(key);
    read(key, v);
    if (n != nullptr && n->is_boolean()) out = v;
  }

  bool read(std::string_view key, std::string& out, bool required = false) {
    const toml::node* n = node(key);
    if (n == nullptr) {
      if (required) missing(key);
      return false;
    }
    if (const auto* s = n->as_string()) {
      out = s->get();
      return true;
    }
    error_at(*n, key, std::string("expected a string, got ") + type_name(*n));
    return false;
  }

  // A choice among names; returns the index.
  std::optional<std::size_t> choice(std::string_view key, const std::vector<std::string>& names) {
    std::string s;
    const toml::node* n = table_.get(key);
    if (!read(key, s)) return std::nullopt;
    for (std::size_t i = 0; i < names.size(); ++i) {
      if (names[i] == s) return i;
    }
    std::string all;
    for (const std::string& c : names) all += (all.empty() ? "" : " | ") + c;
    error_at(*n, key, "unknown value \"" + s + "\"; expected one of " + all);
    return std::nullopt;
  }

  std::optional<Vec2> vec2(const toml::node& n, const std::string& kp) {
    const auto* a = n.as_array();
    if (a == nullptr || a->size() != 2) {
      ctx_.error(n.source(), kp, std::string("expected a 2-D vector [x, y], got ") +
                                     (a ? "an array of " + std::to_string(a->size()) : std::string(type_name(n))));
      return std::nullopt;
    }
    auto x = to_number(*a->get(0), kp + "[0]");
    auto y = to_number(*a->get(1), kp + "[1]");
    if (!x || !y) return std::nullopt;
    return Vec2{*x, *y};
  }
  std::optional<Vec2> vec2(std::string_view key, bool required = false) {
    const toml::node* n = node(key);
    if (n == nullptr) {
      if (required) missing(key);
      return std::nullopt;
    }
    return vec2(*n, key_path(key));
  }
  void read(std::string_view key, Vec2& out, bool required = false) {
    if (auto v = vec2(key, required)) out = *v;
  }

  std::optional<std::vector<double>> numbers(const toml::node& n, const std::string& kp) {
    const auto* a = n.as_array();
    if (a == nullptr) {
      ctx_.error(n.source(), kp, std::string("expected an array of numbers, got ") + type_name(n));
      return std::nullopt;
    }
    std::vector<double> out;
    bool ok = true;
    for (std::size_t i = 0; i < a->size(); ++i) {
      if (auto v = to_number(*a->get(i), kp + "[" + std::to_string(i) + "]")) {
        out.push_back(*v);
      } else {
        ok = false;
      }
    }
    if (!ok) return std::nullopt;
    return out;
  }

  // An array of tables (`[[key]]` or an inline array of inline tables).
  std::vector<const toml::table*> tables(std::string_view key) {
    std::vector<const toml::table*> out;
    const toml::node* n = node(key);
    if (n == nullptr) return out;
    if (const auto* t = n->as_table()) {  // a single table is accepted as a list of one
      out.push_back(t);
      return out;
    }
    const auto* a = n->as_array();
    if (a == nullptr) {
      error_at(*n, key, std::string("expected an array of tables, got ") + type_name(*n));
      return out;
    }
    for (std::size_t i = 0; i < a->size(); ++i) {
      if (const auto* t = a->get(i)->as_table()) {
        out.push_back(t);
      } else {
        ctx_.error(a->get(i)->source(), key_path(key) + "[" + std::to_string(i) + "]",
                   std::string("expected a table, got ") + type_name(*a->get(i)));
      }
    }
    return out;
  }

  const toml::table* subtable(std::string_view key) {
    const toml::node* n = node(key);
    if (n == nullptr) return nullptr;
    if (const auto* t = n->as_table()) return t;
    error_at(*n, key, std::string("expected a table, got ") + type_name(*n));
    return nullptr;
  }

  void mark_used(std::string_view key) { used_.insert(std::string(key)); }

  void finish() {
    if (finished_) return;
    finished_ = true;
    for (auto&& [k, v] : table_) {
      if (used_.count(std::string(k.str())) == 0) {
        ctx_.error(k.source(), key_path(k.str()), "unknown key");
      }
    }
  }

 private:
  Context& ctx_;
  const toml::table& table_;
  std::string path_;
  std::set<std::string> used_;
  bool finished_ = false;
};

std::string indexed(const std::string& base, std::size_t i) { return base + "[" + std::to_string(i) + "]"; }

void read_material(TableReader& r, StaticMaterial& m) {
  r.read_non_negative("restitution", m.restitution);
  r.read_non_negative("friction", m.friction);
  m.static_friction = m.friction;
  r.read_non_negative("static_friction", m.static_friction);
  r.read_non_negative("rolling_friction", m.rolling_friction);
  r.read("group", m.group);
  if (m.static_friction < m.friction && r.has("static_friction")) {
    r.error_here("static_friction", "must be >= friction (mu_s >= mu_k), got " + format_number(m.static_friction) +
                                         " < " + format_number(m.friction));
  }
}

void read_thrust(Context& ctx, const toml::table& t, const std::string& path, ThrustDef& th) {
  TableReader r(ctx, t, path);
  const toml::node* speeds = r.node("speeds");
  if (speeds == nullptr) {
    r.missing("speeds");
  } else if (auto v = r.numbers(*speeds, r.key_path("speeds"))) {
    th.speeds = *v;
    if (th.speeds.empty()) r.error_at(*speeds, "speeds", "must hold at least one speed");
    for (std::size_t i = 1; i < th.speeds.size(); ++i) {
      if (!(th.speeds[i] > th.speeds[i - 1])) {
        r.error_at(*speeds, "speeds", "must be strictly increasing");
        break;
      }
    }
  }
  if (const toml::node* gears = r.node("gears")) {
    if (auto v = r.numbers(*gears, r.key_path("gears"))) {
      th.gears = *v;
      for (std::size_t i = 1; i < th.gears.size(); ++i) {
        if (!(th.gears[i] > th.gears[i - 1])) {
          r.error_at(*gears, "gears", "must be strictly increasing");
          break;
        }
      }
    }
  }
  const toml::node* accel = r.node("accel");
  if (accel == nullptr) {
    r.missing("accel");
  } else if (const auto* a = accel->as_array()) {
    const bool two_inputs = !th.gears.empty();
    if (!two_inputs) {
      if (auto row = r.numbers(*accel, r.key_path("accel"))) th.accel = {*row};
    } else {
      for (std::size_t g = 0; g < a->size(); ++g) {
        if (auto row = r.numbers(*a->get(g), indexed(r.key_path("accel"), g))) th.accel.push_back(*row);
      }
      if (th.accel.size() != th.gears.size()) {
        r.error_at(*accel, "accel", "needs one row per gear (" + std::to_string(th.gears.size()) + "), got " +
                                        std::to_string(th.accel.size()));
      }
    }
    for (const auto& row : th.accel) {
      if (row.size() != th.speeds.size() && !th.speeds.empty()) {
        r.error_at(*accel, "accel", "each row needs one value per speed (" + std::to_string(th.speeds.size()) + ")");
        break;
      }
    }
  } else {
    r.error_at(*accel, "accel", std::string("expected an array, got ") + type_name(*accel));
  }
  r.read("throttle", th.throttle);
  r.read("gear", th.gear);
  if (th.accel.empty() || th.speeds.empty()) th = ThrustDef{};
}

void read_body(Context& ctx, const toml::table& t, std::size_t i, BodyDef& b) {
  TableReader r(ctx, t, indexed("bodies", i));
  b.line = static_cast<int>(t.source().begin.line);
  r.read("name", b.name, true);
  if (auto s = r.choice("shape", {"circle", "point"})) b.shape = *s == 0 ? ShapeKind::Circle : ShapeKind::Point;
  if (b.shape == ShapeKind::Circle) {
    r.read_required("radius", b.radius, "> 0", [](double v) { return v > 0.0; });
  } else {
    r.read("radius", b.radius, "0 for a point", [](double v) { return v == 0.0; });
  }
  r.read("static", b.is_static);
  r.read("mass", b.mass, "> 0", [](double v) { return v > 0.0; });
  if (r.has("vertices") || r.has("vertex_masses")) {
    // A polygon with a mass at each vertex: the body is its centre of mass (lecture 4).
    std::vector<Vec2> vertices;
    std::vector<double> masses;
    if (const toml::node* vn = r.node("vertices")) {
      if (const auto* a = vn->as_array()) {
        for (std::size_t k = 0; k < a->size(); ++k) {
          if (auto v = r.vec2(*a->get(k), indexed(r.key_path("vertices"), k))) vertices.push_back(*v);
        }
      } else {
        r.error_at(*vn, "vertices", std::string("expected an array of [x, y], got ") + type_name(*vn));
      }
    } else {
      r.missing("vertices");
    }
    if (const toml::node* mn = r.node("vertex_masses")) {
      if (auto m = r.numbers(*mn, r.key_path("vertex_masses"))) masses = *m;
      if (masses.size() != vertices.size()) {
        r.error_at(*mn, "vertex_masses", "needs one mass per vertex (" + std::to_string(vertices.size()) + ")");
      } else if (std::any_of(masses.begin(), masses.end(), [](double m) { return !(m > 0.0); })) {
        r.error_at(*mn, "vertex_masses", "every vertex mass must be > 0");
      } else if (!vertices.empty()) {
        b.position = centre_of_mass(vertices, masses);
        b.mass = 0.0;
        for (double m : masses) b.mass += m;
      }
    } else {
      r.missing("vertex_masses");
    }
    if (r.has("position")) r.error_here("position", "give either position or vertices, not both");
    if (r.has("mass")) r.error_here("mass", "give either mass or vertex_masses, not both");
    r.mark_used("position");
  } else {
    r.read("position", b.position, true);
  }
  r.read("velocity", b.velocity);
  r.read("angle", b.angle);
  r.read("angular_velocity", b.angular_velocity);
  r.read_non_negative("restitution", b.restitution);
  r.read_non_negative("friction", b.friction);
  b.static_friction = b.friction;
  r.read_non_negative("static_friction", b.static_friction);
  if (r.has("static_friction") && b.static_friction < b.friction) {
    r.error_here("static_friction", "must be >= friction (mu_s >= mu_k)");
  }
  r.read_non_negative("rolling_friction", b.rolling_friction);
  r.read_non_negative("drag_linear", b.drag_linear);
  r.read_non_negative("drag_quadratic", b.drag_quadratic);
  r.read("group", b.group);
  if (const toml::table* th = r.subtable("thrust")) read_thrust(ctx, *th, r.key_path("thrust"), b.thrust);
}

void read_world(Context& ctx, const toml::table& t, WorldDef& w) {
  TableReader r(ctx, t, "world");
  r.read("gravity", w.gravity);
  r.read("wind", w.wind);
  r.read("newtonian", w.newtonian);
  r.read("G", w.G, "> 0", [](double v) { return v > 0.0; });
  r.read_non_negative("softening", w.softening);
  if ((r.has("G") || r.has("softening")) && !w.newtonian) {
    r.error_here(r.has("G") ? "G" : "softening", "has no effect unless newtonian = true");
  }
}

std::optional<ExpectedContact> read_expected_contact(Context& ctx, const toml::table& t, const std::string& path) {
  TableReader r(ctx, t, path);
  ExpectedContact c;
  r.read("a", c.a, true);
  r.read("b", c.b, true);
  auto time = r.number("time", true);
  if (time) c.time = *time;
  c.tolerance = r.number("tolerance");
  if (c.a.empty() || c.b.empty() || !time) return std::nullopt;
  return c;
}

void read_expect(Context& ctx, const toml::table& t, Expectations& e) {
  TableReader r(ctx, t, "expect");
  if (const toml::table* fc = r.subtable("first_contact")) {
    e.first_contact = read_expected_contact(ctx, *fc, "expect.first_contact");
  }
  auto list = r.tables("contacts");
  for (std::size_t i = 0; i < list.size(); ++i) {
    if (auto c = read_expected_contact(ctx, *list[i], indexed("expect.contacts", i))) e.contacts.push_back(*c);
  }
  list = r.tables("final");
  for (std::size_t i = 0; i < list.size(); ++i) {
    TableReader fr(ctx, *list[i], indexed("expect.final", i));
    ExpectedFinal f;
    fr.read("body", f.body, true);
    f.position = fr.vec2("position");
    f.velocity = fr.vec2("velocity");
    f.tolerance = fr.number("tolerance");
    if (!f.position && !f.velocity && !fr.has("position") && !fr.has("velocity")) {
      fr.error_here("position", "a final expectation needs a position or a velocity");
    }
    e.final_states.push_back(f);
  }
  list = r.tables("apex");
  for (std::size_t i = 0; i < list.size(); ++i) {
    TableReader ar(ctx, *list[i], indexed("expect.apex", i));
    ExpectedApex a;
    ar.read("body", a.body, true);
    if (auto h = ar.number("height", true)) a.height = *h;
    a.time = ar.number("time");
    a.tolerance = ar.number("tolerance");
    e.apex.push_back(a);
  }
  list = r.tables("period");
  for (std::size_t i = 0; i < list.size(); ++i) {
    TableReader pr(ctx, *list[i], indexed("expect.period", i));
    ExpectedPeriod p;
    pr.read("body", p.body, true);
    pr.read("around", p.around);
    pr.read_required("period", p.period, "> 0", [](double v) { return v > 0.0; });
    p.tolerance = pr.number("tolerance");
    e.period.push_back(p);
  }
}

void read_gate_limits(TableReader& r, std::map<std::string, double>& limits,
                      const std::function<bool(std::string_view)>& is_subtable) {
  for (auto&& [k, v] : r.table()) {
    const std::string key(k.str());
    if (is_subtable(key)) continue;
    if (key == "known_failures") continue;  // read by read_known_failures
    if (key == "expectation_failures") {
      r.mark_used(key);
      r.error_at(v, key,
                 "a count of allowed misses lets any new miss pass; name them instead: "
                 "known_failures = { \"expect.final.a.velocity\" = <largest error accepted> } "
                 "(`physval gate PATH --record-known 2` writes them from a run)");
      continue;
    }
    if (!is_metric_name(key)) continue;  // left unused: finish() reports it as unknown
    r.mark_used(key);
    if (auto n = r.to_number(v, r.key_path(key))) {
      if (*n < 0.0) {
        r.error_at(v, key, "a limit must be >= 0, got " + format_number(*n));
      } else {
        limits[key] = *n;
      }
    }
  }
}

void read_known_failures(TableReader& r, std::map<std::string, double>& known) {
  const toml::node* n = r.node("known_failures");
  if (n == nullptr) return;
  const toml::table* t = n->as_table();
  if (t == nullptr) {
    r.error_at(*n, "known_failures", "expected a table of expectation check names and the largest error accepted");
    return;
  }
  for (auto&& [k, v] : *t) {
    const std::string name(k.str());
    const std::string kp = r.key_path("known_failures") + ".\"" + name + "\"";
    if (name == "escaped_bodies") {   // bodies an engine is known to let through barriers
      if (auto b = r.to_number(v, kp)) {
        if (!(*b >= 0.0 && *b == std::floor(*b) && *b <= 1e9)) {
          r.error_at(v, "known_failures", "the bound for \"escaped_bodies\" must be a whole number >= 0, got " +
                                              format_number(*b));
        } else {
          known[name] = *b;
        }
      }
      continue;
    }
    if (name == "energy_crossed_zero" || name == "binding_energy_change") {
      // E(end) / |E(0)| of a bound system an engine is known to break up; |E_settled - E(0)| / E_b
      // of one whose energy it is known to move by more than a quarter of the binding energy
      if (auto b = r.to_number(v, kp)) {
        if (!(*b >= 0.0 && std::isfinite(*b))) {
          r.error_at(v, "known_failures", "the bound for \"" + name + "\" must be a finite number >= 0, got " +
                                              format_number(*b));
        } else {
          known[name] = *b;
        }
      }
      continue;
    }
    if (name.rfind("expect.", 0) != 0) {
      r.error_at(v, "known_failures",
                 "\"" + name + "\" is not an expectation check (they are named expect.*) nor escaped_bodies "
                 "nor energy_crossed_zero nor binding_energy_change");
      continue;
    }
    if (const auto* s = v.as_string(); s != nullptr && s->get() == "not measured") {
      known[name] = GateDef::kKnownNotMeasured;
    } else if (auto b = r.to_number(v, kp)) {
      if (!(*b >= 0.0)) {
        r.error_at(v, "known_failures", "the bound for \"" + name + "\" must be >= 0, got " + format_number(*b));
      } else {
        known[name] = *b;
      }
    }
  }
}

void read_gate(Context& ctx, const toml::table& t, GateDef& g) {
  TableReader r(ctx, t, "gate");
  auto is_engine = [](std::string_view k) { return find_engine(std::string(k)) != nullptr; };
  read_gate_limits(r, g.limits, is_engine);
  for (const EngineFactory& f : engine_registry()) {
    if (const toml::table* sub = r.subtable(f.info.name)) {
      TableReader er(ctx, *sub, "gate." + f.info.name);
      read_gate_limits(er, g.per_engine[f.info.name], [](std::string_view) { return false; });
      read_known_failures(er, g.known_failures[f.info.name]);
    }
  }
}

void read_engine_options(Context& ctx, const toml::table& t, const EngineInfo& info, EngineOptions& out) {
  TableReader r(ctx, t, info.name);
  for (const OptionSpec& spec : info.options) {
    const toml::node* n = r.node(spec.key);
    if (n == nullptr) continue;
    const std::string kp = r.key_path(spec.key);
    switch (spec.default_value.index()) {
      case 0:
        if (const auto* b = n->as_boolean()) {
          out[spec.key] = b->get();
        } else {
          r.error_at(*n, spec.key, std::string("expected a boolean, got ") + type_name(*n));
        }
        break;
      case 1:
        if (const auto* i = n->as_integer()) {
          const auto v = static_cast<std::int64_t>(i->get());
          if (!spec.range.contains(static_cast<double>(v))) {
            r.error_at(*n, spec.key, "must be " + spec.range.describe() + ", got " + std::to_string(v));
            break;
          }
          out[spec.key] = v;
        } else {
          r.error_at(*n, spec.key, std::string("expected an integer, got ") + type_name(*n));
        }
        break;
      case 2:
        if (auto v = r.to_number(*n, kp)) {
          if (!std::isfinite(*v) || !spec.range.contains(*v)) {
            r.error_at(*n, spec.key, "must be a finite number " + spec.range.describe() + ", got " +
                                         option_value_to_string(OptionValue{*v}));
            break;
          }
          out[spec.key] = *v;
        }
        break;
      default: {
        std::string s;
        if (!r.read(spec.key, s)) break;
        if (!spec.choices.empty() && std::find(spec.choices.begin(), spec.choices.end(), s) == spec.choices.end()) {
          std::string all;
          for (const std::string& c : spec.choices) all += (all.empty() ? "" : " | ") + c;
          r.error_at(*n, spec.key, "unknown value \"" + s + "\"; expected one of " + all);
          break;
        }
        out[spec.key] = s;
      }
    }
  }
  // Options that need another option in a range (Bullet's ccd needs a positive
  // contact_processing_threshold): the engine cannot run the scene otherwise, so it is bad
  // input here, not a run error later. Judged on the values the run would use (given or default).
  for (const OptionSpec& spec : info.options) {
    if (spec.needs_key.empty() || spec.default_value.index() != 0) continue;
    auto effective = [&](const std::string& key) -> const OptionValue* {
      if (auto it = out.find(key); it != out.end()) return &it->second;
      for (const OptionSpec& o : info.options) {
        if (o.key == key) return &o.default_value;
      }
      return nullptr;
    };
    const OptionValue* on = effective(spec.key);
    if (on == nullptr || on->index() != 0 || !std::get<bool>(*on)) continue;
    const OptionValue* need = effective(spec.needs_key);
    double v = std::numeric_limits<double>::quiet_NaN();
    if (need != nullptr && need->index() == 1) v = static_cast<double>(std::get<std::int64_t>(*need));
    if (need != nullptr && need->index() == 2) v = std::get<double>(*need);
    if (need != nullptr && (need->index() == 1 || need->index() == 2) && spec.needs_range.contains(v)) continue;
    const std::string got = need == nullptr ? std::string("nothing") : option_value_to_string(*need);
    const bool given = out.count(spec.needs_key) != 0;
    const std::string msg = spec.key + " = true needs " + info.name + "." + spec.needs_key + " " +
                            spec.needs_range.describe() + ", and it is " + got +
                            (given ? std::string() : std::string(" (its default)"));
    if (const toml::node* n = given ? r.node(spec.needs_key) : r.node(spec.key)) {
      r.error_at(*n, given ? spec.needs_key : spec.key, msg);
    } else {
      r.error_here(spec.key, msg);
    }
  }
}

// Checks that need the whole scene: unique names, references by name.
void check_references(Context& ctx, const toml::table& root, Scene& s) {
  auto where = [&](std::string_view array, std::size_t i, std::string_view key = {}) -> toml::source_region {
    if (const auto* a = root.get_as<toml::array>(array)) {
      if (i < a->size()) {
        if (const auto* t = a->get(i)->as_table(); t != nullptr && !key.empty()) {
          if (const toml::node* n = t->get(key)) return n->source();
        }
        return a->get(i)->source();
      }
    }
    if (const auto* t = root.get_as<toml::table>(array)) return t->source();
    return root.source();
  };
  std::map<std::string, std::string> names;   // name -> what it is
  static const std::regex kObjectName("[a-z0-9_]+");
  auto claim = [&](const std::string& name, const std::string& what, std::string_view array, std::size_t i) {
    // Names go into CSV headers, plot labels and the terminal: letters, digits, underscores.
    if (!std::regex_match(name, kObjectName)) {
      ctx.error(where(array, i, "name"), indexed(std::string(array), i) + ".name",
                "must match [a-z0-9_]+ (lower-case letters, digits, underscores), got \"" + shown(name) + "\"");
      return;
    }
    auto [it, fresh] = names.emplace(name, what);
    if (!fresh) ctx.error(where(array, i, "name"), indexed(std::string(array), i) + ".name",
                          "duplicate name \"" + name + "\" (already used by " + it->second + ")");
  };
  for (std::size_t i = 0; i < s.bodies.size(); ++i) claim(s.bodies[i].name, "a body", "bodies", i);
  for (std::size_t i = 0; i < s.walls.size(); ++i) claim(s.walls[i].name, "a wall", "walls", i);
  for (std::size_t i = 0; i < s.boxes.size(); ++i) claim(s.boxes[i].name, "a box", "boxes", i);
  for (std::size_t i = 0; i < s.surfaces.size(); ++i) claim(s.surfaces[i].name, "a surface", "surfaces", i);

  auto body_exists = [&](const std::string& n) { return s.body_index(n) >= 0; };
  auto object_exists = [&](const std::string& n) { return names.count(n) > 0; };
  const toml::table* expect = root.get_as<toml::table>("expect");
  auto expect_where = [&]() { return expect ? expect->source() : root.source(); };
  auto check = [&](bool ok, const std::string& key, const std::string& name, const char* what) {
    if (!ok) ctx.error(expect_where(), key, std::string("no ") + what + " named \"" + name + "\"");
  };
  if (s.expect.first_contact) {
    check(object_exists(s.expect.first_contact->a), "expect.first_contact.a", s.expect.first_contact->a, "body or barrier");
    check(object_exists(s.expect.first_contact->b), "expect.first_contact.b", s.expect.first_contact->b, "body or barrier");
  }
  for (std::size_t i = 0; i < s.expect.contacts.size(); ++i) {
    check(object_exists(s.expect.contacts[i].a), indexed("expect.contacts", i) + ".a", s.expect.contacts[i].a, "body or barrier");
    check(object_exists(s.expect.contacts[i].b), indexed("expect.contacts", i) + ".b", s.expect.contacts[i].b, "body or barrier");
  }
  for (std::size_t i = 0; i < s.expect.final_states.size(); ++i) {
    check(body_exists(s.expect.final_states[i].body), indexed("expect.final", i) + ".body", s.expect.final_states[i].body, "body");
  }
  for (std::size_t i = 0; i < s.expect.apex.size(); ++i) {
    const ExpectedApex& a = s.expect.apex[i];
    check(body_exists(a.body), indexed("expect.apex", i) + ".body", a.body, "body");
    // The highest y includes the start: a body expected to come back up to where it
    // started meets that at t = 0 whatever the run does (an engine whose ball never bounced
    // passed `apex = 10 m` for a 10 m drop). Without its time such an apex checks nothing
    // (with it, the t = 0 start holds the maximum unless the run climbs past it).
    const int b = s.body_index(a.body);
    const double tolerance = a.tolerance.value_or(1e-3);
    if (b >= 0 && !a.time && std::abs(s.bodies[static_cast<std::size_t>(b)].position.y - a.height) <= tolerance) {
      ctx.error(expect_where(), indexed("expect.apex", i) + ".height",
                "\"" + a.body + "\" starts at y = " + format_number(s.bodies[static_cast<std::size_t>(b)].position.y) +
                    " m, within the tolerance of this height: the highest y is met at t = 0 whatever the run does; "
                    "hold the bounce with `contacts` times or a `final` state instead");
    }
  }
  for (std::size_t i = 0; i < s.expect.period.size(); ++i) {
    check(body_exists(s.expect.period[i].body), indexed("expect.period", i) + ".body", s.expect.period[i].body, "body");
  }
  for (std::size_t i = 0; i < s.materials.size(); ++i) {
    for (const std::string* n : {&s.materials[i].a, &s.materials[i].b}) {
      if (!object_exists(*n)) ctx.error(where("materials", i), indexed("materials", i) + (n == &s.materials[i].a ? ".a" : ".b"),
                                        "no body or barrier named \"" + *n + "\"");
    }
  }
  // The pair's static friction must not fall below its kinetic friction (mu_s >= mu_k, as on a
  // body): an override static_friction = 0.05 over rough bodies (mu 0.2) was accepted, a pair
  // whose contact can slide but never stay at rest.
  auto view_of = [&](const std::string& name) -> std::optional<MaterialView> {
    for (const BodyDef& b : s.bodies) if (b.name == name) return material_of(b);
    for (const WallDef& w : s.walls) if (w.name == name) return material_of(w.name, w.material);
    for (const BoxDef& w : s.boxes) if (w.name == name) return material_of(w.name, w.material);
    for (const SurfaceDef& w : s.surfaces) if (w.name == name) return material_of(w.name, w.material);
    return std::nullopt;
  };
  for (std::size_t i = 0; i < s.materials.size(); ++i) {
    if (!s.materials[i].static_friction) continue;
    const std::optional<MaterialView> a = view_of(s.materials[i].a), b = view_of(s.materials[i].b);
    if (!a || !b) continue;
    const PairMaterial pm = combine_materials(s, *a, *b);
    if (pm.static_friction < pm.friction) {
      ctx.error(where("materials", i), indexed("materials", i) + ".static_friction",
                "the pair's static friction " + format_number(pm.static_friction) + " is below its kinetic friction " +
                    format_number(pm.friction) + " (mu_s >= mu_k); give the pair's friction too");
    }
  }
  for (std::size_t i = 0; i < s.emitters.size(); ++i) {
    if (!body_exists(s.emitters[i].parent)) {
      ctx.error(where("emitters", i), indexed("emitters", i) + ".parent", "no body named \"" + s.emitters[i].parent + "\"");
    }
  }
  for (std::size_t i = 0; i < s.bodies.size(); ++i) {
    if (s.bodies[i].is_static && s.bodies[i].shape == ShapeKind::Point) {
      ctx.error(where("bodies", i), indexed("bodies", i) + ".static", "a static body must be a circle");
    }
    // A static body is immovable: every engine ignored a velocity or a thrust given to it
    // (a "moving post" stood still on all five, and the scene was `ok`), so such a key
    // says something that no run does.
    if (s.bodies[i].is_static && (s.bodies[i].velocity.x != 0.0 || s.bodies[i].velocity.y != 0.0)) {
      ctx.error(where("bodies", i, "velocity"), indexed("bodies", i) + ".velocity",
                "a static body does not move (physval has no kinematic bodies): its velocity must be [0, 0]");
    }
    if (s.bodies[i].is_static && s.bodies[i].thrust.enabled()) {
      ctx.error(where("bodies", i, "thrust"), indexed("bodies", i) + ".thrust", "a static body does not move: it takes no thrust");
    }
    // Thrust acts along the heading. core keeps every heading (bodies do not spin, lecture
    // step 6: its angular velocity is always 0), while Box2D, Bullet, Chipmunk and ODE turn
    // it at the body's angular_velocity: a car with angle 0.3 and angular_velocity 2 went
    // straight on core (4 m/s along 0.3 rad after 2 s) and round a curve on the other four,
    // each `ok` and 3.9 m "off" a reference that does not model the key.
    if (s.bodies[i].thrust.enabled() && s.bodies[i].angular_velocity != 0.0) {
      ctx.error(where("bodies", i, "angular_velocity"), indexed("bodies", i) + ".angular_velocity",
                "a body with a thrust table must not spin: core (the reference) keeps its heading, the other "
                "engines would turn it, and the thrust with it; its angular_velocity must be 0");
    }
  }
}

// Bodies that overlap at t = 0 are an error unless the scene opts in with
// allow_initial_overlap = true: engines resolve them each in their own way (the
// reference reported ~500 missed contacts), so nothing afterwards compares. Sweep
// over x (n log n): the first few overlapping pairs are reported, each at the later body.
void check_initial_overlaps(Context& ctx, const toml::table& root, const Scene& s) {
  std::vector<std::size_t> order(s.bodies.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  auto lo = [&](std::size_t i) { return s.bodies[i].position.x - s.bodies[i].radius; };
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return lo(a) < lo(b); });
  const auto* array = root.get_as<toml::array>("bodies");
  int reported = 0;
  for (std::size_t k = 0; k < order.size() && reported < 5; ++k) {
    const BodyDef& a = s.bodies[order[k]];
    for (std::size_t m = k + 1; m < order.size() && reported < 5; ++m) {
      const BodyDef& b = s.bodies[order[m]];
      if (lo(order[m]) > a.position.x + a.radius) break;
      const double reach = a.radius + b.radius;
      const double depth = reach - length(b.position - a.position);
      if (depth <= 1e-9 * reach + 1e-12) continue;
      const std::size_t later = std::max(order[k], order[m]);
      const toml::node* at = array != nullptr && later < array->size() ? array->get(later) : nullptr;
      if (const auto* t = at != nullptr ? at->as_table() : nullptr; t != nullptr && t->get("position") != nullptr) {
        at = t->get("position");
      }
      char text[160];
      std::snprintf(text, sizeof text, "overlaps body \"%s\" by %.3g m at t = 0", (later == order[k] ? b : a).name.c_str(),
                    depth);
      ctx.error(at != nullptr ? at->source() : root.source(), indexed("bodies", later) + ".position",
                std::string(text) + " (set allow_initial_overlap = true at the top level if you mean it)");
      ++reported;
    }
  }
  // A body inside a barrier (a wall, a box side, a surface segment) it collides with: each
  // engine pushes it out its own way, or lets it fall through.
  struct Piece {
    Vec2 a, b;
    const std::string* what;
    const std::string* group;
  };
  std::vector<Piece> pieces;
  std::vector<std::string> names;
  names.reserve(s.walls.size() + s.boxes.size() + s.surfaces.size());
  for (const WallDef& w : s.walls) {
    names.push_back("wall \"" + w.name + "\"");
    pieces.push_back({w.from, w.to, &names.back(), &w.material.group});
  }
  for (const BoxDef& b : s.boxes) {
    names.push_back("box \"" + b.name + "\"");
    const Vec2 c[4] = {b.min, {b.max.x, b.min.y}, b.max, {b.min.x, b.max.y}};
    for (int k = 0; k < 4; ++k) pieces.push_back({c[k], c[(k + 1) % 4], &names.back(), &b.material.group});
  }
  for (const SurfaceDef& f : s.surfaces) {
    names.push_back("surface \"" + f.name + "\"");
    for (std::size_t k = 0; k + 1 < f.points.size(); ++k) {
      pieces.push_back({f.points[k], f.points[k + 1], &names.back(), &f.material.group});
    }
  }
  for (std::size_t i = 0; i < s.bodies.size() && reported < 5; ++i) {
    const BodyDef& d = s.bodies[i];
    if (d.is_static || d.shape == ShapeKind::Point || !(d.radius > 0.0)) continue;
    for (const Piece& p : pieces) {
      const Vec2 ab = p.b - p.a;
      const double len2 = dot(ab, ab);
      const double u = len2 > 0.0 ? std::clamp(dot(d.position - p.a, ab) / len2, 0.0, 1.0) : 0.0;
      const double depth = d.radius - length(d.position - (p.a + ab * u));
      if (depth <= 1e-9 * d.radius + 1e-12) continue;
      if (!response_between(s, d.group, *p.group).collide) continue;
      const toml::node* at = array != nullptr && i < array->size() ? array->get(i) : nullptr;
      if (const auto* t = at != nullptr ? at->as_table() : nullptr; t != nullptr && t->get("position") != nullptr) {
        at = t->get("position");
      }
      char text[200];
      std::snprintf(text, sizeof text, "overlaps %s by %.3g m at t = 0", p.what->c_str(), depth);
      ctx.error(at != nullptr ? at->source() : root.source(), indexed("bodies", i) + ".position",
                std::string(text) + " (set allow_initial_overlap = true at the top level if you mean it)");
      ++reported;
      break;
    }
  }
  // A point on a barrier's line (to round-off): touching it, by the radius rule, but in a
  // zero-thickness barrier it is on neither side, and each engine (core too) picks one: a
  // point put on a floor at rest stayed on it in core and fell through it in the others,
  // moving down it fell through in all five, every run `ok`.
  for (std::size_t i = 0; i < s.bodies.size() && reported < 5; ++i) {
    const BodyDef& d = s.bodies[i];
    if (d.is_static || !(d.shape == ShapeKind::Point || !(d.radius > 0.0))) continue;
    for (const Piece& p : pieces) {
      const Vec2 ab = p.b - p.a;
      const double len2 = dot(ab, ab);
      const double u = len2 > 0.0 ? std::clamp(dot(d.position - p.a, ab) / len2, 0.0, 1.0) : 0.0;
      const double gap = length(d.position - (p.a + ab * u));
      const double roundoff = 1e-12 * (1.0 + length(d.position) + std::sqrt(len2));
      if (gap > roundoff) continue;
      if (!response_between(s, d.group, *p.group).collide) continue;
      const toml::node* at = array != nullptr && i < array->size() ? array->get(i) : nullptr;
      if (const auto* t = at != nullptr ? at->as_table() : nullptr; t != nullptr && t->get("position") != nullptr) {
        at = t->get("position");
      }
      ctx.error(at != nullptr ? at->source() : root.source(), indexed("bodies", i) + ".position",
                "a point on " + *p.what + " at t = 0 (" + format_number(gap) +
                    " m from it): a point in a barrier is on neither side of it, and engines put it on either; "
                    "start it off the line (or set allow_initial_overlap = true at the top level if you mean it)");
      ++reported;
      break;
    }
  }
  // A body whose centre is inside a box: a box is a solid obstacle (the lecture's "a point
  // is inside a box" test; Box2D and Bullet build a solid polygon or box), so a body that
  // starts inside is pushed out by them and kept in by core's four sides. No run compares.
  for (std::size_t i = 0; i < s.bodies.size() && reported < 5; ++i) {
    const BodyDef& d = s.bodies[i];
    if (d.is_static) continue;
    for (const BoxDef& b : s.boxes) {
      const Vec2 x = d.position;
      if (!(x.x > b.min.x && x.x < b.max.x && x.y > b.min.y && x.y < b.max.y)) continue;
      if (!response_between(s, d.group, b.material.group).collide) continue;
      const toml::node* at = array != nullptr && i < array->size() ? array->get(i) : nullptr;
      if (const auto* t = at != nullptr ? at->as_table() : nullptr; t != nullptr && t->get("position") != nullptr) {
        at = t->get("position");
      }
      ctx.error(at != nullptr ? at->source() : root.source(), indexed("bodies", i) + ".position",
                "is inside box \"" + b.name +
                    "\" at t = 0: a box is a solid obstacle (Box2D and Bullet build it solid and push the body "
                    "out, core's sides keep it in); build a container from four [[walls]] (or set "
                    "allow_initial_overlap = true at the top level if you mean it)");
      ++reported;
      break;
    }
  }
}

Scene read_scene(Context& ctx, const toml::table& root) {
  Scene s;
  s.source_file = ctx.file;
  TableReader r(ctx, root, "");
  if (r.read("name", s.name, true)) {
    static const std::regex kName("[a-z0-9_]+");
    if (!std::regex_match(s.name, kName)) {
      r.error_at(*root.get("name"), "name", "must match [a-z0-9_]+, got \"" + s.name + "\"");
    }
  }
  r.read("description", s.description);
  r.read_required("duration", s.duration, "> 0", [](double v) { return v > 0.0; });
  r.read("dt", s.dt, "> 0", [](double v) { return v > 0.0; });
  r.read("sample_interval", s.sample_interval, ">= 0", [](double v) { return v >= 0.0; });
  if (s.duration > 0.0 && s.dt > 0.0) {
    if (const std::string too_many = scene_steps_error(s); !too_many.empty()) {
      const toml::node* at = root.get("dt") != nullptr ? root.get("dt") : root.get("duration");
      if (at != nullptr) r.error_at(*at, root.get("dt") != nullptr ? "dt" : "duration", too_many);
    }
  }
  if (const toml::node* n = r.node("engines")) {
    const auto* a = n->as_array();
    if (a == nullptr) {
      r.error_at(*n, "engines", std::string("expected an array of engine names, got ") + type_name(*n));
    } else {
      for (std::size_t i = 0; i < a->size(); ++i) {
        const auto* str = a->get(i)->as_string();
        if (str == nullptr || find_engine(str->get()) == nullptr) {
          ctx.error(a->get(i)->source(), indexed("engines", i), "not an engine physval knows (see `physval engines`)");
        } else {
          s.engines.push_back(str->get());
        }
      }
    }
  }
  if (const toml::table* w = r.subtable("world")) read_world(ctx, *w, s.world);

  auto bodies = r.tables("bodies");
  s.bodies.resize(bodies.size());
  for (std::size_t i = 0; i < bodies.size(); ++i) read_body(ctx, *bodies[i], i, s.bodies[i]);

  auto walls = r.tables("walls");
  for (std::size_t i = 0; i < walls.size(); ++i) {
    TableReader wr(ctx, *walls[i], indexed("walls", i));
    WallDef w;
    w.line = static_cast<int>(walls[i]->source().begin.line);
    w.name = "wall" + std::to_string(i);
    wr.read("name", w.name);
    wr.read("from", w.from, true);
    wr.read("to", w.to, true);
    read_material(wr, w.material);
    if (wr.has("from") && wr.has("to") && w.from == w.to) wr.error_here("to", "a wall must have non-zero length");
    s.walls.push_back(w);
  }
  auto boxes = r.tables("boxes");
  for (std::size_t i = 0; i < boxes.size(); ++i) {
    TableReader br(ctx, *boxes[i], indexed("boxes", i));
    BoxDef b;
    b.line = static_cast<int>(boxes[i]->source().begin.line);
    b.name = "box" + std::to_string(i);
    br.read("name", b.name);
    br.read("min", b.min, true);
    br.read("max", b.max, true);
    read_material(br, b.material);
    if (br.has("min") && br.has("max") && !(b.max.x > b.min.x && b.max.y > b.min.y)) {
      br.error_here("max", "must be greater than min in x and y");
    }
    s.boxes.push_back(b);
  }
  auto surfaces = r.tables("surfaces");
  for (std::size_t i = 0; i < surfaces.size(); ++i) {
    TableReader sr(ctx, *surfaces[i], indexed("surfaces", i));
    SurfaceDef sd;
    sd.line = static_cast<int>(surfaces[i]->source().begin.line);
    sd.name = "surface" + std::to_string(i);
    sr.read("name", sd.name);
    if (const toml::node* pts = sr.node("points")) {
      if (const auto* a = pts->as_array()) {
        for (std::size_t k = 0; k < a->size(); ++k) {
          if (auto v = sr.vec2(*a->get(k), indexed(sr.key_path("points"), k))) sd.points.push_back(*v);
        }
        if (sd.points.size() < 2) sr.error_at(*pts, "points", "a surface needs at least 2 points");
        for (std::size_t k = 1; k < sd.points.size(); ++k) {
          if (sd.points[k] == sd.points[k - 1]) {
            sr.error_at(*pts, "points", "consecutive points must differ (point " + std::to_string(k) + ")");
          }
        }
      } else {
        sr.error_at(*pts, "points", std::string("expected an array of [x, y], got ") + type_name(*pts));
      }
    } else {
      sr.missing("points");
    }
    if (const toml::node* nrm = sr.node("normals")) {
      if (const auto* a = nrm->as_array()) {
        for (std::size_t k = 0; k < a->size(); ++k) {
          if (auto v = sr.vec2(*a->get(k), indexed(sr.key_path("normals"), k))) {
            if (length(*v) == 0.0) {
              sr.error_at(*a->get(k), "normals", "a normal must be non-zero");
            } else {
              sd.normals.push_back(normalized(*v));
            }
          }
        }
        if (sd.normals.size() != sd.points.size()) sr.error_at(*nrm, "normals", "needs one normal per point");
      } else {
        sr.error_at(*nrm, "normals", std::string("expected an array of [x, y], got ") + type_name(*nrm));
      }
    }
    read_material(sr, sd.material);
    s.surfaces.push_back(sd);
  }
  auto materials = r.tables("materials");
  for (std::size_t i = 0; i < materials.size(); ++i) {
    TableReader mr(ctx, *materials[i], indexed("materials", i));
    MaterialOverride m;
    mr.read("a", m.a, true);
    mr.read("b", m.b, true);
    for (auto [key, field] : {std::pair{"restitution", &m.restitution}, std::pair{"friction", &m.friction},
                              std::pair{"static_friction", &m.static_friction},
                              std::pair{"rolling_friction", &m.rolling_friction}}) {
      double v = 0.0;
      const bool given = mr.has(key);
      mr.read_non_negative(key, v);
      if (given) *field = v;
    }
    s.materials.push_back(m);
  }
  auto rules = r.tables("collision_matrix");
  for (std::size_t i = 0; i < rules.size(); ++i) {
    TableReader cr(ctx, *rules[i], indexed("collision_matrix", i));
    CollisionRule rule;
    cr.read("a", rule.a, true);
    cr.read("b", rule.b, true);
    if (!cr.has("response")) cr.missing("response");
    if (auto c = cr.choice("response", {"bounce", "destroy_a", "destroy_b", "destroy_both", "ignore", "event"})) {
      rule.response = static_cast<CollisionResponse>(*c);
    }
    s.collision_matrix.push_back(rule);
  }
  auto emitters = r.tables("emitters");
  for (std::size_t i = 0; i < emitters.size(); ++i) {
    TableReader er(ctx, *emitters[i], indexed("emitters", i));
    EmitterDef e;
    e.line = static_cast<int>(emitters[i]->source().begin.line);
    e.name = "emitter" + std::to_string(i);
    er.read("name", e.name);
    er.read("parent", e.parent, true);
    if (auto m = er.choice("mode", {"explode", "trail"})) e.mode = *m == 0 ? EmitterMode::Explode : EmitterMode::Trail;
    er.read_non_negative("at", e.at);
    er.read_non_negative("rate", e.rate);
    double count = 0.0;
    er.read("count", count, ("a whole number from 0 to " + format_number(kMaxEmitterCount)).c_str(),
            [](double v) { return v >= 0.0 && v == std::floor(v) && v <= kMaxEmitterCount; });
    e.count = static_cast<int>(count);
    er.read_non_negative("speed", e.speed);
    er.read("lifetime", e.lifetime, "> 0", [](double v) { return v > 0.0; });
    er.read("mass", e.mass, "> 0", [](double v) { return v > 0.0; });
    er.read("destroy_on_collision", e.destroy_on_collision);
    er.read("gravity", e.gravity);
    double seed = 1.0;
    er.read("seed", seed, "a whole number >= 0", [](double v) { return v >= 0.0 && v == std::floor(v); });
    e.seed = static_cast<std::uint64_t>(seed);
    // A count already refused above is not refused again for being 0 (it was never read).
    const toml::node* count_node = emitters[i]->get("count");
    const bool count_refused = count_node != nullptr && !(count_node->value<double>() && *count_node->value<double>() == count);
    if (e.mode == EmitterMode::Explode && e.count == 0 && !count_refused) {
      er.error_here("count", "an exploding emitter needs count > 0");
    }
    if (e.mode == EmitterMode::Trail && e.rate <= 0.0) er.error_here("rate", "a trail emitter needs rate > 0");
    s.emitters.push_back(e);
  }
  // Bound before running: bodies plus every particle the emitters can make (the memory
  // estimate is checked once the whole scene is read, below).
  double particle_bound = 0.0;
  {
    double particles = 0.0;
    for (const EmitterDef& e : s.emitters) {
      particles += e.mode == EmitterMode::Explode ? e.count : std::ceil(e.rate * std::max(s.duration, 0.0));
    }
    particle_bound = particles;
    const double objects = static_cast<double>(s.bodies.size()) + particles;
    const std::string what = std::to_string(s.bodies.size()) + (s.bodies.size() == 1 ? " body" : " bodies") +
                             " and up to " + format_number(particles) + " particles from emitters";
    if (objects > kMaxObjects) {
      r.error_here("bodies", what + ": more than physval's bound of " + format_number(kMaxObjects) + " objects");
    }
  }
  if (const toml::table* c = r.subtable("conserves")) {
    TableReader cr(ctx, *c, "conserves");
    cr.read("energy", s.conserves.energy);
    cr.read("linear_momentum", s.conserves.linear_momentum);
    cr.read("angular_momentum", s.conserves.angular_momentum);
  }
  if (const toml::table* e = r.subtable("expect")) read_expect(ctx, *e, s.expect);
  if (const toml::table* g = r.subtable("gate")) read_gate(ctx, *g, s.gate);
  for (const EngineFactory& f : engine_registry()) {
    if (const toml::table* t = r.subtable(f.info.name)) read_engine_options(ctx, *t, f.info, s.engine_options[f.info.name]);
  }
  if (s.sample_interval > 0.0 && s.sample_interval < s.dt) {
    if (const toml::node* n = root.get("sample_interval")) {
      r.error_at(*n, "sample_interval", "must be >= dt (" + format_number(s.dt) + ") or 0 for automatic, got " +
                                            format_number(s.sample_interval));
    }
  } else if (s.sample_interval > 0.0 && s.dt > 0.0) {
    // States are sampled every whole number of steps: 0.15 s at dt = 0.1 s was silently
    // sampled every 0.1 s. Within 1e-9 of a whole number (round-off of "1/60" and the like).
    const double steps = s.sample_interval / s.dt;
    const double whole = std::round(steps);
    if (std::abs(steps - whole) > 1e-9 * std::max(1.0, steps)) {
      if (const toml::node* n = root.get("sample_interval")) {
        const double below = std::max(1.0, std::floor(steps)) * s.dt, above = std::ceil(steps) * s.dt;
        r.error_at(*n, "sample_interval", "must be a whole number of steps of dt = " + format_number(s.dt) + " (" +
                                              format_number(below) + " or " + format_number(above) + "), got " +
                                              format_number(s.sample_interval));
      }
    }
  }
  bool allow_initial_overlap = false;
  r.read("allow_initial_overlap", allow_initial_overlap);
  r.finish();
  if (ctx.errors.empty() && static_cast<double>(s.bodies.size()) + particle_bound <= kMaxObjects &&
      s.steps() <= Scene::kMaxSteps) {
    std::size_t engines = 0;
    for (const EngineFactory& f : engine_registry()) {
      if (s.engines.empty() || std::find(s.engines.begin(), s.engines.end(), f.info.name) != s.engines.end()) ++engines;
    }
    if (const std::string too_big = memory_bound_error(s, engines); !too_big.empty()) {
      // Where the bulk is: the emitter that makes the most particles, else the last body.
      int line = s.bodies.empty() ? 1 : s.bodies.back().line;
      std::string key = s.bodies.empty() ? "bodies" : "bodies[" + std::to_string(s.bodies.size() - 1) + "]";
      double most = 0.0;
      for (std::size_t k = 0; k < s.emitters.size(); ++k) {
        const EmitterDef& e = s.emitters[k];
        const double n = e.mode == EmitterMode::Explode ? e.count : std::ceil(e.rate * s.duration);
        if (n > most && n > static_cast<double>(s.bodies.size())) {
          most = n;
          line = e.line;
          key = "emitters[" + std::to_string(k) + "]";
        }
      }
      ctx.errors.push_back({ctx.file, line, 1, key, "the scene " + too_big});
    }
  }
  check_references(ctx, root, s);
  if (!allow_initial_overlap) check_initial_overlaps(ctx, root, s);
  return s;
}

// Bounds while the file is read, before the TOML parser builds a tree for it (a 1e6-body
// file took 25 s to refuse): `[[bodies]]` headers are counted line by line (outside
// multi-line strings), and the header past the bound is the error, with its line. Bodies
// written as one inline array are counted after parsing, like everything else.
std::optional<Diagnostic> count_tables_early(std::string_view text, const std::string& source_name) {
  std::size_t bodies = 0, line = 0, pos = 0;
  bool in_basic = false, in_literal = false;   // inside """ or ''' strings
  while (pos < text.size()) {
    ++line;
    std::size_t end = text.find('\n', pos);
    if (end == std::string_view::npos) end = text.size();
    const std::string_view l = text.substr(pos, end - pos);
    pos = end + 1;
    if (!in_basic && !in_literal) {
      std::size_t b = 0;
      while (b < l.size() && (l[b] == ' ' || l[b] == '\t')) ++b;
      if (l.substr(b, 2) == "[[") {
        const std::size_t e = l.find("]]", b + 2);
        if (e != std::string_view::npos) {
          std::string_view name = l.substr(b + 2, e - b - 2);
          while (!name.empty() && (name.front() == ' ' || name.front() == '\t')) name.remove_prefix(1);
          while (!name.empty() && (name.back() == ' ' || name.back() == '\t')) name.remove_suffix(1);
          if (name == "bodies" && ++bodies > static_cast<std::size_t>(kMaxObjects)) {
            return Diagnostic{source_name, static_cast<int>(line), static_cast<int>(b + 1),
                              "bodies[" + std::to_string(bodies - 1) + "]",
                              "more than physval's bound of " + format_number(kMaxObjects) +
                                  " bodies (and particles) in a scene; the file was not read further"};
          }
        }
        continue;
      }
    }
    for (std::size_t k = l.find_first_of("\"'"); k != std::string_view::npos; k = l.find_first_of("\"'", k + 1)) {
      if (l.substr(k, 3) == "\"\"\"" && !in_literal) {
        in_basic = !in_basic;
        k += 2;
      } else if (l.substr(k, 3) == "'''" && !in_basic) {
        in_literal = !in_literal;
        k += 2;
      }
    }
  }
  return std::nullopt;
}

}  // namespace

ScenarioLoad parse_scenario(std::string_view text, const std::string& source_name) {
  Context ctx{source_name, {}};
  ScenarioLoad out;
  if (std::optional<Diagnostic> too_many = count_tables_early(text, source_name)) {
    out.errors.push_back(std::move(*too_many));
    return out;
  }
  toml::table root;

  try {
    root = toml::parse(text, source_name);
  } catch (const toml::parse_error& e) {
    ctx.errors.push_back({source_name, static_cast<int>(e.source().begin.line),
                          static_cast<int>(e.source().begin.column), "", "TOML syntax error: " + std::string(e.description())});
    out.errors = std::move(ctx.errors);
    return out;
  }
  Scene scene = read_scene(ctx, root);
  if (ctx.errors.empty()) {
    out.scene = std::move(scene);
  } else {
    std::stable_sort(ctx.errors.begin(), ctx.errors.end(),
                     [](const Diagnostic& a, const Diagnostic& b) { return a.line < b.line; });
  }
  out.errors = std::move(ctx.errors);
  return out;
}

ScenarioLoad load_scenario_file(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) {
    ScenarioLoad out;
    out.errors.push_back({file.string(), 0, 0, "", "cannot open the file"});
    return out;
  }
  std::ostringstream ss;
  ss << in.rdbuf();
  const std::string text = ss.str();
  note_loaded_scenario_text(file.string(), text);   // the reference cache keys on this text
  return parse_scenario(text, file.string());
}

SuiteLoad load_suite(const std::vector<std::string>& paths) {
  SuiteLoad out;
  std::vector<std::filesystem::path> files;
  for (const std::string& p : paths) {
    std::error_code ec;
    const std::filesystem::path path(p);
    if (std::filesystem::is_directory(path, ec)) {
      std::vector<std::filesystem::path> found;
      for (auto it = std::filesystem::recursive_directory_iterator(path, ec);
           !ec && it != std::filesystem::recursive_directory_iterator(); it.increment(ec)) {
        if (it->is_regular_file() && it->path().extension() == ".toml") found.push_back(it->path());
      }
      std::sort(found.begin(), found.end());
      if (found.empty()) out.errors.push_back({p, 0, 0, "", "no scenario files (*.toml) in this folder"});
      files.insert(files.end(), found.begin(), found.end());
    } else if (std::filesystem::is_regular_file(path, ec)) {
      files.push_back(path);
    } else {
      out.errors.push_back({p, 0, 0, "", "no such file or folder"});
    }
  }
  // The same file given twice (directly and through its folder, or twice) is loaded once.
  std::set<std::filesystem::path> distinct;
  std::vector<std::filesystem::path> unique_files;
  for (const auto& f : files) {
    std::error_code ec;
    std::filesystem::path canonical = std::filesystem::weakly_canonical(f, ec);
    if (ec) canonical = f;
    if (distinct.insert(canonical).second) unique_files.push_back(f);
  }
  files = std::move(unique_files);
  std::map<std::string, std::string> seen;   // scenario name -> file
  for (const auto& f : files) {
    ScenarioLoad one = load_scenario_file(f);
    out.errors.insert(out.errors.end(), one.errors.begin(), one.errors.end());
    if (!one.scene) continue;
    auto [it, fresh] = seen.emplace(one.scene->name, f.string());
    if (!fresh) {
      out.errors.push_back({f.string(), 1, 0, "name",
                            "scenario name \"" + one.scene->name + "\" is already used by " + it->second});
      continue;
    }
    out.scenes.push_back(std::move(*one.scene));
  }
  return out;
}


namespace {
double g_memory_limit = 0.0;   // 0: half of the machine's
}  // namespace

// Measured on this machine (Release, GNU time's maximum resident set of physval with
// core's runs in child processes, -j 1): 5000 and 20000 bodies at 61 samples, 20000 bodies
// at 121 samples: 183, 698 and 1208 MB... fitted as 8 MB + 2400 B per body + 540 B per
// stored state (samples x objects; one engine and the reference); each further engine
// run held adds its series, 56 B a state (sizeof(BodyState)). A particle's engine state is
// taken as core's, about 200 B.
double estimated_memory_bytes(const Scene& scene, std::size_t engines) {
  double particles = 0.0;
  for (const EmitterDef& e : scene.emitters) {
    particles += e.mode == EmitterMode::Explode ? e.count : std::ceil(e.rate * std::max(scene.duration, 0.0));
  }
  const double bodies = static_cast<double>(scene.bodies.size());
  const long every = sample_every(scene, RunOptions{}.max_sample_states);
  const long steps = scene.steps();
  const double samples = static_cast<double>(steps / every + 1 + (steps % every != 0 ? 1 : 0));   // t = 0, each every-th, the last
  const double states = samples * (bodies + particles);
  const double extra_runs = engines > 1 ? static_cast<double>(engines - 1) : 0.0;
  return 8e6 + 2400.0 * bodies + 200.0 * particles + states * (540.0 + 56.0 * extra_runs);
}

void set_memory_limit_bytes(double bytes) { g_memory_limit = bytes; }

double memory_limit_bytes() {
  if (g_memory_limit > 0.0) return g_memory_limit;
  const double machine = static_cast<double>(::sysconf(_SC_PHYS_PAGES)) * static_cast<double>(::sysconf(_SC_PAGE_SIZE));
  return machine > 0.0 ? 0.5 * machine : 1e300;
}

std::string memory_bound_error(const Scene& scene, std::size_t engines) {
  const double need = estimated_memory_bytes(scene, engines);
  const double limit = memory_limit_bytes();
  if (need <= limit) return {};
  double particles = 0.0;
  for (const EmitterDef& e : scene.emitters) {
    particles += e.mode == EmitterMode::Explode ? e.count : std::ceil(e.rate * std::max(scene.duration, 0.0));
  }
  const long every = sample_every(scene, RunOptions{}.max_sample_states);
  const long steps = scene.steps();
  const double samples = static_cast<double>(steps / every + 1 + (steps % every != 0 ? 1 : 0));   // t = 0, each every-th, the last
  return "needs about " + format_number(std::ceil(need / 1e6)) + " MB (" + std::to_string(scene.bodies.size()) +
         (scene.bodies.size() == 1 ? " body, " : " bodies, ") + format_number(particles) + " particles, " +
         format_number(samples) + " samples of each), more than the limit of " + format_number(std::floor(limit / 1e6)) + " MB (" +
         (g_memory_limit > 0.0 ? "--max-memory" : "half of this machine's memory; --max-memory sets it") + ")";
}

}  // namespace physval
