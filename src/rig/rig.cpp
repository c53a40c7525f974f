#include "avatarmap/rig/rig.hpp"

#include <cmath>

#include "avatarmap/core/rotation.hpp"

namespace avatarmap {

int rig::find(const std::string& name) const {
  for (int i = 0; i < joint_count(); ++i)
    if (names[i] == name) return i;
  return -1;
}

namespace {
// Smallest |scale| a rest transform may have on any axis. Real rigs use 0.01 (centimetre
// rigs) at the smallest; 1e-6 is far below that and far above float's denormals.
constexpr float k_min_rest_scale = 1e-6f;

bool finite_matrix(const glm::mat4& m) {
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r)
      if (!std::isfinite(m[c][r])) return false;
  return true;
}

bool finite_transform(const transform& t) {
  return is_finite(t.translation) && is_finite(t.rotation) && is_finite(t.scale);
}
glm::mat4 to_matrix(const transform& t) {
  return joint_matrix(t.translation, glm::normalize(t.rotation), t.scale);
}
}  // namespace

glm::mat4 joint_matrix(const glm::vec3& translation, const glm::quat& rotation,
                       const glm::vec3& scale) {
  glm::mat4 m = glm::mat4_cast(rotation);
  m[0] *= scale.x;
  m[1] *= scale.y;
  m[2] *= scale.z;
  m[3] = glm::vec4(translation, 1.f);
  return m;
}

status build_rig(const raw_rig& raw, rig& out) {
  out = rig{};
  const int n = static_cast<int>(raw.nodes.size());
  const std::string where = raw.file.empty() ? std::string("rig") : raw.file;
  for (int i = 0; i < n; ++i) {
    const raw_rig::node& node = raw.nodes[i];
    if (node.parent < -1 || node.parent >= n || node.parent == i)
      return status::parse_error(where + ": node " + std::to_string(i) + " '" + node.name +
                                 "' has an invalid parent " + std::to_string(node.parent));
    if (!finite_transform(node.rest))
      return status::parse_error(where + ": node " + std::to_string(i) + " '" + node.name +
                                 "' has a non-finite rest transform (inf or nan); fix the file");
    const glm::quat& q = node.rest.rotation;
    if (!(q.x * q.x + q.y * q.y + q.z * q.z + q.w * q.w > 1e-12f))
      return status::parse_error(where + ": node " + std::to_string(i) + " '" + node.name +
                                 "' has a zero rotation");
    // A zero scale collapses everything below the node to a point: its world matrix has no
    // inverse, and every rotation computed through it (retargeting, BVH offsets) is nan.
    const glm::vec3& sc = node.rest.scale;
    for (int c = 0; c < 3; ++c)
      if (!(std::fabs(sc[c]) >= k_min_rest_scale))
        return status::parse_error(where + ": node " + std::to_string(i) + " '" + node.name +
                                   "' has a zero (or near-zero) scale " + std::to_string(sc[c]) +
                                   " on axis " + "xyz"[c] +
                                   "; a rig bone must have a non-zero scale");
  }
  // Depth-first order from the roots; a node never reached sits on a cycle.
  std::vector<std::vector<int>> children(static_cast<size_t>(n));
  std::vector<int> roots;
  for (int i = 0; i < n; ++i) {
    if (raw.nodes[i].parent < 0)
      roots.push_back(i);
    else
      children[static_cast<size_t>(raw.nodes[i].parent)].push_back(i);
  }
  std::vector<int> order;
  order.reserve(static_cast<size_t>(n));
  std::vector<int> stack(roots.rbegin(), roots.rend());
  while (!stack.empty()) {
    int i = stack.back();
    stack.pop_back();
    order.push_back(i);
    const auto& c = children[static_cast<size_t>(i)];
    for (auto it = c.rbegin(); it != c.rend(); ++it) stack.push_back(*it);
  }
  if (static_cast<int>(order.size()) != n) {
    std::vector<bool> seen(static_cast<size_t>(n), false);
    for (int i : order) seen[static_cast<size_t>(i)] = true;
    for (int i = 0; i < n; ++i)
      if (!seen[static_cast<size_t>(i)])
        return status::parse_error(where + ": node '" + raw.nodes[i].name +
                                   "' is part of a parent cycle");
  }
  std::vector<int> new_index(static_cast<size_t>(n), -1);
  for (int k = 0; k < n; ++k) new_index[static_cast<size_t>(order[k])] = k;
  out.names.resize(static_cast<size_t>(n));
  out.parents.resize(static_cast<size_t>(n));
  out.rest_local.resize(static_cast<size_t>(n));
  out.rest_world.resize(static_cast<size_t>(n));
  out.rest_world_rotation.resize(static_cast<size_t>(n));
  out.tips.resize(static_cast<size_t>(n));
  out.source_index = order;
  for (int k = 0; k < n; ++k) {
    const raw_rig::node& node = raw.nodes[static_cast<size_t>(order[k])];
    out.names[k] = node.name;
    out.parents[k] = node.parent < 0 ? -1 : new_index[static_cast<size_t>(node.parent)];
    out.rest_local[k] = node.rest;
    out.tips[k] = node.tip;
    out.rest_local[k].rotation = glm::normalize(node.rest.rotation);
    const glm::mat4 local = to_matrix(out.rest_local[k]);
    out.rest_world[k] = out.parents[k] < 0 ? local : out.rest_world[out.parents[k]] * local;
    // Finite, non-zero local transforms can still overflow or underflow down a long chain.
    const float det = glm::determinant(glm::mat3(out.rest_world[k]));
    if (!finite_matrix(out.rest_world[k]) || !std::isfinite(det) || std::fabs(det) < 1e-30f) {
      const std::string message = where + ": node " + std::to_string(order[k]) + " '" + node.name +
                                  "' has a singular or non-finite world rest transform (the "
                                  "product of its ancestors' scales); fix the file";
      out = rig{};
      return status::parse_error(message);
    }
    // Rotation of the world matrix with scale removed (columns normalised).
    glm::mat3 r(out.rest_world[k]);
    for (int c = 0; c < 3; ++c) r[c] = normalize_or(r[c], glm::vec3(c == 0, c == 1, c == 2));
    out.rest_world_rotation[k] = glm::normalize(glm::quat_cast(r));
  }
  for (int b = 0; b < k_bone_count; ++b) {
    const int src = raw.declared_humanoid[b];
    if (src < -1 || src >= n) {
      const std::string message = where + ": humanoid bone '" +
                                  std::string(bone_name(static_cast<bone>(b))) + "' names node " +
                                  std::to_string(src) + ", out of range (the rig has " +
                                  std::to_string(n) + " nodes)";
      out = rig{};
      return status::parse_error(message);
    }
    out.declared_humanoid[b] = src >= 0 ? new_index[static_cast<size_t>(src)] : -1;
  }
  out.expressions = raw.expressions;
  out.source = raw.source;
  out.file = raw.file;
  out.floor_y = raw.floor_y;
  return {};
}

}  // namespace avatarmap
