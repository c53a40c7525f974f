#include "avatarmap/rig/avatar_loader.hpp"

#include <tiny_gltf.h>

#include <cmath>
#include <cstdint>
#include <exception>
#include <fstream>
#include <limits>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>
#include <string_view>
#include <utility>
#include <vector>

namespace avatarmap {

namespace {

using tinygltf::Value;

// The skeleton needs no pixels: keep tinygltf from decoding every texture (slow, and a broken
// image would fail the whole load).
bool skip_image(tinygltf::Image*, const int, std::string*, std::string*, int, int,
                const unsigned char*, int, void*) {
  return true;
}

// Member `key` of an object, or nullptr when `v` is not an object or has no such member.
// (tinygltf's Value::Get(key) asserts on non-objects: never call it unchecked.)
const Value* member(const Value& v, const char* key) {
  if (!v.IsObject() || !v.Has(key)) return nullptr;
  return &v.Get(key);
}

// A JSON number that is an integer fitting in int.
bool as_int(const Value& v, int& out) {
  if (!v.IsNumber()) return false;
  const double d = v.GetNumberAsDouble();
  if (!(d >= static_cast<double>(std::numeric_limits<int>::min()) &&
        d <= static_cast<double>(std::numeric_limits<int>::max())) ||
      d != std::floor(d))
    return false;
  out = static_cast<int>(d);
  return true;
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

// Local rest transform from a glTF node's TRS or matrix; false (with `out_error`) when a
// property has the wrong number of components.
bool node_transform(const tinygltf::Node& node, transform& out, std::string& out_error) {
  auto check = [&](const std::vector<double>& v, size_t n, const char* what) {
    if (v.empty() || v.size() == n) return true;
    out_error = std::string(what) + " has " + std::to_string(v.size()) + " numbers, expected " +
                std::to_string(n);
    return false;
  };
  if (!check(node.translation, 3, "translation") || !check(node.rotation, 4, "rotation") ||
      !check(node.scale, 3, "scale") || !check(node.matrix, 16, "matrix"))
    return false;
  out = transform{};
  if (!node.matrix.empty()) {
    // Column-major, like glm. Decomposed as T * R * S; a shear, which TRS cannot hold, is lost.
    glm::mat4 m;
    for (int c = 0; c < 4; ++c)
      for (int r = 0; r < 4; ++r) m[c][r] = static_cast<float>(node.matrix[c * 4 + r]);
    out.translation = glm::vec3(m[3]);
    glm::mat3 basis(m);
    glm::vec3 scale(glm::length(basis[0]), glm::length(basis[1]), glm::length(basis[2]));
    if (glm::determinant(basis) < 0.f) scale.x = -scale.x;
    for (int c = 0; c < 3; ++c) {
      if (scale[c] != 0.f && std::isfinite(scale[c]))
        basis[c] /= scale[c];
      else
        basis[c] = glm::vec3(c == 0, c == 1, c == 2);
    }
    out.scale = scale;
    out.rotation = glm::quat_cast(basis);
    const float len2 = glm::dot(out.rotation, out.rotation);
    if (len2 > 0.f && std::isfinite(len2)) out.rotation = glm::normalize(out.rotation);
    return true;
  }
  if (!node.translation.empty())
    out.translation =
        glm::vec3(static_cast<float>(node.translation[0]), static_cast<float>(node.translation[1]),
                  static_cast<float>(node.translation[2]));
  if (!node.rotation.empty())  // glTF order: x, y, z, w; glm's constructor takes w first.
    out.rotation =
        glm::quat(static_cast<float>(node.rotation[3]), static_cast<float>(node.rotation[0]),
                  static_cast<float>(node.rotation[1]), static_cast<float>(node.rotation[2]));
  if (!node.scale.empty())
    out.scale = glm::vec3(static_cast<float>(node.scale[0]), static_cast<float>(node.scale[1]),
                          static_cast<float>(node.scale[2]));
  return true;
}

// Fills raw.declared_humanoid one entry at a time, rejecting what cannot be a humanoid map.
class humanoid_builder {
 public:
  humanoid_builder(raw_rig& raw, std::string where)
      : raw_(raw), where_(std::move(where)), bone_of_node_(raw.nodes.size(), -1) {}

  // `bone_name` is a VRM 1.0 name; `shown` is the name as the file spells it.
  status assign(const std::string& bone_name, const std::string& shown, const Value* node) {
    const std::optional<bone> b = bone_from_name(bone_name);
    if (!b)
      return status::error(where_ + ": humanoid bone " + in_quotes(shown) +
                           " is not a VRM humanoid bone name");
    int index = -1;
    if (!node || !as_int(*node, index))
      return status::error(where_ + ": humanoid bone " + in_quotes(shown) +
                           " has no integer node index");
    const int n = static_cast<int>(raw_.nodes.size());
    if (index < 0 || index >= n)
      return status::error(where_ + ": humanoid bone " + in_quotes(shown) + " names node " +
                           std::to_string(index) + ", out of range (the file has " +
                           std::to_string(n) + " nodes)");
    const int bi = idx(*b);
    if (raw_.declared_humanoid[bi] >= 0)
      return status::error(where_ + ": humanoid bone " + in_quotes(shown) + " is declared twice");
    const int other = bone_of_node_[static_cast<size_t>(index)];
    if (other >= 0)
      return status::error(where_ + ": node " + std::to_string(index) + " " +
                           in_quotes(raw_.nodes[index].name) +
                           " is assigned to two humanoid bones, " +
                           std::string(bone_name_of(other)) + " and " + bone_name);
    raw_.declared_humanoid[bi] = index;
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
status read_vrm1_humanoid(const Value& ext, const char* ext_name, raw_rig& raw) {
  const Value* humanoid = member(ext, "humanoid");
  const Value* bones = humanoid ? member(*humanoid, "humanBones") : nullptr;
  if (!bones || !bones->IsObject())
    return status::error(raw.file + ": " + ext_name +
                         " has no humanoid.humanBones object (expected {name: {node}})");
  humanoid_builder builder(raw, raw.file + ": " + ext_name);
  for (const std::string& name : bones->Keys()) {
    if (status s = builder.assign(name, name, member(bones->Get(name), "node")); !s) return s;
  }
  return {};
}

// VRM 1.0 and VRM Animation: expressions.preset / expressions.custom {name: {...}}.
void read_vrm1_expressions(const Value& ext, raw_rig& raw) {
  const Value* expressions = member(ext, "expressions");
  if (!expressions) return;
  for (const char* group : {"preset", "custom"}) {
    const Value* g = member(*expressions, group);
    if (!g) continue;
    for (const std::string& name : g->Keys()) raw.expressions.push_back(name);
  }
}

// VRM 0.x: humanoid.humanBones [{bone, node}], blendShapeMaster.blendShapeGroups[].
status read_vrm0(const Value& ext, raw_rig& raw) {
  const Value* humanoid = member(ext, "humanoid");
  const Value* bones = humanoid ? member(*humanoid, "humanBones") : nullptr;
  if (!bones || !bones->IsArray())
    return status::error(raw.file +
                         ": VRM has no humanoid.humanBones array (expected [{bone, node}])");
  humanoid_builder builder(raw, raw.file + ": VRM");
  for (size_t i = 0; i < bones->ArrayLen(); ++i) {
    const Value& entry = bones->Get(static_cast<int>(i));
    const Value* name = member(entry, "bone");
    if (!name || !name->IsString())
      return status::error(raw.file + ": VRM humanoid.humanBones[" + std::to_string(i) +
                           "] has no bone name");
    const std::string& shown = name->Get<std::string>();
    if (status s = builder.assign(vrm0_to_vrm1_name(shown), shown, member(entry, "node")); !s)
      return s;
  }
  const Value* master = member(ext, "blendShapeMaster");
  const Value* groups = master ? member(*master, "blendShapeGroups") : nullptr;
  if (groups && groups->IsArray()) {
    for (size_t i = 0; i < groups->ArrayLen(); ++i) {
      const Value& g = groups->Get(static_cast<int>(i));
      std::string name;
      const Value* preset = member(g, "presetName");
      if (preset && preset->IsString() && !preset->Get<std::string>().empty() &&
          preset->Get<std::string>() != "unknown")
        name = preset->Get<std::string>();
      else if (const Value* n = member(g, "name"); n && n->IsString())
        name = n->Get<std::string>();
      if (name.empty()) continue;
      bool seen = false;
      for (const std::string& e : raw.expressions) seen = seen || e == name;
      if (!seen) raw.expressions.push_back(name);
    }
  }
  return {};
}

status read_file(const std::string& path, std::string& out) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return status::error(path + ": cannot open the file (missing or unreadable)");
  std::ostringstream ss;
  ss << in.rdbuf();
  if (in.bad()) return status::error(path + ": read error");
  out = ss.str();
  return {};
}

std::string base_dir_of(const std::string& path) {
  const size_t slash = path.find_last_of('/');
  return slash == std::string::npos ? std::string(".") : path.substr(0, slash);
}

status load_model(const std::string& path, tinygltf::Model& model) {
  std::string bytes;
  if (status s = read_file(path, bytes); !s) return s;
  if (bytes.empty()) return status::error(path + ": the file is empty, not a glTF file");
  if (bytes.size() > std::numeric_limits<std::uint32_t>::max())
    return status::error(path + ": larger than 4 GiB, too large for glTF");

  const bool binary = bytes.size() >= 4 && bytes.compare(0, 4, "glTF") == 0;
  size_t start = 0;
  if (!binary) {
    if (bytes.compare(0, 3, "\xEF\xBB\xBF") == 0) start = 3;  // UTF-8 byte order mark
    while (start < bytes.size() && (bytes[start] == ' ' || bytes[start] == '\t' ||
                                    bytes[start] == '\n' || bytes[start] == '\r'))
      ++start;
    if (start >= bytes.size() || bytes[start] != '{')
      return status::error(path +
                           ": not a glTF file (neither binary glTF, which starts with 'glTF', "
                           "nor a JSON object)");
  }

  tinygltf::TinyGLTF loader;
  loader.SetImageLoader(&skip_image, nullptr);
  std::string err, warn;
  bool ok = false;
  try {
    if (binary)
      ok = loader.LoadBinaryFromMemory(&model, &err, &warn,
                                       reinterpret_cast<const unsigned char*>(bytes.data()),
                                       static_cast<unsigned int>(bytes.size()), base_dir_of(path));
    else
      ok = loader.LoadASCIIFromString(&model, &err, &warn, bytes.data() + start,
                                      static_cast<unsigned int>(bytes.size() - start),
                                      base_dir_of(path));
  } catch (const std::exception& e) {
    return status::error(path + ": cannot parse glTF: " + e.what());
  } catch (...) {
    return status::error(path + ": cannot parse glTF");
  }
  if (!ok) {
    while (!err.empty() && (err.back() == '\n' || err.back() == ' ')) err.pop_back();
    return status::error(path + ": not valid " + (binary ? "binary glTF" : "glTF JSON") + ": " +
                         (err.empty() ? std::string("tinygltf failed without a message") : err));
  }
  // tinygltf silently drops a `children` list (or its tail) that holds anything but integers;
  // a dropped child would become a root. Compare with the JSON itself.
  std::string_view text(bytes);
  if (binary) {  // the header and JSON chunk length were validated by tinygltf
    std::uint32_t json_length = 0;
    for (int k = 3; k >= 0; --k)
      json_length = (json_length << 8) | static_cast<unsigned char>(bytes[12 + k]);
    text = text.substr(20, json_length);
  } else {
    text = text.substr(start);
  }
  const nlohmann::json doc = nlohmann::json::parse(text.begin(), text.end(), nullptr, false);
  const nlohmann::json* nodes = doc.is_object() && doc.contains("nodes") ? &doc["nodes"] : nullptr;
  if (nodes && nodes->is_array() && nodes->size() == model.nodes.size()) {
    for (size_t i = 0; i < nodes->size(); ++i) {
      const nlohmann::json& node = (*nodes)[i];
      if (!node.is_object() || !node.contains("children")) continue;
      const nlohmann::json& children = node["children"];
      if (!children.is_array() || children.size() != model.nodes[i].children.size())
        return status::error(path + ": node " + std::to_string(i) +
                             ": children must be an array of integer node indices");
    }
  }
  return {};
}

status load(const std::string& path, raw_rig& out) {
  tinygltf::Model model;
  if (status s = load_model(path, model); !s) return s;

  // Nodes and their rest transforms.
  const int n = static_cast<int>(model.nodes.size());
  out.nodes.resize(model.nodes.size());
  for (int i = 0; i < n; ++i) {
    const tinygltf::Node& node = model.nodes[static_cast<size_t>(i)];
    raw_rig::node& r = out.nodes[static_cast<size_t>(i)];
    r.name = node.name.empty() ? "node" + std::to_string(i) : node.name;
    std::string why;
    if (!node_transform(node, r.rest, why))
      return status::error(path + ": node " + std::to_string(i) + " " + in_quotes(r.name) + ": " +
                           why);
  }
  // Parents from the children lists.
  for (int i = 0; i < n; ++i) {
    for (int c : model.nodes[static_cast<size_t>(i)].children) {
      const std::string who = path + ": node " + std::to_string(i) + " " +
                              in_quotes(out.nodes[static_cast<size_t>(i)].name);
      if (c < 0 || c >= n)
        return status::error(who + " lists child " + std::to_string(c) +
                             ", out of range (the file has " + std::to_string(n) + " nodes)");
      if (c == i) return status::error(who + " lists itself as a child");
      raw_rig::node& child = out.nodes[static_cast<size_t>(c)];
      if (child.parent >= 0 && child.parent != i)
        return status::error(path + ": node " + std::to_string(c) + " " + in_quotes(child.name) +
                             " is the child of two nodes (" + std::to_string(child.parent) +
                             " and " + std::to_string(i) + ")");
      child.parent = i;
    }
  }

  // Humanoid and expressions from the VRM extensions.
  out.source = rig_source::gltf;
  status s;
  if (auto it = model.extensions.find("VRMC_vrm"); it != model.extensions.end()) {
    out.source = rig_source::vrm1;
    s = read_vrm1_humanoid(it->second, "VRMC_vrm", out);
    if (s) read_vrm1_expressions(it->second, out);
  } else if (auto it0 = model.extensions.find("VRM"); it0 != model.extensions.end()) {
    out.source = rig_source::vrm0;
    s = read_vrm0(it0->second, out);
  } else if (auto ita = model.extensions.find("VRMC_vrm_animation");
             ita != model.extensions.end()) {
    out.source = rig_source::vrm1;
    s = read_vrm1_humanoid(ita->second, "VRMC_vrm_animation", out);
    if (s) read_vrm1_expressions(ita->second, out);
  }
  return s;
}

}  // namespace

status load_avatar(const std::string& path, raw_rig& out) {
  out = raw_rig{};
  out.file = path;
  status s;
  try {
    s = load(path, out);
  } catch (const std::exception& e) {  // e.g. out of memory on a huge declared size
    s = status::error(path + ": cannot load: " + e.what());
  }
  if (!s) {  // no half-filled rig on failure
    out = raw_rig{};
    out.file = path;
  }
  return s;
}

}  // namespace avatarmap
