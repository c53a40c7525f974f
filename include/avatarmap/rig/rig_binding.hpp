// Choosing how a rig's joints bind to the proxy bones, shared by the CLI (`--rig`) and the C
// API: "auto" (the file's own humanoid map for VRM, else the best mapping table of a folder),
// a table name (a table of that folder) or the path of a .json table.
#pragma once

#include <string>

#include "avatarmap/core/status.hpp"
#include "avatarmap/rig/mapping.hpp"
#include "avatarmap/rig/retarget.hpp"
#include "avatarmap/rig/rig.hpp"

namespace avatarmap {

/// The outcome of select_binding. Copyable: the table used is held by value.
struct rig_binding_choice {
  bool uses_table = false;  // false: the rig's declared humanoid (VRM) is used as is
  mapping_table table;      // the table used, when uses_table
  bone_binding binding{};   // rig joint per proxy bone, -1 when unbound
  int bound = 0;            // proxy bones bound
  std::string description;  // how the binding was made, for the user

  /// The table to give retargeter::build (its formulas), or null.
  const mapping_table* table_or_null() const { return uses_table ? &table : nullptr; }
};

/// Binds `r` according to `option`:
///  - "" or "auto": the humanoid the file declares when it binds the hips (VRM 0.x/1.0), else
///    the best-scoring table of `mappings_folder` (auto_detect);
///  - a name ending in ".json": the table at that path (its formulas apply);
///  - anything else: the table of `mappings_folder` whose "name" is `option`.
/// `mappings_folder` is only read when a table of it is needed. `out` is replaced. Errors say
/// what was tried (the rig's file, the table, missing required bones, the known table names);
/// their codes: io (the .json table or the tables' folder cannot be read, or no folder was
/// given), parse (a table is malformed; the table, or with "auto" every table, lacks required
/// bones of this rig), invalid_argument (`option` names no table of the folder). Never throws
/// but for std::bad_alloc.
status select_binding(const rig& r, const std::string& option, const std::string& mappings_folder,
                      rig_binding_choice& out);

}  // namespace avatarmap
