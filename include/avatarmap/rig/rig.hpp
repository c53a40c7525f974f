// A rig (skeleton) of a real avatar: editable raw data (raw_rig, what loaders produce) and the
// immutable, index-based runtime form (rig, built once by build_rig). Units are the file's
// (glTF: metres; a Mixamo rig may be centimetres under a 0.01 scale node: the world transforms
// include every ancestor's scale). Rotations are glTF's: right-handed, Y up.
#pragma once

#include <array>
#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>
#include <limits>
#include <string>
#include <vector>

#include "avatarmap/core/status.hpp"
#include "avatarmap/skeleton/bone.hpp"

namespace avatarmap {

/// A local transform: T * R * S, as glTF composes it.
struct transform {
  glm::vec3 translation{0.f};
  glm::quat rotation{1.f, 0.f, 0.f, 0.f};
  glm::vec3 scale{1.f};
};

/// Where a rig came from (decides the default mapping table and the rest-pose convention).
enum class rig_source : std::uint8_t { unknown, gltf, vrm0, vrm1, test };

/// Editable rig: any node order, names as in the file. A loader fills it; tests build it.
struct raw_rig {
  struct node {
    std::string name;
    int parent = -1;  // index into nodes, -1 for a root
    transform rest;   // local rest transform
    /// Where the joint's segment ends, in its local frame, when the file says (a BVH's End
    /// Site); NaN: not known.
    glm::vec3 tip{std::numeric_limits<float>::quiet_NaN()};
  };
  std::vector<node> nodes;
  rig_source source = rig_source::unknown;
  /// Humanoid bones the file itself declares (VRM's humanoid extension): node index per
  /// proxy bone, -1 when not declared. Other formats leave all -1 (a mapping table matches
  /// names instead).
  std::array<int, k_bone_count> declared_humanoid;
  /// Expression (blend shape group) names the file declares, e.g. VRM presets.
  std::vector<std::string> expressions;
  std::string file;  // for messages
  /// The floor the rest pose stands on (Y of the rig's world), when the file tells it: a BVH's
  /// lowest End Site (the toes' tips, below the toe joints). NaN: unknown (the retargeter takes
  /// the lowest foot or toe joint).
  float floor_y = std::numeric_limits<float>::quiet_NaN();

  raw_rig() { declared_humanoid.fill(-1); }
};

/// Immutable runtime rig: joints in parent-first order, names resolved to indices once.
struct rig {
  std::vector<std::string> names;
  std::vector<int> parents;           // -1 for roots; parents[i] < i
  std::vector<transform> rest_local;  // local rest transforms
  std::vector<glm::mat4> rest_world;  // world rest matrices (all ancestors, scale included)
  std::vector<glm::quat> rest_world_rotation;       // rotation part of rest_world (unit)
  std::vector<int> source_index;                    // raw_rig node index of each joint
  std::vector<glm::vec3> tips;                      // raw_rig::node::tip of each joint
  std::array<int, k_bone_count> declared_humanoid;  // joint index per proxy bone, or -1
  std::vector<std::string> expressions;
  rig_source source = rig_source::unknown;
  std::string file;
  float floor_y = std::numeric_limits<float>::quiet_NaN();  // raw_rig::floor_y

  int joint_count() const { return static_cast<int>(names.size()); }
  /// Joint index of `name` (exact), or -1.
  int find(const std::string& name) const;
};

/// A joint's local matrix: translate · rotate · scale (rotation taken as given: unit).
glm::mat4 joint_matrix(const glm::vec3& translation, const glm::quat& rotation,
                       const glm::vec3& scale);

/// Validates a raw rig (parents in range, no cycles, finite transforms, non-zero scale) and
/// builds the runtime rig, reordering joints parent-first. Errors (status_code::parse: the
/// avatar's skeleton is malformed) name the node.
status build_rig(const raw_rig& raw, rig& out);

}  // namespace avatarmap
