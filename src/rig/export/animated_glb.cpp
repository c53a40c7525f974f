// The animated .glb writer: the avatar's own JSON (opened and checked by gltf_detail) with every
// buffer and image gathered into one BIN chunk, the animation appended, and the GLB container
// made by export_detail::make_glb (no glTF library re-encodes anything: textures pass through
// byte for byte, whatever their format). Written atomically (io_detail::write_file_atomically).
#include "avatarmap/export/animated_glb.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <exception>
#include <new>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "avatarmap/core/limits.hpp"
#include "avatarmap/core/rotation.hpp"
#include "avatarmap/skeleton/blendshape.hpp"
#include "avatarmap/skeleton/expression.hpp"
#include "common/atomic_file.hpp"
#include "rig/export/glb_builder.hpp"
#include "rig/gltf_document.hpp"

namespace avatarmap {
namespace {

using json = nlohmann::json;

using export_detail::glb_builder;

// Moves every buffer of the avatar into the BIN chunk (buffer 0 of the output): the GLB's own
// BIN chunk, data: URIs and external files alike, and rewrites the bufferViews (and extension
// bufferViews such as EXT_meshopt_compression's) to point into it.
status gather_buffers(const gltf_detail::gltf_document& doc, json& j, glb_builder& bin,
                      std::uint64_t& total_read) {
  const std::string& p = doc.path;
  std::vector<std::size_t> offset;
  if (j.contains("buffers")) {
    const json& buffers = j["buffers"];
    if (!buffers.is_array()) return status::parse_error(p + ": buffers is not an array");
    for (std::size_t i = 0; i < buffers.size(); ++i) {
      const json& b = buffers[i];
      const std::string where = "buffers[" + std::to_string(i) + "]";
      if (!b.is_object() || !b.contains("byteLength") || !b["byteLength"].is_number_integer() ||
          b["byteLength"].get<std::int64_t>() < 0)
        return status::parse_error(p + ": " + where + " has no valid byteLength");
      const auto length = static_cast<std::uint64_t>(b["byteLength"].get<std::int64_t>());
      std::string bytes;
      if (b.contains("uri")) {
        if (!b["uri"].is_string())
          return status::parse_error(p + ": " + where + ".uri is not a string");
        if (status s = gltf_detail::read_gltf_uri(doc, b["uri"].get<std::string>(), where + ".uri",
                                                  total_read, bytes);
            !s)
          return s;
      } else if (doc.binary && i == 0) {
        bytes.assign(doc.bin());
      } else {
        return status::parse_error(
            p + ": " + where +
            " has no uri and is not the GLB's binary chunk; its data is nowhere");
      }
      if (bytes.size() < length)
        return status::parse_error(p + ": " + where + " declares " + std::to_string(length) +
                                   " bytes but its data has " + std::to_string(bytes.size()));
      bytes.resize(static_cast<std::size_t>(length));
      offset.push_back(bin.append(bytes));
    }
  }
  // Points a {buffer, byteOffset} object into the BIN chunk.
  auto rebase = [&](json& view, const std::string& where) -> status {
    if (!view.contains("buffer") || !view["buffer"].is_number_integer())
      return status::parse_error(p + ": " + where + " has no valid buffer index");
    const std::int64_t b = view["buffer"].get<std::int64_t>();
    if (b < 0 || b >= static_cast<std::int64_t>(offset.size()))
      return status::parse_error(p + ": " + where + " names buffer " + std::to_string(b) +
                                 ", out of range (the file has " + std::to_string(offset.size()) +
                                 " buffers)");
    std::uint64_t start = 0;
    if (view.contains("byteOffset")) {
      if (!view["byteOffset"].is_number_integer() || view["byteOffset"].get<std::int64_t>() < 0)
        return status::parse_error(p + ": " + where + ".byteOffset is not a non-negative integer");
      start = static_cast<std::uint64_t>(view["byteOffset"].get<std::int64_t>());
    }
    view["buffer"] = 0;
    view["byteOffset"] = start + offset[static_cast<std::size_t>(b)];
    return {};
  };
  if (j.contains("bufferViews")) {
    json& views = j["bufferViews"];
    if (!views.is_array()) return status::parse_error(p + ": bufferViews is not an array");
    for (std::size_t i = 0; i < views.size(); ++i) {
      const std::string where = "bufferViews[" + std::to_string(i) + "]";
      json& v = views[i];
      if (!v.is_object()) return status::parse_error(p + ": " + where + " is not an object");
      if (status s = rebase(v, where); !s) return s;
      if (v.contains("extensions") && v["extensions"].is_object())
        for (auto it = v["extensions"].begin(); it != v["extensions"].end(); ++it)
          if (it.value().is_object() && it.value().contains("buffer"))
            if (status s = rebase(it.value(), where + ".extensions." + it.key()); !s) return s;
    }
  }
  j["buffers"] = json::array();  // replaced by the BIN chunk in write_animated_glb
  return {};
}

// Moves every image given by a URI (file or data:) into the BIN chunk as a bufferView, bytes
// unchanged, with its media type. An image file that does not exist (but that our rules would
// read) is left named as the avatar names it: the avatar already lacked it, and a viewer
// then misses the same texture; nothing is read.
status gather_images(const gltf_detail::gltf_document& doc, json& j, glb_builder& bin,
                     std::uint64_t& total_read) {
  if (!j.contains("images")) return {};
  json& images = j["images"];
  if (!images.is_array()) return status::parse_error(doc.path + ": images is not an array");
  for (std::size_t i = 0; i < images.size(); ++i) {
    json& image = images[i];
    if (!image.is_object() || !image.contains("uri")) continue;
    const std::string where = "images[" + std::to_string(i) + "].uri";
    if (!image["uri"].is_string())
      return status::parse_error(doc.path + ": " + where + " is not a string");
    std::string bytes;
    bool missing = false;
    if (status s = gltf_detail::read_gltf_uri(doc, image["uri"].get<std::string>(), where,
                                              total_read, bytes, &missing);
        !s) {
      if (missing) continue;
      return s;
    }
    std::string mime = gltf_detail::sniff_image_mime_type(bytes);
    if (mime.empty() && image.contains("mimeType") && image["mimeType"].is_string())
      mime = image["mimeType"].get<std::string>();
    if (mime.empty())
      return status::parse_error(
          doc.path + ": " + where +
          ": cannot tell the image's format (not PNG, JPEG, WebP, KTX2, AVIF "
          "or DDS, and no mimeType given)");
    image.erase("uri");
    image["bufferView"] = bin.add_view(bytes);
    image["mimeType"] = mime;
  }
  return {};
}

// ---- The face: the avatar's expression definitions as morph-target binds ----

// One bind of a proxy channel to a morph target of a node's mesh: an expression
// (skeleton/expression.hpp), an ARKit blendshape (skeleton/blendshape.hpp), or both when the
// name is both (browDownLeft, browDownRight: the blendshape when the ARKit layer drives).
struct morph_bind {
  int expression = -1;
  int shape = -1;
  int node = 0;
  int target = 0;
  float weight = 1.f;
};

struct face_binds {
  std::vector<morph_bind> binds;
  std::array<bool, k_expression_count> binary{};   // isBinary of the definition used
  std::array<bool, k_expression_count> defined{};  // the first definition of a name wins
  std::array<bool, k_blendshape_count> shape_binary{};
  std::array<bool, k_blendshape_count> shape_defined{};
};

bool equal_nocase(std::string_view a, std::string_view b) {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i) {
    const auto lower = [](char c) { return c >= 'A' && c <= 'Z' ? char(c - 'A' + 'a') : c; };
    if (lower(a[i]) != lower(b[i])) return false;
  }
  return true;
}

int expression_nocase(std::string_view name) {
  for (int e = 0; e < k_expression_count; ++e)
    if (equal_nocase(name, expression_name(static_cast<expression>(e)))) return e;
  return -1;
}

// ARKit's name in any case, after the prefixes exporters put before it: anything up to the
// last '.' (Maya and FBX: "blendShape1.jawOpen"), then "ARKit_" ("ARKit_jawOpen").
int blendshape_nocase(std::string_view name) {
  if (const std::size_t dot = name.rfind('.'); dot != std::string_view::npos)
    name.remove_prefix(dot + 1);
  if (name.size() > 6 && equal_nocase(name.substr(0, 6), "arkit_")) name.remove_prefix(6);
  for (int b = 0; b < k_blendshape_count; ++b)
    if (equal_nocase(name, blendshape_name(static_cast<blendshape>(b)))) return b;
  return -1;
}

const json* member(const json& v, const char* key) {
  if (!v.is_object()) return nullptr;
  auto it = v.find(key);
  return it == v.end() ? nullptr : &*it;
}

// Morph targets of a node's mesh (its first primitive's; glTF requires every primitive of a
// mesh to have the same count), 0 when the node has no mesh or the mesh none.
int node_target_count(const json& j, int node) {
  const json* nodes = member(j, "nodes");
  const json* meshes = member(j, "meshes");
  if (!nodes || !meshes || !nodes->is_array() || !meshes->is_array() || node < 0 ||
      static_cast<std::size_t>(node) >= nodes->size())
    return 0;
  const json* mesh = member((*nodes)[static_cast<std::size_t>(node)], "mesh");
  if (!mesh || !mesh->is_number_integer()) return 0;
  const std::int64_t m = mesh->get<std::int64_t>();
  if (m < 0 || static_cast<std::size_t>(m) >= meshes->size()) return 0;
  const json* prims = member((*meshes)[static_cast<std::size_t>(m)], "primitives");
  if (!prims || !prims->is_array() || prims->empty()) return 0;
  const json* targets = member((*prims)[0], "targets");
  return targets && targets->is_array() ? static_cast<int>(targets->size()) : 0;
}

// The channel a definition's name drives: {expression, shape}, -1 where none. An expression's
// name is matched exactly (VRM 1.0) or in any case (VRM 0.x names, target names); an ARKit
// name in any case, prefixes allowed.
std::pair<int, int> channel_of(std::string_view name, bool exact_expression) {
  int e = -1;
  if (exact_expression) {
    if (const std::optional<expression> x = expression_from_name(name)) e = idx(*x);
  } else {
    e = expression_nocase(name);
  }
  return {e, blendshape_nocase(name)};
}

// Claims the channel for this definition (the first definition of an expression or a shape
// wins); false when both its channels are taken already.
bool claim(face_binds& out, std::pair<int, int>& ch, bool binary) {
  auto& [e, b] = ch;
  if (e >= 0 && out.defined[static_cast<std::size_t>(e)]) e = -1;
  if (b >= 0 && out.shape_defined[static_cast<std::size_t>(b)]) b = -1;
  if (e < 0 && b < 0) return false;
  if (e >= 0) {
    out.defined[static_cast<std::size_t>(e)] = true;
    out.binary[static_cast<std::size_t>(e)] = binary;
  }
  if (b >= 0) {
    out.shape_defined[static_cast<std::size_t>(b)] = true;
    out.shape_binary[static_cast<std::size_t>(b)] = binary;
  }
  return true;
}

// Adds a bind when its node's mesh has the target and the weight is a number; else ignores it.
void add_bind(const json& j, face_binds& out, std::pair<int, int> ch, const json* node,
              const json* index, const json* weight, float weight_scale) {
  if (!node || !index || !node->is_number_integer() || !index->is_number_integer()) return;
  const std::int64_t n = node->get<std::int64_t>(), t = index->get<std::int64_t>();
  if (n < 0 || n > 0x7fffffff || t < 0 || t >= node_target_count(j, static_cast<int>(n))) return;
  float w = 1.f;
  if (weight) {
    if (!weight->is_number()) return;
    w = weight->get<float>() * weight_scale;
    if (!std::isfinite(w)) return;
  }
  out.binds.push_back({ch.first, ch.second, static_cast<int>(n), static_cast<int>(t), w});
}

bool is_binary(const json& def) {
  const json* b = member(def, "isBinary");
  return b && b->is_boolean() && b->get<bool>();
}

// VRM 1.0: VRMC_vrm.expressions.{preset,custom}.NAME.morphTargetBinds[{node, index, weight}].
void read_vrm1_binds(const json& j, const json& expressions, face_binds& out) {
  for (const char* group : {"preset", "custom"}) {
    const json* g = member(expressions, group);
    if (!g || !g->is_object()) continue;
    for (auto it = g->begin(); it != g->end(); ++it) {
      std::pair<int, int> ch = channel_of(it.key(), true);
      if (!claim(out, ch, is_binary(it.value()))) continue;
      const json* binds = member(it.value(), "morphTargetBinds");
      if (!binds || !binds->is_array()) continue;
      for (const json& b : *binds)
        add_bind(j, out, ch, member(b, "node"), member(b, "index"), member(b, "weight"), 1.f);
    }
  }
}

// VRM 0.x: VRM.blendShapeMaster.blendShapeGroups[{presetName, name, binds[{mesh, index,
// weight 0-100}], isBinary}]; a bind reaches every node that shows its mesh.
void read_vrm0_binds(const json& j, const json& groups, face_binds& out) {
  static constexpr std::array<std::pair<std::string_view, expression>, 16> k_presets = {{
      {"a", expression::aa},
      {"i", expression::ih},
      {"u", expression::ou},
      {"e", expression::ee},
      {"o", expression::oh},
      {"blink", expression::blink},
      {"blink_l", expression::blink_left},
      {"blink_r", expression::blink_right},
      {"lookup", expression::look_up},
      {"lookdown", expression::look_down},
      {"lookleft", expression::look_left},
      {"lookright", expression::look_right},
      {"joy", expression::happy},
      {"angry", expression::angry},
      {"sorrow", expression::sad},
      {"fun", expression::relaxed},
  }};
  const json* nodes = member(j, "nodes");
  for (const json& g : groups) {
    std::pair<int, int> ch{-1, -1};
    const json* preset = member(g, "presetName");
    if (preset && preset->is_string()) {
      for (const auto& [name, ex] : k_presets)
        if (equal_nocase(preset->get_ref<const std::string&>(), name)) ch.first = idx(ex);
    }
    const json* name = member(g, "name");
    if (ch.first < 0 && name && name->is_string())
      ch = channel_of(name->get_ref<const std::string&>(), false);
    if (!claim(out, ch, is_binary(g))) continue;
    const json* binds = member(g, "binds");
    if (!binds || !binds->is_array() || !nodes || !nodes->is_array()) continue;
    for (const json& b : *binds) {
      const json* mesh = member(b, "mesh");
      if (!mesh || !mesh->is_number_integer()) continue;
      for (std::size_t n = 0; n < nodes->size(); ++n) {
        const json* m = member((*nodes)[n], "mesh");
        if (!m || !m->is_number_integer() || m->get<std::int64_t>() != mesh->get<std::int64_t>())
          continue;
        const json node = static_cast<std::int64_t>(n);
        add_bind(j, out, ch, &node, member(b, "index"), member(b, "weight"), 0.01f);
      }
    }
  }
}

// A mesh's morph target names: mesh.extras.targetNames (three.js, Blender), else its first
// primitive's extras.targetNames (UniVRM 0.x); null when neither is an array.
const json* target_names(const json& mesh) {
  const json* extras = member(mesh, "extras");
  const json* names = extras ? member(*extras, "targetNames") : nullptr;
  if (names && names->is_array()) return names;
  const json* prims = member(mesh, "primitives");
  if (!prims || !prims->is_array() || prims->empty()) return nullptr;
  extras = member((*prims)[0], "extras");
  names = extras ? member(*extras, "targetNames") : nullptr;
  return names && names->is_array() ? names : nullptr;
}

// Plain glTF: morph targets named after an expression (when `expressions`) or an ARKit shape,
// any case, weight 1; a channel some definition claimed already is left to it.
void read_named_targets(const json& j, face_binds& out, bool expressions) {
  const json* nodes = member(j, "nodes");
  const json* meshes = member(j, "meshes");
  if (!nodes || !meshes || !nodes->is_array() || !meshes->is_array()) return;
  const face_binds before = out;  // what the avatar's definitions claimed
  for (std::size_t n = 0; n < nodes->size(); ++n) {
    const json* m = member((*nodes)[n], "mesh");
    if (!m || !m->is_number_integer() || m->get<std::int64_t>() < 0 ||
        static_cast<std::size_t>(m->get<std::int64_t>()) >= meshes->size())
      continue;
    const json* names = target_names((*meshes)[static_cast<std::size_t>(m->get<std::int64_t>())]);
    if (!names) continue;
    for (std::size_t t = 0; t < names->size(); ++t) {
      if (!(*names)[t].is_string()) continue;
      std::pair<int, int> ch = channel_of((*names)[t].get_ref<const std::string&>(), false);
      if (!expressions) ch.first = -1;
      if (ch.first >= 0 && before.defined[static_cast<std::size_t>(ch.first)]) ch.first = -1;
      if (ch.second >= 0 && before.shape_defined[static_cast<std::size_t>(ch.second)])
        ch.second = -1;
      if (ch.first < 0 && ch.second < 0) continue;
      if (ch.first >= 0) out.defined[static_cast<std::size_t>(ch.first)] = true;
      if (ch.second >= 0) out.shape_defined[static_cast<std::size_t>(ch.second)] = true;
      const json node = static_cast<std::int64_t>(n), index = static_cast<std::int64_t>(t);
      add_bind(j, out, ch, &node, &index, nullptr, 1.f);
    }
  }
}

// The avatar's definitions, the first kind the file has (VRM 1.0, VRM 0.x, target names),
// then morph targets named after ARKit shapes that no definition claimed (any file).
face_binds read_face_binds(const json& j) {
  face_binds out;
  const json* ext = member(j, "extensions");
  const json* vrm1 = ext ? member(*ext, "VRMC_vrm") : nullptr;
  const json* expressions = vrm1 ? member(*vrm1, "expressions") : nullptr;
  const json* vrm0 = ext ? member(*ext, "VRM") : nullptr;
  const json* master = vrm0 ? member(*vrm0, "blendShapeMaster") : nullptr;
  const json* groups = master ? member(*master, "blendShapeGroups") : nullptr;
  if (expressions && expressions->is_object())
    read_vrm1_binds(j, *expressions, out);
  else if (groups && groups->is_array())
    read_vrm0_binds(j, *groups, out);
  else {
    read_named_targets(j, out, true);
    return out;
  }
  read_named_targets(j, out, false);
  return out;
}

// A node's default morph weights: node.weights, else its mesh's weights, else zeros (glTF 2.0).
std::vector<float> default_weights(const json& j, int node, int count) {
  std::vector<float> w(static_cast<std::size_t>(count), 0.f);
  const json& n = j["nodes"][static_cast<std::size_t>(node)];
  const json* weights = member(n, "weights");
  if (!weights || !weights->is_array())
    weights = member(j["meshes"][n["mesh"].get<std::size_t>()], "weights");
  if (weights && weights->is_array() && weights->size() == w.size())
    for (std::size_t t = 0; t < w.size(); ++t)
      if ((*weights)[t].is_number()) {
        const float v = (*weights)[t].get<float>();
        w[t] = std::isfinite(v) ? std::clamp(v, 0.f, 1.f) : 0.f;
      }
  return w;
}

// Appends the animation (time accessor, one rotation channel per joint that moves, the hips'
// translation). Refuses non-finite values: no writer emits nan.
status add_animation(const rig& r, const std::vector<rig_pose>& frames,
                     const animated_glb_options& options, const std::string& out_path, json& j,
                     glb_builder& bin) {
  const std::size_t n = frames.size();
  for (std::size_t f = 0; f < n; ++f) {
    const rig_pose& pose = frames[f];
    if (pose.local_rotations.size() < static_cast<std::size_t>(r.joint_count()))
      return status::error(out_path + ": frame " + std::to_string(f) +
                           " has fewer rotations than the rig has joints");
    for (int k = 0; k < r.joint_count(); ++k)
      if (!is_finite(pose.local_rotations[static_cast<std::size_t>(k)]))
        return status::error(out_path + ": frame " + std::to_string(f) + " joint '" + r.names[k] +
                             "' has a non-finite rotation; nothing written");
    if (pose.hips_joint >= 0 && !is_finite(pose.hips_translation))
      return status::error(out_path + ": frame " + std::to_string(f) +
                           " has a non-finite hips translation; nothing written");
  }
  const std::vector<proxy_pose>* faces = options.expressions;
  if (faces != nullptr) {
    if (faces->size() != n)
      return status::invalid_argument(out_path + ": " + std::to_string(faces->size()) +
                                      " expression frames for " + std::to_string(n) +
                                      " rig poses; give one per frame");
    for (std::size_t f = 0; f < n; ++f)
      for (int e = 0; e < k_expression_count; ++e)
        if (!std::isfinite((*faces)[f].expressions[static_cast<std::size_t>(e)]))
          return status::error(out_path + ": frame " + std::to_string(f) + " expression '" +
                               std::string(expression_name(static_cast<expression>(e))) +
                               "' is not finite; nothing written");
    for (std::size_t f = 0; f < n; ++f)
      for (int b = 0; b < k_blendshape_count; ++b)
        if (!std::isfinite((*faces)[f].blendshapes[static_cast<std::size_t>(b)]))
          return status::error(out_path + ": frame " + std::to_string(f) + " blendshape '" +
                               std::string(blendshape_name(static_cast<blendshape>(b))) +
                               "' is not finite; nothing written");
  }
  std::vector<float> times(n);
  for (std::size_t i = 0; i < n; ++i) times[i] = static_cast<float>(double(i) / options.fps);
  json anim = {
      {"name", options.animation_name}, {"samplers", json::array()}, {"channels", json::array()}};
  const std::size_t time_acc = bin.add_floats(times, "SCALAR", 1, true);
  auto add_channel = [&](int node, const char* path, const std::vector<float>& values,
                         const char* type, int comps) {
    json sampler = {{"input", time_acc},
                    {"output", bin.add_floats(values, type, comps, false)},
                    {"interpolation", "LINEAR"}};
    anim["samplers"].push_back(std::move(sampler));
    json channel = {{"sampler", anim["samplers"].size() - 1},
                    {"target", {{"node", node}, {"path", path}}}};
    anim["channels"].push_back(std::move(channel));
  };
  std::vector<float> values;
  for (int k = 0; k < r.joint_count(); ++k) {
    bool moves = false;
    for (const rig_pose& f : frames)
      if (angle_between(f.local_rotations[static_cast<size_t>(k)], r.rest_local[k].rotation) >
          1e-6f)
        moves = true;
    if (!moves) continue;
    values.clear();
    glm::quat prev = frames[0].local_rotations[static_cast<size_t>(k)];
    for (const rig_pose& f : frames) {
      glm::quat q = f.local_rotations[static_cast<size_t>(k)];
      // Keep consecutive keys in one hemisphere so LINEAR interpolation takes the short way.
      if (q.x * prev.x + q.y * prev.y + q.z * prev.z + q.w * prev.w < 0.f) q = -q;
      prev = q;
      values.insert(values.end(), {q.x, q.y, q.z, q.w});
    }
    add_channel(r.source_index[k], "rotation", values, "VEC4", 4);
  }
  const int hips = frames[0].hips_joint;
  if (hips >= 0 && hips < r.joint_count()) {
    values.clear();
    for (const rig_pose& f : frames)
      values.insert(values.end(),
                    {f.hips_translation.x, f.hips_translation.y, f.hips_translation.z});
    add_channel(r.source_index[hips], "translation", values, "VEC3", 3);
  }
  if (faces != nullptr) {
    face_binds face = read_face_binds(j);
    // The ARKit layer drives when the avatar has ARKit binds and the clip carries blendshapes
    // (a clip from before them has all zeros: the expressions then drive every bind). Where it
    // drives, a morph target that an ARKit bind reaches is driven by the ARKit shapes alone:
    // expression binds onto it are dropped, so nothing is driven twice.
    bool carries_shapes = false;
    for (const proxy_pose& p : *faces)
      for (float v : p.blendshapes) carries_shapes = carries_shapes || v != 0.f;
    bool arkit = false;
    for (const morph_bind& m : face.binds) arkit = arkit || m.shape >= 0;
    arkit = arkit && carries_shapes;
    std::vector<std::pair<int, int>> by_shape;  // (node, target) an ARKit bind reaches
    if (arkit)
      for (const morph_bind& m : face.binds)
        if (m.shape >= 0) by_shape.emplace_back(m.node, m.target);
    std::sort(by_shape.begin(), by_shape.end());
    std::vector<morph_bind> kept;
    for (morph_bind m : face.binds) {
      if (arkit && m.shape >= 0) {
        m.expression = -1;
      } else {
        m.shape = -1;
        if (m.expression < 0) continue;
        if (std::binary_search(by_shape.begin(), by_shape.end(), std::make_pair(m.node, m.target)))
          continue;
      }
      kept.push_back(m);
    }
    face.binds = std::move(kept);
    std::stable_sort(face.binds.begin(), face.binds.end(),
                     [](const morph_bind& a, const morph_bind& b) { return a.node < b.node; });
    for (std::size_t i = 0; i < face.binds.size();) {
      const int node = face.binds[i].node;
      std::size_t end = i;
      while (end < face.binds.size() && face.binds[end].node == node) ++end;
      const int count = node_target_count(j, node);
      const std::vector<float> base = default_weights(j, node, count);
      values.assign(n * static_cast<std::size_t>(count), 0.f);
      for (std::size_t f = 0; f < n; ++f) {
        float* w = values.data() + f * static_cast<std::size_t>(count);
        std::copy(base.begin(), base.end(), w);
        for (std::size_t b = i; b < end; ++b) {
          const morph_bind& m = face.binds[b];
          const bool shape = m.shape >= 0;
          const auto c = static_cast<std::size_t>(shape ? m.shape : m.expression);
          float v =
              std::clamp(shape ? (*faces)[f].blendshapes[c] : (*faces)[f].expressions[c], 0.f, 1.f);
          if (shape ? face.shape_binary[c] : face.binary[c]) v = v > 0.5f ? 1.f : 0.f;
          w[m.target] += v * m.weight;
        }
        for (int t = 0; t < count; ++t) w[t] = std::clamp(w[t], 0.f, 1.f);
      }
      add_channel(node, "weights", values, "SCALAR", 1);
      i = end;
    }
  }
  if (!j.contains("animations") || !j["animations"].is_array()) j["animations"] = json::array();
  j["animations"].push_back(std::move(anim));
  return {};
}

status write_impl(const std::string& avatar_path, const rig& r, const std::vector<rig_pose>& frames,
                  const animated_glb_options& options, const std::string& out_path) {
  if (frames.empty()) return status::error(out_path + ": no frames to write");
  if (!(options.fps > 0.0 && options.fps <= k_max_fps))
    return status::error(out_path + ": fps must be in (0, " + limit_text(k_max_fps) + "]");
  gltf_detail::gltf_document doc;
  if (status s = gltf_detail::open_gltf_document(avatar_path, doc); !s) return s;
  json j = std::move(doc.json);
  const std::size_t nodes = j.contains("nodes") && j["nodes"].is_array() ? j["nodes"].size() : 0;
  for (int k = 0; k < r.joint_count(); ++k)
    if (r.source_index[k] < 0 || static_cast<std::size_t>(r.source_index[k]) >= nodes)
      return status::invalid_argument(
          avatar_path + ": the rig does not belong to this file (joint '" + r.names[k] + "')");

  glb_builder bin(j);
  std::uint64_t total_read = 0;
  if (status s = gather_buffers(doc, j, bin, total_read); !s) return s;
  if (status s = gather_images(doc, j, bin, total_read); !s) return s;
  if (status s = add_animation(r, frames, options, out_path, j, bin); !s) return s;
  if (!j.contains("asset") || !j["asset"].is_object()) j["asset"] = {{"version", "2.0"}};
  j["asset"]["generator"] = "avatarmap";
  std::string glb;
  if (status s = export_detail::make_glb(j, bin.bytes(), out_path, glb); !s)
    return s.with_message(s.message() + "; use a shorter clip");
  return io_detail::write_file_atomically(out_path, glb);
}

}  // namespace

status write_animated_glb(const std::string& avatar_path, const rig& r,
                          const std::vector<rig_pose>& frames, const animated_glb_options& options,
                          const std::string& out_path) {
  try {
    return write_impl(avatar_path, r, frames, options, out_path);
  } catch (const std::bad_alloc&) {
    return status::out_of_memory(out_path + ": not enough memory to write the animated avatar");
  } catch (const std::exception&) {
    return status::internal(out_path +
                            ": cannot write the animated avatar (unexpected internal "
                            "error)");
  }
}

}  // namespace avatarmap
