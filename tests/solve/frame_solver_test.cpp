// Behaviour of frame_solver on hand-built landmark frames (no generator): known answers for
// the T-pose, a raised arm, a bent elbow, finger flexion past 90 degrees, a squat; mirror;
// bad input; confidence gating over time; inputs never modified.
#include "avatarmap/solve/frame_solver.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>

#include "avatarmap/core/rotation.hpp"

namespace avatarmap {
namespace {

constexpr float k_deg = k_pi / 180.f;

// Writes a VRM-space point (metres) as a MediaPipe world landmark (x, -y, -z).
void put(std::array<landmark, 33>& a, pose_landmark i, glm::vec3 vrm, float vis = 1.f) {
  a[idx(i)] = landmark{vrm.x, -vrm.y, -vrm.z, vis, 1.f};
}

// A T-pose in VRM space, hip midpoint at the origin, soles at y = -0.95.
landmark_frame t_pose_frame() {
  landmark_frame f;
  auto& w = f.pose_world;
  using pl = pose_landmark;
  for (int s = 0; s < 2; ++s) {
    float x = s == 0 ? 1.f : -1.f;
    auto L = [&](pl left, pl right) { return s == 0 ? left : right; };
    put(w, L(pl::left_hip, pl::right_hip), {0.09f * x, 0.f, 0.f});
    put(w, L(pl::left_knee, pl::right_knee), {0.09f * x, -0.45f, 0.f});
    put(w, L(pl::left_ankle, pl::right_ankle), {0.09f * x, -0.87f, 0.f});
    put(w, L(pl::left_heel, pl::right_heel), {0.09f * x, -0.95f, -0.06f});
    put(w, L(pl::left_foot_index, pl::right_foot_index), {0.09f * x, -0.95f, 0.16f});
    put(w, L(pl::left_shoulder, pl::right_shoulder), {0.18f * x, 0.50f, 0.f});
    put(w, L(pl::left_elbow, pl::right_elbow), {0.46f * x, 0.50f, 0.f});
    put(w, L(pl::left_wrist, pl::right_wrist), {0.71f * x, 0.50f, 0.f});
    put(w, L(pl::left_pinky, pl::right_pinky), {0.80f * x, 0.50f, -0.03f});
    put(w, L(pl::left_index, pl::right_index), {0.80f * x, 0.50f, 0.03f});
    put(w, L(pl::left_thumb, pl::right_thumb), {0.75f * x, 0.50f, 0.05f});
    put(w, L(pl::left_ear, pl::right_ear), {0.07f * x, 0.70f, -0.02f});
    put(w, L(pl::left_eye, pl::right_eye), {0.03f * x, 0.74f, 0.08f});
    put(w, L(pl::left_eye_inner, pl::right_eye_inner), {0.02f * x, 0.74f, 0.08f});
    put(w, L(pl::left_eye_outer, pl::right_eye_outer), {0.045f * x, 0.74f, 0.08f});
    put(w, L(pl::mouth_left, pl::mouth_right), {0.025f * x, 0.66f, 0.08f});
  }
  put(w, pl::nose, {0.f, 0.70f, 0.11f});
  f.set(frame_part::pose_world, true);
  return f;
}

// Left hand landmarks (VRM metres): palm down, fingers along +X, index at +Z.
landmark_frame& add_left_hand(landmark_frame& f, float index_flex_degrees) {
  auto put_h = [&](int i, glm::vec3 v) { f.left_hand_world[i] = landmark{v.x, -v.y, -v.z, 1, 1}; };
  put_h(0, {0.f, 0.f, 0.f});
  // Thumb along (1, 0, 1)/sqrt2.
  for (int k = 0; k < 4; ++k)
    put_h(1 + k, glm::vec3(0.02f, 0.f, 0.02f) + float(k) * glm::vec3(0.025f, 0.f, 0.025f));
  const float z[5] = {0.f, 0.025f, 0.f, -0.02f, -0.04f};
  for (int finger = 1; finger < 5; ++finger) {
    glm::vec3 mcp(0.09f, 0.f, z[finger]);
    int b = finger_base_landmark(finger);
    put_h(b, mcp);
    float flex = finger == 1 ? index_flex_degrees * k_deg : 0.f;
    // Proximal bends by flex toward -Y (the palm); the later joints stay straight.
    glm::vec3 dir(std::cos(flex), -std::sin(flex), 0.f);
    put_h(b + 1, mcp + 0.04f * dir);
    put_h(b + 2, mcp + 0.065f * dir);
    put_h(b + 3, mcp + 0.085f * dir);
  }
  f.set(frame_part::left_hand_world, true);
  return f;
}

std::array<glm::quat, k_bone_count> world_of(const proxy_pose& p) {
  std::array<glm::quat, k_bone_count> w;
  compute_world_rotations(p, w);
  return w;
}

glm::vec3 world_dir(const proxy_pose& p, bone b) {
  return world_of(p)[idx(b)] * bone_rest_direction(b);
}

float deg_between(glm::vec3 a, glm::vec3 b) {
  a = glm::normalize(a);
  b = glm::normalize(b);
  return std::atan2(glm::length(glm::cross(a, b)), glm::dot(a, b)) / k_deg;
}

TEST(FrameSolver, TPoseGivesIdentityBodyRotations) {
  frame_solver solver;
  proxy_pose out;
  solver.solve(t_pose_frame(), out);
  for (bone b :
       {bone::hips, bone::spine, bone::chest, bone::upper_chest, bone::left_upper_arm,
        bone::left_lower_arm, bone::right_upper_arm, bone::right_lower_arm, bone::left_upper_leg,
        bone::left_lower_leg, bone::right_upper_leg, bone::right_lower_leg, bone::left_hand,
        bone::right_hand, bone::neck, bone::head}) {
    EXPECT_LT(rotation_angle(out[b]) / k_deg, 0.5f) << bone_name(b);
  }
  // Feet: heel -> toe is horizontal here while the rest direction points 26.6 degrees down,
  // so the foot is pitched up by atan(0.08/0.16)-26.6... just check the direction matches.
  glm::vec3 foot = world_dir(out, bone::left_foot);
  EXPECT_LT(deg_between(foot, glm::vec3(0.f, -0.08f, 0.16f)), 0.5f);
  EXPECT_NEAR(out.hips_position.y, 0.95f, 1e-4f);
}

TEST(FrameSolver, ArmDownAndElbowBentForward) {
  landmark_frame f = t_pose_frame();
  using pl = pose_landmark;
  put(f.pose_world, pl::left_elbow, {0.18f, 0.22f, 0.f});    // upper arm straight down
  put(f.pose_world, pl::left_wrist, {0.18f, 0.22f, 0.25f});  // forearm forward (+Z)
  solver_options o;
  o.parts.hands = false;  // no wrist twist moved into the forearm
  frame_solver solver(o);
  proxy_pose out;
  solver.solve(f, out);
  EXPECT_LT(deg_between(world_dir(out, bone::left_upper_arm), {0, -1, 0}), 0.1f);
  EXPECT_LT(deg_between(world_dir(out, bone::left_lower_arm), {0, 0, 1}), 0.1f);
  // The elbow is a hinge: the lower arm's local rotation is 90 degrees about the upper arm's -Y.
  glm::quat expected = axis_angle({0, -1, 0}, 90.f * k_deg);
  EXPECT_LT(angle_between(out[bone::left_lower_arm], expected) / k_deg, 0.1f);
}

TEST(FrameSolver, ArmAcrossTheChestIsNotATPose) {
  landmark_frame f = t_pose_frame();
  using pl = pose_landmark;
  // Right arm reaching across the chest to the left: elbow in front, wrist at the left.
  put(f.pose_world, pl::right_elbow, {-0.05f, 0.40f, 0.25f});
  put(f.pose_world, pl::right_wrist, {0.15f, 0.45f, 0.10f});
  frame_solver solver;
  proxy_pose out;
  solver.solve(f, out);
  EXPECT_LT(deg_between(world_dir(out, bone::right_upper_arm), glm::vec3(0.13f, -0.10f, 0.25f)),
            0.1f);
  EXPECT_LT(deg_between(world_dir(out, bone::right_lower_arm), glm::vec3(0.20f, 0.05f, -0.15f)),
            0.1f);
}

TEST(FrameSolver, SquatLowersTheHipsInsteadOfRaisingALeg) {
  landmark_frame stand = t_pose_frame();
  landmark_frame squat = t_pose_frame();
  using pl = pose_landmark;
  // Knees forward and the feet 0.3 m lower relative to the hips: the hips are 0.3 m lower.
  for (int s = 0; s < 2; ++s) {
    float x = s == 0 ? 0.09f : -0.09f;
    put(squat.pose_world, s == 0 ? pl::left_knee : pl::right_knee, {x, -0.30f, 0.35f});
    put(squat.pose_world, s == 0 ? pl::left_ankle : pl::right_ankle, {x, -0.57f, 0.0f});
    put(squat.pose_world, s == 0 ? pl::left_heel : pl::right_heel, {x, -0.65f, -0.06f});
    put(squat.pose_world, s == 0 ? pl::left_foot_index : pl::right_foot_index, {x, -0.65f, 0.16f});
  }
  frame_solver solver;
  proxy_pose a, b;
  solver.solve(stand, a);
  squat.t = 0.04;
  solver.solve(squat, b);
  EXPECT_NEAR(a.hips_position.y - b.hips_position.y, 0.30f, 1e-4f);
  // Both thighs point forward and down, symmetrically.
  glm::vec3 thigh_l = world_dir(b, bone::left_upper_leg);
  glm::vec3 thigh_r = world_dir(b, bone::right_upper_leg);
  EXPECT_LT(deg_between(thigh_l, {0.f, -0.30f, 0.35f}), 0.1f);
  EXPECT_LT(deg_between(thigh_r, {0.f, -0.30f, 0.35f}), 0.1f);
}

TEST(FrameSolver, FingerFlexionPast90DegreesIsNotFolded) {
  for (float flex : {0.f, 45.f, 90.f, 105.f, 120.f}) {
    landmark_frame f = t_pose_frame();
    add_left_hand(f, flex);
    frame_solver solver;
    proxy_pose out;
    solver.solve(f, out);
    // The index proximal's local rotation relative to the hand is the flexion about -Z.
    float measured = twist_angle(out[bone::left_index_proximal], {0, 0, -1}) / k_deg;
    EXPECT_NEAR(measured, flex, 0.2f) << "flex " << flex;
    EXPECT_LT(rotation_angle(out[bone::left_middle_proximal]) / k_deg, 0.5f);
  }
}

TEST(FrameSolver, MirrorSwapsSidesAndFlipsX) {
  landmark_frame f = t_pose_frame();
  using pl = pose_landmark;
  put(f.pose_world, pl::left_elbow, {0.30f, 0.25f, 0.15f});
  put(f.pose_world, pl::left_wrist, {0.32f, 0.10f, 0.35f});
  solver_options mo;
  mo.mirror = true;
  frame_solver plain, mirrored(mo);
  proxy_pose a, b;
  plain.solve(f, a);
  mirrored.solve(f, b);
  for (int i = 0; i < k_bone_count; ++i) {
    bone bn = static_cast<bone>(i);
    EXPECT_LT(angle_between(b[bone(mirror_bone(bn))], mirror_x(a[bn])) / k_deg, 0.01f)
        << bone_name(bn);
  }
}

TEST(FrameSolver, InputIsNeverModified) {
  landmark_frame f = t_pose_frame();
  add_left_hand(f, 60.f);
  landmark_frame copy = f;
  frame_solver solver;
  proxy_pose out;
  solver.solve(f, out);
  EXPECT_EQ(std::memcmp(&copy, &f, sizeof f), 0);
}

TEST(FrameSolver, NonFiniteAndHugeInputNeverReachesThePose) {
  const float bad[] = {std::numeric_limits<float>::quiet_NaN(),
                       std::numeric_limits<float>::infinity(), -1e38f, 1e38f};
  for (float v : bad) {
    landmark_frame f = t_pose_frame();
    for (auto& l : f.pose_world) l.x = v;
    f.set(frame_part::face, true);
    f.face_count = 478;
    for (auto& l : f.face) l = landmark{v, v, v, 1, 1};
    add_left_hand(f, 30.f);
    for (auto& l : f.left_hand_world) l.y = v;
    frame_solver solver;
    proxy_pose out;
    solver.solve(f, out);
    for (const auto& q : out.rotations) {
      ASSERT_TRUE(is_finite(q));
      EXPECT_NEAR(glm::length(glm::vec4(q.x, q.y, q.z, q.w)), 1.f, 1e-4f);
    }
    EXPECT_TRUE(is_finite(out.hips_position));
    for (float e : out.expressions) EXPECT_TRUE(e >= 0.f && e <= 1.f);
  }
}

TEST(FrameSolver, WrongFaceCountIsIgnored) {
  landmark_frame f = t_pose_frame();
  f.set(frame_part::face, true);
  f.face_count = 300;
  frame_solver solver;
  proxy_pose out;
  solver.solve(f, out);
  EXPECT_EQ(out.confidence[idx(bone::left_eye)], 0.f);
}

TEST(FrameSolver, LostBoneHoldsThenEasesToRestWithoutSnapping) {
  solver_options o;
  o.confidence.hold_seconds = 0.5f;
  o.confidence.ease_seconds = 1.0f;
  frame_solver solver(o);
  landmark_frame f = t_pose_frame();
  using pl = pose_landmark;
  put(f.pose_world, pl::left_elbow, {0.18f, 0.22f, 0.f});
  put(f.pose_world, pl::left_wrist, {0.18f, -0.03f, 0.f});
  proxy_pose out;
  solver.solve(f, out);
  const glm::quat held = out[bone::left_upper_arm];
  ASSERT_GT(rotation_angle(held) / k_deg, 80.f);
  // The elbow disappears (visibility 0) for 3 seconds at 30 fps.
  f.pose_world[idx(pl::left_elbow)].visibility = 0.f;
  glm::quat prev = held;
  float max_step = 0.f;
  for (int i = 1; i <= 90; ++i) {
    f.t = i / 30.0;
    solver.solve(f, out);
    const glm::quat q = out[bone::left_upper_arm];
    max_step = std::max(max_step, angle_between(q, prev) / k_deg);
    prev = q;
    if (f.t <= 0.5) EXPECT_LT(angle_between(q, held) / k_deg, 1e-3f) << "held at t=" << f.t;
    EXPECT_EQ(out.confidence[idx(bone::left_upper_arm)], 0.f);
  }
  EXPECT_LT(rotation_angle(prev) / k_deg, 1e-3f);  // at rest after hold + ease
  EXPECT_LT(max_step, 90.f / 30.f * 1.6f);         // smoothstep peak slope 1.5x the mean
  // Hysteresis: a confidence between the thresholds does not bring it back...
  f.pose_world[idx(pl::left_elbow)].visibility = 0.4f;
  f.t += 1.0 / 30;
  solver.solve(f, out);
  EXPECT_EQ(out.confidence[idx(bone::left_upper_arm)], 0.f);
  // ...a good one does, blending in over regain_seconds (no snap).
  f.pose_world[idx(pl::left_elbow)].visibility = 0.9f;
  f.t += 1.0 / 30;
  solver.solve(f, out);
  EXPECT_GT(out.confidence[idx(bone::left_upper_arm)], 0.f);
  EXPECT_LT(rotation_angle(out[bone::left_upper_arm]) / k_deg, 45.f);
  for (int i = 0; i < 10; ++i) {
    f.t += 1.0 / 30;
    solver.solve(f, out);
  }
  EXPECT_LT(angle_between(out[bone::left_upper_arm], held) / k_deg, 0.01f);
}

TEST(FrameSolver, TimeGoingBackwardsResets) {
  frame_solver solver;
  landmark_frame f = t_pose_frame();
  f.t = 5.0;
  proxy_pose out;
  solver.solve(f, out);
  f.t = 1.0;
  solver.solve(f, out);
  EXPECT_EQ(out.t, 1.0);
  EXPECT_GT(out.confidence[idx(bone::hips)], 0.f);
}

TEST(FrameSolver, PartsSwitchedOffStayAtRest) {
  solver_options o;
  o.parts.body = false;
  frame_solver solver(o);
  landmark_frame f = t_pose_frame();
  put(f.pose_world, pose_landmark::left_elbow, {0.18f, 0.22f, 0.f});
  proxy_pose out;
  solver.solve(f, out);
  EXPECT_LT(rotation_angle(out[bone::left_upper_arm]), 1e-6f);
  EXPECT_NEAR(out.hips_position.y, o.rest_hips_height, 1e-6f);
}

TEST(SolverOptions, ValidateNamesTheField) {
  solver_options o;
  EXPECT_TRUE(o.validate().ok());
  o.hips_lean_share = 2.f;
  EXPECT_NE(o.validate().message().find("hips_lean_share"), std::string::npos);
  o = {};
  o.image_width = 640.f;
  EXPECT_FALSE(o.validate().ok());
  o = {};
  o.confidence.lost_below = 0.9f;
  EXPECT_FALSE(o.validate().ok());
}

}  // namespace
}  // namespace avatarmap
