// The hand graph's geometry (hand_pipeline.hpp): palm anchors and decoding options, the palm
// and landmark regions (palm_detection_detection_to_roi, hand_landmark_landmarks_to_roi) and
// Holistic's hand region from the body. Needs no ONNX Runtime; the generic pieces
// (transform_rect, detection_to_rect, rotated_bounding_rect, ...) are detection.hpp's.
#include <algorithm>
#include <cmath>

#include "avatarmap/capture/hand_pipeline.hpp"

namespace avatarmap {

namespace {

constexpr float k_half_pi = 1.5707963267948966f;

bool finite_point(const landmark& l) { return std::isfinite(l.x) && std::isfinite(l.y); }

}  // namespace

ssd_anchor_options palm_detection_anchor_options() {
  ssd_anchor_options o;
  o.input_width = 192;
  o.input_height = 192;
  o.min_scale = 0.1484375f;
  o.max_scale = 0.75f;
  o.anchor_offset_x = 0.5f;
  o.anchor_offset_y = 0.5f;
  o.num_layers = 4;
  o.strides = {8, 16, 16, 16};
  o.aspect_ratios = {1.0f};
  o.fixed_anchor_size = true;
  return o;
}

detection_decode_options palm_detection_decode_options() {
  detection_decode_options o;
  o.num_boxes = 2016;
  o.num_coords = 18;
  o.box_coord_offset = 0;
  o.keypoint_coord_offset = 4;
  o.num_keypoints = 7;
  o.num_values_per_keypoint = 2;
  o.x_scale = o.y_scale = o.w_scale = o.h_scale = 192.f;
  o.reverse_output_order = true;
  o.sigmoid_score = true;
  o.score_clipping_thresh = 100.f;
  o.min_score_thresh = 0.5f;
  return o;
}

normalized_rect palm_detection_to_roi(const detection& d, int image_width, int image_height) {
  const normalized_rect r = detection_to_rect(d, k_palm_keypoint_wrist, k_palm_keypoint_middle_mcp,
                                              k_half_pi, image_width, image_height);
  rect_transform_options t;
  t.scale_x = t.scale_y = 2.6f;
  t.shift_y = -0.5f;
  t.square_long = true;
  return transform_rect(r, image_width, image_height, t);
}

float hand_landmarks_rotation(const landmark* p, int image_width, int image_height) {
  // Wrist -> mean(middle MCP, mean(index MCP, ring MCP)), measured in pixels.
  const float x1 = ((p[5].x + p[13].x) * 0.5f + p[9].x) * 0.5f;
  const float y1 = ((p[5].y + p[13].y) * 0.5f + p[9].y) * 0.5f;
  return rotation_from_points(p[0].x, p[0].y, x1, y1, image_width, image_height, k_half_pi);
}

bool hand_landmarks_to_roi(const landmark* points, int image_width, int image_height,
                           normalized_rect& out) {
  if (image_width <= 0 || image_height <= 0) return false;
  std::array<float, 2 * k_hand_roi_landmarks.size()> xy{};
  for (size_t i = 0; i < k_hand_roi_landmarks.size(); ++i) {
    const landmark& l = points[k_hand_roi_landmarks[i]];
    if (!finite_point(l)) return false;
    xy[2 * i] = l.x;
    xy[2 * i + 1] = l.y;
  }
  const float rotation = hand_landmarks_rotation(points, image_width, image_height);
  const normalized_rect box =
      rotated_bounding_rect(xy.data(), static_cast<int>(k_hand_roi_landmarks.size()), rotation,
                            image_width, image_height);
  rect_transform_options t;
  t.scale_x = t.scale_y = 2.0f;
  t.shift_y = -0.1f;
  t.square_long = true;
  out = transform_rect(box, image_width, image_height, t);
  return true;
}

bool hand_roi_from_pose(const landmark_frame& pose, body_side side, int image_width,
                        int image_height, normalized_rect& out,
                        const pose_hand_roi_options& options) {
  if (!pose.has(frame_part::pose) || image_width <= 0 || image_height <= 0) return false;
  const int s = side == body_side::left ? 0 : 1;
  const landmark& wrist = pose.pose[idx(pose_landmark::left_wrist) + s];
  const landmark& pinky = pose.pose[idx(pose_landmark::left_pinky) + s];
  const landmark& index = pose.pose[idx(pose_landmark::left_index) + s];
  // NaN visibility fails this test too.
  if (!(wrist.visibility >= options.min_wrist_visibility)) return false;
  if (!finite_point(wrist) || !finite_point(pinky) || !finite_point(index)) return false;
  const float w = static_cast<float>(image_width), h = static_cast<float>(image_height);
  // The middle finger is estimated two thirds of the way from the pinky to the index.
  const float mx = (2.f * index.x + pinky.x) / 3.f, my = (2.f * index.y + pinky.y) / 3.f;
  const float dx = (mx - wrist.x) * w, dy = (my - wrist.y) * h;
  const float box = 2.f * std::sqrt(dx * dx + dy * dy);
  if (!(box > 0.f)) return false;
  normalized_rect r;
  r.x_center = mx;
  r.y_center = my;
  r.width = box / w;
  r.height = box / h;
  r.rotation = rotation_from_points(wrist.x, wrist.y, mx, my, image_width, image_height, k_half_pi);
  rect_transform_options t;
  t.scale_x = t.scale_y = options.scale;
  t.shift_y = options.shift_y;
  t.square_long = true;
  out = transform_rect(r, image_width, image_height, t);
  return true;
}

body_side hand_side_from_handedness(float left_label_score, bool mirrored_input,
                                    float* out_left_probability) {
  const float p = mirrored_input ? left_label_score : 1.f - left_label_score;
  if (out_left_probability) *out_left_probability = p;
  return p >= 0.5f ? body_side::left : body_side::right;
}

}  // namespace avatarmap
