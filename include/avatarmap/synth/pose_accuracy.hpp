// Accuracy of solved poses against the synthetic ground truth (synth_recording.hpp): the
// measuring stick of docs/accuracy.md and `avatarmap eval-pose`.
//
// Bone-direction error: for each measured bone b, the angle (degrees, [0, 180]) between
// world_true[b] * bone_rest_direction(b) and world_solved[b] * bone_rest_direction(b), where
// world = compute_world_rotations() (the proxy skeleton's FK: a bone's direction is the way
// from its joint to its primary child's joint, independent of bone lengths). The hips position
// is not measured. Measured bones are those of the torso, arms, legs and fingers groups.
// Head orientation error: the angle of world_solved[head]^-1 * world_true[head] (degrees).
// Eyes and jaw are in the head group but not measured (gaze and mouth opening are expressions
// in the output). Every mean is over (frame, bone) samples.
//
// Low visibility: a truth frame is a low-visibility frame when any bone's truth confidence is
// below 0.5 (the marker synth_recording writes for the bones of a limb in a burst). Over those
// frames the same figures are kept again, and separately over the marked bones only.
#pragma once

#include <array>
#include <cstdint>
#include <string>

#include "avatarmap/core/status.hpp"
#include "avatarmap/skeleton/proxy_pose.hpp"

namespace avatarmap {

/// Groups of the proxy skeleton's bones; every bone is in exactly one.
/// torso: hips, spine, chest, upperChest, neck. arms: shoulders, upper/lower arms, hands.
/// legs: upper/lower legs, feet, toes. fingers: thumbs and fingers (30 bones).
/// head: head, eyes, jaw.
enum class accuracy_group : std::uint8_t { torso, arms, legs, fingers, head };
inline constexpr int k_accuracy_group_count = 5;
/// Groups whose bones enter the direction error (all but head).
inline constexpr int k_direction_group_count = 4;

accuracy_group bone_accuracy_group(bone b);
const char* accuracy_group_name(accuracy_group g);

/// Mean and maximum of angles in degrees.
struct angle_stats {
  double sum = 0.0;
  double max = 0.0;
  long count = 0;
  void add(double degrees) {
    sum += degrees;
    if (degrees > max) max = degrees;
    ++count;
  }
  /// 0 when empty.
  double mean() const { return count > 0 ? sum / static_cast<double>(count) : 0.0; }
};

/// Histogram of angles for percentiles: bins of 0.05 degrees over [0, 180] (the last bin
/// takes everything above). quantile() returns the upper edge of the bin where the share q of
/// the samples is reached, so it is at most 0.05 degrees above the exact percentile.
struct angle_histogram {
  static constexpr double k_bin_degrees = 0.05;
  static constexpr int k_bins = 3600;
  std::array<std::uint32_t, k_bins> bins{};
  long count = 0;
  void add(double degrees) {
    int b = degrees >= 0.0 ? static_cast<int>(degrees / k_bin_degrees) : 0;
    if (!(degrees < 180.0)) b = k_bins - 1;  // NaN too
    ++bins[b < k_bins ? b : k_bins - 1];
    ++count;
  }
  /// q in [0, 1]; 0 when empty.
  double quantile(double q) const {
    if (count == 0) return 0.0;
    const double need = q * static_cast<double>(count);
    long seen = 0;
    for (int b = 0; b < k_bins; ++b) {
      seen += bins[b];
      if (static_cast<double>(seen) >= need && seen > 0) return (b + 1) * k_bin_degrees;
    }
    return k_bins * k_bin_degrees;
  }
};

/// Figures over one set of samples.
struct accuracy_figures {
  angle_stats direction;                                    // every measured bone
  std::array<angle_stats, k_direction_group_count> groups;  // torso, arms, legs, fingers
  angle_stats head;                                         // head orientation
  angle_histogram head_histogram;                           // its percentiles
};

/// Mean and maximum of absolute weight errors (weights in [0, 1]).
struct weight_stats {
  double sum = 0.0;
  double max = 0.0;
  long count = 0;
  void add(double error) {
    const double e = error < 0.0 ? -error : error;
    const double v = e == e ? e : 1.0;  // NaN counts as the largest error
    sum += v;
    if (v > max) max = v;
    ++count;
  }
  /// 0 when empty.
  double mean() const { return count > 0 ? sum / static_cast<double>(count) : 0.0; }
};

/// The face's figures (docs/accuracy.md, "The face"), over every frame:
/// - blink: per eye, the eye's closure blink + blinkLeft / blink + blinkRight (expressions,
///   so *.pose.jsonl files carry it); two samples a frame.
/// - jaw_open: ARKit's jawOpen blendshape (0 on both sides where a file carries no
///   blendshapes).
/// - visemes: aa, ih, ou, ee, oh (expressions).
/// - gaze: per eye, the angle between the eye's forward (+Z) under the truth's and the
///   solved local rotation (relative to the head, so the head's error is not counted);
///   two samples a frame, and its percentiles.
/// - shapes: every ARKit blendshape's error (zero where neither side has it).
struct face_accuracy {
  weight_stats blink;
  weight_stats jaw_open;
  std::array<weight_stats, 5> visemes;
  angle_stats gaze;
  angle_histogram gaze_histogram;
  std::array<weight_stats, k_blendshape_count> shapes;
  /// Per shape over the frames whose truth weight is at least 0.2 (the shape in use: most
  /// frames of a take hold a shape at 0, which the figure over every frame is mostly made of).
  std::array<weight_stats, k_blendshape_count> shapes_active;
};

struct pose_accuracy {
  long frames = 0;                  // truth frames compared
  long low_visibility_frames = 0;   // of those, frames with a marked bone
  accuracy_figures all;             // every frame
  accuracy_figures low_visibility;  // low-visibility frames only
  angle_stats marked;               // marked bones only (bone directions)
  /// Per bone over every frame: the direction error (head: its orientation error; eyes and
  /// jaw stay empty). For finding which bone a group's figure comes from.
  std::array<angle_stats, k_bone_count> bones;
  face_accuracy face;  // every frame
};

/// Adds one frame (truth and solved at the same time) to `acc`. Non-finite or zero
/// quaternions in `solved` count as 180 degrees (a solver must never output them).
void accumulate_pose_accuracy(const proxy_pose& truth, const proxy_pose& solved,
                              pose_accuracy& acc);

/// Compares two *.pose.jsonl files: every frame of `truth_path` is matched with the frame of
/// `solved_path` at the same time (within time_tolerance seconds). Both files must have
/// strictly increasing times. Fails (naming the file and line) on a read error or on times
/// that do not increase; fails after reading both files when a truth frame has no solved frame
/// at its time (`out` then holds the figures of the matched frames; the message counts the
/// unmatched frames and gives the first one's time). Solved frames between truth frames are
/// ignored (e.g. a resampled output). An empty truth file is an error.
struct pose_accuracy_options {
  double time_tolerance = 0.5e-3;  // seconds, >= 0
};
status evaluate_pose_files(const std::string& truth_path, const std::string& solved_path,
                           pose_accuracy& out, const pose_accuracy_options& options = {});

/// Jitter of one *.pose.jsonl file (no truth needed; real video): for each measured bone (the
/// direction groups above) the second time derivative of its world direction,
/// a_t = ((u_{t+1} - u_t) / dt_1 - (u_t - u_{t-1}) / dt_0) / ((dt_0 + dt_1) / 2) with u the unit
/// direction vector, and its root mean square over frames and bones, in degrees per second
/// squared (|a| in radians per second squared times 180/pi). Smaller is steadier; compare files
/// at the same frame rate (it grows with the rate for the same noise).
struct pose_jitter {
  long frames = 0;                                       // frames read
  double rms = 0.0;                                      // every measured bone, deg/s^2
  std::array<double, k_direction_group_count> groups{};  // torso, arms, legs, fingers
  std::array<double, k_bone_count> bones{};  // per measured bone (0 for the head's bones)
};
/// Fails (naming the file and line) on a read error, times that do not increase, or fewer than
/// three frames.
status measure_pose_jitter(const std::string& path, pose_jitter& out);

}  // namespace avatarmap
