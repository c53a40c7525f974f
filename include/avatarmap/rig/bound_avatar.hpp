// An avatar ready to be driven, in one call: its file loaded (load_avatar), its rig built
// (build_rig), its joints bound to the proxy bones as a `--rig` option says (select_binding:
// auto, a table name or a .json table) with `--bind BONE=JOINT` overrides on top, and a
// sentence that says how it was bound. Written once for every caller: `convert` (through
// convert_file_job), `inspect`, `live --vmc`, `demo` and the C API (avm_retargeter_create,
// avm_clip_write, avm_convert_file).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "avatarmap/core/status.hpp"
#include "avatarmap/rig/mapping.hpp"
#include "avatarmap/rig/retarget.hpp"
#include "avatarmap/rig/rig.hpp"
#include "avatarmap/rig/rig_binding.hpp"
#include "avatarmap/skeleton/bone.hpp"

namespace avatarmap {

/// One `--bind BONE=JOINT`: a proxy bone and the rig joint that drives it ("none": unbound).
struct bone_override {
  bone proxy_bone = bone::hips;
  std::string joint;  // a joint name of the rig, or "none"
};

/// Parses "BONE=JOINT" (BONE a VRM 1.0 bone name, JOINT a joint name or "none") into `out`.
/// Fails (invalid_argument) with "BONE=JOINT wants a VRM 1.0 bone name (hips, leftUpperArm,
/// ...), got 'TEXT'" when there is no '=' or BONE is no bone name. Which joints exist is only
/// known once the avatar is loaded: bind_avatar checks JOINT.
status parse_bone_override(const std::string& text, bone_override& out);

/// How bind_avatar binds.
struct bind_avatar_options {
  /// The binding (select_binding): "auto" or "" (the humanoid a VRM declares, else the best
  /// table of the mappings folder), a table name of that folder, or the path of a .json table.
  std::string rig = "auto";
  /// Applied in order after the binding: each binds its bone to its joint (a joint drives one
  /// bone: taking it unbinds the bone that had it) or unbinds it ("none"). With rig "auto" and
  /// at least one override, a rig that no table fits is bound by the overrides alone.
  std::vector<bone_override> overrides;
  /// The mapping tables' folder; "" = find_resource(resource::mappings) (io/resources.hpp).
  std::string mappings_folder;
  /// What the report and the messages call the overrides (the CLI says "--bind").
  std::string overrides_name = "overrides";
};

/// The step of bind_avatar that failed.
enum class bind_avatar_step : std::uint8_t {
  none,
  load,       // the file cannot be read or is no valid glTF/VRM (load_avatar)
  build,      // its skeleton is malformed (build_rig)
  select,     // the binding (select_binding): a table unknown, unreadable, malformed or unfit
  overrides,  // an override names a joint the rig lacks
};

/// An avatar with its rig and binding. Large (the table is held by value): keep it on the heap
/// or in one place. Immutable once bound; share it read-only between threads.
struct bound_avatar {
  std::string path;           // the file it was loaded from
  avatarmap::rig rig;         // its runtime rig (set from the `build` step on, even when later
                              // steps fail: `inspect` lists a rig no table fits)
  rig_binding_choice choice;  // what select_binding chose (its table, when one was used)
  bone_binding binding{};     // rig joint per proxy bone after the overrides, -1 when unbound
  int bound = 0;              // proxy bones bound
  /// How it was bound, for the user: select_binding's description ("VRM 1.0 humanoid declared
  /// by the file (53 bones)", "detected mixamo: matched 52/52 bones ...") and "; N binding(s)
  /// from OVERRIDES" when overrides were given, or "bound by OVERRIDES only (no table fits)".
  std::string description;
  /// The mapping tables' folder find_resource gave ("" when none was found; read only when
  /// the binding needed a table of it).
  std::string mappings_folder;
  /// Where bind_avatar stopped (none on success).
  bind_avatar_step failed_step = bind_avatar_step::none;

  /// The table whose formulas the retargeter takes (retargeter::build), or null.
  const mapping_table* table() const { return choice.table_or_null(); }
};

/// Loads the avatar at `path` (.vrm, .glb, .gltf), builds its rig and binds it as `options`
/// say, into `out` (replaced). Fails with the failing step's status (its code kept; messages
/// name the file, the table, the missing bones, or the override and the joint) and
/// out.failed_step set: load (io: cannot be read; parse: not a valid avatar), build (parse),
/// select (io: a table or the tables' folder cannot be read, or none was found; parse: a
/// table is malformed or does not fit, or with "auto" no table fits; invalid_argument: the
/// option names no table), overrides (invalid_argument: "PATH: OVERRIDES BONE=JOINT: the
/// avatar has no joint 'JOINT'"). Reads files only; thread-safe. Never throws but for
/// std::bad_alloc.
status bind_avatar(const std::string& path, const bind_avatar_options& options, bound_avatar& out);

}  // namespace avatarmap
