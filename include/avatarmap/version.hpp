// Library version. The C API exposes the same numbers (avm_version()).
#pragma once

#define AVATARMAP_VERSION_MAJOR 0
#define AVATARMAP_VERSION_MINOR 2
#define AVATARMAP_VERSION_PATCH 0
#define AVATARMAP_VERSION_STRING "0.2.0"

namespace avatarmap {
inline constexpr int k_version_major = AVATARMAP_VERSION_MAJOR;
inline constexpr int k_version_minor = AVATARMAP_VERSION_MINOR;
inline constexpr int k_version_patch = AVATARMAP_VERSION_PATCH;
}  // namespace avatarmap
