// Rest skeleton table (1.70 m person, scaled) and forward kinematics of the proxy skeleton. See
// include/avatarmap/skeleton/proxy_skeleton.hpp.
#include "avatarmap/skeleton/proxy_skeleton.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>

#include "avatarmap/core/rotation.hpp"

namespace avatarmap {

namespace {

// Proportions of the 1.70 m reference person (metres).
struct finger_row {
  bone proximal;      // left side's first bone of the finger
  glm::vec3 knuckle;  // proximal joint's offset from the hand joint (left side)
  float lengths[3];   // proximal, intermediate, distal (distal: to the tip)
};

constexpr float k_hips_to_spine = 0.08f;
constexpr float k_spine = 0.12f;
constexpr float k_chest = 0.12f;
constexpr float k_upper_chest = 0.16f;  // upperChest joint -> neck joint
constexpr float k_neck = 0.10f;
constexpr float k_head = 0.23f;  // head joint -> top of the head
constexpr float k_hip_half_width = 0.09f;
constexpr float k_thigh = 0.42f;
constexpr float k_shin = 0.40f;
constexpr float k_foot = 0.117f;  // ankle -> toe joint (ball of the foot)
constexpr float k_toes = 0.04f;   // toe joint -> toe tip
constexpr float k_clavicle = 0.15f;
constexpr float k_upper_arm = 0.28f;
constexpr float k_forearm = 0.25f;
constexpr float k_hand = 0.095f;                      // wrist -> middle-finger MCP
const glm::vec3 k_shoulder_joint{0.02f, 0.15f, 0.f};  // on the upperChest
const glm::vec3 k_eye_joint{0.031f, 0.11f, 0.075f};   // eyeball centre on the head
const glm::vec3 k_jaw_joint{0.f, 0.03f, 0.02f};
constexpr float k_eye_radius = 0.012f;
constexpr float k_jaw = 0.08f;
const glm::vec3 k_thumb_cmc{0.022f, -0.008f, 0.022f};  // near the wrist, +Z (thumb) side
constexpr float k_thumb[3] = {0.045f, 0.032f, 0.028f};
const finger_row k_fingers[4] = {
    {bone::left_index_proximal, {0.088f, 0.f, 0.024f}, {0.040f, 0.025f, 0.020f}},
    {bone::left_middle_proximal, {k_hand, 0.f, 0.f}, {0.045f, 0.028f, 0.022f}},
    {bone::left_ring_proximal, {0.092f, 0.f, -0.019f}, {0.042f, 0.026f, 0.021f}},
    {bone::left_little_proximal, {0.088f, 0.f, -0.036f}, {0.033f, 0.020f, 0.018f}},
};

// Sets bone b's length and its primary child's offset along the rest direction.
void chain(proxy_skeleton& s, bone b, bone child, float length) {
  s.lengths[idx(b)] = length;
  s.offsets[idx(child)] = length * bone_rest_direction(b);
}

}  // namespace

proxy_skeleton make_proxy_skeleton(float height) {
  assert(height > 0.f && std::isfinite(height));
  if (!(height > 0.f) || !std::isfinite(height)) height = k_proxy_reference_height;
  proxy_skeleton s;
  s.height = height;
  s.offsets.fill(glm::vec3(0.f));
  s.lengths.fill(0.f);

  chain(s, bone::hips, bone::spine, k_hips_to_spine);
  chain(s, bone::spine, bone::chest, k_spine);
  chain(s, bone::chest, bone::upper_chest, k_chest);
  chain(s, bone::upper_chest, bone::neck, k_upper_chest);
  chain(s, bone::neck, bone::head, k_neck);
  s.lengths[idx(bone::head)] = k_head;
  s.offsets[idx(bone::left_eye)] = k_eye_joint;
  s.offsets[idx(bone::right_eye)] = mirror_x(k_eye_joint);
  s.lengths[idx(bone::left_eye)] = k_eye_radius;
  s.lengths[idx(bone::right_eye)] = k_eye_radius;
  s.offsets[idx(bone::jaw)] = k_jaw_joint;
  s.lengths[idx(bone::jaw)] = k_jaw;

  // Left side, then the right side as its mirror image.
  s.offsets[idx(bone::left_upper_leg)] = glm::vec3(k_hip_half_width, 0.f, 0.f);
  chain(s, bone::left_upper_leg, bone::left_lower_leg, k_thigh);
  chain(s, bone::left_lower_leg, bone::left_foot, k_shin);
  chain(s, bone::left_foot, bone::left_toes, k_foot);
  s.lengths[idx(bone::left_toes)] = k_toes;

  s.offsets[idx(bone::left_shoulder)] = k_shoulder_joint;
  chain(s, bone::left_shoulder, bone::left_upper_arm, k_clavicle);
  chain(s, bone::left_upper_arm, bone::left_lower_arm, k_upper_arm);
  chain(s, bone::left_lower_arm, bone::left_hand, k_forearm);
  s.lengths[idx(bone::left_hand)] = k_hand;

  s.offsets[idx(bone::left_thumb_metacarpal)] = k_thumb_cmc;
  chain(s, bone::left_thumb_metacarpal, bone::left_thumb_proximal, k_thumb[0]);
  chain(s, bone::left_thumb_proximal, bone::left_thumb_distal, k_thumb[1]);
  s.lengths[idx(bone::left_thumb_distal)] = k_thumb[2];
  for (const finger_row& f : k_fingers) {
    int p = idx(f.proximal);
    s.offsets[p] = f.knuckle;
    chain(s, static_cast<bone>(p), static_cast<bone>(p + 1), f.lengths[0]);
    chain(s, static_cast<bone>(p + 1), static_cast<bone>(p + 2), f.lengths[1]);
    s.lengths[p + 2] = f.lengths[2];
  }

  for (int b = 0; b < k_bone_count; ++b) {
    if (!is_left(static_cast<bone>(b))) continue;
    int m = idx(mirror_bone(static_cast<bone>(b)));
    s.offsets[m] = mirror_x(s.offsets[b]);
    s.lengths[m] = s.lengths[b];
  }

  s.scale = height / k_proxy_reference_height;
  for (int b = 0; b < k_bone_count; ++b) {
    s.offsets[b] *= s.scale;
    s.lengths[b] *= s.scale;
  }
  s.heel_offset = glm::vec3(0.f, -0.07f, -0.06f) * s.scale;
  return s;
}

void compute_proxy_fk(const proxy_skeleton& skeleton, const proxy_pose& pose, proxy_fk& out) {
  compute_world_rotations(pose, out.world);
  for (int b = 0; b < k_bone_count; ++b) {
    int p = bone_parent(b);
    out.joints[b] =
        p == k_no_parent ? pose.hips_position : out.joints[p] + out.world[p] * skeleton.offsets[b];
  }
  for (int b = 0; b < k_bone_count; ++b) {
    out.tips[b] = out.joints[b] +
                  out.world[b] * (skeleton.lengths[b] * bone_rest_direction(static_cast<bone>(b)));
  }
  out.heels[0] =
      out.joints[idx(bone::left_foot)] + out.world[idx(bone::left_foot)] * skeleton.heel_offset;
  out.heels[1] =
      out.joints[idx(bone::right_foot)] + out.world[idx(bone::right_foot)] * skeleton.heel_offset;
}

void compute_proxy_feet(const proxy_skeleton& skeleton, const proxy_pose& pose, proxy_feet& out) {
  // compute_proxy_fk's steps for the bones from the hips down each leg, in the same order.
  constexpr bone k_toes[2] = {bone::left_toes, bone::right_toes};
  constexpr bone k_feet[2] = {bone::left_foot, bone::right_foot};
  for (int side = 0; side < 2; ++side) {
    // The chain from the root to the toes (the hierarchy's order: parents first).
    int chain[8];
    int n = 0;
    for (int b = idx(k_toes[side]); b != k_no_parent; b = bone_parent(b)) chain[n++] = b;
    glm::quat world = pose.rotations[chain[n - 1]];
    glm::vec3 joint = pose.hips_position;
    for (int i = n - 2; i >= 0; --i) {
      const int b = chain[i];
      joint = joint + world * skeleton.offsets[b];
      world = world * pose.rotations[b];
      if (b == idx(k_feet[side])) out.heels[side] = joint + world * skeleton.heel_offset;
    }
    out.toe_tips[side] =
        joint + world * (skeleton.lengths[chain[0]] * bone_rest_direction(k_toes[side]));
  }
}

void joint_world_positions(const proxy_skeleton& skeleton, const proxy_pose& pose,
                           std::array<glm::vec3, k_bone_count>& out_joints) {
  std::array<glm::quat, k_bone_count> world;
  compute_world_rotations(pose, world);
  for (int b = 0; b < k_bone_count; ++b) {
    int p = bone_parent(b);
    out_joints[b] =
        p == k_no_parent ? pose.hips_position : out_joints[p] + world[p] * skeleton.offsets[b];
  }
}

float lowest_foot_point(const proxy_skeleton& skeleton, const proxy_pose& pose) {
  proxy_fk fk;
  compute_proxy_fk(skeleton, pose, fk);
  return std::min({fk.heels[0].y, fk.heels[1].y, fk.tips[idx(bone::left_toes)].y,
                   fk.tips[idx(bone::right_toes)].y});
}

float standing_hips_height(const proxy_skeleton& skeleton) {
  proxy_pose rest;
  rest.hips_position = glm::vec3(0.f);
  return -lowest_foot_point(skeleton, rest);
}

void ground_pose(const proxy_skeleton& skeleton, proxy_pose& pose) {
  pose.hips_position.y -= lowest_foot_point(skeleton, pose);
}

}  // namespace avatarmap
