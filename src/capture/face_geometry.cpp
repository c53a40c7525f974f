// Geometry of MediaPipe's face graphs (face_pipeline.hpp): the face detector's anchors and
// decoding options, and the regions of interest built from detections, from the mesh and from
// the body's face points. Needs no ONNX Runtime; the generic pieces reuse detection.hpp.
#include <algorithm>
#include <cmath>

#include "avatarmap/capture/face_pipeline.hpp"

namespace avatarmap {

namespace {

// Mesh points that align the tracking region (FaceLandmarkLandmarksToRoi).
constexpr int k_mesh_right_eye_outer = 33;
constexpr int k_mesh_left_eye_outer = 263;
// Body points that make the face search region (FaceLandmarksFromPoseToRecropRoi): 0-10.
constexpr int k_pose_face_points = 11;
constexpr int k_pose_right_eye = 5;
constexpr int k_pose_left_eye = 2;

// Mesh points that face_landmark_with_attention's refined regions replace, in the order of the
// model's outputs (MediaPipe's tensors_to_face_landmarks_with_attention.pbtxt; the same lists
// are the subsets its Landmarks2TransformMatrix operators crop).
constexpr int k_refined_lips[k_face_refined_lips] = {
    61, 146, 91, 181, 84, 17, 314, 405, 321, 375, 291, 185, 40, 39, 37, 0,  267, 269, 270, 409,
    78, 95,  88, 178, 87, 14, 317, 402, 318, 324, 308, 191, 80, 81, 82, 13, 312, 311, 310, 415,
    76, 77,  90, 180, 85, 16, 315, 404, 320, 307, 306, 184, 74, 73, 72, 11, 302, 303, 304, 408,
    62, 96,  89, 179, 86, 15, 316, 403, 319, 325, 292, 183, 42, 41, 38, 12, 268, 271, 272, 407};
constexpr int k_refined_left_eye[k_face_refined_eye] = {
    33,  7,   163, 144, 145, 153, 154, 155, 133, 246, 161, 160, 159, 158, 157, 173, 130, 25,
    110, 24,  23,  22,  26,  112, 243, 247, 30,  29,  27,  28,  56,  190, 226, 31,  228, 229,
    230, 231, 232, 233, 244, 113, 225, 224, 223, 222, 221, 189, 35,  124, 46,  53,  52,  65,
    143, 111, 117, 118, 119, 120, 121, 128, 245, 156, 70,  63,  105, 66,  107, 55,  193};
constexpr int k_refined_right_eye[k_face_refined_eye] = {
    263, 249, 390, 373, 374, 380, 381, 382, 362, 466, 388, 387, 386, 385, 384, 398, 359, 255,
    339, 254, 253, 252, 256, 341, 463, 467, 260, 259, 257, 258, 286, 414, 446, 261, 448, 449,
    450, 451, 452, 453, 464, 342, 445, 444, 443, 442, 441, 413, 265, 353, 276, 283, 282, 295,
    372, 340, 346, 347, 348, 349, 350, 357, 465, 383, 300, 293, 334, 296, 336, 285, 417};
// An iris's depth is the mean depth of its eye's contour: the first 16 points of each eye list.
constexpr int k_eye_contour_points = 16;

void overwrite_xy(const int* indices, int count, const float* xy, float* out) {
  for (int k = 0; k < count; ++k) {
    out[indices[k] * 3] = xy[k * 2];
    out[indices[k] * 3 + 1] = xy[k * 2 + 1];
  }
}

void place_iris(const float* iris, const int* eye, int first, float* out) {
  float z = 0.f;
  for (int k = 0; k < k_eye_contour_points; ++k) z += out[eye[k] * 3 + 2];
  z /= static_cast<float>(k_eye_contour_points);
  for (int k = 0; k < k_face_refined_iris; ++k) {
    out[(first + k) * 3] = iris[k * 2];
    out[(first + k) * 3 + 1] = iris[k * 2 + 1];
    out[(first + k) * 3 + 2] = z;
  }
}

}  // namespace

void refine_face_mesh(const float* mesh, const float* lips, const float* left_eye,
                      const float* right_eye, const float* left_iris, const float* right_iris,
                      float* out) {
  std::copy(mesh, mesh + k_face_mesh_count * 3, out);
  overwrite_xy(k_refined_lips, k_face_refined_lips, lips, out);
  overwrite_xy(k_refined_left_eye, k_face_refined_eye, left_eye, out);
  overwrite_xy(k_refined_right_eye, k_face_refined_eye, right_eye, out);
  place_iris(left_iris, k_refined_left_eye, k_face_mesh_count, out);
  place_iris(right_iris, k_refined_right_eye, k_face_mesh_count + k_face_refined_iris, out);
}

ssd_anchor_options face_detection_anchor_options() {
  // face_detection_short_range.pbtxt + face_detection.pbtxt (SsdAnchorsCalculator).
  ssd_anchor_options o;
  o.input_width = k_face_detector_size;
  o.input_height = k_face_detector_size;
  o.min_scale = 0.1484375f;
  o.max_scale = 0.75f;
  o.anchor_offset_x = 0.5f;
  o.anchor_offset_y = 0.5f;
  o.num_layers = 4;
  o.strides = {8, 16, 16, 16};
  o.aspect_ratios = {1.0f};
  o.reduce_boxes_in_lowest_layer = false;
  o.interpolated_scale_aspect_ratio = 1.0f;
  o.fixed_anchor_size = true;
  return o;
}

detection_decode_options face_detection_decode_options(float min_score) {
  detection_decode_options o;
  o.num_boxes = 896;
  o.num_coords = 16;
  o.box_coord_offset = 0;
  o.keypoint_coord_offset = 4;
  o.num_keypoints = face_detection_keypoint::count;
  o.num_values_per_keypoint = 2;
  o.x_scale = o.y_scale = o.w_scale = o.h_scale = static_cast<float>(k_face_detector_size);
  o.reverse_output_order = true;
  o.sigmoid_score = true;
  o.score_clipping_thresh = 100.f;
  o.min_score_thresh = min_score;
  return o;
}

normalized_rect face_detection_to_roi(const detection& d, int image_width, int image_height) {
  // FaceDetectionFrontDetectionToRoi: DetectionsToRects (box; keypoint 0 -> 1, target 0)
  // then RectTransformation (x 1.5, square_long).
  const normalized_rect r =
      detection_to_rect(d, face_detection_keypoint::right_eye, face_detection_keypoint::left_eye,
                        0.f, image_width, image_height);
  rect_transform_options t;
  t.scale_x = t.scale_y = 1.5f;
  t.square_long = true;
  return transform_rect(r, image_width, image_height, t);
}

normalized_rect face_detection_keypoints_to_roi(const detection& d, int image_width,
                                                int image_height) {
  // Holistic's FaceDetectionFrontDetectionsToRoi: DetectionsToRects USE_KEYPOINTS (keypoint
  // 0 -> 1, target 0) then RectTransformation (x 2, shift_y -0.1, square_long).
  normalized_rect r;
  if (!points_to_rect(d.keypoints.data(), d.keypoint_count, 2, face_detection_keypoint::right_eye,
                      face_detection_keypoint::left_eye, 0.f, image_width, image_height, r))
    r = detection_to_rect(d, -1, -1, 0.f, image_width, image_height);
  rect_transform_options t;
  t.scale_x = t.scale_y = 2.0f;
  t.shift_y = -0.1f;
  t.square_long = true;
  return transform_rect(r, image_width, image_height, t);
}

bool face_landmarks_to_roi(const landmark* mesh, int count, int image_width, int image_height,
                           normalized_rect& out) {
  if (mesh == nullptr || count <= k_mesh_left_eye_outer) return false;
  static_assert(sizeof(landmark) % sizeof(float) == 0, "landmark is a run of floats");
  normalized_rect r;
  if (!points_to_rect(&mesh[0].x, count, static_cast<int>(sizeof(landmark) / sizeof(float)),
                      k_mesh_right_eye_outer, k_mesh_left_eye_outer, 0.f, image_width, image_height,
                      r))
    return false;
  rect_transform_options t;
  t.scale_x = t.scale_y = 1.5f;
  t.square_long = true;
  out = transform_rect(r, image_width, image_height, t);
  return true;
}

bool face_region_from_pose(const landmark* pose, int image_width, int image_height,
                           normalized_rect& out, float scale) {
  if (pose == nullptr || !(scale > 0.f)) return false;
  normalized_rect r;
  if (!points_to_rect(&pose[0].x, k_pose_face_points,
                      static_cast<int>(sizeof(landmark) / sizeof(float)), k_pose_right_eye,
                      k_pose_left_eye, 0.f, image_width, image_height, r))
    return false;
  rect_transform_options t;
  t.scale_x = t.scale_y = scale;
  t.square_long = true;
  out = transform_rect(r, image_width, image_height, t);
  return true;
}

}  // namespace avatarmap
