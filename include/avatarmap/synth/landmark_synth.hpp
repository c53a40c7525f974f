// Synthetic ground truth: the landmark_frame that MediaPipe would ideally output for a known
// proxy_pose. The reference of every solver accuracy test, and the CLI's demo recording.
//
// Geometry (VRM space, metres; skeleton and FK in synth_skeleton.hpp):
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
// Output spaces (REFERENCE §2): pose_world = MediaPipe world (x = X, y = -Y, z = -Z, origin at
// the midpoint of points 23/24); hand world likewise with the origin at the mean of hand
// points 0, 5, 9, 13, 17; image points through a pinhole camera at camera_position looking
// along -Z: x_c = X - cx, y_c = -(Y - cy), z_c = cz - Z, u = W/2 + f x_c / z_c,
// v = H/2 + f y_c / z_c, f = (W/2) / tan(fov/2); landmark (u/W, v/H, (z_c - z_ref) f /
// (z_ref W)) with z_ref the depth of the hip midpoint (pose), the wrist (hands) or the head
// joint (face). visibility = presence = 1 everywhere.
#pragma once

#include <array>
#include <cstdint>
#include <glm/glm.hpp>
#include <random>

#include "avatarmap/core/status.hpp"
#include "avatarmap/landmarks/landmark_frame.hpp"
#include "avatarmap/skeleton/proxy_pose.hpp"
#include "avatarmap/synth/synth_skeleton.hpp"

namespace avatarmap {

/// Which face mesh the generator outputs.
enum class synth_face : std::uint8_t { none, mesh_468, mesh_478 };

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
  float person_height = k_synth_reference_height;
  /// Standard deviation (metres, >= 0) of isotropic Gaussian noise added to every 3-D point
  /// (VRM space) before projection and output, per part.
  float body_noise_sigma = 0.f;
  float hand_noise_sigma = 0.f;
  float face_noise_sigma = 0.f;
  /// Seed of the generator's std::mt19937 (reseeded by landmark_synth::reseed()).
  std::uint32_t seed = 1;

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

/// Pose -> landmark frame generator. Holds the skeleton, the face template, the noise RNG and
/// scratch buffers: generate() allocates nothing. Not thread-safe (one object per thread).
class landmark_synth {
 public:
  /// Builds the skeleton from options.person_height. Options must validate() (asserted;
  /// invalid options are replaced by defaults in release builds).
  explicit landmark_synth(const synth_options& options = {});
  /// Uses `skeleton` (options.person_height is ignored).
  landmark_synth(const synth_skeleton& skeleton, const synth_options& options);

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

  /// Restarts the noise sequence.
  void reseed(std::uint32_t seed);

  const synth_skeleton& skeleton() const { return skeleton_; }
  const synth_options& options() const { return options_; }
  /// 3-D points of the last generate() call.
  const synth_points& points() const { return points_; }
  /// FK of the last generate() call (of the mirrored pose when options.mirror is set).
  const synth_fk& fk() const { return fk_; }

 private:
  void init();
  void build_face(const proxy_pose& pose);
  void add_noise(glm::vec3* points, int count, float sigma);

  synth_skeleton skeleton_;
  synth_options options_;
  glm::vec3 camera_{0.f};
  float focal_ = 1.f;
  std::array<glm::vec3, k_face_mesh_iris_count> face_template_{};
  std::mt19937 rng_;
  std::normal_distribution<float> normal_{0.f, 1.f};
  proxy_pose mirrored_;
  synth_fk fk_;
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
