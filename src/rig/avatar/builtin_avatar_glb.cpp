// The built-in avatar as a VRM 1.0 file: glTF JSON and BIN chunk through the shared GLB builder
// (export_detail::glb_builder), then an atomic write. See
// include/avatarmap/avatar/builtin_avatar.hpp and docs/avatar.md.
#include <exception>
#include <new>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "avatarmap/avatar/builtin_avatar.hpp"
#include "common/atomic_file.hpp"
#include "rig/export/glb_builder.hpp"

namespace avatarmap {
namespace {

using json = nlohmann::json;
using export_detail::glb_builder;

// VRM 1.0 requires meta.licenseUrl to be the VRM Public License 1.0's address; the licence's
// settings below are the project's choice for its own asset (docs/avatar.md).
constexpr const char* k_vrm_licence_url = "https://vrm.dev/licenses/1.0/";

std::vector<float> flatten(const std::vector<glm::vec3>& v) {
  std::vector<float> out;
  out.reserve(v.size() * 3);
  for (const glm::vec3& p : v) out.insert(out.end(), {p.x, p.y, p.z});
  return out;
}

json primitive_json(const avatar_primitive& p, glb_builder& bin) {
  using export_detail::k_target_indices;
  using export_detail::k_target_vertices;
  json attributes = {
      {"POSITION", bin.add_floats(flatten(p.positions), "VEC3", 3, true, k_target_vertices)},
      {"NORMAL", bin.add_floats(flatten(p.normals), "VEC3", 3, false, k_target_vertices)}};
  if (!p.colors.empty())
    attributes["COLOR_0"] = bin.add_floats(flatten(p.colors), "VEC3", 3, false, k_target_vertices);
  std::vector<std::uint32_t> joints;
  joints.reserve(p.joints.size() * 4);
  for (const auto& j : p.joints) joints.insert(joints.end(), j.begin(), j.end());
  attributes["JOINTS_0"] = bin.add_unsigned(joints, export_detail::k_component_ubyte, "VEC4", 4,
                                            false, k_target_vertices);
  std::vector<float> weights;
  weights.reserve(p.weights.size() * 4);
  for (const glm::vec4& w : p.weights) weights.insert(weights.end(), {w.x, w.y, w.z, w.w});
  attributes["WEIGHTS_0"] = bin.add_floats(weights, "VEC4", 4, false, k_target_vertices);
  const int index_type = p.positions.size() <= 65535 ? export_detail::k_component_ushort
                                                     : export_detail::k_component_uint;
  json prim = {
      {"attributes", attributes},
      {"indices", bin.add_unsigned(p.indices, index_type, "SCALAR", 1, false, k_target_indices)},
      {"material", p.material},
      {"mode", 4}};
  if (!p.targets.empty()) {
    json targets = json::array();
    for (const std::vector<glm::vec3>& t : p.targets)
      targets.push_back(
          {{"POSITION", bin.add_floats(flatten(t), "VEC3", 3, true, k_target_vertices)}});
    prim["targets"] = std::move(targets);
  }
  return prim;
}

status encode_impl(const builtin_avatar& a, std::string& out) {
  json doc = json::object();
  glb_builder bin(doc);

  // Nodes 0..54: the bones, rest translation = offset from the parent joint, no rotation.
  json nodes = json::array();
  for (int b = 0; b < k_bone_count; ++b) {
    const int parent = bone_parent(b);
    const glm::vec3 t = parent == k_no_parent ? a.joints[b] : a.joints[b] - a.joints[parent];
    nodes.push_back(
        {{"name", std::string(bone_name(static_cast<bone>(b)))}, {"translation", {t.x, t.y, t.z}}});
  }
  for (int b = 0; b < k_bone_count; ++b)
    if (bone_parent(b) != k_no_parent) nodes[bone_parent(b)]["children"].push_back(b);
  // Skinned mesh nodes: scene roots without a transform, as glTF asks.
  std::vector<int> mesh_nodes;
  for (std::size_t m = 0; m < a.meshes.size(); ++m) {
    mesh_nodes.push_back(static_cast<int>(nodes.size()));
    nodes.push_back({{"name", a.meshes[m].name}, {"mesh", m}, {"skin", 0}});
  }

  // The skin: every bone, inverse bind matrices = inverse of the rest world matrices (pure
  // translations: the rest rotations are identity), column-major.
  std::vector<float> ibm;
  std::vector<int> joints;
  for (int b = 0; b < k_bone_count; ++b) {
    const glm::vec3& p = a.joints[b];
    ibm.insert(ibm.end(),
               {1.f, 0.f, 0.f, 0.f, 0.f, 1.f, 0.f, 0.f, 0.f, 0.f, 1.f, 0.f, -p.x, -p.y, -p.z, 1.f});
    joints.push_back(b);
  }
  json skin = {{"name", "humanoid"},
               {"joints", joints},
               {"skeleton", idx(bone::hips)},
               {"inverseBindMatrices", bin.add_floats(ibm, "MAT4", 16, false)}};

  json meshes = json::array();
  for (const avatar_mesh& m : a.meshes) {
    json primitives = json::array();
    for (const avatar_primitive& p : m.primitives) primitives.push_back(primitive_json(p, bin));
    json mesh = {{"name", m.name}, {"primitives", std::move(primitives)}};
    if (!m.target_names.empty()) {
      mesh["weights"] = std::vector<float>(m.target_names.size(), 0.f);
      mesh["extras"] = {{"targetNames", m.target_names}};  // names for viewers (three.js)
    }
    meshes.push_back(std::move(mesh));
  }

  json materials = json::array();
  for (const avatar_material& m : a.materials)
    materials.push_back(
        {{"name", m.name},
         {"pbrMetallicRoughness",
          {{"baseColorFactor", {m.base_color.r, m.base_color.g, m.base_color.b, m.base_color.a}},
           {"metallicFactor", 0.0},
           {"roughnessFactor", m.roughness}}}});

  // VRMC_vrm: meta, every humanoid bone, lookAt by the eye bones, first-person hints,
  // expressions bound to the face's morph targets.
  json human_bones = json::object();
  for (int b = 0; b < k_bone_count; ++b)
    human_bones[std::string(bone_name(static_cast<bone>(b)))] = {{"node", b}};
  json preset = json::object(), custom = json::object();
  for (const avatar_expression& e : a.expressions) {
    json binds = json::array();
    for (const avatar_expression::bind& b : e.binds)
      binds.push_back({{"node", mesh_nodes[static_cast<std::size_t>(b.mesh)]},
                       {"index", b.target},
                       {"weight", b.weight}});
    json expr = {{"morphTargetBinds", std::move(binds)},
                 {"isBinary", false},
                 {"overrideBlink", "none"},
                 {"overrideLookAt", "none"},
                 {"overrideMouth", "none"}};
    (e.preset ? preset : custom)[e.name] = std::move(expr);
  }
  const glm::vec3 eyes = 0.5f * (a.joints[idx(bone::left_eye)] + a.joints[idx(bone::right_eye)]) -
                         a.joints[idx(bone::head)];
  const json range = {{"inputMaxValue", 90.0}, {"outputScale", 10.0}};
  json vrm = {{"specVersion", "1.0"},
              {"meta",
               {{"name", a.options.name},
                {"version", "1"},
                {"authors", json::array({"avatarmap"})},
                {"copyrightInformation", "Generated by avatarmap; no third-party assets"},
                {"licenseUrl", k_vrm_licence_url},
                {"avatarPermission", "everyone"},
                {"allowExcessivelyViolentUsage", false},
                {"allowExcessivelySexualUsage", false},
                {"commercialUsage", "corporation"},
                {"allowPoliticalOrReligiousUsage", false},
                {"allowAntisocialOrHateUsage", false},
                {"creditNotation", "unnecessary"},
                {"allowRedistribution", true},
                {"modification", "allowModificationRedistribution"}}},
              {"humanoid", {{"humanBones", human_bones}}},
              {"firstPerson",
               {{"meshAnnotations",
                 {{{"node", mesh_nodes[0]}, {"type", "auto"}},
                  {{"node", mesh_nodes[1]}, {"type", "thirdPersonOnly"}}}}}},
              {"lookAt",
               {{"offsetFromHeadBone", {eyes.x, eyes.y, eyes.z}},
                {"type", "bone"},
                {"rangeMapHorizontalInner", range},
                {"rangeMapHorizontalOuter", range},
                {"rangeMapVerticalDown", range},
                {"rangeMapVerticalUp", range}}},
              {"expressions", {{"preset", preset}, {"custom", custom}}}};

  std::vector<int> roots = {idx(bone::hips)};
  roots.insert(roots.end(), mesh_nodes.begin(), mesh_nodes.end());
  doc["asset"] = {{"version", "2.0"}, {"generator", "avatarmap (built-in avatar)"}};
  doc["extensionsUsed"] = json::array({"VRMC_vrm"});
  doc["extensions"] = {{"VRMC_vrm", std::move(vrm)}};
  doc["scene"] = 0;
  doc["scenes"] = json::array({json{{"name", "avatar"}, {"nodes", roots}}});
  doc["nodes"] = std::move(nodes);
  doc["skins"] = json::array({std::move(skin)});
  doc["meshes"] = std::move(meshes);
  doc["materials"] = std::move(materials);
  return export_detail::make_glb(doc, bin.bytes(), "the built-in avatar", out);
}

}  // namespace

status encode_builtin_avatar(const builtin_avatar& avatar, std::string& out) {
  if (avatar.meshes.size() != 2)
    return status::error(
        "the built-in avatar needs its two meshes (Body, Face); build it with "
        "make_builtin_avatar");
  try {
    return encode_impl(avatar, out);
  } catch (const std::bad_alloc&) {
    return status::out_of_memory("not enough memory to encode the built-in avatar");
  } catch (const std::exception& e) {
    return status::error(std::string("cannot encode the built-in avatar: ") + e.what());
  }
}

status builtin_avatar_glb(const builtin_avatar_options& options, std::string& out) {
  builtin_avatar a;
  if (status s = make_builtin_avatar(options, a); !s) return s;
  return encode_builtin_avatar(a, out);
}

status write_builtin_avatar(const std::string& path, const builtin_avatar_options& options) {
  std::string bytes;
  if (status s = builtin_avatar_glb(options, bytes); !s)
    return s.is_out_of_memory() ? s : s.prefixed(path + ": ");
  try {
    return io_detail::write_file_atomically(path, bytes);
  } catch (const std::bad_alloc&) {
    return status::out_of_memory(path + ": not enough memory to write the built-in avatar");
  }
}

}  // namespace avatarmap
