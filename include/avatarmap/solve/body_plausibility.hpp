// Whether a frame's body is a person the avatar should follow (docs/solver.md, "Bodies that
// are not followed"). A pose estimator finds a body in a close-up of a forearm or a desk
// webcam's framing too: legs folded above the hips, a torso far larger than the image, legs
// it cannot see, bones no person has. Followed, the avatar kicks its legs up and falls over.
// judge_body() reads one frame; body_hold adds hysteresis over frames; the solver then holds
// the lower body (hips, legs, feet, root) at a rest pose (solver_options::lower_body_rest)
// while what is plausible (the arms, hands, face) keeps driving. Nothing here allocates.
#pragma once

#include <cstdint>

#include "avatarmap/landmarks/landmark_frame.hpp"

namespace avatarmap {

/// Why a frame's body is not followed: one bit per rule (judge_body).
enum body_doubt : std::uint32_t {
  /// Both ankles above the hips' midpoint in the image, or both knees more than 0.3 torso
  /// lengths above it: a standing or sitting person never shows this (one leg kicked high
  /// does not count; a close-up read as a folded body does).
  body_doubt_legs_above_hips = 1u << 0,
  /// The torso (hips' midpoint to shoulders' midpoint) longer than 1.5 image heights.
  body_doubt_torso_too_large = 1u << 1,
  /// A thigh or shin shorter than 0.4 or longer than 1.4 torso lengths (metric points; a
  /// person's are 0.6-1.0), or a torso outside 0.25-0.8 m.
  body_doubt_bone_ratios = 1u << 2,
  /// The lower body (hips, knees, ankles) seen with a mean confidence under 0.5: a desk
  /// webcam's upper-body framing.
  body_doubt_lower_body_unseen = 1u << 3,
};
inline constexpr int k_body_doubt_count = 4;
/// The doubts that make the whole body untrustworthy (the torso and arms too, not only the
/// legs): the points are not a person's.
inline constexpr std::uint32_t k_body_doubts_torso =
    body_doubt_legs_above_hips | body_doubt_torso_too_large | body_doubt_bone_ratios;

/// The doubt's name as the summary prints it ("legs above the hips", ...); "" for none.
const char* body_doubt_name(int bit_index);

/// How much of the body a frame follows.
enum class body_follow : std::uint8_t {
  all = 0,         ///< everything measured is followed
  upper_body = 1,  ///< the lower body held at rest; spine, arms follow the shoulders
  limbs_off = 2,   ///< the lower body held at rest, the spine chain and arms not followed
};

/// One frame's verdict: the doubts found (0 = plausible) and whether there was a body at all.
struct body_verdict {
  std::uint32_t doubts = 0;
  bool has_body = false;
  body_follow follow() const {
    if (!has_body || doubts == 0) return body_follow::all;
    return (doubts & k_body_doubts_torso) ? body_follow::limbs_off : body_follow::upper_body;
  }
};

/// The rules on one frame's pose: image points (scaled by the image size; 0 = unknown, square
/// pixels) and, when present, the metric world points (bone ratios). Non-finite points count
/// as not seen. Pure: no state.
body_verdict judge_body(const landmark_frame& in, float image_width, float image_height);

/// Hysteresis over frames: the first frame with a body decides at once; later, the body
/// follows less after k_enter_frames frames in a row asked for less (and, when only the lower
/// body is unseen, after k_unseen_enter_seconds too: a shorter dropout is an occlusion the
/// filters bridge, a longer one the framing), and more again after k_leave_frames frames in a
/// row asked for more. Frames without a body keep the state.
class body_hold {
 public:
  static constexpr int k_enter_frames = 3;
  static constexpr int k_leave_frames = 8;
  /// The offline filter fills a bone unseen for up to 1.5 s from both sides (smoothing.md).
  static constexpr double k_unseen_enter_seconds = 1.5;

  void reset() { *this = body_hold{}; }
  /// Updates with this frame's verdict at time `t` (seconds); returns the state now in force.
  body_follow update(const body_verdict& v, double t);
  body_follow state() const { return state_; }

 private:
  body_follow state_ = body_follow::all;
  bool decided_ = false;
  int run_ = 0;                                // frames in a row that asked for a change
  double run_start_ = 0.0;                     // the time of the run's first frame
  body_follow run_target_ = body_follow::all;  // the least change the run asked for
};

/// What the solver did with the frames solved since the take began (frame_solver::
/// body_hold_stats()): frames whose lower body was held, those whose spine and arms were not
/// followed either, and how many of the held frames had each doubt (bit index order).
struct body_hold_stats {
  long frames = 0;       // frames with a body
  long held_frames = 0;  // lower body at rest (upper_body or limbs_off)
  long limbs_off_frames = 0;
  long doubt_frames[k_body_doubt_count] = {};
};

}  // namespace avatarmap
