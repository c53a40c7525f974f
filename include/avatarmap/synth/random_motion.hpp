// Seeded random motion for the synthetic ground truth: what a person does in front of a camera,
// sped up. The body is split into channels (torso with the hips position, head with neck, eyes
// and jaw, each arm, each hand's fingers, each leg, the expressions); each channel moves from one
// random_pose() key to the next on its own timeline, so limbs start and stop at different
// times. Between two keys every local rotation follows slerp_shortest with a minimum-jerk
// weight w(s) = 10 s^3 - 15 s^4 + 6 s^5 (velocity and acceleration zero at the keys); the hips
// position and expression weights follow the same weight linearly; the feet are then put on
// the floor (ground_pose). A segment's length is chosen from a target speed drawn uniformly in
// the channel's range: the peak world angular speed the channel's own bones reach (with the
// rest of the body still) equals the target, within [k_min_segment_seconds,
// k_max_segment_seconds] and never above the channel's top speed. Arms and fingers use
// [1, max_wrist_speed] rad/s, the head [0.5, 3], legs [0.5, 3], the torso [0.3, 1.5];
// expressions change every 0.15..1 s. The parent's motion adds to a bone's world speed, so a
// wrist can exceed max_wrist_speed a little while the torso turns.
#pragma once

#include <array>
#include <cstdint>
#include <random>

#include "avatarmap/skeleton/proxy_pose.hpp"
#include "avatarmap/skeleton/proxy_skeleton.hpp"
#include "avatarmap/synth/random_pose.hpp"

namespace avatarmap {

struct random_motion_options {
  /// Ranges of the key poses (random_pose()). The defaults here differ from
  /// random_pose_limits' in these fields: finger_side_bend 10 degrees (non-hinge fingers),
  /// coupled_deviation 2 degrees (the spine bends as one, the neck turns with the head),
  /// pelvis_share 0.3-0.7 (a lean is shared by the pelvis and the spine, the lumbopelvic
  /// rhythm) and hips_xz_range 0.15 m (the person stays near the spot the camera is aimed at).
  random_pose_limits limits = default_limits();
  /// Top speed of arms and fingers (rad/s, > 0).
  float max_wrist_speed = 6.f;

  static random_pose_limits default_limits() {
    random_pose_limits l;
    l.finger_side_bend = 10.f;
    l.coupled_deviation = 2.f;
    l.pelvis_share_min = 0.3f;
    l.pelvis_share_max = 0.7f;
    l.hips_xz_range = 0.15f;
    return l;
  }
};

inline constexpr float k_min_segment_seconds = 0.2f;
inline constexpr float k_max_segment_seconds = 2.5f;

/// The motion's channels (see the file comment).
enum class motion_channel : std::uint8_t {
  torso,
  head,
  left_arm,
  right_arm,
  left_fingers,
  right_fingers,
  left_leg,
  right_leg,
  expressions,
};
inline constexpr int k_motion_channel_count = 9;

/// Channel that moves bone `b` (never expressions).
motion_channel motion_channel_of(bone b);

/// A seeded random motion: pose_at(t) is a pure function of (skeleton, seed, options, t) — it
/// does not depend on which times were asked before — and allocates nothing. Times before 0
/// are treated as 0; asking times in increasing order is cheap, going back replays from 0.
/// Not thread-safe (one object per thread).
class random_motion {
 public:
  random_motion(const proxy_skeleton& skeleton, std::uint32_t seed,
                const random_motion_options& options = {});

  /// The pose at time t seconds (t = out.t; confidence 1 for every bone).
  void pose_at(double t, proxy_pose& out);

  const proxy_skeleton& skeleton() const { return skeleton_; }

 private:
  struct channel_state {
    std::mt19937 rng;
    double t0 = 0.0, t1 = 0.0;  // times of keys a and b
    proxy_pose a, b;
  };
  void restart();
  void advance(int channel);
  float segment_seconds(int channel, const proxy_pose& a, const proxy_pose& b);

  proxy_skeleton skeleton_;
  std::uint32_t seed_;
  random_motion_options options_;
  std::array<channel_state, k_motion_channel_count> channels_;
};

}  // namespace avatarmap
