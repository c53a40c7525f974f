#include "avatarmap/rig/foot_lock.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "avatarmap/core/rotation.hpp"
#include "avatarmap/skeleton/leg_ik.hpp"

namespace avatarmap {
namespace {

constexpr glm::vec3 k_up(0.f, 1.f, 0.f);

glm::vec3 position_of(const glm::mat4& m) { return glm::vec3(m[3]); }

float clamp_contact(float c) { return std::isfinite(c) ? std::clamp(c, 0.f, 1.f) : 0.f; }

// The unit direction of `v`, or zero.
glm::vec3 unit_or_zero(const glm::vec3& v) { return normalize_or(v, glm::vec3(0.f)); }

// Rotation turning direction `from` onto `to` (either may be unnormalised); identity when one
// is degenerate.
glm::quat turn(const glm::vec3& from, const glm::vec3& to) {
  const glm::vec3 a = unit_or_zero(from), b = unit_or_zero(to);
  if (a == glm::vec3(0.f) || b == glm::vec3(0.f)) return identity_quat();
  return rotation_between(a, b);
}

}  // namespace

status foot_lock_options::validate() const {
  if (!(std::isfinite(max_hips_drop) && max_hips_drop >= 0.f && max_hips_drop <= 1.f))
    return status::invalid_argument("foot_lock_options.max_hips_drop must be in [0, 1], got " +
                                    std::to_string(max_hips_drop));
  return {};
}

status foot_lock::build(const retargeter& rt, const foot_lock_options& options) {
  return build(rt.target(), rt.binding(), rt.floor_height(), options, rt.forward());
}

status foot_lock::build(const rig& r, const bone_binding& binding, float floor,
                        const foot_lock_options& options, const glm::vec3& forward) {
  if (status st = options.validate(); !st.ok()) return st;
  rig_ = &r;
  options_ = options;
  floor_ = std::isfinite(floor) ? floor : 0.f;
  forward_ = normalize_or(glm::vec3(forward.x, 0.f, forward.z), glm::vec3(0.f, 0.f, 1.f));
  hips_ = binding[idx(bone::hips)];
  warning_.clear();
  last_drop_ = 0.f;
  const int n = r.joint_count();
  world_.assign(static_cast<std::size_t>(n), glm::mat4(1.f));
  world_rot_.assign(static_cast<std::size_t>(n), identity_quat());
  const bone chains[2][4] = {
      {bone::left_upper_leg, bone::left_lower_leg, bone::left_foot, bone::left_toes},
      {bone::right_upper_leg, bone::right_lower_leg, bone::right_foot, bone::right_toes}};
  for (int s = 0; s < 2; ++s) {
    leg& l = legs_[s];
    l = leg{};
    const char* side = s == 0 ? "left" : "right";
    int j[4];
    for (int k = 0; k < 4; ++k) {
      const int b = idx(chains[s][k]);
      j[k] = b < static_cast<int>(binding.size()) ? binding[b] : -1;
      if (j[k] >= n) j[k] = -1;
    }
    std::string missing;
    if (hips_ < 0 || hips_ >= n)
      missing = "hips";
    else if (j[0] < 0)
      missing = "upper leg";
    else if (j[1] < 0)
      missing = "lower leg";
    else if (j[2] < 0)
      missing = "foot";
    else if (j[3] < 0)
      missing = "toes";
    // Each joint must descend from the previous one (the retargeter checks it too).
    for (int k = 3; missing.empty() && k > 0; --k) {
      int a = r.parents[j[k]];
      while (a >= 0 && a != j[k - 1]) a = r.parents[a];
      if (a < 0) missing = "chain";
    }
    if (!missing.empty()) {
      if (!warning_.empty()) warning_ += ' ';
      warning_ += std::string(side) +
                  (missing == "chain" ? " leg: its joints are not one chain"
                                      : " leg: the rig has no " + missing + " joint") +
                  "; foot locking is off for it.";
      continue;
    }
    l.upper = j[0];
    l.lower = j[1];
    l.foot = j[2];
    l.toes = j[3];
    for (int a = l.toes; a >= 0; a = r.parents[a]) {
      l.path.push_back(a);
      if (a == l.upper) break;
    }
    std::reverse(l.path.begin(), l.path.end());
    const glm::vec3 hip = position_of(r.rest_world[l.upper]);
    const glm::vec3 knee = position_of(r.rest_world[l.lower]);
    const glm::vec3 ankle = position_of(r.rest_world[l.foot]);
    const glm::vec3 toe = position_of(r.rest_world[l.toes]);
    l.thigh = glm::length(knee - hip);
    l.shin = glm::length(ankle - knee);
    const float scale = std::max(1e-6f, l.thigh + l.shin);
    if (!(l.thigh > 1e-4f * scale && l.shin > 1e-4f * scale && std::isfinite(scale))) {
      if (!warning_.empty()) warning_ += ' ';
      warning_ += std::string(side) +
                  " leg: its thigh or shin has no length; foot locking is off "
                  "for it.";
      l.path.clear();
      continue;
    }
    l.foot_rest = r.rest_world_rotation[l.foot];
    l.toes_rest = r.rest_world_rotation[l.toes];
    l.ankle_height = std::max(0.f, ankle.y - floor_);
    l.heel_local = glm::conjugate(l.foot_rest) * (glm::vec3(ankle.x, floor_, ankle.z) - ankle);
    // The sole's front: under the toes' tip when the rig knows it (a BVH's End Site), else
    // under the toe joint.
    glm::vec3 front = toe;
    const glm::vec3 tip_local = static_cast<std::size_t>(l.toes) < r.tips.size()
                                    ? r.tips[static_cast<std::size_t>(l.toes)]
                                    : glm::vec3(std::nanf(""));
    if (is_finite(tip_local)) {
      const glm::vec3 tip = toe + glm::mat3(r.rest_world[l.toes]) * tip_local;
      if (is_finite(tip)) front = tip;
    }
    l.ball_local = glm::conjugate(r.rest_world_rotation[l.toes]) *
                   (glm::vec3(front.x, std::min(floor_, front.y), front.z) - toe);
    l.ok = true;
  }
  return {};
}

void foot_lock::reset() {
  for (leg& l : legs_) l.locked = false;
  last_drop_ = 0.f;
}

void foot_lock::forward_kinematics(const rig_pose& pose) {
  const rig& r = *rig_;
  const int n = r.joint_count();
  for (int j = 0; j < n; ++j) {
    const transform& t = r.rest_local[j];
    const glm::vec3 tr = j == pose.hips_joint ? pose.hips_translation : t.translation;
    const glm::quat q = pose.local_rotations[j];
    const glm::mat4 m = joint_matrix(tr, q, t.scale);
    const int p = r.parents[j];
    world_[j] = p < 0 ? m : world_[p] * m;
    world_rot_[j] = p < 0 ? q : world_rot_[p] * q;
  }
}

void foot_lock::path_kinematics(const leg& l, const rig_pose& pose) {
  const rig& r = *rig_;
  for (int j : l.path) {
    const transform& t = r.rest_local[j];
    const glm::quat q = pose.local_rotations[j];
    const glm::mat4 m = joint_matrix(t.translation, q, t.scale);
    const int p = r.parents[j];
    world_[j] = p < 0 ? m : world_[p] * m;
    world_rot_[j] = p < 0 ? q : world_rot_[p] * q;
  }
}

float foot_lock::sole_sink(const leg& l) const {
  const glm::vec3 heel = position(l.foot) + world_rot_[l.foot] * l.heel_local;
  const glm::vec3 ball = position(l.toes) + world_rot_[l.toes] * l.ball_local;
  return std::max(floor_ - heel.y, floor_ - ball.y);
}

void foot_lock::place_leg(leg& l, const glm::vec3& ankle_target, const glm::quat* foot_rot,
                          rig_pose& io, const glm::quat* toes_rot) {
  const rig& r = *rig_;
  const glm::vec3 hip = position(l.upper);
  const glm::vec3 knee = position(l.lower);
  if (!is_finite(ankle_target) || !is_finite(hip) || !is_finite(knee)) return;
  const two_bone_ik_result ik =
      solve_two_bone_ik(hip, l.thigh, l.shin, ankle_target, knee, forward_);
  // Thigh: turn the subtree about the hip so the knee lands on the solved knee.
  {
    const int p = r.parents[l.upper];
    const glm::quat w = turn(knee - hip, ik.knee - hip) * world_rot_[l.upper];
    const glm::quat parent = p < 0 ? identity_quat() : world_rot_[p];
    io.local_rotations[l.upper] = normalized(glm::conjugate(parent) * w);
    path_kinematics(l, io);
  }
  // Shin: turn about the (moved) knee so the ankle lands on the solved ankle.
  {
    const glm::vec3 k = position(l.lower);
    const glm::vec3 a = position(l.foot);
    const int p = r.parents[l.lower];
    const glm::quat w = turn(a - k, ik.ankle - k) * world_rot_[l.lower];
    io.local_rotations[l.lower] = normalized(glm::conjugate(world_rot_[p]) * w);
    path_kinematics(l, io);
  }
  if (foot_rot != nullptr && is_finite(*foot_rot)) {
    const int p = r.parents[l.foot];
    io.local_rotations[l.foot] = normalized(glm::conjugate(world_rot_[p]) * *foot_rot);
    path_kinematics(l, io);
  }
  if (toes_rot != nullptr && is_finite(*toes_rot)) {
    const int p = r.parents[l.toes];
    io.local_rotations[l.toes] = normalized(glm::conjugate(world_rot_[p]) * *toes_rot);
    path_kinematics(l, io);
  }
}

void foot_lock::apply(const std::array<float, 2>& contact, rig_pose& io) {
  last_drop_ = 0.f;
  if (!options_.enabled || rig_ == nullptr) return;
  if (static_cast<int>(io.local_rotations.size()) != rig_->joint_count()) return;
  if (!legs_[0].ok && !legs_[1].ok) return;
  forward_kinematics(io);
  float weight[2] = {0.f, 0.f};
  glm::vec3 target[2];
  glm::quat target_rot[2], target_toes[2];
  for (int s = 0; s < 2; ++s) {
    leg& l = legs_[s];
    if (!l.ok) continue;
    const float c = clamp_contact(contact[s]);
    if (c <= 0.f) {
      l.locked = false;
      continue;
    }
    const glm::vec3 ankle = position(l.foot);
    const glm::quat foot = world_rot_[l.foot];
    if (!is_finite(ankle) || !is_finite(foot)) {
      l.locked = false;
      continue;
    }
    if (!l.locked) {
      // The anchor: where the ankle stands, flat on the floor, heading as the performer's foot.
      l.locked = true;
      if (options_.align_foot) {
        const glm::quat heading =
            swing_twist(normalized(foot * glm::conjugate(l.foot_rest)), k_up).twist;
        l.anchor_rot = normalized(heading * l.foot_rest);
        l.anchor_pos = glm::vec3(ankle.x, floor_ + l.ankle_height, ankle.z);
      } else {
        l.anchor_rot = foot;
        l.anchor_pos = glm::vec3(ankle.x, std::max(ankle.y, floor_ + l.ankle_height), ankle.z);
      }
    }
    weight[s] = c;
    target[s] = ankle + (l.anchor_pos - ankle) * c;
    target_rot[s] = slerp_shortest(foot, l.anchor_rot, c);
    // The toes flat with the foot (their rest turn from it), so that the toe tips stay on the
    // floor with the sole (the retargeted toes may point down: 1 cm under on the CMU rig).
    const glm::quat toes_flat =
        normalized(l.anchor_rot * glm::conjugate(l.foot_rest) * l.toes_rest);
    target_toes[s] =
        options_.align_foot ? slerp_shortest(world_rot_[l.toes], toes_flat, c) : world_rot_[l.toes];
  }
  if (options_.lower_hips && (weight[0] > 0.f || weight[1] > 0.f)) {
    float drop = 0.f, shortest = 1e30f;
    for (int s = 0; s < 2; ++s) {
      const leg& l = legs_[s];
      if (!l.ok) continue;
      shortest = std::min(shortest, l.thigh + l.shin);
      if (weight[s] <= 0.f) continue;
      // A hair short of full reach: a straight knee has no bend plane.
      drop = std::max(
          drop, hip_drop_to_reach(position(l.upper), target[s], 0.999f * (l.thigh + l.shin), k_up));
    }
    drop = std::min(drop, options_.max_hips_drop * shortest);
    if (drop > 0.f && std::isfinite(drop) && hips_ >= 0) {
      const int p = rig_->parents[hips_];
      const glm::vec3 world_delta(0.f, -drop, 0.f);
      const glm::vec3 local_delta =
          p < 0 ? world_delta : glm::inverse(glm::mat3(world_[p])) * world_delta;
      if (is_finite(local_delta)) {
        io.hips_translation += local_delta;
        last_drop_ = drop;
        forward_kinematics(io);
      }
    }
  }
  for (int s = 0; s < 2; ++s) {
    leg& l = legs_[s];
    if (!l.ok) continue;
    if (weight[s] > 0.f) place_leg(l, target[s], &target_rot[s], io, &target_toes[s]);
    if (!options_.keep_above_floor) continue;
    const float sink = sole_sink(l);
    if (sink > 0.f && std::isfinite(sink)) {
      const glm::quat keep = world_rot_[l.foot];
      place_leg(l, position(l.foot) + glm::vec3(0.f, sink, 0.f), &keep, io);
    }
  }
}

status proxy_foot_lock::build(float height, const foot_lock_options& options) {
  if (!(std::isfinite(height) && height > 0.f))
    return status::invalid_argument(
        "proxy_foot_lock: height must be a positive number of "
        "metres, got " +
        std::to_string(height));
  const proxy_skeleton sk = make_proxy_skeleton(height);
  raw_rig raw;
  raw.source = rig_source::test;
  raw.file = "proxy skeleton";
  for (int b = 0; b < k_bone_count; ++b) {
    raw_rig::node node;
    node.name = std::string(bone_name(static_cast<bone>(b)));
    node.parent = bone_parent(b);
    node.rest.translation = b == idx(bone::hips) ? glm::vec3(0.f, standing_hips_height(sk), 0.f)
                                                 : sk.offsets[static_cast<std::size_t>(b)];
    raw.nodes.push_back(node);
  }
  if (status st = build_rig(raw, rig_); !st.ok()) return st;
  bone_binding binding;
  binding.fill(-1);
  for (int j = 0; j < rig_.joint_count(); ++j) binding[rig_.source_index[j]] = j;
  joint_of_ = binding;
  pose_.local_rotations.assign(static_cast<std::size_t>(rig_.joint_count()), identity_quat());
  pose_.hips_joint = binding[idx(bone::hips)];
  return lock_.build(rig_, binding, 0.f, options, glm::vec3(0.f, 0.f, 1.f));
}

void proxy_foot_lock::apply(proxy_pose& io) {
  if (pose_.hips_joint < 0 || !lock_.options().enabled) return;
  for (int b = 0; b < k_bone_count; ++b)
    pose_.local_rotations[joint_of_[b]] = io.rotations[static_cast<std::size_t>(b)];
  pose_.hips_translation = io.hips_position;
  lock_.apply(io.foot_contact, pose_);
  for (int b = 0; b < k_bone_count; ++b)
    io.rotations[static_cast<std::size_t>(b)] = pose_.local_rotations[joint_of_[b]];
  io.hips_position = pose_.hips_translation;
}

status lock_feet(std::vector<proxy_pose>& frames, const foot_lock_options& options, float height) {
  if (!options.enabled) return {};
  proxy_foot_lock lock;
  if (status st = lock.build(height, options); !st.ok()) return st;
  for (proxy_pose& p : frames) lock.apply(p);
  return {};
}

}  // namespace avatarmap
