// The avatar itself with a motion as a glTF animation: reads the avatar file again through the
// guarded glTF path (docs/security.md; meshes, skins, materials, extensions such as VRM are
// kept as they are), gathers every buffer (the GLB's own chunk, data URIs, external files
// confined to the avatar's folder) into the one BIN chunk with textures copied byte for byte
// (never decoded: WebP, KTX2 or a 16k PNG pass through), adds one animation that drives the
// rig's joints (rotation channels for every joint whose rotation changes, the hips'
// translation; and, given the frames' expressions, morph-target weight channels for the face)
// and writes a binary glTF (.glb). The written file is replaced atomically; a failed write
// leaves the previous file as it was. Non-finite pose values are refused.
//
// The face (docs/export.md, "The face"): the proxy pose's expressions (skeleton/expression.hpp)
// and ARKit blendshapes (skeleton/blendshape.hpp) drive the avatar's morph targets through the
// avatar's own definitions, the first of these the file has: VRM 1.0 `VRMC_vrm.expressions`
// (preset and custom; morphTargetBinds {node, index, weight}), VRM 0.x
// `VRM.blendShapeMaster.blendShapeGroups` (presetName a/i/u/e/o, blink, blink_l/r,
// lookup/down/left/right, joy/angry/sorrow/fun = happy/angry/sad/relaxed, else name; binds
// {mesh, index, weight 0-100}), else morph targets named after an expression (targetNames, any
// case, weight 1). A definition named after an ARKit shape (Perfect Sync: "eyeBlinkLeft",
// "EyeBlinkLeft", any case) is driven by that blendshape; so is, in any file, a morph target
// named after an ARKit shape (mesh.extras.targetNames or the first primitive's, any case,
// prefixes "anything." and "ARKit_" allowed) when no definition claims that shape. A value v
// (clamped to [0, 1]; isBinary: v > 0.5 ? 1 : 0) adds v x weight to its bound targets, over
// the node's default weights (node.weights, else mesh.weights, else 0), clamped to [0, 1]; one
// "weights" channel (LINEAR) per node that a bind reaches.
//
// Precedence: when the avatar has ARKit binds and some frame carries a non-zero blendshape, a
// morph target that an ARKit bind reaches is driven by the blendshapes only (expression binds
// onto it are dropped: never driven twice); expression binds onto other targets still apply.
// Otherwise (poses without blendshapes) the expressions drive every bind. Names the proxy does
// not carry (a custom "smirk"), binds to a node without that morph target, material and
// texture binds and the override* flags are ignored; an avatar without any is written with
// joints only, as without expressions.
#pragma once

#include <string>
#include <vector>

#include "avatarmap/core/status.hpp"
#include "avatarmap/rig/retarget.hpp"
#include "avatarmap/rig/rig.hpp"
#include "avatarmap/skeleton/proxy_pose.hpp"

namespace avatarmap {

struct animated_glb_options {
  std::string animation_name = "avatarmap";
  double fps = 30.0;  // frames are taken as sampled at this rate, starting at t = 0
  /// The face: one proxy pose per frame (the frames' order and count) whose expressions and
  /// blendshapes drive the avatar's morph targets (see above); null: joints only.
  const std::vector<proxy_pose>* expressions = nullptr;
};

/// `r` must have been built from `avatar_path` (its source_index are the file's node indices);
/// `frames` are retargeted poses of `r`. Errors name the file.
status write_animated_glb(const std::string& avatar_path, const rig& r,
                          const std::vector<rig_pose>& frames, const animated_glb_options& options,
                          const std::string& out_path);

}  // namespace avatarmap
