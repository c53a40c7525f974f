// The proxy skeleton's bones: all 55 VRM 1.0 humanoid bones, in an order where every parent
// comes before its children. Names are VRM 1.0's. Rest geometry: docs/conventions.md, "The
// proxy skeleton" (VRM T-pose, Y up, facing +Z, avatar's left +X).
#pragma once

#include <array>
#include <cstdint>
#include <glm/glm.hpp>
#include <optional>
#include <string_view>

namespace avatarmap {

enum class bone : std::uint8_t {
  hips,
  spine,
  chest,
  upper_chest,
  neck,
  head,
  left_eye,
  right_eye,
  jaw,
  left_upper_leg,
  left_lower_leg,
  left_foot,
  left_toes,
  right_upper_leg,
  right_lower_leg,
  right_foot,
  right_toes,
  left_shoulder,
  left_upper_arm,
  left_lower_arm,
  left_hand,
  right_shoulder,
  right_upper_arm,
  right_lower_arm,
  right_hand,
  left_thumb_metacarpal,
  left_thumb_proximal,
  left_thumb_distal,
  left_index_proximal,
  left_index_intermediate,
  left_index_distal,
  left_middle_proximal,
  left_middle_intermediate,
  left_middle_distal,
  left_ring_proximal,
  left_ring_intermediate,
  left_ring_distal,
  left_little_proximal,
  left_little_intermediate,
  left_little_distal,
  right_thumb_metacarpal,
  right_thumb_proximal,
  right_thumb_distal,
  right_index_proximal,
  right_index_intermediate,
  right_index_distal,
  right_middle_proximal,
  right_middle_intermediate,
  right_middle_distal,
  right_ring_proximal,
  right_ring_intermediate,
  right_ring_distal,
  right_little_proximal,
  right_little_intermediate,
  right_little_distal,
};

inline constexpr int k_bone_count = 55;
inline constexpr int k_no_parent = -1;

constexpr int idx(bone b) { return static_cast<int>(b); }

namespace detail {
inline constexpr std::array<std::string_view, k_bone_count> k_bone_names = {
    "hips",
    "spine",
    "chest",
    "upperChest",
    "neck",
    "head",
    "leftEye",
    "rightEye",
    "jaw",
    "leftUpperLeg",
    "leftLowerLeg",
    "leftFoot",
    "leftToes",
    "rightUpperLeg",
    "rightLowerLeg",
    "rightFoot",
    "rightToes",
    "leftShoulder",
    "leftUpperArm",
    "leftLowerArm",
    "leftHand",
    "rightShoulder",
    "rightUpperArm",
    "rightLowerArm",
    "rightHand",
    "leftThumbMetacarpal",
    "leftThumbProximal",
    "leftThumbDistal",
    "leftIndexProximal",
    "leftIndexIntermediate",
    "leftIndexDistal",
    "leftMiddleProximal",
    "leftMiddleIntermediate",
    "leftMiddleDistal",
    "leftRingProximal",
    "leftRingIntermediate",
    "leftRingDistal",
    "leftLittleProximal",
    "leftLittleIntermediate",
    "leftLittleDistal",
    "rightThumbMetacarpal",
    "rightThumbProximal",
    "rightThumbDistal",
    "rightIndexProximal",
    "rightIndexIntermediate",
    "rightIndexDistal",
    "rightMiddleProximal",
    "rightMiddleIntermediate",
    "rightMiddleDistal",
    "rightRingProximal",
    "rightRingIntermediate",
    "rightRingDistal",
    "rightLittleProximal",
    "rightLittleIntermediate",
    "rightLittleDistal"};

constexpr std::array<std::int8_t, k_bone_count> make_parents() {
  std::array<std::int8_t, k_bone_count> p{};
  using b = bone;
  auto set = [&p](bone child, bone parent) {
    p[idx(child)] = static_cast<std::int8_t>(idx(parent));
  };
  p[idx(b::hips)] = k_no_parent;
  set(b::spine, b::hips);
  set(b::chest, b::spine);
  set(b::upper_chest, b::chest);
  set(b::neck, b::upper_chest);
  set(b::head, b::neck);
  set(b::left_eye, b::head);
  set(b::right_eye, b::head);
  set(b::jaw, b::head);
  set(b::left_upper_leg, b::hips);
  set(b::left_lower_leg, b::left_upper_leg);
  set(b::left_foot, b::left_lower_leg);
  set(b::left_toes, b::left_foot);
  set(b::right_upper_leg, b::hips);
  set(b::right_lower_leg, b::right_upper_leg);
  set(b::right_foot, b::right_lower_leg);
  set(b::right_toes, b::right_foot);
  set(b::left_shoulder, b::upper_chest);
  set(b::left_upper_arm, b::left_shoulder);
  set(b::left_lower_arm, b::left_upper_arm);
  set(b::left_hand, b::left_lower_arm);
  set(b::right_shoulder, b::upper_chest);
  set(b::right_upper_arm, b::right_shoulder);
  set(b::right_lower_arm, b::right_upper_arm);
  set(b::right_hand, b::right_lower_arm);
  for (int side = 0; side < 2; ++side) {
    int hand = side == 0 ? idx(b::left_hand) : idx(b::right_hand);
    int first = side == 0 ? idx(b::left_thumb_metacarpal) : idx(b::right_thumb_metacarpal);
    for (int finger = 0; finger < 5; ++finger) {
      int base = first + 3 * finger;
      p[base] = static_cast<std::int8_t>(hand);
      p[base + 1] = static_cast<std::int8_t>(base);
      p[base + 2] = static_cast<std::int8_t>(base + 1);
    }
  }
  return p;
}
}  // namespace detail

inline constexpr std::array<std::int8_t, k_bone_count> k_bone_parents = detail::make_parents();

/// VRM 1.0 name ("hips", "leftUpperArm", ...).
constexpr std::string_view bone_name(bone b) { return detail::k_bone_names[idx(b)]; }

/// Parent bone index, or k_no_parent for hips.
constexpr int bone_parent(int b) { return k_bone_parents[b]; }

/// Bone from its VRM 1.0 name (exact, case-sensitive); nullopt if unknown.
inline std::optional<bone> bone_from_name(std::string_view name) {
  for (int i = 0; i < k_bone_count; ++i)
    if (detail::k_bone_names[i] == name) return static_cast<bone>(i);
  return std::nullopt;
}

/// True for bones of the person's left side.
constexpr bool is_left(bone b) { return bone_name(b).substr(0, 4) == "left"; }
/// True for bones of the person's right side.
constexpr bool is_right(bone b) { return bone_name(b).substr(0, 5) == "right"; }

/// The same bone on the other side (hips -> hips, leftHand -> rightHand, ...).
constexpr bone mirror_bone(bone b) {
  int i = idx(b);
  if (i >= idx(bone::left_upper_leg) && i <= idx(bone::left_toes)) return static_cast<bone>(i + 4);
  if (i >= idx(bone::right_upper_leg) && i <= idx(bone::right_toes))
    return static_cast<bone>(i - 4);
  if (i >= idx(bone::left_shoulder) && i <= idx(bone::left_hand)) return static_cast<bone>(i + 4);
  if (i >= idx(bone::right_shoulder) && i <= idx(bone::right_hand)) return static_cast<bone>(i - 4);
  if (i >= idx(bone::left_thumb_metacarpal) && i <= idx(bone::left_little_distal))
    return static_cast<bone>(i + 15);
  if (i >= idx(bone::right_thumb_metacarpal)) return static_cast<bone>(i - 15);
  if (b == bone::left_eye) return bone::right_eye;
  if (b == bone::right_eye) return bone::left_eye;
  return b;
}

/// Unit direction, in VRM space at rest (T-pose), from the bone's joint toward its child's
/// joint (docs/conventions.md, "The proxy skeleton"). Eyes and jaw point forward (+Z).
inline glm::vec3 bone_rest_direction(bone b) {
  constexpr float k_r2 = 0.70710678f;
  constexpr float k_r5a = 0.44721360f, k_r5b = 0.89442719f;  // (0, -1, 2) / sqrt(5)
  int i = idx(b);
  float side = is_right(b) ? -1.f : 1.f;
  if (i <= idx(bone::head)) return {0.f, 1.f, 0.f};
  if (b == bone::left_eye || b == bone::right_eye || b == bone::jaw) return {0.f, 0.f, 1.f};
  if (b == bone::left_upper_leg || b == bone::left_lower_leg || b == bone::right_upper_leg ||
      b == bone::right_lower_leg)
    return {0.f, -1.f, 0.f};
  if (b == bone::left_foot || b == bone::left_toes || b == bone::right_foot ||
      b == bone::right_toes)
    return {0.f, -k_r5a, k_r5b};
  if (b == bone::left_thumb_metacarpal || b == bone::left_thumb_proximal ||
      b == bone::left_thumb_distal || b == bone::right_thumb_metacarpal ||
      b == bone::right_thumb_proximal || b == bone::right_thumb_distal)
    return {side * k_r2, 0.f, k_r2};
  return {side, 0.f, 0.f};  // shoulders, arms, hands, fingers
}

}  // namespace avatarmap
