// One frame of the VMC protocol (docs/vmc.md): a proxy pose as one OSC bundle, in this order
//   /VMC/Ext/Root/Pos  s "root", f px py pz, f qx qy qz qw   (the model's root: origin, identity)
//   /VMC/Ext/Bone/Pos  s NAME, f px py pz, f qx qy qz qw     per sent bone, parents first
//   /VMC/Ext/Blend/Val s NAME, f weight                      per expression with a VRM 0.x preset
//   /VMC/Ext/Blend/Apply
//   /VMC/Ext/OK        i 1                                   (a model is loaded)
//   /VMC/Ext/T         f time                                (seconds)
// Bone names are Unity's HumanBodyBones (stream/vmc_names.hpp); positions and rotations are
// local (relative to the nearest sent ancestor bone) and in Unity space (stream/unity_space.hpp).
// A bone's position is its rest offset (stream/vmc_skeleton.hpp); the hips' is the pose's hips
// position mapped onto the model. Rotations are the proxy's normalised local rotations, composed
// over bones that are not sent, so a receiver's normalised model (every VRM 0.x model, UniVRM's
// VRM 1.0 control rig) takes them as they are. Blend weights are clamped to [0, 1].
#pragma once

#include <cstddef>

#include "avatarmap/skeleton/proxy_pose.hpp"
#include "avatarmap/stream/osc_writer.hpp"
#include "avatarmap/stream/vmc_skeleton.hpp"

namespace avatarmap {

/// Bytes that always hold a bundle of write_vmc_bundle (every bone and expression; ~5.5 KB).
inline constexpr std::size_t k_vmc_bundle_capacity = 8192;

/// Expressions that have a VRM 0.x preset name, hence a /VMC/Ext/Blend/Val message each.
int vmc_blend_count();

/// Clears `out` and writes the bundle of `pose` for `skeleton`, stamped `time` (seconds). No
/// allocation. Returns out.complete(): false only when out's buffer is smaller than the bundle
/// (k_vmc_bundle_capacity always suffices).
bool write_vmc_bundle(const vmc_skeleton& skeleton, const proxy_pose& pose, float time,
                      osc_writer& out);

}  // namespace avatarmap
