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

}  // namespace
