#include "avatarmap/rig/avatar_loader.hpp"

#include <cmath>
#include <cstdint>
#include <exception>
#include <limits>
#include <new>
#include <nlohmann/json.hpp>
#include <optional>
#include <string_view>
#include <utility>
#include <vector>

#include "avatarmap/rig/bvh_rig.hpp"
#include "common/file_extension.hpp"
#include "rig/gltf_document.hpp"

namespace avatarmap {

namespace {

using json = nlohmann::json;

// Member `key` of an object, or nullptr when `v` is not an object or has no such member.
const json* member(const json& v, const char* key) {
  if (!v.is_object()) return nullptr;
  const auto it = v.find(key);
  return it == v.end() ? nullptr : &*it;
}

// A JSON number that is a whole number (1 and 1.0 alike), as int64 (saturated far outside
// any index range, so that 2^40 stays 2^40 and is reported, never wraps to a valid index).
bool as_whole_number(const json& v, std::int64_t& out) {
  if (v.is_number_unsigned()) {
    const auto u = v.get<std::uint64_t>();
    out = u > static_cast<std::uint64_t>(std::numeric_limits<std::int64_t>::max())
              ? std::numeric_limits<std::int64_t>::max()
              : static_cast<std::int64_t>(u);
    return true;
  }
  if (v.is_number_integer()) {
    out = v.get<std::int64_t>();
    return true;
  }
  if (v.is_number_float()) {
    const double d = v.get<double>();
    if (!std::isfinite(d) || d != std::floor(d) || std::fabs(d) > 9e18) return false;
    out = static_cast<std::int64_t>(d);
    return true;
  }
  return false;
}

std::string in_quotes(const std::string& s) { return "'" + s + "'"; }

// VRM 0.x names the thumb's three joints Proximal/Intermediate/Distal where VRM 1.0 says
// Metacarpal/Proximal/Distal; every other 0.x name is the 1.0 name.
std::string vrm0_to_vrm1_name(const std::string& name) {
  for (const char* side : {"left", "right"}) {
    const std::string thumb = std::string(side) + "Thumb";
    if (name == thumb + "Proximal") return thumb + "Metacarpal";
    if (name == thumb + "Intermediate") return thumb + "Proximal";
  }
  return name;
}

// Reads `count` numbers of node property `key` into `out` (doubles). False (with
// `out_error`) when the property is present but not an array of `count` numbers; true and
// `present` false when it is absent.
bool numbers(const json& node, const char* key, std::size_t count, double* out, bool& present,
             std::string& out_error) {
  present = false;
  const json* v = member(node, key);
  if (!v) return true;
  if (!v->is_array() || v->size() != count) {
    out_error = std::string(key) + " has " +
                (v->is_array() ? std::to_string(v->size()) + " numbers" : "no array") +
                ", expected " + std::to_string(count) + " numbers";
    return false;
  }
  for (std::size_t i = 0; i < count; ++i) {
    if (!(*v)[i].is_number()) {
      out_error = std::string(key) + "[" + std::to_string(i) + "] is not a number";
      return false;
    }
    out[i] = (*v)[i].get<double>();
  }
  present = true;
  return true;
}

// Local rest transform from a glTF node's TRS or matrix; false (with `out_error`) when a
// property has the wrong shape or a matrix is singular. Zero or non-finite values pass:
// build_rig refuses them with the node's name.
bool node_transform(const json& node, transform& out, std::string& out_error) {
  double t[3], r[4], sc[3], mat[16];
  bool has_t = false, has_r = false, has_s = false, has_m = false;
  if (!numbers(node, "translation", 3, t, has_t, out_error) ||
      !numbers(node, "rotation", 4, r, has_r, out_error) ||
      !numbers(node, "scale", 3, sc, has_s, out_error) ||
      !numbers(node, "matrix", 16, mat, has_m, out_error))
    return false;
  out = transform{};
  if (has_m) {
    // Column-major, like glm. Decomposed as T * R * S; a shear, which TRS cannot hold, is lost.
    glm::dmat4 m;
    for (int c = 0; c < 4; ++c)
      for (int k = 0; k < 4; ++k) m[c][k] = mat[c * 4 + k];
    out.translation = glm::vec3(m[3]);
    glm::dmat3 basis(m);
    glm::dvec3 scale(glm::length(basis[0]), glm::length(basis[1]), glm::length(basis[2]));
    const double det = glm::determinant(basis);
    if (det < 0.0) scale.x = -scale.x;
    for (int c = 0; c < 3; ++c) {
      if (scale[c] != 0.0 && std::isfinite(scale[c]))
        basis[c] /= scale[c];
      else
        basis[c] = glm::dvec3(c == 0, c == 1, c == 2);
    }
    // Columns of non-zero length that are (nearly) parallel: the matrix has no inverse, and no
    // rotation describes it. (A zero column is left to build_rig's zero-scale check.)
    const double unit_det = glm::determinant(basis);
    if (std::isfinite(unit_det) && std::fabs(unit_det) < 1e-6) {
      out_error = "matrix is singular (its 3x3 part has no inverse)";
      return false;
    }
    out.scale = glm::vec3(scale);
    glm::dquat q = glm::quat_cast(basis);
    const double len2 = glm::dot(q, q);
    if (len2 > 0.0 && std::isfinite(len2)) q = glm::normalize(q);
    out.rotation = glm::quat(q);
    return true;
  }
  if (has_t)
    out.translation =
        glm::vec3(static_cast<float>(t[0]), static_cast<float>(t[1]), static_cast<float>(t[2]));
  if (has_r)  // glTF order: x, y, z, w; glm's constructor takes w first.
    out.rotation = glm::quat(static_cast<float>(r[3]), static_cast<float>(r[0]),
                             static_cast<float>(r[1]), static_cast<float>(r[2]));
  if (has_s)
    out.scale =
        glm::vec3(static_cast<float>(sc[0]), static_cast<float>(sc[1]), static_cast<float>(sc[2]));
  return true;
}

// Fills raw.declared_humanoid one entry at a time, rejecting what cannot be a humanoid map.
class humanoid_builder {
 public:
  humanoid_builder(raw_rig& raw, std::string where)
      : raw_(raw), where_(std::move(where)), bone_of_node_(raw.nodes.size(), -1) {}

  // `bone_name` is a VRM 1.0 name; `shown` is the name as the file spells it.
  status assign(const std::string& bone_name, const std::string& shown, const json* node) {
    const std::optional<bone> b = bone_from_name(bone_name);
    if (!b)
      return status::parse_error(where_ + ": humanoid bone " + in_quotes(shown) +
                                 " is not a VRM humanoid bone name");
    std::int64_t index = -1;
    if (!node || !as_whole_number(*node, index))
      return status::parse_error(where_ + ": humanoid bone " + in_quotes(shown) +
                                 " has no integer node index");
    const std::int64_t n = static_cast<std::int64_t>(raw_.nodes.size());
    if (index < 0 || index >= n)
      return status::parse_error(where_ + ": humanoid bone " + in_quotes(shown) + " names node " +
                                 std::to_string(index) + ", out of range (the file has " +
                                 std::to_string(n) + " nodes)");
    const int bi = idx(*b);
    if (raw_.declared_humanoid[bi] >= 0)
      return status::parse_error(where_ + ": humanoid bone " + in_quotes(shown) +
                                 " is declared twice");
    const int other = bone_of_node_[static_cast<size_t>(index)];
    if (other >= 0)
      return status::parse_error(where_ + ": node " + std::to_string(index) + " " +
                                 in_quotes(raw_.nodes[static_cast<size_t>(index)].name) +
                                 " is assigned to two humanoid bones, " +
                                 std::string(bone_name_of(other)) + " and " + bone_name);
    raw_.declared_humanoid[bi] = static_cast<int>(index);
    bone_of_node_[static_cast<size_t>(index)] = bi;
    return {};
  }

 private:
  static std::string_view bone_name_of(int b) { return bone_name(static_cast<bone>(b)); }

  raw_rig& raw_;
  std::string where_;
  std::vector<int> bone_of_node_;
};

// VRM 1.0 and VRM Animation: humanoid.humanBones {name: {node}}.
status read_vrm1_humanoid(const json& ext, const char* ext_name, raw_rig& raw) {
  const json* humanoid = member(ext, "humanoid");
  const json* bones = humanoid ? member(*humanoid, "humanBones") : nullptr;
  if (!bones || !bones->is_object())
    return status::parse_error(raw.file + ": " + ext_name +
                               " has no humanoid.humanBones object (expected {name: {node}})");
  humanoid_builder builder(raw, raw.file + ": " + ext_name);
  for (auto it = bones->begin(); it != bones->end(); ++it) {
    if (status s = builder.assign(it.key(), it.key(), member(it.value(), "node")); !s) return s;
  }
  return {};
}

// VRM 1.0 and VRM Animation: expressions.preset / expressions.custom {name: {...}}.
void read_vrm1_expressions(const json& ext, raw_rig& raw) {
  const json* expressions = member(ext, "expressions");
  if (!expressions) return;
  for (const char* group : {"preset", "custom"}) {
    const json* g = member(*expressions, group);
    if (!g || !g->is_object()) continue;
    for (auto it = g->begin(); it != g->end(); ++it) raw.expressions.push_back(it.key());
  }
}

// A member that is a string, or nullptr.
const std::string* string_member(const json& v, const char* key) {
  const json* m = member(v, key);
  return m && m->is_string() ? &m->get_ref<const std::string&>() : nullptr;
}

// VRM 0.x: humanoid.humanBones [{bone, node}], blendShapeMaster.blendShapeGroups[].
status read_vrm0(const json& ext, raw_rig& raw) {
  const json* humanoid = member(ext, "humanoid");
  const json* bones = humanoid ? member(*humanoid, "humanBones") : nullptr;
  if (!bones || !bones->is_array())
    return status::parse_error(raw.file +
                               ": VRM has no humanoid.humanBones array (expected [{bone, node}])");
  humanoid_builder builder(raw, raw.file + ": VRM");
  for (size_t i = 0; i < bones->size(); ++i) {
    const json& entry = (*bones)[i];
    const std::string* name = string_member(entry, "bone");
    if (!name)
      return status::parse_error(raw.file + ": VRM humanoid.humanBones[" + std::to_string(i) +
                                 "] has no bone name");
    if (status s = builder.assign(vrm0_to_vrm1_name(*name), *name, member(entry, "node")); !s)
      return s;
  }
  const json* master = member(ext, "blendShapeMaster");
  const json* groups = master ? member(*master, "blendShapeGroups") : nullptr;
  if (groups && groups->is_array()) {
    for (const json& g : *groups) {
      std::string name;
      const std::string* preset = string_member(g, "presetName");
      if (preset && !preset->empty() && *preset != "unknown")
        name = *preset;
      else if (const std::string* n = string_member(g, "name"))
        name = *n;
      if (name.empty()) continue;
      bool seen = false;
      for (const std::string& e : raw.expressions) seen = seen || e == name;
      if (!seen) raw.expressions.push_back(name);
    }
  }
  return {};
}

status load(const std::string& path, raw_rig& out) {
  gltf_detail::gltf_document doc;
  if (status s = gltf_detail::open_gltf_document(path, doc); !s) return s;
  // tinygltf checks the rest of the file (accessors, meshes, skins) and reads its buffers,
  // through our resolver; the skeleton itself is read from the checked JSON below, where
  // every index and number is ours to check.
  {
    tinygltf::Model model;
    if (status s = gltf_detail::parse_gltf_model(doc, model); !s) return s;
  }
  const json* nodes = member(doc.json, "nodes");
  if (nodes && !nodes->is_array())
    return status::parse_error(path + ": nodes is not an array; not a valid glTF file");
  const int n = nodes ? static_cast<int>(nodes->size()) : 0;  // below 2^31: checked on open

  // Nodes and their rest transforms.
  out.nodes.resize(static_cast<size_t>(n));
  for (int i = 0; i < n; ++i) {
    const json& node = (*nodes)[static_cast<size_t>(i)];
    raw_rig::node& r = out.nodes[static_cast<size_t>(i)];
    if (!node.is_object())
      return status::parse_error(path + ": node " + std::to_string(i) + " is not a JSON object");
    const std::string* name = string_member(node, "name");
    r.name = name && !name->empty() ? *name : "node" + std::to_string(i);
    std::string why;
    if (!node_transform(node, r.rest, why))
      return status::parse_error(path + ": node " + std::to_string(i) + " " + in_quotes(r.name) +
                                 ": " + why);
  }
  // Parents from the children lists.
  for (int i = 0; i < n; ++i) {
    const json* children = member((*nodes)[static_cast<size_t>(i)], "children");
    if (!children) continue;
    const std::string who = path + ": node " + std::to_string(i) + " " +
                            in_quotes(out.nodes[static_cast<size_t>(i)].name);
    if (!children->is_array())
      return status::parse_error(who + ": children must be an array of integer node indices");
    for (const json& child : *children) {
      std::int64_t c = -1;
      if (!(child.is_number_integer() || child.is_number_unsigned()) || !as_whole_number(child, c))
        return status::parse_error(who + ": children must be an array of integer node indices");
      if (c < 0 || c >= n)
        return status::parse_error(who + " lists child " + std::to_string(c) +
                                   ", out of range (the file has " + std::to_string(n) + " nodes)");
      if (c == i) return status::parse_error(who + " lists itself as a child");
      raw_rig::node& ch = out.nodes[static_cast<size_t>(c)];
      if (ch.parent >= 0 && ch.parent != i)
        return status::parse_error(path + ": node " + std::to_string(c) + " " + in_quotes(ch.name) +
                                   " is the child of two nodes (" + std::to_string(ch.parent) +
                                   " and " + std::to_string(i) + ")");
      ch.parent = i;
    }
  }

  // Humanoid and expressions from the VRM extensions.
  out.source = rig_source::gltf;
  const json* extensions = member(doc.json, "extensions");
  const json* ext = nullptr;
  status s;
  if (extensions && (ext = member(*extensions, "VRMC_vrm"))) {
    out.source = rig_source::vrm1;
    s = read_vrm1_humanoid(*ext, "VRMC_vrm", out);
    if (s) read_vrm1_expressions(*ext, out);
  } else if (extensions && (ext = member(*extensions, "VRM"))) {
    out.source = rig_source::vrm0;
    s = read_vrm0(*ext, out);
  } else if (extensions && (ext = member(*extensions, "VRMC_vrm_animation"))) {
    out.source = rig_source::vrm1;
    s = read_vrm1_humanoid(*ext, "VRMC_vrm_animation", out);
    if (s) read_vrm1_expressions(*ext, out);
  }
  return s;
}

}  // namespace

status load_avatar(const std::string& path, raw_rig& out) {
  out = raw_rig{};
  out.file = path;
  status s;
  try {
    // A BVH's HIERARCHY is a skeleton too (rig/bvh_rig.hpp): by the extension, any case.
    s = jobs_detail::ends_with_nocase(path, ".bvh") ? load_bvh_avatar(path, out) : load(path, out);
  } catch (const std::bad_alloc&) {  // e.g. a huge declared size
    s = status::out_of_memory(path + ": not enough memory to load the file");
  } catch (const std::exception&) {
    s = status::internal(path + ": cannot load the file (unexpected internal error)");
  }
  if (!s) {  // no half-filled rig on failure
    out = raw_rig{};
    out.file = path;
  }
  return s;
}

}  // namespace avatarmap
