// Seeded head sweep for the synthetic ground truth: the head turned relative to the torso over
// the whole range people use in front of a camera (looking down at a keyboard or a phone,
// over the shoulder, tilted), for measuring the head's solve at every angle
// (synth_motion::head, docs/accuracy.md "The head at every angle").
//
// The head's turn relative to the upper chest is R = R_y(yaw) * R_x(-pitch) * R_z(roll)
// (VRM space: yaw toward +X is positive, pitch up is positive, roll toward the person's
// left is positive), shared evenly by the neck and the head (each gets half the turn).
// The angles move from one key to the next with a minimum-jerk weight (velocity and
// acceleration zero at the keys) over move_min..move_max seconds, then dwell at the key for
// 0..dwell_max seconds. Keys: with probability 0.25 a return near the front (each angle within
// +-5 degrees), with probability 0.2 a deep look down (pitch in [pitch_min, pitch_min + 15]
// with any yaw and roll), otherwise uniform over the box [pitch_min, pitch_max] x
// [-yaw_max, yaw_max] x [-roll_max, roll_max]. The first key is the front (0, 0, 0).
#pragma once

#include <cstdint>
#include <glm/gtc/quaternion.hpp>
#include <random>

namespace avatarmap {

struct head_sweep_options {
  float pitch_min = -70.f;  // degrees, down
  float pitch_max = 40.f;   // degrees, up
  float yaw_max = 70.f;     // degrees, either way
  float roll_max = 35.f;    // degrees, either way
  float move_min = 0.6f;    // seconds per move, 0 < move_min <= move_max
  float move_max = 1.6f;
  float dwell_max = 0.6f;  // seconds at a key, >= 0
};

/// Angles of the head relative to the upper chest, degrees.
struct head_angles {
  float yaw = 0.f, pitch = 0.f, roll = 0.f;
};

/// R_y(yaw) * R_x(-pitch) * R_z(roll), angles in degrees (see the file comment).
glm::quat head_turn(const head_angles& a);

/// A seeded sweep: at(t) is a pure function of (seed, options, t) and allocates nothing;
/// asking times in increasing order is cheap, going back replays from 0. Not thread-safe.
class head_sweep {
 public:
  explicit head_sweep(std::uint32_t seed, const head_sweep_options& options = {});
  head_angles at(double t);

 private:
  void restart();
  void advance();
  head_angles draw_key();

  std::uint32_t seed_;
  head_sweep_options options_;
  std::mt19937 rng_;
  head_angles a_, b_;
  double t0_ = 0.0, t1_ = 0.0, t2_ = 0.0;  // move from a (t0) to b (t1), dwell until t2
};

}  // namespace avatarmap
