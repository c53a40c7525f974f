// Biovision Hierarchy (.bvh): writing proxy poses on the proxy skeleton or retargeted poses
// on an avatar's own rig, and a minimal
// reader (hierarchy + motion values) for round trips and for checking third-party clips.
// Conventions: docs/export.md.
#pragma once

#include <cstdint>
#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>
#include <string>
#include <vector>

#include "avatarmap/core/status.hpp"
#include "avatarmap/rig/retarget.hpp"
#include "avatarmap/rig/rig.hpp"
#include "avatarmap/skeleton/proxy_pose.hpp"
#include "avatarmap/skeleton/proxy_skeleton.hpp"

namespace avatarmap {

enum class bvh_units : std::uint8_t { centimetres, metres };

struct bvh_write_options {
  /// 0: one BVH frame per given frame, Frame Time = the mean spacing of the frames' times
  /// (1/30 s for a single frame; BVH has no per-frame times, so unevenly spaced frames play
  /// at the mean rate). > 0: frames resampled at t_first + k / fps (slerp on the shortest arc,
  /// linear for the hips), Frame Time = 1 / fps.
  double fps = 0.0;
  /// Length unit of OFFSETs and root positions. Centimetres by default, like most BVH tools
  /// (Blender, MotionBuilder, the CMU clips).
  bvh_units units = bvh_units::centimetres;
  /// Height (metres) of the proxy skeleton (make_proxy_skeleton) whose T-pose offsets
  /// become the joints' OFFSETs.
  float height = k_proxy_reference_height;
};

/// Writes `frames` (held in memory by the caller) as a BVH file at `path`.
///
/// HIERARCHY: all 55 proxy bones, VRM names, in proxy order (parents first, depth-first);
/// ROOT hips with OFFSET 0 0 0 and channels Xposition Yposition Zposition Zrotation
/// Xrotation Yrotation; every other joint has Zrotation Xrotation Yrotation. OFFSETs are the
/// proxy skeleton's T-pose offsets (VRM axes: Y up, facing +Z, avatar's left +X); leaf
/// bones get an End Site at their tip (length * rest direction). MOTION: root position =
/// hips_position (world, in `units`; rest pose T-pose, so no rest rotation is needed), angles
/// in degrees such that the joint's local rotation is Rz(z) * Rx(x) * Ry(y) (column vectors;
/// = euler_order::zxy), printed with 6 decimals (|error| < 1e-5 degrees per angle).
/// The file is written to a temporary file beside `path`, then renamed over it.
///
/// Non-finite values are replaced by the previous frame's (the rest pose's for the first).
/// Fails when `frames` is empty, a frame's t is not finite or times do not increase strictly,
/// fps is negative or not finite, height is not positive, or the file cannot be written.
status write_bvh(const std::string& path, const std::vector<proxy_pose>& frames,
                 const bvh_write_options& options = {});

struct rig_bvh_options {
  /// Frames are taken as sampled at this rate from t = 0 (Frame Time = 1 / fps); > 0.
  double fps = 30.0;
  /// Length unit of OFFSETs and root positions (the rig's world units are taken as metres,
  /// as glTF's are: a centimetre rig under a 0.01 scale node is metres in world space).
  bvh_units units = bvh_units::centimetres;
};

/// Writes retargeted poses of `r` (rig_pose, as retargeter::apply makes them) as a BVH file at
/// `path`, with the rig's own joints, names and proportions.
///
/// HIERARCHY: the subtree of the hips joint (frames[0].hips_joint), rig order (parents
/// first). Joints that are not the hips or below it (the armature root, meshes, a Mixamo
/// scale node) are dropped; their transforms are folded into the root: ROOT = the hips with
/// OFFSET 0 0 0 (as write_bvh: readers that add the root OFFSET to the position channels and
/// readers that do not then agree) and position channels = its posed world position.
/// BVH cannot store rest rotations, so the written rest pose has every joint frame aligned
/// with the world axes: a joint's OFFSET is its world rest position minus its parent's
/// (world axes, every ancestor's scale applied, in `units`), and its channels carry
///   R_bvh = D_parent⁻¹ · D_joint,  D = rotation of W_posed · W_rest⁻¹
/// (D: the joint's world rotation away from rest; the root's R_bvh is its D). Then the BVH's
/// forward kinematics reproduces every joint's world position exactly (up to printing); the
/// bones' own axes and rest rotations are lost, as in any BVH. Names: whitespace becomes '_',
/// an empty name "joint<i>", a repeated name gets "_<i>" appended (i = rig joint index).
/// Channels: ROOT Xposition Yposition Zposition Zrotation Xrotation Yrotation, JOINTs
/// Zrotation Xrotation Yrotation (R = Rz · Rx · Ry, euler_order::zxy), degrees with 6
/// decimals. Leaves get an End Site continuing their bone: half their OFFSET (a zero-length
/// leaf gets a zero End Site). World axes are the rig's (glTF: Y up).
///
/// Exact for rigs whose scales are uniform (any value, e.g. 0.01); a non-uniform scale on a
/// moving joint's ancestors makes D non-orthogonal and its rotation part is used. Non-finite
/// rotations or hips translation are replaced by the previous frame's (rest for the first).
/// The file is written to a temporary file beside `path`, then renamed over it.
/// Fails when `frames` is empty, a frame's hips_joint is out of range or differs from the
/// first's, a frame's local_rotations do not hold one rotation per joint, fps is not positive
/// and finite, or the file cannot be written. Never throws.
status write_rig_bvh(const std::string& path, const rig& r, const std::vector<rig_pose>& frames,
                     const rig_bvh_options& options = {});

enum class bvh_channel : std::uint8_t {
  x_position,
  y_position,
  z_position,
  x_rotation,
  y_rotation,
  z_rotation
};

struct bvh_joint {
  std::string name;
  int parent = -1;  // index into bvh_clip::joints; -1 for a root
  glm::vec3 offset{0.f};
  std::vector<bvh_channel> channels;
  int first_channel = 0;  // index of channels[0] in a frame's values
  bool has_end_site = false;
  glm::vec3 end_site{0.f};  // End Site OFFSET when has_end_site
};

/// A BVH file as written: joints in file order (parents first), values in file units.
struct bvh_clip {
  std::vector<bvh_joint> joints;
  int channel_count = 0;  // values per frame
  int frame_count = 0;
  double frame_time = 0.0;    // seconds
  std::vector<float> values;  // frame_count * channel_count, frame-major

  /// Value of `joint`'s `c`-th channel in `frame` (both in range).
  float value(int frame, int joint, int c) const {
    return values[static_cast<std::size_t>(frame) * channel_count + joints[joint].first_channel +
                  c];
  }
  /// Local rotation of `joint` in `frame`: the product of its rotation channels' elementary
  /// rotations in channel order (the BVH convention), identity when it has none.
  glm::quat local_rotation(int frame, int joint) const;
  /// Position channels of `joint` in `frame` (0 for absent channels), file units.
  glm::vec3 position(int frame, int joint) const;
};

/// Reads the BVH file at `path` into `out` (replacing it). Accepts ROOT/JOINT/End Site in
/// any nesting, 0 to 6 channels per joint in any order, several roots. Fails with a message
/// that names the file, line and what is wrong (unknown keyword, bad number, missing brace,
/// MOTION values fewer than Frames × channels, ...). Never throws.
status read_bvh(const std::string& path, bvh_clip& out);

}  // namespace avatarmap
