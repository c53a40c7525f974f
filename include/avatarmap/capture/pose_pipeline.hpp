// The body part of the ONNX capture backend: MediaPipe's pose graph (pose_landmark_cpu) around
// the pose_detection and pose_landmark_{lite,full,heavy} models.
//
// Detect once, then track: the detector runs on the first frame (and whenever tracking is
// lost); it yields a detection whose keypoints 0 (hip centre) and 1 (a point encoding the
// body's size and rotation) give a rotated square region of interest. The landmark model runs
// on that region (a rotated, letterboxed 256x256 crop) and, besides the 33 landmarks, returns
// auxiliary points 33 and 34 from which the next frame's region is built the same way. When
// the landmark model's presence flag drops below a threshold the detector runs again.
//
// The geometry (SSD anchors, detection decoding, weighted non-max suppression, detection and
// landmarks to region of interest) is plain C++ and always built; pose_pipeline itself needs
// AVATARMAP_WITH_ONNX (ONNX Runtime never appears in this header).
//
// Spaces: "normalised" means MediaPipe's normalised image coordinates (x / image width, y /
// image height, y down; image_crop.hpp). Rotations are radians, positive clockwise on screen.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "avatarmap/capture/estimator.hpp"
#include "avatarmap/capture/image_crop.hpp"
#include "avatarmap/core/status.hpp"
#include "avatarmap/landmarks/landmark_frame.hpp"

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

/// The anchors of MediaPipe's pose_detection graph (2254 anchors, 224 x 224 input).
ssd_anchor_options pose_detection_anchor_options();

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

/// The pose region of a detection in normalised image coordinates (keypoints 0 and 1).
normalized_rect pose_detection_to_roi(const detection& d, int image_width, int image_height,
                                      const roi_from_points_options& options = {});

/// MediaPipe's angle normalisation into [-pi, pi).
float normalize_radians(float angle);

// ---- the pipeline (AVATARMAP_WITH_ONNX) ----------------------------------------------------

/// The landmark model file: pose_landmark_{lite,full,heavy}.onnx.
enum class pose_model_complexity : std::uint8_t { lite = 0, full = 1, heavy = 2 };

struct pose_pipeline_options {
  /// Folder holding pose_detection.onnx and pose_landmark_<complexity>.onnx (converted with
  /// tools/convert/tflite2onnx.py; the landmark model may keep or drop its segmentation and
  /// heatmap outputs: when it keeps the heatmap, landmarks are refined from it as MediaPipe's
  /// RefineLandmarksFromHeatmap does, at about +1 ms per frame).
  std::string models_dir;
  pose_model_complexity complexity = pose_model_complexity::full;
  int intra_op_threads = 1;     // ORT intra-op threads, >= 1
  bool allow_spinning = false;  // ORT's spinning thread pool; off: better when cores are shared
  float min_detection_score = 0.5f;  // detector score threshold, (0, 1)
  float nms_iou_threshold = 0.3f;    // weighted NMS overlap threshold, (0, 1]
  float min_presence = 0.5f;         // landmark model presence flag below this: lost
  bool static_images = false;        // true: run the detector on every frame
};

/// Time spent in the last process() call, milliseconds (0 for a stage that did not run).
struct pose_timings {
  double detector_ms = 0.0;  // crop + inference + decode + NMS
  double detector_inference_ms = 0.0;
  double landmark_ms = 0.0;  // crop + inference + projection
  double landmark_inference_ms = 0.0;
};

enum class pose_result : std::uint8_t {
  found,      // pose and pose_world written
  not_found,  // no person (detector found none, or presence below min_presence)
  error,      // bad image or an ONNX Runtime failure: see last_error()
};

/// Runs the pose graph on a sequence of frames. Owns the ORT sessions and every buffer; one
/// instance per video stream; not thread-safe (one process() at a time).
class pose_pipeline {
 public:
  /// Loads the models. Fails (naming the file) when a model is missing, does not load, or has
  /// unexpected input or output shapes; or when an option is out of range.
  static status create(const pose_pipeline_options& options, std::unique_ptr<pose_pipeline>& out);
  ~pose_pipeline();
  pose_pipeline(const pose_pipeline&) = delete;
  pose_pipeline& operator=(const pose_pipeline&) = delete;

  /// Processes one frame: sets the pose (33 points, normalised image coordinates, z in units
  /// of the image width, visibility and presence) and pose_world (metres, origin at the hip
  /// centre, rotated back to the image's axes) parts of `out` when found, clears them
  /// otherwise; other parts are untouched. No allocation in the steady state (outside ORT).
  pose_result process(const image_view& image, landmark_frame& out);

  /// Forgets the tracked region: the next frame runs the detector.
  void reset();

  /// Region used for the last landmark inference, and the one tracked for the next frame.
  const normalized_rect& last_roi() const;
  bool tracking() const;
  /// Landmark model presence flag of the last frame in [0, 1].
  float last_presence() const;
  /// Whether the last process() ran the detector.
  bool last_ran_detector() const;
  const pose_timings& last_timings() const;
  /// Whether the landmark model has its heatmap output, so landmarks are refined from it.
  bool refines_from_heatmap() const;
  /// Message of the last error result; valid until the next process().
  const std::string& last_error() const;

 private:
  struct impl;
  explicit pose_pipeline(std::unique_ptr<impl> p);
  std::unique_ptr<impl> impl_;
};

}  // namespace avatarmap
