// Conversions between the C API's frames and poses (avatarmap.h) and the library's types. None
// allocates; quaternions are copied component by component (store_xyzw), never memcpy'd.
#pragma once

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

}  // namespace avatarmap::c_api
