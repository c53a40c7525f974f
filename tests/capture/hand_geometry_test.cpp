// Tests of hand_pipeline.hpp's geometry: the palm detector's anchors and decoding options,
// the palm and landmark regions, Holistic's hand region from the body, and the side
// convention. Known answers are worked out by hand from MediaPipe's graph options (see
// docs/capture-hands.md); none is copied from this code's output.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "avatarmap/capture/hand_pipeline.hpp"

namespace avatarmap {
namespace {

constexpr float k_pi = 3.14159265358979f;

// ---- anchors and decoding -------------------------------------------------------------------

TEST(hand_geometry, palm_anchors_match_the_model_output) {
  std::vector<ssd_anchor> a;
  ASSERT_TRUE(generate_ssd_anchors(palm_detection_anchor_options(), a));
  // 24x24 cells x 2 anchors (stride 8) + 12x12 cells x 6 anchors (three stride-16 layers
  // share one map, each adding its scale and the interpolated one): the model's 2016 boxes.
  ASSERT_EQ(a.size(), 2016u);
  EXPECT_EQ(palm_detection_decode_options().num_boxes, 2016);
  EXPECT_FLOAT_EQ(a[0].x_center, 0.5f / 24);
  EXPECT_FLOAT_EQ(a[0].y_center, 0.5f / 24);
  EXPECT_FLOAT_EQ(a[1].x_center, 0.5f / 24);  // two anchors per cell
  EXPECT_FLOAT_EQ(a[2].x_center, 1.5f / 24);
  EXPECT_FLOAT_EQ(a[47].x_center, 23.5f / 24);
  EXPECT_FLOAT_EQ(a[48].y_center, 1.5f / 24);  // second row
  EXPECT_FLOAT_EQ(a[1151].y_center, 23.5f / 24);
  EXPECT_FLOAT_EQ(a[1152].x_center, 0.5f / 12);  // first cell of the 12x12 map
  EXPECT_FLOAT_EQ(a[1157].x_center, 0.5f / 12);  // six anchors per cell
  EXPECT_FLOAT_EQ(a[1158].x_center, 1.5f / 12);
  EXPECT_FLOAT_EQ(a.back().x_center, 11.5f / 12);
  EXPECT_FLOAT_EQ(a.back().y_center, 11.5f / 12);
  for (const ssd_anchor& x : a) {
    EXPECT_EQ(x.width, 1.f);  // fixed_anchor_size
    EXPECT_EQ(x.height, 1.f);
  }
}

TEST(hand_geometry, palm_decode_reads_box_and_seven_keypoints) {
  std::vector<ssd_anchor> a;
  ASSERT_TRUE(generate_ssd_anchors(palm_detection_anchor_options(), a));
  const detection_decode_options o = palm_detection_decode_options();
  std::vector<float> boxes(2016 * 18, 0.f), scores(2016, -50.f);
  // Anchor 2 (cell (1, 0) of the 24x24 map, centre (1.5/24, 0.5/24)): a box 19.2 px right of
  // it, 38.4 x 19.2 px, keypoint 6 at +9.6 px in y.
  float* r = &boxes[2 * 18];
  r[0] = 19.2f;
  r[2] = 38.4f;
  r[3] = 19.2f;
  r[4 + 12 + 1] = 9.6f;
  scores[2] = 2.f;
  std::vector<detection> out;
  ASSERT_EQ(decode_detections(boxes.data(), scores.data(), a.data(), o, out), 1);
  const detection& d = out[0];
  EXPECT_NEAR(d.score, 1.f / (1.f + std::exp(-2.f)), 1e-6f);
  EXPECT_NEAR(d.xmin + d.width / 2, 1.5f / 24 + 0.1f, 1e-6f);
  EXPECT_NEAR(d.ymin + d.height / 2, 0.5f / 24, 1e-6f);
  EXPECT_NEAR(d.width, 0.2f, 1e-6f);
  EXPECT_NEAR(d.height, 0.1f, 1e-6f);
  EXPECT_EQ(d.keypoint_count, 7);
  EXPECT_NEAR(d.keypoints[12], 1.5f / 24, 1e-6f);
  EXPECT_NEAR(d.keypoints[13], 0.5f / 24 + 0.05f, 1e-6f);
}

// ---- palm detection -> region ---------------------------------------------------------------

detection palm(float cx, float cy, float w, float h, float wx, float wy, float mx, float my) {
  detection d;
  d.score = 0.9f;
  d.xmin = cx - w / 2;
  d.ymin = cy - h / 2;
  d.width = w;
  d.height = h;
  d.keypoint_count = 7;
  d.keypoints[0] = wx;
  d.keypoints[1] = wy;
  d.keypoints[4] = mx;
  d.keypoints[5] = my;
  return d;
}

TEST(hand_geometry, palm_roi_upright_is_shifted_up_and_scaled) {
  // 100x100 image, palm box 20x20 px at the centre, wrist below the middle MCP: rotation 0,
  // shifted up by half its height (10 px), then 2.6 times as large.
  const normalized_rect r =
      palm_detection_to_roi(palm(0.5f, 0.5f, 0.2f, 0.2f, 0.5f, 0.6f, 0.5f, 0.4f), 100, 100);
  EXPECT_NEAR(r.rotation, 0.f, 1e-6f);
  EXPECT_NEAR(r.x_center, 0.5f, 1e-6f);
  EXPECT_NEAR(r.y_center, 0.4f, 1e-6f);
  EXPECT_NEAR(r.width, 0.52f, 1e-6f);
  EXPECT_NEAR(r.height, 0.52f, 1e-6f);
}

TEST(hand_geometry, palm_roi_pointing_right_turns_clockwise) {
  // Fingers to the right: the region turns a quarter clockwise (+90 degrees) and the shift
  // moves it to the right, towards the fingers.
  const normalized_rect r =
      palm_detection_to_roi(palm(0.5f, 0.5f, 0.2f, 0.2f, 0.4f, 0.5f, 0.6f, 0.5f), 100, 100);
  EXPECT_NEAR(r.rotation, k_pi / 2, 1e-6f);
  EXPECT_NEAR(r.x_center, 0.6f, 1e-6f);
  EXPECT_NEAR(r.y_center, 0.5f, 1e-6f);
}

TEST(hand_geometry, palm_roi_is_square_in_pixels) {
  // 200x100 image, box 20 x 30 px: squared on its long side (30 px) before scaling.
  const normalized_rect r =
      palm_detection_to_roi(palm(0.5f, 0.5f, 0.1f, 0.3f, 0.5f, 0.6f, 0.5f, 0.4f), 200, 100);
  EXPECT_NEAR(r.width * 200, 30.f * 2.6f, 1e-4f);
  EXPECT_NEAR(r.height * 100, 30.f * 2.6f, 1e-4f);
  EXPECT_NEAR(r.y_center, 0.5f - 0.15f, 1e-6f);  // half of the 30 px height, upwards
}

// ---- hand landmarks -> next region ----------------------------------------------------------

// An upright hand on a 200x100 image, in pixels: the 12 points the region uses span x 85..115
// and y 40..80; the index/middle/ring MCPs sit straight above the wrist on average.
std::array<landmark, 21> upright_hand_px() {
  std::array<landmark, 21> p{};
  auto set = [&](int i, float x, float y) { p[i] = {x, y, 0.f, 1.f, 1.f}; };
  set(0, 100, 80);                                    // wrist
  set(1, 112, 75), set(2, 115, 68), set(3, 114, 60);  // thumb CMC, MCP, IP
  set(5, 108, 50), set(6, 109, 42);                   // index MCP, PIP
  set(9, 100, 50), set(10, 100, 40);                  // middle
  set(13, 92, 50), set(14, 91, 42);                   // ring
  set(17, 85, 54), set(18, 85, 48);                   // pinky
  set(4, 118, 55);                                    // tips and DIPs: ignored by the region
  set(7, 110, 35), set(8, 110, 5);
  set(11, 100, 30), set(12, 100, 2);
  set(15, 90, 35), set(16, 90, 10);
  set(19, 84, 42), set(20, 60, 38);
  return p;
}

std::array<landmark, 21> normalise(std::array<landmark, 21> p, int w, int h) {
  for (landmark& l : p) {
    l.x /= static_cast<float>(w);
    l.y /= static_cast<float>(h);
  }
  return p;
}

TEST(hand_geometry, landmark_roi_upright_known_answer) {
  const int w = 200, h = 100;
  const auto p = normalise(upright_hand_px(), w, h);
  EXPECT_NEAR(hand_landmarks_rotation(p.data(), w, h), 0.f, 1e-6f);
  normalized_rect r;
  ASSERT_TRUE(hand_landmarks_to_roi(p.data(), w, h, r));
  // Box 30 x 40 px centred (100, 60); shifted up by 0.1 * 40 = 4 px; squared to 40 x 40;
  // doubled: 80 x 80 px centred (100, 56).
  EXPECT_NEAR(r.rotation, 0.f, 1e-6f);
  EXPECT_NEAR(r.x_center * w, 100.f, 1e-3f);
  EXPECT_NEAR(r.y_center * h, 56.f, 1e-3f);
  EXPECT_NEAR(r.width * w, 80.f, 1e-3f);
  EXPECT_NEAR(r.height * h, 80.f, 1e-3f);
}

TEST(hand_geometry, landmark_roi_turns_with_the_hand) {
  // Turning the hand about its wrist by an angle turns the region with it: same size, its
  // centre turned likewise, rotation = the angle (positive clockwise on screen).
  const int w = 200, h = 100;
  for (float deg : {30.f, 90.f, -120.f, 180.f}) {
    const float a = deg * k_pi / 180.f, c = std::cos(a), s = std::sin(a);
    auto px = upright_hand_px();
    for (landmark& l : px) {
      const float dx = l.x - 100.f, dy = l.y - 80.f;
      l.x = 100.f + c * dx - s * dy;
      l.y = 80.f + s * dx + c * dy;
    }
    const auto p = normalise(px, w, h);
    normalized_rect r;
    ASSERT_TRUE(hand_landmarks_to_roi(p.data(), w, h, r));
    EXPECT_NEAR(normalize_radians(r.rotation - a), 0.f, 1e-5f) << deg;
    EXPECT_NEAR(r.width * w, 80.f, 1e-3f) << deg;
    EXPECT_NEAR(r.height * h, 80.f, 1e-3f) << deg;
    // Unturned centre (100, 56): 24 px above the wrist.
    EXPECT_NEAR(r.x_center * w, 100.f + 24.f * s, 1e-3f) << deg;
    EXPECT_NEAR(r.y_center * h, 80.f - 24.f * c, 1e-3f) << deg;
  }
}

TEST(hand_geometry, landmark_roi_ignores_tips_and_rejects_nan) {
  const int w = 200, h = 100;
  auto px = upright_hand_px();
  px[8].y = -500.f;  // a wild fingertip does not move the region
  px[20].x = 1000.f;
  auto p = normalise(px, w, h);
  normalized_rect r;
  ASSERT_TRUE(hand_landmarks_to_roi(p.data(), w, h, r));
  EXPECT_NEAR(r.y_center * h, 56.f, 1e-3f);
  EXPECT_NEAR(r.width * w, 80.f, 1e-3f);
  p[9].x = NAN;
  normalized_rect untouched;
  untouched.x_center = 7.f;
  EXPECT_FALSE(hand_landmarks_to_roi(p.data(), w, h, untouched));
  EXPECT_EQ(untouched.x_center, 7.f);
  EXPECT_FALSE(hand_landmarks_to_roi(normalise(px, w, h).data(), 0, h, untouched));
}

// ---- body -> hand region (Holistic) ---------------------------------------------------------

TEST(hand_geometry, pose_roi_known_answer_and_sides) {
  const int w = 200, h = 100;
  landmark_frame f;
  f.set(frame_part::pose, true);
  auto put = [&](pose_landmark i, float x, float y, float vis) {
    f.pose[idx(i)] = {x / w, y / h, 0.f, vis, 1.f};
  };
  // Left hand upright: middle finger estimated at (2 * index + pinky) / 3 = (100, 50), 30 px
  // above the wrist: box 60 px, shifted up 6 px, then 2.7 times: 162 px centred (100, 44).
  put(pose_landmark::left_wrist, 100, 80, 0.9f);
  put(pose_landmark::left_pinky, 90, 50, 0.9f);
  put(pose_landmark::left_index, 105, 50, 0.9f);
  // Right hand pointing left (fingers towards -x): rotation -90 degrees.
  put(pose_landmark::right_wrist, 60, 50, 0.9f);
  put(pose_landmark::right_pinky, 40, 57, 0.9f);
  put(pose_landmark::right_index, 40, 46, 0.9f);
  normalized_rect r;
  ASSERT_TRUE(hand_roi_from_pose(f, body_side::left, w, h, r));
  EXPECT_NEAR(r.rotation, 0.f, 1e-6f);
  EXPECT_NEAR(r.x_center * w, 100.f, 1e-3f);
  EXPECT_NEAR(r.y_center * h, 44.f, 1e-3f);
  EXPECT_NEAR(r.width * w, 162.f, 1e-3f);
  EXPECT_NEAR(r.height * h, 162.f, 1e-3f);
  ASSERT_TRUE(hand_roi_from_pose(f, body_side::right, w, h, r));
  // Middle (40, 49.667): 20.0028 px from the wrist, so the box is 40.0056 px; the shift of
  // 4.0006 px runs towards the fingers (-x).
  const float mid_y = (2.f * 46.f + 57.f) / 3.f;
  const float d = std::hypot(20.f, mid_y - 50.f);
  EXPECT_NEAR(r.rotation, -k_pi / 2 + std::atan2(50.f - mid_y, 20.f), 1e-5f);
  EXPECT_NEAR(r.width * w, 2.f * d * 2.7f, 1e-3f);
  EXPECT_NEAR(r.x_center * w, 40.f - 0.1f * 2.f * d * std::cos(std::atan2(50.f - mid_y, 20.f)),
              1e-2f);
  // Gates: wrist visibility below 0.1, no pose part, a NaN point.
  f.pose[idx(pose_landmark::left_wrist)].visibility = 0.05f;
  EXPECT_FALSE(hand_roi_from_pose(f, body_side::left, w, h, r));
  pose_hand_roi_options o;
  o.min_wrist_visibility = 0.f;
  EXPECT_TRUE(hand_roi_from_pose(f, body_side::left, w, h, r, o));
  f.pose[idx(pose_landmark::right_index)].x = NAN;
  EXPECT_FALSE(hand_roi_from_pose(f, body_side::right, w, h, r));
  f.set(frame_part::pose, false);
  EXPECT_FALSE(hand_roi_from_pose(f, body_side::left, w, h, r, o));
}

// ---- overlap, containment, sides ------------------------------------------------------------

TEST(hand_geometry, rect_iou_and_contains) {
  normalized_rect a{0.25f, 0.5f, 0.5f, 1.0f, 0.f};  // left half of the image
  normalized_rect b{0.5f, 0.5f, 0.5f, 1.0f, 1.f};   // middle half; rotation ignored by IoU
  EXPECT_NEAR(normalized_rect_iou(a, a, 200, 100), 1.f, 1e-6f);
  EXPECT_NEAR(normalized_rect_iou(a, b, 200, 100), 1.f / 3.f, 1e-6f);
  normalized_rect c{0.9f, 0.5f, 0.1f, 0.1f, 0.f};
  EXPECT_EQ(normalized_rect_iou(a, c, 200, 100), 0.f);
  // A 40 x 20 px box turned by 90 degrees on a 100x100 image covers 20 px in x, 40 px in y.
  normalized_rect t{0.5f, 0.5f, 0.4f, 0.2f, k_pi / 2};
  EXPECT_TRUE(normalized_rect_contains(t, 0.5f, 0.68f, 100, 100));
  EXPECT_FALSE(normalized_rect_contains(t, 0.68f, 0.5f, 100, 100));
  EXPECT_TRUE(normalized_rect_contains(t, 0.58f, 0.5f, 100, 100));
}

TEST(hand_geometry, handedness_follows_the_mirrored_convention) {
  // MediaPipe's label assumes a mirrored image: "Left" (score near 1) is the person's left
  // hand there, and the person's right hand on a raw camera image.
  float p = 0.f;
  EXPECT_EQ(hand_side_from_handedness(0.97f, true, &p), body_side::left);
  EXPECT_NEAR(p, 0.97f, 1e-6f);
  EXPECT_EQ(hand_side_from_handedness(0.97f, false, &p), body_side::right);
  EXPECT_NEAR(p, 0.03f, 1e-6f);
  EXPECT_EQ(hand_side_from_handedness(0.03f, false), body_side::left);
  EXPECT_EQ(hand_side_from_handedness(0.03f, true), body_side::right);
}

}  // namespace
}  // namespace avatarmap
