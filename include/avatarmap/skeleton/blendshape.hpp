// ARKit's 52 face blendshapes (Apple's ARFaceAnchor.BlendShapeLocation names and meanings), in
// Apple's alphabetical order, the order MediaPipe's face landmarker also uses (without its
// "_neutral"). Weights are in [0, 1]. "Left" is the person's own left, as in ARKit.
// docs/expressions.md defines how each is measured from the face mesh.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string_view>

namespace avatarmap {

enum class blendshape : std::uint8_t {
  brow_down_left,
  brow_down_right,
  brow_inner_up,
  brow_outer_up_left,
  brow_outer_up_right,
  cheek_puff,
  cheek_squint_left,
  cheek_squint_right,
  eye_blink_left,
  eye_blink_right,
  eye_look_down_left,
  eye_look_down_right,
  eye_look_in_left,
  eye_look_in_right,
  eye_look_out_left,
  eye_look_out_right,
  eye_look_up_left,
  eye_look_up_right,
  eye_squint_left,
  eye_squint_right,
  eye_wide_left,
  eye_wide_right,
  jaw_forward,
  jaw_left,
  jaw_open,
  jaw_right,
  mouth_close,
  mouth_dimple_left,
  mouth_dimple_right,
  mouth_frown_left,
  mouth_frown_right,
  mouth_funnel,
  mouth_left,
  mouth_lower_down_left,
  mouth_lower_down_right,
  mouth_press_left,
  mouth_press_right,
  mouth_pucker,
  mouth_right,
  mouth_roll_lower,
  mouth_roll_upper,
  mouth_shrug_lower,
  mouth_shrug_upper,
  mouth_smile_left,
  mouth_smile_right,
  mouth_stretch_left,
  mouth_stretch_right,
  mouth_upper_up_left,
  mouth_upper_up_right,
  nose_sneer_left,
  nose_sneer_right,
  tongue_out,
};

inline constexpr int k_blendshape_count = 52;

namespace detail {
inline constexpr std::array<std::string_view, k_blendshape_count> k_blendshape_names = {
    "browDownLeft",      "browDownRight",      "browInnerUp",         "browOuterUpLeft",
    "browOuterUpRight",  "cheekPuff",          "cheekSquintLeft",     "cheekSquintRight",
    "eyeBlinkLeft",      "eyeBlinkRight",      "eyeLookDownLeft",     "eyeLookDownRight",
    "eyeLookInLeft",     "eyeLookInRight",     "eyeLookOutLeft",      "eyeLookOutRight",
    "eyeLookUpLeft",     "eyeLookUpRight",     "eyeSquintLeft",       "eyeSquintRight",
    "eyeWideLeft",       "eyeWideRight",       "jawForward",          "jawLeft",
    "jawOpen",           "jawRight",           "mouthClose",          "mouthDimpleLeft",
    "mouthDimpleRight",  "mouthFrownLeft",     "mouthFrownRight",     "mouthFunnel",
    "mouthLeft",         "mouthLowerDownLeft", "mouthLowerDownRight", "mouthPressLeft",
    "mouthPressRight",   "mouthPucker",        "mouthRight",          "mouthRollLower",
    "mouthRollUpper",    "mouthShrugLower",    "mouthShrugUpper",     "mouthSmileLeft",
    "mouthSmileRight",   "mouthStretchLeft",   "mouthStretchRight",   "mouthUpperUpLeft",
    "mouthUpperUpRight", "noseSneerLeft",      "noseSneerRight",      "tongueOut"};
}

constexpr int idx(blendshape s) { return static_cast<int>(s); }

/// ARKit's name, as written in *.pose.jsonl and sent over VMC ("eyeBlinkLeft", "jawOpen", ...).
constexpr std::string_view blendshape_name(blendshape s) {
  return detail::k_blendshape_names[idx(s)];
}

inline std::optional<blendshape> blendshape_from_name(std::string_view name) {
  for (int i = 0; i < k_blendshape_count; ++i)
    if (detail::k_blendshape_names[i] == name) return static_cast<blendshape>(i);
  return std::nullopt;
}

}  // namespace avatarmap
