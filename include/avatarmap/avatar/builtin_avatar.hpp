// The built-in avatar: a procedurally generated humanoid written by the project (its mesh, skin,
// colours and expressions are all made here; no third-party asset), so that the demo, the viewer
// and tests have an avatar on a fresh machine. It is a VRM 1.0 model (binary glTF with the
// VRMC_vrm extension) whose skeleton is the proxy skeleton (proxy_skeleton.hpp) of the chosen
// height: 55 joints, one per VRM 1.0 humanoid bone, with identity rest rotations, in the VRM
// T-pose (Y up, facing +Z, the avatar's left +X, metres, soles on Y = 0). What it looks like,
// its licence and its expressions: docs/avatar.md.
//
// Raw -> encoded: make_builtin_avatar builds the editable description (positions, skin weights,
// morph targets, materials, expressions) that tests inspect; encode_builtin_avatar turns it into
// the GLB bytes; write_builtin_avatar writes them atomically.
#pragma once

#include <array>
#include <cstdint>
#include <glm/glm.hpp>
#include <string>
#include <vector>

#include "avatarmap/core/status.hpp"
#include "avatarmap/skeleton/bone.hpp"
#include "avatarmap/skeleton/proxy_skeleton.hpp"

namespace avatarmap {

/// Heights the built-in avatar accepts (metres).
inline constexpr float k_builtin_avatar_min_height = 0.5f;
inline constexpr float k_builtin_avatar_max_height = 3.0f;

struct builtin_avatar_options {
  /// Standing height, top of the head above the soles (metres), in [0.5, 3]. Every length of
  /// the 1.70 m design scales with it.
  float height = k_proxy_reference_height;
  /// meta.name of the VRM.
  std::string name = "avatarmap mannequin";

  /// Names the field and its range when a value is out of range.
  status validate() const;
};

/// A material: glTF metallic-roughness, not metallic.
struct avatar_material {
  std::string name;
  glm::vec4 base_color{1.f};  // linear RGBA
  float roughness = 0.8f;
};

/// A triangle list with one material, skinned to the avatar's joints.
struct avatar_primitive {
  int material = 0;                  // index into builtin_avatar::materials
  std::vector<glm::vec3> positions;  // bind pose (VRM space, metres)
  std::vector<glm::vec3> normals;    // unit length
  std::vector<glm::vec3> colors;     // per-vertex linear RGB (COLOR_0), or empty
  /// Skin joints per vertex: joint j is bone j (idx(bone)); unused slots are joint 0 with
  /// weight 0.
  std::vector<std::array<std::uint8_t, 4>> joints;
  std::vector<glm::vec4> weights;      // per vertex, summing to 1
  std::vector<std::uint32_t> indices;  // triangles, counter-clockwise seen from outside
  /// Morph targets: per target of the mesh, a position offset per vertex (metres).
  std::vector<std::vector<glm::vec3>> targets;
};

/// A mesh: its primitives all carry the same morph targets.
struct avatar_mesh {
  std::string name;
  std::vector<avatar_primitive> primitives;
  std::vector<std::string> target_names;
};

/// One VRM expression: morph targets of one mesh set to `weight` times the expression's value.
struct avatar_expression {
  struct bind {
    int mesh = 0;
    int target = 0;
    float weight = 1.f;
  };
  std::string name;  // VRM 1.0 preset name, or the custom name
  bool preset = true;
  std::vector<bind> binds;
};

/// The editable description of the built-in avatar.
struct builtin_avatar {
  builtin_avatar_options options;
  proxy_skeleton skeleton;
  /// Rest world position of each joint (VRM, metres): the proxy skeleton's rest pose with the
  /// hips at (0, standing_hips_height(skeleton), 0).
  std::array<glm::vec3, k_bone_count> joints{};
  std::vector<avatar_material> materials;
  /// [0] "Body" (no morph targets), [1] "Face" (head, eyes, lids, brows, mouth, tongue; the
  /// morph targets: ARKit's 52 blendshapes, target i = blendshape i of skeleton/blendshape.hpp,
  /// named as Apple names them). Both skinned to the one skin.
  std::vector<avatar_mesh> meshes;
  /// The VRM expressions, each a combination of the face's ARKit targets (docs/avatar.md).
  std::vector<avatar_expression> expressions;
};

/// Builds the avatar for `options` into `out` (replaced). Fails, naming the field, when
/// options.validate() does; never throws but for std::bad_alloc.
status make_builtin_avatar(const builtin_avatar_options& options, builtin_avatar& out);

/// The VRM 1.0 file (GLB bytes) of `avatar` into `out` (replaced): nodes 0..54 are the bones
/// (named with their VRM names, rest translation = the offset from the parent joint), then
/// "Body" and "Face" (the skinned meshes, scene roots); skin joints = the bones in bone order,
/// inverse bind matrices = the inverse of each joint's rest world matrix; VRMC_vrm with meta,
/// every humanoid bone, lookAt (type bone) and the expressions. Never throws but for
/// std::bad_alloc.
status encode_builtin_avatar(const builtin_avatar& avatar, std::string& out);

/// make_builtin_avatar + encode_builtin_avatar: the avatar's .vrm bytes in memory.
status builtin_avatar_glb(const builtin_avatar_options& options, std::string& out);

/// Writes the avatar for `options` to `path` (a .vrm; .glb viewers open it too) atomically: on
/// failure an existing file is left as it was and no temporary file remains. Errors name the
/// path (or the option). Never throws.
status write_builtin_avatar(const std::string& path, const builtin_avatar_options& options = {});

}  // namespace avatarmap
