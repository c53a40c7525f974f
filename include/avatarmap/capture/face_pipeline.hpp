// The face part of the ONNX capture backend: MediaPipe's face mesh graph
// (face_landmark_front_cpu) around the face_detection_short_range and face_landmark models,
// plus MediaPipe Holistic's way of finding the face from the body's face points.
//
// Detect once, then track. A region of interest (ROI) for the mesh comes from one of:
//  - the detector on the whole image (face_landmark_front_cpu): the best detection's box,
//    rotated so that keypoint 0 (right eye) -> 1 (left eye) is horizontal, squared on its long
//    side and scaled by 1.5 (FaceDetectionFrontDetectionToRoi);
//  - the body's face points (pose landmarks 0-10), as Holistic does: their bounding box,
//    rotated by pose point 5 (right eye) -> 2 (left eye), squared and scaled by 3 gives a
//    search region (FaceLandmarksFromPoseToRecropRoi); the detector runs inside that region
//    only, and the detection's keypoints' box, rotated the same way, scaled by 2 and shifted up
//    by 0.1 of its height, is the mesh's region (FaceDetectionFrontDetectionsToRoi). A face
//    that is small in a full-body frame is found this way where the whole-image short-range
//    detector (faces within ~2 m) misses it.
// The mesh (a rotated 192x192 crop) gives 478 points (or 468, see below); the next frame's
// region is the bounding box of those points, rotated by mesh point 33 (right eye, outer
// corner) -> 263 (left eye, outer corner), squared and scaled by 1.5
// (FaceLandmarkLandmarksToRoi), so the detector does not run while the face is tracked. With a
// body, the tracked region also moves by the body's head motion since the previous frame
// (follow_body_motion; not in MediaPipe, whose Holistic graph re-runs the detector on every
// frame instead). When the mesh's face-presence score drops below a threshold (or, with a body,
// the tracked region's centre leaves the body's face region) the next frame acquires again.
// docs/capture-face.md has the figures.
//
// 478 or 468 points: by default the mesh stage runs face_landmark_with_attention, MediaPipe's
// refine_landmarks model (lips and eyes refined, the 10 iris points 468-477 added; its three
// MediaPipe-only custom operators are rewritten as standard ONNX by tools/convert/
// tflite2onnx.py), and assembles its six outputs as MediaPipe's LandmarksRefinementCalculator
// does (refine_face_mesh() below): landmark_frame::face_count == 478. face_mesh_model::mesh, or
// a models folder without face_landmark_with_attention.onnx, runs the 468-point
// face_landmark model instead (face_count == 468; the fallback is named by note()).
//
// The geometry below is plain C++ (src/capture/face_geometry.cpp, always built);
// face_pipeline needs AVATARMAP_WITH_ONNX (ONNX Runtime never appears in this header).
//
// Spaces: "normalised" means MediaPipe's normalised image coordinates (x / image width, y /
// image height, y down; image_crop.hpp). Rotations are radians, positive clockwise on screen.
// "Right"/"left" are the person's sides: in a non-mirrored image the right eye has the
// smaller x.
#pragma once

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

/// Keypoints of a face_detection_short_range detection, in order.
namespace face_detection_keypoint {
inline constexpr int right_eye = 0;
inline constexpr int left_eye = 1;
inline constexpr int nose_tip = 2;
inline constexpr int mouth_center = 3;
inline constexpr int right_ear_tragion = 4;
inline constexpr int left_ear_tragion = 5;
inline constexpr int count = 6;
}  // namespace face_detection_keypoint

/// The detector's input side (128 x 128) and the mesh's (192 x 192), pixels.
inline constexpr int k_face_detector_size = 128;
inline constexpr int k_face_mesh_size = 192;

/// The anchors of face_detection_short_range (896 anchors: a 16 x 16 map with 2 anchors per
/// cell, then an 8 x 8 map with 6 per cell; all 1 x 1).
ssd_anchor_options face_detection_anchor_options();

/// TensorsToDetections options of face_detection_short_range: 896 boxes x 16 values (box
/// x, y, w, h then 6 keypoints x, y), scales 128, sigmoid scores clipped at +-100, scores
/// below `min_score` dropped.
detection_decode_options face_detection_decode_options(float min_score = 0.5f);

/// Region for the mesh from a whole-image detection (normalised, projected to the image):
/// the box, rotated by keypoint 0 -> 1 to horizontal, squared on its long side, x 1.5.
normalized_rect face_detection_to_roi(const detection& d, int image_width, int image_height);

/// Region for the mesh from a detection found inside a pose-derived region (Holistic): the
/// axis-aligned box of the keypoints, rotated by keypoint 0 -> 1 to horizontal, shifted by
/// -0.1 of its height along its own y axis (up), squared on its long side, x 2.
normalized_rect face_detection_keypoints_to_roi(const detection& d, int image_width,
                                                int image_height);

/// Next frame's region from the mesh (`mesh`: `count` >= 264 points, normalised): their
/// axis-aligned bounding box, rotated by point 33 -> 263 to horizontal, squared, x 1.5.
/// Returns false (out untouched) when count < 264 or a point used is not finite.
bool face_landmarks_to_roi(const landmark* mesh, int count, int image_width, int image_height,
                           normalized_rect& out);

/// Holistic's face search region from the body (`pose`: the 33 pose points, normalised): the
/// axis-aligned box of points 0-10 (nose, eyes, ears, mouth), rotated by point 5 (right eye)
/// -> 2 (left eye) to horizontal, squared, x `scale` (3 in Holistic). Returns false (out
/// untouched) when one of those points is not finite, or `scale` is not > 0.
bool face_region_from_pose(const landmark* pose, int image_width, int image_height,
                           normalized_rect& out, float scale = 3.0f);

/// face_landmark_with_attention's refined regions, points per output: lips 80, each eye 71
/// (contour and halos), each iris 5 (centre, then the edges: right, top, left, bottom).
inline constexpr int k_face_refined_lips = 80;
inline constexpr int k_face_refined_eye = 71;
inline constexpr int k_face_refined_iris = 5;

/// Assembles face_landmark_with_attention's outputs into the 478-point mesh, as MediaPipe's
/// tensors_to_face_landmarks_with_attention graph (LandmarksRefinementCalculator) does: the 468
/// mesh points (x, y, z), then x and y of the lips, left-eye and right-eye points overwrite
/// their mesh points (z kept), then the left iris becomes points 468-472 and the right iris
/// 473-477, each with z the mean z of its eye's 16 contour points. Inputs are the raw outputs
/// in crop pixels: `mesh` 468 x 3, `lips` 80 x 2, `left_eye` / `right_eye` 71 x 2,
/// `left_iris` / `right_iris` 5 x 2 (the model's "left" is the eye around mesh point 33, the
/// person's right eye in a non-mirrored image: face_landmark.hpp's right_iris = 468). `out`:
/// 478 x 3 floats, same units. Never fails; no allocation.
void refine_face_mesh(const float* mesh, const float* lips, const float* left_eye,
                      const float* right_eye, const float* left_iris, const float* right_iris,
                      float* out);

// ---- the pipeline (AVATARMAP_WITH_ONNX) ----------------------------------------------------

/// Which network the mesh stage runs.
enum class face_mesh_model : std::uint8_t {
  attention,  // face_landmark_with_attention: 478 points (irises), refined lips and eyes
  mesh,       // face_landmark: 468 points, cheaper (docs/capture-face.md has the costs)
};

/// Where a face is looked for when none is tracked.
enum class face_roi_source : std::uint8_t {
  automatic,  // the body's face points when the body part is given, else the detector
  detector,   // the detector on the whole image; the body is ignored
  pose,       // the body's face points only: without a body part, no face
};

struct face_pipeline_options {
  /// Folder holding face_detection_short_range.onnx and face_landmark_with_attention.onnx or
  /// face_landmark.onnx (converted with tools/convert/tflite2onnx.py).
  std::string models_dir;
  /// attention: face_landmark_with_attention when the folder has it, else face_landmark with
  /// a note (note()); mesh: face_landmark always.
  face_mesh_model model = face_mesh_model::attention;
  face_roi_source roi_source = face_roi_source::automatic;
  /// float32: face_detection_short_range.onnx etc.; int8: *.int8.onnx.
  model_precision precision = model_precision::float32;
  int intra_op_threads = 1;          // ORT intra-op threads, >= 1
  bool allow_spinning = false;       // ORT's spinning thread pool; off: better on shared cores
  float min_detection_score = 0.5f;  // detector score threshold, (0, 1)
  float nms_iou_threshold = 0.3f;    // weighted NMS overlap threshold, (0, 1]
  float min_presence = 0.5f;         // mesh face-presence score (sigmoid) below this: lost
  bool static_images = false;        // true: acquire on every frame (no tracking)
  /// How the crops sample the image (image_crop.hpp): `gl`, MediaPipe's OpenGL converter (its
  /// GPU and web graphs, which made the goldens: docs/capture.md), or `opencv`, its CPU one.
  crop_sampling sampling = crop_sampling::gl;
  /// Lift dim, low-contrast model inputs before the models see them (low_light.hpp); inputs
  /// whose luma range is wide enough are untouched.
  bool low_light = true;
  /// Scale of the pose-derived search region (Holistic: 3), in (0, 100].
  float pose_region_scale = 3.0f;
  /// While tracking with a body, move the tracked region by the body's head motion since the
  /// previous frame (the centre of its face region). Not in MediaPipe, whose Holistic graph
  /// instead runs the detector in the body's region on every frame; this keeps the detector
  /// off while tracking and the mesh on a fast head (low frame rates). false: MediaPipe's
  /// face graph's plain tracking.
  bool follow_body_motion = true;
  /// No work on a face that is not there: after a frame on which no face was found (the
  /// detector found none, or the mesh rejected what it found), the next search waits this
  /// many seconds (frame times given to process(): at 30 frames/s 0.1 s searches every third
  /// frame, at 10 frames/s or less every frame). 0: every frame. Not with static_images or
  /// without `t`; a tracked face is never affected.
  double retry_after_miss_seconds = 0.1;
};

/// Time spent in the last process() call, milliseconds (0 for a stage that did not run).
struct face_timings {
  double detector_ms = 0.0;  // crop + inference + decode + NMS + projection
  double detector_inference_ms = 0.0;
  double mesh_ms = 0.0;  // crop + inference + projection + next region
  double mesh_inference_ms = 0.0;
};

/// How the region of the last mesh inference was obtained.
enum class face_acquisition : std::uint8_t {
  none,             // no mesh inference ran
  tracked,          // from the previous frame's mesh
  detector_image,   // the detector on the whole image
  detector_region,  // the detector inside the body's face region
};

enum class face_result : std::uint8_t {
  found,      // face written (478 points, or 468 with the plain mesh model)
  not_found,  // no face (no detection, no body for roi_source::pose, presence too low)
  error,      // bad image or an ONNX Runtime failure: see last_error()
};

/// Runs the face graph on a sequence of frames. Owns the ORT sessions and every buffer; one
/// instance per video stream; not thread-safe (one process() at a time).
class face_pipeline {
 public:
  /// Loads the models. Fails (naming the file) when a model is missing, does not load, or
  /// has unexpected input or output shapes; or when an option is out of range. A missing
  /// face_landmark_with_attention model is not a failure: the 468-point model is used and
  /// note() says so.
  static status create(const face_pipeline_options& options, std::unique_ptr<face_pipeline>& out);
  ~face_pipeline();
  face_pipeline(const face_pipeline&) = delete;
  face_pipeline& operator=(const face_pipeline&) = delete;

  /// Processes one frame. `body` (may be null; read only, same image) supplies the pose part
  /// for the pose-derived region. Sets the face part of `out` (face_count = mesh_points():
  /// normalised x, y; z relative depth in units of the image width, smaller = closer, as
  /// MediaPipe's mesh gives it; visibility and presence 1) when found, clears it
  /// otherwise; other parts are untouched (`out` may be `*body`). No allocation in the
  /// steady state (outside ORT). `t`: the frame's time in seconds (retry_after_miss_seconds;
  /// negative: unknown, a face is searched for on every frame).
  face_result process(const image_view& image, const landmark_frame* body, landmark_frame& out,
                      double t = -1.0);

  /// Forgets the tracked region: the next frame acquires again.
  void reset();
  /// Several people (estimator_options::max_people > 1): makes person slot `person` (0 ..
  /// k_max_people - 1, clamped) the one process(), reset(), tracking() and last_roi() act on;
  /// each slot tracks its own face, the models are shared. Slot 0 is selected at creation.
  void select_person(int person);

  /// The mesh model loaded (after a fallback, mesh) and its point count (478 or 468).
  face_mesh_model mesh_model() const;
  int mesh_points() const;
  /// One line when create() fell back from the attention model to the plain mesh (which file
  /// was missing, how to get it), else empty. Valid for the pipeline's lifetime.
  const std::string& note() const;

  /// Region used for the last mesh inference, and whether one is tracked for the next frame.
  const normalized_rect& last_roi() const;
  bool tracking() const;
  /// Region the detector searched in the last frame (the whole image, or the body's face
  /// region); meaningful when last_ran_detector().
  const normalized_rect& last_search_region() const;
  /// Mesh face-presence score of the last frame, [0, 1] (0 when the mesh did not run).
  float last_presence() const;
  bool last_ran_detector() const;
  /// The best detection of the last detector run (after NMS; box and the 6 keypoints in
  /// normalised image coordinates); meaningful when last_ran_detector() and it found a face.
  const detection& last_detection() const;
  face_acquisition last_acquisition() const;
  const face_timings& last_timings() const;
  /// Message of the last error result; valid until the next process().
  const std::string& last_error() const;

 private:
  struct impl;
  explicit face_pipeline(std::unique_ptr<impl> p);
  std::unique_ptr<impl> impl_;
};

}  // namespace avatarmap
