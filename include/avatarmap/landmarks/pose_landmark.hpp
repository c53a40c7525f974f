// BlazePose's 33 body landmarks with MediaPipe's indices. "left" is the person's left.
#pragma once

#include <cstdint>

namespace avatarmap {

inline constexpr int k_pose_landmark_count = 33;

enum class pose_landmark : std::uint8_t {
  nose = 0,
  left_eye_inner = 1,
  left_eye = 2,
  left_eye_outer = 3,
  right_eye_inner = 4,
  right_eye = 5,
  right_eye_outer = 6,
  left_ear = 7,
  right_ear = 8,
  mouth_left = 9,
  mouth_right = 10,
  left_shoulder = 11,
  right_shoulder = 12,
  left_elbow = 13,
  right_elbow = 14,
  left_wrist = 15,
  right_wrist = 16,
  left_pinky = 17,
  right_pinky = 18,
  left_index = 19,
  right_index = 20,
  left_thumb = 21,
  right_thumb = 22,
  left_hip = 23,
  right_hip = 24,
  left_knee = 25,
  right_knee = 26,
  left_ankle = 27,
  right_ankle = 28,
  left_heel = 29,
  right_heel = 30,
  left_foot_index = 31,
  right_foot_index = 32,
};

/// The same point on the other side of the body (nose -> nose, left_eye -> right_eye, ...).
constexpr int pose_mirror_index(int i) {
  if (i <= 0 || i >= k_pose_landmark_count) return i;
  if (i <= 6) return i <= 3 ? i + 3 : i - 3;  // eyes: 1..3 <-> 4..6
  return (i % 2 == 1) ? i + 1 : i - 1;        // 7/8, 9/10, ... 31/32
}

constexpr int idx(pose_landmark p) { return static_cast<int>(p); }

}  // namespace avatarmap
