// %.12g text of a double (what std::to_chars(general, 12) gives), byte for byte, about
// twice as fast for the magnitudes series hold (1e-5 <= |v| < 1e11): the 12 digits come
// from exact integer arithmetic (the mantissa times a power of ten in 128 bits, rounded
// to nearest); exact ties, other magnitudes, zero, NaN and infinities go to std::to_chars.
// The series CSVs are most of what physval writes (test NumberText.*).
#pragma once

#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>

namespace physval {

// GCC's 128-bit integer (a 53-bit mantissa times a power of ten up to 10^17 needs it);
// __extension__ says so to -Wpedantic.
__extension__ typedef unsigned __int128 uint128_for_text;

inline char* to_chars_g12(char* out, char* end, double v) {
  auto slow = [&] { return std::to_chars(out, end, v, std::chars_format::general, 12).ptr; };
  const double a = std::fabs(v);
  if (!(a >= 1e-5 && a < 1e11)) return slow();   // also NaN, 0 and infinities
  std::uint64_t bits;
  std::memcpy(&bits, &v, sizeof bits);
  const int biased = static_cast<int>((bits >> 52) & 0x7ff);
  const std::uint64_t m = (bits & ((std::uint64_t{1} << 52) - 1)) | (std::uint64_t{1} << 52);
  const int e = biased - 1075;   // v = +-m * 2^e, e in [-1075+..., 0)
  static constexpr std::uint64_t kPow10[] = {1ULL, 10ULL, 100ULL, 1000ULL, 10000ULL, 100000ULL, 1000000ULL, 10000000ULL,
                                             100000000ULL, 1000000000ULL, 10000000000ULL, 100000000000ULL,
                                             1000000000000ULL, 10000000000000ULL, 100000000000000ULL,
                                             1000000000000000ULL, 10000000000000000ULL, 100000000000000000ULL};
  // floor(log10 |v|) from the binary exponent (within one; corrected below).
  int exp10 = ((biased - 1023) * 78913) >> 18;
  std::uint64_t n = 0;
  for (int attempt = 0;; ++attempt) {
    if (attempt == 3) return slow();
    const int k = 11 - exp10;                 // n = round(|v| * 10^k), 12 digits
    if (k < 0 || k > 17 || -e >= 127) return slow();
    const uint128_for_text scaled = static_cast<uint128_for_text>(m) * kPow10[k];   // < 2^53 * 2^57
    const int shift = -e;
    if (shift <= 0) return slow();
    const uint128_for_text q = scaled >> shift;
    const uint128_for_text rem = scaled - (q << shift);
    const uint128_for_text half = static_cast<uint128_for_text>(1) << (shift - 1);
    if (rem == half) return slow();           // an exact tie: leave the rounding rule to to_chars
    n = static_cast<std::uint64_t>(q) + (rem > half ? 1 : 0);
    if (n >= kPow10[12]) {
      if (n == kPow10[12] && static_cast<std::uint64_t>(q) < kPow10[12]) {   // rounded up to 10^12
        n = kPow10[11];
        ++exp10;
        break;
      }
      ++exp10;
      continue;
    }
    if (n < kPow10[11]) {
      --exp10;
      continue;
    }
    break;
  }
  // Two digits at a time from a table (six divisions by 100 instead of twelve by 10).
  static constexpr char kTwoDigits[] =
      "00010203040506070809101112131415161718192021222324252627282930313233343536373839"
      "40414243444546474849505152535455565758596061626364656667686970717273747576777879"
      "8081828384858687888990919293949596979899";
  char digits[12];
  for (int i = 10; i >= 0; i -= 2) {
    const auto pair = static_cast<std::size_t>(n % 100);
    n /= 100;
    digits[i] = kTwoDigits[2 * pair];
    digits[i + 1] = kTwoDigits[2 * pair + 1];
  }
  int nd = 12;
  while (nd > 1 && digits[nd - 1] == '0') --nd;
  if (end - out < 24) return slow();
  char* o = out;
  if (v < 0) *o++ = '-';
  if (exp10 < -4) {   // scientific: d.ddde-XX (exp10 >= -5 here)
    *o++ = digits[0];
    if (nd > 1) {
      *o++ = '.';
      for (int i = 1; i < nd; ++i) *o++ = digits[i];
    }
    *o++ = 'e';
    *o++ = '-';
    *o++ = '0';
    *o++ = static_cast<char>('0' - exp10);
  } else if (exp10 >= 0) {
    for (int i = 0; i <= exp10; ++i) *o++ = i < nd ? digits[i] : '0';
    if (nd > exp10 + 1) {
      *o++ = '.';
      for (int i = exp10 + 1; i < nd; ++i) *o++ = digits[i];
    }
  } else {
    *o++ = '0';
    *o++ = '.';
    for (int i = 0; i < -exp10 - 1; ++i) *o++ = '0';
    for (int i = 0; i < nd; ++i) *o++ = digits[i];
  }
  return o;
}

}  // namespace physval
