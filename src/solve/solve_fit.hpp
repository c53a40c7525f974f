// Stage 1c of the solver: the body in the world. BlazePose's world points are metric and
// smooth but carry a lean toward the camera (12-29 degrees on rendered mocap; Google's own
// landmarks lean the same) and live in the camera's axes, not the world's; its image points do
// not lean. This stage rebuilds the body's metric points from the image points through the
// camera (docs/solver.md, "The body in the world"):
//   1. root: the hip midpoint's camera position (X, Y, Z) from every confident torso and leg
//      point's pinhole equation (linear least squares, focal length known);
//   2. fit: from the hip midpoint outward (shoulder line, arms, legs, toes), each joint is put
//      on its image ray at the segment's length from its parent, lengths learnt over the take
//      from the world points (body_lengths). Foreshortening decides how far a segment turns in
//      depth; of the two points on the ray at that distance the one on the world points' side
//      is taken, the torso's side judged after undoing BlazePose's typical lean;
//   3. gravity: the camera's pitch and roll from the standing body's vertical (frames whose
//      legs are straight), accumulated over the take (camera_gravity), and the points turned
//      into a gravity-aligned frame, so the avatar stands upright whatever the camera's angle.
// Points the fit does not reach (face, hand points, heels) keep their world offsets from
// the fitted joint they hang on. Nothing here allocates.
#pragma once

#include <array>
#include <glm/glm.hpp>

#include "avatarmap/landmarks/landmark_frame.hpp"

namespace avatarmap::solve_detail {

/// The lengths of the body's segments learnt over the take from the world points (metres):
/// a running mean of the confident frames' lengths, both sides pooled.
struct body_lengths {
  enum segment : int { hip_half, torso, shoulder_half, upper_arm, forearm, thigh, shin, foot };
  static constexpr int k_count = 8;
  std::array<double, k_count> sum{};
  std::array<double, k_count> frames{};
  float get(int s) const { return frames[s] > 0.0 ? float(sum[s] / frames[s]) : 0.f; }
  void reset() { *this = body_lengths{}; }
};

/// The camera's "up" in its own axes (MediaPipe's: x right, y down, z away) learnt over the
/// take from the standing body's vertical, starting from a level camera.
struct camera_gravity {
  glm::dvec3 up_sum{0.0, -1.0, 0.0};  // the prior: a level camera, worth k_prior frames
  double weight = 0.0;                // frames of evidence so far
  long frames = 0;
  /// The floor: how far below the camera (metres, gravity's down) the feet's lowest point
  /// rests, a running mean over the frames whose feet are on it (not in a jump).
  double floor_below_camera = 0.0;
  /// The up floor_below_camera is measured along (it is turned with the up, fit_body).
  glm::dvec3 floor_up{0.0, -1.0, 0.0};
  /// Since when the feet have been above the floor (k_not_airborne: on it).
  double airborne_since = k_not_airborne;
  static constexpr double k_not_airborne = -1e300;
  /// The world points' lean (radians about the camera's x axis that turns them onto the
  /// image), summed over the frames that told it.
  double lean_sum = 0.0;
  double lean_frames = 0.0;
  /// The same from the field-of-view fits (focal length free, solve_camera.hpp): preferred
  /// once k_focal_lean_frames frames have told it (a lean searched at a focal length that is
  /// still being learnt takes some of the focal length's error).
  double focal_lean_sum = 0.0;
  double focal_lean_frames = 0.0;
  long lean_tick = 0;  // frames seen, for sampling the lean's search
  // The newest frame time learnt from: each frame tells the lean, the vertical and the floor
  // once (the file warm-up solves its frames again).
  double lean_t_last = -1e300;
  /// The view is held (frame_solver::hold_view): no more evidence of the vertical, the lean,
  /// the floor's plane or the proportions is taken; the floor's level is still followed.
  bool view_held = false;
  bool has_floor = false;
  /// The floor's resting points (camera axes): first and second moments.
  glm::dvec3 floor_m1{0.0};
  glm::dmat3 floor_m2{0.0};
  double floor_n = 0.0;
  void reset() { *this = camera_gravity{}; }
  void add_floor_point(const glm::dvec3& p);
  /// The camera's up (unit, camera axes): floor_normal() once the feet have rested on enough
  /// of the floor (a walk), else the legs' vertical with its prior.
  glm::vec3 up() const;
  /// The floor's normal when it decides the up (enough resting points, agreeing with the legs
  /// within ~37 degrees): the plane's, when they spread both ways; when they lie along one line
  /// (a straight walk), the legs' vertical turned level with that line. False otherwise.
  bool floor_normal(glm::vec3& out) const;
  /// Pitch (degrees, + = the camera looks down) and roll (degrees, + = the world's up leans
  /// toward the image's right) of the camera relative to gravity.
  float pitch_degrees() const;
  float roll_degrees() const;
};

/// What the fit made of one frame.
struct body_fit {
  bool valid = false;
  /// The fitted points, hips-centred, gravity-aligned, MediaPipe world axes (metres): what
  /// the measuring stages read in place of the frame's pose_world.
  std::array<landmark, k_pose_landmark_count> world;
  /// The hip midpoint in the camera's axes turned to gravity (metres): x right, y down (0 at
  /// the camera's height), z the horizontal distance from the camera.
  glm::vec3 hips{0.f};
  /// How far the feet's lowest point is above the floor learnt so far (metres, >= 0): a jump.
  float feet_above_floor = 0.f;
};

/// Fits one frame (needs pose and pose_world, an image of width x height pixels and the focal
/// length in pixels). `learn` adds this frame to `lengths` (before the fit) and `gravity`
/// (after it). Returns out.valid: false when the frame has too few confident torso and leg
/// points or no plausible root (the stage is then skipped for this frame).
bool fit_body(const landmark_frame& in, float width, float height, float focal, bool learn,
              body_lengths& lengths, camera_gravity& gravity, body_fit& out);

}  // namespace avatarmap::solve_detail
