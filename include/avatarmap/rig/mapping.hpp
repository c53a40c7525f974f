// Mapping tables: data files (mappings/*.json, format in docs/mappings.md, schema in
// mappings/schema.json) that say how a rig family names the 55 VRM 1.0 humanoid bones, how
// to recognise it, and optionally, per bone, SysMocap-style formulas that turn the proxy's
// Euler angles into the rig bone's. Loading validates the file and compiles it once into a
// mapping_table (names resolved to bone indices, formulas compiled); matching a table against
// a rig resolves each proxy bone to a rig joint index once. Nothing here runs per frame
// except formula evaluation (formula.hpp).
#pragma once

#include <array>
#include <cstdint>
#include <glm/glm.hpp>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "avatarmap/core/euler.hpp"
#include "avatarmap/core/status.hpp"
#include "avatarmap/rig/formula.hpp"
#include "avatarmap/rig/rig.hpp"
#include "avatarmap/skeleton/bone.hpp"

namespace avatarmap {

/// The mapping file format version this library reads (and the newest it accepts).
inline constexpr int k_mapping_format_version = 1;

/// The rig's rest pose as the table declares it: T-pose, A-pose (arms down ~45°: the
/// retargeter straightens them), or "file" (use the rest pose stored in the model as is).
enum class mapping_rest_pose : std::uint8_t { t_pose, a_pose, file };

/// Which humanoid declaration a table trusts instead of names (VRM files declare their bones
/// in an extension, so node names do not matter there).
enum class mapping_humanoid : std::uint8_t { none, vrm0, vrm1 };

/// One proxy bone's entry of a compiled table.
struct mapping_bone {
  /// Rig joint names (without prefix), tried in order; empty: the rig family has no such bone.
  std::vector<std::string> rig_names;
  /// Euler order of the formulas: the proxy's local rotation is read as Euler angles (x, y,
  /// z) in this order, and the formulas' results are composed in this order (SysMocap's
  /// "order"; default XYZ, three.js's and SysMocap's default).
  euler_order order = euler_order::xyz;
  /// Euler order the formulas' results (added to the rest angles) are composed in, for rigs
  /// whose bone axes call for another order than the proxy's ("target_order"; default:
  /// `order`, as SysMocap does).
  euler_order target_order = euler_order::xyz;
  /// True when the file gives "f": the formulas replace the default rest-aware conversion.
  bool has_formulas = false;
  /// fx, fy, fz: compiled formulas (empty unless has_formulas).
  std::array<formula, 3> f;
  /// The formulas' source text (for messages and export).
  std::array<std::string, 3> f_text;
  /// True when "rest" is given: Euler angles (radians, in `target_order`) replacing the rig bone's
  /// own rest rotation as the base the formulas' results are added to (SysMocap's "init").
  bool has_rest = false;
  glm::vec3 rest{0.f};

  bool mapped() const { return !rig_names.empty(); }
};

/// A compiled mapping table. Immutable after loading; share it freely between threads.
struct mapping_table {
  std::string name;
  std::string description;
  std::string file;  // where it was loaded from ("" for in-memory tables), for messages
  /// Name prefixes the rig may carry (e.g. "mixamorig:"); a name without any prefix is always
  /// tried too. Longest first.
  std::vector<std::string> prefixes;
  /// Bones that must resolve for the table to be usable (bone indices, ascending).
  std::vector<int> required;
  /// Name patterns ('*' matches any run of characters, case-sensitive, matched against full
  /// joint names) characteristic of the family: each matching at least one joint raises the
  /// table's score (e.g. "spine_05" tells UE5 from UE4).
  std::vector<std::string> patterns;
  mapping_humanoid humanoid = mapping_humanoid::none;
  mapping_rest_pose rest_pose = mapping_rest_pose::t_pose;
  /// Scale of the rig's units to metres when the file states it (Mixamo: 0.01), else 1.
  float units_scale = 1.f;
  bool has_units_scale = false;
  std::array<mapping_bone, k_bone_count> bones;
  /// VRM 1.0 expression name (or one of the project's custom brow expressions) -> the rig's
  /// blend shape / expression name, sorted by VRM name.
  std::vector<std::pair<std::string, std::string>> expressions;

  /// Number of bones the table maps.
  int mapped_count() const;
};

/// Loads and compiles a mapping file. Errors name the file and the key, e.g.
/// "mappings/x.json: bones.leftHand.f[1]: column 3: expected ...". Fails on: unreadable file,
/// invalid JSON, missing or non-integer "format_version", a version newer than
/// k_mapping_format_version, missing "name" or "bones", unknown keys (keys starting with '$'
/// are allowed, e.g. "$schema"), an unknown VRM bone or expression name, a rig name used by
/// two bones, an empty rig name, a bad Euler order, a formula that does not compile, an
/// "f" without exactly three formulas, a required bone the table does not map, a bad
/// "rest_pose", a non-positive "units_scale".
status load_mapping(const std::string& path, mapping_table& out);

/// As load_mapping, from text; `name` stands for the file in messages and fills `file`.
status load_mapping_json(std::string_view json, const std::string& name, mapping_table& out);

/// Loads every *.json file of `folder` except schema.json, sorted by file name.
status load_mapping_folder(const std::string& folder, std::vector<mapping_table>& out);

/// How a table resolves against one rig.
struct mapping_match {
  /// Rig joint index per proxy bone, -1 when unresolved (same layout as bone_binding).
  std::array<int, k_bone_count> joint;
  int matched = 0;  // bones resolved
  int needed = 0;   // bones the table maps
  int exact = 0;    // resolved by exact name (after prefix stripping)
  int folded = 0;   // resolved only case-insensitively
  int patterns_matched = 0;
  std::string prefix;                 // the prefix most resolved names carried ("" for none)
  std::vector<int> missing_required;  // required bones not resolved, ascending
  std::vector<int> missing;           // mapped bones not resolved (required or not)

  mapping_match() { joint.fill(-1); }
  /// True when every required bone resolved.
  bool usable() const { return missing_required.empty() && matched > 0; }
  /// "matched 52/55 bones (missing: leftEye, rightEye, jaw)" and the like.
  std::string summary() const;
};

/// Resolves `table` against `r` into `out` and returns its score: 0 when the table is unusable
/// (a required bone missing, or nothing resolved), else 1 + 2*exact + folded +
/// 4*patterns_matched. Name resolution: for each rig joint, the longest of the table's
/// prefixes it starts with is stripped; for each proxy bone, its rig names are tried in order,
/// first exactly, then ASCII case-insensitively; a joint is given to one bone at most. A table
/// with a humanoid declaration ("vrm0"/"vrm1") uses r.declared_humanoid instead when r.source
/// is that VRM version, and scores 0 on a rig of the other VRM version.
int match_score(const mapping_table& table, const rig& r, mapping_match& out);

/// Picks the table with the highest score for `r` (ties: the earlier table). `out_best` gets
/// its index and `out_match` its match. Fails, listing each table's missing required bones,
/// when no table is usable or `tables` is empty.
status auto_detect(const std::vector<mapping_table>& tables, const rig& r, int& out_best,
                   mapping_match& out_match);

/// Imports SysMocap's binding table (its models.json "binding" object) as a mapping table.
/// Accepted shapes: the binding object itself; one model entry {"name", "binding", "init"?};
/// or the models.json array, when exactly one entry has a "binding". Binding keys are
/// SysMocap's bone names: PascalCase VRM 0.x names ("Hips", "LeftUpperArm",
/// "LeftThumbProximal" = VRM 1.0 leftThumbMetacarpal) or camelCase VRM 1.0 names
/// ("leftThumbMetacarpal"). Each entry: {"name": rig joint name (full, prefix included) or
/// "None" (unbound), "order"?: "XYZ"..., "func"?: {"fx", "fy", "fz"}}. The model's "init"
/// (rest Euler angles per bone) becomes the bones' "rest". The result has no prefixes, no
/// required bones (SysMocap binds what it lists) and rest_pose "file". Errors name the key.
status import_sysmocap_binding(std::string_view json, mapping_table& out);

/// Writes `table` as a format_version 1 mapping file (pretty-printed JSON), e.g. to save an
/// imported SysMocap binding. load_mapping_json of the result gives back an equal table.
std::string mapping_to_json(const mapping_table& table);

}  // namespace avatarmap
