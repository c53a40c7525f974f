// overlay_job with several people (overlay_job::people): each person in person_color(id),
// within its own region, over a black outline, with its id written above it; the palette; the
// seven-segment digits; the single-person path untouched by the people fields.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <cstdlib>
#include <limits>
#include <vector>

#include "avatarmap/capture/overlay.hpp"

namespace avatarmap {
namespace {

constexpr int k_w = 360;
constexpr int k_h = 240;
constexpr std::uint8_t k_grey = 128;  // the background: neither the outline nor a colour

struct image {
  std::vector<std::uint8_t> px = std::vector<std::uint8_t>(k_w * k_h * 3, k_grey);
  rgb8_image_ref ref() { return {px.data(), k_w, k_h, k_w * 3}; }
  rgb8_color at(int x, int y) const {
    const std::uint8_t* p = px.data() + (static_cast<std::size_t>(y) * k_w + x) * 3;
    return {p[0], p[1], p[2]};
  }
};

bool same(rgb8_color a, rgb8_color b) { return a.r == b.r && a.g == b.g && a.b == b.b; }

// A stick figure of 33 pose points spread over x in [x0, x1], y in [0.4, 0.95] (normalised),
// every point seen.
landmark_frame figure(int person, float x0, float x1) {
  landmark_frame f;
  f.person = person;
  for (int i = 0; i < k_pose_landmark_count; ++i) {
    f.pose[i].x = x0 + (x1 - x0) * static_cast<float>(i % 5) / 4.f;
    f.pose[i].y = 0.4f + 0.55f * static_cast<float>(i) / (k_pose_landmark_count - 1);
    f.pose[i].visibility = 1.f;
  }
  f.set(frame_part::pose, true);
  return f;
}

struct region {
  int x0, x1;  // pixels
};

TEST(OverlayPeople, PaletteColoursAreDistinctAndLight) {
  for (std::size_t i = 0; i < k_person_palette.size(); ++i) {
    const rgb8_color a = k_person_palette[i];
    // Readable on dark video: a bright channel; on light video the black outline carries it.
    EXPECT_GE(std::max({a.r, a.g, a.b}), 200) << i;
    // Not grey: a saturated hue.
    EXPECT_GE(std::max({a.r, a.g, a.b}) - std::min({a.r, a.g, a.b}), 100) << i;
    for (std::size_t j = 0; j < i; ++j) {
      const rgb8_color b = k_person_palette[j];
      const int d = std::abs(a.r - b.r) + std::abs(a.g - b.g) + std::abs(a.b - b.b);
      EXPECT_GE(d, 150) << i << " vs " << j;
    }
  }
  EXPECT_TRUE(same(person_color(0), k_person_palette[0]));
  EXPECT_TRUE(same(person_color(9), k_person_palette[1]));  // modulo 8
  EXPECT_TRUE(same(person_color(-3), k_person_palette[0]));
}

TEST(OverlayPeople, DigitSegmentsAreTheSevenSegmentFont) {
  // Bits: 0 top, 1 top right, 2 bottom right, 3 bottom, 4 bottom left, 5 top left, 6 middle.
  EXPECT_EQ(overlay_digit_segments(1), 0x06);  // the two on the right
  EXPECT_EQ(overlay_digit_segments(8), 0x7F);  // all seven
  EXPECT_EQ(overlay_digit_segments(0), 0x3F);  // all but the middle
  EXPECT_EQ(overlay_digit_segments(7), 0x07);
  EXPECT_EQ(overlay_digit_segments(4), 0x66);
  EXPECT_EQ(overlay_digit_segments(10), 0);
  EXPECT_EQ(overlay_digit_segments(-1), 0);
}

TEST(OverlayPeople, EachPersonInItsColourWithinItsRegion) {
  const landmark_frame people[3] = {figure(0, 0.05f, 0.28f), figure(1, 0.38f, 0.61f),
                                    figure(5, 0.71f, 0.94f)};
  const region regions[3] = {{18, 101}, {137, 220}, {256, 338}};
  image im;
  overlay_job job;
  job.image = im.ref();
  job.people = people;
  job.people_count = 3;
  ASSERT_TRUE(job.run());
  const int t = overlay_auto_thickness(k_w, k_h);
  const int margin = t + 12;  // lines, joints, outline, and a label a little wider than a body
  long counts[3] = {0, 0, 0};
  long outline = 0, other = 0;
  for (int y = 0; y < k_h; ++y)
    for (int x = 0; x < k_w; ++x) {
      const rgb8_color c = im.at(x, y);
      if (same(c, {k_grey, k_grey, k_grey})) continue;
      if (same(c, {0, 0, 0})) {
        ++outline;
        continue;
      }
      bool known = false;
      for (int k = 0; k < 3; ++k)
        if (same(c, person_color(people[k].person))) {
          known = true;
          ++counts[k];
          EXPECT_GE(x, regions[k].x0 - margin) << "person " << k << " at " << x << "," << y;
          EXPECT_LE(x, regions[k].x1 + margin) << "person " << k << " at " << x << "," << y;
        }
      other += !known;
    }
  EXPECT_EQ(other, 0);  // nothing but the three colours and the outline
  for (int k = 0; k < 3; ++k) EXPECT_GT(counts[k], 100) << k;
  EXPECT_GT(outline, 100);
  // Three distinct colours: person ids 0, 1 and 5 have three palette entries.
  EXPECT_FALSE(same(person_color(0), person_color(1)));
  EXPECT_FALSE(same(person_color(1), person_color(5)));
  EXPECT_FALSE(same(person_color(0), person_color(5)));
}

// The id is written above the person's top point (y 0.4 of the image: row 96), centred on it.
TEST(OverlayPeople, IdIsWrittenAboveThePerson) {
  const int top_row = static_cast<int>(0.4f * k_h);
  auto label_pixels = [&](int id, std::vector<int>& columns) {
    const landmark_frame one[1] = {figure(id, 0.4f, 0.6f)};
    image im;
    overlay_job job;
    job.image = im.ref();
    job.people = one;
    job.people_count = 1;
    EXPECT_TRUE(job.run());
    long n = 0;
    columns.clear();
    for (int y = 0; y < top_row - 1; ++y)
      for (int x = 0; x < k_w; ++x)
        if (same(im.at(x, y), person_color(id))) {
          ++n;
          columns.push_back(x);
        }
    return n;
  };
  std::vector<int> cols1, cols8, cols12;
  const long one = label_pixels(1, cols1);
  const long eight = label_pixels(8, cols8);
  const long twelve = label_pixels(12, cols12);
  EXPECT_GT(one, 0);
  EXPECT_GT(eight, 2 * one);  // seven segments against two
  // "1" is its two right segments: one column band, on the right half of the digit cell.
  const int lo1 = *std::min_element(cols1.begin(), cols1.end());
  const int hi1 = *std::max_element(cols1.begin(), cols1.end());
  const int lo8 = *std::min_element(cols8.begin(), cols8.end());
  const int hi8 = *std::max_element(cols8.begin(), cols8.end());
  EXPECT_LE(hi1 - lo1, overlay_auto_thickness(k_w, k_h) + 2);
  EXPECT_EQ(hi1, hi8);
  EXPECT_GT(lo1, lo8);
  // Centred over the body (x 0.4 .. 0.6 of 360: centre 180).
  EXPECT_NEAR(0.5 * (lo8 + hi8), 180.0, 2.0);
  // Two digits are wider than one.
  const int lo12 = *std::min_element(cols12.begin(), cols12.end());
  const int hi12 = *std::max_element(cols12.begin(), cols12.end());
  EXPECT_GT(hi12 - lo12, hi8 - lo8);
}

// A label that would leave the image is kept inside it.
TEST(OverlayPeople, LabelStaysInsideTheImage) {
  landmark_frame f = figure(3, 0.0f, 0.05f);
  for (landmark& p : f.pose) p.y -= 0.39f;  // the top point at row 2
  image im;
  overlay_job job;
  job.image = im.ref();
  job.people = &f;
  job.people_count = 1;
  ASSERT_TRUE(job.run());
  long label = 0;
  // The label sits to the right of x = 0 and below y = 0: its pixels are in the image, found
  // at the top-left corner.
  for (int y = 0; y < 40; ++y)
    for (int x = 0; x < 40; ++x) label += same(im.at(x, y), person_color(3));
  EXPECT_GT(label, 20);
}

TEST(OverlayPeople, OutlineLiesUnderTheLines) {
  // One horizontal line: shoulders 11-12 across; every other point unseen.
  landmark_frame f;
  f.person = 2;
  for (landmark& p : f.pose) p.x = p.y = std::numeric_limits<float>::quiet_NaN();
  f.pose[11] = {0.25f, 0.75f, 0.f, 1.f, 1.f};
  f.pose[12] = {0.75f, 0.75f, 0.f, 1.f, 1.f};
  f.set(frame_part::pose, true);
  overlay_options o;
  o.thickness = 3;
  o.draw_joints = false;
  image im;
  overlay_job job;
  job.image = im.ref();
  job.options = o;
  job.people = &f;
  job.people_count = 1;
  ASSERT_TRUE(job.run());
  const int x = k_w / 2, y = 180;  // row 0.75 * 240
  // Thickness 3: rows y-1 .. y+1 in colour; the outline (5) adds y-2 and y+2.
  for (int dy = -1; dy <= 1; ++dy) EXPECT_TRUE(same(im.at(x, y + dy), person_color(2))) << dy;
  EXPECT_TRUE(same(im.at(x, y - 2), {0, 0, 0}));
  EXPECT_TRUE(same(im.at(x, y + 2), {0, 0, 0}));
  EXPECT_TRUE(same(im.at(x, y - 3), {k_grey, k_grey, k_grey}));
  EXPECT_TRUE(same(im.at(x, y + 3), {k_grey, k_grey, k_grey}));
}

TEST(OverlayPeople, PeopleFieldsAndTheSinglePersonPath) {
  const landmark_frame f = figure(4, 0.3f, 0.7f);
  // people null: `frame` drawn as one person, in the side colours (no person colour).
  image a;
  overlay_job one;
  one.image = a.ref();
  one.frame = &f;
  ASSERT_TRUE(one.run());
  long own = 0, sides = 0;
  for (int y = 0; y < k_h; ++y)
    for (int x = 0; x < k_w; ++x) {
      own += same(a.at(x, y), person_color(4));
      sides += same(a.at(x, y), overlay_options{}.left_color);
    }
  EXPECT_EQ(own, 0);
  EXPECT_GT(sides, 0);
  // people set with count 0 (nobody in view): nothing drawn, `frame` included.
  image b;
  overlay_job none = one;
  none.image = b.ref();
  none.people = &f;
  none.people_count = 0;
  ASSERT_TRUE(none.run());
  for (std::uint8_t v : b.px) ASSERT_EQ(v, k_grey);
  // A count without frames is refused, the image untouched.
  overlay_job bad = none;
  bad.people = nullptr;
  bad.people_count = 2;
  EXPECT_FALSE(bad.validate());
  EXPECT_FALSE(bad.run());
  for (std::uint8_t v : b.px) ASSERT_EQ(v, k_grey);
}

}  // namespace
}  // namespace avatarmap
