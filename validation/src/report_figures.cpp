// The report's figures: how each quantity of a results folder is drawn. Every
// engine keeps one colour, dash and marker across all plots; the reference is drawn
// underneath as a thick grey line.
#include "report_figures.hpp"

#include "physval/validation/series_file.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <map>
#include <set>

namespace physval::report_detail {

namespace fs = std::filesystem;

std::string str(const json& j, const char* key, const std::string& fallback) {
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

std::string fmt(double v, const char* spec) {
  char buf[48];
  std::snprintf(buf, sizeof buf, spec, v);
  return buf;
}

namespace {

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

}  // namespace

std::optional<Table> read_table(const fs::path& file) {
  // A series is DIR/series/<scenario>/<label>.bin as `physval run` writes it, or the CSV
  // of `--series-csv` or `physval series-csv` (either path may be given: the .bin is read
  // when there is one, else the .csv).
  fs::path bin = file, csv = file;
  bin.replace_extension(".bin");
  csv.replace_extension(".csv");
  std::error_code ec;
  if (fs::is_regular_file(bin, ec)) {
    std::optional<SeriesTable> s = read_series_binary(bin);
    if (!s) return std::nullopt;
    Table t;
    t.names = std::move(s->names);
    const std::size_t columns = t.names.size();
    t.columns.assign(columns, std::vector<double>(s->rows));
    for (std::size_t k = 0; k < s->rows; ++k) {
      for (std::size_t c = 0; c < columns; ++c) t.columns[c][k] = s->values[k * columns + c];
    }
    return t;
  }
  std::ifstream in(csv);
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

namespace {

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

// Beyond this many samples a time series is drawn as its min/max envelope over
// kEnvelopeBins bins: thousands of oscillations in 1000 pixels otherwise alias into a
// solid fill (orbit_1000_periods' energy).
constexpr std::size_t kEnvelopeBins = 250;
constexpr std::size_t kEnvelopeAbove = 2 * kEnvelopeBins;

// A time series as one curve, or as two (its upper and lower envelope, one legend
// entry) when it is too long to draw point by point.
std::vector<plot::Series> time_curves(const Source& s, const std::vector<std::string>& engines, const std::vector<double>& t,
                                      const std::vector<double>& y) {
  if (t.size() <= kEnvelopeAbove || t.size() != y.size()) return {curve(s, engines, t, y)};
  const double t0 = t.front(), t1 = t.back();
  if (!(t1 > t0)) return {curve(s, engines, t, y)};
  std::vector<double> centre, lo, hi;
  std::size_t k = 0;
  for (std::size_t b = 0; b < kEnvelopeBins; ++b) {
    const double end = t0 + (t1 - t0) * static_cast<double>(b + 1) / kEnvelopeBins;
    double mn = INFINITY, mx = -INFINITY, sum_t = 0.0;
    std::size_t n = 0;
    for (; k < t.size() && (t[k] <= end || b + 1 == kEnvelopeBins); ++k) {
      if (!std::isfinite(y[k])) continue;
      mn = std::min(mn, y[k]);
      mx = std::max(mx, y[k]);
      sum_t += t[k];
      ++n;
    }
    if (n == 0) continue;
    centre.push_back(sum_t / static_cast<double>(n));
    lo.push_back(mn);
    hi.push_back(mx);
  }
  plot::Series upper = curve(s, engines, centre, hi);
  plot::Series lower = curve(s, engines, centre, lo);
  upper.title += " (min and max per " + fmt((t1 - t0) / kEnvelopeBins) + " s)";
  lower.title.clear();
  if (s.engine.empty()) {
    upper.line_width = lower.line_width = 3.0;
  } else {
    lower.style = plot::Style::Lines;
    upper.line_width = lower.line_width = 1.5;
    upper.point_interval = std::max<int>(1, static_cast<int>(centre.size() / 10));
  }
  return {upper, lower};
}

}  // namespace

std::string engine_colour(const std::vector<std::string>& engines, const std::string& engine) {
  const Look l = look_of(engines, engine);
  return plot::palette()[static_cast<std::size_t>(l.colour) % plot::palette().size()];
}

std::string reference_label(const json* ref) {
  std::string label = "reference";
  if (ref != nullptr) {
    if (auto dt = num(*ref, "dt"); dt && *dt > 0.0) label += " (dt " + fmt(*dt) + " s)";
  }
  return label;
}

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
  if (v.duration > 0.0) {   // both panels over the whole run, so their time axes line up
    total.x.min = error.x.min = 0.0;
    total.x.max = error.x.max = v.duration;
  }
  for (const Source& s : v.sources) {
    const auto* t = s.table.column("t");
    const auto* e = s.table.column("energy");
    if (t == nullptr || e == nullptr || e->empty()) continue;
    for (plot::Series& c : time_curves(s, engines, *t, *e)) total.series.push_back(std::move(c));
    std::vector<double> d(e->size());
    for (std::size_t i = 0; i < e->size(); ++i) d[i] = std::abs((*e)[i] - e->front());
    for (plot::Series& c : time_curves(s, engines, *t, d)) error.series.push_back(std::move(c));
  }
  // One legend, under the top panel, where every run has something to draw (the
  // reference's own energy error may be exactly zero: nothing on a log axis).
  total.key = "below center horizontal Left reverse";
  error.key = "off";
  fig.panels = {total, error};
  return fig;
}

plot::Figure momentum_figure(const ScenarioView& v, const std::vector<std::string>& engines) {
  plot::Figure fig;
  fig.title = v.name + ": momentum over time";
  fig.height = 1050;   // the legend under the last panel takes from its height
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
    if (v.duration > 0.0) {   // every panel over the whole run, so their time axes line up
      p.x.min = 0.0;
      p.x.max = v.duration;
    }
    for (const Source& s : v.sources) {
      const auto* t = s.table.column("t");
      const auto* y = s.table.column(part.column);
      if (t == nullptr || y == nullptr) continue;
      for (plot::Series& c : time_curves(s, engines, *t, *y)) p.series.push_back(std::move(c));
    }
    fig.panels.push_back(std::move(p));
  }
  // One legend, under the last panel: the same engines are in every panel.
  for (std::size_t i = 0; i < fig.panels.size(); ++i) {
    fig.panels[i].key = i + 1 == fig.panels.size() ? "below center horizontal Left reverse" : "off";
  }
  return fig;
}

namespace {

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

// Whether a path turns so sharply from sample to sample (over 90 degrees on average)
// that joining its samples would draw chords, not the path: an orbit sampled twice a
// period.
bool sampled_too_coarsely(const std::vector<double>& x, const std::vector<double>& y) {
  double turning = 0.0;
  std::size_t turns = 0;
  double px = NAN, py = NAN;   // the previous step
  for (std::size_t k = 1; k < x.size() && k < y.size(); ++k) {
    const double dx = x[k] - x[k - 1], dy = y[k] - y[k - 1];
    if (!std::isfinite(dx) || !std::isfinite(dy) || (dx == 0.0 && dy == 0.0)) continue;
    if (std::isfinite(px)) {
      turning += std::abs(std::atan2(px * dy - py * dx, px * dx + py * dy));
      ++turns;
    }
    px = dx;
    py = dy;
  }
  return turns >= 50 && turning / static_cast<double>(turns) > 0.5 * M_PI;
}

struct Rect {
  double x0, y0, x1, y1;
};
using Point = std::pair<double, double>;

// The scene's barriers as segments: walls, each surface's polyline, each box's sides.
std::vector<std::pair<Point, Point>> barrier_segments(const json& geometry) {
  std::vector<std::pair<Point, Point>> out;
  auto point = [](const json& p) -> std::optional<Point> {
    if (!p.is_array() || p.size() != 2 || !p[0].is_number() || !p[1].is_number()) return std::nullopt;
    return Point{p[0].get<double>(), p[1].get<double>()};
  };
  for (const json& w : member(geometry, "walls").is_array() ? geometry["walls"] : json::array()) {
    auto a = point(member(w, "from")), b = point(member(w, "to"));
    if (a && b) out.emplace_back(*a, *b);
  }
  for (const json& s : member(geometry, "surfaces").is_array() ? geometry["surfaces"] : json::array()) {
    const json& pts = member(s, "points");
    for (std::size_t i = 1; pts.is_array() && i < pts.size(); ++i) {
      auto a = point(pts[i - 1]), b = point(pts[i]);
      if (a && b) out.emplace_back(*a, *b);
    }
  }
  for (const json& b : member(geometry, "boxes").is_array() ? geometry["boxes"] : json::array()) {
    auto lo = point(member(b, "min")), hi = point(member(b, "max"));
    if (!lo || !hi) continue;
    const Point c[4] = {*lo, {hi->first, lo->second}, *hi, {lo->first, hi->second}};
    for (int i = 0; i < 4; ++i) out.emplace_back(c[i], c[(i + 1) % 4]);
  }
  return out;
}

// Liang-Barsky: the part of segment a-b inside the rectangle, if any.
std::optional<std::pair<Point, Point>> clip_segment(Point a, Point b, const Rect& r) {
  const double dx = b.first - a.first, dy = b.second - a.second;
  double t0 = 0.0, t1 = 1.0;
  const double p[4] = {-dx, dx, -dy, dy};
  const double q[4] = {a.first - r.x0, r.x1 - a.first, a.second - r.y0, r.y1 - a.second};
  for (int i = 0; i < 4; ++i) {
    if (p[i] == 0.0) {
      if (q[i] < 0.0) return std::nullopt;
      continue;
    }
    const double t = q[i] / p[i];
    if (p[i] < 0.0) {
      t0 = std::max(t0, t);
    } else {
      t1 = std::min(t1, t);
    }
  }
  if (t0 > t1) return std::nullopt;
  return std::pair<Point, Point>{{a.first + t0 * dx, a.second + t0 * dy}, {a.first + t1 * dx, a.second + t1 * dy}};
}

}  // namespace

plot::Figure trajectory_figure(const ScenarioView& v, const std::vector<std::string>& engines) {
  plot::Figure fig;
  fig.height = 760;
  plot::Panel p;
  p.x.label = "x (m)";
  p.y.label = "y (m)";
  p.key = "below center horizontal Left reverse maxcols 3";
  p.equal_aspect = true;
  std::set<std::string> labelled;
  std::size_t body_total = 0;
  bool dotted = false;
  for (const Source& s : v.sources) {
    const std::vector<std::string> bodies = s.table.bodies();
    body_total = std::max(body_total, bodies.size());
    for (std::size_t b = 0; b < bodies.size() && b < kMaxTrajectoryBodies; ++b) {
      const auto& x = *s.table.column("x_" + bodies[b]);
      const auto& y = *s.table.column("y_" + bodies[b]);
      plot::Series c = curve(s, engines, x, y);
      if (b > 0) c.title.clear();   // one legend entry per engine
      if (!s.engine.empty()) c.style = plot::Style::Lines;
      if (sampled_too_coarsely(x, y)) {   // chords across an orbit, not a path: dots
        c.style = plot::Style::Points;
        c.point_type = 7;
        c.point_size = s.engine.empty() ? 0.9 : 0.45;
        c.point_interval = 1;
        dotted = true;
      }
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
  // Barriers near the paths (within a quarter of their span and a body's radius) are
  // part of the picture: a wall the ball bounces off, a box it stops short of.
  if (!ex.empty()) {
    double radius = 0.0;
    for (const json& b : member(v.geometry, "bodies").is_array() ? v.geometry["bodies"] : json::array()) {
      radius = std::max(radius, num(b, "radius").value_or(0.0));
    }
    const double grow = 0.25 * std::max(ex.hi - ex.lo, ey.hi - ey.lo) + 1.5 * radius;
    const Rect near{ex.lo - grow, ey.lo - grow, ex.hi + grow, ey.hi + grow};
    for (const auto& [a, b] : barrier_segments(v.geometry)) {
      if (auto c = clip_segment(a, b, near)) {
        ex.add(c->first.first);
        ex.add(c->second.first);
        ey.add(c->first.second);
        ey.add(c->second.second);
      }
    }
  }
  if (!ex.empty()) {
    constexpr double kPlotAspect = 1.5;   // width / height of the plot area, m per m
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
  // The barriers, over the paths, cut to the plotted area (a long floor under a short
  // fall crosses it; both its ends may lie outside).
  if (p.x.min && p.x.max && p.y.min && p.y.max) {
    plot::Series barriers;
    barriers.title = "walls, surfaces, boxes";
    barriers.rgb = "#333333";
    barriers.style = plot::Style::Lines;
    barriers.line_width = 3.0;
    const Rect view{*p.x.min, *p.y.min, *p.x.max, *p.y.max};
    for (const auto& [a, b] : barrier_segments(v.geometry)) {
      if (auto clipped = clip_segment(a, b, view)) {
        barriers.x.insert(barriers.x.end(), {clipped->first.first, clipped->second.first, NAN});
        barriers.y.insert(barriers.y.end(), {clipped->first.second, clipped->second.second, NAN});
      }
    }
    if (!barriers.x.empty()) {
      barriers.x.pop_back();
      barriers.y.pop_back();
      p.series.insert(p.series.begin(), std::move(barriers));   // first: the legend reads barriers, then engines
    }
  }
  // Names that would print over one another (a gas, a stack): only the first of any
  // that start within a label's size of each other keeps its name.
  if (p.x.min && p.x.max && p.y.min && p.y.max) {
    const double dx = 0.08 * (*p.x.max - *p.x.min), dy = 0.05 * (*p.y.max - *p.y.min);
    std::vector<plot::Label> kept;
    for (const plot::Label& l : p.labels) {
      const bool clash = std::any_of(kept.begin(), kept.end(), [&](const plot::Label& k) {
        return std::abs(k.x - l.x) < dx && std::abs(k.y - l.y) < dy;
      });
      if (!clash) kept.push_back(l);
    }
    if (kept.size() < p.labels.size()) {
      p.note = std::to_string(p.labels.size() - kept.size()) + " body names left out where they would overlap";
    }
    p.labels = std::move(kept);
  }
  fig.title = v.name + ": trajectories, engines overlaid on the reference";
  p.title = "each body's path; its name marks the start, a marker the end";
  if (dotted) {
    p.note = (p.note.empty() ? "" : p.note + "; ") +
             std::string("paths sampled too coarsely to join (turning over 90 degrees a sample) are drawn as dots");
  }
  if (body_total > kMaxTrajectoryBodies) {
    p.title += " (first " + std::to_string(kMaxTrajectoryBodies) + " of " + std::to_string(body_total) + " bodies)";
  }
  fig.panels.push_back(std::move(p));
  return fig;
}

namespace {

// Beyond this many contacts in one row, the timeline becomes a contact rate.
constexpr std::size_t kMaxTimelineContacts = 150;

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

}  // namespace

// Rows top to bottom: the reference, then each engine.
std::optional<plot::Figure> contact_figure(const ScenarioView& v, const std::vector<std::string>& engines) {
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
  std::size_t busiest = 0;
  for (const Row& r : rows) busiest = std::max(busiest, r.contacts.size());
  if (busiest > kMaxTimelineContacts) {
    // Too many to tell apart as points (a gas): the rate at which contacts begin.
    double span = v.duration;
    for (const Row& r : rows) {
      for (const ContactPoint& c : r.contacts) span = std::max(span, c.time);
    }
    constexpr int kBins = 50;
    const double width = span / kBins;
    plot::Figure fig;
    fig.title = v.name + ": contact rate";
    plot::Panel p;
    p.title = "contacts begun per second, in " + fmt(width) + " s bins (too many contacts to show one by one)";
    p.x.label = "time (s)";
    p.y.label = "contacts begun per second (1/s)";
    p.key = "outside right top";
    for (const Row& r : rows) {
      std::vector<double> counts(kBins, 0.0);
      for (const ContactPoint& c : r.contacts) {
        const int bin = std::clamp(static_cast<int>(c.time / width), 0, kBins - 1);
        counts[static_cast<std::size_t>(bin)] += 1.0 / width;
      }
      std::vector<double> centres(kBins);
      for (int b = 0; b < kBins; ++b) centres[static_cast<std::size_t>(b)] = (b + 0.5) * width;
      Source source{r.label, r.label == "reference" ? "" : r.label, {}};
      p.series.push_back(curve(source, engines, centres, counts));
    }
    fig.panels.push_back(std::move(p));
    return fig;
  }

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

  // How early or late each engine's contacts are: the n-th contact of a pair against
  // the reference's n-th contact of the same pair (the whole-run timeline hides
  // a step's lateness).
  if (!rows.empty() && rows.front().label == "reference" && !rows.front().contacts.empty() && rows.size() > 1) {
    std::map<std::string, std::vector<double>> reference_times;
    for (const ContactPoint& c : rows.front().contacts) reference_times[c.pair].push_back(c.time);
    plot::Panel e;
    e.title = "contact time minus the reference's (n-th contact of a pair against its n-th)";
    e.x.label = "reference contact time (s)";
    e.y.label = "time error (ms)";
    e.key = "outside right top";
    if (v.duration > 0.0) {
      e.x.min = 0.0;
      e.x.max = v.duration;
    }
    bool any = false;
    for (std::size_t r = 1; r < rows.size(); ++r) {
      plot::Series sr;
      sr.title = rows[r].label;
      sr.style = plot::Style::Points;
      sr.point_size = 1.5;
      const Look l = look_of(engines, rows[r].label);
      sr.color = l.colour;
      sr.point_type = std::vector<int>{7, 5, 9, 13, 11}[static_cast<std::size_t>(l.colour) % 5];
      std::map<std::string, std::size_t> seen;
      for (const ContactPoint& c : rows[r].contacts) {
        const std::size_t nth = seen[c.pair]++;
        const auto it = reference_times.find(c.pair);
        if (it == reference_times.end() || nth >= it->second.size()) continue;
        sr.x.push_back(it->second[nth]);
        sr.y.push_back(1000.0 * (c.time - it->second[nth]));
        any = true;
      }
      e.series.push_back(std::move(sr));
    }
    if (any) {
      fig.height += 330;
      fig.panels.push_back(std::move(e));
    }
  }
  return fig;
}

// Every scenario's position and energy divergence, one point per engine.
plot::Figure overview_figure(const std::vector<ScenarioView>& views, const std::vector<std::string>& engines) {
  // Scenarios are rows (top to bottom in suite order), so their names read
  // horizontally; the two measures side by side share the rows.
  plot::Figure fig;
  fig.title = "all scenarios: how far each engine strays from the reference\n"
              "open marker at the left edge: exactly 0; no marker: not measured";
  fig.width = 1100;
  fig.columns = 2;
  fig.height = std::max(420, 150 + 22 * static_cast<int>(views.size()));
  struct Part {
    const char* metric;
    const char* title;
    const char* unit;
  };
  const Part parts[] = {{"position_divergence", "max position divergence", "position divergence (m, log scale)"},
                        {"energy_divergence", "energy divergence", "energy divergence (relative, log scale)"}};
  const double n = static_cast<double>(views.size());
  auto row = [&](std::size_t i) { return n - static_cast<double>(i); };
  for (std::size_t k = 0; k < 2; ++k) {
    const Part& part = parts[k];
    plot::Panel p;
    p.title = part.title;
    p.x.label = part.unit;
    p.x.log = true;
    p.key = k == 0 ? "off" : "outside right top";
    p.y.min = 0.4;
    p.y.max = n + 0.6;
    // Names once, on the left panel; the right one keeps the rows, unlabelled.
    for (std::size_t i = 0; i < views.size(); ++i) p.y.tics.emplace_back(row(i), k == 0 ? views[i].name : "");
    if (k == 0) {
      // gnuplot's own margin underestimates long names in a proportional font.
      std::size_t longest = 0;
      for (const ScenarioView& v : views) longest = std::max(longest, v.name.size());
      p.left_margin = static_cast<int>(longest) + 3;
    }
    // Exact zeros cannot sit on a log axis: they are drawn as open markers at a fixed
    // place left of every measured value, so "0" and "not measured" look different.
    double smallest = INFINITY;
    for (const ScenarioView& v : views) {
      for (const json* run : v.runs) {
        if (auto m = num(member(*run, "metrics"), part.metric); m && *m > 0.0) smallest = std::min(smallest, *m);
      }
    }
    const double zero_at = std::isfinite(smallest) ? smallest / 30.0 : 1e-16;
    for (const std::string& engine : engines) {
      plot::Series s;
      s.title = engine;
      s.style = plot::Style::Points;
      s.point_size = 1.6;
      const Look l = look_of(engines, engine);
      s.color = l.colour;
      s.point_type = std::vector<int>{7, 5, 9, 13, 11}[static_cast<std::size_t>(l.colour) % 5];
      plot::Series zeros = s;   // the same engine's exact zeros: the open version of its marker
      zeros.title = engine + " = 0";
      zeros.point_type = s.point_type - 1;
      for (std::size_t i = 0; i < views.size(); ++i) {
        for (const json* run : views[i].runs) {
          if (str(*run, "engine") != engine) continue;
          if (auto m = num(member(*run, "metrics"), part.metric)) {
            plot::Series& into = *m == 0.0 ? zeros : s;
            into.x.push_back(*m == 0.0 ? zero_at : *m);
            into.y.push_back(row(i));
          }
        }
      }
      p.series.push_back(std::move(s));
      if (!zeros.x.empty()) p.series.push_back(std::move(zeros));
    }
    fig.panels.push_back(std::move(p));
  }
  return fig;
}

}  // namespace physval::report_detail
