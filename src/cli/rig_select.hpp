// Choosing how a rig's joints bind to the proxy bones, for `convert` and `inspect`:
// --rig auto (the file's own humanoid map for VRM, else the best shipped mapping table),
// --rig NAME (a shipped table by name) or --rig FILE.json (a table of the user's). A thin
// wrapper over the library's select_binding (avatarmap/rig/rig_binding.hpp) that knows where
// the CLI finds the shipped tables.
#pragma once

#include <string>

#include "avatarmap/core/status.hpp"
#include "avatarmap/rig/mapping.hpp"
#include "avatarmap/rig/retarget.hpp"
#include "avatarmap/rig/rig.hpp"
#include "avatarmap/rig/rig_binding.hpp"

namespace avatarmap::cli {

struct rig_selection {
  rig_binding_choice choice;             // what select_binding chose (owns the table)
  const mapping_table* table = nullptr;  // the table used; null: the file's declared humanoid
  bone_binding binding{};
  int bound = 0;            // proxy bones bound
  std::string description;  // how the binding was made, for the user

  rig_selection() = default;
  rig_selection(const rig_selection&) = delete;  // `table` points into `choice`
  rig_selection& operator=(const rig_selection&) = delete;
};

/// Where the shipped tables are: $AVATARMAP_MAPPINGS, else the source tree's mappings/ (a
/// build run in place), else the installed share/avatarmap/mappings.
std::string mappings_folder();

/// Binds `r` according to `option` ("auto", a table name, or a .json path). Errors say what
/// was tried and list missing required bones.
status select_rig_binding(const rig& r, const std::string& option, rig_selection& out);

}  // namespace avatarmap::cli
