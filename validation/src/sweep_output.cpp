// What a sweep tells its reader: orders of convergence and the Pareto front, the
// terminal table, sweep.csv and sweep.json, and the two plots (speed against error,
// error against step size).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iomanip>
#include <map>
#include <set>
#include <sstream>

#include "physval/validation/plot.hpp"
#include "physval/validation/results_json.hpp"
#include "physval/validation/sweep.hpp"

namespace physval {

namespace {

std::string series_name(const std::string& engine, const std::string& setting) {
  return setting.empty() ? engine : engine + " " + setting;
}

// A setting as a legend shows it: "integrator=rk4 collision=exact" -> "rk4, exact";
// "velocity_iterations=4 position_iterations=3" -> "4 velocity + 3 position iterations".
std::string display_setting(const std::string& setting) {
  std::istringstream in(setting);
  std::string values, iterations;
  for (std::string token; in >> token;) {
    const auto eq = token.find('=');
    if (eq == std::string::npos) {
      values += (values.empty() ? "" : ", ") + token;
      continue;
    }
    const std::string key = token.substr(0, eq), value = token.substr(eq + 1);
    const std::string suffix = "_iterations";
    if (key.size() > suffix.size() && key.compare(key.size() - suffix.size(), suffix.size(), suffix) == 0) {
      iterations += (iterations.empty() ? "" : " + ") + value + " " + key.substr(0, key.size() - suffix.size());
    } else {
      values += (values.empty() ? "" : ", ") + value;
    }
  }
  if (!iterations.empty()) values += (values.empty() ? "" : ", ") + iterations + " iterations";
  return values;
}

std::string legend_name(const std::string& engine, const std::string& setting) {
  const std::string shown = display_setting(setting);
  return shown.empty() ? engine : engine + " " + shown;
}

// One legend column under the plot (the labels are long; a column keeps them whole).
std::string legend_below(std::size_t entries) {
  return "below center vertical maxrows " + std::to_string(std::max<std::size_t>(1, entries)) + " Left reverse";
}

// Room for the plot plus a legend row per entry.
int figure_height(std::size_t entries) { return 560 + 18 * static_cast<int>(entries); }

std::string sci(std::optional<double> v, const char* unit = "") {
  if (!v) return "-";
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.3g%s", *v, unit);
  return buf;
}

bool usable(const SweepPoint& p) { return p.status == RunStatus::Ok && p.repetitions > 0; }

std::string csv_field(const std::string& s) {
  if (s.find_first_of(",\"\n") == std::string::npos) return s;
  std::string out = "\"";
  for (char c : s) {
    if (c == '"') out += '"';
    out += c;
  }
  return out + "\"";
}

std::string csv_number(double v) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.10g", v);
  return buf;
}

std::string csv_number(std::optional<double> v) { return v ? csv_number(*v) : std::string(); }

nlohmann::json json_number(std::optional<double> v) {
  if (!v || !std::isfinite(*v)) return nullptr;
  return *v;
}

nlohmann::json fit_json(const LogLogFit& f) {
  return {{"order", json_number(f.slope)}, {"points", f.points}, {"r_squared", f.slope ? nlohmann::json(f.r_squared) : nlohmann::json(nullptr)}};
}

// Series in the order of their first point, each with its points' indices.
std::vector<std::pair<std::string, std::vector<std::size_t>>> groups_of(const SweepResult& r) {
  std::vector<std::pair<std::string, std::vector<std::size_t>>> groups;
  std::map<std::string, std::size_t> index;
  for (std::size_t i = 0; i < r.points.size(); ++i) {
    const std::string key = series_name(r.points[i].engine, r.points[i].setting);
    auto [it, fresh] = index.emplace(key, groups.size());
    if (fresh) groups.push_back({key, {}});
    groups[it->second].second.push_back(i);
  }
  return groups;
}

// How a line looks: its colour says the engine (in order of appearance, as in the
// report), its dash and marker the engine's setting (in order of appearance), so four
// Box2D and four Bullet settings are eight lines told apart at a glance.
void style_line(const SweepResult& r, const std::string& engine, const std::string& setting, plot::Series& s) {
  std::vector<std::string> engines;
  std::vector<std::string> settings;   // this engine's
  for (const SweepPoint& p : r.points) {
    if (std::find(engines.begin(), engines.end(), p.engine) == engines.end()) engines.push_back(p.engine);
    if (p.engine == engine && std::find(settings.begin(), settings.end(), p.setting) == settings.end()) {
      settings.push_back(p.setting);
    }
  }
  const auto e = static_cast<std::size_t>(std::find(engines.begin(), engines.end(), engine) - engines.begin());
  const auto k = static_cast<std::size_t>(std::find(settings.begin(), settings.end(), setting) - settings.begin());
  static constexpr int kDashes[] = {1, 2, 4, 5, 3};
  static constexpr int kPoints[] = {7, 5, 9, 13, 11, 3};
  s.color = static_cast<int>(e);
  s.dash = kDashes[k % 5];
  s.point_type = kPoints[k % 6];
  s.point_size = 1.3;
}

std::string order_text(const LogLogFit& f) {
  if (!f.slope) return "n/a";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.2f", *f.slope);
  return buf;
}

// Below this, the errors do not follow a power of dt (contact timing, round-off):
// the slope is reported but flagged.
constexpr double kGoodFit = 0.9;

// Position errors at or below this (m) are round-off, not truncation error.
constexpr double kRoundOff = 1e-9;

plot::Figure speed_vs_error_figure(const SweepResult& r) {
  plot::Figure fig;
  fig.height = figure_height(groups_of(r).size() + 1);
  fig.title = r.scenario + ": speed against accuracy";
  plot::Panel panel;
  panel.title = "each point one step size (coarse dt left, fine dt right); circled: the Pareto front";
  panel.x.label = "wall-clock time per simulated second (s/s, log scale)";
  panel.y.label = "max position error against the reference (m, log scale)";
  panel.x.log = true;
  panel.y.log = true;
  panel.key = legend_below(groups_of(r).size() + 1);
  const auto groups = groups_of(r);
  // The step sizes are named along the line whose points spread the most (in decades
  // of error and time), where their labels do not pile up.
  std::size_t labelled_group = 0;
  double widest = -1.0;
  for (std::size_t g = 0; g < groups.size(); ++g) {
    double xlo = INFINITY, xhi = 0.0, ylo = INFINITY, yhi = 0.0;
    for (std::size_t i : groups[g].second) {
      const SweepPoint& p = r.points[i];
      if (!usable(p) || !p.position_error || !(*p.position_error > 0.0) || !(p.wall_per_sim_median > 0.0)) continue;
      xlo = std::min(xlo, p.wall_per_sim_median);
      xhi = std::max(xhi, p.wall_per_sim_median);
      ylo = std::min(ylo, *p.position_error);
      yhi = std::max(yhi, *p.position_error);
    }
    const double spread = xhi > 0.0 ? std::log10(xhi / xlo) + std::log10(yhi / ylo) : -1.0;
    if (spread > widest) {
      widest = spread;
      labelled_group = g;
    }
  }
  std::set<double> labelled_dts;
  for (std::size_t g = 0; g < groups.size(); ++g) {
    plot::Series s;
    const SweepPoint& first = r.points[groups[g].second.front()];
    s.title = legend_name(first.engine, first.setting);
    style_line(r, first.engine, first.setting, s);
    for (std::size_t i : groups[g].second) {
      const SweepPoint& p = r.points[i];
      if (!usable(p) || !p.position_error) continue;
      s.x.push_back(p.wall_per_sim_median);
      s.y.push_back(*p.position_error);
      if (g == labelled_group && labelled_dts.insert(p.dt).second) {
        char text[48];
        std::snprintf(text, sizeof text, "dt %.3g", p.dt);
        panel.labels.push_back({p.wall_per_sim_median, *p.position_error, text});
      }
    }
    panel.series.push_back(std::move(s));
  }
  plot::Series front;
  front.title = "Pareto front (nothing is faster and more accurate)";
  front.rgb = "#000000";
  front.dash = 3;
  front.line_width = 1.2;
  front.point_type = 6;   // open circle, drawn around the point it marks
  front.point_size = 2.6;
  std::vector<std::pair<double, double>> on_front;
  for (const SweepPoint& p : r.points) {
    if (p.pareto) on_front.emplace_back(p.wall_per_sim_median, *p.position_error);
  }
  std::sort(on_front.begin(), on_front.end());
  for (const auto& [x, y] : on_front) {
    front.x.push_back(x);
    front.y.push_back(y);
  }
  panel.series.push_back(std::move(front));
  fig.panels.push_back(std::move(panel));
  return fig;
}

plot::Figure error_vs_dt_figure(const SweepResult& r) {
  plot::Figure fig;
  fig.height = figure_height(groups_of(r).size());
  fig.title = r.scenario + ": error against step size";
  plot::Panel panel;
  panel.title = "legend: observed order of convergence (slope of log error against log dt)";
  panel.x.label = "step size dt (s, log scale)";
  panel.y.label = "max position error against the reference (m, log scale)";
  panel.x.log = true;
  panel.y.log = true;
  panel.key = legend_below(groups_of(r).size());
  const auto groups = groups_of(r);
  for (std::size_t g = 0; g < groups.size(); ++g) {
    const SweepPoint& first = r.points[groups[g].second.front()];
    plot::Series s;
    const auto order = std::find_if(r.orders.begin(), r.orders.end(), [&](const ConvergenceOrder& o) {
      return o.engine == first.engine && o.setting == first.setting;
    });
    std::string order_note = "order n/a";
    if (order != r.orders.end() && order->exact_to_round_off) {
      order_note = "exact to round-off";
    } else if (order != r.orders.end() && order->position.slope) {
      char fit[64];
      if (order->position.r_squared < kGoodFit) {
        std::snprintf(fit, sizeof fit, "no clear order (R\u00b2 %.2f)", order->position.r_squared);
      } else {
        std::snprintf(fit, sizeof fit, "order %.2f", *order->position.slope);
      }
      order_note = fit;
    }
    s.title = legend_name(first.engine, first.setting) + ": " + order_note;
    style_line(r, first.engine, first.setting, s);
    for (std::size_t i : groups[g].second) {
      const SweepPoint& p = r.points[i];
      if (p.status != RunStatus::Ok || !p.position_error) continue;
      s.x.push_back(p.dt);
      s.y.push_back(*p.position_error);
    }
    panel.series.push_back(std::move(s));
  }
  fig.panels.push_back(std::move(panel));
  return fig;
}

}  // namespace

LogLogFit fit_log_log(const std::vector<double>& x, const std::vector<std::optional<double>>& y) {
  std::vector<double> lx, ly;
  const std::size_t n = std::min(x.size(), y.size());
  for (std::size_t i = 0; i < n; ++i) {
    if (!y[i] || !std::isfinite(x[i]) || !std::isfinite(*y[i]) || x[i] <= 0.0 || *y[i] <= 0.0) continue;
    lx.push_back(std::log10(x[i]));
    ly.push_back(std::log10(*y[i]));
  }
  LogLogFit fit;
  fit.points = static_cast<int>(lx.size());
  if (lx.size() < 2) return fit;
  const double m = static_cast<double>(lx.size());
  double mx = 0.0, my = 0.0;
  for (std::size_t i = 0; i < lx.size(); ++i) {
    mx += lx[i];
    my += ly[i];
  }
  mx /= m;
  my /= m;
  double sxx = 0.0, sxy = 0.0, syy = 0.0;
  for (std::size_t i = 0; i < lx.size(); ++i) {
    sxx += (lx[i] - mx) * (lx[i] - mx);
    sxy += (lx[i] - mx) * (ly[i] - my);
    syy += (ly[i] - my) * (ly[i] - my);
  }
  if (sxx <= 0.0) return fit;   // one step size only: no slope
  const double slope = sxy / sxx;
  fit.slope = slope;
  fit.intercept = my - slope * mx;
  double ss_res = 0.0;
  for (std::size_t i = 0; i < lx.size(); ++i) {
    const double e = ly[i] - (fit.intercept + slope * lx[i]);
    ss_res += e * e;
  }
  fit.r_squared = syy > 0.0 ? 1.0 - ss_res / syy : 1.0;
  return fit;
}

void analyse_sweep(SweepResult& result) {
  result.orders.clear();
  for (const auto& [name, indices] : groups_of(result)) {
    ConvergenceOrder o;
    o.engine = result.points[indices.front()].engine;
    o.setting = result.points[indices.front()].setting;
    std::vector<double> dts;
    std::vector<std::optional<double>> pos, energy;
    for (std::size_t i : indices) {
      const SweepPoint& p = result.points[i];
      if (p.status != RunStatus::Ok) continue;
      dts.push_back(p.dt);
      pos.push_back(p.position_error);
      energy.push_back(p.energy_error);
    }
    for (std::size_t i : indices) {
      if (o.engine_settings.empty()) o.engine_settings = result.points[i].engine_settings;
    }
    o.position = fit_log_log(dts, pos);
    o.exact_to_round_off = o.position.points > 0 && std::all_of(pos.begin(), pos.end(), [](std::optional<double> e) {
      return !e || *e <= kRoundOff;
    });
    o.energy = fit_log_log(dts, energy);
    result.orders.push_back(std::move(o));
  }

  // The front: points no other point beats on both speed and position error.
  auto candidate = [](const SweepPoint& p) {
    return usable(p) && p.position_error && *p.position_error > 0.0 && p.wall_per_sim_median > 0.0;
  };
  for (SweepPoint& p : result.points) {
    p.pareto = false;
    if (!candidate(p)) continue;
    bool dominated = false;
    for (const SweepPoint& q : result.points) {
      if (&q == &p || !candidate(q)) continue;
      const bool no_worse = q.wall_per_sim_median <= p.wall_per_sim_median && *q.position_error <= *p.position_error;
      const bool better = q.wall_per_sim_median < p.wall_per_sim_median || *q.position_error < *p.position_error;
      if (no_worse && better) {
        dominated = true;
        break;
      }
    }
    p.pareto = !dominated;
  }
}

std::string dt_label(double dt) {
  if (dt > 0.0 && std::isfinite(dt)) {
    const double n = 1.0 / dt;
    const double whole = std::round(n);
    if (whole >= 1.0 && std::abs(n - whole) <= 1e-9 * whole) {
      if (whole == 1.0) return "1";
      char buf[32];
      std::snprintf(buf, sizeof buf, "1/%.0f", whole);
      return buf;
    }
  }
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", dt);
  return buf;
}

void print_sweep_table(std::ostream& os, const SweepResult& r) {
  os << "sweep: " << r.scenario << ", " << r.duration << " s simulated per run; reference: ";
  if (r.reference_available) {
    os << "dt " << dt_label(r.reference_dt) << (r.reference_converged ? " (converged)" : " (NOT converged)");
  } else {
    os << "none";
  }
  os << "\n";

  const std::vector<std::string> header = {"engine", "setting", "dt", "steps", "wall s/sim s", "spread",
                                           "position err (m)", "energy err", "contact err (s)", "front", "status"};
  std::vector<std::vector<std::string>> rows;
  for (const SweepPoint& p : r.points) {
    const bool timed = usable(p);
    std::string spread = "-";
    if (timed) {
      spread = std::to_string(static_cast<int>(std::lround(p.spread * 100))) + "%" + (p.spread_warning ? " !" : "");
    }
    std::string status = run_status_name(p.status);
    if (!p.reason.empty()) status += ": " + p.reason;
    if (p.status == RunStatus::Ok && !p.checks_failed.empty()) {
      status += ", missed " + std::to_string(p.checks_failed.size()) + " check" + (p.checks_failed.size() == 1 ? "" : "s") +
                " (" + p.checks_failed.front() + (p.checks_failed.size() > 1 ? ", ..." : "") + ")";
    }
    rows.push_back({p.engine, p.setting.empty() ? "-" : display_setting(p.setting), dt_label(p.dt), std::to_string(p.steps),
                    timed ? sci(p.wall_per_sim_median) : "-", spread, sci(p.position_error), sci(p.energy_error),
                    sci(p.contact_time_error), p.pareto ? "*" : "", status});
  }
  std::vector<std::size_t> width(header.size());
  for (std::size_t c = 0; c < header.size(); ++c) {
    width[c] = header[c].size();
    for (const auto& row : rows) width[c] = std::max(width[c], row[c].size());
  }
  auto print_row = [&](const std::vector<std::string>& row) {
    std::string line;
    for (std::size_t c = 0; c < row.size(); ++c) {
      std::string cell = row[c];
      if (c + 1 < row.size()) cell.resize(width[c], ' ');
      line += cell;
      if (c + 1 < row.size()) line += "  ";
    }
    while (!line.empty() && line.back() == ' ') line.pop_back();
    os << line << "\n";
  };
  print_row(header);
  for (const auto& row : rows) print_row(row);

  if (!r.orders.empty()) {
    os << "\nobserved order of convergence (least-squares slope of log error against log dt):\n";
    std::size_t name_width = 0;
    for (const ConvergenceOrder& o : r.orders) name_width = std::max(name_width, legend_name(o.engine, o.setting).size());
    for (const ConvergenceOrder& o : r.orders) {
      std::string name = legend_name(o.engine, o.setting);
      name.resize(name_width, ' ');
      os << "  " << name << "  position " << order_text(o.position);
      if (o.exact_to_round_off) {
        os << " (exact to round-off: every error below 1e-9 m)";
      } else if (o.position.slope) {
        char buf[48];
        std::snprintf(buf, sizeof buf, " (%d points, R^2 %.3f)", o.position.points, o.position.r_squared);
        os << buf << (o.position.r_squared < kGoodFit ? " no clear order" : "");
      }
      os << "  energy " << order_text(o.energy) << "\n";
    }
  }
  if (std::any_of(r.points.begin(), r.points.end(), [](const SweepPoint& p) { return p.pareto; })) {
    os << "\n* on the Pareto front: no other point is both faster and more accurate (position error)\n";
  }
  for (const std::string& note : r.notes) os << "note: " << note << "\n";
}

std::string sweep_to_csv(const SweepResult& r) {
  std::ostringstream os;
  os << "scenario,engine,setting,dt,dt_label,steps,simulated_seconds,status,reason,repetitions,runs,"
        "wall_per_sim_median,wall_per_sim_min,wall_per_sim_max,spread,spread_warning,"
        "position_error,energy_error,contact_time_error,pareto\n";
  for (const SweepPoint& p : r.points) {
    const bool timed = usable(p);
    os << csv_field(r.scenario) << ',' << csv_field(p.engine) << ',' << csv_field(p.setting) << ','
       << csv_number(p.dt) << ',' << dt_label(p.dt) << ',' << p.steps << ',' << csv_number(p.simulated_seconds) << ','
       << run_status_name(p.status) << ',' << csv_field(p.reason) << ',' << p.repetitions << ',' << p.runs << ','
       << (timed ? csv_number(p.wall_per_sim_median) : "") << ',' << (timed ? csv_number(p.wall_per_sim_min) : "")
       << ',' << (timed ? csv_number(p.wall_per_sim_max) : "") << ',' << (timed ? csv_number(p.spread) : "") << ','
       << (p.spread_warning ? "true" : "false") << ',' << csv_number(p.position_error) << ','
       << csv_number(p.energy_error) << ',' << csv_number(p.contact_time_error) << ','
       << (p.pareto ? "true" : "false") << "\n";
  }
  return os.str();
}

nlohmann::json sweep_to_json(const SweepResult& r) {
  nlohmann::json j;
  j["context"] = context_json();
  j["scenario"] = r.scenario;
  j["duration"] = r.duration;
  j["reference"] = {{"available", r.reference_available},
                    {"converged", r.reference_converged},
                    {"dt", r.reference_available ? nlohmann::json(r.reference_dt) : nlohmann::json(nullptr)},
                    {"reason", r.reference_reason}};
  nlohmann::json points = nlohmann::json::array();
  for (const SweepPoint& p : r.points) {
    const bool timed = usable(p);
    points.push_back({{"engine", p.engine},
                      {"setting", p.setting},
                      {"dt", p.dt},
                      {"dt_label", dt_label(p.dt)},
                      {"steps", p.steps},
                      {"simulated_seconds", p.simulated_seconds},
                      {"status", run_status_name(p.status)},
                      {"reason", p.reason},
                      {"repetitions", p.repetitions},
                      {"runs", p.runs},
                      {"wall_per_sim_median", timed ? json_number(p.wall_per_sim_median) : nullptr},
                      {"wall_per_sim_min", timed ? json_number(p.wall_per_sim_min) : nullptr},
                      {"wall_per_sim_max", timed ? json_number(p.wall_per_sim_max) : nullptr},
                      {"spread", timed ? json_number(p.spread) : nullptr},
                      {"spread_warning", p.spread_warning},
                      {"position_error", json_number(p.position_error)},
                      {"energy_error", json_number(p.energy_error)},
                      {"contact_time_error", json_number(p.contact_time_error)},
                      {"pareto", p.pareto},
                      {"checks_failed", p.checks_failed}});
  }
  j["points"] = std::move(points);
  nlohmann::json orders = nlohmann::json::array();
  for (const ConvergenceOrder& o : r.orders) {
    nlohmann::json settings = nlohmann::json::object();
    for (const auto& [key, value] : o.engine_settings) settings[key] = value;
    orders.push_back({{"engine", o.engine}, {"setting", o.setting}, {"position", fit_json(o.position)},
                      {"energy", fit_json(o.energy)}, {"exact_to_round_off", o.exact_to_round_off},
                      {"engine_settings", settings}});
  }
  j["orders"] = std::move(orders);
  j["notes"] = r.notes;
  if (!r.shard.is_null()) j["shard"] = r.shard;
  return j;
}

void write_sweep(const std::filesystem::path& dir, const SweepResult& result) {
  std::filesystem::create_directories(dir);
  write_file_atomically(dir / "sweep.csv", sweep_to_csv(result));
  write_file_atomically(dir / "sweep.json", sweep_to_json(result).dump(2) + "\n");
  // Both plots with one gnuplot process.
  const std::vector<std::string> errors = plot::render_pngs(
      {{speed_vs_error_figure(result), dir / "speed_vs_error.png"}, {error_vs_dt_figure(result), dir / "error_vs_dt.png"}});
  std::string message;
  for (const std::string& e : errors) message += e.empty() ? "" : (message.empty() ? "" : "\n") + e;
  if (!message.empty()) throw plot::PlotError(message);
}

std::string sweep_measured_nothing(const SweepResult& result) {
  if (result.points.empty()) return "no point was run";
  std::size_t diverged = 0, failed = 0;
  for (const SweepPoint& p : result.points) {
    if (usable(p)) return {};
    diverged += p.status == RunStatus::Diverged ? 1 : 0;
    failed += p.status == RunStatus::Diverged ? 0 : 1;
  }
  return "every point diverged or failed (" + std::to_string(diverged) + " diverged, " + std::to_string(failed) +
         " failed): no speed or error was measured";
}

std::string sweep_engines_never_right(const SweepResult& result) {
  std::vector<std::string> order;
  std::map<std::string, std::pair<std::size_t, bool>> seen;   // points, one was right
  for (const SweepPoint& p : result.points) {
    const std::string& who = p.engine;   // any of its settings may be the right one
    auto [it, fresh] = seen.try_emplace(who, std::pair<std::size_t, bool>{0, false});
    if (fresh) order.push_back(who);
    ++it->second.first;
    if (usable(p) && p.checks_failed.empty()) it->second.second = true;
  }
  std::string out;
  for (const std::string& who : order) {
    const auto& [points, right] = seen.at(who);
    if (right) continue;
    out += (out.empty() ? "" : "; ") + who + ": none of its " + std::to_string(points) +
           " points (step sizes x settings) ran whole and held the scenario's checks";
  }
  return out;
}

}  // namespace physval
