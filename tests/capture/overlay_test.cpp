#include "avatarmap/capture/overlay.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <set>
#include <utility>
#include <vector>

namespace avatarmap {
namespace {

constexpr float k_nan = std::numeric_limits<float>::quiet_NaN();
constexpr float k_inf = std::numeric_limits<float>::infinity();
constexpr double k_pi = 3.14159265358979323846;

// An RGB8 image with `pad` bytes after each row and `guard` bytes before and after the
// pixels; pixels start black, padding and guards hold k_guard.
constexpr std::uint8_t k_guard = 0xA5;

struct test_image {
  int width;
  int height;
  int stride;
  int guard;
  std::vector<std::uint8_t> bytes;

  test_image(int w, int h, int pad = 0, int guard_bytes = 0)
      : width(w), height(h), stride(w * 3 + pad), guard(guard_bytes) {
    bytes.assign(static_cast<std::size_t>(guard) * 2 + static_cast<std::size_t>(stride) * h,
                 k_guard);
    for (int y = 0; y < h; ++y)
      std::fill_n(pixel_ptr(0, y), static_cast<std::size_t>(w) * 3, std::uint8_t{0});
  }
  std::uint8_t* pixel_ptr(int x, int y) {
    return bytes.data() + guard + static_cast<std::size_t>(y) * stride + 3 * x;
  }
  rgb8_color at(int x, int y) {
    const std::uint8_t* p = pixel_ptr(x, y);
    return {p[0], p[1], p[2]};
  }
  bool black(int x, int y) {
    const rgb8_color c = at(x, y);
    return c.r == 0 && c.g == 0 && c.b == 0;
  }
  rgb8_image_ref ref() { return {bytes.data() + guard, width, height, stride}; }
  // The (x, y) of every pixel that is not black.
  std::set<std::pair<int, int>> lit() {
    std::set<std::pair<int, int>> r;
    for (int y = 0; y < height; ++y)
      for (int x = 0; x < width; ++x)
        if (!black(x, y)) r.insert({x, y});
    return r;
  }
  // Bytes outside the pixels (guards, row padding) still hold k_guard.
  bool guards_intact() const {
    for (std::size_t i = 0; i < bytes.size(); ++i) {
      const std::ptrdiff_t off = static_cast<std::ptrdiff_t>(i) - guard;
      const bool inside = off >= 0 && off < static_cast<std::ptrdiff_t>(stride) * height &&
                          off % stride < width * 3;
      if (!inside && bytes[i] != k_guard) return false;
    }
    return true;
  }
};

bool same(rgb8_color a, rgb8_color b) { return a.r == b.r && a.g == b.g && a.b == b.b; }

// A frame with every point of every part "not seen" (NaN) and no part flagged.
landmark_frame empty_frame() {
  landmark_frame f;
  const landmark unseen{k_nan, k_nan, k_nan, 1.f, 1.f};
  f.pose.fill(unseen);
  f.left_hand.fill(unseen);
  f.right_hand.fill(unseen);
  f.face.fill(unseen);
  return f;
}

landmark at(float x, float y, float visibility = 1.f) { return {x, y, 0.f, visibility, 1.f}; }

overlay_options thin_lines() {
  overlay_options o;
  o.thickness = 1;
  o.draw_joints = false;
  return o;
}

bool draw(test_image& img, const landmark_frame* f, const overlay_options& o,
          const normalized_rect* rects = nullptr, std::size_t n = 0) {
  overlay_job job;
  job.image = img.ref();
  job.frame = f;
  job.rects = rects;
  job.rect_count = n;
  job.options = o;
  return job.run();
}

using pixel_set = std::set<std::pair<int, int>>;

pixel_set row_span(int x0, int x1, int y0, int y1) {
  pixel_set s;
  for (int y = y0; y <= y1; ++y)
    for (int x = x0; x <= x1; ++x) s.insert({x, y});
  return s;
}

// ---- connection tables -----------------------------------------------------------------

// MediaPipe's POSE_CONNECTIONS as published in its pose documentation, written with the
// numeric indices of REFERENCE.md §2.
const std::set<std::pair<int, int>> k_expected_pose = {
    {0, 1},   {1, 2},   {2, 3},   {3, 7},   {0, 4},   {4, 5},   {5, 6},   {6, 8},   {9, 10},
    {11, 12}, {11, 13}, {13, 15}, {15, 17}, {15, 19}, {15, 21}, {17, 19}, {12, 14}, {14, 16},
    {16, 18}, {16, 20}, {16, 22}, {18, 20}, {11, 23}, {12, 24}, {23, 24}, {23, 25}, {24, 26},
    {25, 27}, {26, 28}, {27, 29}, {28, 30}, {29, 31}, {30, 32}, {27, 31}, {28, 32}};

// HAND_CONNECTIONS: palm, then the thumb, index, middle, ring and pinky chains.
const std::set<std::pair<int, int>> k_expected_hand = {
    {0, 1},   {0, 5},   {9, 13},  {13, 17}, {5, 9},   {0, 17},  {1, 2},
    {2, 3},   {3, 4},   {5, 6},   {6, 7},   {7, 8},   {9, 10},  {10, 11},
    {11, 12}, {13, 14}, {14, 15}, {15, 16}, {17, 18}, {18, 19}, {19, 20}};

template <std::size_t N>
std::set<std::pair<int, int>> as_set(const std::array<landmark_connection, N>& table) {
  std::set<std::pair<int, int>> s;
  for (const auto& c : table) s.insert({std::min(c.a, c.b), std::max(c.a, c.b)});
  return s;
}

TEST(overlay, PoseConnectionsAreMediaPipes) {
  EXPECT_EQ(k_pose_connections.size(), 35u);
  EXPECT_EQ(as_set(k_pose_connections), k_expected_pose);  // also: no duplicates
}

TEST(overlay, HandConnectionsAreMediaPipes) {
  EXPECT_EQ(k_hand_connections.size(), 21u);
  EXPECT_EQ(as_set(k_hand_connections), k_expected_hand);
}

TEST(overlay, PoseSides) {
  EXPECT_EQ(pose_landmark_side(0), 0);
  for (int i : {1, 2, 3, 7, 9, 11, 13, 15, 17, 19, 21, 23, 25, 27, 29, 31})
    EXPECT_EQ(pose_landmark_side(i), 1) << i;
  for (int i : {4, 5, 6, 8, 10, 12, 14, 16, 18, 20, 22, 24, 26, 28, 30, 32})
    EXPECT_EQ(pose_landmark_side(i), -1) << i;
}

TEST(overlay, AutoThickness) {
  EXPECT_EQ(overlay_auto_thickness(100, 100), 1);
  EXPECT_EQ(overlay_auto_thickness(640, 480), 1);
  EXPECT_EQ(overlay_auto_thickness(1280, 720), 2);
  EXPECT_EQ(overlay_auto_thickness(1920, 1080), 3);
  EXPECT_EQ(overlay_auto_thickness(1080, 1920), 3);
  EXPECT_EQ(overlay_auto_thickness(3840, 2160), 6);
}

// ---- known answers -------------------------------------------------------------------------

// Left shoulder (0.2, 0.5) to left elbow (0.7, 0.5) on 100x80: pixels x = 20..70 of row 40.
landmark_frame horizontal_left_arm() {
  landmark_frame f = empty_frame();
  f.set(frame_part::pose, true);
  f.pose[idx(pose_landmark::left_shoulder)] = at(0.2f, 0.5f);
  f.pose[idx(pose_landmark::left_elbow)] = at(0.7f, 0.5f);
  return f;
}

TEST(overlay, HorizontalSegmentLightsExactlyOneRow) {
  test_image img(100, 80);
  const landmark_frame f = horizontal_left_arm();
  const overlay_options o = thin_lines();
  ASSERT_TRUE(draw(img, &f, o));
  EXPECT_EQ(img.lit(), row_span(20, 70, 40, 40));
  EXPECT_TRUE(same(img.at(45, 40), o.left_color));
}

TEST(overlay, ThickHorizontalSegment) {
  for (int t : {2, 3, 4}) {
    test_image img(100, 80);
    const landmark_frame f = horizontal_left_arm();
    overlay_options o = thin_lines();
    o.thickness = t;
    ASSERT_TRUE(draw(img, &f, o));
    // Rows 40 - (t - 1) / 2 .. 40 + t / 2: t = 2 -> 40..41, 3 -> 39..41, 4 -> 39..42.
    const int lo = t == 2 ? 40 : 39;
    const int hi = t == 4 ? 42 : 41;
    EXPECT_EQ(img.lit(), row_span(20, 70, lo, hi)) << "thickness " << t;
  }
}

TEST(overlay, AutoThicknessOnAnHdImage) {
  test_image img(1280, 720);
  landmark_frame f = empty_frame();
  f.set(frame_part::pose, true);
  f.pose[idx(pose_landmark::left_hip)] = at(0.25f, 0.5f);   // (320, 360)
  f.pose[idx(pose_landmark::left_knee)] = at(0.75f, 0.5f);  // (960, 360)
  overlay_options o;
  o.draw_joints = false;
  ASSERT_TRUE(draw(img, &f, o));
  EXPECT_EQ(img.lit(), row_span(320, 960, 360, 361));  // thickness 2
}

TEST(overlay, StrideLargerThanTheRowIsRespected) {
  test_image img(100, 80, /*pad=*/13, /*guard=*/32);
  const landmark_frame f = horizontal_left_arm();
  ASSERT_TRUE(draw(img, &f, thin_lines()));
  EXPECT_EQ(img.lit(), row_span(20, 70, 40, 40));
  EXPECT_TRUE(img.guards_intact());
}

TEST(overlay, DiagonalSegment) {
  test_image img(40, 40);
  landmark_frame f = empty_frame();
  f.set(frame_part::pose, true);
  f.pose[idx(pose_landmark::right_hip)] = at(0.25f, 0.25f);  // (10, 10)
  f.pose[idx(pose_landmark::right_knee)] = at(0.5f, 0.5f);   // (20, 20)
  ASSERT_TRUE(draw(img, &f, thin_lines()));
  pixel_set expected;
  for (int i = 0; i <= 10; ++i) expected.insert({10 + i, 10 + i});
  EXPECT_EQ(img.lit(), expected);
}

TEST(overlay, JointIsADisc) {
  test_image img(100, 80);
  landmark_frame f = empty_frame();
  f.set(frame_part::pose, true);
  f.pose[idx(pose_landmark::nose)] = at(0.5f, 0.5f);  // (50, 40)
  overlay_options o;
  o.thickness = 1;
  o.joint_radius = 2;
  ASSERT_TRUE(draw(img, &f, o));
  pixel_set expected;
  for (int y = 0; y < 80; ++y)
    for (int x = 0; x < 100; ++x)
      if ((x - 50) * (x - 50) + (y - 40) * (y - 40) <= 4) expected.insert({x, y});
  EXPECT_EQ(expected.size(), 13u);
  EXPECT_EQ(img.lit(), expected);
  EXPECT_TRUE(same(img.at(50, 40), o.center_color));
}

TEST(overlay, SidesHaveTheirColours) {
  test_image img(100, 100);
  landmark_frame f = empty_frame();
  f.set(frame_part::pose, true);
  // Left thigh along row 20, right thigh along row 50.
  f.pose[idx(pose_landmark::left_hip)] = at(0.1f, 0.2f);
  f.pose[idx(pose_landmark::left_knee)] = at(0.9f, 0.2f);
  f.pose[idx(pose_landmark::right_hip)] = at(0.1f, 0.5f);
  f.pose[idx(pose_landmark::right_knee)] = at(0.9f, 0.5f);
  const overlay_options o = thin_lines();
  ASSERT_TRUE(draw(img, &f, o));
  EXPECT_TRUE(same(img.at(50, 20), o.left_color));
  EXPECT_TRUE(same(img.at(50, 50), o.right_color));
  // left_hip - right_hip is also a connection: the vertical line x = 10 from row 20 to 50,
  // across the body, in the centre colour.
  EXPECT_TRUE(same(img.at(10, 35), o.center_color));

  test_image img2(100, 100);
  landmark_frame g = empty_frame();
  g.set(frame_part::pose, true);
  g.pose[idx(pose_landmark::left_shoulder)] = at(0.8f, 0.3f);
  g.pose[idx(pose_landmark::right_shoulder)] = at(0.2f, 0.3f);
  ASSERT_TRUE(draw(img2, &g, o));
  EXPECT_EQ(img2.lit(), row_span(20, 80, 30, 30));
  EXPECT_TRUE(same(img2.at(50, 30), o.center_color));
  // Nose to left eye inner: the midline point takes the other end's side.
  test_image img3(100, 100);
  landmark_frame h = empty_frame();
  h.set(frame_part::pose, true);
  h.pose[idx(pose_landmark::nose)] = at(0.5f, 0.5f);
  h.pose[idx(pose_landmark::left_eye_inner)] = at(0.6f, 0.5f);
  ASSERT_TRUE(draw(img3, &h, o));
  EXPECT_TRUE(same(img3.at(55, 50), o.left_color));
}

TEST(overlay, LowVisibilityIsDimmedOrSkipped) {
  landmark_frame f = horizontal_left_arm();
  f.pose[idx(pose_landmark::left_elbow)].visibility = 0.2f;
  overlay_options o = thin_lines();
  test_image dim(100, 80);
  ASSERT_TRUE(draw(dim, &f, o));
  EXPECT_EQ(dim.lit(), row_span(20, 70, 40, 40));
  const rgb8_color half{static_cast<std::uint8_t>(o.left_color.r / 2),
                        static_cast<std::uint8_t>(o.left_color.g / 2),
                        static_cast<std::uint8_t>(o.left_color.b / 2)};
  EXPECT_TRUE(same(dim.at(45, 40), half));

  o.low_visibility = overlay_low_visibility::skip;
  test_image skipped(100, 80);
  ASSERT_TRUE(draw(skipped, &f, o));
  EXPECT_TRUE(skipped.lit().empty());

  // Exactly at the threshold counts as visible; NaN visibility as not seen.
  o.low_visibility = overlay_low_visibility::dim;
  f.pose[idx(pose_landmark::left_elbow)].visibility = 0.5f;
  test_image full(100, 80);
  ASSERT_TRUE(draw(full, &f, o));
  EXPECT_TRUE(same(full.at(45, 40), o.left_color));
  f.pose[idx(pose_landmark::left_elbow)].visibility = k_nan;
  test_image unseen(100, 80);
  ASSERT_TRUE(draw(unseen, &f, o));
  EXPECT_TRUE(unseen.lit().empty());
}

TEST(overlay, NothingIsDrawnForMissingParts) {
  // Every array holds valid points in the middle of the image, but no part is flagged.
  landmark_frame f;
  f.pose.fill(at(0.5f, 0.5f));
  f.left_hand.fill(at(0.4f, 0.4f));
  f.right_hand.fill(at(0.6f, 0.6f));
  f.face.fill(at(0.5f, 0.3f));
  f.face_count = 478;
  for (int i = 0; i < k_hand_landmark_count; ++i) {
    f.left_hand[i].x += 0.01f * i;
    f.right_hand[i].y += 0.01f * i;
  }
  f.parts = 0;
  f.set(frame_part::pose_world, true);  // world parts are never drawn
  f.set(frame_part::left_hand_world, true);
  test_image img(64, 48, 5, 16);
  ASSERT_TRUE(draw(img, &f, overlay_options{}));
  EXPECT_TRUE(img.lit().empty());
  EXPECT_TRUE(draw(img, nullptr, overlay_options{}));  // no frame at all
  EXPECT_TRUE(img.lit().empty());

  // Flagged parts with every point NaN draw nothing either.
  landmark_frame g = empty_frame();
  g.set(frame_part::pose, true);
  g.set(frame_part::left_hand, true);
  g.set(frame_part::right_hand, true);
  g.set(frame_part::face, true);
  g.face_count = 478;
  ASSERT_TRUE(draw(img, &g, overlay_options{}));
  EXPECT_TRUE(img.lit().empty());
  EXPECT_TRUE(img.guards_intact());
}

TEST(overlay, DrawFlagsTurnPartsOff) {
  landmark_frame f = horizontal_left_arm();
  overlay_options o;
  o.draw_pose = false;
  test_image img(100, 80);
  ASSERT_TRUE(draw(img, &f, o));
  EXPECT_TRUE(img.lit().empty());
}

TEST(overlay, HandsInTheirSidesColours) {
  landmark_frame f = empty_frame();
  f.set(frame_part::left_hand, true);
  // Index finger MCP (0.1, 0.25) .. tip (0.7, 0.25) along one row; nothing else seen.
  for (int j = 0; j < 4; ++j)
    f.left_hand[idx(hand_landmark::index_mcp) + j] = at(0.1f + 0.2f * j, 0.25f);
  overlay_options o = thin_lines();
  test_image img(100, 40);
  ASSERT_TRUE(draw(img, &f, o));
  EXPECT_EQ(img.lit(), row_span(10, 70, 10, 10));
  EXPECT_TRUE(same(img.at(40, 10), o.left_color));

  f.right_hand = f.left_hand;
  f.set(frame_part::left_hand, false);
  f.set(frame_part::right_hand, true);
  test_image img2(100, 40);
  ASSERT_TRUE(draw(img2, &f, o));
  EXPECT_EQ(img2.lit(), row_span(10, 70, 10, 10));
  EXPECT_TRUE(same(img2.at(40, 10), o.right_color));
}

TEST(overlay, FacePointsAreDots) {
  landmark_frame f = empty_frame();
  f.set(frame_part::face, true);
  // Mesh points on a 10-pixel grid: (5 + 10 i, 5 + 10 j) on a 200x100 image; the ten iris
  // points (468..477) alone at (199, 99).
  pixel_set grid;
  for (int i = 0; i < k_face_mesh_count; ++i) {
    const int gx = i % 20;
    const int gy = (i / 20) % 10;
    f.face[i] = at((5.0f + 10.0f * gx) / 200.0f, (5.0f + 10.0f * gy) / 100.0f);
    grid.insert({5 + 10 * gx, 5 + 10 * gy});
  }
  for (int i = k_face_mesh_count; i < k_face_mesh_iris_count; ++i)
    f.face[i] = at(199.0f / 200.0f, 99.0f / 100.0f);
  overlay_options o;
  o.thickness = 1;  // face dots of radius 0: single pixels

  f.face_count = 478;
  test_image img(200, 100);
  ASSERT_TRUE(draw(img, &f, o));
  pixel_set with_iris = grid;
  with_iris.insert({199, 99});
  EXPECT_EQ(img.lit(), with_iris);
  EXPECT_TRUE(same(img.at(5, 5), o.face_color));
  EXPECT_TRUE(same(img.at(199, 99), o.face_color));

  f.face_count = 468;  // the iris points are not part of the frame
  test_image img2(200, 100);
  ASSERT_TRUE(draw(img2, &f, o));
  EXPECT_EQ(img2.lit(), grid);
}

TEST(overlay, RectangleOutline) {
  normalized_rect r;
  r.x_center = 0.5f;
  r.y_center = 0.5f;
  r.width = 0.2f;   // 20 px of 100
  r.height = 0.5f;  // 40 px of 80
  overlay_options o = thin_lines();
  // Unrotated: x 40..60, y 20..60.
  pixel_set expected;
  for (int x = 40; x <= 60; ++x) expected.insert({x, 20}), expected.insert({x, 60});
  for (int y = 20; y <= 60; ++y) expected.insert({40, y}), expected.insert({60, y});
  test_image img(100, 80);
  ASSERT_TRUE(draw(img, nullptr, o, &r, 1));
  EXPECT_EQ(img.lit(), expected);
  EXPECT_TRUE(same(img.at(50, 20), o.rect_color));

  // A quarter turn: the 20-pixel side runs along y, the 40-pixel side along x.
  r.rotation = static_cast<float>(k_pi / 2);
  pixel_set turned;
  for (int x = 30; x <= 70; ++x) turned.insert({x, 30}), turned.insert({x, 50});
  for (int y = 30; y <= 50; ++y) turned.insert({30, y}), turned.insert({70, y});
  test_image img2(100, 80);
  ASSERT_TRUE(draw(img2, nullptr, o, &r, 1));
  EXPECT_EQ(img2.lit(), turned);

  o.draw_rects = false;
  test_image img3(100, 80);
  ASSERT_TRUE(draw(img3, nullptr, o, &r, 1));
  EXPECT_TRUE(img3.lit().empty());
}

TEST(overlay, LineToAFarPointIsClippedPrecisely) {
  // From the nose at (50, 40) to points 1e30 image widths away along the row: the line
  // reaches the image's edge on that row and nothing else.
  for (const float far : {-1e30f, 1e30f, -std::numeric_limits<float>::max()}) {
    landmark_frame f = empty_frame();
    f.set(frame_part::pose, true);
    f.pose[idx(pose_landmark::nose)] = at(0.5f, 0.5f);
    f.pose[idx(pose_landmark::left_eye_inner)] = at(far, 0.5f);
    test_image img(100, 80);
    ASSERT_TRUE(draw(img, &f, thin_lines()));
    EXPECT_EQ(img.lit(), far < 0 ? row_span(0, 50, 40, 40) : row_span(50, 99, 40, 40)) << far;
  }
}

// ---- hostile input -------------------------------------------------------------------------

TEST(overlay, HostilePointsNeverWriteOutsideTheBuffer) {
  const float values[] = {k_nan, k_inf, -k_inf, 1e30f, -1e30f, std::numeric_limits<float>::max(),
                          -5.0f, 7.0f,  -0.01f, 1.01f, 0.0f,   1.0f,
                          0.5f,  0.25f, 0.999f, 2.0f,  -1.0f,  3e9f};
  constexpr int n_values = sizeof(values) / sizeof(values[0]);
  std::mt19937 rng(12345);
  std::uniform_int_distribution<int> pick(0, n_values - 1);
  std::uniform_real_distribution<float> vis(0.0f, 1.0f);
  const int sizes[][2] = {{1, 1}, {2, 3}, {64, 48}, {7, 200}};
  for (const auto& s : sizes) {
    test_image img(s[0], s[1], /*pad=*/7, /*guard=*/256);
    for (int iter = 0; iter < 300; ++iter) {
      landmark_frame f;
      f.parts = 0;
      for (frame_part p :
           {frame_part::pose, frame_part::left_hand, frame_part::right_hand, frame_part::face})
        f.set(p, true);
      f.face_count = iter % 2 ? 478 : 468;
      for (auto& p : f.pose) p = at(values[pick(rng)], values[pick(rng)], vis(rng));
      for (auto& p : f.left_hand) p = at(values[pick(rng)], values[pick(rng)]);
      for (auto& p : f.right_hand) p = at(values[pick(rng)], values[pick(rng)]);
      for (auto& p : f.face) p = at(values[pick(rng)], values[pick(rng)]);
      normalized_rect rects[3];
      for (auto& r : rects) {
        r.x_center = values[pick(rng)];
        r.y_center = values[pick(rng)];
        r.width = values[pick(rng)];
        r.height = values[pick(rng)];
        r.rotation = values[pick(rng)];
      }
      overlay_options o;
      o.thickness = iter % 4 == 0 ? 0 : (iter % 4) * 5;  // auto, 5, 10, 15
      o.joint_radius = iter % 3 == 0 ? -1 : 12;
      ASSERT_TRUE(draw(img, &f, o, rects, 3));
      ASSERT_TRUE(img.guards_intact()) << s[0] << "x" << s[1] << " iteration " << iter;
    }
  }
}

TEST(overlay, ThickLinesAtTheEdgesStayInside) {
  test_image img(50, 40, 3, 64);
  landmark_frame f = empty_frame();
  f.set(frame_part::pose, true);
  // Along each edge and just outside it.
  f.pose[idx(pose_landmark::left_shoulder)] = at(0.0f, 0.0f);
  f.pose[idx(pose_landmark::right_shoulder)] = at(1.0f, 0.0f);
  f.pose[idx(pose_landmark::left_hip)] = at(-0.02f, 1.0f);
  f.pose[idx(pose_landmark::right_hip)] = at(1.02f, 1.0f);
  overlay_options o;
  o.thickness = 9;
  o.joint_radius = 20;
  ASSERT_TRUE(draw(img, &f, o));
  EXPECT_TRUE(img.guards_intact());
  EXPECT_FALSE(img.black(25, 0));   // the shoulder line along the top edge
  EXPECT_FALSE(img.black(25, 39));  // the hip line along the bottom edge
}

TEST(overlay, InvalidJobsAreRefusedAndDrawNothing) {
  test_image img(10, 10);
  const landmark_frame f = horizontal_left_arm();
  overlay_job job;
  job.frame = &f;
  job.image = img.ref();
  EXPECT_TRUE(job.validate());
  overlay_job bad = job;
  bad.image.data = nullptr;
  EXPECT_FALSE(bad.run());
  bad = job;
  bad.image.width = 0;
  EXPECT_FALSE(bad.run());
  bad = job;
  bad.image.stride_bytes = 29;  // < 10 * 3
  EXPECT_FALSE(bad.run());
  bad = job;
  bad.options.thickness = 65;
  EXPECT_FALSE(bad.run());
  bad = job;
  bad.options.joint_radius = -2;
  EXPECT_FALSE(bad.run());
  bad = job;
  bad.rect_count = 1;  // rects is null
  EXPECT_FALSE(bad.run());
  EXPECT_TRUE(img.lit().empty());
}

}  // namespace
}  // namespace avatarmap
