// Conversions between the C API's frames and poses (avatarmap.h) and the library's types. None
// allocates; quaternions are copied component by component (store_xyzw), never memcpy'd.
#pragma once

#include <array>

#include "avatarmap/avatarmap.h"
#include "avatarmap/landmarks/landmark_frame.hpp"
#include "avatarmap/skeleton/proxy_pose.hpp"

namespace avatarmap::c_api {

/// NULL when `f` can be converted, else a static message naming the bad field.
const char* check_frame(const avm_frame& f) noexcept;
/// The C frame as a landmark frame (parts whose pointer is NULL are absent).
void convert_frame(const avm_frame& f, landmark_frame& out) noexcept;
/// The proxy pose as a C pose.
void to_c_pose(const proxy_pose& p, avm_pose& out) noexcept;

/// Storage a C frame handed out by the library points into.
struct frame_storage {
  std::array<avm_landmark, AVM_POSE_LANDMARK_COUNT> pose, pose_world;
  std::array<avm_landmark, AVM_HAND_LANDMARK_COUNT> left_hand, left_hand_world, right_hand,
      right_hand_world;
  std::array<avm_landmark, AVM_FACE_IRIS_LANDMARK_COUNT> face;
};
/// The landmark frame as a C frame whose arrays are in `storage` (NULL for absent parts).
void to_c_frame(const landmark_frame& in, frame_storage& storage, avm_frame& out) noexcept;

}  // namespace avatarmap::c_api
