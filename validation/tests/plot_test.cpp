// The gnuplot driver: a figure becomes a real, non-empty PNG of the requested size;
// awkward data (zeros and NaN on log axes, empty series, quotes in titles) does not
// break it; a missing gnuplot is a clear error. gnuplot-nox is part of the project's
// set-up, so these tests fail (not skip) without it.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include "physval/validation/plot.hpp"

namespace physval::plot {
namespace {

namespace fs = std::filesystem;

fs::path fresh_dir(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / ("physval-plot-test-" + name + "-" + std::to_string(::getpid()));
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

struct PngInfo {
  bool signature = false;
  std::uint32_t width = 0;
  std::uint32_t height = 0;
};

// The PNG signature and the IHDR chunk's width and height (big-endian, bytes 16-23).
PngInfo read_png(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  unsigned char b[24] = {};
  in.read(reinterpret_cast<char*>(b), sizeof b);
  PngInfo info;
  if (in.gcount() != 24) return info;
  const unsigned char sig[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  info.signature = std::equal(sig, sig + 8, b);
  auto be32 = [&](int at) {
    return (std::uint32_t{b[at]} << 24) | (std::uint32_t{b[at + 1]} << 16) | (std::uint32_t{b[at + 2]} << 8) |
           std::uint32_t{b[at + 3]};
  };
  info.width = be32(16);
  info.height = be32(20);
  return info;
}

Series line(const std::string& title, double exponent) {
  Series s;
  s.title = title;
  for (int i = 1; i <= 20; ++i) {
    const double x = 0.001 * i * i;
    s.x.push_back(x);
    s.y.push_back(std::pow(x, exponent));
  }
  return s;
}

TEST(Plot, GnuplotIsInstalled) {
  EXPECT_TRUE(gnuplot_available()) << "install gnuplot-nox (the project's set-up does)";
}

TEST(Plot, RendersALogLogFigureAtTheRequestedSize) {
  const fs::path dir = fresh_dir("loglog");
  Figure fig;
  fig.title = "error against step";
  fig.width = 900;
  fig.height = 600;
  Panel p;
  p.x = {"step size dt (s)", true, {}, {}, {}, 0};
  p.y = {"error (m)", true, {}, {}, {}, 0};
  p.series = {line("order 1", 1.0), line("order 2", 2.0)};
  fig.panels.push_back(p);
  const fs::path png = dir / "sub" / "loglog.png";
  render_png(fig, png);
  ASSERT_TRUE(fs::exists(png));
  EXPECT_GT(fs::file_size(png), 1000u);
  const PngInfo info = read_png(png);
  EXPECT_TRUE(info.signature);
  EXPECT_EQ(info.width, 900u);
  EXPECT_EQ(info.height, 600u);
  fs::remove_all(dir);
}

TEST(Plot, SurvivesZerosNaNsEmptySeriesAndQuotes) {
  const fs::path dir = fresh_dir("awkward");
  Figure fig;
  fig.title = "a \"quoted\" title with 'apostrophes', back\\slash and x_i^2 {braces} @";
  Panel top;
  top.title = "log axis with zeros and NaN";
  top.y.log = true;
  Series s = line("has zero, negative and NaN values", 1.0);
  s.y[3] = 0.0;
  s.y[5] = -1.0;
  s.y[7] = NAN;
  s.x[9] = INFINITY;
  top.series.push_back(s);
  Series empty;
  empty.title = "nothing drawable";
  empty.x = {1.0, 2.0};
  empty.y = {0.0, -3.0};
  top.series.push_back(empty);
  top.labels.push_back({0.01, 0.01, "label's \"text\""});
  Panel categories;
  categories.title = "categorical axis";
  categories.y.tics = {{0.0, "box2d"}, {1.0, "reference_run"}};
  categories.x.tics = {{1.0, "scenario_one"}, {2.0, "scenario_two"}};
  categories.x.tic_rotation = 25;
  Series pts;
  pts.style = Style::Points;
  pts.title = "contacts";
  pts.x = {1.0, 2.0};
  pts.y = {0.0, 1.0};
  categories.series.push_back(pts);
  Panel nothing;
  nothing.title = "no series at all";
  nothing.x.log = true;
  fig.panels = {top, categories, nothing};
  const fs::path png = dir / "awkward.png";
  render_png(fig, png);
  ASSERT_TRUE(fs::exists(png));
  EXPECT_GT(fs::file_size(png), 1000u);
  EXPECT_TRUE(read_png(png).signature);
  fs::remove_all(dir);
}

TEST(Plot, SeriesWithNothingToDrawStayInTheLegendOnly) {
  Figure fig;
  Panel p;
  p.y.log = true;
  Series zero;
  zero.title = "all zero";
  zero.x = {1.0, 2.0};
  zero.y = {0.0, 0.0};
  p.series = {zero, line("drawable", 2.0)};
  fig.panels.push_back(p);
  const std::string script = gnuplot_script(fig, "data.txt", "out.png");
  // In the legend only (keyentry), never as a data block: one `index` for one series.
  EXPECT_NE(script.find("keyentry"), std::string::npos);
  EXPECT_NE(script.find("all zero (nothing to draw)"), std::string::npos);
  EXPECT_NE(script.find("index 0"), std::string::npos);
  EXPECT_EQ(script.find("index 1"), std::string::npos);
  EXPECT_NE(script.find("drawable"), std::string::npos);
  EXPECT_NE(script.find("set logscale y"), std::string::npos);
}

// Many figures, one gnuplot process: each lands at its own path with its own size and
// settings (a log axis in the first does not leak into the next), and a figure gnuplot
// rejects (an unknown colour name) is reported alone while the others are drawn.
TEST(Plot, RendersABatchAndIsolatesABadFigure) {
  const fs::path dir = fresh_dir("batch");
  Figure good;
  good.width = 640;
  good.height = 400;
  Panel p;
  p.x = {"x", true, {}, {}, {}, 0};
  p.y = {"y", true, {}, {}, {}, 0};
  p.series = {line("a", 1.0)};
  good.panels.push_back(p);
  Figure linear = good;
  linear.width = 500;
  linear.panels[0].x.log = false;
  linear.panels[0].y.log = false;
  Figure bad = good;
  bad.panels[0].series[0].rgb = "no-such-colour";
  const std::vector<std::string> errors =
      render_pngs({{good, dir / "a.png"}, {bad, dir / "bad.png"}, {linear, dir / "c.png"}});
  ASSERT_EQ(errors.size(), 3u);
  EXPECT_EQ(errors[0], "");
  EXPECT_NE(errors[1], "") << "gnuplot accepted an unknown colour";
  EXPECT_EQ(errors[2], "");
  EXPECT_EQ(read_png(dir / "a.png").width, 640u);
  EXPECT_EQ(read_png(dir / "c.png").width, 500u);
  EXPECT_FALSE(fs::exists(dir / "bad.png"));
  fs::remove_all(dir);
}

// Readable tics: a log axis under one decade (a constant error) gets labelled tics at
// its data, and a linear axis over a narrow band around 2.5 is drawn as an offset.
TEST(Plot, TicsStayReadableOnNarrowAxes) {
  Figure fig;
  Panel constant;
  constant.y.log = true;
  Series c;
  c.x = {1.0, 2.0, 3.0};
  c.y = {4.77e-7, 4.77e-7, 4.77e-7};
  constant.series.push_back(c);
  Panel band;
  Series b;
  b.x = {0.0, 1.0, 2.0};
  b.y = {2.5, 2.49999995, 2.4999995};
  b.title = "energy";
  band.y.label = "energy (J)";
  band.series.push_back(b);
  fig.panels = {constant, band};
  const std::string script = gnuplot_script(fig, "d.txt", "o.png");
  EXPECT_NE(script.find("set ytics (2.385e-07, 4.77e-07, 9.54e-07)"), std::string::npos) << script;
  EXPECT_NE(script.find("energy (J) - 2.5"), std::string::npos) << script;
  EXPECT_NE(script.find("using 1:($2-(2.5))"), std::string::npos) << script;
}

TEST(Plot, MissingGnuplotIsAClearError) {
  const char* old_path = std::getenv("PATH");
  const std::string saved = old_path != nullptr ? old_path : "";
  ::setenv("PATH", "/nonexistent-physval-test", 1);
  Figure fig;
  Panel p;
  p.series.push_back(line("x", 1.0));
  fig.panels.push_back(p);
  const fs::path dir = fresh_dir("missing");
  std::string message;
  try {
    render_png(fig, dir / "never.png");
  } catch (const PlotError& e) {
    message = e.what();
  }
  ::setenv("PATH", saved.c_str(), 1);
  EXPECT_NE(message.find("gnuplot"), std::string::npos) << "no PlotError naming gnuplot";
  EXPECT_FALSE(fs::exists(dir / "never.png"));
  fs::remove_all(dir);
}

}  // namespace
}  // namespace physval::plot
