// One frame of the VMC protocol (docs/vmc.md): a proxy pose as one OSC bundle, in this order
//   /VMC/Ext/Root/Pos  s "root", f px py pz, f qx qy qz qw   (the model's root: origin, identity)
//   /VMC/Ext/Bone/Pos  s NAME, f px py pz, f qx qy qz qw     per sent bone, parents first
//   /VMC/Ext/Blend/Val s NAME, f weight                      per blend value of the blend set
//   /VMC/Ext/Blend/Apply
//   /VMC/Ext/OK        i 1                                   (a model is loaded)
//   /VMC/Ext/T         f time                                (seconds)
// Bone names are Unity's HumanBodyBones (stream/vmc_names.hpp); positions and rotations are
// local (relative to the nearest sent ancestor bone) and in Unity space (stream/unity_space.hpp).
// A bone's position is its rest offset (stream/vmc_skeleton.hpp); the hips' is the pose's hips
// position mapped onto the model. Rotations are the proxy's normalised local rotations, composed
// over bones that are not sent, so a receiver's normalised model (every VRM 0.x model, UniVRM's
// VRM 1.0 control rig) takes them as they are. Blend values (vmc_blend_set): the expressions
// that have a VRM 0.x preset name (A ... LookRight, Joy, Angry, Sorrow, Fun), and/or ARKit's 52
// blendshapes by Apple's names ("eyeBlinkLeft": the clip names of Perfect Sync avatars); weights
// clamped to [0, 1], NaN sent as 0.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string_view>

#include "avatarmap/skeleton/proxy_pose.hpp"
#include "avatarmap/stream/osc_writer.hpp"
#include "avatarmap/stream/vmc_skeleton.hpp"

namespace avatarmap {

/// Bytes that always hold a bundle of write_vmc_bundle (every bone, the VRM 0.x presets and
/// ARKit's 52: 7,720 bytes with the 55 bones).
inline constexpr std::size_t k_vmc_bundle_capacity = 12288;

/// Which blend values a bundle carries (docs/vmc.md, "Names").
enum class vmc_blend_set : std::uint8_t {
  vrm0,   // the VRM 0.x presets of the expressions (16): every VRM model has these clips
  arkit,  // ARKit's 52 by Apple's names: Perfect Sync avatars' clips
  both,   // the VRM 0.x presets, then ARKit's 52
};

/// The set's name as the CLI writes it ("vrm0", "arkit", "both"), and back (nullopt: unknown).
std::string_view vmc_blend_set_name(vmc_blend_set set);
std::optional<vmc_blend_set> vmc_blend_set_from_name(std::string_view name);

/// /VMC/Ext/Blend/Val messages in each bundle of `set`: 16 (vrm0), 52 (arkit), 68 (both).
int vmc_blend_count(vmc_blend_set set = vmc_blend_set::vrm0);

/// Clears `out` and writes the bundle of `pose` for `skeleton`, stamped `time` (seconds), with
/// the blend values of `blends`. No allocation. Returns out.complete(): false only when out's
/// buffer is smaller than the bundle (k_vmc_bundle_capacity always suffices).
bool write_vmc_bundle(const vmc_skeleton& skeleton, const proxy_pose& pose, float time,
                      osc_writer& out, vmc_blend_set blends = vmc_blend_set::vrm0);

}  // namespace avatarmap
