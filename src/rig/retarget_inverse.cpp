#include "avatarmap/rig/retarget_inverse.hpp"

#include <cmath>

#include "avatarmap/core/rotation.hpp"

namespace avatarmap {
namespace {

constexpr float k_pi_f = 3.14159265358979f;

// Posed world rotations of `r` from local rotations (rig order: parents first).
void forward_kinematics(const rig& r, const std::vector<glm::quat>& local,
                        std::vector<glm::quat>& out) {
  for (int j = 0; j < r.joint_count(); ++j) {
    const int p = r.parents[static_cast<std::size_t>(j)];
    const glm::quat& l = local[static_cast<std::size_t>(j)];
    out[static_cast<std::size_t>(j)] = p < 0 ? l : out[static_cast<std::size_t>(p)] * l;
  }
}

}  // namespace

status inverse_retargeter::build(const retargeter& forward, const retarget_options& options) {
  if (forward.binding()[idx(bone::hips)] < 0)
    return status::invalid_argument("inverse_retargeter: the retargeter is not built");
  rig_ = &forward.target();
  const rig& r = *rig_;
  const int n = r.joint_count();
  binding_ = forward.binding();
  // C as retargeter::build chooses it.
  basis_ = options.auto_basis
               ? (r.source == rig_source::vrm0 ? axis_angle(glm::vec3(0.f, 1.f, 0.f), k_pi_f)
                                               : identity_quat())
               : glm::normalize(options.basis);
  // R_j: the world rotations the retargeter gives the identity pose.
  rig_pose probe;
  forward.prepare(probe);
  proxy_pose pose;
  pose.set_rest();
  pose.hips_position = glm::vec3(0.f);
  forward.apply(pose, probe);
  world_.assign(static_cast<std::size_t>(n), identity_quat());
  forward_kinematics(r, probe.local_rotations, world_);
  rest_inverse_.assign(static_cast<std::size_t>(n), identity_quat());
  const glm::quat inv_basis = glm::conjugate(basis_);
  for (int b = 0; b < k_bone_count; ++b) {
    const int j = binding_[b];
    if (j >= 0)
      rest_inverse_[static_cast<std::size_t>(j)] =
          glm::normalize(glm::conjugate(world_[static_cast<std::size_t>(j)]) * inv_basis);
  }
  // The hips: probe the affine map hips_position -> hips translation.
  hips_ = binding_[idx(bone::hips)];
  const glm::vec3 h0 = probe.hips_translation;
  glm::mat3 linear(0.f);
  float column_norms = 1.f;
  for (int axis = 0; axis < 3; ++axis) {
    pose.hips_position = glm::vec3(0.f);
    pose.hips_position[axis] = 1.f;
    forward.apply(pose, probe);
    linear[axis] = probe.hips_translation - h0;
    column_norms *= glm::length(linear[axis]);
  }
  const float det = glm::determinant(linear);
  hips_invertible_ = std::isfinite(det) && column_norms > 0.f &&
                     std::fabs(det) > 1e-6f * column_norms && std::isfinite(h0.x) &&
                     std::isfinite(h0.y) && std::isfinite(h0.z);
  hips_linear_inverse_ = hips_invertible_ ? glm::inverse(linear) : glm::mat3(1.f);
  hips_offset_ = h0;
  const int hp = r.parents[static_cast<std::size_t>(hips_)];
  hips_parent_rest_inverse_ =
      hp < 0 ? glm::mat4(1.f) : glm::inverse(r.rest_world[static_cast<std::size_t>(hp)]);
  return {};
}

void inverse_retargeter::apply(const rig_pose& in, proxy_pose& out) const {
  const rig& r = *rig_;
  for (int j = 0; j < r.joint_count(); ++j) {
    const int p = r.parents[static_cast<std::size_t>(j)];
    glm::quat l = in.local_rotations[static_cast<std::size_t>(j)];
    const float norm2 = l.x * l.x + l.y * l.y + l.z * l.z + l.w * l.w;
    if (!is_finite(l) || !(norm2 > 1e-12f)) l = r.rest_local[static_cast<std::size_t>(j)].rotation;
    world_[static_cast<std::size_t>(j)] =
        normalized(p < 0 ? l : world_[static_cast<std::size_t>(p)] * l);
  }
  glm::vec3 t = in.hips_translation;
  if (!is_finite(t)) t = r.rest_local[static_cast<std::size_t>(hips_)].translation;
  // apply_world's body, with the hips already in the parent's space.
  std::array<glm::quat, k_bone_count> proxy_world;
  for (int b = 0; b < k_bone_count; ++b) {
    const int parent = bone_parent(b);
    const glm::quat parent_world = parent == k_no_parent ? identity_quat() : proxy_world[parent];
    const int j = binding_[b];
    if (j < 0) {
      proxy_world[b] = parent_world;
      out.rotations[b] = identity_quat();
      out.confidence[b] = 0.f;
      continue;
    }
    proxy_world[b] = normalized(basis_ * world_[static_cast<std::size_t>(j)] *
                                rest_inverse_[static_cast<std::size_t>(j)]);
    out.rotations[b] = normalized(glm::conjugate(parent_world) * proxy_world[b]);
    out.confidence[b] = 1.f;
  }
  out.hips_position = hips_invertible_ ? hips_linear_inverse_ * (t - hips_offset_) : glm::vec3(0.f);
}

void inverse_retargeter::apply_world(const std::vector<glm::quat>& world,
                                     const glm::vec3& hips_world, proxy_pose& out) const {
  // Locals from the world rotations, then apply(): one rule for both entries.
  const rig& r = *rig_;
  rig_pose local;  // allocation: this entry is for tools and tests, not the per-frame path
  local.local_rotations.resize(static_cast<std::size_t>(r.joint_count()));
  for (int j = 0; j < r.joint_count(); ++j) {
    const int p = r.parents[static_cast<std::size_t>(j)];
    const glm::quat& w = world[static_cast<std::size_t>(j)];
    local.local_rotations[static_cast<std::size_t>(j)] =
        p < 0 ? w : glm::conjugate(world[static_cast<std::size_t>(p)]) * w;
  }
  local.hips_joint = hips_;
  local.hips_translation = glm::vec3(hips_parent_rest_inverse_ * glm::vec4(hips_world, 1.f));
  apply(local, out);
}

}  // namespace avatarmap
