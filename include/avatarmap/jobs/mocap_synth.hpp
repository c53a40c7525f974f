// Landmarks from real motion capture: a BVH take's own joints (not the proxy skeleton) seen by a
// pinhole camera, written as MediaPipe pose landmarks with the failures real BlazePose has
// (world points leaning toward the camera, noise, low visibility for hidden or outside points).
// The generator of the world benchmark (docs/world-benchmark.md); the scorer is
// jobs/world_score.hpp.
//
// Spaces: the take's world is the BVH's (metres after `units`, Y up; the CMU clips face +Z with
// the performer's left at +X at rest). Camera axes are MediaPipe's: x right, y down, z away from
// the camera. Everything is computed once at load (the take is held in memory, a few MB); per
// frame nothing allocates.
#pragma once

#include <array>
#include <cmath>
#include <cstdint>
#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>
#include <random>
#include <string>
#include <vector>

#include "avatarmap/core/status.hpp"
#include "avatarmap/landmarks/landmark_frame.hpp"

namespace avatarmap {

/// CMU's length unit (0.45 inch) in metres: the factor of the CMU BVH clips.
inline constexpr float k_cmu_units_to_metres = 0.056444f;

/// The anatomical points of a take, found by joint name (see mocap_take::load).
enum class mocap_point : std::uint8_t {
  hip_mid,  // midpoint of the two hip sockets (MediaPipe's world origin, the proxy's hips)
  left_hip,
  right_hip,
  left_knee,
  right_knee,
  left_ankle,
  right_ankle,
  left_toe,  // toe joint (ball of the foot)
  right_toe,
  left_toe_tip,  // end of the toe (MediaPipe's foot index 31/32)
  right_toe_tip,
  left_heel,  // behind the ankle on the sole (see mocap_take::load)
  right_heel,
  neck,  // base of the neck, at shoulder level
  head,  // head joint (base of the skull)
  head_top,
  left_shoulder,  // the shoulder socket (upper arm joint)
  right_shoulder,
  left_elbow,
  right_elbow,
  left_wrist,
  right_wrist,
  left_hand_tip,  // end of the hand (fingers' end site; else 8 cm past the wrist)
  right_hand_tip,
  left_thumb_tip,
  right_thumb_tip,
};
inline constexpr int k_mocap_point_count = 26;
constexpr int idx(mocap_point p) { return static_cast<int>(p); }

/// One instant of a take: the points (world, metres) and the head's world rotation (relative
/// to the BVH rest pose, whose head faces +Z).
struct mocap_frame {
  std::array<glm::vec3, k_mocap_point_count> p{};
  glm::quat head_rotation{1.f, 0.f, 0.f, 0.f};
  glm::vec3 operator[](mocap_point q) const { return p[idx(q)]; }
};

/// A BVH take turned into anatomical points per frame.
class mocap_take {
 public:
  /// Reads `path` (export/bvh.hpp's reader) and runs the forward kinematics of every frame.
  /// `units_to_metres` multiplies OFFSETs and root positions (CMU: k_cmu_units_to_metres;
  /// > 0 and finite). Joints are found by name, case-insensitively, after any "prefix:":
  ///   hip sockets LeftUpLeg|LeftUpperLeg|LeftHip|LeftThigh, knees LeftLeg|LeftLowerLeg|
  ///   LeftKnee|LeftShin, ankles LeftFoot|LeftAnkle, toes LeftToeBase|LeftToes|LeftToe,
  ///   shoulders LeftArm|LeftUpperArm (else LeftShoulder when it is not a clavicle, i.e. has
  ///   no LeftArm/LeftUpperArm below it), elbows LeftForeArm|LeftLowerArm|LeftElbow, wrists
  ///   LeftHand|LeftWrist, neck Neck (else Neck1, UpperNeck), head Head; "Right..." alike;
  ///   also the VRM names (leftUpperLeg ...) and L/R prefixes (LHip ...).
  /// Derived points: toe tip = the toe's End Site (else 5 cm past the toe along ankle->toe);
  /// heel = ankle + R_ankle * (0, dy, -0.25 * |ankle->toe tip|rest) with dy the rest pose's
  /// toe-tip height minus its ankle height (the heel on the sole, at the toe tip's level);
  /// head top = the head's End Site (else 20 cm above the head along its rest up); hand and
  /// thumb tips from the hand's descendants' End Sites (else 8 / 5 cm past the wrist along
  /// elbow->wrist). Missing toes: the toe is the ankle + R_ankle * (0, -0.05, 0.12) m.
  /// Fails (naming the file and the joint) when the file cannot be read, has no frames or
  /// lacks hip sockets, knees, ankles, shoulders, elbows, wrists or a neck/head; a non-finite
  /// value in the file is a parse error. Never throws.
  status load(const std::string& path, float units_to_metres = k_cmu_units_to_metres);

  int frame_count() const { return static_cast<int>(frames_.size()); }
  double frame_time() const { return frame_time_; }
  /// Time of the last frame (first frame at t = 0).
  double duration() const { return frame_time_ * (frames_.empty() ? 0 : frames_.size() - 1); }
  const mocap_frame& frame(int i) const { return frames_[static_cast<std::size_t>(i)]; }
  /// The rest pose (all channels zero, the root at its OFFSET).
  const mocap_frame& rest() const { return rest_; }
  /// The take at time `t` (seconds, clamped to [0, duration]): points lerped between the two
  /// nearest frames, the head rotation slerped. Allocation-free.
  void sample(double t, mocap_frame& out) const;
  /// Floor height (world Y, metres): the 2nd percentile over the take of the lowest of the
  /// toe tips, toes and heels.
  float floor_y() const { return floor_y_; }
  /// Height of the performer's skeleton: head top above the lowest foot point in the rest pose
  /// (metres; reported, never used to scale anything).
  float rest_height() const;
  const std::string& path() const { return path_; }

 private:
  std::string path_;
  double frame_time_ = 0.0;
  float floor_y_ = 0.f;
  mocap_frame rest_;
  std::vector<mocap_frame> frames_;
};

/// A pinhole camera looking at the performer. Camera axes: x right, y down, z forward.
struct mocap_camera {
  glm::vec3 position{0.f};                          // world, metres
  glm::quat world_from_camera{1.f, 0.f, 0.f, 0.f};  // rotates camera axes into the world
  float horizontal_fov_degrees = 60.f;
  int image_width = 1280;
  int image_height = 720;
  // What placed it (reported in the sidecar): height above the floor, horizontal distance to
  // the look-at point, lateral offset, pitch (+ up) and roll (+ clockwise in the image), deg.
  float height = 0.f, distance = 0.f, lateral = 0.f, pitch_degrees = 0.f, roll_degrees = 0.f;

  /// Focal length in pixels (square pixels).
  float focal_pixels() const;
  glm::vec3 to_camera(const glm::vec3& world) const;
  /// Normalised image position (x / width, y / height) of a point in camera axes; z <= 0
  /// (behind the camera) gives a point far outside.
  glm::vec2 project(const glm::vec3& camera_point) const;
};

/// How to place the camera. NaN fields are drawn from `seed` within the documented ranges:
/// height 0.5-2.0 m above the floor, distance 2.5-5 m, lateral -1..1 m, horizontal field of
/// view 40-90 deg, roll -8..8 deg, pitch: the pitch that looks at the hips (mean height) plus
/// up to +-20 % of the vertical field of view, kept in -30..+20 deg.
struct mocap_camera_setup {
  float height = NAN, distance = NAN, lateral = NAN, pitch_degrees = NAN, roll_degrees = NAN,
        fov_degrees = NAN;
  int image_width = 1280, image_height = 720;
  unsigned seed = 1;
  status validate() const;
};

/// Places the camera: the look-at point is the take's mean hip midpoint (horizontally) at its
/// mean hip height; the camera stands `distance` metres from it horizontally along the
/// performer's mean facing direction (forward = left x up, from the hip sockets), `lateral`
/// metres to the performer's left, `height` above floor_y(); its yaw looks at the look-at
/// point, then pitch (+ up) and roll.
mocap_camera place_mocap_camera(const mocap_take& take, const mocap_camera_setup& setup);

enum class mocap_scenario : std::uint8_t { clean, blazepose };

/// Degradations (docs/world-benchmark.md). `blazepose`: lean drawn 10-25 deg, world noise 15 mm,
/// image noise 0.3 % of the image height, visibility model on. `clean`: all off (points outside
/// the image still get visibility and presence 0.02, as any estimator reports them).
struct mocap_synth_options {
  mocap_scenario scenario = mocap_scenario::blazepose;
  float lean_degrees = NAN;      // world points turned toward the camera about the hips; NaN: draw
  float world_noise_m = 0.015f;  // Gaussian sigma per world coordinate
  float image_noise = 0.003f;    // Gaussian sigma in pixels / image height
  bool visibility_model = true;  // lower visibility for points turned away
  unsigned seed = 1;
  /// The preset of `s` for `seed`.
  static mocap_synth_options preset(mocap_scenario s, unsigned seed);
  status validate() const;
};

/// Makes landmark frames of `take` seen by `camera`. Each call of generate draws new noise
/// (a fixed sequence for the seed). Allocation-free per frame.
class mocap_landmark_synth {
 public:
  mocap_landmark_synth(const mocap_take& take, const mocap_camera& camera,
                       const mocap_synth_options& options);
  /// The lean used (degrees; 0 for clean).
  float lean_degrees() const { return lean_degrees_; }
  /// Fills `out` with pose (image) and pose_world at time t (the take sampled at t).
  void generate(double t, landmark_frame& out);
  /// The world points in camera axes centred on the hip midpoint, before any degradation.
  static void clean_world(const mocap_frame& f, const mocap_camera& camera,
                          std::array<glm::vec3, 33>& out);

 private:
  const mocap_take& take_;
  mocap_camera camera_;
  mocap_synth_options options_;
  float lean_degrees_ = 0.f;
  std::mt19937 rng_;
  std::normal_distribution<float> normal_{0.f, 1.f};
};

struct mocap_synth_summary {
  long frames = 0;
  float lean_degrees = 0.f;    // the lean used
  double inside_fraction = 0;  // of all pose points, those inside the image
};

/// The whole generator: loads nothing, writes frames at t = k / fps, k = 0 .. duration * fps,
/// to a landmark file (header: image size, fps). Fails when the file cannot be written.
struct mocap_synth_job {
  const mocap_take* take = nullptr;
  mocap_camera camera;
  mocap_synth_options options;
  double fps = 30.0;  // (0, 1000]
  std::string output;
  status run(mocap_synth_summary& out) const;
};

/// The camera (and the lean) as a one-line JSON object, for the sidecar file.
std::string mocap_camera_json(const mocap_camera& camera, float lean_degrees);

}  // namespace avatarmap
