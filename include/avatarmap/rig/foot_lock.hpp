// Foot locking: a planted foot of the performer (proxy_pose::foot_contact) stays planted on the
// driven skeleton, whatever its proportions. Written once, for the target rig after the
// retargeter (retarget_clip_job, the C API's avm_retargeter_apply) and for the proxy skeleton
// (proxy_foot_lock: .vrma, proxy .bvh, VMC), docs/foot-locking.md.
//
// Per leg (upper leg -> lower leg -> foot -> toes joints of the rig, bound by the binding):
//   - when foot_contact rises above 0 the leg records an anchor: where the ankle is (X, Z), at
//     the ankle's standing height above the floor (Y), and the foot turned only about the
//     vertical from its rest orientation (flat on the floor);
//   - while the contact stays above 0, two-bone IK with the rig's own thigh and shin lengths
//     (skeleton/leg_ik.hpp) puts the ankle at the anchor blended with the free ankle by the
//     contact weight, the knee in the plane the retargeted knee bends in, the foot turned to
//     the anchor's orientation (by the same weight), and the hips lowered (by the same weight)
//     when a leg cannot reach; at contact 0 the anchor is forgotten;
//   - toes and heels never go below the floor: a foot whose sole points (the ankle and the toe
//     joint projected onto the floor in the rest pose, carried by the foot and toe rotations)
//     would sink is lifted by IK.
// The floor is the plane Y = `floor` of the rig's world (glTF axes, Y up): the height at which
// the retargeter puts the lowest foot or toe joint of a standing performer
// (retargeter::floor_height()); 0 for the proxy skeleton, whose soles stand on Y = 0.
// A leg the rig cannot lock (no lower leg, foot or toes joint bound; a zero-length bone) is
// left as retargeted, and warning() says so. A leg with contact 0 whose sole stays above the
// floor is left exactly as retargeted. Non-finite contacts count as 0.
//
// State: the two anchors, kept between frames (frames must come in time order; reset() when a
// new clip starts). Sized at build(); apply() allocates nothing. One thread at a time.
#pragma once

#include <array>
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

/// What foot locking does; each part can be turned off. Defaults: everything on.
struct foot_lock_options {
  /// Lock planted feet at all (false: apply() changes nothing, the floor clamp included).
  bool enabled = true;
  /// Turn a planted foot flat on the floor (only its heading follows the performer).
  bool align_foot = true;
  /// Lower the hips when a locked leg cannot reach its anchor.
  bool lower_hips = true;
  /// Keep heels and toes above the floor (every frame, locked or not).
  bool keep_above_floor = true;
  /// The most the hips may be lowered, as a fraction of the shorter leg's length (thigh +
  /// shin), in [0, 1].
  float max_hips_drop = 0.35f;

  /// Checks max_hips_drop (finite, in [0, 1]); the message names the field.
  status validate() const;
};

/// Foot locking on one rig. build() once, then apply() per frame, in time order.
class foot_lock {
 public:
  /// Binds the legs of `r` (kept by reference: it must outlive this) through `binding`.
  /// `floor` is the floor's height in the rig's world (see the header comment). Fails only on
  /// invalid options (status_code::invalid_argument); a leg that cannot be locked is switched
  /// off with a warning() instead. `forward` is the direction the rig faces in its world (+Z
  /// for glTF / VRM 1.0, -Z for VRM 0.x), the knee's bend when a leg is straight.
  status build(const rig& r, const bone_binding& binding, float floor,
               const foot_lock_options& options = {},
               const glm::vec3& forward = glm::vec3(0.f, 0.f, 1.f));
  /// Same, with the floor and the facing of `rt` (which must be built for the rig).
  status build(const retargeter& rt, const foot_lock_options& options = {});

  /// Forgets both anchors (a new clip, a jump in time).
  void reset();

  /// Locks the feet of `io` (a pose of the bound rig, e.g. from retargeter::apply) by
  /// `contact` ([0] left, [1] right; 0 free .. 1 planted). Changes the leg joints' local
  /// rotations and, when a locked leg cannot reach, io.hips_translation. Allocation-free.
  void apply(const std::array<float, 2>& contact, rig_pose& io);

  /// Whether leg `side` (0 left, 1 right) can be locked.
  bool leg_enabled(int side) const { return legs_[side & 1].ok; }
  /// "" or one sentence per leg that cannot be locked ("left leg: the rig has no toes joint;
  /// foot locking is off for it").
  const std::string& warning() const { return warning_; }
  /// Whether leg `side` holds an anchor now, and where its ankle is anchored (rig world).
  bool locked(int side) const { return legs_[side & 1].locked; }
  glm::vec3 anchor(int side) const { return legs_[side & 1].anchor_pos; }
  /// How far the last apply() lowered the hips (rig world units, >= 0).
  float last_hips_drop() const { return last_drop_; }
  const foot_lock_options& options() const { return options_; }

 private:
  struct leg {
    bool ok = false;
    int upper = -1, lower = -1, foot = -1, toes = -1;
    std::vector<int> path;  // joints from the upper leg's down to the toes', parent first
    float thigh = 0.f, shin = 0.f;
    float ankle_height = 0.f;   // standing ankle height above the floor
    glm::vec3 heel_local{0.f};  // sole point under the ankle, in the foot's rest frame
    glm::vec3 ball_local{0.f};  // sole point under the toe joint, in the toes' rest frame
    glm::quat foot_rest{1.f, 0.f, 0.f, 0.f};  // the foot's rest world rotation
    glm::quat toes_rest{1.f, 0.f, 0.f, 0.f};  // the toes' rest world rotation
    bool locked = false;
    glm::vec3 anchor_pos{0.f};
    glm::quat anchor_rot{1.f, 0.f, 0.f, 0.f};
  };
  void forward_kinematics(const rig_pose& pose);
  void path_kinematics(const leg& l, const rig_pose& pose);
  glm::vec3 position(int j) const { return glm::vec3(world_[j][3]); }
  float sole_sink(const leg& l) const;
  void place_leg(leg& l, const glm::vec3& ankle_target, const glm::quat* foot_rot, rig_pose& io,
                 const glm::quat* toes_rot = nullptr);

  const rig* rig_ = nullptr;
  foot_lock_options options_{};
  float floor_ = 0.f;
  glm::vec3 forward_{0.f, 0.f, 1.f};
  int hips_ = -1;
  std::array<leg, 2> legs_{};
  std::string warning_;
  float last_drop_ = 0.f;
  std::vector<glm::mat4> world_;      // scratch: posed world matrices
  std::vector<glm::quat> world_rot_;  // scratch: posed world rotations
};

/// Foot locking on the proxy skeleton (make_proxy_skeleton(height)): the same foot_lock on a
/// rig built from the proxy's bones, for the outputs that write proxy poses (.vrma, proxy
/// .bvh, VMC). The floor is Y = 0; hips_position is the hips joint. Every leg is lockable.
class proxy_foot_lock {
 public:
  /// Builds the proxy rig (allocates). Fails only on invalid options.
  status build(float height = k_proxy_reference_height, const foot_lock_options& options = {});
  void reset() { lock_.reset(); }
  /// Locks `io`'s feet by io.foot_contact: changes the leg bones' rotations and, when a leg
  /// cannot reach, hips_position.y. Allocation-free.
  void apply(proxy_pose& io);
  const foot_lock& lock() const { return lock_; }

 private:
  rig rig_;
  foot_lock lock_;
  rig_pose pose_;
  std::array<int, k_bone_count> joint_of_{};
};

/// Locks the feet of a whole clip in order (a fresh anchor state); used by the clip outputs.
status lock_feet(std::vector<proxy_pose>& frames, const foot_lock_options& options = {},
                 float height = k_proxy_reference_height);

}  // namespace avatarmap
