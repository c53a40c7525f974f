// VRM Animation (.vrma) files: reading them into proxy poses and writing proxy poses as one.
// Format, conventions and limits: docs/export.md. A .vrma is a GLB whose root extension
// VRMC_vrm_animation (specVersion "1.0") maps glTF nodes to VRM 1.0 humanoid bones (every
// bone but leftEye/rightEye), expressions (presets other than lookUp/Down/Left/Right, and
// custom names) and the lookAt target; the motion is the file's first glTF animation; the
// rest pose is the VRM T-pose; an expression's weight is the x translation of its node.
// avatarmap writes its proxy expressions (VRM presets, the emotions happy/angry/sad/relaxed/
// surprised included, and four custom brows), ARKit's 52 blendshapes as custom expressions
// named by ARKit ("eyeBlinkLeft", "jawOpen", ...) and gaze as lookAt.
#pragma once

#include <array>
#include <string>
#include <vector>

#include "avatarmap/core/status.hpp"
#include "avatarmap/skeleton/blendshape.hpp"
#include "avatarmap/skeleton/bone.hpp"
#include "avatarmap/skeleton/expression.hpp"
#include "avatarmap/skeleton/proxy_pose.hpp"
#include "avatarmap/skeleton/proxy_skeleton.hpp"

namespace avatarmap {

/// True for the bones a .vrma may animate: every bone but leftEye and rightEye (the spec
/// leaves the eyes to lookAt).
constexpr bool is_vrma_bone(bone b) { return b != bone::left_eye && b != bone::right_eye; }

/// True for the expressions a .vrma may carry: every proxy expression but lookUp, lookDown,
/// lookLeft and lookRight (the spec leaves gaze to lookAt). browUp/Down* are written as
/// custom expressions, the others (happy, angry, sad, relaxed, surprised included) as presets.
constexpr bool is_vrma_expression(expression e) {
  return e != expression::look_up && e != expression::look_down && e != expression::look_left &&
         e != expression::look_right;
}

struct vrma_read_options {
  /// 0: one frame at every key time of the first animation (the sorted union of all its
  /// channels' times). > 0: frames at t_first + k / fps up to the last key time (seconds).
  double fps = 0.0;
  /// 0: hips_position is the hips joint's model-space position as animated, in metres (the
  /// spec puts the feet on Y = 0, so Y is the hips height above the floor). > 0: the
  /// position is scaled by hips_height / rest_hips_height (the spec's translation scaling
  /// between skeletons of different sizes), e.g. standing_hips_height() of the skeleton that
  /// will play the poses. Ignored when the clip's rest hips height is not positive.
  float hips_height = 0.f;
};

/// A clip read from a .vrma.
struct vrma_clip {
  /// Poses in VRM 1.0 normalised space, in time order, pose.t in seconds from the file's
  /// time origin. Bones the file does not map are identity with confidence 0; mapped bones
  /// have confidence 1. Expressions and blendshapes the file does not carry are 0; carried
  /// ones are clamped to [0, 1] as the spec requires. A custom expression named browDownLeft
  /// or browDownRight (avatarmap's brow and ARKit's shape share the name) sets both the
  /// expression and the blendshape. With a lookAt, leftEye and rightEye both get the gaze
  /// rotation (confidence 1).
  std::vector<proxy_pose> frames;
  /// Last key time of the first animation (seconds; glTF animations start at 0).
  double duration = 0.0;
  /// Which humanoid bones the file maps to a node.
  std::array<bool, k_bone_count> has_bone{};
  /// Which proxy expressions the file carries.
  std::array<bool, k_expression_count> has_expression{};
  /// Which ARKit blendshapes the file carries (custom expressions named by ARKit).
  std::array<bool, k_blendshape_count> has_blendshape{};
  /// Whether the file has a lookAt whose gaze was read into the eye bones.
  bool has_look_at = false;
  /// Every expression name the file lists (presets, then custom), including those that are
  /// neither a proxy expression nor an ARKit name (their weights are not read).
  std::vector<std::string> expression_names;
  /// Model-space Y of the hips joint in the rest pose (metres).
  float rest_hips_height = 0.f;
  /// asset.generator ("" when absent).
  std::string generator;
};

/// Reads the .vrma at `path` into `out` (replacing its content).
///
/// Each mapped bone's normalised local rotation is computed from the whole glTF node tree
/// (non-humanoid nodes in between included, rest rotations anything): with N(b) = A(b) R(b)⁻¹
/// the bone's animated model-space rotation times the inverse of its rest one, the local
/// rotation is N(p)⁻¹ N(b) where p is the nearest mapped ancestor in the VRM humanoid
/// hierarchy (identity for hips' parent). For a plain chain this is VRM 1.0's normalised
/// rotation W·L⁻¹·q·W⁻¹ (W, L: the bone's world and local rest rotations; docs/conventions.md).
/// Node scale is applied to positions only (rotations assume uniform scale). Interpolation: LINEAR
/// (slerp on the shortest arc for rotations), STEP, CUBICSPLINE (cubic Hermite on the value and
/// tangent components, rotations normalised). Outside a channel's key range its first or last value
/// holds.
///
/// lookAt: when the lookAt node has a rotation channel, that rotation is the gaze (the rotation
/// that turns the head's forward, +Z, toward the target, in the head's frame: how three-vrm
/// reads it and how write_vrma writes it); otherwise the gaze is the shortest-arc rotation
/// from +Z to the node's model-space position as seen from the head (the spec's target).
/// Either way it becomes leftEye's and rightEye's local rotation.
///
/// Fails, with a message that names the file and the problem, when the file cannot be read or
/// is not glTF/GLB, lacks the VRMC_vrm_animation extension or its humanoid.humanBones, maps a
/// bone or expression to a missing node, has no animation, or has an accessor or sampler that
/// is malformed (wrong type, out of bounds, non-increasing or non-finite times). Never throws.
status read_vrma(const std::string& path, vrma_clip& out, const vrma_read_options& options = {});

struct vrma_write_options {
  /// 0: one key per frame at the frames' own times. > 0: keys at k / fps seconds, the frames
  /// resampled (slerp on the shortest arc for rotations, linear for hips and expressions).
  double fps = 0.0;
  /// Height (metres) of the proxy skeleton (make_proxy_skeleton) whose T-pose offsets
  /// become the nodes' rest translations; the hips node rests at standing_hips_height().
  float height = k_proxy_reference_height;
  /// Subtract the first frame's t so that the animation starts at 0 (glTF times must not be
  /// negative). When false every frame's t must be >= 0.
  bool start_at_zero = true;
  /// Write every .vrma-able expression (and, with `blendshapes`, every ARKit shape), even those
  /// that are 0 in every frame (by default an expression is written when some frame gives it a
  /// non-zero weight, so a clip without a face adds nothing).
  bool all_expressions = false;
  /// Write ARKit's 52 blendshapes as custom expressions named by ARKit ("jawOpen", ...), each
  /// when some frame gives it a non-zero weight: a "Perfect Sync" VRM 1.0 avatar has custom
  /// expressions of those names and plays them; other avatars skip names they lack. ARKit's
  /// browDownLeft/browDownRight share the name of avatarmap's custom brow expressions: with
  /// this on and the shape written, that node carries ARKit's weight.
  bool blendshapes = true;
  /// Write the gaze as VRMC_vrm_animation.lookAt when some frame turns an eye (leftEye or
  /// rightEye not identity): the two eyes' mean rotation (docs/export.md, "lookAt").
  bool look_at = true;
  /// asset.generator.
  std::string generator = "avatarmap";
};

/// Writes `frames` (held in memory by the caller; each ~1.2 kB) as a .vrma at `path`:
/// a node per bone for which is_vrma_bone() holds (names = VRM names, rest rotation
/// identity, rest translation from the proxy skeleton), a node per written expression
/// (a root node named after it), and one animation "avatarmap" with a LINEAR rotation channel
/// per bone, a LINEAR translation channel for hips (hips_position, metres, as given) and a
/// LINEAR translation channel per expression (x = weight clamped to [0, 1]), and with a gaze
/// a lookAt node (two nodes under the head; docs/export.md). Quaternions are
/// normalised and their signs made continuous from key to key. The file is written to a
/// temporary file beside `path`, then renamed over it; on failure `path` is untouched.
///
/// Non-finite rotations, positions, expression or blendshape weights are replaced by the
/// previous frame's value (the rest value for the first frame). Fails when `frames` is empty, a
/// frame's t is not finite, times do not increase strictly, (start_at_zero false) a time is
/// negative, fps or height is not positive and finite (fps may be 0), or the file cannot be
/// written. Never throws.
status write_vrma(const std::string& path, const std::vector<proxy_pose>& frames,
                  const vrma_write_options& options = {});

}  // namespace avatarmap
