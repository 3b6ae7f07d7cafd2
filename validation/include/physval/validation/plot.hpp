// A small gnuplot driver: a figure is data (panels of series), rendered to PNG by
// writing a data file and a script to a temporary folder and running `gnuplot` on it
// (Debian's gnuplot-nox, pngcairo terminal, headless). Reports and the sweep draw
// every picture through it, so all plots share one look: titles, axis labels with
// units, legends, point markers, log axes where errors span decades.
#pragma once

#include <filesystem>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace physval::plot {

// Thrown when gnuplot is missing, fails, or leaves no (or an empty) PNG behind.
class PlotError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

enum class Style { Lines, Points, LinesPoints };

struct Series {
  std::string title;               // legend entry ("" keeps it out of the legend)
  std::vector<double> x;
  std::vector<double> y;           // same length as x
  Style style = Style::LinesPoints;
  int color = -1;                  // index into palette(); -1: next colour in turn
  std::string rgb;                 // "#000000": overrides color
  int dash = 1;                    // gnuplot dash type: 1 solid, 2 dashed, 3 dotted, ...
  int point_type = -1;             // gnuplot point type; -1: one per series in turn
  double point_size = 1.0;
  int point_interval = 1;          // LinesPoints: a marker every n-th point
  double line_width = 2.0;
};

struct Axis {
  std::string label;               // with units: "time (s)"
  bool log = false;                // log10 scale; non-positive values are left out
  std::optional<double> min;
  std::optional<double> max;
  // Fixed tic marks with labels (a categorical axis, e.g. one row per engine).
  std::vector<std::pair<double, std::string>> tics;
  int tic_rotation = 0;            // degrees, for long tic labels
};

// Text placed at data coordinates (a body's name at its start).
struct Label {
  double x = 0.0;
  double y = 0.0;
  std::string text;
};

struct Panel {
  std::string title;
  Axis x;
  Axis y;
  std::vector<Series> series;
  std::string key = "top right";   // gnuplot key placement: "outside right top", "off", ...
  bool equal_aspect = false;       // one metre is as long on x as on y (trajectories)
  std::string note;                // small text under the title ("" for none)
  std::vector<Label> labels;
  int left_margin = 0;             // characters left of the axes for long tic labels; 0: gnuplot's own
};

struct Figure {
  std::string title;               // over all panels ("" for none)
  std::vector<Panel> panels;       // row by row, `columns` to a row
  int columns = 1;
  int width = 1000;                // pixels
  int height = 650;
};

// The colours series take in turn (distinct, colour-blind friendly first).
const std::vector<std::string>& palette();

// Whether a `gnuplot` program can be run.
bool gnuplot_available();

// The gnuplot script that draws `figure` from `data_file` into `png` (exposed for tests).
std::string gnuplot_script(const Figure& figure, const std::filesystem::path& data_file,
                           const std::filesystem::path& png);

// Renders `figure` into `png` (folders created). Throws PlotError with gnuplot's own
// message on failure, or when gnuplot is missing.
void render_png(const Figure& figure, const std::filesystem::path& png);

struct FigureJob {
  Figure figure;
  std::filesystem::path png;
};

// Renders many figures with one gnuplot process (and one probe for gnuplot), the way
// a report draws its dozens of plots. Returns one message per job, "" where the PNG
// was drawn; a figure whose script fails is retried alone, so one bad figure does not
// lose the others. Throws PlotError only when gnuplot is missing.
std::vector<std::string> render_pngs(const std::vector<FigureJob>& jobs);

}  // namespace physval::plot
