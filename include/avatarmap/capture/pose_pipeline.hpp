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
// The geometry is in detection.hpp (plain C++, always built); pose_pipeline itself needs
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

#include "avatarmap/capture/detection.hpp"
#include "avatarmap/capture/estimator.hpp"
#include "avatarmap/capture/image_crop.hpp"
#include "avatarmap/core/status.hpp"
#include "avatarmap/landmarks/landmark_frame.hpp"

namespace avatarmap {

/// The anchors of MediaPipe's pose_detection graph (2254 anchors, 224 x 224 input).
ssd_anchor_options pose_detection_anchor_options();

/// The pose region of a detection in normalised image coordinates (keypoints 0 and 1).
normalized_rect pose_detection_to_roi(const detection& d, int image_width, int image_height,
                                      const roi_from_points_options& options = {});

// ---- the pipeline (AVATARMAP_WITH_ONNX) ----------------------------------------------------

/// The landmark model file: pose_landmark_{lite,full,heavy}.onnx.
enum class pose_model_complexity : std::uint8_t { lite = 0, full = 1, heavy = 2 };

/// Temporal smoothing of the landmarks in video mode. World points get MediaPipe's One Euro
/// (0.1 Hz, beta 40, unscaled) and visibility its low-pass (0.1) except with `none`.
enum class pose_smoothing : std::uint8_t {
  /// tfjs-models' BlazePose (and MediaPipe's graphs before 0.9): velocity filters (window 5,
  /// velocity scale 10) on the image landmarks and on the two auxiliary points that steer the
  /// next region. The default: it agrees best with Google's reference video landmarks.
  velocity,
  /// MediaPipe's current pose_landmark_filtering: One Euro (0.05 Hz, beta 80) on the image
  /// landmarks, (0.01 Hz, beta 10) on the auxiliary points.
  one_euro,
  none,  // raw model output
};

struct pose_pipeline_options {
  /// Folder holding pose_detection.onnx and pose_landmark_<complexity>.onnx (converted with
  /// tools/convert/tflite2onnx.py; the landmark model may keep or drop its segmentation and
  /// heatmap outputs: when it keeps the heatmap, landmarks are refined from it as MediaPipe's
  /// RefineLandmarksFromHeatmap does, at about +1 ms per frame).
  std::string models_dir;
  pose_model_complexity complexity = pose_model_complexity::full;
  /// float32: pose_detection.onnx etc.; int8: pose_detection.int8.onnx etc.
  model_precision precision = model_precision::float32;
  int intra_op_threads = 1;     // ORT intra-op threads, >= 1
  bool allow_spinning = false;  // ORT's spinning thread pool; off: better when cores are shared
  float min_detection_score = 0.5f;  // detector score threshold, (0, 1)
  float nms_iou_threshold = 0.3f;    // weighted NMS overlap threshold, (0, 1]
  float min_presence = 0.5f;         // landmark model presence flag below this: lost
  bool static_images = false;        // true: run the detector on every frame
  /// Video mode (static_images false): how landmarks are smoothed over time
  /// (landmark_smoothing.hpp), using the frame's time out.t.
  pose_smoothing smoothing = pose_smoothing::velocity;
  /// How the crops sample the image (image_crop.hpp): `gl`, MediaPipe's OpenGL converter (its
  /// GPU and web graphs, which made the goldens: docs/capture.md), or `opencv`, its CPU one.
  crop_sampling sampling = crop_sampling::gl;
  /// Lift dim, low-contrast model inputs before the models see them (low_light.hpp); inputs
  /// whose luma range is wide enough are untouched.
  bool low_light = true;
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

  /// Processes one frame (out.t is its time in seconds, for the smoothing): sets the pose (33
  /// points, normalised image coordinates, z in units of the image width, visibility and presence)
  /// and pose_world (metres, origin at the hip centre, rotated back to the image's axes) parts of
  /// `out` when found, clears them otherwise; other parts are untouched. No allocation in the
  /// steady state (outside ORT).
  pose_result process(const image_view& image, landmark_frame& out);

  /// Forgets the tracked region: the next frame runs the detector.
  void reset();

  // ---- several people (estimator_options::max_people > 1) ----
  // Each person slot keeps its own tracked region and smoothing; the models are shared, so
  // the people of a frame run one after another. Slot 0 is selected at creation, and the
  // single-person capture uses only it.

  /// Makes slot `person` (0 .. k_max_people - 1, clamped) the one process(), reset(),
  /// start_track(), tracking(), tracked_roi() and last_roi() act on.
  void select_person(int person);
  /// Runs the detector on the whole image: the regions of up to `max` (1 .. k_max_people)
  /// people, best detection score first, into out_rois, their scores into out_scores and
  /// their hip centre (keypoint 0) and shoulder centre (keypoint 2) into out_anchors as x0, y0,
  /// x2, y2 (normalised; room for 4 x `max`). Returns how many (0: nobody), or -1 on an error
  /// (last_error()). Touches no person's state.
  int detect_people(const image_view& image, int max, normalized_rect* out_rois, float* out_scores,
                    float* out_anchors);
  /// Starts the selected person's track at `roi` (normalised; a region detect_people() gave):
  /// the next process() runs the landmark model there without the detector (also with
  /// static_images), with fresh smoothing.
  void start_track(const normalized_rect& roi);
  /// The region tracked into the selected person's next frame (meaningful when tracking()).
  const normalized_rect& tracked_roi() const;

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
