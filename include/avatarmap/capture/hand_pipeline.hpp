// The hand part of the ONNX capture backend: MediaPipe's hand graph (hand_landmark_tracking_cpu)
// around the palm_detection_{lite,full} and hand_landmark_{lite,full} models, plus MediaPipe
// Holistic's second way to find a hand: a region built from the body's wrist, pinky and index
// landmarks.
//
// Detect (or derive from the body) once, then track: each of up to two hands is followed in
// its own slot. A slot that has no hand is filled either from the body's landmarks (cheap: no
// model runs) or from the palm detector (one run per frame at most, ~9 ms); the landmark model
// then runs on a rotated, letterboxed 224x224 crop of the hand's region and, when its presence
// flag passes, the next frame's region is built from the landmarks (HandLandmarksToRect).
//
// The geometry (declared here, src/capture/hand_geometry.cpp) is plain C++ and always built;
// hand_pipeline itself needs AVATARMAP_WITH_ONNX (ONNX Runtime never appears in this header).
//
// Spaces: "normalised" means MediaPipe's normalised image coordinates (x / image width, y /
// image height, y down; image_crop.hpp). Rotations are radians, positive clockwise on screen.
// Sides are the person's (landmark_frame.hpp): see hand_pipeline_options::mirrored_input.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <string>

#include "avatarmap/capture/detection.hpp"
#include "avatarmap/capture/estimator.hpp"
#include "avatarmap/capture/image_crop.hpp"
#include "avatarmap/core/status.hpp"
#include "avatarmap/landmarks/landmark_frame.hpp"

namespace avatarmap {

// ---- geometry (always built) ---------------------------------------------------------------

/// The anchors of MediaPipe's palm_detection graph: 192 x 192 input, 4 layers with strides
/// 8, 16, 16, 16 (24x24x2 + 12x12x6 = 2016 anchors), fixed size.
ssd_anchor_options palm_detection_anchor_options();

/// TensorsToDetections options of the palm detector: 2016 boxes of 18 values (box x, y, w, h
/// then 7 keypoints x, y), scales 192, sigmoid scores clipped to +-100, threshold 0.5.
detection_decode_options palm_detection_decode_options();

/// Palm detection keypoints (MediaPipe's order).
inline constexpr int k_palm_keypoint_wrist = 0;
inline constexpr int k_palm_keypoint_middle_mcp = 2;

/// PalmDetectionDetectionToRoi: the hand region of a palm detection (box and keypoints in
/// normalised image coordinates): the box rotated so that wrist (keypoint 0) -> middle-finger
/// MCP (keypoint 2) points up, shifted by -0.5 of its height along that direction, squared on
/// its long side and scaled by 2.6. Needs d.keypoint_count >= 3 (else rotation 0) and image
/// sizes > 0.
normalized_rect palm_detection_to_roi(const detection& d, int image_width, int image_height);

/// The 12 landmarks HandLandmarkLandmarksToRoi keeps (wrist, the thumb's CMC/MCP/IP and the
/// MCP and PIP of the four fingers): stable across frames, unlike the fingertips.
inline constexpr std::array<int, 12> k_hand_roi_landmarks = {0, 1,  2,  3,  5,  6,
                                                             9, 10, 13, 14, 17, 18};

/// HandLandmarksToRectCalculator's rotation: the vector from the wrist to the mean of the
/// middle-finger MCP and the midpoint of the index and ring MCPs, turned to point up (in
/// pixels). (MediaPipe names these "PIP" joints; on the 12-point subset its indices 4, 6, 8
/// are the MCPs 5, 9, 13.) `points`: 21 hand landmarks, normalised.
float hand_landmarks_rotation(const landmark* points, int image_width, int image_height);

/// HandLandmarkLandmarksToRoi: the next frame's region from 21 hand landmarks (normalised):
/// the tightest box with hand_landmarks_rotation() around k_hand_roi_landmarks, shifted by
/// -0.1 of its height towards the fingers, squared on its long side, scaled by 2.0. Returns
/// false (out untouched) when a used landmark is not finite or an image size is <= 0.
bool hand_landmarks_to_roi(const landmark* points, int image_width, int image_height,
                           normalized_rect& out);

/// Which of the person's hands.
enum class body_side : std::uint8_t { left = 0, right = 1 };

/// Options of hand_roi_from_pose (MediaPipe Holistic's HandLandmarksFromPoseToRecropRoi).
struct pose_hand_roi_options {
  float min_wrist_visibility = 0.1f;  // pose wrist visibility below this: no region
  float scale = 2.7f;                 // RectTransformation scale_x = scale_y
  float shift_y = -0.1f;              // along the region's up axis, fraction of its height
};

/// Holistic's hand region from the body: pose landmarks wrist, pinky and index of `side`
/// (15/17/19 left, 16/18/20 right; person's sides, normalised coordinates of the same image).
/// The hand centre is estimated at the middle finger, (2 * index + pinky) / 3; the box is
/// twice its distance from the wrist, rotated so wrist -> middle points up, then shifted,
/// squared and scaled (HandDetectionsFromPoseToRectsCalculator + RectTransformation).
/// Holistic refines this region with its hand_recrop model, which is not used here: the
/// region is the landmark model's first crop directly. Returns false (out untouched) when
/// `pose` lacks the pose part, the wrist's visibility is below the threshold, a point is
/// not finite, the box is empty, or an image size is <= 0.
bool hand_roi_from_pose(const landmark_frame& pose, body_side side, int image_width,
                        int image_height, normalized_rect& out,
                        const pose_hand_roi_options& options = {});

/// The person's side of a hand from the landmark model's handedness output `left_label_score`
/// (the probability of MediaPipe's label "Left", which assumes a mirrored, selfie-view image):
/// on a mirrored image "Left" is the person's left hand, on a raw camera image it is the
/// person's right hand. Writes the probability that the hand is the person's left into
/// out_left_probability when non-null.
body_side hand_side_from_handedness(float left_label_score, bool mirrored_input,
                                    float* out_left_probability = nullptr);

// ---- the pipeline (AVATARMAP_WITH_ONNX) ----------------------------------------------------

/// The model files: palm_detection_<c>.onnx and hand_landmark_<c>.onnx (MediaPipe's Hands
/// uses one complexity for both; so does this).
enum class hand_model_complexity : std::uint8_t { lite = 0, full = 1 };

/// Where a hand that is not tracked is looked for.
enum class hand_roi_source : std::uint8_t {
  automatic,  // from the body when process() is given a frame with the pose part, else palm
  palm,       // always the palm detector
  pose,       // always the body (no body: no new hand; tracked hands continue)
};

struct hand_pipeline_options {
  /// Folder holding palm_detection_<c>.onnx and hand_landmark_<c>.onnx (converted with
  /// tools/convert/tflite2onnx.py). The palm detector is loaded even when only pose regions
  /// are used (roi_source = pose), so that the source can change per frame.
  std::string models_dir;
  hand_model_complexity complexity = hand_model_complexity::full;
  /// float32: palm_detection_<c>.onnx etc.; int8: palm_detection_<c>.int8.onnx etc.
  model_precision precision = model_precision::float32;
  int max_hands = 2;  // 1 or 2
  hand_roi_source roi_source = hand_roi_source::automatic;
  /// false (the default): the images are raw camera images (not mirrored), so the person's
  /// left hand appears at larger x; MediaPipe's handedness label, trained on mirrored selfie
  /// images, is swapped accordingly. true: the images are mirrored (selfie view), MediaPipe's
  /// label is the person's side as is. Only palm-detected hands use it: a hand found from
  /// the body takes the side of the pose wrist it came from.
  bool mirrored_input = false;
  int intra_op_threads = 1;     // ORT intra-op threads, >= 1
  bool allow_spinning = false;  // ORT's spinning thread pool; off: better when cores are shared
  float min_detection_score = 0.5f;  // palm detector score threshold, (0, 1)
  float nms_iou_threshold = 0.3f;    // weighted NMS overlap threshold, (0, 1]
  float min_presence = 0.5f;         // landmark model presence below this: hand lost, [0, 1]
  /// A new palm region overlapping a tracked hand's region by more than this (IoU, rotation
  /// ignored) is dropped (MediaPipe's AssociationNormRect, 0.5); two hands found in one frame
  /// whose next regions overlap by more than this are one hand seen twice: the one with the
  /// lower presence (or, with pose regions, the one whose wrist is farther from its pose
  /// wrist) is dropped. (0, 1].
  float max_overlap = 0.5f;
  /// Regions from the body (Holistic's, sized for its hand_recrop model, which is not used
  /// here) are about twice as loose as a hand's tracked region; true: a hand found from the
  /// body is run a second time, on the region of its first landmarks, in the same frame (one
  /// more landmark run on the frames a hand is acquired from the body).
  bool refine_pose_roi = true;
  pose_hand_roi_options pose_roi{};
  bool static_images = false;  // true: nothing is tracked, every frame starts afresh
  /// With a body: move a tracked hand's region by the body's wrist motion since the last
  /// frame before running the landmark model (not in MediaPipe). At low frame rates a
  /// moving hand leaves last frame's region; this keeps it tracked (one landmark run)
  /// instead of lost and found again from the body (two runs).
  bool follow_body_motion = true;
  /// No work on hands that are not there: a side whose region from the body held no hand is
  /// looked for again from the body only after this many seconds (frame times given to
  /// process(); at 30 frames/s 0.1 s tries every third frame, at 10 frames/s or less every
  /// frame). 0: every frame, as MediaPipe's Holistic. Not with static_images or without `t`.
  double retry_after_miss_seconds = 0.1;
  /// How the crops sample the image (image_crop.hpp): `gl`, MediaPipe's OpenGL converter (its
  /// GPU and web graphs, which made the goldens: docs/capture.md), or `opencv`, its CPU one.
  crop_sampling sampling = crop_sampling::gl;
  /// Lift dim, low-contrast model inputs before the models see them (low_light.hpp); inputs
  /// whose luma range is wide enough are untouched.
  bool low_light = true;
};

/// Time spent in the last process() call, milliseconds (0 for a stage that did not run).
struct hand_timings {
  double palm_ms = 0.0;  // crop + inference + decode + NMS
  double palm_inference_ms = 0.0;
  double landmark_ms = 0.0;  // all landmark runs: crop + inference + projection
  double landmark_inference_ms = 0.0;
  int landmark_runs = 0;  // landmark model runs this frame (0..max_hands)
};

/// How a hand's region for the current frame was obtained.
enum class hand_roi_origin : std::uint8_t { tracked, palm, pose };

/// One hand found in the last frame.
struct hand_observation {
  body_side side = body_side::left;  // person's side (after resolving a clash, see process())
  hand_roi_origin origin = hand_roi_origin::palm;
  float presence = 0.f;          // landmark model presence flag in [0, 1]
  float left_probability = 0.f;  // model's belief that this is the person's left hand
  float handedness_score = 0.f;  // MediaPipe's "Left" label score (mirrored-image convention)
  normalized_rect roi;           // region the landmarks were found in
  std::array<landmark, k_hand_landmark_count> image{};  // normalised, z in image widths
  std::array<landmark, k_hand_landmark_count> world{};  // metres, origin at the hand's centre
};

enum class hand_result : std::uint8_t {
  found,      // at least one hand written
  not_found,  // no hand
  error,      // bad image or an ONNX Runtime failure: see last_error()
};

/// Runs the hand graph on a sequence of frames. Owns the ORT sessions and every buffer; one
/// instance per video stream; not thread-safe (one process() at a time).
class hand_pipeline {
 public:
  /// Loads the models. Fails (naming the file) when a model is missing, does not load, or has
  /// unexpected input or output shapes; or when an option is out of range (naming it).
  static status create(const hand_pipeline_options& options, std::unique_ptr<hand_pipeline>& out);
  ~hand_pipeline();
  hand_pipeline(const hand_pipeline&) = delete;
  hand_pipeline& operator=(const hand_pipeline&) = delete;

  /// Processes one frame. `body`: this frame's landmarks with the pose part (nullable; used
  /// for pose regions, see hand_roi_source). Sets left_hand / left_hand_world and
  /// right_hand / right_hand_world of `out` for each hand found, clears them otherwise;
  /// other parts are untouched (`out` may be `*body`). Image points are normalised with z in
  /// units of the image width (MediaPipe's, normalize_z 0.4 included); world points are
  /// metres, rotated back to the image's axes. When two palm-detected hands claim the same
  /// side, the one whose handedness is more certain keeps it and the other takes the other
  /// side. `t`: the frame's time in seconds (for retry_after_miss_seconds; negative: unknown,
  /// every side is tried every frame). No allocation in the steady state (outside ORT).
  hand_result process(const image_view& image, const landmark_frame* body, landmark_frame& out,
                      double t = -1.0);

  /// Forgets the tracked hands: the next frame starts afresh.
  void reset();
  /// Several people (estimator_options::max_people > 1): makes person slot `person` (0 ..
  /// k_max_people - 1, clamped) the one process(), reset() and tracked_count() act on; each
  /// slot tracks its own hands, the models are shared. Slot 0 is selected at creation.
  void select_person(int person);

  /// Hands found in the last frame (0..max_hands), and each of them (i < hand_count()).
  int hand_count() const;
  const hand_observation& hand(int i) const;
  /// Number of hands tracked into the next frame.
  int tracked_count() const;
  /// Whether the last process() ran the palm detector.
  bool last_ran_palm_detector() const;
  const hand_timings& last_timings() const;
  /// Message of the last error result; valid until the next process().
  const std::string& last_error() const;

 private:
  struct impl;
  explicit hand_pipeline(std::unique_ptr<impl> p);
  std::unique_ptr<impl> impl_;
};

}  // namespace avatarmap
