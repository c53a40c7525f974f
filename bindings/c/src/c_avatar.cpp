// The C API's avatars: the mapping-tables folder (avm_set_mappings_folder) and loading and
// binding an avatar for the retargeter and for clips (c_avatar.hpp).
#include "c_avatar.hpp"

#include <cstdio>
#include <cstdlib>
#include <mutex>
#include <string>

#include "avatarmap/rig/avatar_loader.hpp"
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

// $AVATARMAP_MAPPINGS when set and not empty, else the folder given to
// avm_set_mappings_folder() ("" when none).
std::string current_mappings_folder() {
  if (const char* env = std::getenv("AVATARMAP_MAPPINGS"); env != nullptr && *env != '\0')
    return env;
  std::lock_guard<std::mutex> lock(mappings_mutex());
  return mappings_folder_slot();
}

avm_status binding_status(am::rig_binding_failure f) {
  switch (f) {
    case am::rig_binding_failure::io:
      return AVM_ERROR_IO;
    case am::rig_binding_failure::unknown_name:
      return AVM_ERROR_INVALID_ARGUMENT;
    case am::rig_binding_failure::bad_table:
    case am::rig_binding_failure::no_fit:
      return AVM_ERROR_PARSE;
    case am::rig_binding_failure::none:
      break;
  }
  return AVM_ERROR_INTERNAL;
}

bool file_readable(const std::string& path) {
  FILE* f = std::fopen(path.c_str(), "rb");
  if (f == nullptr) return false;
  std::fclose(f);
  return true;
}

}  // namespace

// Loads the avatar at `avatar_path` into `out_rig` and binds it as `mapping` says (NULL =
// "auto"). On failure returns the status and sets `msg` (naming the file).
avm_status load_bound_avatar(const char* avatar_path, const char* mapping, am::rig& out_rig,
                             am::rig_binding_choice& out_choice, std::string& msg) {
  am::raw_rig raw;
  am::status st = am::load_avatar(avatar_path, raw);
  if (!st.ok()) {
    msg = st.message();
    return file_readable(avatar_path) ? AVM_ERROR_PARSE : AVM_ERROR_IO;
  }
  st = am::build_rig(raw, out_rig);
  if (!st.ok()) {
    msg = st.message();
    return AVM_ERROR_PARSE;
  }
  const std::string option = mapping != nullptr ? mapping : "auto";
  const std::string folder = current_mappings_folder();
  st = am::select_binding(out_rig, option, folder, out_choice);
  if (!st.ok()) {
    msg = st.message();
    if (out_choice.failure == am::rig_binding_failure::io && folder.empty())
      msg = std::string(avatar_path) + ": mapping '" + option +
            "' needs the mapping tables: no mappings folder is set (set AVATARMAP_MAPPINGS or "
            "call avm_set_mappings_folder())";
    return binding_status(out_choice.failure);
  }
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
