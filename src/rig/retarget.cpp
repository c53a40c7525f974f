#include "avatarmap/rig/retarget.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "avatarmap/core/euler.hpp"
#include "avatarmap/core/rotation.hpp"

namespace avatarmap {
namespace {

constexpr float k_pi_f = 3.14159265358979f;

glm::vec3 position_of(const glm::mat4& m) { return glm::vec3(m[3]); }

// The proxy child that continues the bone (hips -> spine, upperChest -> neck, hand -> middle
// finger, ...), or -1 for leaves (head, distal finger bones, toes).
int primary_child(int b) {
  for (int c = b + 1; c < k_bone_count; ++c) {
    if (bone_parent(c) != b) continue;
    const bone cb = static_cast<bone>(c);
    if (cb == bone::left_eye || cb == bone::right_eye || cb == bone::jaw) continue;
    if (b == idx(bone::hips) && c != idx(bone::spine)) continue;
    if (b == idx(bone::upper_chest) && c != idx(bone::neck)) continue;
    if (b == idx(bone::left_hand) && c != idx(bone::left_middle_proximal)) continue;
    if (b == idx(bone::right_hand) && c != idx(bone::right_middle_proximal)) continue;
    return c;
  }
  return -1;
}

bool skips_rest_alignment(bone b) {
  // The proxy's foot/toe rest direction (ankle -> toe tip) is an idealisation that differs from
  // any rig's ankle -> ball; eyes and jaw have no bone direction. A clavicle's rest direction is
  // the rig's anatomy, not a pose to straighten (CMU's LeftCollar rises 26 degrees from the
  // chest to the socket): turning it onto the proxy's +X would drop the shoulder sockets, and
  // the arms with them, by the clavicle's rise (8 cm on the CMU skeleton).
  return b == bone::left_foot || b == bone::right_foot || b == bone::left_toes ||
         b == bone::right_toes || b == bone::left_eye || b == bone::right_eye || b == bone::jaw ||
         b == bone::left_shoulder || b == bone::right_shoulder;
}

}  // namespace

status retargeter::build(const rig& r, const bone_binding& binding, const retarget_options& options,
                         const mapping_table* table) {
  rig_ = &r;
  binding_ = binding;
  options_ = options;
  const int n = r.joint_count();
  const std::string where = r.file.empty() ? std::string("rig") : r.file;
  if (binding[idx(bone::hips)] < 0)
    return status::parse_error(where + ": no joint is bound to the hips (required)");
  bone_of_joint_.assign(static_cast<size_t>(n), -1);
  for (int b = 0; b < k_bone_count; ++b) {
    const int j = binding[b];
    if (j < -1 || j >= n)
      return status::parse_error(where + ": bone " + std::string(bone_name(static_cast<bone>(b))) +
                                 " is bound to joint " + std::to_string(j) + ", out of range");
    if (j < 0) continue;
    if (bone_of_joint_[j] >= 0)
      return status::parse_error(where + ": joint '" + r.names[j] + "' is bound to both " +
                                 std::string(bone_name(static_cast<bone>(bone_of_joint_[j]))) +
                                 " and " + std::string(bone_name(static_cast<bone>(b))));
    bone_of_joint_[j] = b;
  }
  // Proxy bones must map to rig joints in a consistent hierarchy: a bound bone's joint must
  // descend from its nearest bound proxy ancestor's joint.
  for (int b = 1; b < k_bone_count; ++b) {
    if (binding[b] < 0) continue;
    int a = bone_parent(b);
    while (a >= 0 && binding[a] < 0) a = bone_parent(a);
    if (a < 0) continue;
    int j = r.parents[binding[b]];
    while (j >= 0 && j != binding[a]) j = r.parents[j];
    if (j < 0)
      return status::parse_error(where + ": joint '" + r.names[binding[b]] + "' (" +
                                 std::string(bone_name(static_cast<bone>(b))) +
                                 ") is not below joint '" + r.names[binding[a]] + "' (" +
                                 std::string(bone_name(static_cast<bone>(a))) + ")");
  }

  basis_ = options.basis;
  if (options.auto_basis)
    basis_ = r.source == rig_source::vrm0 ? axis_angle(glm::vec3(0.f, 1.f, 0.f), k_pi_f)
                                          : identity_quat();

  identity_basis_ = basis_.w == 1.f;
  // Rest alignment: C · T_j · W_j per bound joint, in VRM space.
  rest_aligned_.assign(static_cast<size_t>(n), identity_quat());
  for (int j = 0; j < n; ++j) {
    const int b = bone_of_joint_[j];
    if (b < 0) continue;
    glm::quat aligned = basis_ * r.rest_world_rotation[j];
    if (!skips_rest_alignment(static_cast<bone>(b))) {
      // Follow the proxy's primary chain to the first bound descendant; else any rig child.
      int target = -1;
      for (int c = primary_child(b); c >= 0 && target < 0; c = primary_child(c))
        if (binding[c] >= 0) target = binding[c];
      // A leaf of the proxy (head, last finger joint): the rig's end joint, when it has
      // exactly one child that drives nothing else.
      if (target < 0 && primary_child(b) < 0) {
        int only = -1, count = 0;
        for (int k = j + 1; k < n; ++k)
          if (r.parents[k] == j) {
            ++count;
            only = k;
          }
        if (count == 1 && bone_of_joint_[only] < 0) target = only;
      }
      glm::vec3 d(0.f);
      const int left_leg = binding[idx(bone::left_upper_leg)];
      const int right_leg = binding[idx(bone::right_upper_leg)];
      if (target >= 0 && b == idx(bone::hips) && left_leg >= 0 && right_leg >= 0) {
        // The proxy's hips joint is the hip sockets' midpoint: its hips bone runs from there to
        // the spine. A rig's hips joint often sits above and behind the sockets (CMU: 9 cm up,
        // 4 cm back, with a zero-length hips -> lowerback bone), so the midpoint, not the hips
        // joint, starts the direction that is turned onto the proxy's +Y.
        const glm::vec3 mid =
            0.5f * (position_of(r.rest_world[left_leg]) + position_of(r.rest_world[right_leg]));
        d = position_of(r.rest_world[target]) - mid;
      } else if (target >= 0) {
        d = position_of(r.rest_world[target]) - position_of(r.rest_world[j]);
      } else if (primary_child(b) >= 0 && r.parents[j] >= 0) {
        // A rig leaf driving a bone the proxy continues (a one-joint finger such as CMU's
        // LFingers, a hand without fingers): taken to continue its parent joint's bone.
        bool leaf = true;
        for (int k = j + 1; k < n && leaf; ++k) leaf = r.parents[k] != j;
        if (leaf) d = position_of(r.rest_world[j]) - position_of(r.rest_world[r.parents[j]]);
      }
      const glm::vec3 dv = normalize_or(basis_ * d, glm::vec3(0.f));
      if (glm::dot(dv, dv) > 0.5f)
        aligned = rotation_between(dv, bone_rest_direction(static_cast<bone>(b))) * aligned;
    }
    rest_aligned_[j] = glm::normalize(aligned);
  }

  // Floor and hips height at rest.
  const int hips = binding[idx(bone::hips)];
  foot_joints_.clear();
  for (bone fb : {bone::left_foot, bone::right_foot, bone::left_toes, bone::right_toes})
    if (binding[idx(fb)] >= 0) foot_joints_.push_back(binding[idx(fb)]);
  const glm::vec3 hips_vrm = basis_ * position_of(r.rest_world[hips]);
  float floor = 0.f;
  if (!foot_joints_.empty()) {
    floor = 1e30f;
    for (int j : foot_joints_) floor = std::min(floor, (basis_ * position_of(r.rest_world[j])).y);
  }
  // The rig's floor when the file tells it (a BVH's toe tips, below the toe joints): the soles
  // stand there, a standing performer's soles map onto it and foot locking keeps them above it.
  float sole_depth = 0.f;  // how far that floor lies below the lowest foot joint
  if (!foot_joints_.empty() && std::isfinite(r.floor_y))
    sole_depth = std::max(0.f, floor - (basis_ * glm::vec3(0.f, r.floor_y, 0.f)).y);
  floor -= sole_depth;
  hips_rest_world_ = position_of(r.rest_world[hips]);
  const int hp = r.parents[hips];
  hips_parent_inverse_ = hp < 0 ? glm::mat4(1.f) : glm::inverse(r.rest_world[hp]);
  floor_vrm_ = floor;
  formula_bones_.clear();
  formula_of_joint_.assign(static_cast<size_t>(n), -1);
  if (table != nullptr) {
    for (int b = 0; b < k_bone_count; ++b) {
      const mapping_bone& mb = table->bones[b];
      const int j = binding[b];
      if (j < 0 || !mb.has_formulas) continue;
      formula_bone fb{
          j,
          b,
          mb.order,
          mb.target_order,
          mb.f,
          mb.has_rest ? mb.rest : euler_from_quat(r.rest_local[j].rotation, mb.target_order)};
      formula_of_joint_[j] = static_cast<int>(formula_bones_.size());
      formula_bones_.push_back(fb);
    }
  }
  world_.assign(static_cast<size_t>(n), identity_quat());
  positions_.assign(static_cast<size_t>(n), glm::vec3(0.f));

  // The hips height that a standing performer maps to: measured in the pose the rig takes for
  // the proxy's rest pose (its bound bones turned onto the proxy's rest directions), not in the
  // rig's own rest. The two differ when the rig's legs are not straight down at rest (the CMU
  // skeleton's spread 20 degrees apart): straightened, they reach lower than the rest pose's
  // feet, and the rest pose's hips height would sink the feet into the floor (5 cm on CMU).
  float hips_y = hips_vrm.y, lowest = floor;
  if (!foot_joints_.empty()) {
    rig_pose aligned;
    prepare(aligned);
    apply(proxy_pose{}, aligned);
    std::vector<glm::mat4> m(static_cast<size_t>(n));
    for (int j = 0; j < n; ++j) {
      const transform& t = r.rest_local[j];
      const glm::mat4 local = joint_matrix(t.translation, aligned.local_rotations[j], t.scale);
      m[j] = r.parents[j] < 0 ? local : m[r.parents[j]] * local;
    }
    hips_y = (basis_ * position_of(m[hips])).y;
    lowest = 1e30f;
    for (int j : foot_joints_) lowest = std::min(lowest, (basis_ * position_of(m[j])).y);
    lowest -= sole_depth;
  }
  rig_hips_height_ = hips_y - lowest;
  if (!(rig_hips_height_ > 0.f))
    rig_hips_height_ = std::abs(hips_vrm.y) > 0.f ? std::abs(hips_vrm.y) : 1.f;
  translation_scale_ =
      options.performer_hips_height > 0.f ? rig_hips_height_ / options.performer_hips_height : 1.f;
  return {};
}

void retargeter::prepare(rig_pose& out) const {
  out.local_rotations.assign(static_cast<size_t>(rig_->joint_count()), identity_quat());
  out.hips_joint = binding_[idx(bone::hips)];
  out.hips_translation = rig_->rest_local[out.hips_joint].translation;
}

void retargeter::apply(const proxy_pose& pose, rig_pose& out) const {
  const rig& r = *rig_;
  const int n = r.joint_count();
  std::array<glm::quat, k_bone_count> proxy_world;
  compute_world_rotations(pose, proxy_world);
  const glm::quat inv_basis = glm::conjugate(basis_);
  for (int j = 0; j < n; ++j) {
    const int p = r.parents[j];
    const glm::quat parent_world = p < 0 ? identity_quat() : world_[p];
    const int b = bone_of_joint_[j];
    const int fi = formula_of_joint_[j];
    if (fi >= 0) {
      // SysMocap's conversion: rest Euler angles + f(proxy Euler angles), in the bone's order.
      const formula_bone& fb = formula_bones_[static_cast<size_t>(fi)];
      const glm::vec3 e = euler_from_quat(pose.rotations[static_cast<size_t>(b)], fb.order);
      const glm::vec3 sum(fb.rest.x + fb.f[0].eval(e.x, e.y, e.z),
                          fb.rest.y + fb.f[1].eval(e.x, e.y, e.z),
                          fb.rest.z + fb.f[2].eval(e.x, e.y, e.z));
      out.local_rotations[j] =
          is_finite(sum) ? quat_from_euler(sum, fb.target_order) : r.rest_local[j].rotation;
      world_[j] = parent_world * out.local_rotations[j];
    } else if (b >= 0) {
      // Unit quaternions stay unit through these products to float precision; the one
      // renormalisation keeps long chains from drifting.
      world_[j] = identity_basis_ ? proxy_world[b] * rest_aligned_[j]
                                  : inv_basis * proxy_world[b] * rest_aligned_[j];
      out.local_rotations[j] = normalized(glm::conjugate(parent_world) * world_[j]);
    } else {
      out.local_rotations[j] = r.rest_local[j].rotation;
      world_[j] = parent_world * out.local_rotations[j];
    }
  }
  const int hips = binding_[idx(bone::hips)];
  if (!options_.root_motion) {
    out.hips_translation = r.rest_local[hips].translation;
    return;
  }
  // Hips position: X/Z from the rest position plus the scaled motion, Y above the rig's floor.
  glm::vec3 rest_vrm = basis_ * hips_rest_world_;
  glm::vec3 target_vrm(rest_vrm.x + translation_scale_ * pose.hips_position.x,
                       floor_vrm_ + translation_scale_ * pose.hips_position.y,
                       rest_vrm.z + translation_scale_ * pose.hips_position.z);
  if (options_.keep_feet_on_ground && !foot_joints_.empty()) {
    // Posed foot heights relative to the hips (rotations only; lengths from the rest pose).
    for (int j = 0; j < n; ++j) {
      const int p = r.parents[j];
      if (p < 0 || j == hips) {
        positions_[j] = glm::vec3(0.f);
        continue;
      }
      const glm::vec3 rest_offset = position_of(r.rest_world[j]) - position_of(r.rest_world[p]);
      // The rest offset expressed in the parent's rest frame, carried by its posed rotation.
      const glm::quat rest_parent = r.rest_world_rotation[p];
      positions_[j] = positions_[p] + world_[p] * (glm::conjugate(rest_parent) * rest_offset);
    }
    float lowest = 1e30f;
    for (int j : foot_joints_) lowest = std::min(lowest, (basis_ * positions_[j]).y);
    target_vrm.y = floor_vrm_ - lowest;
  }
  const glm::vec3 world = inv_basis * target_vrm;
  out.hips_translation = glm::vec3(hips_parent_inverse_ * glm::vec4(world, 1.f));
}

}  // namespace avatarmap
