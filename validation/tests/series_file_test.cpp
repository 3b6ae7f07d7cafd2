// The series files (series_file.hpp, README "Series files"): `physval run` writes each
// run's series as the doubles themselves (<engine>.bin); --series-csv writes the CSV it wrote
// before, and `physval series-csv` turns a .bin into that same CSV byte for byte; the
// report reads either.
#include <gtest/gtest.h>
#include <unistd.h>

#include <charconv>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <random>
#include <string>

#include "physval/validation/results_json.hpp"
#include "physval/validation/series_file.hpp"
#include "../src/report_figures.hpp"
#include "physval_command.hpp"

namespace physval {
namespace {

namespace fs = std::filesystem;

std::string read_bytes(const fs::path& f) {
  std::ifstream in(f, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

fs::path fresh_dir(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / ("physval-series-test-" + name + "-" + std::to_string(::getpid()));
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

bool same_bits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

// A run whose series has every kind of value the text must get right: random positions of
// many magnitudes, exact ties of the 12-digit rounding, zeros of both signs, infinities,
// a NaN position of a live body, dead bodies, and rows shorter than the body list (a body
// not there yet). `bodies` may pass kMaxBodiesInSeries (the files keep the first ones).
RunRecord odd_run(const std::string& engine, std::size_t bodies, unsigned seed) {
  RunRecord r;
  r.scenario = "odd";
  r.engine = engine;
  for (std::size_t i = 0; i < bodies; ++i) r.bodies.push_back(BodyMeta{"b" + std::to_string(i), 1.0, 0.1, false});
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  std::uniform_int_distribution<int> exponent(-9, 12);
  auto value = [&]() -> double {
    switch (rng() % 16) {
      case 0: return 0.0;
      case 1: return -0.0;
      case 2: return std::numeric_limits<double>::infinity();
      case 3: return 0.5 + static_cast<double>(rng() % 1000);   // ties at 12 digits when large
      case 4: return 1.0000000000005;
      default: return unit(rng) * std::pow(10.0, exponent(rng));
    }
  };
  for (int k = 0; k < 25; ++k) {
    r.series.time.push_back(0.01 * k);
    Totals t;
    t.kinetic = value();
    t.potential = value();
    t.momentum = {value(), value()};
    t.angular_momentum = value();
    r.series.totals.push_back(t);
    SampleRow row(k < 3 ? bodies / 2 : bodies);
    for (std::size_t i = 0; i < row.size(); ++i) {
      row[i].position = {value(), value()};
      row[i].alive = (rng() % 7) != 0;
      if (rng() % 50 == 0) row[i].position.x = std::numeric_limits<double>::quiet_NaN();
    }
    r.series.states.push_back(row);
  }
  return r;
}

SuiteResult odd_suite() {
  SuiteResult suite;
  ScenarioResult s;
  s.scene.name = "odd";
  s.scene.duration = 0.25;
  s.scene.dt = 0.01;
  s.runs.push_back(odd_run("core", 7, 1));
  s.runs.push_back(odd_run("box2d", kMaxBodiesInSeries + 3, 2));
  RunRecord empty;   // no series: no file
  empty.scenario = "odd";
  empty.engine = "bullet";
  empty.status = RunStatus::Unsupported;
  s.runs.push_back(empty);
  s.reference.available = true;
  s.reference.run = odd_run("core", 7, 3);
  suite.scenarios.push_back(std::move(s));
  return suite;
}

TEST(SeriesFile, BinaryHoldsTheSeriesDoublesAndConvertsToTheCsvByteForByte) {
  const fs::path bin = fresh_dir("bin"), csv = fresh_dir("csv");
  const SuiteResult suite = odd_suite();
  write_results(bin, suite);
  write_results(csv, suite, SeriesFormat::Csv);
  const fs::path sb = bin / "series" / "odd", sc = csv / "series" / "odd";
  for (const char* label : {"core", "box2d", "reference"}) {
    EXPECT_TRUE(fs::exists(sb / (std::string(label) + ".bin"))) << label;
    EXPECT_FALSE(fs::exists(sb / (std::string(label) + ".csv"))) << label;
    EXPECT_TRUE(fs::exists(sc / (std::string(label) + ".csv"))) << label;
    EXPECT_FALSE(fs::exists(sc / (std::string(label) + ".bin"))) << label;
  }
  EXPECT_FALSE(fs::exists(sb / "bullet.bin"));
  // The file holds exactly the doubles the CSV is made of (series_values), bit for bit.
  const RunRecord* runs[] = {&suite.scenarios[0].runs[0], &suite.scenarios[0].runs[1], &*suite.scenarios[0].reference.run};
  const char* labels[] = {"core", "box2d", "reference"};
  for (int k = 0; k < 3; ++k) {
    const std::optional<SeriesTable> t = read_series_binary(sb / (std::string(labels[k]) + ".bin"));
    ASSERT_TRUE(t) << labels[k];
    std::vector<double> expected;
    const std::size_t columns = series_values(*runs[k], expected);
    ASSERT_EQ(t->names.size(), columns) << labels[k];
    EXPECT_EQ(t->names.front(), "t");
    EXPECT_EQ(t->names.back(), "y_b" + std::to_string(std::min(runs[k]->bodies.size(), kMaxBodiesInSeries) - 1));
    ASSERT_EQ(t->rows, runs[k]->series.time.size());
    ASSERT_EQ(t->values.size(), expected.size());
    std::size_t differ = 0;
    for (std::size_t i = 0; i < expected.size(); ++i) differ += same_bits(t->values[i], expected[i]) ? 0 : 1;
    EXPECT_EQ(differ, 0u) << labels[k];
    // A dead body's columns are NaN; a live body's are its position.
    const SampleState& s = runs[k]->series.states[10][1];
    const double x = t->values[10 * columns + 7 + 2];
    if (s.alive) {
      EXPECT_TRUE(same_bits(x, s.position.x)) << labels[k];
    } else {
      EXPECT_TRUE(std::isnan(x)) << labels[k];
    }
  }
  // The CSV is the header and each double as %.12g (std::to_chars, 12 digits), "nan" for NaN.
  {
    std::vector<double> values;
    const std::size_t columns = series_values(*runs[1], values);
    std::string oracle = series_header(*runs[1]) + "\n";
    for (std::size_t i = 0; i < values.size(); ++i) {
      char buf[40];
      oracle += std::isnan(values[i]) ? std::string("nan")
                                      : std::string(buf, std::to_chars(buf, buf + sizeof buf, values[i],
                                                                       std::chars_format::general, 12).ptr);
      oracle += (i + 1) % columns == 0 ? '\n' : ',';
    }
    EXPECT_EQ(read_bytes(sc / "box2d.csv"), oracle);
  }
  EXPECT_EQ(convert_series_to_csv(bin), 3u);
  for (const char* label : labels) {
    const std::string made = read_bytes(sb / (std::string(label) + ".csv"));
    EXPECT_FALSE(made.empty()) << label;
    EXPECT_EQ(made, read_bytes(sc / (std::string(label) + ".csv"))) << label;
  }
  fs::remove_all(bin);
  fs::remove_all(csv);
}

// The report reads a .bin where there is one, else the CSV: the same table to the CSV's
// 12 digits.
TEST(SeriesFile, ReportReadsEitherFormatAlike) {
  const fs::path bin = fresh_dir("rbin"), csv = fresh_dir("rcsv");
  const SuiteResult suite = odd_suite();
  write_results(bin, suite);
  write_results(csv, suite, SeriesFormat::Csv);
  for (const char* label : {"core", "box2d", "reference"}) {
    const auto a = report_detail::read_table(bin / "series" / "odd" / (std::string(label) + ".csv"));
    const auto b = report_detail::read_table(csv / "series" / "odd" / (std::string(label) + ".csv"));
    ASSERT_TRUE(a && b) << label;
    ASSERT_EQ(a->names, b->names) << label;
    ASSERT_EQ(a->rows(), b->rows()) << label;
    std::size_t differ = 0;
    for (std::size_t c = 0; c < a->names.size(); ++c) {
      for (std::size_t k = 0; k < a->rows(); ++k) {
        const double x = a->columns[c][k], y = b->columns[c][k];
        const bool same = (std::isnan(x) && std::isnan(y)) || x == y || std::fabs(x - y) <= 1e-11 * std::fabs(x);
        differ += same ? 0 : 1;
      }
    }
    EXPECT_EQ(differ, 0u) << label;
  }
  fs::remove_all(bin);
  fs::remove_all(csv);
}

TEST(SeriesFile, AMalformedFileIsRefusedNamingIt) {
  const fs::path dir = fresh_dir("bad");
  const SuiteResult suite = odd_suite();
  write_results(dir, suite);
  const fs::path f = dir / "series" / "odd" / "core.bin";
  const std::string bytes = read_bytes(f);
  auto refused = [&](const std::string& content, const std::string& why) {
    std::ofstream(f, std::ios::binary | std::ios::trunc) << content;
    try {
      read_series_binary(f);
      ADD_FAILURE() << why << ": read";
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find(f.string()), std::string::npos) << why << ": " << e.what();
    }
  };
  refused(bytes.substr(0, bytes.size() - 8), "a row cut short");
  refused(bytes + "12345678", "a double too many");
  refused("t,energy\n1,2\n", "a CSV");
  std::string wrong_columns = bytes;
  wrong_columns[std::strlen("physval-series 1 25 ")] = '9';
  refused(wrong_columns, "a column count the header does not have");
  EXPECT_FALSE(read_series_binary(dir / "series" / "odd" / "none.bin"));
  fs::remove_all(dir);
}

class SeriesCli : public physval_test::TempDirTest {
 protected:
  SeriesCli() : TempDirTest("physval_series_cli_") {}
};

TEST_F(SeriesCli, RunWritesBinaryOrCsvAndSeriesCsvConvertsAlike) {
  const std::string scene = PHYSVAL_SOURCE_SCENARIOS "/basics/head_on_elastic.toml --engines core,box2d -j 1 --no-cache --quiet";
  const fs::path bin = dir_ / "bin", csv = dir_ / "csv";
  auto r = physval_test::physval("run " + scene + " --out " + bin.string());
  ASSERT_EQ(r.status, 0) << r.output;
  r = physval_test::physval("run " + scene + " --series-csv --out " + csv.string());
  ASSERT_EQ(r.status, 0) << r.output;
  const fs::path sb = bin / "series" / "head_on_elastic", sc = csv / "series" / "head_on_elastic";
  for (const char* label : {"core", "box2d", "reference"}) {
    EXPECT_TRUE(fs::exists(sb / (std::string(label) + ".bin"))) << label;
    EXPECT_FALSE(fs::exists(sb / (std::string(label) + ".csv"))) << label;
    EXPECT_TRUE(fs::exists(sc / (std::string(label) + ".csv"))) << label;
  }
  r = physval_test::physval("series-csv " + bin.string());
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("3 series files written as CSV"), std::string::npos) << r.output;
  for (const char* label : {"core", "box2d", "reference"}) {
    EXPECT_EQ(read_bytes(sb / (std::string(label) + ".csv")), read_bytes(sc / (std::string(label) + ".csv"))) << label;
  }
  r = physval_test::physval("series-csv " + (dir_ / "nothing").string());
  EXPECT_EQ(r.status, 2) << r.output;
}

}  // namespace
}  // namespace physval
