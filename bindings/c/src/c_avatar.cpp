// The C API's avatars: the mapping-tables folder (avm_set_mappings_folder) and loading and
// binding an avatar for the retargeter and for clips (c_avatar.hpp).
#include "c_avatar.hpp"

#include <cstdio>
#include <mutex>
#include <string>

#include "avatarmap/rig/bound_avatar.hpp"
#include "c_guard.hpp"

namespace am = avatarmap;

namespace avatarmap::c_api {

namespace {

// The folder given to avm_set_mappings_folder(); function-local statics so that a call made
// during another translation unit's static initialisation still finds them constructed.
std::mutex& mappings_mutex() {
  static std::mutex m;
  return m;
}
std::string& mappings_folder_slot() {
  static std::string folder;
  return folder;
}

}  // namespace

std::string given_mappings_folder() {
  std::lock_guard<std::mutex> lock(mappings_mutex());
  return mappings_folder_slot();
}

avm_status bind_c_avatar(const char* avatar_path, const char* mapping, am::bound_avatar& out,
                         std::string& msg) {
  am::bind_avatar_options options;
  options.rig = mapping != nullptr ? mapping : "auto";
  // io/resources.hpp's order: the folder given to avm_set_mappings_folder(), else
  // $AVATARMAP_MAPPINGS, else the installed tables, else the source tree's.
  options.mappings_folder = given_mappings_folder();
  const am::status st = am::bind_avatar(avatar_path, options, out);
  if (st.ok()) return AVM_OK;
  msg = st.message();
  if (out.failed_step == am::bind_avatar_step::select && st.code() == am::status_code::io &&
      out.mappings_folder.empty())
    msg = std::string(avatar_path) + ": mapping '" + options.rig +
          "' needs the mapping tables: no mappings folder was found (set AVATARMAP_MAPPINGS "
          "or call avm_set_mappings_folder())";
  return avm_code(st);  // io (cannot be read), parse (not a valid avatar; a table), ...
}

avm_status load_bound_avatar(const char* avatar_path, const char* mapping, am::rig& out_rig,
                             am::rig_binding_choice& out_choice, std::string& msg) {
  am::bound_avatar avatar;
  const avm_status code = bind_c_avatar(avatar_path, mapping, avatar, msg);
  if (code != AVM_OK) return code;
  out_rig = std::move(avatar.rig);
  out_choice = std::move(avatar.choice);  // no overrides: its binding is the avatar's
  return AVM_OK;
}

}  // namespace avatarmap::c_api

using namespace avatarmap::c_api;

extern "C" {

AVATARMAP_C_API avm_status avm_set_mappings_folder(const char* folder) {
  return guard("avm_set_mappings_folder", silently, [&]() -> avm_status {
    std::string copy = folder != nullptr ? folder : "";
    std::lock_guard<std::mutex> lock(mappings_mutex());
    mappings_folder_slot().swap(copy);
    return AVM_OK;
  });
}

}  // extern "C"
