// lift_low_light (include/avatarmap/capture/low_light.hpp): known answers on small tensors.
// The expected values are computed here from the header's formula, not taken from the code.
#include "avatarmap/capture/low_light.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

namespace avatarmap {
namespace {

// A W x H tensor of grey pixels: the left half at `a`, the right half at `b` (values of [0, 1]).
std::vector<float> halves(int w, int h, float a, float b) {
  std::vector<float> t(static_cast<std::size_t>(w) * h * 3);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      for (int c = 0; c < 3; ++c)
        t[(static_cast<std::size_t>(y) * w + x) * 3 + c] = x < w / 2 ? a : b;
  return t;
}

crop_options options_of(int w, int h, float range_min = 0.f, float range_max = 1.f) {
  crop_options o;
  o.output_width = w;
  o.output_height = h;
  o.range_min = range_min;
  o.range_max = range_max;
  return o;
}

// The header's formula for a grey value v of [0, 1] with luma percentiles lo, hi.
float expected(float v, float lo, float hi, const low_light_options& l) {
  const float gain = std::clamp(l.target_range / (hi - lo), 1.f, l.max_gain);
  const float m = 0.5f * (lo + hi);
  return std::clamp((v - m) * gain + m + (0.5f - m) * (1.f - 1.f / gain), 0.f, 1.f);
}

TEST(low_light, a_wide_range_is_left_bit_for_bit) {
  const crop_options o = options_of(16, 8);
  std::vector<float> t = halves(16, 8, 0.2f, 0.6f);  // range 0.4 >= 0.3
  t[5] = 0.123456789f;                               // one odd value: still untouched
  const std::vector<float> before = t;
  EXPECT_EQ(lift_low_light(t.data(), o, crop_transform{}), 1.f);
  EXPECT_EQ(t, before);
}

TEST(low_light, a_narrow_range_is_stretched_to_the_target_about_its_middle) {
  const crop_options o = options_of(16, 8);
  // Two greys 0.1 apart (on the histogram's 1/1023 grid): gain 0.3 / 0.1 = 3.
  const float a = 100.f / 1023.f, b = 200.f / 1023.f;
  std::vector<float> t = halves(16, 8, a, b);
  const low_light_options l;
  const float gain = lift_low_light(t.data(), o, crop_transform{}, l);
  EXPECT_NEAR(gain, 0.3f / (b - a), 1e-5f);
  EXPECT_NEAR(t[0], expected(a, a, b, l), 1e-5f);
  EXPECT_NEAR(t[3 * 15], expected(b, a, b, l), 1e-5f);
  EXPECT_NEAR(t[3 * 15] - t[0], 0.3f, 1e-5f);  // the range is now the target
  // The middle moved toward mid-grey by (1 - 1/gain) of the way.
  const float m = 0.5f * (a + b);
  EXPECT_NEAR(0.5f * (t[0] + t[3 * 15]), m + (0.5f - m) * (1.f - 1.f / gain), 1e-5f);
}

TEST(low_light, the_gain_stops_at_max_gain_and_values_stay_in_range) {
  // A [-1, 1] input (the pose detector's): greys 0.01 apart of [0, 1], far below 0.3 / 8.
  const crop_options o = options_of(8, 8, -1.f, 1.f);
  const float a = 10.f / 1023.f, b = 20.f / 1023.f;  // of [0, 1]
  std::vector<float> t = halves(8, 8, -1.f + 2.f * a, -1.f + 2.f * b);
  low_light_options l;
  l.max_gain = 8.f;
  EXPECT_FLOAT_EQ(lift_low_light(t.data(), o, crop_transform{}, l), 8.f);
  EXPECT_NEAR((t[3 * 7] - t[0]) / 2.f, 8.f * (b - a), 1e-5f);  // back in [0, 1] units
  EXPECT_NEAR((t[0] + 1.f) / 2.f, expected(a, a, b, l), 1e-5f);
  for (float v : t) {
    EXPECT_GE(v, -1.f);
    EXPECT_LE(v, 1.f);
  }
}

TEST(low_light, letterbox_bands_are_neither_counted_nor_changed) {
  // A 10 x 10 tensor with 2-pixel black bands top and bottom (the detector's letterbox): the
  // picture between them spans 0.4 .. 0.5. Counted, the black bands would widen the range to
  // 0.5 and nothing would be lifted.
  const crop_options o = options_of(10, 10);
  crop_transform tr;
  tr.letterbox_padding = {0.f, 0.2f, 0.f, 0.2f};
  const float a = 409.f / 1023.f, b = 511.f / 1023.f;
  std::vector<float> t = halves(10, 10, a, b);
  for (int y : {0, 1, 8, 9})
    for (int i = 0; i < 30; ++i) t[static_cast<std::size_t>(y) * 30 + i] = 0.f;
  const low_light_options l;
  EXPECT_NEAR(lift_low_light(t.data(), o, tr, l), 0.3f / (b - a), 1e-4f);
  for (int y : {0, 1, 8, 9})
    for (int i = 0; i < 30; ++i) EXPECT_EQ(t[static_cast<std::size_t>(y) * 30 + i], 0.f);
  EXPECT_NEAR(t[2 * 30], expected(a, a, b, l), 1e-5f);
}

TEST(low_light, percentiles_ignore_the_odd_bright_pixel) {
  // A dark picture with one white pixel in 400 (under 1 %): it does not set the range.
  const crop_options o = options_of(20, 20);
  const float a = 50.f / 1023.f, b = 100.f / 1023.f;
  std::vector<float> t = halves(20, 20, a, b);
  for (int c = 0; c < 3; ++c) t[static_cast<std::size_t>(c)] = 1.f;
  EXPECT_NEAR(lift_low_light(t.data(), o, crop_transform{}), 0.3f / (b - a), 1e-4f);
}

TEST(low_light, bad_arguments_change_nothing) {
  const crop_options o = options_of(4, 4);
  std::vector<float> t = halves(4, 4, 0.1f, 0.11f);
  const std::vector<float> before = t;
  EXPECT_EQ(lift_low_light(nullptr, o, crop_transform{}), 1.f);
  low_light_options off;
  off.max_gain = 1.f;
  EXPECT_EQ(lift_low_light(t.data(), o, crop_transform{}, off), 1.f);
  crop_options flat = o;
  flat.range_max = flat.range_min;
  EXPECT_EQ(lift_low_light(t.data(), flat, crop_transform{}), 1.f);
  EXPECT_EQ(t, before);
}

}  // namespace
}  // namespace avatarmap
