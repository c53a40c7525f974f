// Internal: a float as the shortest decimal text that reads back as the same float: exactly
// the characters std::to_chars(first, last, value) writes, faster for the magnitudes the pose
// and landmark files hold. No stability promise.
//
// A positive float is c * 2^q with an integer c < 2^24. Reading text back rounds to the
// nearest float (ties to even), so the text may be any decimal in the rounding interval
// [v - 2^(q-1), v + 2^(q-1)] (the lower half is 2^(q-2) when c = 2^23: the float below is
// closer), endpoints included when c is even. With 10^k the largest power of ten not above
// the interval's width, the interval holds at least one multiple of 10^k and at most one of
// 10^(k+1). The shortest text is that multiple of 10^(k+1) when there is one (trailing zeros
// dropped); otherwise the multiple of 10^k nearest to v (ties to even), which is one of the
// two around v. All of it is exact integer arithmetic: for 2^-36 <= v < 2^24 (q from -59 to
// 0) the endpoints scaled by 10^-k * 2^(2-q) fit 128 bits. Other values (zero, subnormals,
// very small or large, non-finite) are std::to_chars's. Then fixed or scientific notation,
// whichever is shorter (fixed on a tie), as std::to_chars chooses.
#pragma once

#include <charconv>
#include <cstddef>
#include <cstdint>
#include <cstring>

// The own path needs unsigned __int128 and stores it as bytes, least significant first.
#if defined(__SIZEOF_INT128__) && (defined(__GNUC__) || defined(__clang__)) && \
    defined(__BYTE_ORDER__) && __BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__
#define AVATARMAP_FLOAT_TEXT_INT128 1
#else
#define AVATARMAP_FLOAT_TEXT_INT128 0
#endif

namespace avatarmap::io_detail {

#if AVATARMAP_FLOAT_TEXT_INT128
namespace float_text_detail {

inline constexpr std::uint64_t k_pow10[20] = {1u,
                                              10u,
                                              100u,
                                              1000u,
                                              10000u,
                                              100000u,
                                              1000000u,
                                              10000000u,
                                              100000000u,
                                              1000000000u,
                                              10000000000u,
                                              100000000000u,
                                              1000000000000u,
                                              10000000000000u,
                                              100000000000000u,
                                              1000000000000000u,
                                              10000000000000000u,
                                              100000000000000000u,
                                              1000000000000000000u,
                                              10000000000000000000u};

// 5^n for n <= 16.
inline constexpr std::uint64_t k_pow5[17] = {
    1u,         5u,          25u,         125u,         625u,         3125u,
    15625u,     78125u,      390625u,     1953125u,     9765625u,     48828125u,
    244140625u, 1220703125u, 6103515625u, 30517578125u, 152587890625u};

// The eight decimal digits of x < 10^8 as ASCII, the most significant in byte 0: halves of
// four digits in 32-bit lanes, then pairs in 16-bit lanes, then single digits in bytes
// (divisions by 100 and 10 as multiply-shifts, exact in these ranges).
inline std::uint64_t eight_ascii_digits(std::uint32_t x) {
  const std::uint64_t fours = (x / 10000u) | (static_cast<std::uint64_t>(x % 10000u) << 32);
  const std::uint64_t hundreds = ((fours * 5243u) >> 19) & 0x0000007f0000007fu;  // / 100
  const std::uint64_t pairs = hundreds | ((fours - hundreds * 100u) << 16);
  const std::uint64_t tens = ((pairs * 103u) >> 10) & 0x000f000f000f000fu;  // / 10
  return (tens | ((pairs - tens * 10u) << 8)) | 0x3030303030303030u;
}

// Number of decimal digits of 0 < d < 10^10.
inline int digit_count(std::uint64_t d) {
  // floor(log10(d)) from floor(log2(d)) (1233 / 4096 ~ log10(2)), then one comparison.
  const int log2 = 63 - __builtin_clzll(d);
  const int guess = (log2 + 1) * 1233 >> 12;
  return guess + (d >= k_pow10[guess] ? 1 : 0);
}

}  // namespace float_text_detail
#endif

/// Room write_shortest_float needs at `out`: it writes 16-byte blocks up to 31 bytes on,
/// of which at most 15 bytes are the text.
inline constexpr std::size_t k_shortest_float_room = 32;

/// The characters std::to_chars(out, out + 16, v) writes for a finite float v, written at
/// `out`, which must have k_shortest_float_room bytes of room; returns their end.
inline char* write_shortest_float(char* out, float v) {
#if AVATARMAP_FLOAT_TEXT_INT128
  using namespace float_text_detail;
  __extension__ typedef unsigned __int128 u128;  // __extension__: no -Wpedantic warning
  std::uint32_t bits;
  std::memcpy(&bits, &v, sizeof bits);
  const std::uint32_t biased = (bits >> 23) & 0xffu;
  if (biased < 91 || biased > 150) return std::to_chars(out, out + 16, v).ptr;
  if (bits >> 31) *out++ = '-';
  const std::uint64_t c = (bits & 0x7fffffu) | 0x800000u;
  const int s = 150 - static_cast<int>(biased);  // v = c / 2^s, 0 <= s <= 59
  const bool irregular = (bits & 0x7fffffu) == 0;
  const bool closed = (c & 1u) == 0;
  // k = floor(log10(width)), width = 2^-s (or 3/4 of it): -k = ceil(s log10 2) at most 19.
  int minus_k = (s * 78913 + (1 << 18) - 1) >> 18;  // ceil(s * log10(2)) for 0 <= s <= 59
  if (irregular && (u128{3} * k_pow10[minus_k] >> (s + 2)) == 0) ++minus_k;  // 3/4 2^-s < 10^k
  // The first multiple of 10^k at or above the lower end (above it when open), the last at
  // or below the upper, and the one nearest to v (ties to even), inside the interval.
  // Arithmetic rather than branches on the low bits, which are random.
  const unsigned open = closed ? 0u : 1u;
  std::uint64_t lowest, highest, floor, rest, half;
  if (minus_k <= 16) {
    // 10^-k = 5^-k 2^-k: v and the interval's ends in units of 2^-(s+2+k) * 10^k, which
    // fit 64 bits ((4 c + 2) 5^16 < 2^64; s + 2 + k >= 1). Most values take this path.
    const std::uint64_t p = k_pow5[minus_k];
    const int shift = s + 2 - minus_k;
    const std::uint64_t mid = 4 * c * p;
    const std::uint64_t below = mid - (irregular ? p : 2 * p);
    const std::uint64_t above = mid + 2 * p;
    const std::uint64_t unit = std::uint64_t{1} << shift;
    lowest = (below + unit - (1u - open)) >> shift;
    highest = (above - open) >> shift;
    floor = mid >> shift;
    rest = mid & (unit - 1);
    half = unit >> 1;
  } else {
    // v and the interval's ends in units of 2^-(s+2) * 10^k, 128 bits.
    const std::uint64_t p = k_pow10[minus_k];
    const int shift = s + 2;
    const u128 mid = u128{4 * c} * p;
    const u128 below = mid - (irregular ? u128{p} : 2 * u128{p});
    const u128 above = mid + 2 * u128{p};
    const u128 unit = u128{1} << shift;
    lowest = static_cast<std::uint64_t>((below + unit - (1u - open)) >> shift);
    highest = static_cast<std::uint64_t>((above - open) >> shift);
    floor = static_cast<std::uint64_t>(mid >> shift);
    rest = static_cast<std::uint64_t>(mid) & ((std::uint64_t{1} << shift) - 1);
    half = std::uint64_t{1} << (shift - 1);
  }
  std::uint64_t nearest = floor + (rest + (floor & 1u) > half ? 1u : 0u);
  if (nearest > highest) nearest = floor;
  if (nearest < lowest) nearest = floor + 1;
  // The multiple of 10^(k+1) in the interval, when there is one, is shorter.
  const std::uint64_t tens = (lowest + 9) / 10;
  const bool shorter = tens * 10 <= highest;
  std::uint64_t d = shorter ? tens : nearest;
  int k = shorter ? 1 - minus_k : -minus_k;
  while (d % 10 == 0) {
    d /= 10;
    ++k;
  }
  // d * 10^k with d of n digits (d < 10^10): the digits as bytes 0..n-1 of a 128-bit word
  // (zero bytes above), then stores only: building the text in memory and copying it would
  // read back bytes just written in pieces, which the processor cannot forward.
  const int n = digit_count(d);
  const auto high = static_cast<std::uint32_t>(d / 100000000u);  // 0..99
  const u128 ten_digits = (static_cast<u128>(eight_ascii_digits(d % 100000000u)) << 16) |
                          ('0' + high / 10) | (('0' + high % 10) << 8);
  const u128 digits = ten_digits >> (8 * (10 - n));
  const u128 zeros = (static_cast<u128>(0x3030303030303030u) << 64) | 0x3030303030303030u;
  auto store = [](char* at, u128 x) { std::memcpy(at, &x, 16); };
  // Fixed or scientific notation, whichever is shorter (fixed on a tie); |exponent| < 100.
  const int fixed = k >= 0 ? n + k : (n + k > 0 ? n + 1 : 2 - k);
  const int scientific = n + (n > 1 ? 1 : 0) + 4;
  if (fixed <= scientific) {
    if (k >= 0) {  // the digits, then k zeros
      store(out, digits | (zeros << (8 * n)));
      return out + n + k;
    }
    if (n + k > 0) {  // a point among the digits
      store(out, digits);
      store(out + n + k + 1, digits >> (8 * (n + k)));
      out[n + k] = '.';
      return out + n + 1;
    }
    store(out, zeros);  // 0.000ddd
    out[1] = '.';
    store(out + 2 - k - n, digits);
    return out + 2 - k;
  }
  const int exp10 = k + n - 1;
  const int e = exp10 < 0 ? -exp10 : exp10;
  store(out + 1, digits);  // d.ddd: the first digit moves in front of the point
  out[0] = out[1];
  out[1] = '.';
  char* x = out + (n > 1 ? n + 1 : 1);
  x[0] = 'e';
  x[1] = exp10 < 0 ? '-' : '+';
  x[2] = static_cast<char>('0' + e / 10);
  x[3] = static_cast<char>('0' + e % 10);
  return x + 4;
#else
  return std::to_chars(out, out + 16, v).ptr;
#endif
}

}  // namespace avatarmap::io_detail
