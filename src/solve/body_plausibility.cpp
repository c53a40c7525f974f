// Bodies that are not followed: the rules on one frame (judge_body), their hysteresis
// (body_hold) and what the solver does with a held frame's measurement (hold_body). See
// include/avatarmap/solve/body_plausibility.hpp and docs/solver.md.
#include "avatarmap/solve/body_plausibility.hpp"

#include <algorithm>
#include <cmath>

#include "solve/body_hold.hpp"
#include "solve/solve_geometry.hpp"
#include "solve/solve_measurement.hpp"
#include "solve/solve_prepare.hpp"

namespace avatarmap {
namespace {

using pl = pose_landmark;

// Knees above the hips' midpoint by more than this share of the torso's image length (a deep
// squat keeps them 0.18 below; on a forearm close-up read as a body they were 0.8 above).
constexpr float k_knees_above_hips = 0.3f;
// Torso image length over the image height beyond which the body is larger than any framing
// (a webcam's upper-body framing shows ~0.8).
constexpr float k_max_torso_per_height = 1.5f;
// Thigh and shin over the torso (hips' midpoint to shoulders' midpoint), metric points: a
// person's are 0.6-1.0 (Google's reference squat: 0.62-0.86); BlazePose's world points keep a
// person's proportions, so outside this the points are not a person's.
constexpr float k_min_leg_ratio = 0.4f, k_max_leg_ratio = 1.4f;
// The torso's metric length (BlazePose's world points scale every body to a person's size:
// 0.46-0.51 m on the reference squat).
constexpr float k_min_torso_m = 0.25f, k_max_torso_m = 0.8f;
// Mean confidence of hips, knees and ankles under which the lower body is not seen.
constexpr float k_min_lower_body_confidence = 0.5f;

bool finite2(const landmark& l) { return std::isfinite(l.x) && std::isfinite(l.y); }
bool finite3(const landmark& l) { return finite2(l) && std::isfinite(l.z); }

float distance(const landmark& a, const landmark& b) {
  const float dx = a.x - b.x, dy = a.y - b.y, dz = a.z - b.z;
  return std::sqrt(dx * dx + dy * dy + dz * dz);
}

}  // namespace

const char* body_doubt_name(int bit_index) {
  switch (bit_index) {
    case 0:
      return "legs above the hips";
    case 1:
      return "torso larger than the image";
    case 2:
      return "bone lengths no person has";
    case 3:
      return "lower body not seen";
    default:
      return "";
  }
}

body_verdict judge_body(const landmark_frame& in, float image_width, float image_height) {
  body_verdict v;
  const bool has_image = in.has(frame_part::pose), has_world = in.has(frame_part::pose_world);
  if (!has_image && !has_world) return v;
  const auto& pts = has_image ? in.pose : in.pose_world;
  const int hips[2] = {idx(pl::left_hip), idx(pl::right_hip)};
  const int shoulders[2] = {idx(pl::left_shoulder), idx(pl::right_shoulder)};
  for (int i : {hips[0], hips[1], shoulders[0], shoulders[1]})
    if (!finite3(pts[i])) return v;  // no torso: nothing to judge (the body is not measured)
  v.has_body = true;

  // Lower body's confidence (the points the estimator reports; image or world alike).
  float c_sum = 0.f;
  for (pl l : {pl::left_hip, pl::right_hip, pl::left_knee, pl::right_knee, pl::left_ankle,
               pl::right_ankle})
    c_sum += solve_detail::landmark_confidence(pts[idx(l)]);
  if (c_sum < 6.f * k_min_lower_body_confidence) v.doubts |= body_doubt_lower_body_unseen;

  if (has_image) {
    // Image points in pixels (square pixels when the size is unknown); y down.
    const float w = image_width > 0.f ? image_width : 1.f;
    const float h = image_height > 0.f ? image_height : 1.f;
    auto px = [&](int i) { return glm::vec2(in.pose[i].x * w, in.pose[i].y * h); };
    const glm::vec2 hip = 0.5f * (px(hips[0]) + px(hips[1]));
    const glm::vec2 sh = 0.5f * (px(shoulders[0]) + px(shoulders[1]));
    const float torso = glm::length(sh - hip);
    if (torso > k_max_torso_per_height * h) v.doubts |= body_doubt_torso_too_large;
    const landmark &kl = in.pose[idx(pl::left_knee)], &kr = in.pose[idx(pl::right_knee)];
    const landmark &al = in.pose[idx(pl::left_ankle)], &ar = in.pose[idx(pl::right_ankle)];
    if (finite2(kl) && finite2(kr) && finite2(al) && finite2(ar) && torso > 0.f) {
      const float knees_above = std::min(hip.y - kl.y * h, hip.y - kr.y * h) / torso;
      const float ankles_above = std::min(hip.y - al.y * h, hip.y - ar.y * h) / torso;
      if (ankles_above > 0.f || knees_above > k_knees_above_hips)
        v.doubts |= body_doubt_legs_above_hips;
    }
  }
  if (has_world) {
    const auto& p = in.pose_world;
    bool ok = true;
    for (pl l : {pl::left_hip, pl::right_hip, pl::left_shoulder, pl::right_shoulder, pl::left_knee,
                 pl::right_knee, pl::left_ankle, pl::right_ankle})
      ok = ok && finite3(p[idx(l)]);
    if (ok) {
      landmark hip_mid = p[hips[0]], sh_mid = p[shoulders[0]];
      hip_mid.x = 0.5f * (p[hips[0]].x + p[hips[1]].x);
      hip_mid.y = 0.5f * (p[hips[0]].y + p[hips[1]].y);
      hip_mid.z = 0.5f * (p[hips[0]].z + p[hips[1]].z);
      sh_mid.x = 0.5f * (p[shoulders[0]].x + p[shoulders[1]].x);
      sh_mid.y = 0.5f * (p[shoulders[0]].y + p[shoulders[1]].y);
      sh_mid.z = 0.5f * (p[shoulders[0]].z + p[shoulders[1]].z);
      const float torso = distance(hip_mid, sh_mid);
      bool bad = !(torso >= k_min_torso_m && torso <= k_max_torso_m);
      if (!bad) {
        const float bones[4] = {distance(p[idx(pl::left_hip)], p[idx(pl::left_knee)]),
                                distance(p[idx(pl::right_hip)], p[idx(pl::right_knee)]),
                                distance(p[idx(pl::left_knee)], p[idx(pl::left_ankle)]),
                                distance(p[idx(pl::right_knee)], p[idx(pl::right_ankle)])};
        for (float b : bones)
          bad = bad || !(b >= k_min_leg_ratio * torso && b <= k_max_leg_ratio * torso);
      }
      if (bad) v.doubts |= body_doubt_bone_ratios;
    }
  }
  return v;
}

body_follow body_hold::update(const body_verdict& v, double t) {
  if (!v.has_body) return state_;
  const body_follow want = v.follow();
  if (!decided_) {
    decided_ = true;
    state_ = want;
    run_ = 0;
    return state_;
  }
  const int w = static_cast<int>(want), s = static_cast<int>(state_);
  if (w == s) {
    run_ = 0;
    return state_;
  }
  // A run asks for a change in one direction; a frame asking the other way (or none) ends it.
  const int r = static_cast<int>(run_target_);
  if (run_ > 0 && (w > s) != (r > s)) run_ = 0;
  if (run_ == 0) run_start_ = t;
  // The run's target: the least change any of its frames asked for.
  if (run_ == 0 || (w > s ? w < r : w > r)) run_target_ = want;
  ++run_;
  bool change = run_ >= (w > s ? k_enter_frames : k_leave_frames);
  if (change && run_target_ == body_follow::upper_body && state_ == body_follow::all)
    change = t - run_start_ >= k_unseen_enter_seconds;
  if (change) {
    state_ = run_target_;
    run_ = 0;
  }
  return state_;
}

namespace solve_detail {

void hold_body(body_follow follow, body_rest rest, const prepared_frame& f, const solver_options& o,
               frame_measurement& m) {
  if (follow == body_follow::all || rest == body_rest::off) return;
  // The lower body at rest: hips upright facing the camera, the legs straight down
  // (standing) or the thighs forward and the shins down (sitting), feet flat. Confidence 1:
  // a decision, not a lost bone (the gate and the offline filter blend into it and out).
  constexpr float k_held = 1.f;
  const glm::quat id = identity_quat();
  // About +X by -90 degrees: the thigh's rest direction (-Y) turns to the avatar's front (+Z).
  const glm::quat thigh_forward = glm::angleAxis(-0.5f * k_pi, k_x);
  const bool sitting = rest == body_rest::sitting;
  const glm::quat thigh_w = sitting ? thigh_forward : id;
  const glm::quat shin_local = sitting ? glm::conjugate(thigh_forward) : id;
  set(m, bone::hips, id, k_held);
  for (bone b : {bone::left_upper_leg, bone::right_upper_leg}) set(m, b, thigh_w, k_held);
  for (bone b : {bone::left_lower_leg, bone::right_lower_leg}) set(m, b, id, shin_local, k_held);
  for (bone b : {bone::left_foot, bone::right_foot}) set(m, b, id, id, k_held);
  for (bone b : {bone::left_toes, bone::right_toes}) set(m, b, id, id, k_held);
  m.hips_height_valid = o.parts.hips_translation;
  m.hips_height = sitting ? k_sitting_hips_share * o.rest_hips_height : o.rest_hips_height;
  m.hips_ground_valid = false;  // the root stays where it was (the gate holds it)

  const bone chain[] = {bone::spine, bone::chest, bone::upper_chest, bone::left_shoulder,
                        bone::right_shoulder};
  if (follow == body_follow::limbs_off) {
    // The points are not a person's: the spine chain and the arms are not followed either
    // (lost: held, then eased to rest); hands from their own landmarks replace the coarse
    // wrists later (measure_hands).
    for (bone b : chain) m.bones[idx(b)].confidence = 0.f;
    for (bone b : {bone::left_upper_arm, bone::right_upper_arm, bone::left_lower_arm,
                   bone::right_lower_arm, bone::left_hand, bone::right_hand})
      m.bones[idx(b)].confidence = 0.f;
    return;
  }
  // Upper-body framing: the spine chain turns from the upright hips to the shoulders' frame,
  // split as measure_body splits it, with the shoulders' confidence (the hips' is low).
  // measure_body wrote the shoulders' frame with the torso's confidence, which the unseen hips
  // pull down: the shoulders' own confidence is the chain's now.
  if (!f.body.valid) return;
  using pl = pose_landmark;
  const float c_shoulders = min_conf(f.body, {idx(pl::left_shoulder), idx(pl::right_shoulder)});
  const glm::quat shoulders_w = m.bones[idx(bone::upper_chest)].world;
  const glm::quat third = nlerp_shortest(id, shoulders_w, k_spine_chain_share);
  set(m, bone::spine, third, third, c_shoulders);
  set(m, bone::chest, third * third, third, c_shoulders);
  set(m, bone::upper_chest, shoulders_w, c_shoulders);
  set(m, bone::left_shoulder, shoulders_w, id, c_shoulders);
  set(m, bone::right_shoulder, shoulders_w, id, c_shoulders);
}

}  // namespace solve_detail
}  // namespace avatarmap
