// %.12g text of a double (what std::to_chars(general, 12) gives), byte for byte, about
// three times as fast (BM_SeriesNumberText) for the magnitudes series hold (1e-5 <= |v| < 1e11): the 12 digits come
// from exact integer arithmetic (the mantissa times a power of ten in 128 bits, rounded
// to nearest); exact ties, other magnitudes, zero, NaN and infinities go to std::to_chars.
// The series CSVs are most of what physval writes (test NumberText.*).
#pragma once

#include <bit>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>

namespace physval {

// GCC's 128-bit integer (a 53-bit mantissa times a power of ten up to 10^17 needs it);
// __extension__ says so to -Wpedantic.
__extension__ typedef unsigned __int128 uint128_for_text;

[[gnu::always_inline]] inline char* to_chars_g12(char* out, char* end, double v) {
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
  static constexpr double kPow10d[] = {1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9,
                                       1e10, 1e11, 1e12, 1e13, 1e14, 1e15, 1e16, 1e17};
  std::uint64_t n = 0;
  for (int attempt = 0;; ++attempt) {
    if (attempt == 3) return slow();
    const int k = 11 - exp10;                 // n = round(|v| * 10^k), 12 digits
    if (k < 0 || k > 17 || -e >= 127) return slow();
    // First in double: 10^k (k <= 17 < 23) is exact, so y is |v| 10^k to within half an ulp
    // of y. Kept only for y < 10^12 < 2^40 (half an ulp 2^-14 at most; a larger y, up to
    // 10^13 as exp10 is at most one below floor(log10 |v|), only moves exp10 up, and is
    // above 10^12 - 0.5 by far more than its error): unless y lies within 2^-12 of a half,
    // y and the exact product round to the same integer (y + 0.5 and the truncations are
    // exact below 2^52). Near a half the exact 128-bit product below decides.
    {
      const double y = a * kPow10d[k];   // < 10^12 x 10 (exp10 at most one too low)
      const auto whole = static_cast<std::uint64_t>(y);
      if (std::fabs((y - static_cast<double>(whole)) - 0.5) > 0x1p-12) {
        n = static_cast<std::uint64_t>(y + 0.5);
        if (n >= kPow10[12]) {
          ++exp10;
          continue;
        }
        if (n < kPow10[11]) {
          --exp10;
          continue;
        }
        break;
      }
    }
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
  // The 12 digits, as characters, in one 128-bit value (digit i in byte i, bytes 12-15
  // '0'), made from two 6-digit halves of three table pairs each (short, independent chains
  // of 32-bit divisions by constants), then placed with shifts and stored in whole 16-byte
  // blocks: no digit is stored byte by byte and read back.
  static constexpr char kTwoDigits[] =
      "00010203040506070809101112131415161718192021222324252627282930313233343536373839"
      "40414243444546474849505152535455565758596061626364656667686970717273747576777879"
      "8081828384858687888990919293949596979899";
  if constexpr (std::endian::native != std::endian::little) return slow();
  const auto pair = [&](std::uint32_t x) {
    std::uint16_t p;
    std::memcpy(&p, kTwoDigits + 2 * x, 2);
    return static_cast<std::uint64_t>(p);
  };
  const auto six = [&](std::uint32_t x) {   // 6 characters in the low 48 bits
    const std::uint32_t hi = x / 10000, bc = x % 10000;
    return pair(hi) | pair(bc / 100) << 16 | pair(bc % 100) << 32;
  };
  const std::uint64_t hi6 = six(static_cast<std::uint32_t>(n / 1000000));
  const std::uint64_t lo6 = six(static_cast<std::uint32_t>(n % 1000000));
  const std::uint64_t w0 = hi6 | lo6 << 48;
  const std::uint64_t w1 = lo6 >> 16 | std::uint64_t{0x30303030} << 32;
  const uint128_for_text digits = static_cast<uint128_for_text>(w1) << 64 | w0;
  // Significant digits: up to the last one that is not '0' (digit 0 never is: n >= 10^11).
  constexpr std::uint64_t kZeros = 0x3030303030303030ULL;
  const std::uint64_t z0 = w0 - kZeros, z1 = w1 - kZeros;   // each byte its digit's value
  const int nd = z1 != 0 ? 8 + (63 - __builtin_clzll(z1)) / 8 + 1 : (63 - __builtin_clzll(z0)) / 8 + 1;
  // Every store below stays within out + 32 (a sign, at most "0.000", then one 16-byte
  // block), so the caller's end must leave 32 bytes.
  if (end - out < 32) return slow();
  const auto store16 = [](char* at, uint128_for_text x) { std::memcpy(at, &x, 16); };
  char* o = out;
  *o = '-';
  o += v < 0 ? 1 : 0;
  if (exp10 < -4) {   // scientific: d.ddde-05 (exp10 >= -5 here)
    const auto first = static_cast<char>(w0 & 0xff);
    if (nd > 1) {
      store16(o, (digits >> 8) << 16 | static_cast<uint128_for_text>('.') << 8 | static_cast<unsigned char>(first));
      o += nd + 1;
    } else {
      *o++ = first;
    }
    std::memcpy(o, "e-0", 3);
    o[3] = static_cast<char>('0' - exp10);
    o += 4;
  } else if (exp10 >= 0) {   // ddd[.ddd]: an integer part of exp10 + 1 <= 11 digits
    const int whole = exp10 + 1;
    if (nd > whole) {
      const uint128_for_text low = digits & ((static_cast<uint128_for_text>(1) << (8 * whole)) - 1);
      store16(o, low | static_cast<uint128_for_text>('.') << (8 * whole) | (digits >> (8 * whole)) << (8 * whole + 8));
      o += nd + 1;
    } else {
      store16(o, digits);   // the padding '0's fill an integer part longer than nd
      o += whole;
    }
  } else {   // 0.[000]ddd: -exp10 - 1 <= 3 zeros after the point
    std::memcpy(o, "0.000", 5);
    o += 1 - exp10;
    store16(o, digits);
    o += nd;
  }
  return o;
}

}  // namespace physval
