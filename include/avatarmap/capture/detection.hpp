// Detection geometry shared by the capture pipelines (MediaPipe's calculators, in plain C++
// with no ONNX Runtime): SSD anchors, decoding detector outputs, weighted non-max
// suppression, and the regions of interest built from detections and landmarks.
//
// Spaces: "normalised" means MediaPipe's normalised image coordinates (x / image width, y /
// image height, y down; image_crop.hpp). Rotations are radians, positive clockwise on screen.
#pragma once

#include <array>
#include <vector>

#include "avatarmap/capture/image_crop.hpp"

namespace avatarmap {

// ---- SSD anchors (MediaPipe's SsdAnchorsCalculator) ---------------------------------------

/// One anchor: centre and size as fractions of the detector input (1 x 1 with
/// fixed_anchor_size).
struct ssd_anchor {
  float x_center = 0.f;
  float y_center = 0.f;
  float width = 1.f;
  float height = 1.f;
};

/// SsdAnchorsCalculatorOptions. Layers that share a stride share one feature map, their
/// anchors interleaved per cell, as MediaPipe does.
struct ssd_anchor_options {
  int input_width = 224;
  int input_height = 224;
  float min_scale = 0.1484375f;
  float max_scale = 0.75f;
  float anchor_offset_x = 0.5f;
  float anchor_offset_y = 0.5f;
  int num_layers = 5;
  std::vector<int> strides{8, 16, 32, 32, 32};  // one per layer
  std::vector<float> aspect_ratios{1.0f};
  /// Empty: ceil(input / stride). Else one per layer.
  std::vector<int> feature_map_width{};
  std::vector<int> feature_map_height{};
  bool reduce_boxes_in_lowest_layer = false;
  /// > 0: one more anchor per cell with scale sqrt(scale * next scale) and this aspect.
  float interpolated_scale_aspect_ratio = 1.0f;
  bool fixed_anchor_size = true;
};

/// Generates the anchors into `out` (replaced). Returns false (out empty) when num_layers
/// <= 0, strides has fewer than num_layers entries or a stride <= 0, aspect_ratios is empty,
/// an input size <= 0, or a feature map list is given with fewer than num_layers entries.
bool generate_ssd_anchors(const ssd_anchor_options& options, std::vector<ssd_anchor>& out);

// ---- detections ----------------------------------------------------------------------------

inline constexpr int k_detection_max_keypoints = 8;

/// A detection in normalised coordinates of the space it was decoded in (the detector input
/// until projected back to the image): box corner and size, score in [0, 1] and keypoints.
struct detection {
  float score = 0.f;
  float xmin = 0.f;
  float ymin = 0.f;
  float width = 0.f;
  float height = 0.f;
  int keypoint_count = 0;
  std::array<float, 2 * k_detection_max_keypoints> keypoints{};  // x0, y0, x1, y1, ...
};

/// TensorsToDetectionsCalculatorOptions (single class, no exponential box size). The
/// defaults are pose_detection's.
struct detection_decode_options {
  int num_boxes = 2254;
  int num_coords = 12;
  int box_coord_offset = 0;
  int keypoint_coord_offset = 4;
  int num_keypoints = 4;  // <= k_detection_max_keypoints
  int num_values_per_keypoint = 2;
  float x_scale = 224.f;
  float y_scale = 224.f;
  float w_scale = 224.f;
  float h_scale = 224.f;
  bool reverse_output_order = true;  // boxes stored x, y, w, h (else y, x, h, w)
  bool sigmoid_score = true;
  float score_clipping_thresh = 100.f;  // raw scores clipped to +-this before the sigmoid
  float min_score_thresh = 0.5f;        // detections scoring below are dropped
};

/// Decodes raw model outputs (`raw_boxes`: num_boxes x num_coords, `raw_scores`: num_boxes)
/// against `anchors` (num_boxes of them) into `out` (cleared first; keeps its capacity, so a
/// vector reserved to num_boxes never allocates). Returns the number of detections.
int decode_detections(const float* raw_boxes, const float* raw_scores, const ssd_anchor* anchors,
                      const detection_decode_options& options, std::vector<detection>& out);

/// Intersection over union of two boxes; 0 when they do not overlap or on a zero union.
float detection_iou(const detection& a, const detection& b);

/// MediaPipe's weighted non-max suppression (NonMaxSuppressionCalculator, WEIGHTED,
/// INTERSECTION_OVER_UNION): repeatedly takes the best remaining detection, averages the box
/// and keypoints of every remaining detection overlapping it by more than `iou_threshold`
/// (itself included) weighted by score, keeps the best score. At most `max_detections`
/// results (<= 0: no limit), best first, into `out` (cleared first). `scratch` holds indices;
/// both keep their capacity. Returns the number of results.
int weighted_non_max_suppression(const std::vector<detection>& detections, float iou_threshold,
                                 int max_detections, std::vector<detection>& out,
                                 std::vector<int>& scratch);

// ---- regions of interest -------------------------------------------------------------------

/// How a pair of alignment points becomes a region: DetectionsToRects with rotation
/// (AlignmentPointsRects) followed by RectTransformation.
struct roi_from_points_options {
  float target_angle = 1.5707963267948966f;  // radians; 90 degrees: the body stands upright
  float scale_x = 1.25f;
  float scale_y = 1.25f;
  bool square_long = true;  // make the region square in pixels on its long side first
};

/// The region centred on `center` (normalised) whose half side is the pixel distance from
/// `center` to `scale_point`, rotated so that the vector center -> scale_point points to
/// `target_angle` (90 degrees = up), then squared and scaled. Needs image sizes > 0.
normalized_rect roi_from_alignment_points(float center_x, float center_y, float scale_x_point,
                                          float scale_y_point, int image_width, int image_height,
                                          const roi_from_points_options& options = {});

/// RectTransformationCalculator: shifts the region by (shift_x * width, shift_y * height)
/// along its own rotated axes, optionally squares it on its long side in pixels, then scales
/// its size. Needs image sizes > 0.
struct rect_transform_options {
  float scale_x = 1.f;
  float scale_y = 1.f;
  float shift_x = 0.f;
  float shift_y = 0.f;
  bool square_long = true;
};
normalized_rect transform_rect(const normalized_rect& r, int image_width, int image_height,
                               const rect_transform_options& options);

/// DetectionsToRectsCalculator with rotation: the detection's box (normalised) as a region,
/// rotated so that the vector from keypoint `start_keypoint` to `end_keypoint` points to
/// `target_angle` (radians; 0 = right, 90 degrees = up). Keypoint indices must be below
/// d.keypoint_count (else the rotation is 0).
normalized_rect detection_to_rect(const detection& d, int start_keypoint, int end_keypoint,
                                  float target_angle, int image_width, int image_height);

/// The rotation DetectionsToRects gives for the vector (x0, y0) -> (x1, y1) (normalised).
float rotation_from_points(float x0, float y0, float x1, float y1, int image_width,
                           int image_height, float target_angle);

/// HandLandmarksToRectCalculator's box: the tightest region with rotation `rotation` around
/// `count` points (`xy`: x0, y0, x1, y1, ... normalised). count >= 1.
normalized_rect rotated_bounding_rect(const float* xy, int count, float rotation, int image_width,
                                      int image_height);

/// LandmarksToDetection + DetectionsToRects (default conversion): the axis-aligned bounding
/// box of `count` points (normalised, x and y read from `xy` with `stride_floats` floats per
/// point) with the rotation that makes point `start` -> point `end` point to `target_angle`
/// (radians). Returns false when count < 1, start or end is out of range, or a point is not
/// finite.
bool points_to_rect(const float* xy, int count, int stride_floats, int start, int end,
                    float target_angle, int image_width, int image_height, normalized_rect& out);

/// DetectionProjection: a detection decoded in fractions of the crop tensor (as
/// decode_detections gives it) mapped through the crop's transform to normalised image
/// coordinates: keypoints exactly, the box as the axis-aligned box around its 4 projected
/// corners.
detection project_detection(const crop_transform& transform, const detection& d);

/// Intersection over union of two regions, as MediaPipe's AssociationNormRectCalculator
/// measures them: axis-aligned boxes (the rotation is ignored) in pixels. 0 when they do not
/// overlap or on an empty union.
float normalized_rect_iou(const normalized_rect& a, const normalized_rect& b, int image_width,
                          int image_height);

/// Whether the point (x, y) (normalised) lies inside the rotated region `r`.
bool normalized_rect_contains(const normalized_rect& r, float x, float y, int image_width,
                              int image_height);

/// MediaPipe's angle normalisation into [-pi, pi).
float normalize_radians(float angle);

}  // namespace avatarmap
