// A BVH file as an avatar and as motion (docs/avatar.md "BVH skeletons", docs/convert.md):
// its HIERARCHY becomes a rig (raw_rig; the joints named as in the file, the rest pose the
// OFFSETs with every channel rotation zero), and its MOTION becomes proxy poses by the inverse
// of the retargeter (rig/retarget_inverse.hpp) on that rig, bound by the mapping tables like
// any rig (cmu.json, mixamo.json, ...).
//
// Units: a BVH states none. The length unit is the one (metres, CMU units = 0.056444 m,
// centimetres or millimetres) that makes the rest pose's height (highest minus lowest joint or
// End Site) closest to 1.7 m, unless the caller gives metres_per_unit. Axes: Y up (the BVH
// convention); a rig facing +Z with its left at +X (CMU, Mixamo) is in VRM space as is.
// The floor: the rest pose is lifted so that its lowest joint or End Site (the toes' tips) stands
// at Y = 0, the rig's floor (raw_rig::floor_y), and the motion's
// root positions are taken as they are, in a world whose floor is Y = 0 (CMU and Mixamo exports
// stand on Y = 0).
#pragma once

#include <string>
#include <vector>

#include "avatarmap/core/status.hpp"
#include "avatarmap/export/bvh.hpp"
#include "avatarmap/rig/rig.hpp"
#include "avatarmap/skeleton/proxy_pose.hpp"

namespace avatarmap {

/// Metres per CMU unit: the CMU mocap database's length unit, (1 / 0.45) inch (its FAQ).
inline constexpr float k_cmu_metres_per_unit = 0.056444f;

/// The person height (metres) unit detection aims for.
inline constexpr float k_bvh_reference_height = 1.7f;

/// A BVH length unit: metres per file unit and its name ("centimetres").
struct bvh_length_unit {
  float metres_per_unit = 1.f;
  const char* name = "metres";
};

/// The rest pose's height in file units: highest minus lowest Y of the joints and End Sites
/// with every channel rotation zero (OFFSETs only). 0 for a clip without joints.
float bvh_rest_height(const bvh_clip& clip);

/// The unit among metres, CMU units (k_cmu_metres_per_unit), centimetres and millimetres that
/// makes bvh_rest_height closest to k_bvh_reference_height (by ratio). Metres when the height
/// is 0 or not finite.
bvh_length_unit detect_bvh_units(const bvh_clip& clip);

struct bvh_rig_options {
  /// Metres per file unit, > 0; 0 = detect_bvh_units.
  float metres_per_unit = 0.f;
};

/// Builds the rig of `clip`'s HIERARCHY into `out` (replaced): one node per joint, file order
/// and names, rest translation = OFFSET × metres per unit, rest rotation identity, scale 1;
/// every root lifted by the same height so that the lowest joint or End Site stands at Y = 0
/// (floor_y = 0). End Sites are not joints. source = unknown, no declared humanoid, no expressions;
/// out.file = `file`. `out_unit` (optional) gets the unit used. Fails (parse, naming `file`) when
/// the clip has no joints or metres_per_unit is negative or not finite; the names and the hierarchy
/// are build_rig's to check.
status bvh_rig_from_clip(const bvh_clip& clip, const std::string& file,
                         const bvh_rig_options& options, raw_rig& out,
                         bvh_length_unit* out_unit = nullptr);

/// read_bvh, then bvh_rig_from_clip: what load_avatar does with a .bvh.
status load_bvh_avatar(const std::string& path, raw_rig& out, const bvh_rig_options& options = {});

/// How read_bvh_motion reads.
struct bvh_motion_options {
  /// Metres per file unit, > 0; 0 = detect_bvh_units.
  float metres_per_unit = 0.f;
  /// The binding of the file's skeleton (select_binding: "auto", a table name, a .json table).
  std::string rig = "auto";
  /// The mapping tables' folder; "" = find_resource(resource::mappings).
  std::string mappings_folder;
};

/// What read_bvh_motion found.
struct bvh_motion_summary {
  bvh_length_unit unit;
  std::string binding;      // select_binding's description ("detected cmu: matched 23/23 bones")
  int bound = 0;            // proxy bones bound
  double frame_time = 0.0;  // seconds, as used (see read_bvh_motion)
};

/// Reads the BVH at `path` into proxy poses (`out`, replaced), one per frame at t = i ×
/// Frame Time (a Frame Time whose rate is within 1e-4 of a whole number of frames per second,
/// such as CMU's .0083333, is taken as exactly 1 / that number): the file's skeleton becomes a rig
/// (bvh_rig_from_clip), bound as `options.rig` says, and each frame's posed world rotations go
/// through the inverse of the retargeter (inverse_retargeter, with the performer's hips height =
/// the rig's, so hips_position is the root's position in metres, Y above the floor at the rest
/// pose's lowest foot/toe joint). Bound bones get confidence 1, the others 0 and an identity local
/// rotation. The root's position: its position channels, in metres; an axis without a channel keeps
/// the rest translation. When the hips joint is not a root, the hips keep their rest
/// translation (motion of the joints above the hips keeps only their rotations).
/// Fails with read_bvh's status (io; parse naming the file and line: truncated MOTION, a bad
/// or non-finite value, ...), build_rig's, select_binding's (parse with "auto": no table fits,
/// each table's missing bones listed; io: no tables' folder found), or parse "PATH: the
/// skeleton has no BONE ...: its motion needs both legs" when an upper leg, lower leg or foot
/// is unbound. `out` is empty on failure. Never throws but for std::bad_alloc.
status read_bvh_motion(const std::string& path, const bvh_motion_options& options,
                       std::vector<proxy_pose>& out, bvh_motion_summary* out_summary = nullptr);

}  // namespace avatarmap
