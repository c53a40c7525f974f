// Loading and binding an avatar for the C API (the retargeter handle and clip writing), with
// the mapping tables found as io/resources.hpp says (avm_set_mappings_folder() is its explicit
// folder).
#pragma once

#include <string>

#include "avatarmap/avatarmap.h"
#include "avatarmap/rig/bound_avatar.hpp"
#include "avatarmap/rig/rig.hpp"
#include "avatarmap/rig/rig_binding.hpp"

namespace avatarmap::c_api {

/// The folder given to avm_set_mappings_folder() ("" when none): find_resource()'s explicit
/// folder for the mapping tables.
std::string given_mappings_folder();

/// Loads, builds and binds the avatar at `avatar_path` as `mapping` says (NULL = "auto"): the
/// library's bind_avatar (as the CLI's `convert --avatar --rig`), with the mappings folder
/// above. On failure returns the status and sets `msg` (naming the file).
avm_status bind_c_avatar(const char* avatar_path, const char* mapping, bound_avatar& out,
                         std::string& msg);

/// bind_c_avatar, keeping the rig and the binding (the retargeter's handle).
avm_status load_bound_avatar(const char* avatar_path, const char* mapping, rig& out_rig,
                             rig_binding_choice& out_choice, std::string& msg);

}  // namespace avatarmap::c_api
