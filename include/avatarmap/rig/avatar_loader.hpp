// Loading an avatar's skeleton from a glTF 2.0 file: plain glTF (.gltf text or .glb binary),
// VRM 0.x and 1.0 (.vrm) and VRM Animation (.vrma). Produces a raw_rig; build_rig then
// validates the hierarchy (cycles) and builds the runtime rig.
#pragma once

#include <string>

#include "avatarmap/core/status.hpp"
#include "avatarmap/rig/rig.hpp"

namespace avatarmap {

/// Reads every node of the glTF file at `path` into `out` (replaced; left empty but for
/// `file` on failure): its name ("node<i>" when the file gives none), its parent (from the
/// glTF `children` lists; -1 for roots) and its local rest transform (translation, rotation,
/// scale; a node given as a `matrix` is decomposed into them, a negative determinant becoming
/// a negative x scale, a shear dropped).
/// Node order and indices are the file's. Every node is included, not only skin joints,
/// because VRM humanoid bones may lie outside any skin.
///
/// Binary (GLB) or text glTF is chosen by the content, not the extension. `out.source` and
/// the humanoid map come from the file's extensions:
///  - `VRMC_vrm` (VRM 1.0): vrm1; `humanoid.humanBones {name: {node}}`; expressions are the
///    keys of `expressions.preset` then `expressions.custom` (each group in key order).
///  - `VRM` (VRM 0.x): vrm0; `humanoid.humanBones [{bone, node}]`, the 0.x thumb names
///    thumbProximal/Intermediate/Distal mapped to 1.0's thumbMetacarpal/Proximal/Distal;
///    expressions are `blendShapeMaster.blendShapeGroups[]`' presetName (or name when the
///    preset is "unknown" or absent), duplicates dropped.
///  - `VRMC_vrm_animation` (VRM Animation): read like VRM 1.0 (source vrm1).
///  - none of these: gltf, no humanoid bones, no expressions.
/// When a file carries both VRMC_vrm and VRM, VRM 1.0 wins. `out.file` is `path`.
///
/// A name ending in .bvh (any case) is read as a BVH skeleton instead (load_bvh_avatar,
/// rig/bvh_rig.hpp: the HIERARCHY's joints, rest = OFFSETs with zero rotations, units detected
/// from the height); its errors name the file and line.
///
/// The file is untrusted: before any parser that recurses sees it, it must keep the limits of
/// docs/security.md (at most 1 GiB, JSON nested at most 128 levels, a well-formed GLB
/// container, core indices within int, bufferViews inside their buffers, buffer and image URIs
/// inside the file's folder, data URIs at most 256 MiB). Images are never decoded.
///
/// Fails, with a message that starts with `path`, when the file cannot be read or is empty,
/// is neither binary glTF nor JSON, breaks one of those limits, is otherwise invalid glTF (the
/// reason is included, in our words), a node's `matrix` is singular, a node's transform has the
/// wrong number of components, a
/// child index is out of range or names the node itself, a node is the child of two parents,
/// a humanoid bone name is not a VRM bone (the name is quoted), a humanoid entry has no node
/// or a node index out of range, one bone is declared twice, or one node is assigned to two
/// bones. Parent cycles and non-finite transforms are not checked here: build_rig reports
/// them. Never throws; never crashes on malformed input.
status load_avatar(const std::string& path, raw_rig& out);

}  // namespace avatarmap
