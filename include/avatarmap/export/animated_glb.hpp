// The avatar itself with a motion as a glTF animation: reads the avatar file again through the
// guarded glTF path (docs/security.md; meshes, skins, materials, extensions such as VRM are
// kept as they are), gathers every buffer (the GLB's own chunk, data URIs, external files
// confined to the avatar's folder) into the one BIN chunk with textures copied byte for byte
// (never decoded: WebP, KTX2 or a 16k PNG pass through), adds one animation that drives the
// rig's joints (rotation channels for every joint whose rotation changes, the hips'
// translation) and writes a binary glTF (.glb). The written file is replaced atomically; a
// failed write leaves the previous file as it was. Non-finite pose values are refused.
#pragma once

#include <string>
#include <vector>

#include "avatarmap/core/status.hpp"
#include "avatarmap/rig/retarget.hpp"
#include "avatarmap/rig/rig.hpp"

namespace avatarmap {

struct animated_glb_options {
  std::string animation_name = "avatarmap";
  double fps = 30.0;  // frames are taken as sampled at this rate, starting at t = 0
};

/// `r` must have been built from `avatar_path` (its source_index are the file's node indices);
/// `frames` are retargeted poses of `r`. Errors name the file.
status write_animated_glb(const std::string& avatar_path, const rig& r,
                          const std::vector<rig_pose>& frames, const animated_glb_options& options,
                          const std::string& out_path);

}  // namespace avatarmap
