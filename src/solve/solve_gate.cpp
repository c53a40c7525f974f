// Stage 3 of the solver: the confidence gate, from this frame's measurement to what is shown.
// The rules themselves (hysteresis, hold and ease, blend in) are written once, in
// include/avatarmap/solve/confidence_gate.hpp; this file applies them to the bones, the hips
// position and the expressions, with the state frame_solver keeps between frames.
#include <cstdint>

#include "avatarmap/core/rotation.hpp"
#include "avatarmap/solve/confidence_gate.hpp"
#include "avatarmap/solve/frame_solver.hpp"

namespace avatarmap {

void frame_solver::gate_bones(const frame_measurement& m, double t, proxy_pose& out) {
  // Local rotation of a measured bone, relative to the measured parent when there is one,
  // else to the parent's output. Called in bone order while the gate runs, so an unmeasured
  // parent's output is this frame's unless previous_world() memoised it earlier this frame.
  auto local_of = [&](int b) -> glm::quat {
    const bone_measurement& bm = m.bones[b];
    const int p = bone_parent(b);
    if (p == k_no_parent) return bm.world;
    if (m.bones[p].confidence > 0.f)
      return bm.has_local ? bm.local : glm::conjugate(m.bones[p].world) * bm.world;
    return glm::conjugate(previous_world(p)) * bm.world;
  };
  // Move a share of the wrist's twist about the forearm into the lower arm (the radius and
  // ulna do most of the turning), where both are measured.
  glm::quat split[4];  // left lower arm, left hand, right lower arm, right hand
  std::uint64_t split_mask = 0;
  for (int side = 0; side < 2; ++side) {
    const int la = idx(side == 0 ? bone::left_lower_arm : bone::right_lower_arm);
    const int hd = idx(side == 0 ? bone::left_hand : bone::right_hand);
    if (m.bones[la].confidence <= 0.f || m.bones[hd].confidence <= 0.f) continue;
    const glm::quat hand_local = local_of(hd);
    const glm::vec3 axis = bone_rest_direction(static_cast<bone>(hd));
    const glm::quat twist = nlerp_shortest(identity_quat(), swing_twist(hand_local, axis).twist,
                                           options_.forearm_twist_share);
    split[2 * side] = local_of(la) * twist;
    split[2 * side + 1] = glm::conjugate(twist) * hand_local;
    split_mask |= (1ull << la) | (1ull << hd);
  }
  // World rotations of this frame's output, filled in bone order (a parent comes before its
  // children). The neck and head are measured in the camera's frame by the face mesh (or the
  // pose's face points), not relative to the torso: their locals are taken relative to the
  // parent's output, so the head shows the world rotation measured even when the torso shown
  // differs from the torso measured (held, blended, eased, or a lower-body hold).
  glm::quat out_world[k_bone_count];
  auto measured_local = [&](int b) -> glm::quat {
    if (b == idx(bone::neck) || b == idx(bone::head))
      return glm::conjugate(out_world[bone_parent(b)]) * m.bones[b].world;
    if (!((split_mask >> b) & 1u)) return local_of(b);
    if (b == idx(bone::left_lower_arm)) return split[0];
    if (b == idx(bone::left_hand)) return split[1];
    if (b == idx(bone::right_lower_arm)) return split[2];
    return split[3];
  };

  const confidence_options& co = options_.confidence;
  for (int b = 0; b < k_bone_count; ++b) {
    rotation_gate& g = bones_[b];
    const float c = m.bones[b].confidence;
    out.rotations[b] = g.update(c, t, co, [&] { return measured_local(b); });
    out.confidence[b] = g.gate.tracked ? c : 0.f;
    const int p = bone_parent(b);
    out_world[b] = p == k_no_parent ? out.rotations[b] : out_world[p] * out.rotations[b];
  }
  ++world_generation_;  // previous_world() now refers to this output
}

glm::vec3 frame_solver::gate_hips_position(const frame_measurement& m, double t) {
  const confidence_options& co = options_.confidence;
  // Height: hold, then ease to the rest height.
  update_gate(hips_height_state_, m.hips_height_valid ? 1.f : 0.f, t, co);
  if (hips_height_state_.tracked) {
    hips_height_ = hips_height_held_ = m.hips_height;
  } else if (hips_height_state_.ever_tracked) {
    const gate_ramp r = hold_and_ease(t - hips_height_state_.lost_at, co);
    hips_height_ = glm::mix(hips_height_held_, options_.rest_hips_height, r.weight);
  }
  // Ground position: relative to where the person was first seen; held while unseen (a
  // person who walks out of view has not gone back to the origin).
  update_gate(ground_state_, m.hips_ground_valid ? 1.f : 0.f, t, co);
  if (ground_state_.tracked) {
    if (!have_origin_) {
      ground_origin_ = m.hips_ground;
      have_origin_ = true;
    }
    ground_ = m.hips_ground - ground_origin_;
  }
  return glm::vec3(ground_.x, hips_height_, ground_.y);
}

void frame_solver::gate_expressions(const frame_measurement& m, double t, proxy_pose& out) {
  // Expressions and blendshapes: held, then eased to 0 (neutral).
  update_gate(face_state_, m.expressions_valid ? 1.f : 0.f, t, options_.confidence);
  if (face_state_.tracked) {
    expressions_held_ = m.expressions;
    blendshapes_held_ = m.blendshapes;
    out.expressions = m.expressions;
    out.blendshapes = m.blendshapes;
    return;
  }
  const float k = face_state_.ever_tracked
                      ? 1.f - hold_and_ease(t - face_state_.lost_at, options_.confidence).weight
                      : 0.f;
  for (int i = 0; i < k_expression_count; ++i) out.expressions[i] = expressions_held_[i] * k;
  for (int i = 0; i < k_blendshape_count; ++i) out.blendshapes[i] = blendshapes_held_[i] * k;
}

}  // namespace avatarmap
