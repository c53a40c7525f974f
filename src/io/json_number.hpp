// Internal: a JSON number read as the correctly rounded float, fast. The landmark and pose
// files hold little else (a full holistic frame is ~2,000 numbers such as -0.018443659), so
// this is most of the readers' time. No stability promise.
//
// Two paths give the value std::from_chars gives (correctly rounded, ties to even), or leave
// the token to the caller's exact path (std::from_chars) by returning nullptr:
//  - vector (x86-64, SSE2): the token's end is found first (the first ',', ']' or '}' among
//    the next 16 bytes; the landmark reader finds them 64 bytes at a time). A token of the
//    plain form -?D or -?D.F (one integer digit, 1 to 13 fraction digits: MediaPipe's
//    coordinates) then has its fraction digits checked and converted together in one 16-byte
//    register, right-aligned by loading the 16 bytes that end at the token's end, and its
//    value m / 10^n (m < 10^14, exact as a double) is rounded as m * fl(10^-n): two roundings,
//    so the double d is within 2.0001 units in its last place (ulp) of the true value, and d
//    rounds to the same float as the true value unless a float midpoint lies within 2 ulps of
//    d; d within 4 ulps of a midpoint goes to the exact path. The next token's position
//    depends only on the delimiter search, not on the digits, so the processor works on
//    several numbers at once, and there is no branch per digit;
//  - digits: any other token (white space before the delimiter, several integer digits, an
//    exponent), the ends of the line, other processors: one digit at a time, then Clinger's
//    fast path: a mantissa m <= 2^53 and 10^k with |k| <= 22 are exact doubles, so one IEEE
//    division or multiplication gives the correctly rounded double d, which rounds to the
//    correctly rounded float unless d lies exactly halfway between two floats (the true value
//    may not). Those, and subnormal or out-of-range results, go to the exact path.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>

#if defined(__GNUC__) || defined(__clang__)
#define AVATARMAP_JSON_INLINE inline __attribute__((always_inline))
#else
#define AVATARMAP_JSON_INLINE inline
#endif

#if defined(__x86_64__) || defined(_M_X64)
#include <emmintrin.h>
#define AVATARMAP_JSON_SSE2 1
#else
#define AVATARMAP_JSON_SSE2 0
#endif

namespace avatarmap::io_detail {

/// The vector path reads up to this many bytes from a number's first character, and up to
/// k_float_scan_lookback bytes before its token's end; nearer the ends of the line the
/// digit path runs. No byte outside the line is read.
inline constexpr std::ptrdiff_t k_float_scan_margin = 32;
inline constexpr std::ptrdiff_t k_float_scan_lookback = 16;

namespace number_detail {

inline bool g_vector_path = true;

inline constexpr double k_pow10[23] = {1e0,  1e1,  1e2,  1e3,  1e4,  1e5,  1e6,  1e7,
                                       1e8,  1e9,  1e10, 1e11, 1e12, 1e13, 1e14, 1e15,
                                       1e16, 1e17, 1e18, 1e19, 1e20, 1e21, 1e22};

// m * 10^e as a float when that is certainly the correctly rounded value (see the top of the
// file); false otherwise. |e| <= 22, m <= 2^53.
inline bool exact_float(std::uint64_t m, int e, bool negative, float& out) {
  double d = static_cast<double>(m);
  d = e < 0 ? d / k_pow10[-e] : d * k_pow10[e];
  if (m != 0 && !(d >= 1.1754943508222875e-38 && d <= 3.4028234663852886e38)) return false;
  std::uint64_t bits;
  std::memcpy(&bits, &d, sizeof bits);
  // A float midpoint has a 1 followed by 28 zeros below the float's last mantissa bit.
  if ((bits & 0x1fffffffu) == 0x10000000u) return false;
  const float f = static_cast<float>(d);
  out = negative ? -f : f;
  return true;
}

#if AVATARMAP_JSON_SSE2
inline constexpr std::uint64_t k_pow10_int[14] = {
    1u,           10u,           100u,           1000u,          10000u,
    100000u,      1000000u,      10000000u,      100000000u,     1000000000u,
    10000000000u, 100000000000u, 1000000000000u, 10000000000000u};

inline constexpr double k_pow10_neg[14] = {1e-0, 1e-1, 1e-2, 1e-3,  1e-4,  1e-5,  1e-6,
                                           1e-7, 1e-8, 1e-9, 1e-10, 1e-11, 1e-12, 1e-13};

// Loaded at offset n: 16 - n zero bytes, then n 0xff bytes (keeps the last n bytes).
alignas(16) inline constexpr unsigned char k_last_bytes[32] = {
    0,    0,    0,    0,    0,    0,    0,    0,    0,    0,    0,    0,    0,    0,    0,    0,
    0xff, 0xff, 0xff, 0xff, 0xff, 0xff, 0xff, 0xff, 0xff, 0xff, 0xff, 0xff, 0xff, 0xff, 0xff, 0xff};

// Index of the lowest set bit of x != 0.
AVATARMAP_JSON_INLINE int lowest_bit(std::uint64_t x) {
#if defined(__GNUC__) || defined(__clang__)
  return __builtin_ctzll(x);
#else
  int n = 0;
  for (; (x & 1u) == 0; x >>= 1) ++n;
  return n;
#endif
}

// 0xff in each byte of v that is ',', ']' or '}' (']' | 0x20 is '}', and no other byte is).
AVATARMAP_JSON_INLINE __m128i delimiter_bytes(__m128i v) {
  return _mm_or_si128(_mm_cmpeq_epi8(v, _mm_set1_epi8(',')),
                      _mm_cmpeq_epi8(_mm_or_si128(v, _mm_set1_epi8(0x20)), _mm_set1_epi8('}')));
}

// Offset of the first ',', ']' or '}' among the 16 bytes at p, or 16 when there is none.
AVATARMAP_JSON_INLINE int delimiter_offset(const char* p) {
  const __m128i hit = delimiter_bytes(_mm_loadu_si128(reinterpret_cast<const __m128i*>(p)));
  return lowest_bit(static_cast<unsigned>(_mm_movemask_epi8(hit)) | 0x10000u);
}

// Bit i set when p[i] is ',', ']' or '}', for the 64 bytes at p.
inline std::uint64_t delimiter_mask64(const char* p) {
  std::uint64_t mask = 0;
  for (int i = 0; i < 4; ++i) {
    const __m128i hit =
        delimiter_bytes(_mm_loadu_si128(reinterpret_cast<const __m128i*>(p + 16 * i)));
    mask |= static_cast<std::uint64_t>(static_cast<unsigned>(_mm_movemask_epi8(hit))) << (16 * i);
  }
  return mask;
}

// The value of the n (1 to 16) characters before e when all are ASCII digits; false
// otherwise. Reads the 16 bytes before e. Digit pairs, then fours, then eights are combined
// with multiply-adds (SSE2 has no byte multiply-add).
AVATARMAP_JSON_INLINE bool digits_before(const char* e, int n, std::uint64_t& out) {
  const __m128i text = _mm_loadu_si128(reinterpret_cast<const __m128i*>(e - 16));
  const __m128i keep = _mm_loadu_si128(reinterpret_cast<const __m128i*>(k_last_bytes + n));
  const __m128i d = _mm_and_si128(_mm_sub_epi8(text, _mm_set1_epi8('0')), keep);
  // A byte above 9 (unsigned) was not a digit.
  const __m128i over = _mm_subs_epu8(d, _mm_set1_epi8(9));
  if (_mm_movemask_epi8(_mm_cmpeq_epi8(over, _mm_setzero_si128())) != 0xffff) return false;
  // Each 16-bit lane holds two digits, the more significant in the low byte.
  const __m128i pairs =
      _mm_add_epi16(_mm_mullo_epi16(_mm_and_si128(d, _mm_set1_epi16(0xff)), _mm_set1_epi16(10)),
                    _mm_srli_epi16(d, 8));
  const __m128i fours = _mm_madd_epi16(pairs, _mm_set1_epi32((1 << 16) | 100));
  const __m128i fours16 = _mm_packs_epi32(fours, fours);  // each <= 9999
  const __m128i eights = _mm_madd_epi16(fours16, _mm_set1_epi32((1 << 16) | 10000));
  const auto both = static_cast<std::uint64_t>(_mm_cvtsi128_si64(eights));
  out = (both & 0xffffffffu) * 100000000u + (both >> 32);
  return true;
}

// The number whose token is exactly [p, e) (1 to 15 characters), when it has the plain form
// -?D or -?D.F with one integer digit D and 1 to 13 fraction digits F (MediaPipe's
// coordinates); false, storing nothing, for anything else. Reads the 16 bytes before e.
AVATARMAP_JSON_INLINE bool plain_decimal(const char* p, const char* e, float& out) {
  const bool negative = *p == '-';
  const char* s = p + (negative ? 1 : 0);
  const unsigned d0 = static_cast<unsigned char>(s[0]) - unsigned{'0'};
  if (d0 > 9) return false;
  if (s + 1 == e) return exact_float(d0, 0, negative, out);
  if (s[1] != '.') return false;  // several integer digits, a leading zero, an exponent
  const int nf = static_cast<int>(e - s) - 2;
  std::uint64_t fraction = 0;
  if (nf < 1 || !digits_before(e, nf, fraction)) return false;
  // At most 14 digits: m < 10^14 < 2^53, exact as a double. m * fl(10^-nf) is within 2.0001
  // ulp of m / 10^nf (see the top of the file); a value in [1e-13, 10) is a normal float.
  const auto m = static_cast<std::int64_t>(d0 * k_pow10_int[nf] + fraction);
  const double d = static_cast<double>(m) * k_pow10_neg[nf];
  std::uint64_t bits;
  std::memcpy(&bits, &d, sizeof bits);
  // A float midpoint has a 1 followed by 28 zeros below the float's last mantissa bit: the
  // low 29 bits of d within [-4, +3] of that are too close to decide.
  if (((bits + 4) & 0x1ffffff8u) == 0x10000000u) return false;
  const float f = static_cast<float>(d);
  out = negative ? -f : f;
  return true;
}
#endif

}  // namespace number_detail

/// Test hook: false sends every number (and every landmark point) through the digit path,
/// so that tests can compare the two. Not thread-safe; not for production use.
inline bool& json_vector_path() { return number_detail::g_vector_path; }

/// The digit-at-a-time path of json_scan_float (any position on the line, any processor).
inline const char* json_scan_float_digits(const char* p, const char* end, float& out) {
  using namespace number_detail;
  const char* q = p;
  bool negative = false;
  if (q < end && *q == '-') {
    negative = true;
    ++q;
  }
  if (q >= end || *q < '0' || *q > '9') return nullptr;
  std::uint64_t m = 0;
  int digits = 0;  // all digits read into m; at most 19 so that m cannot overflow
  int exp10 = 0;
  if (*q == '0') {
    ++q;
    if (q < end && *q >= '0' && *q <= '9') return nullptr;  // leading zero: not JSON
  } else {
    while (q < end && *q >= '0' && *q <= '9') {
      if (++digits > 19) return nullptr;
      m = m * 10 + static_cast<unsigned>(*q - '0');
      ++q;
    }
  }
  if (q < end && *q == '.') {
    ++q;
    const char* first = q;
    while (q < end && *q >= '0' && *q <= '9') {
      if (++digits > 19) return nullptr;
      m = m * 10 + static_cast<unsigned>(*q - '0');
      --exp10;
      ++q;
    }
    if (q == first) return nullptr;  // "1." is not JSON
  }
  if (m > (std::uint64_t{1} << 53)) return nullptr;
  if (q < end && (*q == 'e' || *q == 'E')) {
    ++q;
    bool eneg = false;
    if (q < end && (*q == '+' || *q == '-')) eneg = *q++ == '-';
    if (q >= end || *q < '0' || *q > '9') return nullptr;
    int e = 0;
    while (q < end && *q >= '0' && *q <= '9') {
      if (e > 1000) return nullptr;
      e = e * 10 + (*q - '0');
      ++q;
    }
    exp10 += eneg ? -e : e;
  }
  if (exp10 < -22 || exp10 > 22) return nullptr;
  return exact_float(m, exp10, negative, out) ? q : nullptr;
}

/// Reads the JSON number token at `p` (RFC 8259: optional '-', no leading zeros, digits after
/// '.' and after 'e') on the line [begin, end) as the correctly rounded float (what
/// std::from_chars gives) and returns the end of the token. Returns nullptr, storing
/// nothing, when the text there is not a JSON number or when the value needs the exact path
/// (more than 19 significant digits, a decimal exponent beyond +-22, a float midpoint, a
/// subnormal or out-of-range result). Whatever follows the token is the caller's to check.
AVATARMAP_JSON_INLINE const char* json_scan_float(const char* begin, const char* p, const char* end,
                                                  float& out) {
#if AVATARMAP_JSON_SSE2
  using namespace number_detail;
  if (end - p >= k_float_scan_margin && p - begin >= k_float_scan_lookback &&
      number_detail::g_vector_path) {
    const char* e = p + delimiter_offset(p);
    if (e != p && e != p + 16 && plain_decimal(p, e, out)) return e;
  }
#else
  (void)begin;
#endif
  return json_scan_float_digits(p, end, out);
}

}  // namespace avatarmap::io_detail
