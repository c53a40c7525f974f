// Landmarks -> proxy pose: body, hands, face, confidence gating, hips translation.
// Stages: prepare -> measure body / hands / face -> confidence gate (docs/solver.md, "Stages";
// the gate's rules: solve/confidence_gate.hpp). The solver keeps per-bone state between
// frames (the gate's, the translation origin, the last upper-arm twist); frames must be fed in
// capture order. solve() allocates nothing.
// Thread-safety: one solver per performer and thread; no member (not even the const
// measure()) may run concurrently with another on the same object. See docs/solver.md.
#pragma once

#include <array>
#include <cstddef>
#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>
#include <memory>

#include "avatarmap/landmarks/landmark_frame.hpp"
#include "avatarmap/skeleton/proxy_pose.hpp"
#include "avatarmap/solve/body_plausibility.hpp"
#include "avatarmap/solve/confidence_gate.hpp"
#include "avatarmap/solve/hand_shape.hpp"
#include "avatarmap/solve/solver_options.hpp"

namespace avatarmap {

namespace solve_detail {
struct prepared_frame;  // src/solve/solve_prepare.hpp
struct body_lengths;    // src/solve/solve_fit.hpp
struct camera_gravity;
struct body_fit;
struct face_calibration;  // src/solve/solve_face.hpp
struct face_features;
struct face_take;
}  // namespace solve_detail

/// One bone's measurement before confidence gating and its confidence (0 = not measured this
/// frame): a world rotation in VRM space, or, when has_local, the rotation relative to the
/// measured parent (finger joints, eyes, toes, shoulders). For has_local bones `world` is
/// filled only where a child needs it (shoulders, toes); compose parent world * local to get it.
struct bone_measurement {
  glm::quat world{1.f, 0.f, 0.f, 0.f};
  glm::quat local{1.f, 0.f, 0.f, 0.f};
  float confidence = 0.f;
  bool has_local = false;
};

/// What the solver measured in one frame, before gating (exposed for tests and tools).
struct frame_measurement {
  std::array<bone_measurement, k_bone_count> bones{};
  bool hips_height_valid = false;
  float hips_height = 0.f;  // metres above the lowest foot point
  bool hips_ground_valid = false;
  glm::vec2 hips_ground{0.f};  // X, Z in metres from the camera axis / depth
  std::array<float, k_expression_count> expressions{};  // derived from the blendshapes
  std::array<float, k_blendshape_count> blendshapes{};  // ARKit's 52 (docs/expressions.md)
  bool expressions_valid = false;                       // both set (a face mesh was read)
};

class frame_solver {
 public:
  /// Options must satisfy options.validate(); invalid options are replaced by defaults
  /// (check validate() first to report the error).
  explicit frame_solver(const solver_options& options = {});
  ~frame_solver();
  frame_solver(frame_solver&&) noexcept;
  frame_solver& operator=(frame_solver&&) noexcept;

  /// Solves one frame into `out` (out.t = in.t). Input is never modified. Frames with a time
  /// earlier than the previous one reset the solver's state first. Non-finite landmarks are
  /// treated as not seen.
  void solve(const landmark_frame& in, proxy_pose& out);

  /// Measurement only (no gating, no state change: the hands are fitted to the shapes learnt
  /// so far, and nothing is learnt): for tests and diagnostics.
  void measure(const landmark_frame& in, frame_measurement& out) const;

  /// Forgets all state (as if newly constructed with the same options).
  void reset();
  /// Forgets the take's pose state (gates, held rotations, the root's origin, the floor's
  /// place) but keeps what was learnt of the camera (field of view, pitch and roll, the world
  /// points' lean) and of the performer (bone lengths, hand shapes): a file is solved once
  /// for these (a warm-up over its first seconds), then from its start with them known.
  /// `keep_view` false also forgets the camera's pitch and roll, the floor and the world
  /// points' lean (learnt while the field of view was still moving), keeping the field of
  /// view and the proportions: the warm-up's second pass learns them again.
  void restart_take(bool keep_view = true);
  /// Holds what was learnt of the camera (field of view, pitch and roll, the floor's plane,
  /// the world points' lean) and of the performer's proportions: later frames are solved
  /// with them as they are (one depth scale and one vertical for the whole take), the floor's
  /// level is still followed. The file job holds the view after its warm-up. reset() and
  /// restart_take(false) release it.
  void hold_view(bool hold = true);

  /// The root's ground origin: where the person was first seen (X from the camera's axis,
  /// Y = minus the depth, metres); hips_position X/Z are measured from it. false before.
  bool ground_origin(glm::vec2& out) const;
  /// Measures hips_position X/Z from `origin` (a point of ground_origin()'s space) instead of
  /// where the person is first seen: several people placed from one origin
  /// (capture_pipeline::solve_people). reset() and restart_take() forget it.
  void set_ground_origin(const glm::vec2& origin);

  const solver_options& options() const { return options_; }

  /// The horizontal field of view in use (degrees): options().horizontal_fov_degrees when
  /// given, else the estimate so far (60 before any evidence).
  float horizontal_fov_degrees() const;
  /// Frames whose pose told something about the field of view (0 when it was given, or when
  /// no frame's image and world points formed one pinhole view). Every third frame is
  /// fitted, up to 600 that told something (consecutive frames are nearly the same view).
  long fov_evidence_frames() const { return focal_frames_; }
  /// The camera's pitch (degrees, + = looking down) and roll (+ = the world's up leans toward
  /// the image's right) relative to gravity, learnt from the standing body's vertical when the
  /// body is fitted to the image (options().fit_body_to_image); 0 before any evidence (a
  /// level camera is assumed).
  float camera_pitch_degrees() const;
  float camera_roll_degrees() const;
  /// The performer's leg length learnt so far when the body is fitted to the image: thigh +
  /// shin (metres, hip socket to ankle, the running means of the world points' lengths); 0
  /// while either is unknown. The contact stage scales its skeleton by it (solve/pose_stream).
  float performer_leg_length() const;
  /// Frames that told the vertical (both legs straight and parallel, feet level, confident
  /// points), and the feet's resting points when the floor's plane decides it (a walk over
  /// enough of the floor); both 0: a level camera is assumed.
  long gravity_evidence_frames() const;
  long floor_evidence_points() const;
  /// The shape learnt of the avatar's left (0) or right (1) hand (options().fit_hand_shape).
  const hand_shape& learnt_hand(int side) const { return hand_shapes_[side != 0 ? 1 : 0]; }
  /// Frames of this take whose lower body was held at rest because the body was not
  /// plausible or the legs not seen (options().lower_body_rest; body_plausibility.hpp), and
  /// why. restart_take() and reset() start the count again.
  const body_hold_stats& hold_stats() const { return hold_stats_; }
  /// Whether the face's neutral is calibrated (docs/expressions.md, "Calibration"): every
  /// measurement of the mesh has its own neutral from the face's first frontal frames; until
  /// then the population's is used. restart_take() keeps the calibration, reset() forgets it.
  bool face_calibrated() const;
  /// Frontal face frames the calibration has learnt from (calibrated over a take: the take's
  /// frames whose face was read).
  long face_calibration_frames() const;
  /// Calibrates the face over a whole take before it is solved (docs/expressions.md,
  /// "Calibration over a take"): every measurement but the irises' gets the take's neutral,
  /// its dependence on the head's turn from the camera and a dead zone of the take's noise,
  /// and is not learnt further (the irises still learn as live). The frames are read with
  /// what the solver knows now (its field of view), nothing else is learnt; a take with fewer
  /// than 8 frames whose face is read changes nothing (false). restart_take() keeps it,
  /// reset() forgets it. The file job (jobs/solve_file.hpp) calls it on every file.
  bool calibrate_face(const landmark_frame* frames, std::size_t count);
  /// The same one frame at a time, for a take too long to hold (a file read twice):
  /// begin_face_take(), add_face_take() for each frame in order, then end_face_take().
  /// Allocates (a few hundred bytes per frame).
  void begin_face_take();
  void add_face_take(const landmark_frame& in);
  bool end_face_take();
  /// How much of the body the last solved frame followed.
  body_follow body_follow_state() const { return hold_.state(); }

 private:
  // The gate stage (src/solve/solve_gate.cpp): this frame's measurement -> what is shown.
  void gate_bones(const frame_measurement& m, double t, proxy_pose& out);
  glm::vec3 gate_hips_position(const frame_measurement& m, double t);
  void gate_expressions(const frame_measurement& m, double t, proxy_pose& out);
  const glm::quat& previous_world(int b) const;
  // Adds this frame's evidence on the focal length (horizontal_fov_degrees 0 only).
  void update_focal(const landmark_frame& in);
  // Stage 1c: the body fitted to the image through the camera (src/solve/solve_fit.hpp);
  // null when it does not run on this frame. `learn` updates the lengths and gravity.
  const solve_detail::body_fit* fit_frame(const landmark_frame& in, bool learn,
                                          solve_detail::body_fit& out) const;
  // Whether a prepared hand is fitted to its shape (options, and metric points seen).
  bool fits_hand(const solve_detail::prepared_frame& f, int side) const;
  // The measuring stages on a prepared frame whose hands are fitted already.
  void measure_prepared(const landmark_frame& in, const solve_detail::prepared_frame& f,
                        body_follow follow, frame_measurement& m,
                        solve_detail::face_features& features) const;

  solver_options options_;
  float focal_per_width_ = 1.f;  // focal length / image width, from the field of view
  // Field of view estimated from the pose (horizontal_fov_degrees 0): the information-weighted
  // sum of the frames' focal lengths with a prior (src/solve/solve_camera.hpp).
  double focal_information_ = 0.0;
  double focal_weighted_sum_ = 0.0;
  long focal_frames_ = 0;
  long focal_tick_ = 0;        // frames seen, for sampling the focal length's fit
  double focal_t_last_ = 0.0;  // the newest frame time fitted (kept by restart_take)
  std::array<rotation_gate, k_bone_count> bones_{};           // output = the local rotation shown
  mutable std::array<glm::quat, k_bone_count> prev_world_{};  // memo of previous_world()
  mutable std::array<unsigned, k_bone_count> world_stamp_{};
  unsigned world_generation_ = 1;
  glm::quat arm_reference_[2]{};  // last measured upper-arm world rotations (left, right)
  bool have_arm_reference_[2] = {false, false};
  gate_state hips_height_state_{};
  gate_state ground_state_{};
  gate_state face_state_{};
  float hips_height_ = 0.f;
  float hips_height_held_ = 0.f;
  glm::vec2 ground_{0.f};
  glm::vec2 ground_origin_{0.f};
  bool have_origin_ = false;
  std::array<float, k_expression_count> expressions_held_{};
  std::array<float, k_blendshape_count> blendshapes_held_{};
  double last_t_ = 0.0;
  bool started_ = false;
  mutable frame_measurement scratch_{};
  std::array<hand_shape, 2> hand_shapes_{};  // avatar's left, right (canonical space)
  body_hold hold_{};  // whether the body is followed (hysteresis over frames)
  body_hold_stats hold_stats_{};
  // The body fit's state (allocated once, at construction): segment lengths learnt over the
  // take, the camera's gravity, this frame's fit.
  std::unique_ptr<solve_detail::body_lengths> lengths_;
  std::unique_ptr<solve_detail::camera_gravity> gravity_;
  std::unique_ptr<solve_detail::body_fit> fit_;
  // The face's neutral measurements (learnt over the take, kept by restart_take) and this
  // frame's measurements (allocated once, at construction).
  std::unique_ptr<solve_detail::face_calibration> face_calibration_;
  std::unique_ptr<solve_detail::face_features> face_features_;
  std::unique_ptr<solve_detail::face_take> face_take_;  // between begin_ and end_face_take
};

}  // namespace avatarmap
