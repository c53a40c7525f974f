// .vrma writer: the GLB is assembled by hand (export_detail::glb_builder: JSON chunk via
// nlohmann::json, BIN chunk of little-endian floats) so that the extension object and every
// number are exactly as written here; the output goes through io_detail::text_output for the
// atomic rename.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <exception>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "avatarmap/core/rotation.hpp"
#include "avatarmap/export/vrma.hpp"
#include "common/text_output.hpp"
#include "rig/export/export_common.hpp"
#include "rig/export/glb_builder.hpp"

namespace avatarmap {
namespace {

using json = nlohmann::json;

constexpr bool is_custom_expression(expression e) {
  return e == expression::brow_up_left || e == expression::brow_up_right ||
         e == expression::brow_down_left || e == expression::brow_down_right;
}

status write_impl(const std::string& path, const std::vector<proxy_pose>& frames,
                  const vrma_write_options& options) {
  if (status s = export_detail::check_frames(path, frames, options.fps); !s) return s;
  if (!std::isfinite(options.height) || options.height <= 0.f)
    return status::error(path + ": height must be positive, got " + std::to_string(options.height));
  if (!options.start_at_zero && frames.front().t < 0.0)
    return status::error(path +
                         ": frame 0 has a negative time (glTF times start at 0); set "
                         "start_at_zero");
  std::vector<proxy_pose> keys;
  if (status s =
          export_detail::frames_to_write(path, frames, options.fps, options.start_at_zero, keys);
      !s)
    return s;
  const std::size_t n = keys.size();

  const proxy_skeleton skeleton = make_proxy_skeleton(options.height);
  std::array<int, k_bone_count> node_of_bone;
  node_of_bone.fill(-1);
  json nodes = json::array();
  for (int b = 0; b < k_bone_count; ++b) {
    if (!is_vrma_bone(static_cast<bone>(b))) continue;
    node_of_bone[b] = static_cast<int>(nodes.size());
    glm::vec3 t = b == idx(bone::hips) ? glm::vec3(0.f, standing_hips_height(skeleton), 0.f)
                                       : skeleton.offsets[b];
    nodes.push_back(
        {{"name", std::string(bone_name(static_cast<bone>(b)))}, {"translation", {t.x, t.y, t.z}}});
  }
  for (int b = 0; b < k_bone_count; ++b) {
    int p = bone_parent(b);
    if (node_of_bone[b] < 0 || p == k_no_parent) continue;
    nodes[node_of_bone[p]]["children"].push_back(node_of_bone[b]);
  }

  // The weights written, by name: the proxy's expressions, then ARKit's shapes as custom
  // expressions (a shape whose name is already listed, browDownLeft/Right, takes that entry).
  struct weight_track {
    std::string name;
    bool custom = false;
    int expression = -1;  // index into expressions, or -1
    int shape = -1;       // index into blendshapes (wins over `expression`), or -1
  };
  std::vector<weight_track> written;
  for (int e = 0; e < k_expression_count; ++e) {
    if (!is_vrma_expression(static_cast<expression>(e))) continue;
    bool used = options.all_expressions;
    for (std::size_t k = 0; k < n && !used; ++k) used = keys[k].expressions[e] != 0.f;
    if (used)
      written.push_back({std::string(expression_name(static_cast<expression>(e))),
                         is_custom_expression(static_cast<expression>(e)), e, -1});
  }
  // export_detail::clean_frame leaves the blendshapes as given: cleaned here the same way
  // (non-finite: the previous key's, 0 for the first; clamped to [0, 1]).
  std::vector<float> shapes;
  if (options.blendshapes) {
    shapes.resize(n * k_blendshape_count);
    for (std::size_t k = 0; k < n; ++k)
      for (int sh = 0; sh < k_blendshape_count; ++sh) {
        const float w = keys[k].blendshapes[sh];
        shapes[k * k_blendshape_count + sh] =
            std::isfinite(w) ? std::clamp(w, 0.f, 1.f)
                             : (k > 0 ? shapes[(k - 1) * k_blendshape_count + sh] : 0.f);
      }
    for (int sh = 0; sh < k_blendshape_count; ++sh) {
      bool used = options.all_expressions;
      for (std::size_t k = 0; k < n && !used; ++k)
        used = shapes[k * k_blendshape_count + sh] != 0.f;
      if (!used) continue;
      std::string name(blendshape_name(static_cast<blendshape>(sh)));
      auto same = std::find_if(written.begin(), written.end(),
                               [&](const weight_track& w) { return w.name == name; });
      if (same != written.end())
        same->shape = sh;
      else
        written.push_back({name, true, -1, sh});
    }
  }

  // Gaze: written when some key turns an eye.
  bool gaze = false;
  if (options.look_at)
    for (std::size_t k = 0; k < n && !gaze; ++k)
      for (bone eye : {bone::left_eye, bone::right_eye}) {
        const glm::quat& q = keys[k][eye];
        gaze = gaze || q.x != 0.f || q.y != 0.f || q.z != 0.f;
      }

  json doc = json::object();
  export_detail::glb_builder bin(doc);
  std::vector<float> values;
  values.reserve(n * 4);
  for (const proxy_pose& p : keys) values.push_back(static_cast<float>(p.t));
  const std::size_t time_accessor = bin.add_floats(values, "SCALAR", 1, true);

  json samplers = json::array();
  json channels = json::array();
  auto add_channel = [&](int node, const char* target, std::size_t output) {
    samplers.push_back({{"input", time_accessor}, {"output", output}, {"interpolation", "LINEAR"}});
    channels.push_back(
        {{"sampler", samplers.size() - 1}, {"target", {{"node", node}, {"path", target}}}});
  };

  // Hips translation first, then one rotation channel per bone.
  values.clear();
  for (const proxy_pose& p : keys)
    values.insert(values.end(), {p.hips_position.x, p.hips_position.y, p.hips_position.z});
  add_channel(node_of_bone[idx(bone::hips)], "translation",
              bin.add_floats(values, "VEC3", 3, false));
  for (int b = 0; b < k_bone_count; ++b) {
    if (node_of_bone[b] < 0) continue;
    values.clear();
    glm::quat prev(1.f, 0.f, 0.f, 0.f);
    for (const proxy_pose& p : keys) {
      glm::quat q = p.rotations[b];
      if (glm::dot(prev, q) < 0.f) q = -q;  // continuous signs: any slerp takes the short arc
      prev = q;
      values.insert(values.end(), {q.x, q.y, q.z, q.w});  // glTF order {x, y, z, w}
    }
    add_channel(node_of_bone[b], "rotation", bin.add_floats(values, "VEC4", 4, false));
  }

  json preset = json::object(), custom = json::object();
  std::vector<int> scene_nodes{node_of_bone[idx(bone::hips)]};
  for (const weight_track& w : written) {
    int node = static_cast<int>(nodes.size());
    nodes.push_back({{"name", w.name}});
    scene_nodes.push_back(node);
    (w.custom ? custom : preset)[w.name] = {{"node", node}};
    values.clear();
    for (std::size_t k = 0; k < n; ++k)
      values.insert(values.end(), {w.shape >= 0 ? shapes[k * k_blendshape_count + w.shape]
                                                : keys[k].expressions[w.expression],
                                   0.f, 0.f});
    add_channel(node, "translation", bin.add_floats(values, "VEC3", 3, false));
  }

  // lookAt (docs/export.md): a pivot under the head at the eyes' midpoint and the lookAt node
  // 1 m ahead of it, both rotated by the gaze. The lookAt node's own rotation channel is the
  // gaze as three-vrm reads it (it accepts no other channel on that node); the pivot's turns
  // the node's model-space position into the look target, as the spec reads it.
  int look_at_node = -1;
  if (gaze) {
    const int pivot = static_cast<int>(nodes.size());
    look_at_node = pivot + 1;
    const glm::vec3 mid =
        0.5f * (skeleton.offsets[idx(bone::left_eye)] + skeleton.offsets[idx(bone::right_eye)]);
    nodes.push_back({{"name", "lookAtPivot"},
                     {"translation", {mid.x, mid.y, mid.z}},
                     {"children", {look_at_node}}});
    nodes.push_back({{"name", "lookAtTarget"}, {"translation", {0.f, 0.f, 1.f}}});
    nodes[node_of_bone[idx(bone::head)]]["children"].push_back(pivot);
    values.clear();
    glm::quat prev(1.f, 0.f, 0.f, 0.f);
    for (const proxy_pose& p : keys) {
      glm::quat q = glm::normalize(slerp_shortest(p[bone::left_eye], p[bone::right_eye], 0.5f));
      if (glm::dot(prev, q) < 0.f) q = -q;
      prev = q;
      values.insert(values.end(), {q.x, q.y, q.z, q.w});
    }
    const std::size_t gaze_values = bin.add_floats(values, "VEC4", 4, false);
    add_channel(pivot, "rotation", gaze_values);
    add_channel(look_at_node, "rotation", gaze_values);
  }

  json humanoid_bones = json::object();
  for (int b = 0; b < k_bone_count; ++b)
    if (node_of_bone[b] >= 0)
      humanoid_bones[std::string(bone_name(static_cast<bone>(b)))] = {{"node", node_of_bone[b]}};
  json ext = {{"specVersion", "1.0"}, {"humanoid", {{"humanBones", humanoid_bones}}}};
  if (!written.empty()) {
    json exprs = json::object();
    if (!preset.empty()) exprs["preset"] = preset;
    if (!custom.empty()) exprs["custom"] = custom;
    ext["expressions"] = exprs;
  }
  if (look_at_node >= 0) ext["lookAt"] = {{"node", look_at_node}};

  doc["asset"] = {{"version", "2.0"}, {"generator", options.generator}};
  doc["extensionsUsed"] = json::array({"VRMC_vrm_animation"});
  doc["extensions"] = {{"VRMC_vrm_animation", ext}};
  doc["scene"] = 0;
  doc["scenes"] = {{{"nodes", scene_nodes}}};
  doc["nodes"] = nodes;
  doc["animations"] = {{{"name", "avatarmap"}, {"samplers", samplers}, {"channels", channels}}};
  std::string glb;
  if (status s = export_detail::make_glb(doc, bin.bytes(), path, glb); !s) return s;

  io_detail::text_output out;
  if (status s = out.open(path); !s) return s;
  if (!out.write(glb)) return out.error_status();
  return out.commit();
}

}  // namespace

status write_vrma(const std::string& path, const std::vector<proxy_pose>& frames,
                  const vrma_write_options& options) {
  try {
    return write_impl(path, frames, options);
  } catch (const std::exception& e) {
    return status::internal(path + ": " + e.what());
  } catch (...) {
    return status::internal(path + ": unexpected error while writing");
  }
}

}  // namespace avatarmap
