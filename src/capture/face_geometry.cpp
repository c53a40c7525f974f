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

}  // namespace

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
