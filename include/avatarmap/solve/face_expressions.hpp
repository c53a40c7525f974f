// ARKit's 52 blendshapes -> the proxy's 21 expressions (VRM presets plus the custom brows), and
// the eyeLook* shapes of an eye's turn. These are definitions, not measurements: the solver
// derives its expressions from the blendshapes it measured with them, and the synthetic
// generator derives its truth expressions from the blendshapes it drew with them, so that a
// preset's error is the error of the blendshapes it comes from. docs/expressions.md writes
// every formula out. Nothing here allocates.
#pragma once

#include <array>

#include "avatarmap/skeleton/blendshape.hpp"
#include "avatarmap/skeleton/expression.hpp"

namespace avatarmap {

using blendshape_weights = std::array<float, k_blendshape_count>;
using expression_weights = std::array<float, k_expression_count>;

/// Gaze turn at which an eyeLook* shape (and VRM's lookLeft/Right, lookUp/Down) reaches 1:
/// 25 degrees sideways, 20 degrees up or down (VRM's lookAt presets mean "looking fully"
/// that way; the angles are the project's choice). As sines.
/// The blendshapes the solver measures from the mesh's shape (docs/expressions.md, each
/// one's measurement); the eight eyeLook ones come from the irises; the others stay 0.
inline constexpr blendshape k_mesh_blendshapes[] = {blendshape::brow_down_left,
                                                    blendshape::brow_down_right,
                                                    blendshape::brow_inner_up,
                                                    blendshape::brow_outer_up_left,
                                                    blendshape::brow_outer_up_right,
                                                    blendshape::cheek_squint_left,
                                                    blendshape::cheek_squint_right,
                                                    blendshape::eye_blink_left,
                                                    blendshape::eye_blink_right,
                                                    blendshape::eye_wide_left,
                                                    blendshape::eye_wide_right,
                                                    blendshape::jaw_open,
                                                    blendshape::mouth_frown_left,
                                                    blendshape::mouth_frown_right,
                                                    blendshape::mouth_funnel,
                                                    blendshape::mouth_left,
                                                    blendshape::mouth_pucker,
                                                    blendshape::mouth_right,
                                                    blendshape::mouth_smile_left,
                                                    blendshape::mouth_smile_right,
                                                    blendshape::mouth_stretch_left,
                                                    blendshape::mouth_stretch_right,
                                                    blendshape::jaw_left,
                                                    blendshape::jaw_right,
                                                    blendshape::mouth_roll_lower,
                                                    blendshape::mouth_roll_upper,
                                                    blendshape::mouth_close,
                                                    blendshape::mouth_upper_up_left,
                                                    blendshape::mouth_upper_up_right,
                                                    blendshape::mouth_lower_down_left,
                                                    blendshape::mouth_lower_down_right,
                                                    blendshape::nose_sneer_left,
                                                    blendshape::nose_sneer_right};

inline constexpr float k_eye_look_full_side_sin = 0.42261826f;  // sin 25 deg
inline constexpr float k_eye_look_full_vert_sin = 0.34202014f;  // sin 20 deg

/// Writes the eyeLook{Up,Down,In,Out} shapes of one eye: `person_left` for the person's left
/// eye; `sin_yaw` the sine of the eye's turn toward the person's left (VRM +X), `sin_pitch`
/// the sine of its turn up. The left eye turning toward the person's left looks out, the right
/// eye in. Non-finite input writes 0.
void eye_look_blendshapes(bool person_left, float sin_yaw, float sin_pitch,
                          blendshape_weights& out);

/// The 21 expressions from the 52 blendshapes (inputs clamped to [0, 1], non-finite read as
/// 0; every output in [0, 1]):
/// - blink = min(eyeBlinkLeft, eyeBlinkRight); blinkLeft/Right = that eye's blink - blink.
/// - visemes from o = jawOpen - mouthClose (lips kept together show no viseme),
///   r = max(mouthFunnel, mouthPucker), w = max(mean mouthStretch, mean mouthSmile): aa = o (1 -
///   r)(1 - w), ee = w (1 - r)(1 - o), ih = w (1 - r) o, oh = r o, ou = r (1 - o). Their sum is at
///   most 1.
/// - lookLeft = mean(eyeLookOutLeft, eyeLookInRight), lookRight = mean(eyeLookInLeft,
///   eyeLookOutRight), lookUp/Down = the mean of both eyes' eyeLookUp/Down.
/// - browUpLeft/Right = max(browInnerUp, browOuterUpLeft/Right), browDownLeft/Right =
///   browDownLeft/Right.
/// - emotions, with smile = mean mouthSmile, frown = mean mouthFrown, cheek = mean
///   cheekSquint, down = mean browDown, wide = mean eyeWide, up = max(browInnerUp, mean
///   browOuterUp): happy = smile (0.6 + 0.4 cheek), relaxed = 0.6 smile (1 - cheek)(1 - o),
///   angry = down (1 - smile), sad = frown (0.6 + 0.4 browInnerUp)(1 - smile),
///   surprised = up max(wide, o).
void expressions_from_blendshapes(const blendshape_weights& b, expression_weights& out);

/// The same shapes seen in a mirror: every Left/Right pair swapped (eyeBlinkLeft <->
/// eyeBlinkRight, eyeLookInLeft <-> eyeLookInRight, mouthLeft <-> mouthRight, jawLeft <->
/// jawRight, ...); the unpaired shapes kept.
void mirror_blendshapes(blendshape_weights& b);

}  // namespace avatarmap
