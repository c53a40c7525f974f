// Random human-ish poses and a scripted demo motion for the synthetic ground truth.
// Conventions of the sampled local rotations (VRM normalised space, left side; the right side
// is always mirror_x of the same construction):
// - finger flexion theta at a joint: axis_angle((0, 0, -1), theta) (bends toward the palm,
//   -Y); proximal joints add spread about local Y first: q = flex * axis_angle((0,1,0), s);
//   with random_pose_limits::finger_side_bend the intermediate and distal joints too.
// - thumb hinge axis h = normalize(cross(rest_dir, (0, -1, 0))) = (1, 0, -1)/sqrt(2);
//   proximal/distal flexion = axis_angle(h, theta); metacarpal = flex(h) * spread(Y) *
//   twist(rest_dir).
// - elbow: hinge = axis_angle((0, -1, 0), theta) (forearm toward +Z) times forearm twist
//   about the rest direction: q = hinge * twist.
// - knee: axis_angle((1, 0, 0), theta) (shin backward). Eyes: R_y(yaw) * R_x(pitch).
#pragma once

#include <random>

#include "avatarmap/skeleton/proxy_pose.hpp"
#include "avatarmap/skeleton/proxy_skeleton.hpp"

namespace avatarmap {

/// Ranges of random_pose() (degrees unless stated). Each angle is drawn uniformly.
struct random_pose_limits {
  // Upper arm direction: uniform on the unit sphere restricted to Z >= arm_min_forward (front
  // hemisphere and the sides, slightly behind) and side * X >= -arm_max_across (across the
  // chest), which includes overhead and hanging down; plus a twist about the bone.
  float arm_min_forward = -0.25f;
  float arm_max_across = 0.6f;
  float upper_arm_twist = 45.f;
  float shoulder = 10.f;  // each axis
  float elbow_max = 140.f;
  float forearm_twist = 80.f;
  float hand = 60.f;  // each axis
  float leg_forward_min = -30.f;
  float leg_forward_max = 100.f;
  float leg_side = 40.f;
  float leg_twist = 20.f;
  float knee_max = 130.f;
  float foot = 30.f;  // about X; Y and Z get half of it
  float hips_yaw = 45.f;
  float hips_lean = 30.f;  // about X and about Z
  float spine = 15.f;      // spine, chest, upperChest: each axis
  float neck = 30.f;
  float head = 40.f;
  float finger_flex_max = 110.f;
  float finger_spread = 15.f;
  float thumb_metacarpal = 30.f;
  float thumb_flex_max = 80.f;
  /// Non-hinge fingers: a sideways bend drawn in +-finger_side_bend at every finger
  /// intermediate and distal joint (q = flex * axis_angle((0, 1, 0), b)) and at the thumb's
  /// proximal and distal joints (about cross(h, rest_dir), after the hinge). 0 (the default)
  /// draws nothing, so the random sequence of older seeds is unchanged.
  float finger_side_bend = 0.f;
  /// Coupled spine and neck, as a person bends: when >= 0, one rotation drawn with `spine` per
  /// axis is shared by spine, chest and upperChest, and one drawn with `head` per axis is
  /// split in halves between neck and head (quat_fraction 1/2 each); every one of these five
  /// bones then gets its own deviation drawn in +-coupled_deviation degrees per axis (the
  /// part no landmark can tell apart). Negative (the default): the five are drawn
  /// independently, as before.
  float coupled_deviation = -1.f;
  /// Lumbopelvic rhythm (only with coupled_deviation >= 0): when pelvis_share_max > 0, a
  /// person leans as a whole: one lean (about X and Z, each in +-hips_lean) is split between
  /// the pelvis, which takes a share drawn in [pelvis_share_min, pelvis_share_max], and the
  /// spine, chest and upperChest, which take a third each of the rest; on top of that the
  /// spine chain's shared rotation keeps its twist (+-spine about Y) and only +-spine_free_lean
  /// per axis of lean of its own. 0 (the default): the hips lean and the spine bend are drawn
  /// independently, as before.
  float pelvis_share_min = 0.f;
  float pelvis_share_max = 0.f;
  float spine_free_lean = 5.f;
  float eye_yaw = 25.f;
  float eye_pitch = 15.f;
  bool fingers = true;      // else finger bones stay at rest
  bool expressions = true;  // else all weights 0
  /// hips_position: X and Z uniform in +-hips_xz_range (metres) around 0, Y = hips_height.
  /// Use ground_pose() afterwards to put the feet on the floor.
  float hips_xz_range = 0.3f;
  float hips_height = 0.89f;
};

/// A random pose (confidence 1 for every bone, t = 0): see random_pose_limits. Expressions:
/// blink with probability 1/2 (uniform weight), one-sided extra closure with probability 1/4,
/// one viseme at a time (probability 5/6), per side one of none / browUp / browDown.
proxy_pose random_pose(std::mt19937& rng, const random_pose_limits& limits = {});

/// Scripted 10 s loop (t in seconds, any value; wraps): two squats with the hips lowering
/// (0-4 s, feet kept flat on the floor), waving with the right hand (4-8 s), left-hand finger
/// curls (5-9 s), talking (6-9.5 s), blinks, a slow head turn and gaze. hips_position puts
/// the soles on Y = 0 for `skeleton`. Allocation-free.
proxy_pose demo_motion_pose(double t, const proxy_skeleton& skeleton);
/// Same for the default 1.70 m skeleton.
proxy_pose demo_motion_pose(double t);

}  // namespace avatarmap
