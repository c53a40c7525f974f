// write_shortest_float (common/float_text.hpp) writes exactly what std::to_chars writes. Checked
// once over every positive finite float (2^31 values, ~1 minute); here over whole binades at
// both ends of its own range and the most common one, the edges of that range, every power
// of two, and random bit patterns of every magnitude and sign.
#include "common/float_text.hpp"

#include <gtest/gtest.h>

#include <charconv>
#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <string>

namespace avatarmap::io_detail {
namespace {

float from_bits(std::uint32_t u) {
  float f;
  std::memcpy(&f, &u, 4);
  return f;
}

::testing::AssertionResult same_as_to_chars(float v) {
  char mine[32], theirs[32];
  std::memset(mine, 'x', sizeof mine);
  const char* end = write_shortest_float(mine, v);
  const char* ref = std::to_chars(theirs, theirs + sizeof theirs, v).ptr;
  const std::string a(static_cast<const char*>(mine), end),
      b(static_cast<const char*>(theirs), ref);
  if (a == b) return ::testing::AssertionSuccess();
  std::uint32_t u;
  std::memcpy(&u, &v, 4);
  return ::testing::AssertionFailure()
         << std::hex << u << ": wrote '" << a << "', to_chars '" << b << "'";
}

// Every float with biased exponent `biased` (one binade), positive and negative.
void check_binade(std::uint32_t biased) {
  for (std::uint32_t m = 0; m < (1u << 23); ++m) {
    const std::uint32_t u = (biased << 23) | m;
    ASSERT_TRUE(same_as_to_chars(from_bits(u)));
    if ((m & 0xfff) == 0) ASSERT_TRUE(same_as_to_chars(from_bits(u | 0x80000000u)));
  }
}

TEST(float_text, whole_binades_match_to_chars) {
  check_binade(91);   // [2^-36, 2^-35): the smallest the own path writes
  check_binade(126);  // [0.5, 1): most quaternion components
  check_binade(150);  // [2^23, 2^24): the largest, integers
}

TEST(float_text, edges_powers_of_two_and_specials_match_to_chars) {
  for (std::uint32_t biased = 1; biased < 255; ++biased) {
    for (std::uint32_t m : {0u, 1u, 2u, 0x400000u, 0x7ffffeu, 0x7fffffu}) {
      ASSERT_TRUE(same_as_to_chars(from_bits((biased << 23) | m)));
      ASSERT_TRUE(same_as_to_chars(from_bits(0x80000000u | (biased << 23) | m)));
    }
  }
  for (float v : {0.f,
                  -0.f,
                  1.f,
                  -1.f,
                  0.1f,
                  0.2f,
                  0.3f,
                  1e-5f,
                  1e-4f,
                  1e-3f,
                  123456.7f,
                  1234567.f,
                  16777215.f,
                  16777216.f,
                  5e-12f,
                  7.2759576e-12f,
                  std::numeric_limits<float>::denorm_min(),
                  std::numeric_limits<float>::min(),
                  std::numeric_limits<float>::max(),
                  std::numeric_limits<float>::lowest()})
    ASSERT_TRUE(same_as_to_chars(v));
}

TEST(float_text, random_floats_match_to_chars) {
  std::mt19937 rng(3);
  std::uniform_int_distribution<std::uint32_t> any;
  std::uniform_real_distribution<float> unit(-1.f, 1.f);
  for (int i = 0; i < 2000000; ++i) {
    const float v = i % 2 ? unit(rng) : from_bits(any(rng));
    if (!std::isfinite(v)) continue;
    ASSERT_TRUE(same_as_to_chars(v));
  }
}

}  // namespace
}  // namespace avatarmap::io_detail
