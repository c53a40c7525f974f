// Stage 2c of the solver (internal): neck, head, eyes, ARKit's 52 blendshapes and the
// expressions derived from them, from the face mesh (or, without one, the head from the pose's
// face points). Rotations in VRM space (docs/conventions.md); weights in [0, 1].
// docs/expressions.md defines every measurement, its neutral and full values, and the
// calibration.
#pragma once

#include <array>
#include <glm/gtc/quaternion.hpp>
#include <vector>

#include "avatarmap/solve/frame_solver.hpp"
#include "solve/solve_prepare.hpp"

namespace avatarmap::solve_detail {

/// The face's raw measurements (ratios of mesh distances, no unit): each blendshape is read
/// as the change of one of these from its neutral value. l = the person's left, r = right.
enum face_feature : int {
  ff_eye_gap_l,  // mean lid gap / eye width
  ff_eye_gap_r,
  ff_brow_inner_l,  // inner brow end above the inner eye corner / eye width
  ff_brow_inner_r,
  ff_brow_outer_l,  // outer brow end above the outer eye corner / eye width
  ff_brow_outer_r,
  ff_cheek_l,  // point below the lower lid, above the eye's corner line / eye width
  ff_cheek_r,
  ff_mouth_gap,    // inner-lip gap / face width (outer eye corners)
  ff_mouth_width,  // corner to corner / face width
  ff_corner_up_l,  // mouth corner above the outer lips' middle / face width
  ff_corner_up_r,
  ff_corner_out_l,  // mouth corner out from the upper lip's middle (0 and 13) / face width
  ff_corner_out_r,
  ff_mouth_shift,   // upper lip's middle toward the person's left of the nose base / face width
  ff_jaw_shift,     // chin toward the person's left of the outer eye corners' midpoint / face w.
  ff_lip_upper_h,   // upper lip's height: outer (0) above inner (13) / face width
  ff_lip_lower_h,   // lower lip's height: inner (14) above outer (17) / face width
  ff_chin_drop,     // chin below the outer eye corners' midpoint / face width
  ff_upper_side_l,  // upper lip's side point above its middle-to-corner line / face width
  ff_upper_side_r,
  ff_lower_side_l,  // lower lip's side point below its middle-to-corner line / face width
  ff_lower_side_r,
  ff_nose_wing_l,  // nose's wing above the point below the nose (2) / face width
  ff_nose_wing_r,
  ff_iris_u_l,  // iris (centre and ring) from the inner corner along the corner line / w
  ff_iris_u_r,
  ff_iris_v_l,  // iris (centre and ring) above the corners' midpoint / eye width
  ff_iris_v_r,
  k_face_feature_count
};

/// One frame's measurements. `valid`: the mesh was read (every feature but the irises'
/// set); `iris[s]`: that eye's iris features set (478 points, eye open enough). `frontal`:
/// the face turned less than 45 degrees from the camera (the calibration learns only then).
struct face_features {
  std::array<float, k_face_feature_count> v{};
  bool valid = false;
  bool iris[2] = {false, false};
  bool frontal = false;
  bool readable = false;  // turned less than 65 degrees: expressions are read
  /// This frame's head from the mesh and from the pose's face points (ears, eyes, mouth
  /// corners), when each was seen: the calibration learns the rotation between the two.
  glm::quat mesh_head{1.f, 0.f, 0.f, 0.f};
  glm::quat body_head{1.f, 0.f, 0.f, 0.f};
  bool mesh_head_valid = false;
  bool body_head_valid = false;
  /// The way back to the camera in the head's frame: its X (toward the person's left) and Y
  /// (up) components (0, 0 = the face looks straight at the camera). Set with `valid`; the
  /// take's calibration models each measurement's neutral as linear in them.
  float camera_x = 0.f, camera_y = 0.f;
};

/// The face's neutral value of each measurement: the population's until calibrated, then a
/// robust estimate learnt from the face itself (docs/expressions.md, "Calibration"): the
/// per-measurement quantile of the first k_window frontal frames, then a stochastic quantile
/// step per frame whose size decreases (the quantile of the take so far) to a floor (slow
/// changes followed); for the irises a slow median from the population's (no window; calibrate_take
/// takes the take's gaze mode). Fixed size; update() allocates nothing.
struct face_calibration {
  static constexpr int k_window = 24;
  std::array<float, k_face_feature_count> neutral{};
  std::array<std::array<float, k_window>, k_face_feature_count> window{};
  std::array<int, k_face_feature_count> filled{};
  std::array<long, k_face_feature_count> seen{};  // values learnt after the window
  std::array<bool, k_face_feature_count> settled{};
  long frames = 0;  // frames learnt from (from_take: the take's read frames)
  /// The head from the pose's face points, turned into the mesh's head: body_head *
  /// body_to_mesh = mesh_head, averaged over the frames that saw both (docs/solver.md, "The
  /// head"). The two frames differ by a person- and model-dependent rotation (43 degrees mean,
  /// sd 5, on pose_squats.mp4: BlazePose's face depths are rough), so the fallback uses the
  /// one learnt; identity until a frame saw both.
  glm::quat body_to_mesh{1.f, 0.f, 0.f, 0.f};
  long head_pairs = 0;

  /// From a whole take (calibrate_take): each measurement's neutral is `neutral` + slope_x *
  /// camera_x + slope_y * camera_y (the mesh's proportions change with the head's turn from
  /// the camera: MediaPipe's depth is not to scale), and a change from it smaller than
  /// `dead_zone` (the take's frame-to-frame noise) reads as none. 0 live. `from_take`: the
  /// neutrals are the take's; update() then learns only the head offset (and an iris the take
  /// did not calibrate).
  std::array<float, k_face_feature_count> slope_x{};
  std::array<float, k_face_feature_count> slope_y{};
  std::array<float, k_face_feature_count> dead_zone{};
  bool from_take = false;
  /// Per eye: its iris's rest place is the take's (the median over frontal frames with the eye
  /// open); update() then leaves it. False for an eye the take saw too seldom: it learns live.
  bool iris_from_take[2] = {false, false};

  face_calibration() { reset(); }
  void reset();
  void update(const face_features& f);
  void learn_gaze(int feature, float value);
  /// Whether every measurement the mesh gives (the irises' when seen) has its own neutral.
  bool calibrated() const;
  /// Measurement i's neutral in frame `f` (the take's fit at f's turn from the camera,
  /// clamped to the plausible range), and f's change from it less the dead zone, toward 0.
  float neutral_at(int i, const face_features& f) const;
  float change(int i, const face_features& f) const;
};

/// A whole take's face measurements, for face_calibration's calibration over the take.
struct face_take {
  std::vector<face_features> frames;  // in capture order, unread frames included
};

/// Calibrates `c` from a whole take (docs/expressions.md, "Calibration over a take"): per
/// measurement but the irises', over every frame whose face is read, a robust linear fit of
/// the value on the way to the camera (camera_x, camera_y), its neutral the table's quantile
/// of what the fit leaves, and a dead zone of the frame-to-frame noise; each iris's rest
/// place the median over frontal frames with that eye open. A take with fewer than
/// k_take_min_frames read frames leaves `c` as it is (false).
bool calibrate_take(const face_take& take, face_calibration& c);
inline constexpr int k_take_min_frames = 8;

/// The face measurements of one prepared frame (the head from the mesh), no blendshapes: the
/// take's calibration reads every frame with it before solving. False without a readable mesh.
bool read_face_features(const prepared_frame& f, const solver_options& o, face_features& out);

/// Neck and head relative to `upper_chest_w` (this frame's measured upper chest when
/// `base_measured`, else the last output's); with a face mesh also `features`, and from them
/// against `calibration`'s neutral the eyes (478-point meshes), m.blendshapes and
/// m.expressions (m.expressions_valid). Nothing when the face part is off. The neck's and
/// head's world rotations are what the gate keeps: it takes their locals relative to the
/// torso it shows (solve_gate.cpp; docs/solver.md, "The head").
void measure_face(const prepared_frame& f, const solver_options& o, const glm::quat& upper_chest_w,
                  bool base_measured, const face_calibration& calibration, face_features& features,
                  frame_measurement& m);

}  // namespace avatarmap::solve_detail
