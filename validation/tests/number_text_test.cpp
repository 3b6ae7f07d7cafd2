// to_chars_g12 (the series CSVs' number text) against std::to_chars(general, 12).
#include <gtest/gtest.h>

#include <charconv>
#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <string>

#include "../src/number_text.hpp"

namespace {

std::string reference_text(double v) {
  char buf[64];
  return std::string(buf, std::to_chars(buf, buf + sizeof buf, v, std::chars_format::general, 12).ptr);
}

std::string fast_text(double v) {
  char buf[64];
  return std::string(buf, physval::to_chars_g12(buf, buf + sizeof buf, v));
}

TEST(NumberText, EqualsToCharsOnEdgeCases) {
  const double inf = std::numeric_limits<double>::infinity();
  for (double v : {0.0, -0.0, 1.0, -1.0, 0.1, 1e-5, 9.99999999999e-6, 1e-4, 1.5e-5, 1e11, 99999999999.9, 1e12,
                   123456789012.0, 0.5, 2.5e-5, 9.999999999995, 9.9999999999949996, 9.99999999999951, 0.099999999999951,
                   1234567890125.0, 1.000000000005, 0.30000000000000004, 1.0 / 3.0, -2.0 / 3.0, 5e-324, 1e308, inf,
                   -inf, std::numeric_limits<double>::quiet_NaN(), 4503599627370496.5, 1e10 + 0.5, 12345.678901249999}) {
    EXPECT_EQ(fast_text(v), reference_text(v)) << v;
    EXPECT_EQ(fast_text(std::nextafter(v, 0.0)), reference_text(std::nextafter(v, 0.0))) << v;
    EXPECT_EQ(fast_text(std::nextafter(v, inf)), reference_text(std::nextafter(v, inf))) << v;
  }
}

TEST(NumberText, EqualsToCharsOnRandomValues) {
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> unit(-3.0, 3.0);
  std::uniform_int_distribution<int> decade(-12, 14);
  for (int i = 0; i < 300000; ++i) {
    double v = 0.0;
    switch (i % 5) {
      case 0: v = unit(rng); break;                                            // positions, energies
      case 1: v = unit(rng) * std::pow(10.0, decade(rng)); break;              // every magnitude
      case 2: {                                                                // any bit pattern
        const std::uint64_t b = rng();
        std::memcpy(&v, &b, sizeof v);
        break;
      }
      case 3: v = std::round(unit(rng) * 1e6) / 1e6; break;                    // short decimals
      default: v = std::round(unit(rng) * 1e12) / 1e12 + 0.5e-12; break;       // near a 12-digit tie
    }
    ASSERT_EQ(fast_text(v), reference_text(v)) << std::hexfloat << v;
  }
}

// Every layout the fast path writes (scientific, integer part with or without a fraction,
// 0.[000]ddd), for every count of significant digits from 1 to 12, both signs, and the
// neighbouring doubles (which carry 12 digits and may round up to the next decade).
TEST(NumberText, EqualsToCharsForEveryLayoutAndDigitCount) {
  const double inf = std::numeric_limits<double>::infinity();
  for (int exp10 = -6; exp10 <= 11; ++exp10) {
    for (int digits = 1; digits <= 12; ++digits) {
      std::string text = "9";   // d.ddd...e<exp10> with `digits` digits, last one not 0
      if (digits > 1) text += ".";
      for (int d = 1; d < digits; ++d) {   // zeros inside, the last digit never 0
        const int k = d * 7 + exp10 + 10;
        text += static_cast<char>(d + 1 < digits ? '0' + k % 10 : '1' + k % 9);
      }
      for (const char* lead : {"1", "9"}) {
        const double v = std::stod(lead + text.substr(1) + "e" + std::to_string(exp10));
        for (const double w : {v, -v, std::nextafter(v, 0.0), std::nextafter(v, inf), -std::nextafter(v, inf)}) {
          ASSERT_EQ(fast_text(w), reference_text(w)) << std::hexfloat << w;
        }
      }
    }
  }
}

// to_chars_g<P> (the series' body positions, P = 9 by default) against std::to_chars(general,
// P) for every P of the fast path: layouts, decades, neighbours, random values, P-digit ties.
template <int P>
void expect_g_equals_to_chars() {
  const auto ref = [](double v) {
    char buf[64];
    return std::string(buf, std::to_chars(buf, buf + sizeof buf, v, std::chars_format::general, P).ptr);
  };
  const auto fast = [](double v) {
    char buf[64];
    return std::string(buf, physval::to_chars_g<P>(buf, buf + sizeof buf, v));
  };
  const double inf = std::numeric_limits<double>::infinity();
  for (int exp10 = -7; exp10 <= P + 1; ++exp10) {
    for (const double mant : {1.0, 9.999999999999, 9.99999999, 5.0, 1.2345678901234, 9.5, 2.5, 4.4999999999}) {
      const double v = mant * std::pow(10.0, exp10);
      for (const double w : {v, -v, std::nextafter(v, 0.0), std::nextafter(v, inf)}) {
        ASSERT_EQ(fast(w), ref(w)) << "P=" << P << " " << std::hexfloat << w;
      }
    }
  }
  std::mt19937_64 rng(static_cast<std::uint64_t>(P) * 7919u);
  std::uniform_real_distribution<double> unit(-3.0, 3.0);
  std::uniform_int_distribution<int> decade(-8, 13);
  const double scale = std::pow(10.0, P - 1);
  for (int i = 0; i < 60000; ++i) {
    double v = 0.0;
    switch (i % 4) {
      case 0: v = unit(rng); break;
      case 1: v = unit(rng) * std::pow(10.0, decade(rng)); break;
      case 2: v = (std::round(unit(rng) * scale) + 0.5) / scale; break;   // near a P-digit tie
      default: {
        const std::uint64_t b = rng();
        std::memcpy(&v, &b, sizeof v);
        break;
      }
    }
    ASSERT_EQ(fast(v), ref(v)) << "P=" << P << " " << std::hexfloat << v;
  }
  // Exact decimal ties: m / 2^j ends in a 5 at its j-th decimal, so with P + 1 significant
  // digits it lies exactly between two P-digit texts (std::to_chars rounds it to even).
  for (int j = 1; j <= 12; ++j) {
    for (std::uint64_t m = 1; m < 4000; m += 2) {
      const double v = std::ldexp(static_cast<double>(m), -j);
      for (const double w : {v, -v, v * 1024.0}) ASSERT_EQ(fast(w), ref(w)) << "P=" << P << " " << std::hexfloat << w;
    }
  }
}

TEST(NumberText, FewerDigitsEqualToCharsForEveryDigitCount) {
  expect_g_equals_to_chars<1>();
  expect_g_equals_to_chars<2>();
  expect_g_equals_to_chars<3>();
  expect_g_equals_to_chars<4>();
  expect_g_equals_to_chars<5>();
  expect_g_equals_to_chars<6>();
  expect_g_equals_to_chars<7>();
  expect_g_equals_to_chars<8>();
  expect_g_equals_to_chars<9>();
  expect_g_equals_to_chars<10>();
  expect_g_equals_to_chars<11>();
  expect_g_equals_to_chars<12>();
}

}  // namespace

// results.json's contacts are written as text, not through a json tree: the text must be
// the tree's dump for any names and times.
#include <sstream>

#include "physval/validation/results_json.hpp"

namespace {

TEST(NumberText, StreamedContactsAreTheTreesDumpForOddNamesAndTimes) {
  physval::SuiteResult result;
  physval::ScenarioResult sr;
  sr.scene.name = "odd";
  physval::RunRecord r;
  r.scenario = "odd";
  r.engine = "core";
  const double inf = std::numeric_limits<double>::infinity();
  const std::string names[] = {"plain", "quote\"d", "back\\slash", "tab\there", "caf\xc3\xa9", "del\x7f", "", "c0"};
  const double times[] = {0.0, -0.0, 1.0, 0.1, 1e-300, 123456789.123, -2.5, inf, -inf, std::nan(""), 1.0 / 3.0};
  long step = -3;
  for (const std::string& a : names) {
    for (const double t : times) r.contacts.push_back({a, names[static_cast<std::size_t>(step + 3) % 8], t, step++});
  }
  physval::RunRecord ref = r;
  ref.engine = "reference";
  sr.reference.available = true;
  sr.reference.run = ref;
  sr.runs.push_back(r);
  result.scenarios.push_back(sr);
  std::ostringstream streamed;
  physval::write_results_json(streamed, result);
  nlohmann::json tree = physval::suite_to_json(result);
  tree["context"] = nlohmann::json::parse(streamed.str())["context"];
  EXPECT_EQ(streamed.str(), tree.dump(2) + "\n");
}

}  // namespace

// The series CSV: t and the totals with 12 significant digits, the body positions with the
// digits asked (9 by default; 17 writes every double exactly, totals too); nan for a body
// not alive. What the report and gnuplot read is the same columns either way.
#include <filesystem>
#include <fstream>

#include <unistd.h>

namespace {

std::vector<std::string> series_row(const std::filesystem::path& file, std::size_t row) {
  std::ifstream in(file);
  std::string line;
  for (std::size_t i = 0; i <= row; ++i) std::getline(in, line);
  std::vector<std::string> cells;
  std::stringstream ss(line);
  for (std::string c; std::getline(ss, c, ',');) cells.push_back(c);
  return cells;
}

TEST(NumberText, SeriesPositionsGetTheDigitsAskedTotalsTwelve) {
  physval::SuiteResult result;
  physval::ScenarioResult sr;
  sr.scene.name = "digits";
  physval::RunRecord r;
  r.scenario = "digits";
  r.engine = "core";
  r.bodies = {physval::BodyMeta{}, physval::BodyMeta{}};
  r.bodies[0].name = "a";
  r.bodies[1].name = "b";
  const double x = 1.0 / 3.0, y = -2.0 / 3.0, e = 12.345678901234567, t = 0.1;
  r.series.time = {t};
  physval::Totals tot;
  tot.kinetic = e;
  r.series.totals = {tot};
  r.series.states = {physval::SampleRow{physval::SampleState({x, y}, true), physval::SampleState({x, y}, false)}};
  sr.runs.push_back(r);
  result.scenarios.push_back(sr);
  const auto dir = std::filesystem::temp_directory_path() / ("physval-digits-" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  physval::write_results(dir / "default", result);
  auto cells = series_row(dir / "default" / "series" / "digits" / "core.csv", 1);
  ASSERT_EQ(cells.size(), 11u);
  EXPECT_EQ(cells[0], "0.1");
  EXPECT_EQ(cells[2], "12.3456789012");   // kinetic: 12 digits
  EXPECT_EQ(cells[7], "0.333333333");     // x_a: 9
  EXPECT_EQ(cells[8], "-0.666666667");
  EXPECT_EQ(cells[9], "nan");
  EXPECT_EQ(cells[10], "nan");
  physval::write_results(dir / "twelve", result, 12);
  cells = series_row(dir / "twelve" / "series" / "digits" / "core.csv", 1);
  EXPECT_EQ(cells[7], "0.333333333333");
  EXPECT_EQ(cells[8], "-0.666666666667");
  physval::write_results(dir / "full", result, 17);
  cells = series_row(dir / "full" / "series" / "digits" / "core.csv", 1);
  EXPECT_EQ(std::stod(cells[7]), x);   // every double back exactly
  EXPECT_EQ(std::stod(cells[8]), y);
  EXPECT_EQ(std::stod(cells[2]), e);
  EXPECT_EQ(std::stod(cells[0]), t);
  EXPECT_THROW(physval::write_results(dir / "bad", result, 0), std::invalid_argument);
  EXPECT_THROW(physval::write_results(dir / "bad", result, 18), std::invalid_argument);
  std::filesystem::remove_all(dir);
}

}  // namespace
