// Tests of the geometry in face_pipeline.hpp (face_geometry.cpp): the face detector's anchors
// and decoding options, and the regions of interest of MediaPipe's face and Holistic graphs,
// against answers worked out by hand from the graphs' options (face_detection_short_range,
// face_detection_front_detection_to_roi, face_landmark_landmarks_to_roi,
// face_landmarks_from_pose_to_recrop_roi, holistic face_detection_front_detections_to_roi).
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

#include "avatarmap/capture/face_pipeline.hpp"

namespace avatarmap {
namespace {

constexpr float k_pi = 3.14159265358979f;
constexpr float k_eps = 1e-5f;

void expect_rect(const normalized_rect& r, float x, float y, float w, float h, float rot) {
  EXPECT_NEAR(r.x_center, x, k_eps);
  EXPECT_NEAR(r.y_center, y, k_eps);
  EXPECT_NEAR(r.width, w, k_eps);
  EXPECT_NEAR(r.height, h, k_eps);
  EXPECT_NEAR(r.rotation, rot, k_eps);
}

// ---- anchors and decoding ------------------------------------------------------------------

TEST(face_geometry, anchors_896_in_two_maps) {
  std::vector<ssd_anchor> a;
  ASSERT_TRUE(generate_ssd_anchors(face_detection_anchor_options(), a));
  // Stride 8: 16 x 16 cells x (1 aspect + 1 interpolated) = 512; strides 16, 16, 16 share an
  // 8 x 8 map: 8 x 8 x 3 x 2 = 384.
  ASSERT_EQ(a.size(), 896u);
  EXPECT_FLOAT_EQ(a[0].x_center, 0.5f / 16);
  EXPECT_FLOAT_EQ(a[0].y_center, 0.5f / 16);
  EXPECT_FLOAT_EQ(a[1].x_center, 0.5f / 16);  // two per cell
  EXPECT_FLOAT_EQ(a[2].x_center, 1.5f / 16);
  EXPECT_FLOAT_EQ(a[31].x_center, 15.5f / 16);
  EXPECT_FLOAT_EQ(a[32].x_center, 0.5f / 16);  // next row
  EXPECT_FLOAT_EQ(a[32].y_center, 1.5f / 16);
  EXPECT_FLOAT_EQ(a[511].x_center, 15.5f / 16);
  EXPECT_FLOAT_EQ(a[511].y_center, 15.5f / 16);
  for (int i = 512; i < 518; ++i) {  // six per cell in the second map
    EXPECT_FLOAT_EQ(a[i].x_center, 0.5f / 8) << i;
    EXPECT_FLOAT_EQ(a[i].y_center, 0.5f / 8) << i;
  }
  EXPECT_FLOAT_EQ(a[518].x_center, 1.5f / 8);
  EXPECT_FLOAT_EQ(a[512 + 6 * 8].y_center, 1.5f / 8);
  EXPECT_FLOAT_EQ(a.back().x_center, 7.5f / 8);
  EXPECT_FLOAT_EQ(a.back().y_center, 7.5f / 8);
  for (const ssd_anchor& x : a) {
    ASSERT_EQ(x.width, 1.f);  // fixed_anchor_size
    ASSERT_EQ(x.height, 1.f);
  }
}

TEST(face_geometry, decode_options_and_one_known_box) {
  const detection_decode_options o = face_detection_decode_options(0.6f);
  EXPECT_EQ(o.num_boxes, 896);
  EXPECT_EQ(o.num_coords, 16);
  EXPECT_EQ(o.num_keypoints, 6);
  EXPECT_EQ(o.keypoint_coord_offset, 4);
  EXPECT_FLOAT_EQ(o.x_scale, 128.f);
  EXPECT_FLOAT_EQ(o.min_score_thresh, 0.6f);
  // One box on anchor 2 (centre (1.5/16, 0.5/16)): offsets in detector pixels.
  std::vector<ssd_anchor> anchors;
  ASSERT_TRUE(generate_ssd_anchors(face_detection_anchor_options(), anchors));
  std::vector<float> boxes(896 * 16, 0.f), scores(896, -10.f);
  float* b = &boxes[2 * 16];
  b[0] = 12.8f;          // x offset: +0.1
  b[1] = -6.4f;          // y offset: -0.05
  b[2] = 32.f;           // w 0.25
  b[3] = 64.f;           // h 0.5
  b[4 + 2 * 1] = 25.6f;  // keypoint 1 x: anchor + 0.2
  b[4 + 2 * 1 + 1] = 0.f;
  scores[2] = 2.f;  // sigmoid 0.881
  std::vector<detection> out;
  ASSERT_EQ(decode_detections(boxes.data(), scores.data(), anchors.data(), o, out), 1);
  const detection& d = out[0];
  EXPECT_NEAR(d.score, 1.f / (1.f + std::exp(-2.f)), 1e-6f);
  EXPECT_NEAR(d.xmin, 1.5f / 16 + 0.1f - 0.125f, 1e-6f);
  EXPECT_NEAR(d.ymin, 0.5f / 16 - 0.05f - 0.25f, 1e-6f);
  EXPECT_EQ(d.keypoint_count, 6);
  EXPECT_NEAR(d.keypoints[2], 1.5f / 16 + 0.2f, 1e-6f);
  EXPECT_NEAR(d.keypoints[0], 1.5f / 16, 1e-6f);
}

// ---- regions -------------------------------------------------------------------------------

detection face_detection_at(float xmin, float ymin, float w, float h, float rx, float ry, float lx,
                            float ly) {
  detection d;
  d.score = 0.9f;
  d.xmin = xmin;
  d.ymin = ymin;
  d.width = w;
  d.height = h;
  d.keypoint_count = 6;
  d.keypoints = {rx, ry, lx, ly, 0.5f, 0.5f, 0.5f, 0.6f, 0.3f, 0.45f, 0.7f, 0.45f};
  return d;
}

TEST(face_geometry, detection_to_roi_upright_square_image) {
  const detection d = face_detection_at(0.25f, 0.3f, 0.5f, 0.4f, 0.4f, 0.4f, 0.6f, 0.4f);
  // Box centre (0.5, 0.5); 50 x 40 px -> square 50 -> x 1.5 = 75 px.
  expect_rect(face_detection_to_roi(d, 100, 100), 0.5f, 0.5f, 0.75f, 0.75f, 0.f);
}

TEST(face_geometry, detection_to_roi_tilted_on_wide_image) {
  // Right eye (0.4, 0.4) -> left eye (0.45, 0.5) on 200 x 100: (10, 10) px, 45 degrees down:
  // the region turns 45 degrees clockwise to level the eyes.
  const detection d = face_detection_at(0.25f, 0.25f, 0.25f, 0.5f, 0.4f, 0.4f, 0.45f, 0.5f);
  // Box 50 x 50 px -> x 1.5 = 75 px = 0.375 x 0.75.
  expect_rect(face_detection_to_roi(d, 200, 100), 0.375f, 0.5f, 0.375f, 0.75f, k_pi / 4);
}

TEST(face_geometry, keypoints_to_roi_upright_shifts_up) {
  detection d = face_detection_at(0.f, 0.f, 1.f, 1.f, 0.4f, 0.5f, 0.6f, 0.5f);
  d.keypoints = {0.4f, 0.5f, 0.6f, 0.5f, 0.5f, 0.6f, 0.5f, 0.7f, 0.3f, 0.55f, 0.7f, 0.55f};
  // Keypoint box x 0.3..0.7, y 0.5..0.7: centre (0.5, 0.6), 40 x 20 px; shifted up by 0.1 x 20
  // px = 2 px; square 40 -> x 2 = 80 px. The detection's own box is ignored.
  expect_rect(face_detection_keypoints_to_roi(d, 100, 100), 0.5f, 0.58f, 0.8f, 0.8f, 0.f);
}

TEST(face_geometry, keypoints_to_roi_rotated_shifts_along_face_up) {
  // Right eye below the left one (head turned 90 degrees counter-clockwise): the region
  // turns -90 degrees, and "up" for the face is image -x.
  detection d = face_detection_at(0.f, 0.f, 1.f, 1.f, 0.5f, 0.6f, 0.5f, 0.4f);
  d.keypoints = {0.5f, 0.6f, 0.5f, 0.4f, 0.45f, 0.5f, 0.4f, 0.5f, 0.55f, 0.7f, 0.55f, 0.3f};
  const normalized_rect r = face_detection_keypoints_to_roi(d, 100, 100);
  // Keypoint box x 0.4..0.55, y 0.3..0.7: centre (0.475, 0.5), 15 x 40 px. The shift is -0.1 of
  // the box height (4 px) along the region's y axis, which R(-90 degrees) maps to image +x:
  // the centre moves 4 px toward -x. Square 40 px -> x 2 = 80 px.
  expect_rect(r, 0.475f - 0.04f, 0.5f, 0.8f, 0.8f, -k_pi / 2);
}

std::vector<landmark> mesh_points() {
  std::vector<landmark> m(k_face_mesh_count);
  for (landmark& l : m) l = {0.5f, 0.5f, 0.f, 1.f, 1.f};
  m[33] = {0.4f, 0.45f, 0.f, 1.f, 1.f};
  m[263] = {0.6f, 0.45f, 0.f, 1.f, 1.f};
  m[10] = {0.5f, 0.3f, 0.f, 1.f, 1.f};
  m[152] = {0.5f, 0.8f, 0.f, 1.f, 1.f};
  return m;
}

TEST(face_geometry, landmarks_to_roi_bounding_box_and_eye_line) {
  std::vector<landmark> m = mesh_points();
  normalized_rect r;
  ASSERT_TRUE(face_landmarks_to_roi(m.data(), k_face_mesh_count, 100, 100, r));
  // Box x 0.4..0.6, y 0.3..0.8: centre (0.5, 0.55), 20 x 50 px -> square 50 -> x 1.5 = 75.
  expect_rect(r, 0.5f, 0.55f, 0.75f, 0.75f, 0.f);
  // Tilt the eye line: 33 (0.4, 0.45) -> 263 (0.6, 0.55) is atan(0.5) below horizontal.
  m[263].y = 0.55f;
  ASSERT_TRUE(face_landmarks_to_roi(m.data(), k_face_mesh_count, 100, 100, r));
  EXPECT_NEAR(r.rotation, std::atan(0.5f), k_eps);
  // On a 200 x 100 image the same normalised points are 40 x 10 px apart.
  ASSERT_TRUE(face_landmarks_to_roi(m.data(), k_face_mesh_count, 200, 100, r));
  EXPECT_NEAR(r.rotation, std::atan(0.25f), k_eps);
  EXPECT_NEAR(r.width * 200, r.height * 100, 1e-3f);  // square in pixels
}

TEST(face_geometry, landmarks_to_roi_rejects_short_or_broken_meshes) {
  std::vector<landmark> m = mesh_points();
  normalized_rect r;
  r.x_center = 42.f;
  EXPECT_FALSE(face_landmarks_to_roi(m.data(), 263, 100, 100, r));
  EXPECT_FALSE(face_landmarks_to_roi(nullptr, k_face_mesh_count, 100, 100, r));
  m[100].x = std::numeric_limits<float>::quiet_NaN();
  EXPECT_FALSE(face_landmarks_to_roi(m.data(), k_face_mesh_count, 100, 100, r));
  EXPECT_EQ(r.x_center, 42.f);  // untouched
}

std::array<landmark, k_pose_landmark_count> pose_points() {
  std::array<landmark, k_pose_landmark_count> p{};
  const float nan = std::numeric_limits<float>::quiet_NaN();
  for (landmark& l : p) l = {nan, nan, nan, 0.f, 0.f};  // points 11+ are not read
  p[0] = {0.5f, 0.33f, 0.f, 1.f, 1.f};                  // nose
  p[1] = {0.53f, 0.3f, 0.f, 1.f, 1.f};                  // left eye inner
  p[2] = {0.55f, 0.3f, 0.f, 1.f, 1.f};                  // left eye
  p[3] = {0.57f, 0.3f, 0.f, 1.f, 1.f};                  // left eye outer
  p[4] = {0.47f, 0.3f, 0.f, 1.f, 1.f};                  // right eye inner
  p[5] = {0.45f, 0.3f, 0.f, 1.f, 1.f};                  // right eye
  p[6] = {0.43f, 0.3f, 0.f, 1.f, 1.f};                  // right eye outer
  p[7] = {0.6f, 0.32f, 0.f, 1.f, 1.f};                  // left ear
  p[8] = {0.4f, 0.32f, 0.f, 1.f, 1.f};                  // right ear
  p[9] = {0.53f, 0.36f, 0.f, 1.f, 1.f};                 // mouth left
  p[10] = {0.47f, 0.36f, 0.f, 1.f, 1.f};                // mouth right
  return p;
}

TEST(face_geometry, face_region_from_pose_holistic_recrop) {
  std::array<landmark, k_pose_landmark_count> p = pose_points();
  normalized_rect r;
  ASSERT_TRUE(face_region_from_pose(p.data(), 200, 100, r));
  // Box x 0.4..0.6, y 0.3..0.36 on 200 x 100: 40 x 6 px -> square 40 px -> x 3 = 120 px.
  expect_rect(r, 0.5f, 0.33f, 0.6f, 1.2f, 0.f);
  ASSERT_TRUE(face_region_from_pose(p.data(), 200, 100, r, 1.5f));
  EXPECT_NEAR(r.width, 0.3f, k_eps);
  // Rotation from the right eye (5) to the left eye (2): 10 px right and 10 px down on
  // 100 x 100 is 45 degrees below horizontal, levelled by turning the region clockwise.
  p[2].y = 0.4f;
  ASSERT_TRUE(face_region_from_pose(p.data(), 100, 100, r));
  EXPECT_NEAR(r.rotation, k_pi / 4, k_eps);
  p[7].x = std::numeric_limits<float>::infinity();
  EXPECT_FALSE(face_region_from_pose(p.data(), 100, 100, r));
  p = pose_points();
  EXPECT_FALSE(face_region_from_pose(p.data(), 100, 100, r, 0.f));
}

// ---- generic helpers -----------------------------------------------------------------------

TEST(face_geometry, project_detection_through_letterbox) {
  crop_options o;
  o.output_width = o.output_height = 128;
  crop_transform tr;
  ASSERT_TRUE(make_crop_transform(200, 100, normalized_rect{}, o, tr));
  // The 200 x 100 image letterboxed into a 200 x 200 square: tensor fraction f is image pixel
  // centre + (f - 0.5) * 200.
  detection d;
  d.xmin = 0.25f;
  d.ymin = 0.25f;
  d.width = 0.5f;
  d.height = 0.5f;
  d.keypoint_count = 2;
  d.keypoints[0] = 0.5f;
  d.keypoints[1] = 0.5f;
  d.keypoints[2] = 0.75f;
  d.keypoints[3] = 0.375f;
  const detection p = project_detection(tr, d);
  EXPECT_NEAR(p.xmin, 0.25f, k_eps);
  EXPECT_NEAR(p.width, 0.5f, k_eps);
  EXPECT_NEAR(p.ymin, 0.f, k_eps);
  EXPECT_NEAR(p.height, 1.f, k_eps);
  EXPECT_NEAR(p.keypoints[0], 0.5f, k_eps);
  EXPECT_NEAR(p.keypoints[1], 0.5f, k_eps);
  EXPECT_NEAR(p.keypoints[2], 0.75f, k_eps);
  EXPECT_NEAR(p.keypoints[3], 0.25f, k_eps);
}

TEST(face_geometry, project_detection_through_rotated_region) {
  crop_options o;
  o.output_width = o.output_height = 128;
  crop_transform tr;
  normalized_rect roi{0.5f, 0.5f, 0.5f, 0.5f, k_pi / 2};
  ASSERT_TRUE(make_crop_transform(100, 100, roi, o, tr));
  detection d;
  d.xmin = 0.5f;
  d.ymin = 0.5f;
  d.width = 0.25f;
  d.height = 0.125f;
  d.keypoint_count = 1;
  d.keypoints[0] = 0.75f;  // 12.5 px right of the centre in the region's axes
  d.keypoints[1] = 0.5f;
  const detection p = project_detection(tr, d);
  // Turned 90 degrees clockwise: the region's +x is image +y.
  EXPECT_NEAR(p.keypoints[0], 0.5f, k_eps);
  EXPECT_NEAR(p.keypoints[1], 0.625f, k_eps);
  // Corners (0, 0), (12.5, 0), (12.5, 6.25), (0, 6.25) px -> (0, 0), (0, 12.5), (-6.25, 12.5),
  // (-6.25, 0): x 43.75..50, y 50..62.5.
  EXPECT_NEAR(p.xmin, 0.4375f, k_eps);
  EXPECT_NEAR(p.width, 0.0625f, k_eps);
  EXPECT_NEAR(p.ymin, 0.5f, k_eps);
  EXPECT_NEAR(p.height, 0.125f, k_eps);
}

TEST(face_geometry, rect_contains_rotated) {
  // 40 x 10 px region at the centre of 100 x 100, turned 90 degrees: 10 wide, 40 tall.
  const normalized_rect r{0.5f, 0.5f, 0.4f, 0.1f, k_pi / 2};
  EXPECT_TRUE(normalized_rect_contains(r, 0.5f, 0.5f, 100, 100));
  EXPECT_TRUE(normalized_rect_contains(r, 0.5f, 0.68f, 100, 100));
  EXPECT_FALSE(normalized_rect_contains(r, 0.68f, 0.5f, 100, 100));
  EXPECT_TRUE(normalized_rect_contains(r, 0.54f, 0.5f, 100, 100));
  EXPECT_FALSE(normalized_rect_contains(r, 0.56f, 0.5f, 100, 100));
}

TEST(face_geometry, points_to_rect_rejects_bad_arguments) {
  const float xy[6] = {0.1f, 0.2f, 0.3f, 0.4f, 0.5f, 0.6f};
  normalized_rect r;
  EXPECT_FALSE(points_to_rect(xy, 3, 2, 0, 3, 0.f, 10, 10, r));
  EXPECT_FALSE(points_to_rect(xy, 0, 2, 0, 0, 0.f, 10, 10, r));
  EXPECT_FALSE(points_to_rect(xy, 3, 1, 0, 1, 0.f, 10, 10, r));
  ASSERT_TRUE(points_to_rect(xy, 3, 2, 0, 2, 0.f, 10, 10, r));
  expect_rect(r, 0.3f, 0.4f, 0.4f, 0.4f, k_pi / 4);
}

// face_landmark_with_attention's outputs -> 478 points. Inputs carry their own index so that
// every output point says where it came from.
TEST(face_geometry, refine_face_mesh_assembles_478_points) {
  std::vector<float> mesh(468 * 3), lips(80 * 2), le(71 * 2), re(71 * 2), li(5 * 2), ri(5 * 2);
  for (int i = 0; i < 468; ++i) {
    mesh[i * 3] = static_cast<float>(i);
    mesh[i * 3 + 1] = 1000.f + i;
    mesh[i * 3 + 2] = 2000.f + i;
  }
  auto fill = [](std::vector<float>& v, float base) {
    for (size_t k = 0; k < v.size() / 2; ++k) {
      v[k * 2] = base + k;
      v[k * 2 + 1] = base + 500 + k;
    }
  };
  fill(lips, -10000), fill(le, -20000), fill(re, -30000), fill(li, -40000), fill(ri, -50000);
  std::vector<float> out(478 * 3, std::numeric_limits<float>::quiet_NaN());
  refine_face_mesh(mesh.data(), lips.data(), le.data(), re.data(), li.data(), ri.data(),
                   out.data());
  int from[5] = {0, 0, 0, 0, 0};  // mesh, lips, left eye, right eye, other
  for (int i = 0; i < 468; ++i) {
    EXPECT_EQ(out[i * 3 + 2], 2000.f + i) << i;  // z is never refined
    const float x = out[i * 3];
    const int src = x >= 0 ? 0 : x > -15000 ? 1 : x > -25000 ? 2 : x > -35000 ? 3 : 4;
    ++from[src];
    if (src > 0) EXPECT_EQ(out[i * 3 + 1], x + 500) << i;  // x and y from the same point
  }
  // Disjoint regions: 80 lips + 71 + 71 eye points replaced, the other 246 kept.
  EXPECT_EQ(from[0], 468 - 80 - 71 - 71);
  EXPECT_EQ(from[1], 80);
  EXPECT_EQ(from[2], 71);
  EXPECT_EQ(from[3], 71);
  EXPECT_EQ(from[4], 0);
  // The corners the model's own Landmarks2TransformMatrix operators align each region by
  // (their left / right_rotation_idx options): mouth 61 -> 291, eyes 33 -> 133 and 362 -> 263,
  // are the first and the ninth point of each list.
  EXPECT_EQ(out[61 * 3], -10000.f);
  EXPECT_EQ(out[291 * 3], -10000.f + 10);
  EXPECT_EQ(out[33 * 3], -20000.f);
  EXPECT_EQ(out[133 * 3], -20000.f + 8);
  EXPECT_EQ(out[263 * 3], -30000.f);
  EXPECT_EQ(out[362 * 3], -30000.f + 8);
  // Irises: 468-472 from the left-iris output, 473-477 from the right; depth = the mean depth of
  // the eye's 16 contour points (mean index 143.8125 around point 33, 371.75 around 263).
  for (int k = 0; k < 5; ++k) {
    EXPECT_EQ(out[(468 + k) * 3], -40000.f + k);
    EXPECT_EQ(out[(468 + k) * 3 + 1], -39500.f + k);
    EXPECT_FLOAT_EQ(out[(468 + k) * 3 + 2], 2143.8125f);
    EXPECT_EQ(out[(473 + k) * 3], -50000.f + k);
    EXPECT_FLOAT_EQ(out[(473 + k) * 3 + 2], 2371.75f);
  }
}

}  // namespace
}  // namespace avatarmap
