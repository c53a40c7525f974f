// Tests of detection.hpp: SSD anchors against MediaPipe's golden anchor files, detection
// decoding, weighted NMS and region-of-interest known answers.
#include "avatarmap/capture/detection.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "avatarmap/capture/pose_pipeline.hpp"
#include "support/test_data.hpp"

namespace avatarmap {
namespace {

constexpr float k_pi = 3.14159265358979f;

// ---- anchors -------------------------------------------------------------------------------

// [[x_center, y_center, width, height], ...] from MediaPipe's ssd_anchors_calculator_test.
bool load_golden_anchors(const std::string& name, std::vector<ssd_anchor>& out) {
  const std::string path = test::test_data_path("motion/tfjs-models/" + name);
  std::ifstream f(path);
  if (path.empty() || !f) return false;
  nlohmann::json j = nlohmann::json::parse(f);
  out.clear();
  for (const auto& a : j)
    out.push_back({a[0].get<float>(), a[1].get<float>(), a[2].get<float>(), a[3].get<float>()});
  return true;
}

void expect_anchors_near(const std::vector<ssd_anchor>& got, const std::vector<ssd_anchor>& want) {
  ASSERT_EQ(got.size(), want.size());
  int bad = 0;
  for (size_t i = 0; i < got.size() && bad < 5; ++i) {
    const bool ok = std::fabs(got[i].x_center - want[i].x_center) < 1e-5f &&
                    std::fabs(got[i].y_center - want[i].y_center) < 1e-5f &&
                    std::fabs(got[i].width - want[i].width) < 1e-5f &&
                    std::fabs(got[i].height - want[i].height) < 1e-5f;
    if (!ok) {
      ++bad;
      ADD_FAILURE() << "anchor " << i << ": got " << got[i].x_center << " " << got[i].y_center
                    << " " << got[i].width << " " << got[i].height << ", want " << want[i].x_center
                    << " " << want[i].y_center << " " << want[i].width << " " << want[i].height;
    }
  }
}

TEST(ssd_anchors, pose_detection_count_and_corners) {
  std::vector<ssd_anchor> a;
  ASSERT_TRUE(generate_ssd_anchors(pose_detection_anchor_options(), a));
  // 28x28x2 + 14x14x2 + 7x7x6.
  ASSERT_EQ(a.size(), 2254u);
  EXPECT_FLOAT_EQ(a[0].x_center, 0.5f / 28);
  EXPECT_FLOAT_EQ(a[1].x_center, 0.5f / 28);  // two anchors per cell
  EXPECT_FLOAT_EQ(a[2].x_center, 1.5f / 28);
  EXPECT_FLOAT_EQ(a.back().x_center, 6.5f / 7);
  EXPECT_FLOAT_EQ(a.back().y_center, 6.5f / 7);
  EXPECT_FLOAT_EQ(a.back().width, 1.f);
}

// MediaPipe's "FaceDetectionConfig" test: 256x256, strides 8,16,32,32,32, fixed anchor size.
TEST(ssd_anchors, golden_file_0) {
  std::vector<ssd_anchor> want;
  if (!load_golden_anchors("anchor_golden_file_0.json", want)) GTEST_SKIP() << test::k_no_test_data;
  ssd_anchor_options o;
  o.num_layers = 5;
  o.min_scale = 0.1171875f;
  o.max_scale = 0.75f;
  o.input_width = o.input_height = 256;
  o.strides = {8, 16, 32, 32, 32};
  o.aspect_ratios = {1.0f};
  o.fixed_anchor_size = true;
  std::vector<ssd_anchor> got;
  ASSERT_TRUE(generate_ssd_anchors(o, got));
  expect_anchors_near(got, want);
}

// MediaPipe's "MobileSSDConfig" test: 300x300, six layers, five aspect ratios, reduced lowest
// layer, interpolated scales, sized anchors.
TEST(ssd_anchors, golden_file_1) {
  std::vector<ssd_anchor> want;
  if (!load_golden_anchors("anchor_golden_file_1.json", want)) GTEST_SKIP() << test::k_no_test_data;
  ssd_anchor_options o;
  o.num_layers = 6;
  o.min_scale = 0.2f;
  o.max_scale = 0.95f;
  o.input_width = o.input_height = 300;
  o.strides = {16, 32, 64, 128, 256, 512};
  o.aspect_ratios = {1.0f, 2.0f, 0.5f, 3.0f, 0.3333f};
  o.reduce_boxes_in_lowest_layer = true;
  o.fixed_anchor_size = false;
  std::vector<ssd_anchor> got;
  ASSERT_TRUE(generate_ssd_anchors(o, got));
  expect_anchors_near(got, want);
}

TEST(ssd_anchors, rejects_bad_options) {
  std::vector<ssd_anchor> a;
  ssd_anchor_options o;
  o.strides = {8, 16};
  EXPECT_FALSE(generate_ssd_anchors(o, a));
  EXPECT_TRUE(a.empty());
  o = ssd_anchor_options{};
  o.aspect_ratios.clear();
  EXPECT_FALSE(generate_ssd_anchors(o, a));
  o = ssd_anchor_options{};
  o.input_width = 0;
  EXPECT_FALSE(generate_ssd_anchors(o, a));
}

// ---- decoding and NMS ----------------------------------------------------------------------

TEST(decode_detections, known_answer) {
  detection_decode_options o;
  o.num_boxes = 2;
  ssd_anchor anchors[2] = {{0.25f, 0.5f, 1.f, 1.f}, {0.75f, 0.5f, 1.f, 1.f}};
  float boxes[24] = {};
  // Box 0: centre offset (22.4, -44.8) px of 224, size 112 x 56, keypoint 0 at +(0, 22.4).
  boxes[0] = 22.4f;
  boxes[1] = -44.8f;
  boxes[2] = 112.f;
  boxes[3] = 56.f;
  boxes[4] = 0.f;
  boxes[5] = 22.4f;
  float scores[2] = {2.f, -2.f};  // sigmoid: 0.881, 0.119 (dropped)
  std::vector<detection> out;
  ASSERT_EQ(decode_detections(boxes, scores, anchors, o, out), 1);
  const detection& d = out[0];
  EXPECT_NEAR(d.score, 1.f / (1.f + std::exp(-2.f)), 1e-6f);
  EXPECT_NEAR(d.xmin, 0.35f - 0.25f, 1e-6f);
  EXPECT_NEAR(d.ymin, 0.3f - 0.125f, 1e-6f);
  EXPECT_NEAR(d.width, 0.5f, 1e-6f);
  EXPECT_NEAR(d.height, 0.25f, 1e-6f);
  EXPECT_EQ(d.keypoint_count, 4);
  EXPECT_NEAR(d.keypoints[0], 0.25f, 1e-6f);
  EXPECT_NEAR(d.keypoints[1], 0.6f, 1e-6f);
  // Score clipping: a huge logit is clipped to 100 before the sigmoid, never NaN.
  scores[1] = 1e30f;
  ASSERT_EQ(decode_detections(boxes, scores, anchors, o, out), 2);
  EXPECT_EQ(out[1].score, 1.f);
}

detection box(float score, float x, float y, float w, float h, float kx, float ky) {
  detection d;
  d.score = score;
  d.xmin = x;
  d.ymin = y;
  d.width = w;
  d.height = h;
  d.keypoint_count = 1;
  d.keypoints[0] = kx;
  d.keypoints[1] = ky;
  return d;
}

TEST(weighted_nms, iou_known_answers) {
  const detection a = box(1, 0, 0, 2, 2, 0, 0);
  EXPECT_FLOAT_EQ(detection_iou(a, box(1, 1, 1, 2, 2, 0, 0)), 1.f / 7.f);
  EXPECT_FLOAT_EQ(detection_iou(a, box(1, 2, 0, 2, 2, 0, 0)), 0.f);  // touching
  EXPECT_FLOAT_EQ(detection_iou(a, a), 1.f);
}

TEST(weighted_nms, averages_overlapping_group_by_score) {
  std::vector<detection> in = {
      box(0.6f, 0.1f, 0.1f, 0.4f, 0.4f, 0.3f, 0.3f),      // overlaps the best (IoU 0.6)
      box(0.9f, 0.0f, 0.0f, 0.5f, 0.5f, 0.2f, 0.2f),      // best
      box(0.8f, 0.6f, 0.6f, 0.3f, 0.3f, 0.7f, 0.7f),      // separate
      box(0.55f, 0.4f, 0.4f, 0.1f, 0.1f, 0.45f, 0.45f)};  // IoU 0.04 with the best: kept
  std::vector<detection> out;
  std::vector<int> scratch;
  ASSERT_EQ(weighted_non_max_suppression(in, 0.3f, 0, out, scratch), 3);
  // Group {0.9, 0.6}: total 1.5.
  EXPECT_FLOAT_EQ(out[0].score, 0.9f);
  EXPECT_NEAR(out[0].xmin, (0.9f * 0.f + 0.6f * 0.1f) / 1.5f, 1e-6f);
  EXPECT_NEAR(out[0].xmin + out[0].width, (0.9f * 0.5f + 0.6f * 0.5f) / 1.5f, 1e-6f);
  EXPECT_NEAR(out[0].keypoints[0], (0.9f * 0.2f + 0.6f * 0.3f) / 1.5f, 1e-6f);
  EXPECT_FLOAT_EQ(out[1].score, 0.8f);
  EXPECT_FLOAT_EQ(out[1].xmin, 0.6f);
  EXPECT_FLOAT_EQ(out[2].score, 0.55f);
  EXPECT_FLOAT_EQ(out[2].keypoints[0], 0.45f);
  // A limit keeps the best only.
  ASSERT_EQ(weighted_non_max_suppression(in, 0.3f, 1, out, scratch), 1);
  EXPECT_FLOAT_EQ(out[0].score, 0.9f);
  // Empty in, empty out.
  ASSERT_EQ(weighted_non_max_suppression({}, 0.3f, 0, out, scratch), 0);
}

// ---- regions of interest -------------------------------------------------------------------

TEST(roi, upright_body_on_square_image) {
  // Hip centre (0.5, 0.6), scale point straight above at distance 0.2: side 0.4 * 1.25.
  const normalized_rect r = roi_from_alignment_points(0.5f, 0.6f, 0.5f, 0.4f, 100, 100);
  EXPECT_FLOAT_EQ(r.x_center, 0.5f);
  EXPECT_FLOAT_EQ(r.y_center, 0.6f);
  EXPECT_NEAR(r.width, 0.5f, 1e-6f);
  EXPECT_NEAR(r.height, 0.5f, 1e-6f);
  EXPECT_NEAR(r.rotation, 0.f, 1e-6f);
}

TEST(roi, rotation_and_square_long_on_wide_image) {
  // 200 x 100 image; the scale point 20 px to the right of the centre: the body lies on its
  // side, head to the right, so the region turns by +90 degrees (clockwise on screen).
  const normalized_rect r = roi_from_alignment_points(0.5f, 0.5f, 0.6f, 0.5f, 200, 100);
  EXPECT_NEAR(r.rotation, k_pi / 2, 1e-6f);  // 90 - atan2(0, +x) = +90 degrees
  // 40 px square -> 50 px after scaling: 0.25 of the width, 0.5 of the height.
  EXPECT_NEAR(r.width, 0.25f, 1e-6f);
  EXPECT_NEAR(r.height, 0.5f, 1e-6f);
  // Scale point below the centre (head down): 180 degrees, normalised into [-pi, pi).
  const normalized_rect d = roi_from_alignment_points(0.5f, 0.5f, 0.5f, 0.7f, 200, 100);
  EXPECT_NEAR(std::fabs(d.rotation), k_pi, 1e-5f);
  // Up and to the left at 45 degrees: rotation -45 degrees.
  const normalized_rect l = roi_from_alignment_points(0.5f, 0.5f, 0.45f, 0.4f, 200, 100);
  EXPECT_NEAR(l.rotation, -k_pi / 4, 1e-6f);
}

TEST(roi, normalize_radians_range) {
  EXPECT_NEAR(normalize_radians(3 * k_pi / 2), -k_pi / 2, 1e-6f);
  EXPECT_NEAR(normalize_radians(-3 * k_pi / 2), k_pi / 2, 1e-6f);
  EXPECT_NEAR(normalize_radians(0.5f), 0.5f, 1e-7f);
}

TEST(roi, detection_uses_keypoints_0_and_1) {
  detection d;
  d.keypoint_count = 4;
  d.keypoints = {0.5f, 0.6f, 0.5f, 0.4f, 0.f, 0.f, 0.f, 0.f};
  const normalized_rect r = pose_detection_to_roi(d, 100, 100);
  EXPECT_NEAR(r.width, 0.5f, 1e-6f);
  EXPECT_NEAR(r.rotation, 0.f, 1e-6f);
}

// ---- rect transformation, detection and landmark rectangles (MediaPipe's calculators) -------

TEST(rect, transform_shift_runs_along_the_rotated_axes) {
  normalized_rect r{0.5f, 0.5f, 0.2f, 0.4f, 0.f};
  rect_transform_options o;
  o.shift_y = -0.5f;
  o.square_long = false;
  normalized_rect t = transform_rect(r, 100, 100, o);
  EXPECT_NEAR(t.x_center, 0.5f, 1e-6f);
  EXPECT_NEAR(t.y_center, 0.3f, 1e-6f);  // half the height up
  // Rotated 90 degrees clockwise on screen: the region's "up" is the image's right.
  r.rotation = k_pi / 2;
  t = transform_rect(r, 100, 100, o);
  EXPECT_NEAR(t.x_center, 0.7f, 1e-6f);
  EXPECT_NEAR(t.y_center, 0.5f, 1e-6f);
  // Pixels matter on a non-square image: 0.2 of 200 px = 40 px = 0.4 of 100 px.
  r = {0.5f, 0.5f, 0.2f, 0.4f, k_pi / 2};
  o.shift_y = 0.f;
  o.shift_x = 1.f;
  t = transform_rect(r, 200, 100, o);
  EXPECT_NEAR(t.x_center, 0.5f, 1e-6f);
  EXPECT_NEAR(t.y_center, 0.9f, 1e-6f);
}

TEST(rect, transform_squares_in_pixels_then_scales) {
  const normalized_rect r{0.5f, 0.5f, 0.25f, 0.2f, 0.3f};  // 50 x 20 px on 200 x 100
  rect_transform_options o;
  o.scale_x = o.scale_y = 2.f;
  const normalized_rect t = transform_rect(r, 200, 100, o);
  EXPECT_NEAR(t.width * 200, 100.f, 1e-4f);
  EXPECT_NEAR(t.height * 100, 100.f, 1e-4f);
  EXPECT_NEAR(t.rotation, 0.3f, 1e-7f);
}

TEST(rect, detection_box_with_keypoint_rotation) {
  detection d;
  d.xmin = 0.2f;
  d.ymin = 0.3f;
  d.width = 0.4f;
  d.height = 0.2f;
  d.keypoint_count = 3;
  // Keypoint 0 -> 2 points left on screen; palm graphs want it up (90 degrees): turn -90.
  d.keypoints = {0.6f, 0.4f, 0.f, 0.f, 0.4f, 0.4f};
  normalized_rect r = detection_to_rect(d, 0, 2, k_pi / 2, 100, 100);
  EXPECT_NEAR(r.x_center, 0.4f, 1e-6f);
  EXPECT_NEAR(r.y_center, 0.4f, 1e-6f);
  EXPECT_NEAR(r.width, 0.4f, 1e-6f);
  EXPECT_NEAR(r.height, 0.2f, 1e-6f);
  EXPECT_NEAR(r.rotation, -k_pi / 2, 1e-6f);
  // Eyes level (face graphs: target 0) gives no rotation; an index past the keypoints too.
  EXPECT_NEAR(detection_to_rect(d, 2, 0, 0.f, 100, 100).rotation, 0.f, 1e-6f);
  EXPECT_EQ(detection_to_rect(d, 0, 5, 0.f, 100, 100).rotation, 0.f);
}

TEST(rect, rotated_bounding_rect_of_a_rotated_square) {
  // The corners of a 20 x 40 px rectangle centred on (50, 60), turned by 30 degrees: the
  // rotated box with the same rotation gives it back exactly.
  const float a = k_pi / 6, c = std::cos(a), s = std::sin(a);
  std::vector<float> xy;
  for (float u : {-10.f, 10.f})
    for (float v : {-20.f, 20.f}) {
      xy.push_back((50.f + u * c - v * s) / 100.f);
      xy.push_back((60.f + u * s + v * c) / 100.f);
    }
  xy.push_back((50.f + 3.f) / 100.f);  // an inside point changes nothing
  xy.push_back(60.f / 100.f);
  const normalized_rect r = rotated_bounding_rect(xy.data(), 5, a, 100, 100);
  EXPECT_NEAR(r.x_center, 0.5f, 1e-5f);
  EXPECT_NEAR(r.y_center, 0.6f, 1e-5f);
  EXPECT_NEAR(r.width, 0.2f, 1e-5f);
  EXPECT_NEAR(r.height, 0.4f, 1e-5f);
  EXPECT_NEAR(r.rotation, a, 1e-7f);
  // Unrotated it is the axis-aligned box.
  const normalized_rect b = rotated_bounding_rect(xy.data(), 5, 0.f, 100, 100);
  EXPECT_NEAR(b.width, (20 * c + 40 * s) / 100, 1e-5f);
  EXPECT_NEAR(b.height, (20 * s + 40 * c) / 100, 1e-5f);
}

}  // namespace
}  // namespace avatarmap
