// One captured frame of landmarks: body (image + world), both hands (image + world) and the
// face mesh, each optional. Fixed-size storage: a frame never allocates. Coordinates are
// MediaPipe's (include/avatarmap/core/spaces.hpp); "left"/"right" are the person's sides.
#pragma once

#include <array>
#include <cstdint>

#include "avatarmap/landmarks/face_landmark.hpp"
#include "avatarmap/landmarks/hand_landmark.hpp"
#include "avatarmap/landmarks/pose_landmark.hpp"

namespace avatarmap {

/// One landmark. visibility (not occluded) and presence (inside the image) are in [0, 1];
/// hand and face points carry 1 for both. Non-finite values mean "not seen".
struct landmark {
  float x = 0.f;
  float y = 0.f;
  float z = 0.f;
  float visibility = 1.f;
  float presence = 1.f;
};

/// The optional parts of a frame; each is a bit in landmark_frame::parts.
enum class frame_part : std::uint8_t {
  pose = 0,              // 33 image points
  pose_world = 1,        // 33 world points (metres, origin at hip midpoint)
  left_hand = 2,         // 21 image points of the person's left hand
  left_hand_world = 3,   // 21 world points (metres, origin at the hand's centre)
  right_hand = 4,        // 21 image points of the person's right hand
  right_hand_world = 5,  // 21 world points
  face = 6,              // face_count (468 or 478) image points
};
inline constexpr int k_frame_part_count = 7;

/// JSON key of a part in *.landmarks.jsonl ("pose", "pose_world", "left_hand", ...).
constexpr const char* frame_part_key(frame_part p) {
  constexpr const char* k_keys[k_frame_part_count] = {
      "pose",       "pose_world",       "left_hand", "left_hand_world",
      "right_hand", "right_hand_world", "face"};
  return k_keys[static_cast<int>(p)];
}

/// Points a part's storage in landmark_frame holds: 33 (body), 21 (a hand) or 478 (the face
/// mesh with iris; a 468-point face uses the first 468).
constexpr int frame_part_capacity(frame_part p) {
  switch (p) {
    case frame_part::pose:
    case frame_part::pose_world:
      return k_pose_landmark_count;
    case frame_part::face:
      return k_face_mesh_iris_count;
    default:
      return k_hand_landmark_count;
  }
}

/// The largest person id a landmark file may carry (docs/file-formats.md, version 2).
inline constexpr int k_max_person_id = 999999;

struct landmark_frame {
  double t = 0.0;           // capture time in seconds
  int person = 0;           // which person (0 .. k_max_person_id): several per time, version 2
  std::uint32_t parts = 0;  // bit (1 << frame_part) set for each part present
  int face_count = 0;       // 468 or 478 when the face part is present, else 0
  std::array<landmark, k_pose_landmark_count> pose{};
  std::array<landmark, k_pose_landmark_count> pose_world{};
  std::array<landmark, k_hand_landmark_count> left_hand{};
  std::array<landmark, k_hand_landmark_count> left_hand_world{};
  std::array<landmark, k_hand_landmark_count> right_hand{};
  std::array<landmark, k_hand_landmark_count> right_hand_world{};
  std::array<landmark, k_face_mesh_iris_count> face{};

  bool has(frame_part p) const { return (parts >> static_cast<int>(p)) & 1u; }
  /// The storage of part `p` (frame_part_capacity(p) points; meaningful when has(p)).
  landmark* points(frame_part p) {
    switch (p) {
      case frame_part::pose:
        return pose.data();
      case frame_part::pose_world:
        return pose_world.data();
      case frame_part::left_hand:
        return left_hand.data();
      case frame_part::left_hand_world:
        return left_hand_world.data();
      case frame_part::right_hand:
        return right_hand.data();
      case frame_part::right_hand_world:
        return right_hand_world.data();
      case frame_part::face:
        break;
    }
    return face.data();
  }
  const landmark* points(frame_part p) const {
    return const_cast<landmark_frame*>(this)->points(p);
  }
  void set(frame_part p, bool present) {
    std::uint32_t bit = 1u << static_cast<int>(p);
    parts = present ? (parts | bit) : (parts & ~bit);
  }
  /// Removes every part; keeps the storage.
  void clear() {
    t = 0.0;
    person = 0;
    parts = 0;
    face_count = 0;
  }
};

}  // namespace avatarmap
