// DIR/report.html from DIR/results.json and DIR/series/: tables and gnuplot pictures.
// Reads only the files (never the in-memory suite), so `physval report DIR` works on
// any results folder, including one from another machine. Fields missing from an
// older or partial results.json leave their cell or plot out rather than failing.
#include "physval/validation/report.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <map>
#include <optional>
#include <set>
#include <sstream>
#include <stdexcept>

#include <nlohmann/json.hpp>

#include "physval/validation/plot.hpp"
#include "physval/validation/results_json.hpp"

namespace physval {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

// ---- reading --------------------------------------------------------------------

std::string str(const json& j, const char* key, const std::string& fallback = "") {
  if (!j.is_object()) return fallback;
  auto it = j.find(key);
  return it != j.end() && it->is_string() ? it->get<std::string>() : fallback;
}

std::optional<double> num(const json& j, const char* key) {
  if (!j.is_object()) return std::nullopt;
  auto it = j.find(key);
  if (it == j.end() || !it->is_number()) return std::nullopt;
  return it->get<double>();
}

const json& member(const json& j, const char* key) {
  static const json null_value;
  if (!j.is_object()) return null_value;
  auto it = j.find(key);
  return it != j.end() ? *it : null_value;
}

// A series CSV: named columns of numbers ("nan" where a body no longer exists).
struct Table {
  std::vector<std::string> names;
  std::vector<std::vector<double>> columns;
  const std::vector<double>* column(const std::string& name) const {
    for (std::size_t i = 0; i < names.size(); ++i) {
      if (names[i] == name) return &columns[i];
    }
    return nullptr;
  }
  std::size_t rows() const { return columns.empty() ? 0 : columns.front().size(); }
  // Body names, from the x_<name> / y_<name> column pairs, in file order.
  std::vector<std::string> bodies() const {
    std::vector<std::string> out;
    for (const std::string& n : names) {
      if (n.size() > 2 && n.compare(0, 2, "x_") == 0 && column("y_" + n.substr(2)) != nullptr) {
        out.push_back(n.substr(2));
      }
    }
    return out;
  }
};

std::vector<std::string> split_csv_line(const std::string& line) {
  std::vector<std::string> out;
  std::string cell;
  for (char c : line) {
    if (c == ',') {
      out.push_back(cell);
      cell.clear();
    } else if (c != '\r') {
      cell += c;
    }
  }
  out.push_back(cell);
  return out;
}

std::optional<Table> read_table(const fs::path& file) {
  std::ifstream in(file);
  if (!in) return std::nullopt;
  std::string line;
  if (!std::getline(in, line)) return std::nullopt;
  Table t;
  t.names = split_csv_line(line);
  t.columns.resize(t.names.size());
  while (std::getline(in, line)) {
    if (line.empty()) continue;
    const std::vector<std::string> cells = split_csv_line(line);
    for (std::size_t i = 0; i < t.names.size(); ++i) {
      double v = NAN;
      if (i < cells.size() && !cells[i].empty()) {
        char* end = nullptr;
        v = std::strtod(cells[i].c_str(), &end);
        if (end == cells[i].c_str()) v = NAN;
      }
      t.columns[i].push_back(v);
    }
  }
  return t;
}

// ---- formatting -----------------------------------------------------------------

std::string html(const std::string& s) {
  std::string out;
  for (char c : s) {
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      default: out += c;
    }
  }
  return out;
}

std::string fmt(double v, const char* spec = "%.3g") {
  char buf[48];
  std::snprintf(buf, sizeof buf, spec, v);
  return buf;
}

// A metric cell: the value, or a grey dash for null / missing ("does not apply").
std::string metric_cell(const json& metrics, const char* key, const char* unit = "") {
  const json& v = member(metrics, key);
  if (v.is_number()) return "<td class=num>" + fmt(v.get<double>()) + unit + "</td>";
  return "<td class=na title=\"does not apply or not measured\">&ndash;</td>";
}

// ---- what a scenario has --------------------------------------------------------

struct Source {
  std::string label;     // legend: engine name, or "reference"
  std::string engine;    // "" for the reference
  Table table;
};

struct ScenarioView {
  std::string name;
  std::vector<const json*> runs;
  const json* reference = nullptr;
  std::vector<Source> sources;   // the reference first (drawn underneath), then engines
  double duration = 0.0;
};

constexpr const char* kReferenceColour = "#a8a8a8";

// Colour and dash of an engine: by its place among all engines of the results, so an
// engine looks the same in every plot of the report.
struct Look {
  int colour = 0;
  int dash = 1;
};
Look look_of(const std::vector<std::string>& engines, const std::string& engine) {
  static constexpr int kDashes[] = {1, 2, 4, 5, 3};
  const auto it = std::find(engines.begin(), engines.end(), engine);
  const std::size_t i = static_cast<std::size_t>(it - engines.begin());
  return {static_cast<int>(i), kDashes[i % 5]};
}

plot::Series curve(const Source& s, const std::vector<std::string>& engines, const std::vector<double>& x,
                   const std::vector<double>& y) {
  plot::Series c;
  c.x = x;
  c.y = y;
  if (s.engine.empty()) {
    c.title = s.label;
    c.rgb = kReferenceColour;
    c.style = plot::Style::Lines;
    c.line_width = 6.0;
  } else {
    const Look l = look_of(engines, s.engine);
    c.title = s.label;
    c.color = l.colour;
    c.dash = l.dash;
    c.style = plot::Style::LinesPoints;
    c.line_width = 2.0;
    c.point_type = std::vector<int>{7, 5, 9, 13, 11}[static_cast<std::size_t>(l.colour) % 5];
    c.point_size = 1.1;
    c.point_interval = std::max<int>(1, static_cast<int>(x.size() / 12));
  }
  return c;
}

std::string reference_label(const json* ref) {
  std::string label = "reference";
  if (ref != nullptr) {
    if (auto dt = num(*ref, "dt"); dt && *dt > 0.0) label += " (core, dt " + fmt(*dt) + " s)";
  }
  return label;
}

// ---- the plots ------------------------------------------------------------------

plot::Figure energy_figure(const ScenarioView& v, const std::vector<std::string>& engines) {
  plot::Figure fig;
  fig.title = v.name + ": energy over time";
  fig.height = 820;
  plot::Panel total;
  total.title = "total energy E = kinetic + potential";
  total.x.label = "time (s)";
  total.y.label = "energy (J)";
  total.key = "outside right top";
  plot::Panel error;
  error.title = "energy error |E(t) - E(0)| of each run against its own start";
  error.x.label = "time (s)";
  error.y.label = "|E(t) - E(0)| (J, log scale)";
  error.y.log = true;
  error.key = "outside right top";
  for (const Source& s : v.sources) {
    const auto* t = s.table.column("t");
    const auto* e = s.table.column("energy");
    if (t == nullptr || e == nullptr || e->empty()) continue;
    total.series.push_back(curve(s, engines, *t, *e));
    std::vector<double> d(e->size());
    for (std::size_t i = 0; i < e->size(); ++i) d[i] = std::abs((*e)[i] - e->front());
    error.series.push_back(curve(s, engines, *t, d));
  }
  fig.panels = {total, error};
  return fig;
}

plot::Figure momentum_figure(const ScenarioView& v, const std::vector<std::string>& engines) {
  plot::Figure fig;
  fig.title = v.name + ": momentum over time";
  fig.height = 950;
  struct Part {
    const char* column;
    const char* title;
    const char* unit;
  };
  const Part parts[] = {{"px", "linear momentum, x component", "p_x (kg m/s)"},
                        {"py", "linear momentum, y component", "p_y (kg m/s)"},
                        {"angular_momentum", "angular momentum about the origin", "L (kg m^2/s)"}};
  for (const Part& part : parts) {
    plot::Panel p;
    p.title = part.title;
    p.x.label = "time (s)";
    p.y.label = part.unit;
    p.key = "outside right top";
    for (const Source& s : v.sources) {
      const auto* t = s.table.column("t");
      const auto* y = s.table.column(part.column);
      if (t != nullptr && y != nullptr) p.series.push_back(curve(s, engines, *t, *y));
    }
    fig.panels.push_back(std::move(p));
  }
  return fig;
}

constexpr std::size_t kMaxTrajectoryBodies = 8;

struct Extent {
  double lo = INFINITY;
  double hi = -INFINITY;
  void add(double v) {
    lo = std::min(lo, v);
    hi = std::max(hi, v);
  }
  bool empty() const { return !(lo <= hi); }
};

plot::Figure trajectory_figure(const ScenarioView& v, const std::vector<std::string>& engines) {
  plot::Figure fig;
  fig.height = 760;
  plot::Panel p;
  p.x.label = "x (m)";
  p.y.label = "y (m)";
  p.key = "outside right top";
  p.equal_aspect = true;
  std::set<std::string> labelled;
  std::size_t body_total = 0;
  for (const Source& s : v.sources) {
    const std::vector<std::string> bodies = s.table.bodies();
    body_total = std::max(body_total, bodies.size());
    for (std::size_t b = 0; b < bodies.size() && b < kMaxTrajectoryBodies; ++b) {
      const auto& x = *s.table.column("x_" + bodies[b]);
      const auto& y = *s.table.column("y_" + bodies[b]);
      plot::Series c = curve(s, engines, x, y);
      if (b > 0) c.title.clear();   // one legend entry per engine
      if (!s.engine.empty()) c.style = plot::Style::Lines;
      p.series.push_back(c);
      // Where the body ends, as a marker: divergence shows as markers apart.
      for (std::size_t k = x.size(); k-- > 0;) {
        if (std::isfinite(x[k]) && std::isfinite(y[k])) {
          plot::Series end = c;
          end.title.clear();
          end.style = plot::Style::Points;
          end.x = {x[k]};
          end.y = {y[k]};
          end.point_size = s.engine.empty() ? 2.4 : 1.5;
          if (s.engine.empty()) end.point_type = 7;
          p.series.push_back(std::move(end));
          break;
        }
      }
      if (labelled.insert(bodies[b]).second) {
        for (std::size_t k = 0; k < x.size(); ++k) {
          if (std::isfinite(x[k]) && std::isfinite(y[k])) {
            p.labels.push_back({x[k], y[k], bodies[b]});
            break;
          }
        }
      }
    }
  }
  // Equal scales on both axes, but the ranges widened to the canvas's shape so a
  // fall (tall and thin) or a head-on collision (wide and flat) fills the picture.
  Extent ex, ey;
  for (const plot::Series& c : p.series) {
    for (std::size_t k = 0; k < c.x.size() && k < c.y.size(); ++k) {
      if (!std::isfinite(c.x[k]) || !std::isfinite(c.y[k])) continue;
      ex.add(c.x[k]);
      ey.add(c.y[k]);
    }
  }
  if (!ex.empty()) {
    constexpr double kPlotAspect = 1.15;   // width / height of the plot area, m per m
    double xs = ex.hi - ex.lo, ys = ey.hi - ey.lo;
    const double floor_span = std::max({xs, ys, 1e-3});
    xs = std::max(xs, 0.05 * floor_span);
    ys = std::max(ys, 0.05 * floor_span);
    if (xs / ys < kPlotAspect) {
      xs = ys * kPlotAspect;
    } else {
      ys = xs / kPlotAspect;
    }
    const double cx = 0.5 * (ex.lo + ex.hi), cy = 0.5 * (ey.lo + ey.hi);
    p.x.min = cx - 0.55 * xs;
    p.x.max = cx + 0.55 * xs;
    p.y.min = cy - 0.55 * ys;
    p.y.max = cy + 0.55 * ys;
  }
  fig.title = v.name + ": trajectories, engines overlaid on the reference";
  p.title = "each body's path; its name marks the start, a marker the end";
  if (body_total > kMaxTrajectoryBodies) {
    p.title += " (first " + std::to_string(kMaxTrajectoryBodies) + " of " + std::to_string(body_total) + " bodies)";
  }
  fig.panels.push_back(std::move(p));
  return fig;
}

struct ContactPoint {
  std::string pair;
  double time = 0.0;
};

std::vector<ContactPoint> contacts_of(const json& holder) {
  std::vector<ContactPoint> out;
  const json& list = member(holder, "contacts");
  if (!list.is_array()) return out;
  for (const json& c : list) {
    const auto t = num(c, "time");
    if (!t) continue;
    std::string a = str(c, "a"), b = str(c, "b");
    if (b < a) std::swap(a, b);
    out.push_back({a + " / " + b, *t});
  }
  return out;
}

// Rows top to bottom: the reference, then each engine.
std::optional<plot::Figure> contact_figure(const ScenarioView& v) {
  struct Row {
    std::string label;
    std::vector<ContactPoint> contacts;
  };
  std::vector<Row> rows;
  if (v.reference != nullptr && member(*v.reference, "contacts").is_array()) {
    rows.push_back({"reference", contacts_of(*v.reference)});
  }
  for (const json* run : v.runs) {
    if (str(*run, "status") != "ok") continue;
    rows.push_back({str(*run, "engine"), contacts_of(*run)});
  }
  std::map<std::string, std::size_t> frequency;
  std::size_t total = 0;
  for (const Row& r : rows) {
    for (const ContactPoint& c : r.contacts) ++frequency[c.pair];
    total += r.contacts.size();
  }
  if (total == 0) return std::nullopt;

  // The most frequent pairs get a colour each; the rest share one.
  constexpr std::size_t kMaxPairs = 8;
  std::vector<std::pair<std::size_t, std::string>> ranked;
  for (const auto& [pair, n] : frequency) ranked.emplace_back(n, pair);
  std::stable_sort(ranked.begin(), ranked.end(), [](const auto& a, const auto& b) { return a.first > b.first; });
  std::map<std::string, std::size_t> pair_series;
  for (std::size_t i = 0; i < ranked.size() && i < kMaxPairs; ++i) pair_series[ranked[i].second] = i;
  const bool others = ranked.size() > kMaxPairs;

  plot::Figure fig;
  fig.title = v.name + ": contact timeline";
  fig.height = std::clamp(260 + 70 * static_cast<int>(rows.size()), 420, 700);
  plot::Panel p;
  p.title = "a point where each engine reported a contact beginning; grey lines: the reference's contact times";
  p.x.label = "time (s)";
  p.y.label = "";
  p.key = "outside right top";
  const double n = static_cast<double>(rows.size());
  p.y.min = -0.6;
  p.y.max = n - 0.4;
  if (v.duration > 0.0) {
    p.x.min = 0.0;
    p.x.max = v.duration;
  }
  for (std::size_t r = 0; r < rows.size(); ++r) p.y.tics.emplace_back(n - 1.0 - static_cast<double>(r), rows[r].label);

  if (!rows.empty() && rows.front().label == "reference" && !rows.front().contacts.empty()) {
    plot::Series guide;
    guide.title = "reference contact times";
    guide.rgb = "#c8c8c8";
    guide.style = plot::Style::Lines;
    guide.line_width = 1.0;
    for (const ContactPoint& c : rows.front().contacts) {
      guide.x.insert(guide.x.end(), {c.time, c.time, NAN});
      guide.y.insert(guide.y.end(), {-0.5, n - 0.5, NAN});
    }
    p.series.push_back(std::move(guide));
  }
  std::vector<plot::Series> by_pair(std::min(ranked.size(), kMaxPairs) + (others ? 1 : 0));
  for (std::size_t i = 0; i < by_pair.size(); ++i) {
    by_pair[i].style = plot::Style::Points;
    by_pair[i].point_size = 1.6;
    by_pair[i].color = static_cast<int>(i);
    by_pair[i].title = i < kMaxPairs && i < ranked.size() ? ranked[i].second : "other pairs";
    if (i == kMaxPairs) by_pair[i].rgb = "#555555";
  }
  for (std::size_t r = 0; r < rows.size(); ++r) {
    const double y = n - 1.0 - static_cast<double>(r);
    for (const ContactPoint& c : rows[r].contacts) {
      auto it = pair_series.find(c.pair);
      plot::Series& s = by_pair[it != pair_series.end() ? it->second : kMaxPairs];
      s.x.push_back(c.time);
      s.y.push_back(y);
    }
  }
  for (plot::Series& s : by_pair) p.series.push_back(std::move(s));
  fig.panels.push_back(std::move(p));
  return fig;
}

// Every scenario's position and energy divergence, one point per engine.
plot::Figure overview_figure(const std::vector<ScenarioView>& views, const std::vector<std::string>& engines) {
  plot::Figure fig;
  fig.title = "all scenarios: how far each engine strays from the reference";
  fig.height = 850;
  struct Part {
    const char* metric;
    const char* title;
    const char* unit;
  };
  const Part parts[] = {{"position_divergence", "max position divergence", "position divergence (m, log scale)"},
                        {"energy_divergence", "energy divergence", "energy divergence (relative, log scale)"}};
  for (const Part& part : parts) {
    plot::Panel p;
    p.title = part.title + std::string(" (missing point: not measured, or exactly zero)");
    p.y.label = part.unit;
    p.y.log = true;
    p.key = "outside right top";
    p.x.min = 0.5;
    p.x.max = static_cast<double>(views.size()) + 0.5;
    p.x.tic_rotation = views.size() > 4 ? 25 : 0;
    for (std::size_t i = 0; i < views.size(); ++i) p.x.tics.emplace_back(static_cast<double>(i + 1), views[i].name);
    for (const std::string& engine : engines) {
      plot::Series s;
      s.title = engine;
      s.style = plot::Style::Points;
      s.point_size = 1.8;
      const Look l = look_of(engines, engine);
      s.color = l.colour;
      s.point_type = std::vector<int>{7, 5, 9, 13, 11}[static_cast<std::size_t>(l.colour) % 5];
      for (std::size_t i = 0; i < views.size(); ++i) {
        for (const json* run : views[i].runs) {
          if (str(*run, "engine") != engine) continue;
          if (auto m = num(member(*run, "metrics"), part.metric)) {
            s.x.push_back(static_cast<double>(i + 1));
            s.y.push_back(*m);
          }
        }
      }
      p.series.push_back(std::move(s));
    }
    fig.panels.push_back(std::move(p));
  }
  return fig;
}

// ---- the page -------------------------------------------------------------------

const char* kStyle = R"(
body { font-family: -apple-system, "Segoe UI", Roboto, "DejaVu Sans", sans-serif; margin: 2em auto;
       max-width: 1100px; padding: 0 1em; color: #222; line-height: 1.45; }
h1 { margin-bottom: 0.2em; }
h2 { border-bottom: 2px solid #ddd; padding-bottom: 0.2em; margin-top: 2.2em; }
.ctx, .note { color: #666; font-size: 0.9em; }
table { border-collapse: collapse; margin: 0.8em 0; font-size: 0.88em; }
th, td { border: 1px solid #ddd; padding: 0.3em 0.55em; text-align: left; vertical-align: top; }
th { background: #f4f4f4; }
td.num { text-align: right; font-variant-numeric: tabular-nums; white-space: nowrap; }
td.na { color: #aaa; text-align: center; }
.ok { color: #176b2c; font-weight: 600; }
.bad { color: #b3261e; font-weight: 600; }
.grey { color: #888; }
.warn { color: #9a6700; font-weight: 600; }
figure { margin: 1.2em 0; }
figure img { max-width: 100%; border: 1px solid #eee; }
figcaption { color: #555; font-size: 0.9em; }
.missing { border: 1px dashed #b3261e; padding: 1em; color: #b3261e; }
details { margin: 0.5em 0; font-size: 0.9em; }
nav a { margin-right: 0.8em; }
)";

std::string status_html(const std::string& status) {
  const char* cls = status == "ok" ? "ok" : (status == "unsupported" ? "grey" : "bad");
  return "<span class=" + std::string(cls) + ">" + html(status.empty() ? "?" : status) + "</span>";
}

// Checks: enforced ones decide pass/fail; others are reported only.
std::string checks_html(const json& run) {
  const json& checks = member(run, "checks");
  if (!checks.is_array() || checks.empty()) return "<td class=na>&ndash;</td>";
  int enforced = 0, failed = 0, reported_failed = 0;
  std::string failures;
  for (const json& c : checks) {
    const bool pass = member(c, "pass").is_boolean() && c["pass"].get<bool>();
    const bool is_enforced = !member(c, "enforced").is_boolean() || c["enforced"].get<bool>();
    if (is_enforced) ++enforced;
    if (pass) continue;
    if (is_enforced) {
      ++failed;
    } else {
      ++reported_failed;
    }
    std::string line = html(str(c, "what"));
    if (auto v = num(c, "value")) {
      line += " " + fmt(*v);
    } else {
      line += " (not measured)";
    }
    if (auto l = num(c, "limit")) line += " &gt; " + fmt(*l);
    if (!is_enforced) line += " <span class=grey>(gate, not enforced)</span>";
    failures += "<br>" + line;
  }
  std::string head;
  if (failed > 0) {
    head = "<span class=bad>" + std::to_string(failed) + " of " + std::to_string(enforced) + " failed</span>";
  } else {
    head = "<span class=ok>" + std::to_string(enforced) + " passed</span>";
    if (reported_failed > 0) head += " <span class=warn>(" + std::to_string(reported_failed) + " gate limits exceeded)</span>";
  }
  return "<td>" + head + failures + "</td>";
}

std::string metrics_table(const ScenarioView& v) {
  std::ostringstream os;
  os << "<table><tr><th>engine</th><th>status</th><th>energy drift</th><th>momentum drift</th>"
        "<th>angular momentum drift</th><th>energy divergence</th><th>momentum divergence</th>"
        "<th>position divergence</th><th>first contact</th><th>contact time error</th><th>missed / extra contacts</th>"
        "<th>wall time</th><th>checks</th></tr>\n";
  for (const json* run : v.runs) {
    const json& m = member(*run, "metrics");
    const std::string status = str(*run, "status");
    os << "<tr><td><b>" << html(str(*run, "engine")) << "</b>";
    const std::string version = str(*run, "engine_version");
    if (!version.empty()) os << "<br><span class=grey>" << html(version) << " " << html(str(*run, "precision")) << "</span>";
    os << "</td><td>" << status_html(status);
    const std::string reason = str(*run, "reason");
    if (!reason.empty()) os << "<br><span class=grey>" << html(reason) << "</span>";
    os << "</td>" << metric_cell(m, "energy_drift") << metric_cell(m, "linear_momentum_drift")
       << metric_cell(m, "angular_momentum_drift") << metric_cell(m, "energy_divergence")
       << metric_cell(m, "linear_momentum_divergence") << metric_cell(m, "position_divergence", " m")
       << metric_cell(m, "first_contact_time", " s") << metric_cell(m, "contact_time_error", " s");
    const auto missed = num(m, "missed_contacts");
    const auto extra = num(m, "extra_contacts");
    if (missed || extra) {
      os << "<td class=num>" << (missed ? fmt(*missed, "%.0f") : "&ndash;") << " / " << (extra ? fmt(*extra, "%.0f") : "&ndash;")
         << "</td>";
    } else {
      os << "<td class=na>&ndash;</td>";
    }
    if (auto w = num(*run, "wall_seconds"); w && status != "unsupported") {
      os << "<td class=num>" << fmt(*w) << " s</td>";
    } else {
      os << "<td class=na>&ndash;</td>";
    }
    os << checks_html(*run) << "</tr>\n";
  }
  os << "</table>\n";
  return os.str();
}

std::string settings_html(const ScenarioView& v) {
  std::ostringstream os;
  bool any = false;
  os << "<details><summary>engine settings and limits hit</summary><table><tr><th>engine</th><th>dt</th>"
        "<th>settings</th><th>limits hit</th></tr>\n";
  for (const json* run : v.runs) {
    const json& settings = member(*run, "settings");
    const json& limits = member(*run, "limits_hit");
    if (str(*run, "status") == "unsupported" || (!settings.is_object() && !limits.is_array())) continue;
    any = true;
    os << "<tr><td>" << html(str(*run, "engine")) << "</td><td class=num>";
    if (auto dt = num(*run, "dt")) os << fmt(*dt) << " s";
    os << "</td><td>";
    if (settings.is_object()) {
      for (const auto& [k, val] : settings.items()) {
        os << html(k) << " = " << html(val.is_string() ? val.get<std::string>() : val.dump()) << "<br>";
      }
    }
    os << "</td><td>";
    if (limits.is_array()) {
      for (const json& l : limits) os << html(l.is_string() ? l.get<std::string>() : l.dump()) << "<br>";
    }
    os << "</td></tr>\n";
  }
  os << "</table></details>\n";
  return any ? os.str() : std::string();
}

struct Drawn {
  std::string file;        // relative to the results folder: plots/<name>.png
  std::string caption;
  std::string alt;
  std::string error;       // why it is missing ("" when drawn)
};

std::string figure_html(const Drawn& d) {
  if (!d.error.empty()) {
    return "<figure><div class=missing>" + html(d.alt) + " could not be drawn: " + html(d.error) + "</div></figure>\n";
  }
  return "<figure><img src=\"" + html(d.file) + "\" alt=\"" + html(d.alt) + "\" loading=lazy><figcaption>" +
         html(d.caption) + "</figcaption></figure>\n";
}

}  // namespace

std::string report_file_name(const std::string& name) {
  std::string out;
  for (char c : name) out += (std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-') ? c : '_';
  return out;
}

void write_report(const fs::path& dir, const Progress& progress) {
  auto say = [&](const std::string& line) {
    if (progress) progress(line);
  };
  const fs::path results_file = dir / "results.json";
  std::ifstream in(results_file);
  if (!in) throw std::runtime_error("no results to report: cannot read " + results_file.string());
  json results;
  try {
    in >> results;
  } catch (const std::exception& e) {
    throw std::runtime_error(results_file.string() + " is not valid JSON: " + e.what());
  }
  const json& runs = member(results, "runs");
  if (!runs.is_array()) throw std::runtime_error(results_file.string() + " has no \"runs\" array");

  std::vector<std::string> notes;
  // Engines in a fixed order: the context's list, then any others as they appear.
  std::vector<std::string> engines;
  const json& context = member(results, "context");
  if (member(context, "engines").is_array()) {
    for (const json& e : context["engines"]) {
      if (!str(e, "name").empty()) engines.push_back(str(e, "name"));
    }
  }
  std::vector<ScenarioView> views;
  auto view_of = [&](const std::string& name) -> ScenarioView& {
    for (ScenarioView& v : views) {
      if (v.name == name) return v;
    }
    views.push_back(ScenarioView{});
    views.back().name = name;
    return views.back();
  };
  for (const json& run : runs) {
    ScenarioView& v = view_of(str(run, "scenario", "(unnamed)"));
    v.runs.push_back(&run);
    const std::string engine = str(run, "engine");
    if (!engine.empty() && std::find(engines.begin(), engines.end(), engine) == engines.end()) engines.push_back(engine);
    if (auto dt = num(run, "dt"), steps = num(run, "steps"); dt && steps) v.duration = std::max(v.duration, *dt * *steps);
  }
  const json& references = member(results, "references");
  if (references.is_array()) {
    for (const json& ref : references) view_of(str(ref, "scenario", "(unnamed)")).reference = &ref;
  } else {
    notes.push_back("results.json has no \"references\": reference contacts and status are not shown.");
  }
  // Only engines that actually ran somewhere get a legend entry in the overview.
  std::vector<std::string> ran;
  for (const std::string& e : engines) {
    for (const json& run : runs) {
      if (str(run, "engine") == e && str(run, "status") != "unsupported") {
        ran.push_back(e);
        break;
      }
    }
  }

  for (ScenarioView& v : views) {
    const fs::path series_dir = dir / "series" / report_file_name(v.name);
    if (auto t = read_table(series_dir / "reference.csv")) v.sources.push_back({reference_label(v.reference), "", std::move(*t)});
    for (const json* run : v.runs) {
      const std::string engine = str(*run, "engine");
      if (engine.empty()) continue;
      if (auto t = read_table(series_dir / (report_file_name(engine) + ".csv"))) v.sources.push_back({engine, engine, std::move(*t)});
    }
  }

  const fs::path plots = dir / "plots";
  std::vector<std::string> failures;
  auto draw = [&](const plot::Figure& fig, const std::string& name, const std::string& alt,
                  const std::string& caption) {
    Drawn d{"plots/" + name + ".png", caption, alt, ""};
    try {
      plot::render_png(fig, plots / (name + ".png"));
    } catch (const std::exception& e) {
      d.error = e.what();
      failures.push_back(name + ".png: " + d.error);
    }
    return d;
  };

  std::ostringstream page;
  page << "<!doctype html>\n<html lang=en><head><meta charset=utf-8><title>physval report</title>"
       << "<meta name=viewport content=\"width=device-width, initial-scale=1\"><style>" << kStyle
       << "</style></head><body>\n<h1>physval report</h1>\n<p class=ctx>";
  {
    std::vector<std::string> parts;
    const std::string version = str(context, "physval_version", str(results, "physval_version"));
    if (!version.empty()) parts.push_back("physval " + html(version));
    for (const char* key : {"date", "host", "build_type", "compiler"}) {
      if (!str(context, key).empty()) parts.push_back(html(str(context, key)));
    }
    if (member(context, "engines").is_array()) {
      std::string list;
      for (const json& e : context["engines"]) {
        if (!list.empty()) list += ", ";
        list += html(str(e, "name") + " " + str(e, "version") + " (" + str(e, "precision") + ")");
      }
      parts.push_back("engines: " + list);
    }
    for (std::size_t i = 0; i < parts.size(); ++i) page << (i ? " &middot; " : "") << parts[i];
  }
  page << "</p>\n";
  if (member(results, "gates_enforced").is_boolean()) {
    page << "<p class=note>" << (results["gates_enforced"].get<bool>() ? "Gate limits were enforced (physval gate)."
                                                                       : "Gate limits were reported, not enforced (physval run).")
         << "</p>\n";
  }
  for (const std::string& n : notes) page << "<p class=note>Note: " << html(n) << "</p>\n";

  // Summary: scenario x engine.
  page << "<h2>Summary</h2>\n<nav>";
  for (const ScenarioView& v : views) page << "<a href=\"#" << html(report_file_name(v.name)) << "\">" << html(v.name) << "</a> ";
  page << "</nav>\n<table><tr><th>scenario</th>";
  for (const std::string& e : engines) page << "<th>" << html(e) << "</th>";
  page << "</tr>\n";
  for (const ScenarioView& v : views) {
    page << "<tr><td><a href=\"#" << html(report_file_name(v.name)) << "\">" << html(v.name) << "</a></td>";
    for (const std::string& e : engines) {
      const json* run = nullptr;
      for (const json* r : v.runs) {
        if (str(*r, "engine") == e) run = r;
      }
      if (run == nullptr) {
        page << "<td class=na>&ndash;</td>";
        continue;
      }
      const std::string status = str(*run, "status");
      bool failed = false;
      if (member(*run, "checks").is_array()) {
        for (const json& c : (*run)["checks"]) {
          const bool enforced = !member(c, "enforced").is_boolean() || c["enforced"].get<bool>();
          if (enforced && !(member(c, "pass").is_boolean() && c["pass"].get<bool>())) failed = true;
        }
      }
      page << "<td>" << status_html(status);
      if (status == "ok") page << (failed ? " <span class=bad>checks failed</span>" : " <span class=ok>&#10003;</span>");
      page << "</td>";
    }
    page << "</tr>\n";
  }
  page << "</table>\n";
  const bool any_divergence = std::any_of(runs.begin(), runs.end(), [](const json& run) {
    for (const char* m : {"position_divergence", "energy_divergence"}) {
      if (auto v = num(member(run, "metrics"), m); v && *v > 0.0) return true;
    }
    return false;
  });
  if (!any_divergence) {
    page << "<p class=note>No run has a measured divergence from a reference (none was available or converged), "
            "so there is no overview plot.</p>\n";
  } else {
    say("report: overview plot");
    page << figure_html(draw(overview_figure(views, ran), "overview", "divergence of every scenario and engine",
                             "Each engine's largest position divergence and its energy divergence from the scenario's "
                             "reference, per scenario. Log scale: one grid line is a factor of ten."));
  }

  std::size_t index = 0;
  for (const ScenarioView& v : views) {
    ++index;
    say("report: plots for " + v.name + " (" + std::to_string(index) + "/" + std::to_string(views.size()) + ")");
    const std::string base = report_file_name(v.name);
    page << "<h2 id=\"" << html(base) << "\">" << html(v.name) << "</h2>\n";
    if (v.reference != nullptr) {
      const json& ref = *v.reference;
      const bool available = member(ref, "available").is_boolean() && ref["available"].get<bool>();
      const bool converged = member(ref, "converged").is_boolean() && ref["converged"].get<bool>();
      page << "<p class=note>Reference: ";
      if (!available) {
        page << "<span class=warn>none</span>";
      } else {
        page << "core";
        if (auto dt = num(ref, "dt")) page << " at dt " << fmt(*dt) << " s";
        page << (converged ? ", <span class=ok>converged</span>" : ", <span class=warn>not converged</span>");
        if (auto ce = num(ref, "convergence_error")) page << " (two resolutions agree to " << fmt(*ce) << " m)";
      }
      if (!str(ref, "reason").empty()) page << " &mdash; " << html(str(ref, "reason"));
      page << "</p>\n";
    }
    page << metrics_table(v) << settings_html(v);
    page << "<p class=note>Drifts are relative to the run's own start; divergences are against the reference. "
            "&ndash; means the quantity is not conserved by this scene or could not be measured.</p>\n";

    if (v.sources.empty()) {
      page << "<p class=note>No time series in series/" << html(base) << "/: nothing to plot.</p>\n";
      continue;
    }
    page << figure_html(draw(energy_figure(v, engines), base + "_energy", v.name + " energy over time",
                             "Top: total energy of each engine's run and of the reference. Bottom: how far each run's "
                             "energy has moved from its starting value, log scale (a straight rising line is a steady "
                             "drift; gaps are exact zeros)."));
    page << figure_html(draw(momentum_figure(v, engines), base + "_momentum", v.name + " momentum over time",
                             "Linear momentum (x and y) and angular momentum about the origin, per engine. Walls, "
                             "uniform gravity and drag change momentum; compare the engines with the reference."));
    page << figure_html(draw(trajectory_figure(v, engines), base + "_trajectories", v.name + " trajectories",
                             "The path of each body in each engine, drawn over the reference's (thick grey). Equal "
                             "scales on both axes."));
    if (auto contacts = contact_figure(v)) {
      page << figure_html(draw(*contacts, base + "_contacts", v.name + " contact timeline",
                               "One row per engine: where it reported a contact beginning, coloured by the pair in "
                               "contact. Grey vertical lines: the reference's contact times."));
    } else {
      page << "<p class=note>No contacts in this scenario (reference and engines).</p>\n";
    }
  }
  page << "<p class=ctx>Written by physval report from " << html(results_file.filename().string())
       << ". Plots drawn with gnuplot.</p>\n</body></html>\n";
  write_file_atomically(dir / "report.html", page.str());

  if (!failures.empty()) {
    std::string message = "report written to " + (dir / "report.html").string() + ", but " +
                          std::to_string(failures.size()) + " plot(s) could not be drawn:";
    for (const std::string& f : failures) message += "\n  " + f;
    throw plot::PlotError(message);
  }
}

}  // namespace physval
