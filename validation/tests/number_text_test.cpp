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
  // A long name of escapes (6 characters each: more than the room made for a name's text)
  // and enough contacts (about 350 kB) for the text to be flushed and grown several times.
  const std::string names[] = {"plain", "quote\"d", "back\\slash", "tab\there", "caf\xc3\xa9", "del\x7f", "",
                               std::string(40, '\x01')};
  const double times[] = {0.0, -0.0, 1.0, 0.1, 1e-300, 123456789.123, -2.5, inf, -inf, std::nan(""), 1.0 / 3.0};
  long step = -3;
  for (int round = 0; round < 20; ++round) {
    for (const std::string& a : names) {
      for (const double t : times) r.contacts.push_back({a, names[static_cast<std::size_t>(step + 3) % 8], t, step++});
    }
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
