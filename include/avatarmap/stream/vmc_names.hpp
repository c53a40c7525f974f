// The names the VMC protocol speaks (docs/vmc.md, "Names"): bones by Unity's HumanBodyBones
// names, expressions by VRM 0.x blend shape preset names. Tables in the proxy's orders
// (skeleton/bone.hpp, skeleton/expression.hpp).
#pragma once

#include <array>
#include <string_view>

#include "avatarmap/skeleton/bone.hpp"
#include "avatarmap/skeleton/expression.hpp"

namespace avatarmap {

namespace detail {
// Unity's thumb is Proximal/Intermediate/Distal where VRM 1.0 says Metacarpal/Proximal/Distal
// (the same three joints, as VRM 0.x names them).
inline constexpr std::array<std::string_view, k_bone_count> k_unity_bone_names = {
    "Hips",
    "Spine",
    "Chest",
    "UpperChest",
    "Neck",
    "Head",
    "LeftEye",
    "RightEye",
    "Jaw",
    "LeftUpperLeg",
    "LeftLowerLeg",
    "LeftFoot",
    "LeftToes",
    "RightUpperLeg",
    "RightLowerLeg",
    "RightFoot",
    "RightToes",
    "LeftShoulder",
    "LeftUpperArm",
    "LeftLowerArm",
    "LeftHand",
    "RightShoulder",
    "RightUpperArm",
    "RightLowerArm",
    "RightHand",
    "LeftThumbProximal",
    "LeftThumbIntermediate",
    "LeftThumbDistal",
    "LeftIndexProximal",
    "LeftIndexIntermediate",
    "LeftIndexDistal",
    "LeftMiddleProximal",
    "LeftMiddleIntermediate",
    "LeftMiddleDistal",
    "LeftRingProximal",
    "LeftRingIntermediate",
    "LeftRingDistal",
    "LeftLittleProximal",
    "LeftLittleIntermediate",
    "LeftLittleDistal",
    "RightThumbProximal",
    "RightThumbIntermediate",
    "RightThumbDistal",
    "RightIndexProximal",
    "RightIndexIntermediate",
    "RightIndexDistal",
    "RightMiddleProximal",
    "RightMiddleIntermediate",
    "RightMiddleDistal",
    "RightRingProximal",
    "RightRingIntermediate",
    "RightRingDistal",
    "RightLittleProximal",
    "RightLittleIntermediate",
    "RightLittleDistal"};

// VRM 0.x presets for the proxy's expressions; "" where VRM 0.x has none (the custom brows,
// surprised). VRM 1.0's happy, angry, sad and relaxed were VRM 0.x's Joy, Angry, Sorrow, Fun.
inline constexpr std::array<std::string_view, k_expression_count> k_vrm0_blend_names = {
    "Blink", "Blink_L", "Blink_R",  "A",        "I",         "U",   "E",
    "O",     "LookUp",  "LookDown", "LookLeft", "LookRight", "",    "",
    "",      "",        "Joy",      "Angry",    "Sorrow",    "Fun", ""};
}  // namespace detail

/// Unity HumanBodyBones name of a proxy bone ("Hips", "LeftThumbProximal", ...).
constexpr std::string_view unity_bone_name(bone b) { return detail::k_unity_bone_names[idx(b)]; }

/// VRM 0.x blend shape preset name of an expression ("A", "Blink_L", ...), or "" when VRM 0.x
/// has no preset for it (browUpLeft, browUpRight, browDownLeft, browDownRight, surprised).
constexpr std::string_view vrm0_blend_name(expression e) {
  return detail::k_vrm0_blend_names[idx(e)];
}

}  // namespace avatarmap
