// Loading and binding an avatar for the C API (the retargeter handle and clip writing), with
// the mapping tables from $AVATARMAP_MAPPINGS or avm_set_mappings_folder().
#pragma once

#include <string>

#include "avatarmap/avatarmap.h"
#include "avatarmap/rig/rig.hpp"
#include "avatarmap/rig/rig_binding.hpp"

namespace avatarmap::c_api {

/// Loads the avatar at `avatar_path` into `out_rig` and binds it as `mapping` says (NULL =
/// "auto"). On failure returns the status and sets `msg` (naming the file).
avm_status load_bound_avatar(const char* avatar_path, const char* mapping, rig& out_rig,
                             rig_binding_choice& out_choice, std::string& msg);

}  // namespace avatarmap::c_api
