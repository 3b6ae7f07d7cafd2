// Renders plot::Figure through gnuplot: one data file (a block per series, selected
// with `index`), one script, one PNG, all in a private temporary folder; the PNG is
// then moved into place. Values a log axis cannot show (zero, negative) and non-finite
// values are left out here, so gnuplot never sees them.
#include "physval/validation/plot.hpp"

#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <random>
#include <sstream>
#include <system_error>

namespace physval::plot {

namespace fs = std::filesystem;

namespace {

// Point types that read well at ~1000 px: filled circle, square, triangle, diamond,
// inverted triangle, then open versions.
constexpr int kPointTypes[] = {7, 5, 9, 13, 11, 6, 4, 8, 12, 10};
constexpr int kPointTypeCount = static_cast<int>(sizeof(kPointTypes) / sizeof(kPointTypes[0]));

// A gnuplot double-quoted string (backslash escapes processed, "\n" a line break).
std::string gp_string(const std::string& s) {
  std::string out = "\"";
  for (char c : s) {
    switch (c) {
      case '\\': out += "\\\\"; break;
      case '"': out += "\\\""; break;
      case '\n': out += "\\n"; break;
      default: out += c;
    }
  }
  out += '"';
  return out;
}

// A POSIX shell single-quoted word.
std::string shell_quoted(const std::string& s) {
  std::string out = "'";
  for (char c : s) {
    if (c == '\'') {
      out += "'\\''";
    } else {
      out += c;
    }
  }
  out += '\'';
  return out;
}

std::string number(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.10g", v);
  return buf;
}

bool keep(double v, bool log_axis) { return std::isfinite(v) && (!log_axis || v > 0.0); }

// The points of a series a panel can draw, in order. A value the panel cannot show
// (not finite, or not positive on a log axis) breaks the line there: it becomes a gap,
// marked by a NaN pair. Gaps are never doubled and never lead or trail (two blank lines
// in a data file would end gnuplot's data block).
std::vector<std::pair<double, double>> drawable(const Series& s, const Panel& p) {
  std::vector<std::pair<double, double>> out;
  const std::size_t n = std::min(s.x.size(), s.y.size());
  out.reserve(n);
  bool gap = false;
  for (std::size_t i = 0; i < n; ++i) {
    if (keep(s.x[i], p.x.log) && keep(s.y[i], p.y.log)) {
      if (gap && !out.empty()) out.emplace_back(NAN, NAN);
      gap = false;
      out.emplace_back(s.x[i], s.y[i]);
    } else {
      gap = true;
    }
  }
  return out;
}

bool is_gap(const std::pair<double, double>& pt) { return std::isnan(pt.first); }

struct Extent {
  double lo = INFINITY;
  double hi = -INFINITY;
  bool empty() const { return !(lo <= hi); }
};

// `label_gap`: an empty line under the label, so a legend placed below the plot does
// not cover it (gnuplot underestimates cairo's text height there).
std::string axis_commands(char name, const Axis& axis, const Extent& data, bool label_gap = false) {
  std::ostringstream os;
  const std::string a(1, name);
  double log_step = 0.0;   // tic factor on a log axis; 0: every decade
  os << "set " << a << "label " << gp_string(axis.label + (label_gap ? "\n" : "")) << " noenhanced\n";
  if (axis.log) {
    os << "set logscale " << a << " 10\n";
    // Power-of-ten labels only when the axis spans a decade; otherwise plain numbers
    // (10^{%L} would mislabel tics that are not powers of ten).
    const double lo = axis.min.value_or(data.lo);
    const double hi = axis.max.value_or(data.hi);
    if (!data.empty() && hi / lo >= 10.0) {
      os << "set format " << a << " \"10^{%L}\"\n";
    } else {
      os << "set format " << a << " \"%g\"\n";
    }
    // Many decades: a labelled tic every second or fourth decade, so labels do not collide.
    const double decades = data.empty() ? 0.0 : std::log10(hi / lo);
    log_step = decades > 16.0 ? 10000.0 : (decades > 8.0 ? 100.0 : 0.0);
    os << "set m" << a << "tics " << (log_step > 0.0 ? "default" : "10") << "\n";
  } else {
    // Enough digits for an axis over a narrow band (a conserved quantity's wobble).
    // Just enough significant digits to tell neighbouring tics apart (about eight tics
    // over the span), at most ten: a wobble of 5e-8 around 2.5 reads 2.4999999, 2.5.
    int digits = 6;
    if (!data.empty() && data.hi > data.lo) {
      const double magnitude = std::max(std::abs(data.lo), std::abs(data.hi));
      digits = std::clamp(static_cast<int>(std::ceil(std::log10(magnitude / ((data.hi - data.lo) / 8.0)))) + 1, 3, 10);
    }
    os << "unset logscale " << a << "\nset format " << a << " \"%." << digits << "g\"\nset m" << a
       << "tics default\n";
  }
  // A log axis spanning less than a decade holds no power of ten, so gnuplot would label
  // nothing: tics at the data's own ends (and the margins) instead.
  std::vector<double> narrow_log_tics;
  if (axis.log && axis.tics.empty() && !data.empty() && data.hi / data.lo < 10.0) {
    narrow_log_tics = {data.lo / 2.0, data.lo};
    if (data.hi / data.lo > 1.5) narrow_log_tics.push_back(data.hi);
    narrow_log_tics.push_back(data.hi * 2.0);
    os << "set format " << a << " \"%.3g\"\n";
  }
  if (!narrow_log_tics.empty()) {
    os << "set " << a << "tics (";
    for (std::size_t i = 0; i < narrow_log_tics.size(); ++i) os << (i ? ", " : "") << number(narrow_log_tics[i]);
    os << ") norotate enhanced\n";
  } else if (!axis.tics.empty()) {
    os << "set " << a << "tics (";
    for (std::size_t i = 0; i < axis.tics.size(); ++i) {
      if (i > 0) os << ", ";
      os << gp_string(axis.tics[i].second) << ' ' << number(axis.tics[i].first);
    }
    os << ")";
    if (axis.tic_rotation != 0) os << " rotate by " << axis.tic_rotation << (name == 'x' ? " right" : "");
    os << " noenhanced\n";
  } else {
    if (log_step > 0.0) {
      os << "set " << a << "tics " << number(log_step) << " norotate enhanced\n";
    } else {
      os << "set " << a << "tics auto norotate enhanced\n";
    }
  }
  // A log axis gets a margin of a factor 2 beyond its data, so points at the extremes
  // are not drawn on the border; a linear axis extends to its next tics by itself.
  std::optional<double> lo = axis.min, hi = axis.max;
  if (axis.log && !data.empty()) {
    if (!lo) lo = data.lo / 2.0;
    if (!hi) hi = data.hi * 2.0;
  }
  os << "set " << a << "range [" << (lo ? number(*lo) : std::string("*")) << ':'
     << (hi ? number(*hi) : std::string("*")) << "]\n";
  return os.str();
}

std::string style_of(const Series& s) {
  switch (s.style) {
    case Style::Lines: return "lines";
    case Style::Points: return "points";
    case Style::LinesPoints: return "linespoints";
  }
  return "linespoints";
}

}  // namespace

const std::vector<std::string>& palette() {
  static const std::vector<std::string> colours = {
      "#0072B2", "#D55E00", "#009E73", "#CC79A7", "#E69F00", "#56B4E9",
      "#8C564B", "#9467BD", "#7F7F7F", "#17BECF", "#BCBD22", "#1F3A93"};
  return colours;
}

bool gnuplot_available() {
  const int rc = std::system("gnuplot --version >/dev/null 2>&1");
  return rc != -1 && WIFEXITED(rc) && WEXITSTATUS(rc) == 0;
}

std::string gnuplot_script(const Figure& figure, const fs::path& data_file, const fs::path& png) {
  std::ostringstream os;
  os << "set terminal pngcairo enhanced size " << figure.width << ',' << figure.height
     << " font 'Sans,11' linewidth 1\n";
  os << "set output " << gp_string(png.string()) << "\n";
  os << "set datafile separator whitespace\n";
  os << "set grid xtics ytics mxtics mytics lc rgb '#e4e4e4' lw 1, lc rgb '#f2f2f2' lw 1\n";
  os << "set border lw 1.2\n";
  os << "set tics out nomirror\n";
  const bool multi = figure.panels.size() > 1;
  if (multi) {
    const std::size_t columns = static_cast<std::size_t>(std::max(1, figure.columns));
    os << "set multiplot layout " << (figure.panels.size() + columns - 1) / columns << ',' << columns;
    if (!figure.title.empty()) os << " title " << gp_string(figure.title) << " font ',13' noenhanced";
    os << "\n";
  }

  const bool aligned = multi && figure.columns <= 1;
  const bool keys_outside = std::any_of(figure.panels.begin(), figure.panels.end(), [](const Panel& p) {
    return p.key.find("outside") != std::string::npos;
  });
  std::size_t block = 0;   // index of the next data block in the data file
  for (const Panel& panel : figure.panels) {
    // Automatic colours and markers restart in each panel: series i looks the same
    // in every panel of a figure.
    int auto_colour = 0;
    int auto_point = 0;
    Extent ex, ey;
    std::vector<std::vector<std::pair<double, double>>> data;
    for (const Series& s : panel.series) {
      data.push_back(drawable(s, panel));
      for (const auto& pt : data.back()) {
        if (is_gap(pt)) continue;
        const auto [x, y] = pt;
        ex.lo = std::min(ex.lo, x);
        ex.hi = std::max(ex.hi, x);
        ey.lo = std::min(ey.lo, y);
        ey.hi = std::max(ey.hi, y);
      }
    }
    std::string title = multi ? panel.title
                              : (figure.title.empty() ? panel.title
                                                      : (panel.title.empty() ? figure.title
                                                                             : figure.title + "\n" + panel.title));
    if (!panel.note.empty()) title += "\n" + panel.note;
    os << "unset label\n";
    os << "set title " << gp_string(title) << " noenhanced font ',12'\n";
    const bool key_below = panel.key.find("below") != std::string::npos;
    // A linear y axis over a band far narrower than its values (a conserved energy's
    // wobble, 2.5 J +- 5e-8) is drawn as the offset from a round value, named in the
    // label: tics read -4e-07, -2e-07, 0 instead of 2.4999996, 2.4999998, 2.5.
    double y_offset = 0.0;
    plot::Axis y_axis = panel.y;
    if (!panel.y.log && !panel.y.min && !panel.y.max && panel.y.tics.empty() && !ey.empty() && ey.hi > ey.lo &&
        std::max(std::abs(ey.lo), std::abs(ey.hi)) / (ey.hi - ey.lo) > 1e4) {
      const double unit = std::pow(10.0, std::ceil(std::log10(ey.hi - ey.lo)));
      y_offset = std::round(ey.hi / unit) * unit;
      y_axis.label += " - " + number(y_offset);
      ey.lo -= y_offset;
      ey.hi -= y_offset;
    }
    os << axis_commands('x', panel.x, ex, key_below) << axis_commands('y', y_axis, ey);
    if (panel.key == "off") {
      os << "set key off\n";
    } else {
      os << "set key default\nset key " << panel.key << " box opaque samplen 3 spacing 1.15 font ',10' noenhanced\n";
    }
    // Stacked panels with legends beside them share their left and right edges, so
    // their time axes line up.
    if (aligned) {
      os << "set lmargin at screen 0.14\nset rmargin at screen " << (keys_outside ? "0.74" : "0.96") << "\n";
    } else {
      os << "unset lmargin\nunset rmargin\n";
      if (panel.left_margin > 0) os << "set lmargin " << panel.left_margin << "\n";
    }
    os << (panel.equal_aspect ? "set size ratio -1\n" : "set size noratio\n");
    for (std::size_t i = 0; i < panel.labels.size(); ++i) {
      const Label& l = panel.labels[i];
      if (!std::isfinite(l.x) || !std::isfinite(l.y)) continue;
      os << "set label " << (i + 2) << ' ' << gp_string(l.text) << " at " << number(l.x) << ',' << number(l.y)
         << " offset 0.6,0.6 font ',10' front noenhanced\n";
    }

    std::vector<std::string> parts;
    const std::size_t first_block = block;
    for (std::size_t i = 0; i < panel.series.size(); ++i) {
      const Series& s = panel.series[i];
      const int colour = s.color >= 0 ? s.color : auto_colour++;
      const int pt = s.point_type >= 0 ? s.point_type : kPointTypes[auto_point++ % kPointTypeCount];
      if (data[i].empty()) {
        // Nothing drawable (all zero on a log axis, or unmeasured): still in the legend,
        // saying so, so a reader does not look for a line that is not there.
        if (!s.title.empty()) {
          std::ostringstream k;
          k << "keyentry with " << style_of(s) << " lc rgb '"
            << (s.rgb.empty() ? palette()[static_cast<std::size_t>(colour) % palette().size()] : s.rgb) << "' lw "
            << number(s.line_width) << " dt " << s.dash;
          if (s.style != Style::Lines) k << " pt " << pt << " ps " << number(s.point_size);
          k << " title " << gp_string(s.title + " (nothing to draw)") << " noenhanced";
          parts.push_back(k.str());
        }
        continue;
      }
      std::ostringstream p;
      p << gp_string(data_file.string()) << " index " << block
        << (y_offset != 0.0 ? " using 1:($2-(" + number(y_offset) + "))" : std::string(" using 1:2")) << " with " << style_of(s)
        << " lc rgb '"
        << (s.rgb.empty() ? palette()[static_cast<std::size_t>(colour) % palette().size()] : s.rgb) << "'"
        << " lw " << number(s.line_width) << " dt " << s.dash;
      if (s.style != Style::Lines) p << " pt " << pt << " ps " << number(s.point_size);
      if (s.style == Style::LinesPoints && s.point_interval > 1) p << " pi " << s.point_interval;
      if (s.title.empty()) {
        p << " notitle";
      } else {
        p << " title " << gp_string(s.title) << " noenhanced";
      }
      parts.push_back(p.str());
      ++block;
    }
    if (block == first_block) {   // not one drawable series
      // An empty panel still renders (and says so) rather than failing the figure.
      os << "unset logscale xy\nset format x \"%g\"\nset format y \"%g\"\n"
         << "set xtics auto norotate\nset ytics auto norotate\nset mxtics default\nset mytics default\n"
         << "set xrange [0:1]\nset yrange [0:1]\nset key off\n"
         << "set label 1 \"no data to plot\" at graph 0.5, graph 0.5 center font ',14' noenhanced\n"
         << "plot 2 notitle\n";
    } else {
      os << "plot ";
      for (std::size_t i = 0; i < parts.size(); ++i) {
        if (i > 0) os << ", \\\n     ";
        os << parts[i];
      }
      os << "\n";
    }
  }
  if (multi) os << "unset multiplot\n";
  os << "set output\n";
  return os.str();
}

namespace {

std::string read_text(const fs::path& file) {
  std::ifstream in(file);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

void write_data(const Figure& figure, std::ostream& data) {
  for (const Panel& panel : figure.panels) {
    for (const Series& s : panel.series) {
      const auto points = drawable(s, panel);
      if (points.empty()) continue;
      for (const auto& pt : points) {
        if (is_gap(pt)) {
          data << "\n";   // one blank line: a break in the line, same block
          continue;
        }
        char line[80];
        std::snprintf(line, sizeof line, "%.17g %.17g\n", pt.first, pt.second);
        data << line;
      }
      data << "\n\n";   // two blank lines end a gnuplot `index` block
    }
  }
}

// Runs gnuplot once on `script`, its messages into `log`; whether it exited 0.
bool run_gnuplot(const fs::path& script, const fs::path& log) {
  const std::string command = "gnuplot " + shell_quoted(script.string()) + " >" + shell_quoted(log.string()) + " 2>&1";
  const int rc = std::system(command.c_str());
  return rc != -1 && WIFEXITED(rc) && WEXITSTATUS(rc) == 0;
}

// Into place whole: copy next to the target, then rename over it.
void move_into_place(const fs::path& from, const fs::path& png) {
  if (png.has_parent_path()) fs::create_directories(png.parent_path());
  const fs::path staged = png.string() + ".tmp";
  fs::copy_file(from, staged, fs::copy_options::overwrite_existing);
  fs::rename(staged, png);
}

}  // namespace

std::vector<std::string> render_pngs(const std::vector<FigureJob>& jobs) {
  std::vector<std::string> errors(jobs.size());
  if (jobs.empty()) return errors;
  if (!gnuplot_available()) {   // probed once for the whole batch
    throw PlotError("gnuplot is not installed (or not on PATH): the plots need it; on Debian "
                    "install the gnuplot-nox package");
  }
  static std::atomic<unsigned> counter{0};
  std::random_device rd;
  const fs::path tmp = fs::temp_directory_path() /
                       ("physval-plot-" + std::to_string(::getpid()) + "-" +
                        std::to_string(counter++) + "-" + std::to_string(rd()));
  fs::create_directories(tmp);
  struct Cleanup {
    fs::path dir;
    bool keep = false;   // a failed script stays for inspection
    ~Cleanup() {
      std::error_code ec;
      if (!keep) fs::remove_all(dir, ec);
    }
  } cleanup{tmp};

  // Every figure has its own data file, script and PNG; one batch script runs them all
  // in a single gnuplot process (`reset` between figures, so no setting leaks over).
  auto file = [&](std::size_t i, const char* what) { return tmp / ("figure" + std::to_string(i) + what); };
  const fs::path batch_file = tmp / "batch.gp";
  {
    std::ofstream batch(batch_file);
    for (std::size_t i = 0; i < jobs.size(); ++i) {
      std::ofstream data(file(i, ".txt"));
      write_data(jobs[i].figure, data);
      std::ofstream script(file(i, ".gp"));
      script << gnuplot_script(jobs[i].figure, file(i, ".txt"), file(i, ".png"));
      if (!data || !script) throw PlotError("cannot write gnuplot input in " + tmp.string());
      batch << "reset\nload " << gp_string(file(i, ".gp").string()) << "\n";
    }
    if (!batch) throw PlotError("cannot write gnuplot input in " + tmp.string());
  }
  const fs::path batch_log = tmp / "batch.log";
  const bool batch_ok = run_gnuplot(batch_file, batch_log);

  for (std::size_t i = 0; i < jobs.size(); ++i) {
    const fs::path out_png = file(i, ".png");
    std::error_code ec;
    bool drawn = batch_ok && fs::exists(out_png) && fs::file_size(out_png, ec) > 0;
    std::string log = batch_ok ? read_text(batch_log) : std::string();
    if (!drawn) {
      // The batch stopped at some figure's error (gnuplot ends a script there): this
      // figure gets its own process, so its message is its own and the others still draw.
      const fs::path own_log = file(i, ".log");
      const bool ok = run_gnuplot(file(i, ".gp"), own_log);
      log = read_text(own_log);
      if (!ok) {
        cleanup.keep = true;
        errors[i] = "gnuplot failed drawing " + jobs[i].png.string() + " (script and data kept in " +
                    tmp.string() + "):\n" + log;
        continue;
      }
      drawn = fs::exists(out_png) && fs::file_size(out_png, ec) > 0;
    }
    if (!drawn) {
      errors[i] = "gnuplot produced no image for " + jobs[i].png.string() + ":\n" + log;
      continue;
    }
    move_into_place(out_png, jobs[i].png);
  }
  return errors;
}

void render_png(const Figure& figure, const fs::path& png) {
  const std::vector<std::string> errors = render_pngs({FigureJob{figure, png}});
  if (!errors.front().empty()) throw PlotError(errors.front());
}

}  // namespace physval::plot
