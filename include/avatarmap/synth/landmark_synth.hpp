// Synthetic ground truth: the landmark_frame that MediaPipe would ideally output for a known
// proxy_pose. The reference of every solver accuracy test, and the CLI's demo recording.
//
// Geometry (VRM space, metres; skeleton and FK in proxy_skeleton.hpp):
// - Pose: 11/12 upper-arm joints, 13/14 lower-arm joints, 15/16 hand joints, 17/18 little-
//   proximal joints, 19/20 index-proximal joints, 21/22 thumb-proximal joints, 23/24 upper-leg
//   joints, 25/26 lower-leg joints, 27/28 foot joints, 29/30 heels (foot joint + foot world *
//   skeleton.heel_offset), 31/32 toe tips. 0-10 (nose, eyes, ears, mouth corners) come from a
//   head-local template (head joint + head world * offset); the mouth corners follow the
//   mouth's width (visemes). At rest (left ear - right ear) || +X and (eye-centre midpoint -
//   mouth-corner midpoint) || +Y exactly.
// - Hands: 0 hand joint, 1-3 thumb metacarpal/proximal/distal joints, 4 thumb tip, then
//   index, middle, ring, little: proximal/intermediate/distal joints and the distal tip.
// - Face mesh: a head-local template (face_template_point()) deformed by the expressions
//   (lids, lips, brows) and the eye bones (irises); see landmark_synth.cpp for the exact
//   rules. The forehead, chin, cheeks, temples and jaw points never move with expressions,
//   so they carry the head's orientation only.
//
// Output spaces (docs/conventions.md, "Spaces"): pose_world = MediaPipe world (x = X, y = -Y, z =
// -Z, origin at the midpoint of points 23/24); hand world likewise with the origin at the mean of
// hand points 0, 5, 9, 13, 17; image points through a pinhole camera at camera_position looking
// along -Z: x_c = X - cx, y_c = -(Y - cy), z_c = cz - Z, u = W/2 + f x_c / z_c,
// v = H/2 + f y_c / z_c, f = (W/2) / tan(fov/2); landmark (u/W, v/H, (z_c - z_ref) f /
// (z_ref W)) with z_ref the depth of the hip midpoint (pose), the wrist (hands) or the head
// joint (face). visibility = presence = 1 everywhere, except in low-visibility bursts.
//
// Variation of real recordings (all off by default, so the defaults reproduce the fixed camera
// above; synth_recording.hpp's scenario presets turn them on):
// - random_camera: horizontal field of view, distance, height and sideways offset drawn once
//   per seed (the camera still looks along -Z; the person is off the optical axis).
// - low-visibility bursts (low_visibility_fraction > 0): per limb (each arm with its hand,
//   each leg) an alternating schedule along pose.t of gaps and bursts of about
//   low_visibility_seconds; inside a burst the limb's points (pose 13/15/17/19/21 or
//   14/16/18/20/22 and that hand's 21 points for an arm; pose 25/27/29/31 or 26/28/30/32 for
//   a leg) get a visibility drawn uniformly in [low_visibility_min, low_visibility_max] per
//   point and frame, and extra Gaussian noise of low_visibility_noise_sigma on their 3-D
//   points. The pose passed in keeps moving: the generator only degrades what is reported.
#pragma once

#include <array>
#include <cstdint>
#include <glm/glm.hpp>
#include <random>

#include "avatarmap/core/status.hpp"
#include "avatarmap/landmarks/landmark_frame.hpp"
#include "avatarmap/skeleton/proxy_pose.hpp"
#include "avatarmap/skeleton/proxy_skeleton.hpp"
#include "avatarmap/solve/face_expressions.hpp"

namespace avatarmap {

/// Which face mesh the generator outputs.
enum class synth_face : std::uint8_t { none, mesh_468, mesh_478 };

/// Which motion a synthetic recording plays (synth_recording.hpp; landmark_synth itself takes
/// any pose): demo = demo_motion_pose()'s scripted 10 s loop; random = random_motion
/// (random_motion.hpp), fast, seeded by synth_options::seed; head = the random motion's arms,
/// legs, eyes and expressions with the torso upright and the head swept over its whole range
/// relative to it (head_sweep.hpp: pitch -70..+40, yaw +-70, roll +-35 degrees).
enum class synth_motion : std::uint8_t { demo, random, head };

/// The limbs that low-visibility bursts affect (the person's sides, also when mirrored).
enum class synth_limb : std::uint8_t { left_arm, right_arm, left_leg, right_leg };
inline constexpr int k_synth_limb_count = 4;

/// The limb whose burst marks bone `b` as low-visibility: an arm's upper arm, lower arm, hand
/// and all its fingers; a leg's upper leg, lower leg, foot and toes. -1 for every other bone
/// (torso, head, eyes, jaw, shoulders: their child joints stay visible).
int synth_limb_of(bone b);

struct synth_options {
  // Parts to output.
  bool pose_image = true;
  bool pose_world = true;
  bool hands_image = true;
  bool hands_world = true;
  synth_face face = synth_face::mesh_478;
  // Image size in pixels (> 0).
  int image_width = 1280;
  int image_height = 720;
  /// Camera centre in VRM space (metres). When camera_y_scales_with_height is true the Y used
  /// is camera_position.y * skeleton.scale (so the default sits at 1.0 m for a 1.70 m person).
  glm::vec3 camera_position{0.f, 1.f, 3.5f};
  bool camera_y_scales_with_height = true;
  /// Horizontal field of view in degrees, in (1, 179).
  float horizontal_fov_degrees = 60.f;
  /// Mirrored camera (webcam preview): the output is what MediaPipe reports on the mirrored
  /// image, i.e. the mirror-image performer seen by the mirror-image camera: image x -> 1 - x,
  /// world x -> -x and the left/right labels swapped (the person's right hand arrives as
  /// left_hand...). frame_solver with options.mirror = true undoes it.
  bool mirror = false;
  /// Person height in metres; used only by the constructor that builds the skeleton itself.
  float person_height = k_proxy_reference_height;
  /// Standard deviation (metres, >= 0) of isotropic Gaussian noise added to every 3-D point
  /// (VRM space) before projection and output, per part.
  float body_noise_sigma = 0.f;
  float hand_noise_sigma = 0.f;
  float face_noise_sigma = 0.f;
  /// Seed of the generator's std::mt19937 (reseeded by landmark_synth::reseed()). The camera
  /// draws and the burst schedule use their own generators derived from it, so turning them
  /// on leaves the noise sequence as it was.
  std::uint32_t seed = 1;
  /// Face variation: when true the face's own proportions and how far its shapes move
  /// (synth_face_shape) are drawn once from the seed, as real faces differ; when false every
  /// seed has the population face (synth_face_shape{}).
  bool face_variation = false;

  /// Random camera: when true, camera_position and horizontal_fov_degrees are ignored and
  /// drawn once from the seed: field of view uniform in [fov_min_degrees, fov_max_degrees]
  /// (each in (1, 179), min <= max), distance from the origin (where the person starts)
  /// uniform in [distance_min, distance_max] metres (> 0), height uniform in
  /// [camera_height_min, camera_height_max] metres (scaled like camera_position.y), and a
  /// sideways offset that puts the origin anywhere up to off_centre_max (in [0, 1]) of the
  /// half image width from the image centre.
  bool random_camera = false;
  float fov_min_degrees = 50.f;
  float fov_max_degrees = 90.f;
  float distance_min = 1.5f;
  float distance_max = 4.f;
  float camera_height_min = 0.8f;
  float camera_height_max = 1.5f;
  float off_centre_max = 0.5f;

  /// Low-visibility bursts (see above): fraction of each limb's time in bursts, in [0, 0.9]
  /// (0 = none); mean burst length in seconds (> 0; each burst lasts 0.6..1.4 times it);
  /// visibility range inside a burst (0 <= min <= max <= 1); extra noise on the limb's 3-D
  /// points (metres, >= 0). Bursts are scheduled along pose.t: call generate() with
  /// non-decreasing times (a time going back restarts the schedule from that time).
  float low_visibility_fraction = 0.f;
  float low_visibility_seconds = 1.f;
  float low_visibility_min = 0.02f;
  float low_visibility_max = 0.3f;
  float low_visibility_noise_sigma = 0.03f;

  /// Motion of a synth_recording (landmark_synth ignores these): the motion, the random
  /// motion's top wrist speed (rad/s, > 0) and the random sideways bend of finger
  /// intermediate/distal and thumb joints (degrees, in [0, 45]).
  synth_motion motion = synth_motion::demo;
  float max_wrist_speed = 6.f;
  float finger_side_bend_degrees = 10.f;

  /// Names the first field out of range.
  status validate() const;
};

/// The last generated 3-D points (VRM space, metres, noise included; mirrored when
/// options.mirror is set, with labels as output).
struct synth_points {
  std::array<glm::vec3, k_pose_landmark_count> pose{};
  std::array<glm::vec3, k_hand_landmark_count> left_hand{};
  std::array<glm::vec3, k_hand_landmark_count> right_hand{};
  std::array<glm::vec3, k_face_mesh_iris_count> face{};
  glm::vec3 head_joint{0.f};
};

/// A face's own proportions and the reach of its shapes (metres at the 1.70 m reference
/// scale; shares and ratios without unit). The defaults are the population face; with
/// synth_options::face_variation each is drawn per seed from the range in brackets.
/// docs/expressions.md ("The generator") describes how each shape deforms the mesh.
struct synth_face_shape {
  float eye_open[2] = {
      0.22f,
      0.22f};  // middle lid gap / eye width at rest, person's L, R [0.17, 0.28] x [0.95, 1.05]
  float shut_fraction = 0.09f;        // a shut eye's gap / its open gap [0.05, 0.14]
  float wide_gain = 0.4f;             // extra gap at eyeWide 1 / open gap [0.34, 0.46]
  float brow_offset[2] = {0.f, 0.f};  // brow height at rest beyond the template's [-2, 2] mm
  float brow_raise = 0.0075f;         // brow end's rise at browInnerUp/OuterUp 1 [6.8, 8.2] mm
  float brow_lower = 0.005f;          // inner end's drop at browDown 1 [4.5, 5.5] mm
  float cheek_raise = 0.0035f;        // rise below the lid at cheekSquint 1 [3, 4] mm
  float mouth_width = 0.05f;          // corner to corner at rest [45, 56] mm
  float jaw_drop = 0.029f;            // lower lip's drop at jawOpen 1 [27, 31] mm
  float corner_follow = 0.5f;         // share of that drop the corners follow [0.46, 0.54]
  float narrow = 0.3f;                // width lost at mouthFunnel/Pucker 1 [0.27, 0.33]
  float funnel_open = 0.006f;         // lips parted by mouthFunnel 1 [5, 7] mm
  float smile_rise = 0.009f;          // corner's rise at mouthSmile 1 [8.2, 9.8] mm
  float smile_out = 0.6f;             // its outward move / rise [0.5, 0.7]
  float stretch_out = 0.007f;         // corner's outward move at mouthStretch 1 [6.5, 7.5] mm
  float frown_drop = 0.005f;          // corner's drop at mouthFrown 1 [4.5, 5.5] mm
  float shift = 0.007f;               // lips' sideways move at mouthLeft/Right 1 [6.5, 7.5] mm
  float eyeball_radius = 0.012f;      // iris move per sine of the eye's turn [11.2, 12.8] mm
  float iris_u = 0.f, iris_v = 0.f;   // iris rest offset (eye widths, out / up) [-0.03, 0.03]
  float jaw_side = 0.0095f;           // chin's and lower lip's sideways move at jawLeft/Right 1
                                      // [8.5, 10.5] mm
  float roll_upper = 0.005f;          // upper lip's outer edge toward the lip line at
                                      // mouthRollUpper 1 [4.5, 5.5] mm
  float roll_lower = 0.0065f;         // lower lip's outer edge at mouthRollLower 1 [6, 7] mm
  float chin_ratio = 1.17f;           // chin's drop / the lower lip's at jawOpen [1.12, 1.22]
  float upper_up = 0.004f;    // upper lip's side points' rise at mouthUpperUp 1 [3.5, 4.5] mm
  float lower_down = 0.004f;  // lower lip's side points' drop at mouthLowerDown 1 [3.5, 4.5] mm
  float sneer = 0.003f;       // nose wing's rise at noseSneer 1 [2.5, 3.5] mm
};

/// Draws a face for `seed` (the ranges of synth_face_shape).
synth_face_shape draw_face_shape(std::uint32_t seed);

/// The truth expressions of a pose the generator draws: its eyeLook* blendshapes set from the
/// eye bones' turn (euler YXZ of each eye's local rotation; sideways and up as sines, the
/// definitions of solve/face_expressions.hpp), then the 21 expressions derived from the 52
/// (expressions_from_blendshapes).
void set_truth_expressions(proxy_pose& pose);

/// The blendshapes the generator draws for a pose that carries only expressions (every
/// blendshape 0): eyeBlinkLeft/Right = blink + blinkLeft/Right; jawOpen = aa + ih + oh,
/// mouthStretch = ih + ee, mouthFunnel = oh, mouthPucker = ou (clamped); browOuterUp =
/// browUp per side, browInnerUp = the smaller browUp, browDown per side. A single viseme,
/// blink or brow then derives back to itself. Emotions and looks are not converted (the eye
/// bones give the gaze).
void blendshapes_from_expressions(const proxy_pose& pose, blendshape_weights& out);

/// Pose -> landmark frame generator. Holds the skeleton, the face template, the noise RNG and
/// scratch buffers: generate() allocates nothing. Not thread-safe (one object per thread).
class landmark_synth {
 public:
  /// Builds the skeleton from options.person_height. Options must validate() (asserted;
  /// invalid options are replaced by defaults in release builds).
  explicit landmark_synth(const synth_options& options = {});
  /// Uses `skeleton` (options.person_height is ignored).
  landmark_synth(const proxy_skeleton& skeleton, const synth_options& options);

  /// Writes the frame for `pose` into `out` (out.t = pose.t; parts per options; every other
  /// part cleared). Non-unit rotations give distorted bones: pass unit quaternions.
  void generate(const proxy_pose& pose, landmark_frame& out);

  /// Image landmark of a VRM point (x, y normalised, z relative to depth z_ref in metres),
  /// for the non-mirrored camera. Depths below 1 mm are clamped to 1 mm (no NaN).
  glm::vec3 project(const glm::vec3& vrm_point, float z_ref) const;
  /// Camera depth z_c = cz - Z (metres) of a VRM point.
  float depth(const glm::vec3& vrm_point) const { return camera_.z - vrm_point.z; }
  /// Focal length in pixels.
  float focal_pixels() const { return focal_; }
  /// Camera centre actually used (VRM, metres, non-mirrored).
  const glm::vec3& camera_position() const { return camera_; }

  /// Horizontal field of view actually used (degrees): drawn when options.random_camera.
  float horizontal_fov_degrees() const { return fov_degrees_; }

  /// Restarts the noise sequence and the burst schedule (the camera stays as drawn).
  void reseed(std::uint32_t seed);

  /// Whether limb `l` was in a low-visibility burst in the last generate() call.
  bool limb_low_visibility(synth_limb l) const { return in_burst_[static_cast<int>(l)]; }
  /// Whether bone `b` was marked low-visibility in the last generate() call (synth_limb_of).
  bool bone_low_visibility(bone b) const {
    const int l = synth_limb_of(b);
    return l >= 0 && in_burst_[l];
  }

  const proxy_skeleton& skeleton() const { return skeleton_; }
  const synth_options& options() const { return options_; }
  /// The face drawn (synth_options::face_variation) or the population face.
  const synth_face_shape& face_shape() const { return face_shape_; }
  /// 3-D points of the last generate() call.
  const synth_points& points() const { return points_; }
  /// FK of the last generate() call (of the mirrored pose when options.mirror is set).
  const proxy_fk& fk() const { return fk_; }

 private:
  void init();
  void build_face(const proxy_pose& pose);
  void add_noise(glm::vec3* points, int count, float sigma);
  void add_noise_at(glm::vec3* points, const int* indices, int count, float sigma);
  void update_bursts(double t);
  float draw_visibility();

  proxy_skeleton skeleton_;
  synth_options options_;
  synth_face_shape face_shape_;
  glm::vec3 camera_{0.f};
  float focal_ = 1.f;
  std::array<glm::vec3, k_face_mesh_iris_count> face_template_{};
  float fov_degrees_ = 60.f;
  std::mt19937 rng_;
  std::normal_distribution<float> normal_{0.f, 1.f};
  // Burst schedule: its own generator so that the noise sequence does not depend on it.
  std::mt19937 burst_rng_;
  bool bursts_started_ = false;
  double last_t_ = 0.0;
  std::array<double, k_synth_limb_count> burst_start_{};
  std::array<double, k_synth_limb_count> burst_end_{};
  std::array<bool, k_synth_limb_count> in_burst_{};
  proxy_pose mirrored_;
  proxy_fk fk_;
  synth_points points_;
};

/// Rest position of face-mesh point `index` (0..477) in the head's frame (VRM axes at rest,
/// metres from the head joint) for a skeleton of scale `scale`, eyes open, mouth neutral.
glm::vec3 face_template_point(int index, float scale);

/// Viseme table: for aa, ih, ou, ee, oh (in that order) the mouth opening (inner-lip gap /
/// mouth width) and the width scale (mouth width / neutral width 0.05 * scale).
struct synth_viseme_shape {
  float open;
  float width_scale;
};
inline constexpr synth_viseme_shape k_synth_visemes[5] = {
    {0.60f, 1.00f}, {0.20f, 1.10f}, {0.25f, 0.72f}, {0.25f, 1.22f}, {0.45f, 0.80f}};

/// Blended mouth shape of a pose's viseme weights (clamped to [0, 1]; a sum above 1 is
/// normalised; the remainder is neutral (0, 1)).
synth_viseme_shape blend_visemes(const proxy_pose& pose);

}  // namespace avatarmap
